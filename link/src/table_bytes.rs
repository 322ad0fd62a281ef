//! A force table as the bytes a tissue load carries: the [`RawTable`]'s fields in their
//! declaration order, then its segments, each an `i32` little-endian
//! ([`HEADER_WORDS`] + 4 per segment: 1,112 bytes at 65 knots). The hash names a tissue
//! in `Ack` and `Hello`: FNV-1a over those bytes.

use crate::schema::fnv1a;
use mccs::{ForceTable, RawTable};

/// The header's 4-byte fields.
pub const HEADER_WORDS: usize = 22;

/// The bytes of a table of `S` segments.
pub const fn len(segments: usize) -> usize {
    4 * (HEADER_WORDS + 4 * segments)
}

/// The header's fields, in order, as `i32` bits.
fn header<const S: usize>(r: &RawTable<S>) -> [i32; HEADER_WORDS] {
    [
        r.strain_lo,
        r.strain_hi,
        r.index_pre as i32,
        r.index_scale as i32,
        r.anchor_lo,
        r.force_lo,
        r.stiffness_lo,
        r.slope_lo,
        r.force_hi,
        r.stiffness_hi,
        r.slope_hi,
        r.shift as i32,
        r.stiff_scale,
        r.stiff_post,
        r.corner_hi,
        r.corner_anchor,
        r.corner_pre as i32,
        r.corner_base as i32,
        r.corner_scale,
        r.corner_post,
        r.err_force_ppb as i32,
        r.err_stiffness_ppb as i32,
    ]
}

/// Writes `table` into `out` (at least [`len`]`(S)` bytes); returns the bytes written.
pub fn write<const S: usize>(table: &ForceTable<S>, out: &mut [u8]) -> usize {
    let r = table.raw();
    let words = header(r)
        .into_iter()
        .chain(r.segments.iter().flat_map(|s| s.iter().copied()));
    let mut n = 0;
    for (w, slot) in words.zip(out.chunks_exact_mut(4)) {
        slot.copy_from_slice(&w.to_le_bytes());
        n += 4;
    }
    n
}

/// The table in `bytes`, unchecked (the caller validates it); `None` if `bytes` is not
/// [`len`]`(S)` long.
pub fn read<const S: usize>(bytes: &[u8]) -> Option<RawTable<S>> {
    if bytes.len() != len(S) {
        return None;
    }
    let word = |i: usize| {
        let b = &bytes[4 * i..4 * i + 4];
        i32::from_le_bytes([b[0], b[1], b[2], b[3]])
    };
    let header: [i32; HEADER_WORDS] = core::array::from_fn(word);
    let segments =
        core::array::from_fn(|k| core::array::from_fn(|j| word(HEADER_WORDS + 4 * k + j)));
    Some(from_words(&header, segments))
}

/// The table of these words: the header's fields in order, and the segments.
pub fn from_words<const S: usize>(h: &[i32; HEADER_WORDS], segments: [[i32; 4]; S]) -> RawTable<S> {
    RawTable {
        strain_lo: h[0],
        strain_hi: h[1],
        index_pre: h[2] as u32,
        index_scale: h[3] as u32,
        anchor_lo: h[4],
        force_lo: h[5],
        stiffness_lo: h[6],
        slope_lo: h[7],
        force_hi: h[8],
        stiffness_hi: h[9],
        slope_hi: h[10],
        shift: h[11] as u32,
        stiff_scale: h[12],
        stiff_post: h[13],
        corner_hi: h[14],
        corner_anchor: h[15],
        corner_pre: h[16] as u32,
        corner_base: h[17] as u32,
        corner_scale: h[18],
        corner_post: h[19],
        err_force_ppb: h[20] as u32,
        err_stiffness_ppb: h[21] as u32,
        segments,
    }
}

/// A table's hash: FNV-1a over its bytes, fed in 4-byte words (no buffer).
pub fn hash<const S: usize>(table: &ForceTable<S>) -> u32 {
    let r = table.raw();
    let mut h = 0x811C_9DC5u32;
    let words = header(r)
        .into_iter()
        .chain(r.segments.iter().flat_map(|s| s.iter().copied()));
    for w in words {
        for b in w.to_le_bytes() {
            h ^= b as u32;
            h = h.wrapping_mul(0x0100_0193);
        }
    }
    h
}

/// The hash of bytes as they arrive ([`hash`] of the table they hold).
pub fn hash_bytes(bytes: &[u8]) -> u32 {
    fnv1a(bytes)
}
