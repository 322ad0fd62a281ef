//! `As5047p`: an AS5047P-style 14-bit magnetic angle encoder on SPI (embedded-hal 1.0),
//! and its conversion to probe travel in mm.
//!
//! Frames are 16 bits, SPI mode 1, MSB first. A command is `PARC | R/W | ADDR[13:0]`
//! (`PARC` makes the frame's parity even); a response is `PARD | EF | DATA[13:0]` for the
//! command sent in the *previous* frame. The driver sends "read ANGLECOM" (0x3FFF), so
//! each read returns the angle sampled one frame (one tick) earlier.
//!
//! # Bad frames
//! A frame is *bad* — not used, the last good position kept, counted in
//! [`EncoderErrors`] (`consecutive` too, which the device turns into a fault) — when:
//! - its parity is odd (corrupted on the wire);
//! - the sensor's error flag is set (the driver then reads ERRFL once, which clears it;
//!   the frame carrying ERRFL's contents is not a position either);
//! - its angle is *implausible*: farther from the last good angle than
//!   [`EncoderConfig::max_step`] counts per frame since it allows;
//! - it answers the periodic diagnostic read of DIAAGC
//!   ([`EncoderConfig::diag_every`]) and that does not show the sensor running: the
//!   offset loop finished (`LF` = 1) and no CORDIC overflow (`COF` = 0). Until a diagnostic
//!   passes (at start, and after a failed one) the driver reads DIAAGC every frame and
//!   takes no angle.
//!
//! # Stuck lines
//! - MISO stuck high reads `0xFFFF`: even parity, error flag set: every frame is bad.
//! - MISO stuck low reads `0x0000`: even parity, no flag, angle 0 — a valid-looking frame.
//!   It is caught by the next diagnostic read (DIAAGC reads 0: `LF` = 0), at the latest
//!   `diag_every` frames later, wherever the probe is; and at once by the plausibility
//!   check unless the probe was within `max_step` counts of angle 0.
//! - A stuck clock or chip select leaves MISO at one level: as above.
//! - One stuck data bit flips the parity whenever the true bit differs from it: about
//!   half the frames are parity errors, and the jumps of the others fail the
//!   plausibility check unless they are small.
//!
//! Travel: `mm = counts · mm_per_count`, where `counts` starts at `wrap(angle − zero)`
//! (`wrap` into ±8192 counts, half a turn) and then follows the angle over whole turns:
//! each good angle adds its wrapped step from the last good one. A lever that travels
//! past half a turn reads on, never jumps to the other end. Past `max_travel_counts`
//! from zero (either way) the driver reports [`As5047p::out_of_travel`], and the device
//! takes it as a fault: the lever has left the travel it was built for. For a lever of radius `r` mm turned through a capstan of ratio `i`,
//! `mm_per_count = 2π r / (16384 i)`; e.g. r = 75 mm, i = 10: 0.002876 mm per count.

use embedded_hal::spi::SpiDevice;
use mccs::units::{from_f64, Length};

/// ANGLECOM: the dynamic-angle-compensated angle.
pub const ANGLECOM: u16 = 0x3FFF;
/// ERRFL: the error register (reading it clears the error flag).
pub const ERRFL: u16 = 0x0001;
/// DIAAGC: diagnostics and automatic gain control.
pub const DIAAGC: u16 = 0x3FFC;
/// DIAAGC's `LF` bit: the offset compensation loop has finished (1 in normal operation).
pub const DIAAGC_LF: u16 = 1 << 8;
/// DIAAGC's `COF` bit: CORDIC overflow (the angle is invalid).
pub const DIAAGC_COF: u16 = 1 << 9;
/// NOP (address 0).
pub const NOP: u16 = 0x0000;

/// A read command for `addr`, with the read bit and even parity.
pub const fn read_command(addr: u16) -> u16 {
    let frame = 0x4000 | (addr & 0x3FFF);
    if frame.count_ones() % 2 == 1 {
        frame | 0x8000
    } else {
        frame
    }
}

