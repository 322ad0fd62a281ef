//! The arguments `patch` and `replay` share: the standard patch, the solver and its
//! configuration, with the same defaults in both.

use super::{arg_error, ArithArg, Backend, CliError, IntegratorArg};
use crate::replay::{Engine, MAX_GRID_FIXED};
use mccs::{Coupling, SolverConfig};

/// The largest grid of the reference backend.
pub const MAX_GRID_REFERENCE: usize = 40;

/// The standard patch and the solver that runs it.
#[derive(clap::Args, Debug, Clone, Copy)]
pub(super) struct PatchArgs {
    /// Surface nodes per side, N (3 … 40; 3 … 12 with `--backend fixed`).
    #[arg(long, default_value_t = 5)]
    pub grid: usize,
    /// Grid spacing, mm (grid × spacing ≤ 100 mm).
    #[arg(long, default_value_t = 2.5, allow_negative_numbers = true)]
    pub spacing: f64,
    /// Solver: the f64 twin or the no_std fixed-point core.
    #[arg(long, value_enum, default_value_t = Backend::Reference)]
    pub backend: Backend,
    /// Arithmetic of the fixed-point core (`--backend fixed` only; default wide).
    #[arg(long, value_enum)]
    pub arith: Option<ArithArg>,
    /// Tick rate, Hz (a whole number, 1 … 100000).
    #[arg(long, default_value_t = 1000.0, allow_negative_numbers = true)]
    pub rate: f64,
    /// Integrator of either backend (docs/performance.md, "The symplectic option").
    #[arg(long, value_enum, default_value_t = IntegratorArg::ImprovedEuler)]
    pub integrator: IntegratorArg,
}

impl PatchArgs {
    /// Checks the arguments; each error names its argument.
    pub fn check(&self) -> Result<(), CliError> {
        let max_grid = match self.backend {
            Backend::Reference => MAX_GRID_REFERENCE,
            Backend::Fixed => MAX_GRID_FIXED,
        };
        if !(3..=max_grid).contains(&self.grid) {
            return Err(arg_error(
                "--grid",
                &format!("must be 3 … {max_grid} for this backend"),
            ));
        }
        if !(self.spacing.is_finite()
            && self.spacing > 0.0
            && self.spacing * self.grid as f64 <= 100.0)
        {
            return Err(arg_error(
                "--spacing",
                "must be > 0 mm, with grid × spacing ≤ 100 mm",
            ));
        }
        let r = self.rate;
        if !(r.is_finite() && (1.0..=100_000.0).contains(&r) && r.fract() == 0.0) {
            return Err(arg_error(
                "--rate",
                "must be a whole number of Hz, 1 … 100000",
            ));
        }
        if self.arith.is_some() && self.backend != Backend::Fixed {
            return Err(arg_error("--arith", "only with --backend fixed"));
        }
        Ok(())
    }

    /// The engine these arguments ask for.
    pub fn engine(&self) -> Engine {
        match (self.backend, self.arith) {
            (Backend::Reference, _) => Engine::Reference,
            (Backend::Fixed, Some(ArithArg::Narrow)) => Engine::Narrow,
            (Backend::Fixed, _) => Engine::Wide,
        }
    }
}

/// The patch's dynamics beyond its geometry: the node mass and the spring damping (the
/// defaults are `SolverConfig::default()`'s). `patch`, `replay` and `check` take them.
#[derive(clap::Args, Debug, Clone, Copy)]
pub(super) struct DynamicsArgs {
    /// Haptic mass of each free node, g (> 0).
    #[arg(long, default_value_t = SolverConfig::default().node_mass * 1000.0, allow_negative_numbers = true)]
    pub node_mass: f64,
    /// Relative damping of each spring, N·s/m (0 … 30).
    #[arg(long, default_value_t = SolverConfig::default().spring_damping, allow_negative_numbers = true)]
    pub spring_damping: f64,
}

impl DynamicsArgs {
    /// The configuration at `rate` with `coupling`; each value out of range names its
    /// argument.
    pub fn config(&self, rate: f64, coupling: Coupling) -> Result<SolverConfig, CliError> {
        let cfg = SolverConfig {
            tick_hz: rate,
            node_mass: self.node_mass / 1000.0,
            spring_damping: self.spring_damping,
            coupling,
            ..SolverConfig::default()
        };
        cfg.validate().map_err(|e| config_error(e, &cfg))?;
        Ok(cfg)
    }
}

