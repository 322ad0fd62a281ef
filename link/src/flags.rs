//! [`Flags`]: what a live tick says about itself, one bit each (`Telemetry::flags`), and
//! a replay row's ([`crate::replay`] uses the first two bits and its own third).

use postcard_schema::Schema;
use serde::{Deserialize, Serialize};

/// A live tick's flags. On the wire a `u16` (a postcard varint).
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Flags(pub u16);

impl Flags {
    /// The probe touches the tissue (the proxy is on its surface; glued: a force is
    /// rendered).
    pub const CONTACT: Flags = Flags(1 << 0);
    /// The proxy slides over the surface (kinetic friction).
    pub const SLIPPING: Flags = Flags(1 << 1);
    /// A host holds the device armed (fading included).
    pub const ARMED: Flags = Flags(1 << 2);
    /// The device is in its safe state (`Telemetry::fault` says why).
    pub const FAULT: Flags = Flags(1 << 3);
    /// The force was held to the device's clamp this tick.
    pub const CLAMPED: Flags = Flags(1 << 4);
    /// The arm has been homed (always set on a device without homing).
    pub const HOMED: Flags = Flags(1 << 5);
    /// A joint is at or past its limit (the arm).
    pub const AT_LIMIT: Flags = Flags(1 << 6);
    /// A tissue is being checked (the old one renders until the swap).
    pub const CHECKING: Flags = Flags(1 << 7);
    /// The link's gain is below full (fading after silence, or ramping up after `Arm`).
    pub const GAIN_LIMITED: Flags = Flags(1 << 8);
    /// A joint's current is folded back to its continuous current (the I²t model).
    pub const THERMAL: Flags = Flags(1 << 9);

    /// Every flag, with its name in the CLI's columns, in bit order.
    pub const ALL: [(Flags, &'static str); 10] = [
        (Self::CONTACT, "contact"),
        (Self::SLIPPING, "slipping"),
        (Self::ARMED, "armed"),
        (Self::FAULT, "fault"),
        (Self::CLAMPED, "clamped"),
        (Self::HOMED, "homed"),
        (Self::AT_LIMIT, "at_limit"),
        (Self::CHECKING, "checking"),
        (Self::GAIN_LIMITED, "gain_limited"),
        (Self::THERMAL, "thermal"),
    ];

    /// None set.
    pub const NONE: Flags = Flags(0);

    /// Whether every bit of `other` is set.
    pub const fn contains(self, other: Flags) -> bool {
        self.0 & other.0 == other.0
    }

    /// With `other`'s bits set where `on`.
    #[must_use]
    pub const fn with(self, other: Flags, on: bool) -> Flags {
        if on {
            Flags(self.0 | other.0)
        } else {
            Flags(self.0 & !other.0)
        }
    }
}

impl core::ops::BitOr for Flags {
    type Output = Flags;
    fn bitor(self, rhs: Flags) -> Flags {
        Flags(self.0 | rhs.0)
    }
}

impl core::ops::BitOrAssign for Flags {
    fn bitor_assign(&mut self, rhs: Flags) {
        self.0 |= rhs.0;
    }
}
