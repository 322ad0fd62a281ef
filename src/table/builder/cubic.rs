//! The segments' cubics: Hermite with a monotone limiter, the coefficients' unit and
//! rounding, and the stiffness scale.

use super::grid::Grid;
use crate::law::Law;
use crate::table::{knot_bias, TableError};
use crate::units::{FORCE_FRAC, STIFF_FRAC};

/// The cubic of one segment from its end values `a0, a1` and end slopes `m0, m1` (same
/// unit): `[C1, C2, C3]` unrounded, with the Fritsch–Carlson limiter where the law bends
/// harder than the grid resolves (a soft cone against a stiff series spring, just below
/// the solid point): the end slopes are scaled into the circle α² + β² ≤ 9 that keeps
/// the cubic monotone. Smooth laws (Table 2) never reach it.
pub(super) fn hermite(a0: f64, a1: f64, m0: f64, m1: f64) -> [f64; 3] {
    let secant = a1 - a0;
    let (mut s0, mut s1) = (m0, m1);
    if secant != 0.0 {
        let (al, be) = (s0 / secant, s1 / secant);
        let r2 = al * al + be * be;
        if r2 > 9.0 {
            let tau = 3.0 / libm::sqrt(r2);
            (s0, s1) = (tau * s0, tau * s1);
        }
    }
    let c1 = 2.0 * s0;
    let c2 = 4.0 * (3.0 * secant - 2.0 * s0 - s1);
    [c1, c2, 8.0 * secant - 4.0 * c1 - 2.0 * c2]
}

/// The coefficients' unit, Q(20 + shift) N: the largest shift (≤ 12) that keeps every knot
/// within 2³⁰, every segment's |C1| + |C2| + |C3| within 2²⁹, so that no Horner step of
/// the value or the stiffness can overflow, and, in the graded corner's octave `z`,
/// that sum times `2^z` within [`CORNER_STIFF_MAX`], so that `D << z` cannot.
pub(super) fn coefficient_shift(
    law: &Law,
    grid: &Grid,
    corner: Magnitude,
) -> Result<u32, TableError> {
    let (mut big_value, mut big_poly) = (
        libm::fmax(1e-30, corner.value),
        libm::fmax(1e-30, corner.poly),
    );
    let mut prev = grid.knot(law, 0)?;
    big_value = libm::fmax(big_value, libm::fabs(prev.value));
    for i in 1..=grid.used {
        let k = grid.knot(law, i)?;
        let c = hermite(prev.value, k.value, prev.slope_above, k.slope_below);
        big_value = libm::fmax(big_value, libm::fabs(k.value));
        big_poly = libm::fmax(
            big_poly,
            libm::fabs(c[0]) + libm::fabs(c[1]) + libm::fabs(c[2]),
        );
        prev = k;
    }
    let fits = |shift: u32| {
        let x = (1u64 << shift) as f64;
        big_value * x + knot_bias(shift) as f64 <= (1u64 << 30) as f64 - 64.0
            && 1.01 * big_poly * x <= (1u64 << 29) as f64 - 64.0
            && 1.01 * corner.stiff * x <= CORNER_STIFF_MAX
    };
    if !fits(0) {
        return Err(TableError::OutOfRange);
    }
    let mut shift = 0u32;
    while shift < 12 && fits(shift + 1) {
        shift += 1;
    }
    Ok(shift)
}

/// The segments' coefficients in the unit of `shift`, with the first knot and a bound on
/// `|dF/dτ|` (in the unit).
pub(super) struct Segments<const S: usize> {
    pub(super) coefficients: [[i32; 4]; S],
    pub(super) first: i32,
    pub(super) slope_bound: f64,
}

/// The segments: knots rounded to Q(20 + shift); `C1`, `C2` rounded at full resolution,
/// `C3 = 8 (a1 − a0) − 4 C1 − 2 C2` exact, so that `c0 + c1 + c2 + c3` is the next knot.
pub(super) fn segments<const S: usize>(
    law: &Law,
    grid: &Grid,
    shift: u32,
) -> Result<Segments<S>, TableError> {
    let scale = (1u64 << shift) as f64;
    let first = grid.knot(law, 0)?;
    let mut coefficients = [[0i32; 4]; S];
    let (mut a0, mut m0) = (knot_units(first.value, shift), first.slope_above);
    let a_first = a0;
    let mut slope_bound = 0.0f64;
    for (i, c) in coefficients.iter_mut().enumerate().take(grid.used) {
        let k = grid.knot(law, i + 1)?;
        let a1 = knot_units(k.value, shift);
        *c = rounded_cubic(a0, a1, m0 * scale, k.slope_below * scale, 0)?;
        let [c1, c2, c3] = [c[1], c[2], c[3]].map(|x| libm::fabs(x as f64));
        // |dF/dτ| ≤ |c1| + 2|c2| + 3|c3|, in the unit.
        slope_bound = libm::fmax(slope_bound, c1 / 2.0 + c2 / 2.0 + 3.0 * c3 / 8.0);
        (a0, m0) = (a1, k.slope_above);
    }
    Ok(Segments {
        coefficients,
        first: a_first as i32,
        slope_bound,
    })
}

