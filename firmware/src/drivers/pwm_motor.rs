//! `PwmMotor`: force out through one `SetDutyCycle` PWM channel and a direction
//! `OutputPin` (embedded-hal 1.0), for a 1-DOF device driven by a DC motor through a
//! capstan.
//!
//! Motor constant: the force at the probe at 100 % duty is
//! `F_full = k_t · I_max · i / (r / 1000)` N, with `k_t` the torque constant (N·m/A),
//! `I_max` the driver's current at full duty (A), `i` the capstan ratio and `r` the lever
//! radius (mm). Duty = `|F| / F_full`, saturating at 100 %; the direction pin is high for a
//! force along `+z` (pushing the probe up, out of the tissue) and is written only when the
//! direction changes.

use embedded_hal::digital::OutputPin;
use embedded_hal::pwm::SetDutyCycle;
use mccs::Force;

/// The motor and its drive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotorConfig {
    /// Force at the probe at 100 % duty, N (> 0).
    pub force_at_full_duty: f64,
}

/// Why the motor could not be driven.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotorError<P, D> {
    /// The PWM channel failed.
    Pwm(P),
    /// The direction pin failed.
    Direction(D),
}

/// The motor driver.
#[derive(Debug)]
pub struct PwmMotor<PWM, DIR> {
    pwm: PWM,
    dir: DIR,
    /// Duty counts per N, Q16.
    duty_per_newton: u64,
    max_duty: u16,
    up: Option<bool>,
}

impl<PWM: SetDutyCycle, DIR: OutputPin> PwmMotor<PWM, DIR> {
    /// A driver; reads the PWM's full-scale duty once.
    pub fn new(pwm: PWM, dir: DIR, config: MotorConfig) -> Self {
        let max_duty = pwm.max_duty_cycle();
        let full = if config.force_at_full_duty > 0.0 {
            config.force_at_full_duty
        } else {
            f64::INFINITY
        };
        let per_newton = max_duty as f64 / full * 65536.0;
        Self {
            pwm,
            dir,
            duty_per_newton: if per_newton.is_finite() {
                per_newton as u64
            } else {
                0
            },
            max_duty,
            up: None,
        }
    }

    /// The duty (counts) for a force magnitude, saturating at full scale.
    pub fn duty_for(&self, force: Force) -> u16 {
        let magnitude = force.to_bits().unsigned_abs() as u64; // Q20 N
        let duty = (magnitude * self.duty_per_newton) >> 36; // Q20 · Q16 → counts
        duty.min(self.max_duty as u64) as u16
    }

    /// Renders a force along the device's axis.
    pub fn write(&mut self, force: Force) -> Result<(), MotorError<PWM::Error, DIR::Error>> {
        let up = force > Force::ZERO;
        if self.up != Some(up) {
            let r = if up {
                self.dir.set_high()
            } else {
                self.dir.set_low()
            };
            r.map_err(MotorError::Direction)?;
            self.up = Some(up);
        }
        self.pwm
            .set_duty_cycle(self.duty_for(force))
            .map_err(MotorError::Pwm)
    }

    /// Gives the PWM channel and the pin back.
    pub fn release(self) -> (PWM, DIR) {
        (self.pwm, self.dir)
    }
}
