//! `OneDofDevice`: a real 1-DOF haptic device — an [`As5047p`] encoder for the probe's
//! travel along `z` and a [`PwmMotor`] for the force along `z` — as a [`HapticDevice`].
//! The probe stays on the contact node's axis (`x = y = 0`); forces along `x`, `y` are
//! not rendered.
//!
//! After `max_bad_frames` bad encoder frames in a row (parity, error flag, an implausible
//! jump, a failed diagnostic: see [`As5047p`]), reads fail with [`OneDofError::Encoder`],
//! and the controller goes to its safe state, which is [`PwmMotor::safe`].
//!
//! With [`OneDofDevice::with_passivity`], a passivity observer ([`mccs::PassivityObserver`],
//! as on the arm) watches the work the rendered force does on the lever: energy put out
//! beyond its limits is [`OneDofError::EnergyOut`], the motor in its safe state first. It
//! watches from the first tick the force is zero (a lever resting in the tissue at
//! start-up meets a force it did not earn).

use crate::device::HapticDevice;
use crate::drivers::as5047p::As5047p;
use crate::drivers::pwm_motor::{MotorError, NoEnable, PwmMotor};
use embedded_hal::digital::OutputPin;
use embedded_hal::pwm::SetDutyCycle;
use embedded_hal::spi::SpiDevice;
use mccs::{Force, Length, PassivityLimits, PassivityObserver};

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
    /// The force put energy into the hand beyond the passivity observer's limits
    /// ([`OneDofDevice::with_passivity`]): an unstable tissue, a reversed motor sign.
    EnergyOut,
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
    /// The passivity observer, if any ([`OneDofDevice::with_passivity`]).
    passivity: Option<Watch>,
    /// The probe last read.
    probe: Option<[Length; 3]>,
}

/// A passivity observer on the lever, its limits, and whether it watches yet.
#[derive(Clone, Copy, Debug)]
struct Watch {
    observer: PassivityObserver,
    limits: PassivityLimits,
    watching: bool,
}

impl<SPI, PWM, DIR, EN> OneDofDevice<SPI, PWM, DIR, EN> {
    /// The device on its encoder and motor, a read failing after `max_bad_frames` bad
    /// frames in a row; no passivity observer.
    pub fn new(encoder: As5047p<SPI>, motor: PwmMotor<PWM, DIR, EN>, max_bad_frames: u32) -> Self {
        Self {
            encoder,
            motor,
            max_bad_frames,
            passivity: None,
            probe: None,
        }
    }

    /// With a passivity observer on the force along the lever: energy put out beyond
    /// `limits` fails the write with [`OneDofError::EnergyOut`], the motor safe first.
    pub fn with_passivity(mut self, limits: PassivityLimits) -> Self {
        self.passivity = Some(Watch {
            observer: PassivityObserver::default(),
            limits,
            watching: false,
        });
        self
    }

    /// The observer's energy, mJ (`None`: no observer).
    pub fn passivity_mj(&self) -> Option<f64> {
        self.passivity.map(|w| w.observer.energy_mj())
    }
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
        let probe = [Length::ZERO, Length::ZERO, z];
        self.probe = Some(probe);
        Ok(probe)
    }

    fn write_force(&mut self, force: [Force; 3]) -> Result<(), Self::Error> {
        if let (Some(w), Some(probe)) = (self.passivity.as_mut(), self.probe) {
            // Only the force along the lever is rendered, and only it does work.
            let rendered = [Force::ZERO, Force::ZERO, force[2]];
            if !w.watching && force[2] == Force::ZERO {
                w.observer.reset();
                w.watching = true;
            }
            if w.watching && w.observer.tick(probe, rendered, w.limits) {
                let _ = self.motor.safe();
                return Err(OneDofError::EnergyOut);
            }
        }
        self.motor.write(force[2]).map_err(OneDofError::Motor)
    }

    fn safe_state(&mut self) -> Result<(), Self::Error> {
        self.motor.safe().map_err(OneDofError::Motor)
    }
}
