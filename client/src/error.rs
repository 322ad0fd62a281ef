//! [`Error`]: everything that can go wrong talking to a device, typed; a device's
//! refusal carries its reason and values ([`Refusal`]).

use crate::shown::ShownName;
use mccs_link::{scale, NakReason, SpecOption};
use std::fmt;
use std::time::Duration;

/// A device's refusal: its reason, with the values it sent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Refusal(pub NakReason);

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let r = self.0;
        f.write_str(r.message())?;
        match r {
            NakReason::Budget {
                substeps,
                instructions,
                budget,
            } => write!(
                f,
                ": it needs {substeps} substeps a tick, {instructions} instructions against a budget of {budget}"
            ),
            NakReason::Stability { substeps } => write!(f, ": {substeps} substeps proposed"),
            NakReason::Pose { axis, limit } => write!(
                f,
                ": {} passes {} mm",
                ["x", "y", "z"].get(axis as usize).copied().unwrap_or("?"),
                scale::mm(limit)
            ),
            NakReason::Option { option, limit } => match option {
                SpecOption::Grid => write!(f, ": {} holds at most {limit} nodes a side", option.flag()),
                SpecOption::Arith => write!(f, ": the device runs one arithmetic ({})", if limit != 0 { "narrow" } else { "wide" }),
                SpecOption::CapRadius => write!(f, ": the device roams flat tissues only"),
                SpecOption::Tissue => write!(f, ": {} holds at most {limit} nodes a side", option.flag()),
                SpecOption::Config => write!(f, ": its solver refused this configuration ({})", option.flag()),
                _ => write!(f, ": {} beyond the device's limit ({limit})", option.flag()),
            },
            _ => Ok(()),
        }
    }
}

/// What went wrong.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The address is not one.
    #[error("{}: {why}", ShownName(.addr))]
    Address {
        /// As given.
        addr: String,
        /// Why not.
        why: &'static str,
    },
    /// The device could not be reached.
    #[error("{}: {source}", ShownName(.addr))]
    Connect {
        /// Where.
        addr: String,
        /// The OS's reason.
        source: std::io::Error,
    },
    /// The device never answered `Hello`.
    #[error("{}: no answer to hello in {} s", ShownName(.addr), .waited.as_secs())]
    NoAnswer {
        /// Where.
        addr: String,
        /// How long it was asked.
        waited: Duration,
    },
    /// The device speaks another protocol or schema.
    #[error(
        "{}: the device speaks protocol {device_protocol} schema {device_schema:08x}, this client protocol {protocol} schema {schema:08x}: update one of them",
        ShownName(.addr)
    )]
    Protocol {
        /// Where.
        addr: String,
        /// The device's.
        device_protocol: u16,
        /// The device's.
        device_schema: u32,
        /// This client's.
        protocol: u16,
        /// This client's.
        schema: u32,
    },
    /// The device refused, with its reason and values.
    #[error("{}: the device refused: {refusal}", ShownName(.addr))]
    Refused {
        /// Where.
        addr: String,
        /// Why.
        refusal: Refusal,
    },
    /// No answer within the wait's timeout.
    #[error("{}: no answer to {what} in {} ms", ShownName(.addr), .waited.as_millis())]
    Timeout {
        /// Where.
        addr: String,
        /// What was asked.
        what: &'static str,
        /// How long it waited.
        waited: Duration,
    },
    /// The connection was lost (the device fades its force by its own guard).
    #[error("{}: the connection was lost: {why}", ShownName(.addr))]
    Lost {
        /// Where.
        addr: String,
        /// What the transport said.
        why: String,
    },
    /// A tissue could not be made.
    #[error(transparent)]
    Tissue(#[from] crate::tissue::TissueError),
    /// An argument out of range.
    #[error("{what}: {why}")]
    Argument {
        /// Which.
        what: &'static str,
        /// Why.
        why: String,
    },
    /// The device answered something this client cannot use.
    #[error("{}: {what}", ShownName(.addr))]
    Unexpected {
        /// Where.
        addr: String,
        /// What.
        what: String,
    },
}

impl Error {
    /// The device's refusal, if this is one.
    pub fn refusal(&self) -> Option<NakReason> {
        match self {
            Error::Refused { refusal, .. } => Some(refusal.0),
            _ => None,
        }
    }
}
