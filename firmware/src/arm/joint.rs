//! [`Joint`]: what one joint of the arm does for [`super::device::ArmDevice`] — its
//! counter, its PWM channel and its direction pin behind one interface
//! ([`JointParts`] on embedded-hal parts), and a signed duty written through them.

use crate::arm::encoder::JointEncoder;
use embedded_hal::digital::OutputPin;
use embedded_hal::pwm::SetDutyCycle;

/// One joint's parts.
#[derive(Debug)]
pub struct JointParts<E, P, D> {
    /// Its counter.
    pub encoder: E,
    /// Its motor's PWM channel.
    pub pwm: P,
    /// Its motor's direction pin (high: the joint's angle grows).
    pub direction: D,
}

/// A joint's part that failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PartFailed;

/// What a joint does for the device (its parts behind one interface, so that three
/// joints of different timer and pin types make one device without an indirect call).
pub trait Joint {
    /// The counter now.
    fn read(&mut self) -> Result<u16, PartFailed>;
    /// A duty (counts, ≤ the channel's full scale).
    fn duty(&mut self, duty: u16) -> Result<(), PartFailed>;
    /// The direction pin.
    fn direction(&mut self, forward: bool) -> Result<(), PartFailed>;
    /// The channel's full scale.
    fn max_duty(&self) -> u16;

    /// Writes a signed duty (Q16, ±65,536: ±100 %), a direction change through zero
    /// duty (a failed pin write leaves the joint idle, never pushing the wrong way);
    /// `forward_was` is the direction last written (None: unknown).
    fn write(&mut self, forward_was: &mut Option<bool>, duty_q16: i32) -> Result<(), WriteFailed> {
        let forward = duty_q16 > 0;
        let max = self.max_duty() as i64;
        let counts = ((duty_q16.unsigned_abs() as i64 * max) >> 16).min(max) as u16;
        if counts > 0 && *forward_was != Some(forward) {
            self.duty(0).map_err(|_| WriteFailed::Pwm)?;
            *forward_was = None;
            self.direction(forward)
                .map_err(|_| WriteFailed::Direction)?;
            *forward_was = Some(forward);
        }
        self.duty(counts).map_err(|_| WriteFailed::Pwm)
    }
}

impl<E: JointEncoder, P: SetDutyCycle, D: OutputPin> Joint for JointParts<E, P, D> {
    fn read(&mut self) -> Result<u16, PartFailed> {
        self.encoder.read().map_err(|_| PartFailed)
    }
    fn duty(&mut self, duty: u16) -> Result<(), PartFailed> {
        self.pwm.set_duty_cycle(duty).map_err(|_| PartFailed)
    }
    fn direction(&mut self, forward: bool) -> Result<(), PartFailed> {
        if forward {
            self.direction.set_high()
        } else {
            self.direction.set_low()
        }
        .map_err(|_| PartFailed)
    }
    fn max_duty(&self) -> u16 {
        self.pwm.max_duty_cycle()
    }
}

/// Which part a [`Joint::write`] failed at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WriteFailed {
    /// Its PWM channel.
    Pwm,
    /// Its direction pin.
    Direction,
}
