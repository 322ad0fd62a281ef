//! `Cap`: a tissue's rest surface shaped as a spherical cap, in fixed point:
//! node heights, the rest normal and the radial direction through a point, each by
//! products and at most one reciprocal square root ([`crate::q::rsqrt`]): no division.
//! The window's shifts and the proxy use them on the tick; the `f64` reference is
//! `mccs_host::roam::Tissue` with `Shape::Cap`.
//!
//! The cap has radius `R` (4/3 of the tissue's half-diagonal … 2000 mm); its top is at the
//! tissue's centre at `z = 0` and its centre at `(0, 0, −R)`: `z = √(R² − ρ²) − R` with
//! `ρ² = x² + y²`, and the rest normal at a surface point is `(x, y, z + R)/R`.
//!
//! Formats: positions Q24 mm in the tissue frame, `R` Q20 mm, directions Q29 rounded to a
//! Q15 grid (so that a product by one takes a 16-bit operand, [`N16_SH`]). Heights
//! are within `2e-8 R` of the sphere (the reciprocal square root's error; tested against
//! `f64` over whole tissues).

use crate::q::{mul_wide, mul_wide_u, mulhi_u, narrow, rsqrt, sat, V3};
use crate::units::from_f64;

/// Fraction bits of a direction.
pub(crate) const N_FRAC: u32 = 29;

/// A direction's low bits that are zero: its components lie on a Q15 grid within
/// `±(1 − 2⁻¹⁵)`, so that `c >> N16_SH` is exact and a 16-bit operand of [`crate::q::mul_s`]
/// (one 32 × 16 product: two 32-bit multiplies on the M0 instead of a 64-bit product),
/// whose `⌊a/2¹⁶⌋ · c · 2` stays within `i32` for every `a`.
pub(crate) const N16_SH: u32 = N_FRAC - 15;

/// `d` (Q29) rounded to nearest on the Q15 grid, held within `±(1 − 2⁻¹⁵)` (within `2⁻¹⁵`,
/// 3.1e-5, of `d` per component for a unit vector).
fn on_q15_grid(d: V3) -> V3 {
    // |c| ≤ 2³⁰ here (a unit vector's component to within its rounding): no wrap.
    d.map(|c| narrow::<N16_SH>(c).clamp(-0x7FFF, 0x7FFF) << N16_SH)
}

/// Largest cap radius, mm (`R` in Q20 within `i32`).
pub const MAX_CAP_RADIUS_MM: f64 = 2000.0;

/// A spherical cap over a `W × H` tissue at spacing `s`: a window's [`crate::shape::Shape`]
/// (built from a [`crate::shape::Sphere`] at start-up).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cap {
    /// `R`, Q20 mm.
    r: i32,
    /// `1/R` per mm as `inv_r · 2^−(31 + inv_sh)`, `inv_r` normalised within `[2³⁰, 2³¹)`
    /// (so that it keeps 31 significant bits at every radius).
    inv_r: i32,
    inv_sh: u32,
    /// `s²/(4R²)`, Q62: node `(i, j)`'s `ρ²/R²` is `m k` for the integer
    /// `m = (2i − W + 1)² + (2j − H + 1)²`.
    k: u64,
    w: i32,
    h: i32,
}

impl Cap {
    /// The cap of radius `radius` mm over a `w × h` tissue at `spacing` mm (start-up);
    /// `None` unless `radius` is within 4/3 of the tissue's half-diagonal … 2000 mm.
    pub(crate) fn new(radius: f64, w: usize, h: usize, spacing: f64) -> Option<Cap> {
        let hx = (w as f64 - 1.0) * spacing / 2.0;
        let hy = (h as f64 - 1.0) * spacing / 2.0;
        let half_diagonal = libm::sqrt(hx * hx + hy * hy);
        let ok = radius.is_finite()
            && radius >= 4.0 / 3.0 * half_diagonal
            && radius <= MAX_CAP_RADIUS_MM;
        // 1/R ≤ 0.53 (R ≥ 4/3 of the smallest tissue's half-diagonal, √2 mm).
        let mut inv_sh = 0;
        while ok && 1.0 / radius * libm::ldexp(1.0, 32 + inv_sh) < libm::ldexp(1.0, 31) {
            inv_sh += 1;
        }
        ok.then(|| Cap {
            r: from_f64(radius, 20),
            inv_r: from_f64(1.0 / radius, 31 + inv_sh as u32),
            inv_sh: inv_sh as u32,
            k: libm::round(spacing * spacing / (4.0 * radius * radius) * libm::ldexp(1.0, 62))
                as u64,
            w: w as i32,
            h: h as i32,
        })
    }