/// One segment's `[C0, C1, C2, C3]` from its rounded end values `a0, a1` and its end
/// slopes `m0, m1` (the coefficients' unit): `C1`, `C2` rounded, `C3 = 8 (a1 − a0) − 4 C1
/// − 2 C2` exact, so that the cubic ends on `a1`; refused unless `|a0| < 2³⁰`,
/// `|C1| + |C2| + |C3| ≤ 2²⁹` and that sum times `2^z` within [`CORNER_STIFF_MAX`] (`z` =
/// 0 on the uniform grid, the octave in the graded corner, whose stiffness takes
/// `D << z`, `|D| ≤ |C1| + |C2| + ¾ |C3|`).
pub(super) fn rounded_cubic(
    a0: f64,
    a1: f64,
    m0: f64,
    m1: f64,
    z: i32,
) -> Result<[i32; 4], TableError> {
    let [c1, c2, _] = hermite(a0, a1, m0, m1);
    let (c1, c2) = (libm::round(c1), libm::round(c2));
    let c3 = 8.0 * (a1 - a0) - 4.0 * c1 - 2.0 * c2;
    let sum = libm::fabs(c1) + libm::fabs(c2) + libm::fabs(c3);
    if libm::fabs(a0) >= (1u64 << 30) as f64
        || sum > (1u64 << 29) as f64
        || libm::ldexp(sum, z) > CORNER_STIFF_MAX
    {
        return Err(TableError::OutOfRange);
    }
    Ok([a0 as i32, c1 as i32, c2 as i32, c3 as i32])
}

/// The stiffness scale `(stiff_scale, stiff_post)`: dF/dε (Q16) = (D / 2) · sps ·
/// 2^(16 − 20 − shift) for D = 2 dF/dτ, sps = 1/step segments per strain:
/// ⌊D · M / 2³²⌋ with M = sps · 2^(27 − shift) (at least sps · 2¹⁵ significant: `shift`
/// ≤ 12), a power of two moved into `stiff_post` while M would not fit.
pub(super) fn stiffness_scale(
    grid: &Grid,
    shift: u32,
    slope_bound: f64,
) -> Result<(i32, i32), TableError> {
    let (unit, scale) = ((1u64 << FORCE_FRAC) as f64, (1u64 << shift) as f64);
    let sps = 1.0 / grid.step;
    let k_bound = slope_bound / (scale * unit) * sps * (1u64 << STIFF_FRAC) as f64;
    if k_bound.is_nan() || k_bound > (1u64 << 30) as f64 {
        return Err(TableError::OutOfRange);
    }
    with_post(sps * libm::ldexp(1.0, 27 - shift as i32))
}

/// A knot's value (Q20 N, as an `f64`) in the coefficients' unit Q(20 + `shift`):
/// rounded, plus [`knot_bias`], so that the evaluation's final `>> shift` rounds to the
/// nearest Q20 N instead of flooring.
pub(super) fn knot_units(value: f64, shift: u32) -> f64 {
    libm::round(libm::ldexp(value, shift as i32)) + knot_bias(shift) as f64
}

/// A positive scale `v` as `(⌊v / 2^p⌉, 2^p)`, the least power `p` (< 30) that brings it
/// below 2³¹ − 1.
pub(super) fn with_post(mut v: f64) -> Result<(i32, i32), TableError> {
    let mut post = 0u32;
    while v >= (1u64 << 31) as f64 - 1.0 && post < 30 {
        v /= 2.0;
        post += 1;
    }
    if v >= (1u64 << 31) as f64 - 1.0 {
        return Err(TableError::OutOfRange);
    }
    Ok((libm::round(v) as i32, 1i32 << post))
}

/// A graded corner's largest values in Q20 N units (for the coefficients' shift).
#[derive(Clone, Copy, Default)]
pub(super) struct Magnitude {
    /// The largest knot.
    pub(super) value: f64,
    /// The largest `|C1| + |C2| + |C3|`.
    pub(super) poly: f64,
    /// The largest `(|C1| + |C2| + |C3|) · 2^z` in octave `z`: the stiffness takes
    /// `D << z`.
    pub(super) stiff: f64,
}

/// The bound on a graded corner's `(|C1| + |C2| + |C3|) · 2^z` in octave `z` (the
/// coefficients' unit): `D << z` within `i32` (`|D| ≤ |C1| + |C2| + ¾ |C3|`), with room
/// for the halving Horner steps' flooring. The sum's own bound, 2²⁹, would hold a
/// corner's steepest stiffness times its length to about 2,048 N in Q20, short of a soft
/// series spring's lower corner
/// (`the_long_runs_soft_series_spring_meets_the_bound_with_its_lower_corner`).
pub(super) const CORNER_STIFF_MAX: f64 = (1u64 << 31) as f64 - (1u64 << 24) as f64;
