//! `mccs patch`: the indentation test on the standard patch, in the `f64` twin or the
//! fixed-point core.

use super::table::table;
use super::{arg_error, file_error, fmt_strain, io_error, ArithArg, Backend, CliError};
use crate::paramfile;
use crate::reference::Reference;
use mccs::{Arith, Params};
use std::io::Write;
use std::path::{Path, PathBuf};

#[derive(clap::Args, Debug)]
pub(super) struct Args {
    /// Parameter file (the TOML schema of docs/model.md).
    #[arg(long)]
    params: PathBuf,
    /// Surface nodes per side, N (3 … 40; 3 … 12 with `--backend fixed`).
    #[arg(long)]
    grid: usize,
    /// Grid spacing, mm.
    #[arg(long, allow_negative_numbers = true)]
    spacing: f64,
    /// Indentation depth, mm (0 … spacing).
    #[arg(long, allow_negative_numbers = true)]
    indent: f64,
    /// Solver: the f64 twin or the no_std fixed-point core.
    #[arg(long, value_enum)]
    backend: Backend,
    /// Arithmetic of the fixed-point core (`--backend fixed` only).
    #[arg(long, value_enum, default_value_t = ArithArg::Wide)]
    arith: ArithArg,
    /// Tick rate, Hz.
    #[arg(long, default_value_t = 1000.0, allow_negative_numbers = true)]
    rate: f64,
    /// Length of the run, s.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    duration: f64,
}

pub(super) fn run(a: Args, out: &mut dyn Write) -> Result<(), CliError> {
    let p = paramfile::read(&a.params)?;
    if a.arith != ArithArg::Wide && a.backend != Backend::Fixed {
        return Err(arg_error("--arith", "only with --backend fixed"));
    }
    let mut run = PatchRun::new(a.grid, a.spacing, a.indent, a.backend, a.rate, a.duration)?;
    run.arith = a.arith;
    let rows = run.reactions(&p, &a.params)?;
    let mut w = csv::Writer::from_writer(out);
    let err = |e: csv::Error| CliError(format!("stdout: {e}"));
    w.write_record(["time_s", "reaction_n"]).map_err(err)?;
    for (t, r) in rows {
        w.write_record([fmt_strain(t), r.to_string()])
            .map_err(err)?;
    }
    w.flush().map_err(io_error)
}

/// A validated `mccs patch` run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchRun {
    grid: usize,
    spacing: f64,
    depth: f64,
    backend: Backend,
    /// The fixed backend's spring arithmetic.
    pub arith: ArithArg,
    rate: f64,
    ticks: usize,
}

/// Largest grid per backend.
const MAX_GRID_REFERENCE: usize = 40;
const MAX_GRID_FIXED: usize = 12;
/// Capacities of the fixed backend's solver: N = 12 has 101 node slots and 558 springs.
const FIXED_NODES: usize = 101;
const FIXED_EDGES: usize = 558;

impl PatchRun {
    /// Checks the arguments; each error names its argument.
    pub fn new(
        grid: usize,
        spacing: f64,
        depth: f64,
        backend: Backend,
        rate: f64,
        duration: f64,
    ) -> Result<Self, CliError> {
        let max_grid = match backend {
            Backend::Reference => MAX_GRID_REFERENCE,
            Backend::Fixed => MAX_GRID_FIXED,
        };
        if !(3..=max_grid).contains(&grid) {
            return Err(arg_error(
                "--grid",
                &format!("must be 3 … {max_grid} for this backend"),
            ));
        }
        if !(spacing.is_finite() && spacing > 0.0 && spacing * grid as f64 <= 100.0) {
            return Err(arg_error(
                "--spacing",
                "must be > 0 mm, with grid × spacing ≤ 100 mm",
            ));
        }
        if !(depth.is_finite() && (0.0..=spacing).contains(&depth)) {
            return Err(arg_error("--indent", "must be 0 … spacing mm"));
        }
        if !(rate.is_finite() && (1.0..=100_000.0).contains(&rate) && rate.fract() == 0.0) {
            return Err(arg_error(
                "--rate",
                "must be a whole number of Hz, 1 … 100000",
            ));
        }
        if !(duration.is_finite() && duration > 0.0 && duration <= 60.0) {
            return Err(arg_error("--duration", "must be > 0 and ≤ 60 s"));
        }
        let ticks = (duration * rate).round() as usize;
        if ticks < 2 {
            return Err(arg_error("--duration", "must cover at least 2 ticks"));
        }
        Ok(Self {
            grid,
            spacing,
            depth,
            backend,
            arith: ArithArg::Wide,
            rate,
            ticks,
        })
    }

