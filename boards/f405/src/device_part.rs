//! [`DevicePart`]: each part of the board's devices (the lever's and the arm's) that can
//! fail, by its name in the log and its code in the black box.

/// A part of the board's device.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DevicePart {
    /// The encoder's SPI bus.
    Spi,
    /// The encoder's frames (too many bad ones in a row).
    Encoder,
    /// The lever beyond its travel (`BoardConfig::travel_mm`).
    Travel,
    /// The motor's PWM channel.
    Pwm,
    /// The motor's direction pin.
    Direction,
    /// The motor driver's enable pin.
    Enable,
    /// The arm's joint `0..3` (A, B, C): its quadrature counter.
    JointEncoder(u8),
    /// Its PWM channel.
    JointPwm(u8),
    /// Its direction pin.
    JointDirection(u8),
    /// The arm's home input.
    Home,
    /// The arm's joint `0..3` turned faster than its limit (a runaway).
    JointSpeed(u8),
    /// The arm's probe moved faster than its limit (a runaway).
    ProbeSpeed,
    /// The arm's joint `0..3` turned against its start-up nudge.
    JointReversed(u8),
    /// The arm's joint `0..3` did not move when nudged at start-up.
    JointUnmoved(u8),
    /// The force (the lever's or the arm's) put out energy beyond the passivity
    /// observer's trip.
    EnergyOut,
    /// The lever moved against its start-up nudge.
    LeverReversed,
    /// The lever did not move when nudged at start-up.
    LeverUnmoved,
}

impl DevicePart {
    /// Every part, by its code less one ([`DevicePart::code`]).
    pub const ALL: [DevicePart; 29] = {
        use DevicePart::*;
        [
            Spi,
            Encoder,
            Travel,
            Pwm,
            Direction,
            Enable,
            JointEncoder(0),
            JointEncoder(1),
            JointEncoder(2),
            JointPwm(0),
            JointPwm(1),
            JointPwm(2),
            JointDirection(0),
            JointDirection(1),
            JointDirection(2),
            Home,
            JointSpeed(0),
            JointSpeed(1),
            JointSpeed(2),
            ProbeSpeed,
            EnergyOut,
            JointReversed(0),
            JointReversed(1),
            JointReversed(2),
            JointUnmoved(0),
            JointUnmoved(1),
            JointUnmoved(2),
            LeverReversed,
            LeverUnmoved,
        ]
    };

    /// Its code in the black box (1 … 29, its place in [`DevicePart::ALL`]; 0 is no
    /// part). A joint past C is C, as its name is.
    pub const fn code(self) -> u8 {
        const fn j(k: u8) -> u8 {
            if k > 2 {
                2
            } else {
                k
            }
        }
        match self {
            Self::Spi => 1,
            Self::Encoder => 2,
            Self::Travel => 3,
            Self::Pwm => 4,
            Self::Direction => 5,
            Self::Enable => 6,
            Self::JointEncoder(k) => 7 + j(k),
            Self::JointPwm(k) => 10 + j(k),
            Self::JointDirection(k) => 13 + j(k),
            Self::Home => 16,
            Self::JointSpeed(k) => 17 + j(k),
            Self::ProbeSpeed => 20,
            Self::EnergyOut => 21,
            Self::JointReversed(k) => 22 + j(k),
            Self::JointUnmoved(k) => 25 + j(k),
            Self::LeverReversed => 28,
            Self::LeverUnmoved => 29,
        }
    }

    /// The part of black-box code `code` (0 or unknown: none).
    pub fn from_code(code: u8) -> Option<DevicePart> {
        Self::ALL.get((code as usize).checked_sub(1)?).copied()
    }

    /// Its name in the log.
    pub const fn name(&self) -> &'static str {
        match self {
            Self::Spi => "the encoder's SPI bus",
            Self::Encoder => "the encoder's frames",
            Self::Travel => "the lever beyond its travel",
            Self::Pwm => "the motor's PWM channel",
            Self::Direction => "the motor's direction pin",
            Self::Enable => "the motor driver's enable pin",
            Self::JointEncoder(k) => pick(
                *k,
                [
                    "joint A's counter",
                    "joint B's counter",
                    "joint C's counter",
                ],
            ),
            Self::JointPwm(k) => pick(
                *k,
                [
                    "joint A's PWM channel",
                    "joint B's PWM channel",
                    "joint C's PWM channel",
                ],
            ),
            Self::JointDirection(k) => pick(
                *k,
                [
                    "joint A's direction pin",
                    "joint B's direction pin",
                    "joint C's direction pin",
                ],
            ),
            Self::Home => "the arm's home input",
            Self::JointSpeed(k) => pick(
                *k,
                [
                    "joint A running away",
                    "joint B running away",
                    "joint C running away",
                ],
            ),
            Self::ProbeSpeed => "the probe running away",
            Self::JointReversed(k) => pick(
                *k,
                [
                    "joint A turning against its drive (motor or encoder reversed)",
                    "joint B turning against its drive (motor or encoder reversed)",
                    "joint C turning against its drive (motor or encoder reversed)",
                ],
            ),
            Self::JointUnmoved(k) => pick(
                *k,
                [
                    "joint A not moving when nudged (let go of the handle; reset)",
                    "joint B not moving when nudged (let go of the handle; reset)",
                    "joint C not moving when nudged (let go of the handle; reset)",
                ],
            ),
            Self::EnergyOut => "the force putting energy into the hand (passivity)",
            Self::LeverReversed => "the lever moving against its drive (motor or encoder reversed)",
            Self::LeverUnmoved => "the lever not moving when nudged (let go of it; reset)",
        }
    }
}

/// Joint `k`'s name of three (C past the end).
pub(crate) const fn pick(k: u8, names: [&'static str; 3]) -> &'static str {
    match k {
        0 => names[0],
        1 => names[1],
        _ => names[2],
    }
}
