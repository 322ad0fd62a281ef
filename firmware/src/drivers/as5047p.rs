//! `As5047p`: an AS5047P-style 14-bit magnetic angle encoder on SPI (embedded-hal 1.0),
//! and its conversion to probe travel in mm.
//!
//! Frames are 16 bits, SPI mode 1, MSB first. A command is `PARC | R/W | ADDR[13:0]`
//! (`PARC` makes the frame's parity even); a response is `PARD | EF | DATA[13:0]` for the
//! command sent in the *previous* frame. This driver always sends "read ANGLECOM"
//! (0x3FFF), so each read returns the angle sampled one frame (one tick) earlier. A frame
//! with bad parity, or with the error flag set, is not used: the last good position is
//! kept and the error is counted; after an error flag the driver sends "read ERRFL" once
//! (which clears the flag) and then the angle again: the position resumes three frames
//! later (the frame carrying ERRFL's contents is not a position).
//!
//! Travel: `mm = wrap(angle − zero) · mm_per_count`, with `wrap` into ±8192 counts (half a
//! turn). For a lever of radius `r` mm turned through a capstan of ratio `i`,
//! `mm_per_count = 2π r / (16384 i)`; e.g. r = 75 mm, i = 10: 0.002876 mm per count.

use embedded_hal::spi::SpiDevice;
use mccs::units::{from_f64, Length};

/// ANGLECOM: the dynamic-angle-compensated angle.
pub const ANGLECOM: u16 = 0x3FFF;
/// ERRFL: the error register (reading it clears the error flag).
pub const ERRFL: u16 = 0x0001;
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

/// Encoder mounting: the angle at zero travel and the travel per count.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EncoderConfig {
    /// Angle (counts, 0 … 16383) at zero travel.
    pub zero: u16,
    /// Travel per count, mm (sign gives the direction), |x| < 0.01.
    pub mm_per_count: f64,
}

/// Error counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EncoderErrors {
    /// Frames with bad parity.
    pub parity: u32,
    /// Frames with the sensor's error flag.
    pub flagged: u32,
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
    last_good: i32,
    /// The command sent in the last frame, answered in the next.
    in_flight: u16,
    /// The command to send next.
    next: u16,
    errors: EncoderErrors,
}

impl<SPI: SpiDevice<u8>> As5047p<SPI> {
    /// A driver on `spi`; the first read returns the previous command's answer (none yet:
    /// position 0 until the first good angle).
    pub fn new(spi: SPI, config: EncoderConfig) -> Self {
        Self {
            spi,
            zero: config.zero & 0x3FFF,
            scale: from_f64(config.mm_per_count.clamp(-0.01, 0.01), 30),
            last_good: 0,
            // The first frame answers nothing we sent: treat it as a NOP's answer.
            in_flight: NOP,
            next: ANGLECOM,
            errors: EncoderErrors::default(),
        }
    }

    /// One frame: returns the travel (mm) — the new one, or the last good one if the
    /// frame was bad or carried ERRFL. Errs only when the SPI bus itself fails.
    pub fn read(&mut self) -> Result<Length, SPI::Error> {
        let answered = self.in_flight;
        let sent = self.next;
        let mut rx = [0u8; 2];
        self.spi
            .transfer(&mut rx, &read_command(sent).to_be_bytes())?;
        self.in_flight = sent;
        self.next = ANGLECOM;
        match decode(u16::from_be_bytes(rx)) {
            Frame::Data(angle) if answered == ANGLECOM => {
                let delta = ((angle.wrapping_sub(self.zero) << 2) as i16) >> 2; // ±8192
                                                                                // Counts · Q30 mm/count → Q24 mm.
                self.last_good = mccs::q::sat((delta as i64 * self.scale as i64) >> 6);
                self.errors.consecutive = 0;
            }
            Frame::Data(_) => {} // ERRFL's contents: reading it cleared the flag
            Frame::Parity => {
                self.errors.parity = self.errors.parity.saturating_add(1);
                self.errors.consecutive = self.errors.consecutive.saturating_add(1);
            }
            Frame::ErrorFlag => {
                self.errors.flagged = self.errors.flagged.saturating_add(1);
                self.errors.consecutive = self.errors.consecutive.saturating_add(1);
                // Read ERRFL once to clear the flag (unless this frame just asked).
                if sent != ERRFL {
                    self.next = ERRFL;
                }
            }
        }
        Ok(Length::from_bits(self.last_good))
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
