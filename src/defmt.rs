//! Every `defmt::Format` impl of the core, in one place (feature `defmt`). Each writes the
//! same text as the type's `Display`, from the same `message()`/`reason()` strings.

use crate::{ConfigKey, ParamError, ParamKey, ProxyError, SolverError, TableError, TopologyError};
use defmt::{write, Format, Formatter};

impl Format for ParamKey {
    fn format(&self, f: Formatter) {
        write!(f, "{=str}", self.as_str())
    }
}

impl Format for ParamError {
    fn format(&self, f: Formatter) {
        write!(f, "{=str}: {=str}", self.key().as_str(), self.reason())
    }
}

impl Format for TableError {
    fn format(&self, f: Formatter) {
        match self {
            Self::Param(e) => write!(f, "{}", e),
            other => write!(f, "{=str}", other.message()),
        }
    }
}

impl Format for ProxyError {
    fn format(&self, f: Formatter) {
        write!(f, "{=str}", self.message())
    }
}

impl Format for TopologyError {
    fn format(&self, f: Formatter) {
        write!(f, "{=str}", self.message())
    }
}

impl Format for ConfigKey {
    fn format(&self, f: Formatter) {
        write!(f, "{=str}", self.as_str())
    }
}

impl Format for SolverError {
    fn format(&self, f: Formatter) {
        match self {
            Self::Config(k) => write!(f, "{=str}: {=str}", k.as_str(), self.message()),
            Self::TooManySubsteps { needed } => write!(
                f,
                "max_substeps: stability needs {=u32} substeps per tick ({=str})",
                needed,
                self.message()
            ),
            Self::SpringTooLong { max_mm } => write!(
                f,
                "topology: a spring is longer than {=u32} mm ({=str})",
                max_mm,
                self.message()
            ),
            other => write!(f, "{=str}", other.message()),
        }
    }
}
