//! Every `defmt::Format` impl of the crate, in one place (feature `defmt`).

use crate::{ParamError, ParamKey, TableError};
use defmt::{write, Format, Formatter};

impl Format for ParamKey {
    fn format(&self, f: Formatter) {
        write!(f, "{=str}", self.as_str())
    }
}

impl Format for ParamError {
    fn format(&self, f: Formatter) {
        match self {
            Self::NotFinite(k) => write!(f, "{}: must be a finite number", k),
            Self::NotPositive(k) => write!(f, "{}: must be > 0", k),
            Self::LargeNotAboveSmall => {
                write!(
                    f,
                    "cone.large_diameter: must be larger than cone.small_diameter"
                )
            }
            Self::PreloadNotBelowSolid => {
                write!(f, "linear.preload: must be below the cone's solid force")
            }
        }
    }
}

impl Format for TableError {
    fn format(&self, f: Formatter) {
        match self {
            Self::Param(e) => write!(f, "{}", e),
            Self::BadDomain => write!(f, "domain: bad bounds"),
            Self::NoNonlinearPhase => write!(f, "domain: no nonlinear phase"),
            Self::TooNarrow => write!(f, "domain: nonlinear phase too narrow"),
            Self::OutOfRange => write!(f, "params: out of fixed-point range"),
            Self::NoSegments => write!(f, "knots: at least 2 are needed"),
        }
    }
}
