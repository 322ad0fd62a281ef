//! A tissue's table as a file (`mccs table --format bin`): what a scene in any language
//! ships and sends with `TissueBegin`/`TissueChunk` unchanged. A 20-byte header, then
//! the table's bytes ([`crate::table_bytes`]):
//!
//! | offset | bytes | what |
//! |---|---|---|
//! | 0 | 8 | the magic `MCCSTIS1` |
//! | 8 | 2 | segments (knots − 1), `u16` little-endian |
//! | 10 | 2 | zero |
//! | 12 | 4 | the table's length in bytes, `u32` little-endian |
//! | 16 | 4 | its hash (FNV-1a over the table's bytes), `u32` little-endian |
//! | 20 | length | the table's bytes |

use crate::table_bytes;

/// The file's first bytes.
pub const MAGIC: [u8; 8] = *b"MCCSTIS1";
/// The header's length.
pub const HEADER: usize = 20;

/// Why a file is not a tissue.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TissueFileError {
    /// Shorter than the header, or without the magic.
    NotATissue,
    /// The reserved bytes are not zero (a later format).
    Version,
    /// The length in the header is not the segments' table length, or not what follows.
    Length,
    /// The bytes' hash is not the header's.
    Hash,
}

impl TissueFileError {
    /// In words.
    pub const fn message(self) -> &'static str {
        match self {
            Self::NotATissue => "not a tissue file (no MCCSTIS1 header)",
            Self::Version => "a tissue file of another version (its reserved bytes are not zero)",
            Self::Length => "the header's length is not the table's that follows",
            Self::Hash => "the table's bytes do not match the header's hash (corrupted)",
        }
    }
}

impl core::fmt::Display for TissueFileError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.message())
    }
}

impl core::error::Error for TissueFileError {}

/// A tissue file's parts: its segments, hash and table bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TissueFile<'a> {
    /// Segments (knots − 1).
    pub segments: u16,
    /// FNV-1a of `bytes`.
    pub hash: u32,
    /// The table's bytes.
    pub bytes: &'a [u8],
}

impl<'a> TissueFile<'a> {
    /// The file in `data`, checked: header, length and hash.
    pub fn parse(data: &'a [u8]) -> Result<Self, TissueFileError> {
        let (head, bytes) = data
            .split_at_checked(HEADER)
            .ok_or(TissueFileError::NotATissue)?;
        if head[..8] != MAGIC {
            return Err(TissueFileError::NotATissue);
        }
        if head[10..12] != [0, 0] {
            return Err(TissueFileError::Version);
        }
        let segments = u16::from_le_bytes([head[8], head[9]]);
        let len = u32::from_le_bytes([head[12], head[13], head[14], head[15]]);
        let hash = u32::from_le_bytes([head[16], head[17], head[18], head[19]]);
        if len as usize != bytes.len() || len as usize != table_bytes::len(segments as usize) {
            return Err(TissueFileError::Length);
        }
        if table_bytes::hash_bytes(bytes) != hash {
            return Err(TissueFileError::Hash);
        }
        Ok(Self {
            segments,
            hash,
            bytes,
        })
    }

    /// The header for a table of `segments` whose bytes are `bytes`.
    pub fn header(segments: u16, bytes: &[u8]) -> [u8; HEADER] {
        let mut h = [0u8; HEADER];
        h[..8].copy_from_slice(&MAGIC);
        h[8..10].copy_from_slice(&segments.to_le_bytes());
        h[12..16].copy_from_slice(&(bytes.len() as u32).to_le_bytes());
        h[16..20].copy_from_slice(&table_bytes::hash_bytes(bytes).to_le_bytes());
        h
    }
}