    /// Depth commanded at tick `i` (0-based): a ramp over the first half, then held.
    fn depth_at(&self, i: usize) -> f64 {
        let ramp = (self.ticks / 2).max(1);
        self.depth * ((i + 1) as f64 / ramp as f64).min(1.0)
    }

    /// `(time_s, reaction_n)` per tick of the fixed-point core in arithmetic `A`.
    fn fixed_reactions<A: Arith>(
        &self,
        topo: mccs::Topology<FIXED_NODES, FIXED_EDGES>,
        table: mccs::ForceTable64,
        cfg: &mccs::SolverConfig,
        arith: A,
    ) -> Result<Vec<(f64, f64)>, mccs::SolverError> {
        let mut s = mccs::Solver::with_arith(topo, table, cfg, arith)?;
        Ok((0..self.ticks)
            .map(|i| {
                let z = mccs::Length::from_num(-self.depth_at(i));
                let r = s.step_held([mccs::Length::ZERO, mccs::Length::ZERO, z]);
                ((i + 1) as f64 / self.rate, r[2].to_num::<f64>())
            })
            .collect())
    }

    /// `(time_s, reaction_n)` per tick.
    pub fn reactions(&self, p: &Params, file: &Path) -> Result<Vec<(f64, f64)>, CliError> {
        let cfg = mccs::SolverConfig {
            tick_hz: self.rate,
            ..mccs::SolverConfig::default()
        };
        let table = table::<64>(
            p,
            file,
            mccs::table::DEFAULT_DOMAIN.0,
            mccs::table::DEFAULT_DOMAIN.1,
        )?;
        let too_stiff = |e: mccs::SolverError| {
            match e {
            mccs::SolverError::TooManySubsteps { needed } => arg_error(
                "--rate",
                &format!("this spring needs {needed} substeps per tick at this rate (at most 64): lower it"),
            ),
            other => CliError(format!("{}: {other}", file.display())),
        }
        };
        let time = |i: usize| (i + 1) as f64 / self.rate;
        match self.backend {
            Backend::Fixed => {
                let topo = mccs::Topology::<FIXED_NODES, FIXED_EDGES>::standard_patch(
                    self.grid,
                    self.spacing,
                )
                .map_err(|e| arg_error("--grid", &e.to_string()))?;
                match self.arith {
                    ArithArg::Wide => self.fixed_reactions(topo, table, &cfg, mccs::Wide),
                    ArithArg::Narrow => self.fixed_reactions(topo, table, &cfg, mccs::Narrow),
                }
                .map_err(too_stiff)
            }
            Backend::Reference => {
                let law = Reference::new(p).map_err(|e| file_error(file, e))?;
                let mesh = crate::patch::Mesh::standard(self.grid, self.spacing);
                let mut tc = crate::patch::TwinConfig::from_solver(&cfg, 0);
                let k_max = reference_max_stiffness(&law);
                let n = crate::patch::substeps(&mesh, k_max, &tc)
                    .ok_or_else(|| too_stiff(mccs::SolverError::NoDamping))?;
                if n > cfg.max_substeps {
                    return Err(too_stiff(mccs::SolverError::TooManySubsteps { needed: n }));
                }
                tc.substeps = n;
                let mut twin = crate::patch::Twin::new(mesh, law, tc);
                Ok((0..self.ticks)
                    .map(|i| (time(i), twin.step_held([0.0, 0.0, -self.depth_at(i)])[2]))
                    .collect())
            }
        }
    }
}

/// The law's largest tangent stiffness over the default strain domain (N per unit strain).
pub fn reference_max_stiffness(law: &Reference) -> f64 {
    let (lo, hi) = mccs::table::DEFAULT_DOMAIN;
    (0..=1000)
        .map(|i| law.stiffness(lo + (hi - lo) * i as f64 / 1000.0))
        .fold(0.0, f64::max)
}
