//! [`NakReason`]: why the device refused what a host sent, with the values that make the
//! reason actionable.

use postcard_schema::Schema;
use serde::{Deserialize, Serialize};

/// Why the device refused.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq)]
pub enum NakReason {
    /// (0) A replay, a load or a tissue check is under way.
    Busy,
    /// (1) A chunk out of order, or a commit without a begin.
    Order,
    /// (2) The bytes received are not the length announced, or not a table's.
    Length,
    /// (3) The bytes' hash is not the one announced.
    Hash,
    /// (4) The table has another knot count than the device's.
    Segments,
    /// (5) The table's own check refused it (`ForceTable::validate`).
    Table,
    /// (6) Its recorded error is over the product's bound, or unmeasured.
    Bound,
    /// (7) The solver refused it on the device's patch (its substeps or coefficients).
    Solver,
    /// (8) A replay without a tissue.
    NoTissue,
    /// (9) A replay asks for more than the device holds: the option, and its limit.
    Option {
        /// The option at fault.
        option: SpecOption,
        /// The device's limit for it.
        limit: i32,
    },
    /// (10) The tissue's tick would pass the device's budget: `substeps` substeps cost
    /// `instructions` against `budget` (instructions a tick).
    Budget {
        /// Substeps the tissue needs.
        substeps: u16,
        /// Instructions its tick would take.
        instructions: u32,
        /// The device's budget.
        budget: u32,
    },
    /// (11) The host's substeps are not stable on the device's patch with the margin the
    /// device keeps (its own check of them failed).
    Stability {
        /// The substeps the host proposed.
        substeps: u16,
    },
    /// (12) Friction coefficients above 2, or `mu_k > mu_s`.
    Friction,
    /// (13) A pose whose origin is outside the workspace: the axis (0 = x) and the limit
    /// it passed (Q24 mm).
    Pose {
        /// 0, 1, 2: x, y, z.
        axis: u8,
        /// The workspace's bound on that axis, Q24 mm.
        limit: i32,
    },
    /// (14) A pose whose rotation is not a unit quaternion (within 2⁻¹⁰).
    Rotation,
}

impl NakReason {
    /// In words, for a host's one line (the values are the caller's to add).
    pub const fn message(self) -> &'static str {
        match self {
            Self::Busy => "the device is busy with a replay, a load or a tissue check",
            Self::Order => "a piece out of order, or a commit without a begin",
            Self::Length => "the bytes received are not the length announced",
            Self::Hash => "the bytes' hash is not the one announced",
            Self::Segments => "the table's knot count is not the device's",
            Self::Table => "the table failed its own check (ForceTable::validate)",
            Self::Bound => "the table's recorded error is over the product's bound, or unmeasured",
            Self::Solver => "the device's solver refused the tissue on its patch",
            Self::NoTissue => "no tissue",
            Self::Option { .. } => "the device does not hold that option's value",
            Self::Budget { .. } => "the tissue's tick would pass the device's instruction budget",
            Self::Stability { .. } => {
                "the proposed substeps are not stable on the device's patch with its margin"
            }
            Self::Friction => "friction coefficients must be within 0 … 2 with mu_k ≤ mu_s",
            Self::Pose { .. } => "the pose's origin is outside the device's workspace",
            Self::Rotation => "the pose's rotation is not a unit quaternion",
        }
    }
}

/// An option of a replay the device may not hold.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpecOption {
    /// `--grid`.
    Grid,
    /// `--spacing`.
    Spacing,
    /// `--rate`.
    Rate,
    /// `--node-mass`.
    NodeMass,
    /// `--arith`.
    Arith,
    /// `--tissue`.
    Tissue,
    /// `--cap-radius`.
    CapRadius,
    /// The path's length.
    Samples,
    /// The solver's configuration as a whole (its substeps).
    Config,
}

impl SpecOption {
    /// The host's option it stands for.
    pub const fn flag(self) -> &'static str {
        match self {
            Self::Grid => "--grid",
            Self::Spacing => "--spacing",
            Self::Rate => "--rate",
            Self::NodeMass => "--node-mass",
            Self::Arith => "--arith",
            Self::Tissue => "--tissue",
            Self::CapRadius => "--cap-radius",
            Self::Samples => "--probe",
            Self::Config => "--rate",
        }
    }
}
