//! Every `defmt::Format` impl of the crate, in one place (feature `defmt`): the error
//! types and the fault, so that firmware can log them.

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

impl Format for crate::TopologyError {
    fn format(&self, f: Formatter) {
        use crate::TopologyError as E;
        let what = match self {
            E::NodeCapacity => "topology: node capacity",
            E::EdgeCapacity => "topology: edge capacity",
            E::BadGrid => "topology: bad grid",
            E::OutOfRange => "topology: node out of range",
            E::TooShort => "topology: spring shorter than 1 mm",
            E::BadEnd => "topology: bad spring end",
            E::TooManySprings => "topology: too many springs at a node",
        };
        write!(f, "{=str}", what)
    }
}

impl Format for crate::ConfigKey {
    fn format(&self, f: Formatter) {
        write!(f, "{=str}", self.as_str())
    }
}

impl Format for crate::SolverError {
    fn format(&self, f: Formatter) {
        use crate::SolverError as E;
        match self {
            E::Config(k) => write!(f, "{}: out of range", k),
            E::NoDamping => write!(f, "no damping: the improved Euler step needs some"),
            E::TooManySubsteps { needed } => {
                write!(f, "stability needs {=u32} substeps per tick", needed)
            }
            E::NoContact => write!(f, "topology: no contact node"),
        }
    }
}

impl Format for crate::Fault {
    fn format(&self, f: Formatter) {
        match self {
            Self::Read => write!(f, "device read failed"),
            Self::Write => write!(f, "device write failed"),
        }
    }
}

impl Format for crate::PathError {
    fn format(&self, f: Formatter) {
        use crate::PathError as E;
        match self {
            E::Count => write!(f, "path: no waypoint, or too many"),
            E::Order => write!(f, "path: ticks not increasing"),
            E::Position => write!(f, "path: position out of range"),
        }
    }
}

impl Format for crate::demo::DemoError {
    fn format(&self, f: Formatter) {
        use crate::demo::DemoError as E;
        match self {
            E::Topology(e) => write!(f, "{}", e),
            E::Solver(e) => write!(f, "{}", e),
            E::Table(e) => write!(f, "{}", e),
            E::Path(e) => write!(f, "{}", e),
        }
    }
}
