//! The coupling's force between proxy and probe, held to the device's maximum, and the
//! ratios behind it and behind a slip: no division, one reciprocal square root each.

use super::{G_FRAC, ONE_G};
use crate::coupling::CouplingQ;
use crate::q::{self, mul_wide, sat, V3};
use crate::units::{FORCE_FRAC, LEN_FRAC, VEL_FRAC};

/// Q24 mm · Q16 N/mm and Q16 mm/s · Q24 N·s/mm are Q40: Q20 N after `>> COUPLING_SH`.
const COUPLING_SH: u32 = LEN_FRAC + 16 - FORCE_FRAC;
const _: () = assert!(VEL_FRAC + 24 - FORCE_FRAC == COUPLING_SH);

/// The coupling's spring force (Q20 N) between the proxy's centre and the probe (Q24 mm).
#[inline(always)]
pub(super) fn spring(coupling: &CouplingQ, proxy: V3, probe: V3) -> V3 {
    core::array::from_fn(|k| {
        sat(mul_wide(proxy[k].saturating_sub(probe[k]), coupling.stiffness) >> COUPLING_SH)
    })
}

/// The coupling's damping force (Q20 N) for a closing speed along the normal (Q16 mm/s).
#[inline(always)]
pub(super) fn damping(coupling: &CouplingQ, closing: i32) -> i32 {
    sat(mul_wide(closing, coupling.damping) >> COUPLING_SH)
}

/// `f` (Q20 N) held to `max` in magnitude, never above it: the squares in Q12 from each
/// component's magnitude rounded up (an estimate never below |f|), the scale from below
/// (`scale_to`), the scaled components truncated toward zero.
#[inline(always)]
pub(super) fn held(f: V3, max: i32) -> V3 {
    let up = |x: i32| ((x.unsigned_abs() >> 8) + 1) as i32;
    let f2: i64 = f.iter().map(|&x| mul_wide(up(x), up(x))).sum();
    if f2 <= mul_wide(max >> 8, max >> 8) {
        return f;
    }
    let lambda = scale_to(max >> 8, f2);
    f.map(|x| {
        let m = mul_wide(x.saturating_abs(), lambda) >> G_FRAC;
        sat(if x < 0 { -m } else { m })
    })
}

/// `r / √x` in Q16 for `0 < r` and `r² < x` (a value below 1): `x` a square in the
/// square of `r`'s format. Two Newton steps for `1/√M`, `M ∈ [¼, 1)` the normalised
/// `x`, from a table's first guess (within 4e-3), in 32-bit products: within 2e-8;
/// the result is then floored and lowered by one unit (1.5e-5 of one), so that it is
/// never above the exact value and a force scaled by it stays within its limit.
pub(super) fn scale_to(r: i32, x: i64) -> i32 {
    // r/√x = r · y · 2^(e/2 − 62), y Q30: in Q16, r · y >> (46 − e/2) (e is even).
    let (y, e) = q::rsqrt(x);
    let sh = 46 - (e >> 1);
    sat((q::mul_wide_u(r.max(0) as u32, y) >> sh) as i64)
        .min(ONE_G)
        .saturating_sub(1)
        .max(0)
}

/// `tan x` for `0 ≤ x ≤ 0.7` (start-up: the hysteresis cone, `x = 0.6 atan μ_k ≤ 0.665`),
/// as `sin x / cos x` from their Taylor series to `x¹⁵` and `x¹⁴`: the first omitted
/// terms are below `0.7¹⁷/17! = 6e-18` and `0.7¹⁶/16! = 2e-16`, so the result is within
/// 1e-15 relative of `tan` (tested against `std`). libm's `tan` costs 6 KiB of flash
/// (its argument reduction), `tanf` 4.6 KiB; this costs a few hundred bytes.
pub(super) fn tan_small(x: f64) -> f64 {
    let x2 = x * x;
    let (mut sin, mut cos) = (0.0, 0.0);
    // Horner from the highest term: sin = x Σ (−x²)^k/(2k+1)!, cos = Σ (−x²)^k/(2k)!.
    for k in (0..8u32).rev() {
        let (s_den, c_den) = ((2 * k + 2) * (2 * k + 3), (2 * k + 1) * (2 * k + 2));
        sin = 1.0 - x2 * sin / s_den as f64;
        cos = 1.0 - x2 * cos / c_den as f64;
    }
    x * sin / cos
}

#[cfg(test)]
mod tests {
    /// `rsqrt` against `f64` over its whole domain (1 … 2⁶³, log-spaced, and each power of
    /// two's neighbours), within 2e-8 relative (the measured figure printed); `scale_to`
    /// never above the exact ratio.
    #[test]
    fn rsqrt_matches_f64() {
        let mut worst = 0.0f64;
        let mut xs: Vec<i64> = (0..63)
            .flat_map(|k| [(1i64 << k) - 1, 1i64 << k, (1i64 << k) + 1])
            .collect();
        xs.extend((0..20_000).map(|i| 2f64.powf(i as f64 * 63.0 / 20_000.0) as i64));
        xs.push(i64::MAX);
        for x in xs.into_iter().filter(|&x| x > 0) {
            let (y, e) = crate::q::rsqrt(x);
            let got = y as f64 * 2f64.powf(e as f64 / 2.0 - 62.0);
            worst = worst.max((got * (x as f64).sqrt() - 1.0).abs());
        }
        println!("RSQRT max_rel_err={worst:.1e}");
        // Its normalisation by 32-bit halves against the 64-bit one, at every power of
        // two and its neighbours, and at 10⁵ random values of every size.
        let mut k = 7u64;
        let powers = (0..64).flat_map(|b| [(1u64 << b) - 1, 1u64 << b, (1u64 << b) + 1]);
        let random = (0..100_000u32).map(|i| {
            k = k
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            k >> (i % 64)
        });
        for x in powers.chain(random).chain([u64::MAX]).filter(|&x| x > 0) {
            let e = x.leading_zeros() & !1;
            let want = (((x << e) >> 34) as u32, e);
            assert_eq!(crate::q::normalise(x), want, "{x:#x}");
        }
        assert!(worst < 2e-8, "worst relative error {worst:e}");
        // scale_to: within two Q16 units of r/√x, and never above it, over ratios from
        // 1e-4 to 1 and squares of every size.
        let mut k = 1u64;
        for i in 0..20_000u32 {
            k = k
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let r = (((k >> 33) as i32) & 0x3FFF_FFFF).max(1) >> (i % 30);
            let ratio = 1e-4 + (i as f64 / 20_000.0) * (1.0 - 1e-4);
            let x = ((r.max(1) as f64 / ratio).powi(2)) as i64;
            if x <= (r as i64).pow(2) {
                continue;
            }
            let want = r as f64 / (x as f64).sqrt() * 65536.0;
            let got = super::scale_to(r, x) as f64;
            assert!(got <= want && want - got <= 2.0, "{r} {x}: {got} vs {want}");
        }
    }

    /// `tan_small` against `std` over its whole domain.
    #[test]
    fn tan_small_matches_std() {
        let mut worst = 0.0f64;
        for i in 1..=70_000 {
            let x = i as f64 * 1e-5;
            let rel = (super::tan_small(x) - x.tan()).abs() / x.tan();
            worst = worst.max(rel);
        }
        assert!(worst < 1e-15, "worst relative error {worst:e}");
        assert_eq!(super::tan_small(0.0), 0.0);
    }
}
