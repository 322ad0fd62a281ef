//! `PwmMotor`: force out through one `SetDutyCycle` PWM channel, a direction `OutputPin`
//! and an optional driver-enable `OutputPin` (embedded-hal 1.0), for a 1-DOF device
//! driven by a DC motor through a capstan.
//!
//! Motor constant: the force at the probe at 100 % duty is
//! `F_full = k_t · I_max · i / (r / 1000)` N, with `k_t` the torque constant (N·m/A),
//! `I_max` the driver's current at full duty (A), `i` the capstan ratio and `r` the lever
//! radius (mm). Duty = `|F| / F_full`, saturating at 100 %; the direction pin is high for a
//! force along `+z` (pushing the probe up, out of the tissue).
//!
//! # Faults end at the actuator
//! - The duty goes to zero *before* the direction pin changes, so that a failed pin
//!   write leaves the motor idle, never pushing the wrong way at the old duty.
//! - A failed duty write is followed by an attempt to write zero duty.
//! - [`PwmMotor::safe`] writes zero duty first, then drops the enable pin, each attempted
//!   whatever the other did; the controller calls it on a fault and on every tick after.

use embedded_hal::digital::{ErrorType, OutputPin};
use embedded_hal::pwm::SetDutyCycle;
use mccs::Force;

/// The motor and its drive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotorConfig {
    /// Force at the probe at 100 % duty, N: 0.001 … 1024.
    pub force_at_full_duty: f64,
}

impl MotorConfig {
    /// Checks a force at full duty: a finite number of 0.001 … 1024 N.
    pub fn check(force_at_full_duty: f64) -> Result<(), MotorConfigError> {
        let f = force_at_full_duty;
        if f.is_finite() && (0.001..=1024.0).contains(&f) {
            Ok(())
        } else {
            Err(MotorConfigError::ForceAtFullDuty)
        }
    }
}

/// The motor configuration cannot be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotorConfigError {
    /// `force_at_full_duty` is not a finite number in 0.001 … 1024 N.
    ForceAtFullDuty,
}

impl core::fmt::Display for MotorConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("force_at_full_duty: must be a finite number of 0.001 … 1024 N")
    }
}

/// Why the motor could not be driven.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotorError<P, D, E = core::convert::Infallible> {
    /// The PWM channel failed.
    Pwm(P),
    /// The direction pin failed.
    Direction(D),
    /// The enable pin failed.
    Enable(E),
}

/// The error of a [`PwmMotor`] on these peripherals.
pub type ErrorOf<PWM, DIR, EN> = MotorError<
    <PWM as embedded_hal::pwm::ErrorType>::Error,
    <DIR as ErrorType>::Error,
    <EN as ErrorType>::Error,
>;

/// A driver without an enable pin: [`PwmMotor::new`]'s default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NoEnable;

impl ErrorType for NoEnable {
    type Error = core::convert::Infallible;
}

impl OutputPin for NoEnable {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// The motor driver.
#[derive(Debug)]
pub struct PwmMotor<PWM, DIR, EN = NoEnable> {
    pwm: PWM,
    dir: DIR,
    enable: EN,
    /// `F_full` in Q20 N.
    full: u32,
    /// `full << pre` is in [2³¹, 2³²): below full scale the duty is
    /// `⌊(|F| << pre) · scale / 2⁴⁷⌋`, `scale = max_duty · 2⁴⁷ / (full << pre)` (< 2³²).
    pre: u32,
    scale: u32,
    max_duty: u16,
    /// The direction pin's state when known.
    up: Option<bool>,
}

impl<PWM: SetDutyCycle, DIR: OutputPin> PwmMotor<PWM, DIR, NoEnable> {
    /// A driver without an enable pin; reads the PWM's full-scale duty once.
    pub fn new(pwm: PWM, dir: DIR, config: MotorConfig) -> Result<Self, MotorConfigError> {
        Self::with_enable(pwm, dir, NoEnable, config)
    }
}

impl<PWM: SetDutyCycle, DIR: OutputPin, EN: OutputPin> PwmMotor<PWM, DIR, EN> {
    /// A driver with a driver-enable pin (high: enabled), which [`PwmMotor::safe`]
    /// drops. The pin is not driven here: enable it with [`PwmMotor::enable`] once the
    /// duty is zero.
    pub fn with_enable(
        pwm: PWM,
        dir: DIR,
        enable: EN,
        config: MotorConfig,
    ) -> Result<Self, MotorConfigError> {
        let f = config.force_at_full_duty;
        MotorConfig::check(f)?;
        let full = libm::round(f * (1u64 << 20) as f64) as u64;
        let full = full.clamp(1, u32::MAX as u64) as u32;
        let pre = full.leading_zeros();
        let max_duty = pwm.max_duty_cycle();
        // max_duty · 2⁴⁷ / (full << pre) ≤ max_duty · 2¹⁶ < 2³².
        let scale = ((max_duty as u64) << 47) / ((full as u64) << pre);
        Ok(Self {
            pwm,
            dir,
            enable,
            full,
            pre,
            scale: scale as u32,
            max_duty,
            up: None,
        })
    }

    /// The duty (counts) for a force magnitude: proportional (rounded down) below
    /// `F_full`, full scale from it on. No overflow for any force; no division.
    pub fn duty_for(&self, force: Force) -> u16 {
        let magnitude = force.to_bits().unsigned_abs();
        if magnitude >= self.full {
            return self.max_duty;
        }
        let duty = mccs::q::mulhi_u(magnitude << self.pre, self.scale) >> 15;
        duty.min(self.max_duty as u32) as u16
    }

    /// The force a signed duty of `duty_q16` renders (65,536: 100 %, clamped to ±100 %):
    /// what [`PwmMotor::write`] takes to drive that duty (the lever's direction check).
    pub fn force_at(&self, duty_q16: i32) -> Force {
        let d = duty_q16.clamp(-65_536, 65_536) as i64;
        Force::from_bits(((self.full as i64 * d) >> 16) as i32)
    }

    /// Renders a force along the device's axis. A direction change goes through zero
    /// duty; on a failed write the duty is set to zero if it can be.
    pub fn write(&mut self, force: Force) -> Result<(), ErrorOf<PWM, DIR, EN>> {
        let duty = self.duty_for(force);
        let up = force > Force::ZERO;
        if duty > 0 && self.up != Some(up) {
            // Zero first: a failed pin write must leave the motor idle.
            self.pwm.set_duty_cycle(0).map_err(MotorError::Pwm)?;
            self.up = None;
            let r = if up {
                self.dir.set_high()
            } else {
                self.dir.set_low()
            };
            r.map_err(MotorError::Direction)?;
            self.up = Some(up);
        }
        self.pwm.set_duty_cycle(duty).map_err(|e| {
            let _ = self.pwm.set_duty_cycle(0);
            MotorError::Pwm(e)
        })
    }

    /// The safe state: zero duty first, then the driver disabled; each attempted
    /// whatever the other did. Returns the first error.
    pub fn safe(&mut self) -> Result<(), ErrorOf<PWM, DIR, EN>> {
        let duty = self.pwm.set_duty_cycle(0).map_err(MotorError::Pwm);
        let enable = self.enable.set_low().map_err(MotorError::Enable);
        duty.and(enable)
    }

    /// Enables the driver (enable pin high).
    pub fn enable(&mut self) -> Result<(), ErrorOf<PWM, DIR, EN>> {
        self.enable.set_high().map_err(MotorError::Enable)
    }

    /// Gives the PWM channel and the pins back.
    pub fn release(self) -> (PWM, DIR, EN) {
        (self.pwm, self.dir, self.enable)
    }
}
