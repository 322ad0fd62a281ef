//! A message on the wire: its postcard bytes (at most [`MAX_PAYLOAD`]), then the CRC-32
//! of those bytes (4 bytes, little-endian), the whole COBS-encoded and ended by `0x00`:
//! at most [`MAX_FRAME`] bytes. A payload too large for one frame travels in pieces
//! (a tissue's table, a replay's path: [`crate::ToDevice`]).
//!
//! The [`Decoder`] takes a byte stream one byte at a time (as a UART interrupt delivers
//! it) and hands out each frame's checked payload; everything else — a CRC or COBS
//! error, a frame too long, a message that does not parse or has bytes left over — is
//! one [`FrameError`], for the caller to count, and the decoder is ready for the next
//! frame at the next delimiter.

use crate::crc::crc32;
use serde::{Deserialize, Serialize};

/// The largest frame, bytes, delimiter included.
pub const MAX_FRAME: usize = 256;
/// The largest message, bytes: its CRC and COBS's overhead (one byte in 254, plus one)
/// and the delimiter fit in [`MAX_FRAME`].
pub const MAX_PAYLOAD: usize = 248;

/// Why a frame was dropped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameError {
    /// The message does not fit in [`MAX_PAYLOAD`] bytes (when encoding).
    TooLarge,
    /// More than [`MAX_FRAME`] bytes before a delimiter.
    TooLong,
    /// Not valid COBS.
    Cobs,
    /// Shorter than a CRC and one byte.
    TooShort,
    /// The CRC does not match.
    Crc,
    /// The bytes are not a message, or have bytes left over after one.
    Message,
}

impl FrameError {
    /// In words.
    pub const fn message(self) -> &'static str {
        match self {
            Self::TooLarge => "frame: the message is larger than a frame takes",
            Self::TooLong => "frame: more bytes than a frame holds before its delimiter",
            Self::Cobs => "frame: not valid COBS",
            Self::TooShort => "frame: shorter than a CRC",
            Self::Crc => "frame: its CRC does not match",
            Self::Message => "frame: not a message of this protocol",
        }
    }
}

impl core::fmt::Display for FrameError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.message())
    }
}

/// Encodes `msg` as one frame into `out`; returns the frame (delimiter included).
pub fn encode<'o, T: Serialize>(
    msg: &T,
    out: &'o mut [u8; MAX_FRAME],
) -> Result<&'o [u8], FrameError> {
    let mut raw = [0u8; MAX_PAYLOAD + 4];
    let n = postcard::to_slice(msg, &mut raw[..MAX_PAYLOAD])
        .map_err(|_| FrameError::TooLarge)?
        .len();
    let crc = crc32(&raw[..n]).to_le_bytes();
    raw[n..n + 4].copy_from_slice(&crc);
    let m = cobs::try_encode(&raw[..n + 4], &mut out[..MAX_FRAME - 1])
        .map_err(|_| FrameError::TooLarge)?;
    out[m] = 0;
    Ok(&out[..m + 1])
}

/// The message in a checked payload: all of it, nothing left over.
pub fn parse<'a, T: Deserialize<'a>>(payload: &'a [u8]) -> Result<T, FrameError> {
    match postcard::take_from_bytes::<T>(payload) {
        Ok((msg, [])) => Ok(msg),
        _ => Err(FrameError::Message),
    }
}

/// Reassembles frames from a byte stream.
#[derive(Clone, Debug)]
pub struct Decoder {
    buf: [u8; MAX_FRAME],
    len: usize,
    /// Bytes are being dropped until the next delimiter (the frame was too long).
    skipping: bool,
}

impl Default for Decoder {
    fn default() -> Self {
        Self::new()
    }
}

impl Decoder {
    /// Empty.
    pub const fn new() -> Self {
        Self {
            buf: [0; MAX_FRAME],
            len: 0,
            skipping: false,
        }
    }

    /// Takes one byte. At a delimiter, the frame it ends: its checked payload, or why
    /// it was dropped; `None` otherwise (and for delimiters between frames).
    pub fn push(&mut self, byte: u8) -> Option<Result<&[u8], FrameError>> {
        if byte != 0 {
            if self.skipping {
                return None;
            }
            if self.len == MAX_FRAME {
                self.len = 0;
                self.skipping = true;
                return Some(Err(FrameError::TooLong));
            }
            self.buf[self.len] = byte;
            self.len += 1;
            return None;
        }
        let len = core::mem::take(&mut self.len);
        if core::mem::take(&mut self.skipping) || len == 0 {
            return None;
        }
        Some(check(&mut self.buf[..len]))
    }
}

/// A frame's bytes (no delimiter) decoded in place and checked: the payload.
fn check(frame: &mut [u8]) -> Result<&[u8], FrameError> {
    let n = cobs::decode_in_place(frame).map_err(|_| FrameError::Cobs)?;
    if n < 5 {
        return Err(FrameError::TooShort);
    }
    let (payload, crc) = frame[..n].split_at(n - 4);
    if crc32(payload).to_le_bytes() != crc {
        return Err(FrameError::Crc);
    }
    Ok(payload)
}
