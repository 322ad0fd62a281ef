//! [`Lever`]: a simulated 1-DOF lever behind the board's own encoder bus and motor pins
//! (`haptic-f405 --features sim`), so that the 1-DOF board's main, tick, link and device
//! run unchanged in QEMU, whose SPI has no encoder behind it.
//!
//! The lever presses the tissue over and over on its own clock ([`press_path`]): from
//! 1 mm above the surface to 1.2 mm into it, a hold, and back. Its AS5047P answers each
//! frame as the sensor does — the answer to the previous frame's command, with even
//! parity: the angle for ANGLECOM (the lever's travel over `mm_per_count` from `zero`),
//! a running sensor for DIAAGC (`LF` = 1), an empty ERRFL — so the driver's every check
//! runs on it. The motor's duty, direction and enable are recorded. The loop is open:
//! the lever follows its path whatever force it is driven with, but for its first
//! [`NUDGE_FRAMES`]: it rests at the path's start, and the board's start-up nudges move
//! it a count a frame the way they drive it (a duty over 1 %), as a lever wired right
//! moves.

use crate::drivers::as5047p::{ANGLECOM, DIAAGC, DIAAGC_LF};
use crate::probe_path::{PathError, ProbePath, Waypoint};
use crate::Shared;
use embedded_hal::spi::{Operation, SpiDevice};

/// The lever's press: 1 mm above the surface, 1.2 mm into it, held, back up; 2.5 s at
/// `tick_hz`, ending where it starts.
pub fn press_path(tick_hz: u32) -> Result<ProbePath<5>, PathError> {
    let at = |s: f64, z: f64| Waypoint {
        tick: (s * tick_hz as f64) as u32,
        position: [0.0, 0.0, z],
    };
    ProbePath::new(&[
        at(0.0, 1.0),
        at(0.5, -1.2),
        at(1.5, -1.2),
        at(2.0, 1.0),
        at(2.5, 1.0),
    ])
}

/// Frames the lever rests for its direction check before its path starts (0.4 s at
/// 1 kHz; the board's check takes 74).
pub const NUDGE_FRAMES: u32 = 400;

/// What the lever's parts change.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LeverState {
    /// Frames answered (one a tick).
    pub frames: u32,
    /// The command of the last frame (its answer goes out in the next).
    pub last_command: u16,
    /// The motor's duty (PWM counts), direction and enable.
    pub duty: u16,
    /// See `duty`.
    pub forward: bool,
    /// See `duty`.
    pub enabled: bool,
    /// Counts the nudges moved it (up: the way the angle grows with `mm_per_count` > 0).
    pub nudged: i32,
}

/// A simulated lever: its path, its encoder's mounting, and its parts' state.
pub struct Lever {
    path: ProbePath<5>,
    period: u32,
    zero: u16,
    mm_per_count: f64,
    state: Shared<LeverState>,
}

/// The PWM's full scale in the simulation (the board's: 8,400 steps at 20 kHz).
pub const LEVER_MAX_DUTY: u16 = 8400;

impl Lever {
    /// A lever pressing along [`press_path`] at `tick_hz`, its encoder mounted with
    /// `zero` and `mm_per_count` (the board's `BoardConfig`).
    pub fn new(tick_hz: u32, zero: u16, mm_per_count: f64) -> Result<Self, PathError> {
        Ok(Self {
            path: press_path(tick_hz)?,
            period: (2.5 * tick_hz as f64) as u32,
            zero,
            mm_per_count,
            state: Shared::new(LeverState::default()),
        })
    }

    /// Its parts' state now.
    pub fn state(&self) -> LeverState {
        self.state.get()
    }

    /// The sensor's 14-bit angle at frame `frame`, nudged `nudged` counts.
    pub fn angle(&self, frame: u32, nudged: i32) -> u16 {
        let t = frame.saturating_sub(NUDGE_FRAMES) % self.period.max(1);
        let z = self.path.at(t)[2].to_num::<f64>();
        let counts = libm::round(z / self.mm_per_count) as i32 + nudged;
        (self.zero as i32 + counts).rem_euclid(1 << 14) as u16
    }

    /// Its encoder's bus, its motor's PWM channel, direction and enable.
    pub fn parts(&'static self) -> (LeverSpi, LeverPwm, LeverPin<false>, LeverPin<true>) {
        (
            LeverSpi(self),
            LeverPwm(self),
            LeverPin(self),
            LeverPin(self),
        )
    }
}

/// A 16-bit frame with even parity.
const fn with_parity(data: u16) -> u16 {
    let f = data & 0x3FFF;
    if f.count_ones() % 2 == 1 {
        f | 0x8000
    } else {
        f
    }
}

/// The lever's encoder bus.
pub struct LeverSpi(&'static Lever);

impl embedded_hal::spi::ErrorType for LeverSpi {
    type Error = core::convert::Infallible;
}

impl SpiDevice<u8> for LeverSpi {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), Self::Error> {
        for op in operations {
            let Operation::Transfer(rx, tx) = op else {
                continue;
            };
            let command = u16::from_be_bytes([
                tx.first().copied().unwrap_or(0),
                tx.get(1).copied().unwrap_or(0),
            ]) & 0x3FFF;
            let lever = self.0;
            let up = if lever.mm_per_count > 0.0 { 1 } else { -1 };
            let (frame, last, nudged) = lever.state.update(|s| {
                if s.frames < NUDGE_FRAMES && s.enabled && s.duty > LEVER_MAX_DUTY / 100 {
                    s.nudged += if s.forward { up } else { -up };
                }
                let out = (s.frames, s.last_command, s.nudged);
                s.frames = s.frames.saturating_add(1);
                s.last_command = command;
                out
            });
            let answer = match last {
                ANGLECOM => with_parity(lever.angle(frame, nudged)),
                DIAAGC => with_parity(DIAAGC_LF),
                _ => 0,
            };
            for (slot, b) in rx.iter_mut().zip(answer.to_be_bytes()) {
                *slot = b;
            }
        }
        Ok(())
    }
}

/// The lever's motor PWM channel.
pub struct LeverPwm(&'static Lever);

impl embedded_hal::pwm::ErrorType for LeverPwm {
    type Error = core::convert::Infallible;
}

impl embedded_hal::pwm::SetDutyCycle for LeverPwm {
    fn max_duty_cycle(&self) -> u16 {
        LEVER_MAX_DUTY
    }
    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
        self.0.state.update(|s| s.duty = duty.min(LEVER_MAX_DUTY));
        Ok(())
    }
}

/// The lever's motor direction (`ENABLE` false) or driver enable (`ENABLE` true).
pub struct LeverPin<const ENABLE: bool>(&'static Lever);

impl<const ENABLE: bool> embedded_hal::digital::ErrorType for LeverPin<ENABLE> {
    type Error = core::convert::Infallible;
}

impl<const ENABLE: bool> embedded_hal::digital::OutputPin for LeverPin<ENABLE> {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        self.0.state.update(|s| {
            if ENABLE {
                s.enabled = false
            } else {
                s.forward = false
            }
        });
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), Self::Error> {
        self.0.state.update(|s| {
            if ENABLE {
                s.enabled = true
            } else {
                s.forward = true
            }
        });
        Ok(())
    }
}
