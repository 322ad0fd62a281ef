//! `mccs replay`: a recorded probe trajectory against the standard patch, one CSV row
//! per tick; with `--tissue`, against the `f64` roaming probe (docs/roaming.md).

use super::patch_args::{config_error, topology_error, twin_limits, PatchArgs, TuningArgs};
use super::progress::Simulated;
use super::table::{build, with_knots, Domain, TableArgs};
use super::watch::{setup_line, Watch};
use super::{arg_error, file_error, fmt_given, io_error, Backend, CliError, OUTPUT_CLOSED};
use crate::paramfile;
use crate::replay::{Engine, Replay, ReplayError, RoamRow, Roaming};
use crate::roam::tissue::{MAX_CAP_RADIUS_MM, MAX_EXTENT_MM, MAX_SIDE};
use crate::roam::{Friction, RoamError, Shape, Tissue};
use crate::trajectory;
use mccs::{ProxyError, SolverConfig};
use std::io::Write;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub(super) struct Args {
    /// Parameter file (the TOML schema of docs/model.md).
    #[arg(long)]
    params: PathBuf,
    /// Probe trajectory, CSV `time_s,x_mm,y_mm,z_mm` (patch frame, surface at z = 0),
    /// times strictly increasing; sampled linearly at the tick rate.
    #[arg(long, required_unless_present = "joints", conflicts_with = "joints")]
    probe: Option<PathBuf>,
    /// A recorded arm motion instead, CSV `time_s,count_a,count_b,count_c`: each tick's
    /// probe is the fixed forward kinematics of --device less its tissue origin, and the
    /// rows end with the arm's duties (docs/arm.md).
    #[arg(long, requires = "device")]
    joints: Option<PathBuf>,
    /// The arm's device file (with --joints).
    #[arg(long, requires = "joints")]
    device: Option<PathBuf>,
    #[command(flatten)]
    patch: PatchArgs,
    #[command(flatten)]
    tuning: TuningArgs,
    #[command(flatten)]
    table: TableArgs,
    #[command(flatten)]
    roam: RoamArgs,
}

/// The roaming options of `replay` and `link replay`.
#[derive(clap::Args, Debug)]
pub(super) struct RoamArgs {
    /// Roam a tissue of W,H nodes (3 … 64 each, at --spacing; --grid is the window) with
    /// a proxy that slides on its surface; the trajectory is then in the tissue's frame
    /// (origin at its centre, top at z = 0).
    #[arg(long, value_name = "W,H")]
    tissue: Option<String>,
    /// Static and kinetic friction MU_S,MU_K (0 … 2 each; with --tissue; default 0,0).
    #[arg(long, value_name = "MU_S,MU_K")]
    friction: Option<String>,
    /// Probe radius, mm (0 … spacing/2; with --tissue; default 0).
    #[arg(long, value_name = "R", allow_negative_numbers = true)]
    probe_radius: Option<f64>,
    /// Shape the tissue as a spherical cap of this radius, mm (with --tissue; 4/3 of the
    /// tissue's half-diagonal … 2000).
    #[arg(long, value_name = "R", allow_negative_numbers = true)]
    cap_radius: Option<f64>,
}

/// `A,B` as two numbers, or an error naming `arg`.
fn pair<T: std::str::FromStr>(arg: &str, text: &str, what: &str) -> Result<(T, T), CliError> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    match parts.as_slice() {
        [a, b] => match (a.parse(), b.parse()) {
            (Ok(a), Ok(b)) => Ok((a, b)),
            _ => Err(arg_error(arg, what)),
        },
        _ => Err(arg_error(arg, what)),
    }
}