/// What a response frame holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Frame {
    /// 14 bits of data.
    Data(u16),
    /// The frame's parity is odd: corrupted on the wire.
    Parity,
    /// The sensor's error flag (EF) is set.
    ErrorFlag,
}

/// Decodes a response frame.
pub const fn decode(frame: u16) -> Frame {
    if frame.count_ones() % 2 == 1 {
        Frame::Parity
    } else if frame & 0x4000 != 0 {
        Frame::ErrorFlag
    } else {
        Frame::Data(frame & 0x3FFF)
    }
}

/// Encoder mounting and checks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EncoderConfig {
    /// Angle (counts, 0 … 16383) at zero travel.
    pub zero: u16,
    /// Travel per count, mm (sign gives the direction), |x| < 0.01.
    pub mm_per_count: f64,
    /// The largest plausible change of angle per frame, counts (the fastest the probe
    /// moves, times the frame period, over the travel per count; 0 … 8191, 8191 disables
    /// the check). An angle farther from the last good one than this times the frames
    /// since it is a bad frame.
    pub max_step: u16,
    /// Frames between diagnostic reads of DIAAGC (0: never). One frame in this many
    /// carries no angle (the position holds for that tick).
    pub diag_every: u16,
    /// The travel either side of zero, counts (any turns), beyond which the position is
    /// out of travel ([`As5047p::out_of_travel`]); at most 2²⁴ (the Q24 mm position's
    /// range at the largest `mm_per_count`).
    pub max_travel_counts: u32,
}

impl EncoderConfig {
    /// `max_step` for a probe speed (mm/s) at a frame rate (Hz): the counts the probe
    /// can cover in one frame, plus one, at most 8191.
    pub fn max_step_for(mm_per_count: f64, speed_mm_s: f64, frame_hz: f64) -> u16 {
        let counts = speed_mm_s / frame_hz / libm::fabs(mm_per_count);
        if counts.is_finite() {
            (libm::ceil(counts) + 1.0).clamp(1.0, 8191.0) as u16
        } else {
            8191
        }
    }
}

/// Error counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EncoderErrors {
    /// Frames with bad parity.
    pub parity: u32,
    /// Frames with the sensor's error flag.
    pub flagged: u32,
    /// Angles farther from the last good one than the probe can move.
    pub implausible: u32,
    /// Diagnostic reads that did not show the sensor running.
    pub diagnostic: u32,
    /// Bad frames in a row (reset by a good angle).
    pub consecutive: u32,
}

/// The encoder driver.
#[derive(Debug)]
pub struct As5047p<SPI> {
    spi: SPI,
    zero: u16,
    /// mm per count, Q30.
    scale: i32,
    max_step: u16,
    diag_every: u16,
    /// Frames until the next diagnostic read.
    diag_in: u16,
    /// Whether a diagnostic has passed since the start or the last failed one.
    verified: bool,
    /// The last good angle (counts) and its travel (Q24 mm), and frames since it.
    last_angle: Option<u16>,
    last_good: i32,
    since_good: u32,
    /// Travel from zero, counts, over whole turns (the last good angle's), and its limit.
    counts: i32,
    max_travel: i32,
    /// The command sent in the last frame, answered in the next.
    in_flight: u16,
    /// Whether the next frame reads ERRFL (after an error flag).
    errfl_pending: bool,
    errors: EncoderErrors,
}

impl<SPI: SpiDevice<u8>> As5047p<SPI> {
    /// A driver on `spi`. Until the first good angle the position is 0; with diagnostics
    /// on, the first frames read DIAAGC until it passes.
    pub fn new(spi: SPI, config: EncoderConfig) -> Self {
        Self {
            spi,
            zero: config.zero & 0x3FFF,
            scale: from_f64(config.mm_per_count.clamp(-0.01, 0.01), 30),
            max_step: config.max_step.min(8191),
            diag_every: config.diag_every,
            diag_in: config.diag_every,
            verified: config.diag_every == 0,
            last_angle: None,
            last_good: 0,
            since_good: 0,
            counts: 0,
            max_travel: config.max_travel_counts.min(1 << 24) as i32,
            // The first frame answers nothing we sent: treat it as a NOP's answer.
            in_flight: NOP,
            errfl_pending: false,
            errors: EncoderErrors::default(),
        }
    }

