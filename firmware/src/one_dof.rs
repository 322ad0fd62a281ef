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
//!
//! With [`OneDofDevice::with_direction_check`], the lever is nudged up and back down
//! before any tissue force ([`DirectionCheck`]): a motor or encoder wired the wrong way
//! round (the tissue would pull the lever in) is [`OneDofError::Reversed`], a lever
//! that does not move is [`OneDofError::Unmoved`], the motor in its safe state first.
//! Until the check passes the device reports itself not homed, so that the link's ramp
//! starts from zero once it has (and once the probe is out of contact).

use crate::device::{DeviceStatus, HapticDevice};
pub use crate::direction::DirectionCheck;
use crate::direction::{Nudge, NudgeFault, Nudges};
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
    /// The lever moved against its start-up nudge ([`OneDofDevice::with_direction_check`]):
    /// its motor or its encoder is wired the wrong way round.
    Reversed,
    /// The lever did not move when nudged: held, jammed, or its motor not connected.
    Unmoved,
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
    /// The direction check (none by default), where it is, and the duty it asks of the
    /// next write (`None` once it has passed: the tissue's force).
    direction: Option<DirectionCheck<1>>,
    nudges: Nudges,
    nudge_duty: Option<i32>,
}

/// The lever's position in the direction check's counts: 2⁻¹⁰ mm (about 1 µm).
pub const DIRECTION_COUNT_MM: f64 = 1.0 / 1024.0;

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
            direction: None,
            nudges: Nudges::default(),
            nudge_duty: None,
        }
    }

    /// The device nudging the lever up and back down before any tissue force (`check`'s
    /// counts in [`DIRECTION_COUNT_MM`]): moving against a nudge fails the read with
    /// [`OneDofError::Reversed`], not moving with [`OneDofError::Unmoved`] (the motor
    /// safe first). Until it passes, the device is not homed ([`HapticDevice::status`]).
    pub fn with_direction_check(mut self, check: DirectionCheck<1>) -> Self {
        self.direction = Some(check);
        self.nudge_duty = Some(0);
        self
    }

    /// Whether the lever moved the way it was nudged (true without a check).
    pub fn direction_checked(&self) -> bool {
        self.nudge_duty.is_none()
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
        if let (Some(check), Some(_)) = (self.direction, self.nudge_duty) {
            match self.nudges.step(&check, [z.to_bits() >> 14]) {
                Nudge::Drive([duty]) => self.nudge_duty = Some(duty),
                Nudge::Passed => self.nudge_duty = None,
                Nudge::Failed(fault) => {
                    self.nudge_duty = Some(0);
                    let _ = self.motor.safe();
                    return Err(match fault {
                        NudgeFault::Reversed(_) => OneDofError::Reversed,
                        NudgeFault::Unmoved(_) => OneDofError::Unmoved,
                    });
                }
            }
        }
        Ok(probe)
    }

    fn write_force(&mut self, force: [Force; 3]) -> Result<(), Self::Error> {
        if let Some(duty) = self.nudge_duty {
            // The check's nudge, not the tissue's force (and not the observer's work).
            let nudge = self.motor.force_at(duty);
            return self.motor.write(nudge).map_err(OneDofError::Motor);
        }
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

    fn status(&self) -> DeviceStatus {
        DeviceStatus {
            homed: self.direction_checked(),
            ..DeviceStatus::default()
        }
    }
}
