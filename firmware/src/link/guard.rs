//! The link's force gain ([`Guard`]), Q15 (`mccs_link::scale::GAIN_FULL` is full force):
//!
//! - **Silence fades.** Once a host has sent `Arm`, the device renders only while the
//!   host keeps talking: no valid frame for `timeout` ticks fades the force to zero over
//!   `fade` ticks and disarms; the host must send `Arm` again.
//! - **Force comes on gently.** After `Arm`, after a start (standalone, never armed) and
//!   after homing ([`Guard::restart_ramp`]), the gain ramps from 0 to full over `ramp`
//!   ticks, and the ramp starts only once the probe is out of contact: a hand resting in
//!   the tissue is not pushed.
//! - `Disarm` holds the force at zero at once.
//!
//! The tick calls [`Guard::gain`] once per tick (a few compares and adds: no division,
//! the steps are computed when the guard is made); the main loop calls
//! [`Guard::frame`], [`Guard::arm`] and [`Guard::disarm`] between ticks.

use mccs_link::scale::GAIN_FULL;

/// Where the guard is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Never armed: full force (after its ramp), no timeout.
    Standalone,
    /// Armed: full force (after its ramp) while frames arrive.
    Armed,
    /// The host fell silent: the force fades.
    Fading,
    /// Disarmed (by the host, or after a fade): zero force until `Arm`.
    Disarmed,
}

/// The guard's times, ticks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GuardTimes {
    /// An armed host's longest silence.
    pub timeout: u32,
    /// The fade to zero after it.
    pub fade: u32,
    /// The ramp to full force.
    pub ramp: u32,
}

impl GuardTimes {
    /// At `tick_hz`: the link's timeout and fade (`mccs_link::rates`), and a ramp of
    /// `ramp_ms`.
    pub const fn at_rate(tick_hz: u32, ramp_ms: u32) -> Self {
        Self {
            timeout: ticks(tick_hz, mccs_link::rates::SILENCE_TIMEOUT_MS),
            fade: ticks(tick_hz, mccs_link::rates::FADE_MS),
            ramp: ticks(tick_hz, ramp_ms),
        }
    }
}

/// `ms` at `tick_hz`, ticks.
pub(crate) const fn ticks(tick_hz: u32, ms: u32) -> u32 {
    ((tick_hz as u64 * ms as u64) / 1000) as u32
}

/// The link's force gain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Guard {
    mode: Mode,
    last_frame: u32,
    timeout: u32,
    fade_step: u16,
    ramp_step: u16,
    /// The gain now, Q15.
    level: u16,
    /// The probe has been out of contact since the ramp began (it may rise).
    released: bool,
}

/// `GAIN_FULL / ticks`, rounded up, at least 1 (a zero-tick ramp or fade is one tick).
const fn step(ticks: u32) -> u16 {
    let t = if ticks == 0 { 1 } else { ticks };
    let s = (GAIN_FULL as u32).div_ceil(t);
    if s == 0 {
        1
    } else {
        s as u16
    }
}

impl Guard {
    /// Standalone, at zero gain, ramping once the probe is out of contact.
    pub const fn new(times: GuardTimes) -> Self {
        Self {
            mode: Mode::Standalone,
            last_frame: 0,
            timeout: times.timeout,
            fade_step: step(times.fade),
            ramp_step: step(times.ramp),
            level: 0,
            released: false,
        }
    }

    /// The mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// The gain the last tick took, Q15.
    pub fn level(&self) -> u16 {
        self.level
    }

    /// Whether a host holds the device armed (fading included).
    pub fn armed(&self) -> bool {
        matches!(self.mode, Mode::Armed | Mode::Fading)
    }

    /// A valid frame arrived at tick `now`.
    pub fn frame(&mut self, now: u32) {
        self.last_frame = now;
    }

    /// `Arm` at tick `now`: the timeout from now; the gain rises from where it is (from
    /// zero after a disarm or a fade, waiting for the probe to leave the tissue).
    pub fn arm(&mut self, now: u32) {
        if self.mode == Mode::Fading {
            // A host that comes back mid-fade ramps up from the level it left.
            self.released = true;
        }
        self.mode = Mode::Armed;
        self.last_frame = now;
    }

    /// `Disarm`: zero force until the next `Arm`.
    pub fn disarm(&mut self) {
        self.mode = Mode::Disarmed;
        self.level = 0;
        self.released = false;
    }

    /// The force drops to zero and ramps again once the probe is out of contact (after
    /// homing, or a fault cleared).
    pub fn restart_ramp(&mut self) {
        self.level = 0;
        self.released = false;
    }

    /// The force gain at tick `now`, with the probe in contact or not, Q15
    /// (0 … `GAIN_FULL`).
    pub fn gain(&mut self, now: u32, in_contact: bool) -> u16 {
        if self.mode == Mode::Armed && now.wrapping_sub(self.last_frame) > self.timeout {
            self.mode = Mode::Fading;
        }
        match self.mode {
            Mode::Disarmed => {
                self.level = 0;
                self.released = false;
            }
            Mode::Fading => {
                self.level = self.level.saturating_sub(self.fade_step);
                if self.level == 0 {
                    self.disarm();
                }
            }
            Mode::Standalone | Mode::Armed => {
                if !self.released && !in_contact {
                    self.released = true;
                }
                if self.released {
                    self.level = self.level.saturating_add(self.ramp_step).min(GAIN_FULL);
                }
            }
        }
        self.level
    }
}
