//! `mccs patch`: the indentation test on the standard patch, in the `f64` twin or the
//! fixed-point core.

use super::patch_args::{config_error, topology_error, twin_limits, DynamicsArgs, PatchArgs};
use super::progress::Simulated;
use super::table::{build, with_knots, Domain, TableArgs};
use super::watch::setup_line;
use super::{arg_error, csv_error, file_error, fmt_given, fmt_strain, io_error, Backend, CliError};
use crate::paramfile;
use crate::patch::{max_stiffness, substeps, Mesh, Twin, TwinConfig, TWIN_MAX_SUBSTEPS};
use crate::reference::Reference;
use crate::replay::{Engine, FIXED_EDGES, FIXED_NODES};
use mccs::{Arith, Length, Params, Solver, SolverConfig, Topology};
use std::io::Write;
use std::path::{Path, PathBuf};

#[derive(clap::Args, Debug)]
pub(super) struct Args {
    /// Parameter file (the TOML schema of docs/model.md).
    #[arg(long)]
    params: PathBuf,
    #[command(flatten)]
    patch: PatchArgs,
    /// Indentation depth, mm (0 … spacing).
    #[arg(long, allow_negative_numbers = true)]
    indent: f64,
    /// Length of the run, s (≤ 60).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    duration: f64,
    #[command(flatten)]
    dynamics: DynamicsArgs,
    #[command(flatten)]
    table: TableArgs,
}

pub(super) fn run(a: Args, out: &mut dyn Write) -> Result<(), CliError> {
    let run = PatchRun::new(a.patch, a.dynamics, a.indent, a.duration)?;
    if a.patch.backend == Backend::Reference {
        a.table.only_with_fixed()?;
    }
    let p = paramfile::read(&a.params)?;
    let rows = run.reactions(&p, &a.params, &a.table)?;
    let mut w = csv::Writer::from_writer(out);
    w.write_record(["time_s", "reaction_n"])
        .map_err(csv_error)?;
    for (t, r) in rows {
        w.write_record([fmt_strain(t), r.to_string()])
            .map_err(csv_error)?;
    }
    w.flush().map_err(io_error)
}

/// A validated `mccs patch` run.
#[derive(Clone, Copy, Debug)]
pub struct PatchRun {
    patch: PatchArgs,
    cfg: SolverConfig,
    depth: f64,
    ticks: usize,
}

impl PatchRun {
    /// Checks the arguments; each error names its argument.
    fn new(
        patch: PatchArgs,
        dynamics: DynamicsArgs,
        depth: f64,
        duration: f64,
    ) -> Result<Self, CliError> {
        patch.check()?;
        let cfg = SolverConfig {
            integrator: patch.integrator.into(),
            ..dynamics.config(patch.rate, mccs::Coupling::default())?
        };
        if !(depth.is_finite() && (0.0..=patch.spacing).contains(&depth)) {
            let what = format!(
                "must be 0 … {} mm (the --spacing)",
                fmt_given(patch.spacing)
            );
            return Err(arg_error("--indent", &what));
        }
        if !(duration.is_finite() && duration > 0.0 && duration <= 60.0) {
            return Err(arg_error("--duration", "must be > 0 and ≤ 60 s"));
        }
        let ticks = (duration * patch.rate).round() as usize;
        if ticks < 2 {
            return Err(arg_error("--duration", "must cover at least 2 ticks"));
        }
        Ok(Self {
            patch,
            cfg,
            depth,
            ticks,
        })
    }

    /// Depth commanded at tick `i` (0-based): a ramp over the first half, then held.
    fn depth_at(&self, i: usize) -> f64 {
        let ramp = (self.ticks / 2).max(1);
        self.depth * ((i + 1) as f64 / ramp as f64).min(1.0)
    }

    fn time(&self, i: usize) -> f64 {
        (i + 1) as f64 / self.patch.rate
    }

    /// Progress lines on stderr for a run that takes long (a large reference patch: the
    /// 40 × 40 twin over 60 s takes most of a minute).
    fn progress(&self) -> Simulated {
        Simulated::new("patch", self.time(self.ticks - 1))
    }

    /// `(time_s, reaction_n)` per tick of the fixed-point core in arithmetic `A`, on the
    /// table `mccs table` emits for `p` with `table`'s knots.
    fn fixed<A: Arith>(
        &self,
        p: &Params,
        file: &Path,
        table: &TableArgs,
        cfg: &SolverConfig,
        arith: A,
    ) -> Result<Vec<(f64, f64)>, CliError> {
        with_knots!(table.knots(), |S| {
            let t = build::<S>(p, file, Domain::Default, table.accept_error, true)?;
            self.fixed_on(t, cfg, arith)
        })
    }

    fn fixed_on<A: Arith, const S: usize>(
        &self,
        table: mccs::ForceTable<S>,
        cfg: &SolverConfig,
        arith: A,
    ) -> Result<Vec<(f64, f64)>, CliError> {
        let topo = Topology::<FIXED_NODES, FIXED_EDGES>::standard_patch(
            self.patch.grid,
            self.patch.spacing,
        )
        .map_err(topology_error)?;
        let mut s =
            Solver::with_arith(topo, table, cfg, arith).map_err(|e| config_error(e, cfg))?;
        self.announce(s.substeps());
        let mut progress = self.progress();
        Ok((0..self.ticks)
            .map(|i| {
                progress.at(self.time(i));
                let z = Length::from_num(-self.depth_at(i));
                let r = s.step_held([Length::ZERO, Length::ZERO, z]);
                (self.time(i), r[2].to_num::<f64>())
            })
            .collect())
    }

    /// `(time_s, reaction_n)` per tick of the `f64` twin.
    fn twin(
        &self,
        p: &Params,
        file: &Path,
        cfg: &SolverConfig,
    ) -> Result<Vec<(f64, f64)>, CliError> {
        let law = Reference::new(p).map_err(|e| file_error(file, e))?;
        let mesh = Mesh::standard(self.patch.grid, self.patch.spacing);
        let mut tc = TwinConfig::from_solver(cfg, 0);
        let k_max = max_stiffness(&law);
        let n = substeps(&mesh, k_max, &tc)
            .ok_or_else(|| config_error(mccs::SolverError::NoDamping, cfg))?;
        if n > TWIN_MAX_SUBSTEPS {
            return Err(config_error(
                mccs::SolverError::TooManySubsteps { needed: n },
                &twin_limits(cfg),
            ));
        }
        tc.substeps = n;
        self.announce(n);
        let mut twin = Twin::new(mesh, law, tc);
        let mut progress = self.progress();
        Ok((0..self.ticks)
            .map(|i| {
                progress.at(self.time(i));
                (
                    self.time(i),
                    twin.step_held([0.0, 0.0, -self.depth_at(i)])[2],
                )
            })
            .collect())
    }

    /// The line on stderr that says what the run simulates.
    fn announce(&self, substeps: u32) {
        eprintln!(
            "{}",
            setup_line("patch", &self.patch, None, &self.cfg, substeps, false)
        );
    }

    /// `(time_s, reaction_n)` per tick; the fixed-point core's table as `table` asks.
    pub(crate) fn reactions(
        &self,
        p: &Params,
        file: &Path,
        table: &TableArgs,
    ) -> Result<Vec<(f64, f64)>, CliError> {
        let cfg = self.cfg;
        match self.patch.engine() {
            Engine::Reference => self.twin(p, file, &cfg),
            Engine::Wide => self.fixed(p, file, table, &cfg, mccs::Wide),
            Engine::Narrow => self.fixed(p, file, table, &cfg, mccs::Narrow),
        }
    }
}