impl RoamArgs {
    /// The roaming arguments on `patch`, if `--tissue` is given; each error names its
    /// argument.
    pub(super) fn roaming(&self, patch: &PatchArgs) -> Result<Option<Roaming>, CliError> {
        let Some(tissue) = &self.tissue else {
            for (given, arg) in [
                (self.friction.is_some(), "--friction"),
                (self.probe_radius.is_some(), "--probe-radius"),
                (self.cap_radius.is_some(), "--cap-radius"),
            ] {
                if given {
                    return Err(arg_error(arg, "only with --tissue"));
                }
            }
            return Ok(None);
        };
        let (w, h) = pair::<usize>(
            "--tissue",
            tissue,
            "must be W,H: two whole numbers of nodes, 3 … 64",
        )?;
        let (mu_s, mu_k) = match &self.friction {
            Some(f) => pair::<f64>("--friction", f, "must be MU_S,MU_K: two numbers, 0 … 2")?,
            None => (0.0, 0.0),
        };
        let shape = match self.cap_radius {
            Some(radius) => Shape::Cap { radius },
            None => Shape::Flat,
        };
        let named = |e: RoamError| self.roaming_error(patch, e, (w, h), (mu_s, mu_k));
        let tissue = Tissue::new(w, h, patch.spacing, shape).map_err(&named)?;
        let friction = Friction::new(mu_s, mu_k).map_err(&named)?;
        let probe_radius = self.probe_radius.unwrap_or(0.0);
        if !(probe_radius.is_finite() && (0.0..=tissue.spacing / 2.0).contains(&probe_radius)) {
            return Err(named(RoamError::ProbeRadius));
        }
        if patch.grid > w.min(h) {
            return Err(named(RoamError::Window));
        }
        Ok(Some(Roaming {
            tissue,
            friction,
            probe_radius,
        }))
    }

    /// A refused roaming configuration as one line: the argument at fault, the rule, and
    /// what was given or computed from it.
    fn roaming_error(
        &self,
        patch: &PatchArgs,
        e: RoamError,
        (w, h): (usize, usize),
        mu: (f64, f64),
    ) -> CliError {
        let s = patch.spacing;
        let extent = |n: usize| (n.saturating_sub(1)) as f64 * s;
        match e {
            RoamError::TissueSize => arg_error(
                "--tissue",
                &format!("each side must be 3 to {MAX_SIDE} nodes (got {w},{h})"),
            ),
            RoamError::Spacing => arg_error(
                "--spacing",
                &format!("must be a finite number of mm, 1 or more, with --tissue (got {})", fmt_given(s)),
            ),
            RoamError::TissueExtent => arg_error(
                "--spacing",
                &format!(
                    "the tissue {w} × {h} nodes at {} mm spans {} × {} mm, more than the {} mm a side the core holds (±{} mm): lower --spacing or --tissue",
                    fmt_given(s),
                    fmt_given(extent(w)),
                    fmt_given(extent(h)),
                    2.0 * MAX_EXTENT_MM,
                    MAX_EXTENT_MM,
                ),
            ),
            RoamError::CapRadius => {
                let (hx, hy) = (extent(w) / 2.0, extent(h) / 2.0);
                let least = 4.0 / 3.0 * (hx * hx + hy * hy).sqrt();
                arg_error(
                    "--cap-radius",
                    &format!(
                        "must be {:.1} to {MAX_CAP_RADIUS_MM} mm for this tissue (4/3 of its half-diagonal at least; got {})",
                        least,
                        fmt_given(self.cap_radius.unwrap_or(f64::NAN)),
                    ),
                )
            }
            RoamError::Window => arg_error(
                "--grid",
                &format!(
                    "the window ({} nodes a side) must fit in the tissue ({w} × {h} nodes)",
                    patch.grid
                ),
            ),
            RoamError::Friction => arg_error(
                "--friction",
                &format!(
                    "MU_S and MU_K must each be 0 to 2 (got {},{})",
                    fmt_given(mu.0),
                    fmt_given(mu.1)
                ),
            ),
            RoamError::ProbeRadius => arg_error(
                "--probe-radius",
                &format!(
                    "must be 0 to {} mm, half the spacing (got {})",
                    fmt_given(s / 2.0),
                    fmt_given(self.probe_radius.unwrap_or(f64::NAN)),
                ),
            ),
            RoamError::Hysteresis => arg_error("--tissue", &e.to_string()),
        }
    }
}