    /// The command for the next frame.
    fn next_command(&mut self) -> u16 {
        if core::mem::take(&mut self.errfl_pending) {
            return ERRFL;
        }
        if self.diag_every == 0 {
            return ANGLECOM;
        }
        if !self.verified {
            return DIAAGC;
        }
        self.diag_in = self.diag_in.saturating_sub(1);
        if self.diag_in == 0 {
            self.diag_in = self.diag_every;
            DIAAGC
        } else {
            ANGLECOM
        }
    }

    fn bad(&mut self) {
        let e = &mut self.errors;
        e.consecutive = e.consecutive.saturating_add(1);
    }

    /// One frame: returns the travel (mm) — the new one, or the last good one if the
    /// frame was bad or carried no angle. Errs only when the SPI bus itself fails.
    pub fn read(&mut self) -> Result<Length, SPI::Error> {
        let answered = self.in_flight;
        let sent = self.next_command();
        let mut rx = [0u8; 2];
        self.spi
            .transfer(&mut rx, &read_command(sent).to_be_bytes())?;
        self.in_flight = sent;
        self.since_good = self.since_good.saturating_add(1);
        match decode(u16::from_be_bytes(rx)) {
            Frame::Data(angle) if answered == ANGLECOM && self.verified => self.angle(angle),
            Frame::Data(d) if answered == DIAAGC => {
                let running = d & DIAAGC_LF != 0 && d & DIAAGC_COF == 0;
                if running {
                    self.verified = true;
                } else {
                    self.verified = false;
                    self.errors.diagnostic = self.errors.diagnostic.saturating_add(1);
                    self.bad();
                }
            }
            Frame::Data(_) => {} // ERRFL's contents (reading it cleared the flag), or NOP's
            Frame::Parity => {
                self.errors.parity = self.errors.parity.saturating_add(1);
                self.bad();
            }
            Frame::ErrorFlag => {
                self.errors.flagged = self.errors.flagged.saturating_add(1);
                self.bad();
                // Read ERRFL once to clear the flag (unless this frame just asked).
                self.errfl_pending = sent != ERRFL;
            }
        }
        Ok(Length::from_bits(self.last_good))
    }

    /// A data frame answering ANGLECOM: taken if plausible.
    fn angle(&mut self, angle: u16) {
        if let Some(last) = self.last_angle {
            let jump = (((angle.wrapping_sub(last)) << 2) as i16 >> 2).unsigned_abs() as u32;
            let allowed = (self.max_step as u32).saturating_mul(self.since_good);
            if jump > allowed {
                self.errors.implausible = self.errors.implausible.saturating_add(1);
                self.bad();
                return;
            }
        }
        self.counts = match self.last_angle {
            // The wrapped step from the last good angle (±8192), over whole turns.
            Some(last) => self
                .counts
                .saturating_add((((angle.wrapping_sub(last)) << 2) as i16 >> 2) as i32),
            None => (((angle.wrapping_sub(self.zero) << 2) as i16) >> 2) as i32,
        };
        // Counts · Q30 mm/count → Q24 mm.
        self.last_good = mccs::q::sat((self.counts as i64 * self.scale as i64) >> 6);
        self.last_angle = Some(angle);
        self.since_good = 0;
        self.errors.consecutive = 0;
    }

    /// Travel from zero, counts, over whole turns (the last good angle's).
    pub fn counts(&self) -> i32 {
        self.counts
    }

    /// Whether the last good angle is beyond `max_travel_counts` from zero.
    pub fn out_of_travel(&self) -> bool {
        self.counts.unsigned_abs() > self.max_travel as u32
    }

    /// Error counters so far.
    pub fn errors(&self) -> EncoderErrors {
        self.errors
    }

    /// Gives the SPI device back.
    pub fn release(self) -> SPI {
        self.spi
    }
}
