//! [`TableError`]: why a force table could not be built.

use crate::params::ParamError;
use core::fmt;

/// Why a table could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableError {
    /// The spring parameters are invalid.
    Param(ParamError),
    /// The domain bounds are not finite, not ordered, or outside ±127.
    BadDomain,
    /// The domain does not reach into the nonlinear phase `(Δ(F_T), Δ(F_C))`.
    NoNonlinearPhase,
    /// The nonlinear phase inside the domain is too narrow for `S` segments at Q16.
    TooNarrow,
    /// A force or stiffness in the table exceeds its fixed-point format.
    OutOfRange,
    /// Fewer than one segment.
    NoSegments,
    /// The table's measured error is over the bound asked for
    /// ([`crate::ForceTable::with_bound`]); it reached this (parts per 10⁹: force of
    /// `F(to)`, stiffness relative).
    BoundNotMet {
        /// Force error reached, ppb of `F(to)`.
        force_ppb: u32,
        /// Stiffness error reached, ppb (relative).
        stiffness_ppb: u32,
    },
    /// A raw table's header breaks the invariants the builder keeps
    /// ([`crate::ForceTable::validate`]): it was not emitted by `mccs table`, or was edited.
    Inconsistent,
}

impl TableError {
    /// The message, without the parameter error's own (see `Display`): one source for
    /// `Display` and the `defmt` impl.
    pub const fn message(&self) -> &'static str {
        match self {
            Self::Param(_) => "params: invalid",
            Self::BadDomain => "domain: bounds must be finite, within ±127, and from < to",
            Self::NoNonlinearPhase => {
                "domain: does not reach into the nonlinear phase (Δ(F_T), Δ(F_C)) of this spring"
            }
            Self::TooNarrow => {
                "domain: the nonlinear phase inside it is too narrow for this many knots"
            }
            Self::OutOfRange => {
                "params: forces or stiffnesses in the domain exceed the fixed-point formats (±2048 N, ±32768 N/strain)"
            }
            Self::NoSegments => "knots: at least 2 are needed",
            Self::BoundNotMet { .. } => {
                "table: its measured error is over the bound (more knots or a narrower domain)"
            }
            Self::Inconsistent => {
                "table: its header is inconsistent (not as `mccs table` emits it)"
            }
        }
    }
}

impl From<ParamError> for TableError {
    fn from(e: ParamError) -> Self {
        Self::Param(e)
    }
}

impl fmt::Display for TableError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Param(e) => e.fmt(f),
            Self::BoundNotMet {
                force_ppb,
                stiffness_ppb,
            } => {
                let reached = crate::TableBound::from_ppb(*force_ppb, *stiffness_ppb);
                write!(
                    f,
                    "table: its measured error, force {:.1e} of F(to) and stiffness {:.1e} relative, is over the bound (more knots or a narrower domain)",
                    reached.force, reached.stiffness
                )
            }
            other => f.write_str(other.message()),
        }
    }
}

impl core::error::Error for TableError {}
