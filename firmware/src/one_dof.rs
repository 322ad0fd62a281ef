//! `OneDofDevice`: a real 1-DOF haptic device — an [`As5047p`] encoder for the probe's
//! travel along `z` and a [`PwmMotor`] for the force along `z` — as a [`HapticDevice`].
//! The probe stays on the contact node's axis (`x = y = 0`); forces along `x`, `y` are
//! not rendered.
//!
//! After `max_bad_frames` bad encoder frames in a row (parity, error flag, an implausible
//! jump, a failed diagnostic: see [`As5047p`]), reads fail with [`OneDofError::Encoder`],
//! and the controller goes to its safe state, which is [`PwmMotor::safe`].

use crate::device::HapticDevice;
use crate::drivers::as5047p::As5047p;
use crate::drivers::pwm_motor::{MotorError, NoEnable, PwmMotor};
use embedded_hal::digital::OutputPin;
use embedded_hal::pwm::SetDutyCycle;
use embedded_hal::spi::SpiDevice;
use mccs::{Force, Length};

/// Device errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OneDofError<S, P, D, E = core::convert::Infallible> {
    /// The SPI bus failed.
    Spi(S),
    /// Too many bad encoder frames in a row.
    Encoder,
    /// The lever left its travel (`EncoderConfig::max_travel_counts`).
    Travel,
    /// The motor drive failed.
    Motor(MotorError<P, D, E>),
}

/// Encoder and motor.
#[derive(Debug)]
pub struct OneDofDevice<SPI, PWM, DIR, EN = NoEnable> {
    /// The encoder.
    pub encoder: As5047p<SPI>,
    /// The motor.
    pub motor: PwmMotor<PWM, DIR, EN>,
    /// Bad frames in a row tolerated before a read fails.
    pub max_bad_frames: u32,
}

impl<SPI, PWM, DIR, EN> HapticDevice for OneDofDevice<SPI, PWM, DIR, EN>
where
    SPI: SpiDevice<u8>,
    PWM: SetDutyCycle,
    DIR: OutputPin,
    EN: OutputPin,
{
    type Error = OneDofError<SPI::Error, PWM::Error, DIR::Error, EN::Error>;

    fn read_position(&mut self) -> Result<[Length; 3], Self::Error> {
        let z = self.encoder.read().map_err(OneDofError::Spi)?;
        if self.encoder.errors().consecutive > self.max_bad_frames {
            return Err(OneDofError::Encoder);
        }
        if self.encoder.out_of_travel() {
            return Err(OneDofError::Travel);
        }
        Ok([Length::ZERO, Length::ZERO, z])
    }

    fn write_force(&mut self, force: [Force; 3]) -> Result<(), Self::Error> {
        self.motor.write(force[2]).map_err(OneDofError::Motor)
    }

    fn safe_state(&mut self) -> Result<(), Self::Error> {
        self.motor.safe().map_err(OneDofError::Motor)
    }
}
