//! The link's safety rule: once a host has sent `Arm`, the device renders only while the
//! host keeps talking. No valid frame for `timeout` ticks fades the force to zero over
//! `fade` ticks and disarms; the host must send `Arm` again. A device no host ever armed
//! renders standalone, at full force. `Disarm` holds the force at zero at once.
//!
//! The tick calls [`Guard::gain`] once per tick (a few compares and one multiply: no
//! division, the fade's step is computed when the guard is made); the main loop calls
//! [`Guard::frame`], [`Guard::arm`] and [`Guard::disarm`] between ticks.

/// Full force, Q15.
pub const FULL: u16 = 1 << 15;

/// Where the guard is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Never armed: full force, no timeout.
    Standalone,
    /// Armed: full force while frames arrive.
    Armed,
    /// The host fell silent at tick `since`: the force fades.
    Fading {
        /// The tick the fade began.
        since: u32,
    },
    /// Disarmed (by the host, or after a fade): zero force until `Arm`.
    Disarmed,
}

/// The link's force gain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Guard {
    mode: Mode,
    last_frame: u32,
    timeout: u32,
    fade: u32,
    step: u32,
}

impl Guard {
    /// Standalone; an armed host's silence of more than `timeout` ticks fades the force
    /// over `fade` ticks (≥ 1).
    pub const fn new(timeout: u32, fade: u32) -> Self {
        let fade = if fade == 0 { 1 } else { fade };
        Self {
            mode: Mode::Standalone,
            last_frame: 0,
            timeout,
            fade,
            step: (FULL as u32).div_ceil(fade),
        }
    }

    /// For a tick rate: a 100 ms timeout, a 20 ms fade.
    pub const fn at_rate(tick_hz: u32) -> Self {
        Self::new(tick_hz / 10, tick_hz / 50)
    }

    /// The mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Whether a host holds the device armed (fading included).
    pub fn armed(&self) -> bool {
        matches!(self.mode, Mode::Armed | Mode::Fading { .. })
    }

    /// A valid frame arrived at tick `now`.
    pub fn frame(&mut self, now: u32) {
        self.last_frame = now;
    }

    /// `Arm` at tick `now`: full force, the timeout from now.
    pub fn arm(&mut self, now: u32) {
        self.mode = Mode::Armed;
        self.last_frame = now;
    }

    /// `Disarm`: zero force until the next `Arm`.
    pub fn disarm(&mut self) {
        self.mode = Mode::Disarmed;
    }

    /// The force gain at tick `now`, Q15 (0 … [`FULL`]).
    pub fn gain(&mut self, now: u32) -> u16 {
        match self.mode {
            Mode::Standalone => FULL,
            Mode::Disarmed => 0,
            Mode::Armed => {
                if now.wrapping_sub(self.last_frame) > self.timeout {
                    self.mode = Mode::Fading { since: now };
                    return self.gain(now);
                }
                FULL
            }
            Mode::Fading { since } => {
                let down = now
                    .wrapping_sub(since)
                    .saturating_add(1)
                    .saturating_mul(self.step);
                if down >= FULL as u32 {
                    self.mode = Mode::Disarmed;
                    0
                } else {
                    (FULL as u32 - down) as u16
                }
            }
        }
    }
}