    /// Rest height of tissue node `(i, j)` (Q24 mm): `−R (1 − √(1 − q))` with
    /// `q = ρ²/R² ≤ 9/16`, `√(1 − q) = (1 − q) / √(1 − q)` in Q30.
    pub(crate) fn height(&self, i: i32, j: i32) -> i32 {
        // |2i − W + 1| ≤ 127: the squares fit i32.
        let sq = |d: i32| d.wrapping_mul(d) as u32;
        let m = sq(2 * i - self.w + 1).saturating_add(sq(2 * j - self.h + 1));
        // m k (m < 2¹⁵) held at 2⁶² by two 32 × 32 products (no 64-bit library product
        // on the M0): the high word's part alone reaches 2⁶² once it is 2³⁰.
        let hi = mul_wide_u(m, (self.k >> 32) as u32);
        let q = if hi >= 1 << 30 {
            1 << 62
        } else {
            ((hi << 32) + mul_wide_u(m, self.k as u32)).min(1 << 62)
        };
        // 1 − q in Q62, at least 7/16 of one for a node of the tissue (R ≥ 4/3 of its
        // half-diagonal): its leading zeros are 1 … 3, so rsqrt's e is 0 or 2.
        let x = ((1u64 << 62) - q).max(1 << 60);
        let (y, e) = rsqrt(x as i64);
        // 1/√(1 − q) = 2^31/√x = y 2^(e/2 − 31): in Q30, y 2^(e/2 − 1) (at most 1.52).
        let r30 = ((y as u64) << (e >> 1) >> 1) as u32;
        // √(1 − q) in Q30: (1 − q) Q30 · r30 Q30 = Q60, the high word Q28, << 2.
        let w30 = mulhi_u((x >> 32) as u32, r30) << 2;
        let sag = (1u32 << 30).saturating_sub(w30);
        // R Q20 · sag Q30 = Q50: Q24 after >> 26.
        sat(-(mul_wide(self.r, sag as i32) >> 26))
    }

    /// The rest normal at a rest surface point (tissue frame, Q24 mm): `(x, y, z + R)/R`,
    /// Q29 on the Q15 grid ([`N16_SH`]; a unit vector to the chord's sag, `s²/(8R²)`, and
    /// the grid's `2⁻¹⁵` per component).
    pub(crate) fn normal(&self, p: V3) -> V3 {
        // Q24 · Q(31 + sh) = Q(55 + sh): Q29 after >> (26 + sh).
        let scaled = |x: i32| sat(mul_wide(x, self.inv_r) >> (26 + self.inv_sh));
        on_q15_grid([
            scaled(p[0]),
            scaled(p[1]),
            (1i32 << N_FRAC).saturating_add(scaled(p[2])),
        ])
    }

    /// The unit vector from the cap's centre through `p` (tissue frame, Q24 mm), Q29 on the
    /// Q15 grid ([`N16_SH`]): the rest normal where that line meets the cap (within
    /// 1.5e-7 before the grid's `2⁻¹⁵`: `p` taken in Q16).
    pub(crate) fn radial(&self, p: V3) -> V3 {
        // In Q16 (|x|, |y| ≤ 128 mm and z + R ≤ 2128 mm fit i32): the squares by 32-bit
        // halves (no 64-bit library product on the M0), summed within i64.
        let d = [
            p[0] >> 8,
            p[1] >> 8,
            (p[2] >> 8).saturating_add(self.r >> 4),
        ];
        let (y, e) = rsqrt(d.iter().map(|&c| mul_wide(c, c)).sum());
        // d_k/|d| = d_k y 2^(e/2 − 62), y Q30 taken halved (within i32): in Q29,
        // d_k (y/2) >> (32 − e/2) (e/2 ≤ 17 here).
        let sh = 32 - (e >> 1);
        let half = (y >> 1) as i32;
        on_q15_grid(d.map(|c| sat(mul_wide(c, half) >> sh)))
    }

