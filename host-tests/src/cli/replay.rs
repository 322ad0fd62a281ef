//! `mccs replay`: a recorded probe trajectory against the standard patch, one CSV row
//! per tick.

use super::patch_args::{config_error, PatchArgs, TuningArgs};
use super::table::solver_table;
use super::{file_error, io_error, CliError};
use crate::paramfile;
use crate::replay::{Replay, ReplayError};
use crate::trajectory;
use std::io::Write;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub(super) struct Args {
    /// Parameter file (the TOML schema of docs/model.md).
    #[arg(long)]
    params: PathBuf,
    /// Probe trajectory, CSV `time_s,x_mm,y_mm,z_mm` (patch frame, surface at z = 0),
    /// times strictly increasing; sampled linearly at the tick rate.
    #[arg(long)]
    probe: PathBuf,
    #[command(flatten)]
    patch: PatchArgs,
    #[command(flatten)]
    tuning: TuningArgs,
}

pub(super) fn run(a: Args, out: &mut dyn Write) -> Result<(), CliError> {
    a.patch.check()?;
    let cfg = a.tuning.config(a.patch.rate)?;
    let p = paramfile::read(&a.params)?;
    // The table is built (and its errors named) before the trajectory is read.
    solver_table(&p, &a.params)?;
    let traj = trajectory::read(&a.probe).map_err(|e| CliError::new(e.to_string()))?;
    let replay = Replay {
        grid: a.patch.grid,
        spacing: a.patch.spacing,
        config: cfg,
        engine: a.patch.engine(),
    };
    let mut w = std::io::BufWriter::new(out);
    writeln!(
        w,
        "time_s,fx_n,fy_n,fz_n,contact_dx_mm,contact_dy_mm,contact_dz_mm,max_disp_mm"
    )
    .map_err(io_error)?;
    let mut failed = None;
    replay
        .run(&p, &traj, |r| {
            if failed.is_some() {
                return;
            }
            let line = format!(
                "{},{},{},{},{},{},{},{}",
                fmt_time(r.time),
                r.force[0],
                r.force[1],
                r.force[2],
                r.contact[0],
                r.contact[1],
                r.contact[2],
                r.max_disp
            );
            if let Err(e) = writeln!(w, "{line}") {
                failed = Some(e);
            }
        })
        .map_err(|e| match e {
            ReplayError::Solver(s) => config_error(s, &cfg),
            other => file_error(&a.params, other),
        })?;
    if let Some(e) = failed {
        return Err(io_error(e));
    }
    w.flush().map_err(io_error)
}

/// A tick time with its float noise removed (9 decimals at most).
fn fmt_time(t: f64) -> String {
    let s = format!("{t:.9}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}
