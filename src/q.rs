//! Fixed-point helpers for the per-tick path: saturating products of raw `i32` values in
//! different Q formats, and 3-vectors of them. Every product is 32 × 32 → 64 bits, shifted
//! back and clamped to `i32`: never wrapping, never panicking.

/// A 3-vector of raw fixed-point values (x, y, z).
pub type V3 = [i32; 3];

/// Clamps an `i64` into `i32`.
#[inline(always)]
pub fn sat(x: i64) -> i32 {
    x.clamp(i32::MIN as i64, i32::MAX as i64) as i32
}

/// `(a · b) >> shift`, saturated to `i32` (floor).
#[inline(always)]
pub fn mul(a: i32, b: i32, shift: u32) -> i32 {
    sat((a as i64 * b as i64) >> shift)
}

/// `(a · b) >> S`, not saturated: for products the caller knows to fit.
#[inline(always)]
pub fn mulsh<const S: u32>(a: i32, b: i32) -> i32 {
    ((a as i64 * b as i64) >> S) as i32
}

/// Component-wise saturating `a + b`.
#[inline(always)]
pub fn add(a: V3, b: V3) -> V3 {
    [
        a[0].saturating_add(b[0]),
        a[1].saturating_add(b[1]),
        a[2].saturating_add(b[2]),
    ]
}

/// Component-wise saturating `a − b`.
#[inline(always)]
pub fn sub(a: V3, b: V3) -> V3 {
    [
        a[0].saturating_sub(b[0]),
        a[1].saturating_sub(b[1]),
        a[2].saturating_sub(b[2]),
    ]
}

/// `v · s >> shift` for each component, saturating.
#[inline(always)]
pub fn scale(v: V3, s: i32, shift: u32) -> V3 {
    [
        mul(v[0], s, shift),
        mul(v[1], s, shift),
        mul(v[2], s, shift),
    ]
}

/// `|v|² >> shift`, saturating.
#[inline(always)]
pub fn norm2(v: V3, shift: u32) -> i32 {
    let s = v[0] as i64 * v[0] as i64 + v[1] as i64 * v[1] as i64;
    // Each square is < 2^62; the sum of two fits, the third is added after the shift.
    sat((s >> shift) + ((v[2] as i64 * v[2] as i64) >> shift))
}

/// Rounds an `f64` to the nearest raw value with `frac` fraction bits, saturating
/// (start-up only).
pub fn from_f64(x: f64, frac: u32) -> i32 {
    let v = libm::round(x * (1u64 << frac) as f64);
    if v.is_nan() {
        0
    } else if v >= i32::MAX as f64 {
        i32::MAX
    } else if v <= i32::MIN as f64 {
        i32::MIN
    } else {
        v as i32
    }
}