    /// `R`, Q20 mm.
    pub(crate) fn radius_q20(&self) -> i32 {
        self.r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Heights of every node of whole tissues, against `f64`, from the smallest radius
    /// the tissue allows to 2000 mm: within `2e-8 R + 2` Q24 units.
    #[test]
    fn heights_match_f64() {
        let mut worst = 0.0f64;
        for (w, h, s) in [(64, 64, 2.5), (3, 3, 1.0), (64, 17, 3.0), (9, 9, 20.0)] {
            let hx = (w as f64 - 1.0) * s / 2.0;
            let hy = (h as f64 - 1.0) * s / 2.0;
            let hd = (hx * hx + hy * hy).sqrt();
            for r in [4.0 / 3.0 * hd * 1.000001, 200.0_f64.max(1.5 * hd), 2000.0] {
                let cap = Cap::new(r, w, h, s).unwrap();
                for i in 0..w {
                    for j in 0..h {
                        let (x, y) = (i as f64 * s - hx, j as f64 * s - hy);
                        let want = (r * r - x * x - y * y).sqrt() - r;
                        let got = cap.height(i as i32, j as i32) as f64 / 2f64.powi(24);
                        let err = (got - want).abs();
                        worst = worst.max(err / r);
                        assert!(
                            err <= 2e-8 * r + 2.0 / 2f64.powi(24),
                            "{w}x{h} s {s} R {r} ({i},{j}): {got} vs {want}"
                        );
                    }
                }
            }
        }
        println!("CAP height_rel_err={worst:.2e}");
    }

    /// The rest normal and the radial direction against `f64`, within 1e-8 and 1.5e-7 (the
    /// radial line's point taken in Q16: 1.5e-5 mm over the cap's 150 mm) plus one Q15
    /// step (the grid they are rounded to, held within `1 − 2⁻¹⁵`), and on that grid.
    #[test]
    fn directions_match_f64() {
        let r = 150.0;
        let cap = Cap::new(r, 64, 64, 2.5).unwrap();
        let q24 = |x: f64| from_f64(x, 24);
        let unq = |x: i32| {
            assert_eq!(x & ((1 << N16_SH) - 1), 0, "{x} off the Q15 grid");
            x as f64 / 2f64.powi(29)
        };
        for (x, y) in [(0.0, 0.0), (78.75, -78.75), (-30.0, 55.5), (1.25, 0.0)] {
            let z = (r * r - x * x - y * y).sqrt() - r;
            let n = cap.normal([q24(x), q24(y), q24(z)]).map(unq);
            let want = [x / r, y / r, (z + r) / r];
            let step = 1.0 / 32768.0;
            for k in 0..3 {
                assert!(
                    (n[k] - want[k]).abs() < 1e-8 + step,
                    "normal at ({x}, {y}): {n:?}"
                );
            }
            // A point 3 mm below the surface along the normal: the same direction.
            let p = [0, 1, 2].map(|k| [x, y, z][k] - 3.0 * want[k]);
            let d = cap.radial(p.map(q24)).map(unq);
            for k in 0..3 {
                assert!(
                    (d[k] - want[k]).abs() < 1.5e-7 + step,
                    "radial at ({x}, {y}): {d:?}"
                );
            }
        }
    }

    /// Radii outside 4/3 of the half-diagonal … 2000 mm are refused.
    #[test]
    fn radii_out_of_range_are_refused() {
        // 64 × 64 at 2.5 mm: half-diagonal 111.37 mm.
        assert!(Cap::new(148.0, 64, 64, 2.5).is_none());
        assert!(Cap::new(148.5, 64, 64, 2.5).is_some());
        assert!(Cap::new(2000.0, 64, 64, 2.5).is_some());
        for bad in [2000.1, f64::NAN, f64::INFINITY, -150.0] {
            assert!(Cap::new(bad, 64, 64, 2.5).is_none(), "{bad}");
        }
    }
}
