//! `2⁶² / m` for `m` in `[2³⁰, 2³¹)` without a division: a 64-entry table of the
//! reciprocal at each interval's middle (7 bits), then two Newton steps
//! `y ← y + y (2⁶² − m y) / 2⁶²` (each doubles the bits: 2⁻²⁸ relative, measured
//! against the exact quotient over the whole domain in `host-tests/tests/arm.rs`).

/// `round(2⁶² / m)` for `m` at the middle of each of the 64 intervals of `[2³⁰, 2³¹)`.
const TABLE: [u32; 64] = table();

const fn table() -> [u32; 64] {
    let mut t = [0u32; 64];
    let mut i = 0;
    while i < 64 {
        let mid = (1u64 << 30) + ((2 * i as u64 + 1) << 23);
        t[i] = ((1u64 << 62) / mid) as u32;
        i += 1;
    }
    t
}

/// `≈ 2⁶² / m`, for `m` in `[2³⁰, 2³¹)` (outside it, held to the nearest end).
#[inline]
pub fn recip(m: i64) -> i64 {
    let m = m.clamp(1 << 30, (1 << 31) - 1);
    let mut y = TABLE[((m >> 24) & 63) as usize] as i64;
    for _ in 0..2 {
        // e = 2⁶² − m y is small (≤ 2⁵⁶ after the table): y e / 2⁶² in two shifts.
        let e = (1i64 << 62) - m * y;
        y += (y * (e >> 31)) >> 31;
    }
    y
}