/// The dynamics and the probe's coupling: what a run with a probe takes (`replay`,
/// `check`). `patch` holds its contact node, so it has no coupling.
#[derive(clap::Args, Debug, Clone, Copy)]
pub(super) struct TuningArgs {
    /// Coupling stiffness, N/mm (> 0, ≤ 1000).
    #[arg(long, default_value_t = Coupling::default().stiffness, allow_negative_numbers = true)]
    pub coupling_stiffness: f64,
    /// Coupling damping, N·s/m (0 … 1000).
    #[arg(long, default_value_t = Coupling::default().damping, allow_negative_numbers = true)]
    pub coupling_damping: f64,
    /// Largest force per axis the device renders, N (> 0, < 2000).
    #[arg(long, default_value_t = Coupling::default().max_force, allow_negative_numbers = true)]
    pub max_force: f64,
    #[command(flatten)]
    pub dynamics: DynamicsArgs,
}

impl TuningArgs {
    /// The configuration at `rate`; each value out of range names its argument.
    pub fn config(&self, rate: f64) -> Result<SolverConfig, CliError> {
        self.dynamics.config(
            rate,
            Coupling {
                stiffness: self.coupling_stiffness,
                damping: self.coupling_damping,
                max_force: self.max_force,
            },
        )
    }
}

/// The standard patch's topology refused by the fixed-point core, as the argument at
/// fault: its spring lengths and positions come from `--spacing` (springs of 1 mm at
/// least), its node and spring counts from `--grid`.
pub(super) fn topology_error(e: mccs::TopologyError) -> CliError {
    use mccs::TopologyError as E;
    match e {
        E::TooShort => arg_error(
            "--spacing",
            "must be ≥ 1 mm with --backend fixed (its springs are 1 mm long at least)",
        ),
        E::OutOfRange | E::BadGrid => arg_error("--spacing", &e.to_string()),
        E::NodeCapacity | E::EdgeCapacity | E::BadEnd | E::TooManySprings => {
            arg_error("--grid", &e.to_string())
        }
    }
}

/// `cfg` with the twin's cap on substeps: what the reference backend's errors quote.
pub(super) fn twin_limits(cfg: &SolverConfig) -> SolverConfig {
    SolverConfig {
        max_substeps: crate::patch::TWIN_MAX_SUBSTEPS,
        ..*cfg
    }
}

/// A solver error as the argument at fault, where one is.
pub(super) fn config_error(e: mccs::SolverError, cfg: &SolverConfig) -> CliError {
    use mccs::{ConfigKey as K, SolverError as E};
    let (arg, what) = match e {
        E::Config(K::TickHz) => ("--rate", "out of range for this configuration"),
        E::Config(K::NodeMass) => ("--node-mass", "must be > 0 g (and large enough for the rate)"),
        E::Config(K::SpringDamping) => ("--spring-damping", "must be 0 … 30 N·s/m"),
        E::Config(K::CouplingStiffness) => ("--coupling-stiffness", "must be > 0 and ≤ 1000 N/mm"),
        E::Config(K::CouplingDamping) => ("--coupling-damping", "must be 0 … 1000 N·s/m"),
        E::Config(K::CouplingMaxForce) => ("--max-force", "must be > 0 and < 2000 N"),
        E::TooManySubsteps { needed } => {
            return arg_error(
                "--rate",
                &format!(
                    "this spring needs {} substeps per tick at {} Hz (at most {}): raise the rate (the substeps are per tick), --node-mass or --spacing, or change the damping",
                    if needed == u32::MAX { format!("{needed} or more") } else { needed.to_string() },
                    cfg.tick_hz, cfg.max_substeps
                ),
            )
        }
        E::NoDamping => ("--spring-damping", "the integrator needs damping: must be > 0"),
        E::SpringTooLong { max_mm } => {
            return arg_error(
                "--spacing",
                &format!("the narrow arithmetic holds springs up to {max_mm} mm: use a smaller spacing or --arith wide"),
            )
        }
        other => return CliError::new(other.to_string()),
    };
    arg_error(arg, what)
}