pub(super) fn run(a: Args, out: &mut dyn Write) -> Result<(), CliError> {
    a.patch.check()?;
    let cfg = SolverConfig {
        integrator: a.patch.integrator.into(),
        ..a.tuning.config(a.patch.rate)?
    };
    let roaming = a.roam.roaming(&a.patch)?;
    let p = paramfile::read(&a.params)?;
    match a.patch.backend {
        Backend::Reference => {
            a.table.only_with_fixed()?;
            replay::<64>(&a, &p, cfg, roaming, None, out)
        }
        Backend::Fixed => with_knots!(a.table.knots(), |S| {
            // The table is built (and its errors named) before the trajectory is read.
            let t = build::<S>(&p, &a.params, Domain::Default, a.table.accept_error, true)?;
            replay::<S>(&a, &p, cfg, roaming, Some(&t), out)
        }),
    }
}

/// The columns of each mode, for `--help` (the tests hold it to the headers printed).
pub(super) const COLUMNS_HELP: &str = "\
Columns (one row per tick, stdout):
  every mode:  time_s,fx_n,fy_n,fz_n,max_disp_mm
               the tick's time (s), the device force (N), the largest node displacement (mm)
  glued:       then contact_dx_mm,contact_dy_mm,contact_dz_mm
               the contact node's displacement from rest (mm)
  --tissue:    then proxy_x_mm,proxy_y_mm,proxy_z_mm,contact,slipping,window_shifts
               the proxy (mm, the tissue's frame; the probe out of contact), 1 in contact,
               1 slipping, the window's shifts so far
stderr: one line with what the run simulates, then one counted line for each way the
probe left what the model represents (below the patch's depth, pressing off its side or
the tissue's edge, at the force clamp).";

/// The columns every mode prints first, in this order; each mode's own follow
/// ([`GLUED_COLUMNS`], [`ROAMING_COLUMNS`]).
pub const LEADING_COLUMNS: &str = "time_s,fx_n,fy_n,fz_n,max_disp_mm";
/// A glued replay's own columns: the contact node's displacement from rest.
pub const GLUED_COLUMNS: &str = "contact_dx_mm,contact_dy_mm,contact_dz_mm";
/// A roaming replay's own columns: the proxy, the contact's state, the window's shifts.
pub const ROAMING_COLUMNS: &str = "proxy_x_mm,proxy_y_mm,proxy_z_mm,contact,slipping,window_shifts";

/// The replay of `a`'s trajectory on `table` (`None`: the reference backend).
fn replay<const S: usize>(
    a: &Args,
    p: &mccs::Params,
    cfg: SolverConfig,
    roaming: Option<Roaming>,
    table: Option<&mccs::ForceTable<S>>,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    let (traj, arm) = probe_motion(a)?;
    // With an arm, each row ends with its duties at that tick.
    let duty_columns = if arm.is_some() {
        ",duty_a,duty_b,duty_c"
    } else {
        ""
    };
    let replay = Replay {
        grid: a.patch.grid,
        spacing: a.patch.spacing,
        config: cfg,
        engine: a.patch.engine(),
    };
    let w = std::io::BufWriter::new(out);
    // The reference backend's substeps are the twin's, under its own cap.
    let limits = match replay.engine {
        Engine::Reference => twin_limits(&cfg),
        _ => cfg,
    };
    let fail = |e| replay_error(e, &limits, &a.params);
    let substeps = replay.substeps(p, table).map_err(fail)?;
    let tissue = roaming.as_ref().map(|r| r.tissue);
    let mut seen = RowsSeen::new(a, tissue, &cfg, substeps, traj.span().1, arm);
    let mut observe = |time: f64, probe, force: [f64; 3]| seen.row_end(time, probe, force);
    let done = match roaming {
        Some(roaming) => csv(
            w,
            &format!("{}{duty_columns}", header(true)),
            |row| {
                replay.roam_with(p, table, &traj, &roaming, |r: RoamRow| {
                    row(format!(
                        "{}{}",
                        roam_line(&r),
                        observe(r.time, r.probe, r.force)
                    ))
                })
            },
            fail,
        ),
        None => csv(
            w,
            &format!("{}{duty_columns}", header(false)),
            |row| {
                replay.run_with(p, table, &traj, |r| {
                    row(format!(
                        "{}{}",
                        glued_line(&r),
                        observe(r.time, r.probe, r.force)
                    ))
                })
            },
            fail,
        ),
    };
    for line in seen.watch.warnings() {
        eprintln!("{line}");
    }
    done
}

/// What a replay does with each row as it goes: the setup line before the first, the
/// progress, the watch over force and depth, and the row's duties (with an arm).
struct RowsSeen {
    setup: Option<String>,
    progress: Simulated,
    watch: Watch,
    tick: usize,
    arm: Option<ArmPoses>,
}

impl RowsSeen {
    /// For the replay of `a` over `duration_s` on `tissue` (roaming) with `cfg` at
    /// `substeps` per tick, with `arm`'s poses for the duties.
    fn new(
        a: &Args,
        tissue: Option<crate::roam::Tissue>,
        cfg: &SolverConfig,
        substeps: u32,
        duration_s: f64,
        arm: Option<ArmPoses>,
    ) -> Self {
        Self {
            // Said with the first row: a configuration the core refuses when the run starts
            // (a cap's window) gets its one error line alone.
            setup: Some(setup_line(
                "replay",
                &a.patch,
                tissue.as_ref(),
                cfg,
                substeps,
                true,
            )),
            // Progress lines on stderr for a replay that takes long (a long trajectory on a
            // large reference patch: 600 s on the 8 × 8 twin takes 14 s).
            progress: Simulated::new("replay", duration_s),
            watch: Watch::new(
                "replay",
                a.patch.grid,
                a.patch.spacing,
                tissue,
                cfg.coupling.max_force,
            ),
            tick: 0,
            arm,
        }
    }

    /// Sees the row at `time`, and returns the end of its line: its duties, if any.
    fn row_end(&mut self, time: f64, probe: [f64; 3], force: [f64; 3]) -> String {
        if let Some(line) = self.setup.take() {
            eprintln!("{line}");
        }
        self.progress.at(time);
        self.watch.see(time, probe, force);
        let k = self.tick;
        self.tick += 1;
        duty_text(self.arm.as_ref(), k, force)
    }
}

/// A replay's error as the CLI says it: a solver configuration against the `limits` it
/// ran under, a cap or tissue argument, a topology, or else the parameter file's.
fn replay_error(e: ReplayError, limits: &SolverConfig, params: &std::path::Path) -> CliError {
    match e {
        ReplayError::Solver(s) => config_error(s, limits),
        ReplayError::Proxy(e @ ProxyError::Cap) => arg_error("--cap-radius", &e.to_string()),
        ReplayError::Proxy(e) => arg_error("--tissue", &e.to_string()),
        ReplayError::Topology(e) => topology_error(e),
        other => file_error(params, other),
    }
}

/// An arm and its pose at each tick of a replay, for the duties.
type ArmPoses = (mccs::Arm, Vec<mccs::ArmPose>);

/// The probe's motion of `a`: its trajectory, or the arm's (each tick's probe from its
/// counts, and its pose for the duties).
fn probe_motion(a: &Args) -> Result<(trajectory::Trajectory, Option<ArmPoses>), CliError> {
    match (&a.probe, &a.joints, &a.device) {
        // (clap's `requires = "joints"` on --device does not hold here: clap drops a
        // requirement whose argument conflicts with one given, and --joints conflicts
        // with --probe.)
        (Some(_), _, Some(_)) => Err(arg_error(
            "--device",
            "only with --joints (a --probe trajectory needs no arm)",
        )),
        (Some(p), _, _) => Ok((
            trajectory::read(p).map_err(|e| CliError::new(e.to_string()))?,
            None,
        )),
        (None, Some(j), Some(d)) => {
            let spec = crate::arm::device_file::read(d).map_err(CliError::new)?;
            let arm = mccs::Arm::new(&spec).map_err(|e| arg_error("--device", &e.to_string()))?;
            let rows = crate::arm::joints::read(j).map_err(CliError::new)?;
            let ticks = crate::arm::joints::ticks(&rows, a.patch.rate, &arm);
            let samples: Vec<(f64, [f64; 3])> = ticks
                .iter()
                .map(|(t, _, pose)| (*t, pose.probe.map(|c| c.to_num::<f64>())))
                .collect();
            let traj = trajectory::Trajectory::new(samples).map_err(|e| {
                arg_error(
                    "--joints",
                    &format!(
                        "the arm's probe (--device's fixed kinematics less its tissue origin): {}",
                        e.what
                    ),
                )
            })?;
            let poses = ticks.into_iter().map(|(_, _, p)| p).collect();
            Ok((traj, Some((arm, poses))))
        }
        _ => Err(arg_error(
            "--probe",
            "give --probe, or --joints with --device",
        )),
    }
}

/// `,duty_a,duty_b,duty_c` of tick `k` rendering `force` (N) on the arm; nothing without
/// one.
fn duty_text(arm: Option<&ArmPoses>, k: usize, force: [f64; 3]) -> String {
    let Some((arm, poses)) = arm else {
        return String::new();
    };
    let Some(pose) = poses.get(k.min(poses.len().saturating_sub(1))) else {
        return String::new();
    };
    let d = arm.drive(pose, force.map(mccs::Force::saturating_from_num));
    let q = |x: i32| x as f64 / 65_536.0;
    format!(
        ",{},{},{}",
        q(d.duty_q16[0]),
        q(d.duty_q16[1]),
        q(d.duty_q16[2])
    )
}

/// A glued tick's CSV line.
pub(super) fn glued_line(r: &crate::replay::Row) -> String {
    format!(
        "{},{},{},{},{},{},{},{}",
        fmt_time(r.time),
        r.force[0],
        r.force[1],
        r.force[2],
        r.max_disp,
        r.contact[0],
        r.contact[1],
        r.contact[2],
    )
}

/// A roaming tick's CSV line.
pub(super) fn roam_line(r: &RoamRow) -> String {
    format!(
        "{},{},{},{},{},{},{},{},{},{},{}",
        fmt_time(r.time),
        r.force[0],
        r.force[1],
        r.force[2],
        r.max_disp,
        r.proxy[0],
        r.proxy[1],
        r.proxy[2],
        r.contact as u8,
        r.slipping as u8,
        r.window_shifts
    )
}

/// The CSV header of a mode.
pub(super) fn header(roaming: bool) -> String {
    if roaming {
        format!("{LEADING_COLUMNS},{ROAMING_COLUMNS}")
    } else {
        format!("{LEADING_COLUMNS},{GLUED_COLUMNS}")
    }
}

/// Writes `header`, then each line `run` hands its row function; stops writing at the
/// first failed write, which it reports after the run.
fn csv(
    mut w: impl Write,
    header: &str,
    run: impl FnOnce(&mut dyn FnMut(String)) -> Result<(), ReplayError>,
    fail: impl FnOnce(ReplayError) -> CliError,
) -> Result<(), CliError> {
    // The header with the first row: a configuration the core refuses (found when the
    // run starts) leaves stdout empty, as every other usage error does.
    let (mut failed, mut started) = (None, false);
    run(&mut |line| {
        if failed.is_none() {
            let header = if started {
                Ok(())
            } else {
                writeln!(w, "{header}")
            };
            started = true;
            if let Err(e) = header.and_then(|()| writeln!(w, "{line}")) {
                // The reader closed stdout: nothing more to write or to run for.
                if e.kind() == std::io::ErrorKind::BrokenPipe {
                    std::process::exit(OUTPUT_CLOSED.into());
                }
                failed = Some(e);
            }
        }
    })
    .map_err(fail)?;
    if let Some(e) = failed {
        return Err(io_error(e));
    }
    if !started {
        writeln!(w, "{header}").map_err(io_error)?;
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
