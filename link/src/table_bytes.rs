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
    let mut segments = [[0i32; 4]; S];
    for (k, seg) in segments.iter_mut().enumerate() {
        for (j, v) in seg.iter_mut().enumerate() {
            *v = word(HEADER_WORDS + 4 * k + j);
        }
    }
    Some(RawTable {
        strain_lo: word(0),
        strain_hi: word(1),
        index_pre: word(2) as u32,
        index_scale: word(3) as u32,
        anchor_lo: word(4),
        force_lo: word(5),
        stiffness_lo: word(6),
        slope_lo: word(7),
        force_hi: word(8),
        stiffness_hi: word(9),
        slope_hi: word(10),
        shift: word(11) as u32,
        stiff_scale: word(12),
        stiff_post: word(13),
        corner_hi: word(14),
        corner_anchor: word(15),
        corner_pre: word(16) as u32,
        corner_base: word(17) as u32,
        corner_scale: word(18),
        corner_post: word(19),
        err_force_ppb: word(20) as u32,
        err_stiffness_ppb: word(21) as u32,
        segments,
    })
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
