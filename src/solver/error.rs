//! [`SolverError`]: why a solver or a parameter set could not be built.

use super::ConfigKey;

/// Why a solver could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SolverError {
    /// A configuration value is out of its range (see [`crate::SolverConfig`]).
    Config(ConfigKey),
    /// No damping at all: the improved Euler step is unstable at any step size.
    NoDamping,
    /// The stability bound needs more substeps per tick than `max_substeps`.
    TooManySubsteps {
        /// Substeps the bound asks for (saturated at `u32::MAX`).
        needed: u32,
    },
    /// The topology has no contact node.
    NoContact,
    /// A [`crate::ParamSet`] prepared for another topology or tick rate was applied; the
    /// solver keeps its set.
    ForeignParamSet,
    /// A spring is longer than the arithmetic's precision allows
    /// ([`crate::Arith::MAX_REST_LENGTH_MM`]: 16 mm for [`crate::Narrow`]).
    SpringTooLong {
        /// The longest rest length allowed, mm.
        max_mm: u32,
    },
    /// A proposed substep count failed the stability check: its substep is not stable
    /// with the margin the estimate keeps ([`crate::solver::stability::StabilityCheck`]).
    Unverified {
        /// The substeps proposed.
        substeps: u32,
    },
}

impl core::fmt::Display for SolverError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Config(k) => write!(f, "{k}: {}", self.message()),
            Self::TooManySubsteps { needed } => {
                write!(
                    f,
                    "max_substeps: stability needs {needed} substeps per tick ({})",
                    self.message()
                )
            }
            Self::SpringTooLong { max_mm } => {
                write!(
                    f,
                    "topology: a spring is longer than {max_mm} mm ({})",
                    self.message()
                )
            }
            Self::Unverified { substeps } => {
                write!(
                    f,
                    "stability: {substeps} substeps per tick: {}",
                    self.message()
                )
            }
            other => f.write_str(other.message()),
        }
    }
}

impl SolverError {
    /// The message without its values (see `Display`): one source for `Display` and the
    /// `defmt` impl.
    pub const fn message(&self) -> &'static str {
        match self {
            Self::Config(_) => "out of range",
            Self::NoDamping => {
                "spring_damping/node_damping: the improved Euler integrator needs damping"
            }
            Self::TooManySubsteps { .. } => {
                "raise max_substeps, the node mass or the tick rate (the substeps are per tick), or change the damping"
            }
            Self::NoContact => "topology: no contact node",
            Self::ForeignParamSet => {
                "parameter set: prepared for another topology or tick rate; the solver keeps its own"
            }
            Self::SpringTooLong { .. } => {
                "this arithmetic's precision; scale the patch down or use the wide arithmetic"
            }
            Self::Unverified { .. } => {
                "not stable with the estimate's margin on this patch (propose more, or none)"
            }
        }
    }
}

impl core::error::Error for SolverError {}
