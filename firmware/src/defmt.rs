//! Every `defmt::Format` impl of the device layer, in one place (feature `defmt`).

use crate::arm::sim::SimArmError;
use crate::demo::DemoError;
use crate::{Fault, PathError};
use defmt::{write, Format, Formatter};

impl Format for Fault {
    fn format(&self, f: Formatter) {
        write!(f, "{=str}", self.message())
    }
}

impl Format for PathError {
    fn format(&self, f: Formatter) {
        write!(f, "{=str}", self.message())
    }
}

impl Format for SimArmError {
    fn format(&self, f: Formatter) {
        match self {
            Self::Unreachable(t) => write!(f, "{=str} (tick {=u32})", self.message(), t),
            _ => write!(f, "{=str}", self.message()),
        }
    }
}

impl Format for DemoError {
    fn format(&self, f: Formatter) {
        match self {
            Self::Topology(e) => write!(f, "{}", e),
            Self::Solver(e) => write!(f, "{}", e),
            Self::Path(e) => write!(f, "{}", e),
            Self::Contact(e) => write!(f, "{}", e),
            Self::Arm(e) => write!(f, "{}", e),
        }
    }
}
