//! `OneDofDevice`: a real 1-DOF haptic device — an [`As5047p`] encoder for the probe's
//! travel along `z` and a [`PwmMotor`] for the force along `z` — as a [`HapticDevice`].
//! The probe stays on the contact node's axis (`x = y = 0`); forces along `x`, `y` are
//! not rendered.
//!
//! After `max_bad_frames` bad encoder frames in a row, reads fail with
//! [`OneDofError::Encoder`], and the controller goes to its safe state.

use crate::device::HapticDevice;
use crate::drivers::as5047p::As5047p;
use crate::drivers::pwm_motor::{MotorError, PwmMotor};
use embedded_hal::digital::OutputPin;
use embedded_hal::pwm::SetDutyCycle;
use embedded_hal::spi::SpiDevice;
use mccs::{Force, Length};

/// Device errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OneDofError<S, P, D> {
    /// The SPI bus failed.
    Spi(S),
    /// Too many bad encoder frames in a row.
    Encoder,
    /// The motor drive failed.
    Motor(MotorError<P, D>),
}

/// Encoder, motor, and the travel offset of the probe's rest point above the surface.
#[derive(Debug)]
pub struct OneDofDevice<SPI, PWM, DIR> {
    /// The encoder.
    pub encoder: As5047p<SPI>,
    /// The motor.
    pub motor: PwmMotor<PWM, DIR>,
    /// Bad frames in a row tolerated before a read fails.
    pub max_bad_frames: u32,
}

impl<SPI, PWM, DIR> HapticDevice for OneDofDevice<SPI, PWM, DIR>
where
    SPI: SpiDevice<u8>,
    PWM: SetDutyCycle,
    DIR: OutputPin,
{
    type Error = OneDofError<SPI::Error, PWM::Error, DIR::Error>;

    fn read_position(&mut self) -> Result<[Length; 3], Self::Error> {
        let z = self.encoder.read().map_err(OneDofError::Spi)?;
        if self.encoder.errors().consecutive > self.max_bad_frames {
            return Err(OneDofError::Encoder);
        }
        Ok([Length::ZERO, Length::ZERO, z])
    }

    fn write_force(&mut self, force: [Force; 3]) -> Result<(), Self::Error> {
        self.motor.write(force[2]).map_err(OneDofError::Motor)
    }
}
