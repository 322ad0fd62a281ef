//! `ForceTable`: the inverse MCCS law `F(ε)` tabulated for constant-time fixed-point
//! evaluation (the paper's MATLAB `finverse` step, made fit for a microcontroller).
//!
//! # Layout
//! Only where the law is curved is it tabulated: from the end of the straight line `k ε`
//! (`Δ(min(F_T, P))`) to the solid point `Δ(F_C)`, clipped to the strain domain, on a grid
//! uniform in strain with `S` segments (`S + 1` knots). Below it the law is the exact line
//! of slope `k`; above `Δ(F_C)` the exact line of slope `k_p`. Where the domain cuts the
//! curved part short, the line beyond the domain edge is the tangent there (an
//! under-estimate of the stiffening law above the edge). With a preload above `F_T` the
//! grid is placed so that a knot sits on the slope kink `Δ(P)`.
//!
//! Each segment holds the cubic Hermite polynomial through its two knots with the exact
//! analytic slopes `dF/dε` there (scaled down by the Fritsch–Carlson limiter only where
//! the law bends harder than the grid resolves, so that the curve stays monotone), as
//! power-basis coefficients in `t ∈ [0, 1)`: `3 × i32` per segment, the cubic coefficient
//! implied by the next knot (812 bytes in all for 65 knots), so each segment ends
//! bit-exactly on the next knot; the straight lines are anchored on the end knots (at the
//! kink, the line through zero with `k` rounded down), so the curve is continuous and
//! monotone.
//!
//! # Formats and ranges
//! - strain: [`Strain`] = `I8F24`, range ±128, resolution 6.0e-8;
//! - force: [`Force`] = `I12F20` in N, range ±2048 N, resolution 9.5e-7 N;
//! - stiffness: [`Stiffness`] = `I16F16` in N per unit strain, range ±32768, resolution 1.5e-5;
//! - coefficients: knot values Q(20 + `value_shift`), `c1, c2` Q(20 + `poly_shift`), the
//!   shifts chosen per table.
//!
//! Evaluation saturates: a force beyond the format clamps to ±2048 N (`Force::MAX`/`MIN`).
//!
//! # Cost
//! Segment lookup is one subtract and one multiply (no search, no division); the value is
//! a 3-multiply Horner step in a Q16 segment parameter ([`mul_q16`]), the stiffness 2 more
//! and one scaling multiply. No loop; the only branch is which of the three pieces the
//! strain falls in. Measured: 88 instructions on a Cortex-M4F, 211 on a Cortex-M0 (QEMU).
//!
//! # Accuracy (measured by `host-tests/tests/table_accuracy.rs`, see README)
//! Table 2 spring, domain [−0.5, 0.95], 65 knots: max |ΔF| 5.6e-7 · F(0.95), stiffness
//! within 9.0e-6 relative.

use crate::law::Law;
use crate::params::{ParamError, Params};
use crate::{Force, Stiffness, Strain};
use core::fmt;

const STRAIN_FRAC: u32 = 24;
const FORCE_FRAC: u32 = 20;
const STIFF_FRAC: u32 = 16;
/// Fraction bits of the segment coordinate `u = (ε − ε_lo) · segments per unit strain`.
const U_FRAC: u32 = 16;

/// The default strain domain `[ε_min, ε_max]`.
pub const DEFAULT_DOMAIN: (f64, f64) = (-0.5, 0.95);

/// The raw contents of a [`ForceTable`], as emitted by `mccs table` for `include!`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RawTable<const S: usize> {
    /// Lower end of the tabulated strain range (Q24).
    pub strain_lo: i32,
    /// Upper end of the tabulated strain range (Q24).
    pub strain_hi: i32,
    /// Segments per unit strain (Q16).
    pub segments_per_strain: i32,
    /// The line below `strain_lo` passes through (`anchor_lo`, `force_lo`) (Q24, Q20 N):
    /// through zero when the table starts at the kink, else through the first knot.
    pub anchor_lo: i32,
    /// See `anchor_lo`.
    pub force_lo: i32,
    /// Slope of the line below `strain_lo` (Q16 N per unit strain).
    pub stiffness_lo: i32,
    /// The line above `strain_hi` passes through (`strain_hi`, `force_hi`) (Q20 N).
    pub force_hi: i32,
    /// Slope of the line above `strain_hi` (Q16 N per unit strain).
    pub stiffness_hi: i32,
    /// Extra fraction bits of the knot values `c0`: Q(20 + `value_shift`) N, 0 … 10.
    pub value_shift: u32,
    /// Extra fraction bits of `c1, c2, c3`: Q(20 + `poly_shift`) N, `value_shift` … 24.
    pub poly_shift: u32,
    /// Per segment `[c0, c1, c2]` of `F(t) = c0 + c1 t + c2 t² + c3 t³`, `t ∈ [0, 1)`:
    /// `c0` is the knot value, and `c3` is implied, since the cubic ends on the next knot:
    /// `c3 = ((c0' − c0) << (poly_shift − value_shift)) − c1 − c2`. The shifts are chosen
    /// per table so that each part uses most of `i32`: the knots keep sub-Q20 precision,
    /// and a small slope under a large force keeps its resolution.
    pub segments: [[i32; 3]; S],
    /// The last knot's value, Q(20 + `value_shift`) N.
    pub knot_last: i32,
}

/// A tabulated inverse law with `S` segments (`S + 1` knots); see the module docs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ForceTable<const S: usize> {
    raw: RawTable<S>,
}

/// 16 segments, 17 knots, 256 bytes of coefficients.
pub type ForceTable16 = ForceTable<16>;
/// 32 segments, 33 knots, 512 bytes of coefficients.
pub type ForceTable32 = ForceTable<32>;
/// 64 segments, 65 knots, 1 KiB of coefficients: the project default.
pub type ForceTable64 = ForceTable<64>;
/// 128 segments, 129 knots, 2 KiB of coefficients.
pub type ForceTable128 = ForceTable<128>;

/// Why a table could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableError {
    /// The spring parameters are invalid.
    Param(ParamError),
    /// The domain bounds are not finite, not ordered, or outside ±127.
    BadDomain,
    /// The domain does not reach into the nonlinear phase `(Δ(F_T), Δ(F_C))`.
    NoNonlinearPhase,
    /// The nonlinear phase inside the domain is too narrow for `S` segments at Q16.
    TooNarrow,
    /// A force or stiffness in the table exceeds its fixed-point format.
    OutOfRange,
    /// Fewer than one segment.
    NoSegments,
}

impl From<ParamError> for TableError {
    fn from(e: ParamError) -> Self {
        Self::Param(e)
    }
}

impl fmt::Display for TableError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Param(e) => e.fmt(f),
            Self::BadDomain => f.write_str("domain: bounds must be finite, within ±127, and from < to"),
            Self::NoNonlinearPhase => f.write_str(
                "domain: does not reach into the nonlinear phase (Δ(F_T), Δ(F_C)) of this spring",
            ),
            Self::TooNarrow => {
                f.write_str("domain: the nonlinear phase inside it is too narrow for this many knots")
            }
            Self::OutOfRange => f.write_str(
                "params: forces or stiffnesses in the domain exceed the fixed-point formats (±2048 N, ±32768 N/strain)",
            ),
            Self::NoSegments => f.write_str("knots: at least 2 are needed"),
        }
    }
}

impl core::error::Error for TableError {}

/// `(a · t) >> 16` for a Q16 `t ∈ [0, 65535]`, exact floor.
///
/// Cores with a 32 × 32 → 64 multiply (everything but Cortex-M0) use it; the M0 splits
/// `a = hi·2^16 + lo` (`lo ∈ [0, 65535]`): `(a·t) >> 16 = hi·t + (lo·t) >> 16` exactly,
/// and neither product overflows 32 bits for `t ≤ 65535`. Both give the same bits.
#[inline(always)]
pub fn mul_q16(a: i32, t: i32) -> i32 {
    #[cfg(core = "m0")]
    {
        let hi = a >> 16;
        let lo = (a & 0xFFFF) as u32;
        hi.wrapping_mul(t)
            .wrapping_add(((lo * t as u32) >> 16) as i32)
    }
    #[cfg(not(core = "m0"))]
    {
        // t ∈ [0, 65535]: through u16, so the compiler knows it is not negative.
        ((a as i64 * (t as u16) as i64) >> 16) as i32
    }
}

fn q(x: f64, frac: u32) -> Option<i32> {
    let v = libm::round(x * (1u64 << frac) as f64);
    if v.is_finite() && v >= i32::MIN as f64 && v <= i32::MAX as f64 {
        Some(v as i32)
    } else {
        None
    }
}

#[inline(always)]
fn sat_i32(x: i64) -> i32 {
    x.clamp(i32::MIN as i64, i32::MAX as i64) as i32
}

impl<const S: usize> ForceTable<S> {
    /// Builds the table for `params` over the default domain [−0.5, 0.95].
    pub fn new(params: &Params) -> Result<Self, TableError> {
        Self::with_domain(params, DEFAULT_DOMAIN.0, DEFAULT_DOMAIN.1)
    }

    /// Builds the table for `params` over the strain domain `[from, to]`.
    ///
    /// Runs the `f64` law (software floating point on most cores): call it at start-up or
    /// on the host (`mccs table`), never per tick.
    pub fn with_domain(params: &Params, from: f64, to: f64) -> Result<Self, TableError> {
        let law = Law::new(params)?;
        Self::from_law(&law, from, to)
    }

    /// Builds the table for an already derived law.
    #[inline(never)]
    pub fn from_law(law: &Law, from: f64, to: f64) -> Result<Self, TableError> {
        if S == 0 {
            return Err(TableError::NoSegments);
        }
        if !(from.is_finite() && to.is_finite() && from < to && from > -127.0 && to < 127.0) {
            return Err(TableError::BadDomain);
        }
        let (e_t, e_c) = (law.strain_t(), law.strain_c());
        // Whether the table starts at the kink and ends at the solid point (exact lines
        // beyond), decided before the ends are rounded to the strain format.
        let (at_kink, at_solid) = (from <= e_t, to >= e_c);
        let lo = if at_kink { e_t } else { from };
        let hi = if at_solid { e_c } else { to };
        if hi <= lo {
            return Err(TableError::NoNonlinearPhase);
        }
        // A preload above F_T puts the law's one slope kink, Δ(P), inside the table. The
        // grid is then placed so that a knot falls on it, and the two segments meeting
        // there get the two one-sided slopes: the first knot moves down (into the exact
        // linear phase, or below the domain) by less than a segment, and the step grows
        // only if the table would otherwise end short of `hi`.
        let e_p = law.delta(law.preload);
        let mut kink_knot = None;
        let mut lo_grid = lo;
        let mut width = hi - lo;
        if law.preload > law.f_t && e_p > lo && e_p < hi {
            let mut step = width / S as f64;
            let j = libm::ceil((e_p - lo) / step);
            if j < S as f64 {
                step = libm::fmax(step, (hi - e_p) / (S as f64 - j));
                lo_grid = e_p - j * step;
                width = S as f64 * step;
                kink_knot = Some(j as usize);
            }
        }
        let strain_lo = q(lo_grid, STRAIN_FRAC).ok_or(TableError::BadDomain)?;
        let grid_moved = lo_grid < lo;
        let lo = strain_lo as f64 / (1u64 << STRAIN_FRAC) as f64;
        let per_strain = q(S as f64 / width, U_FRAC).ok_or(TableError::TooNarrow)?;
        if per_strain <= 0 {
            return Err(TableError::TooNarrow);
        }
        // The evaluation places knot i at lo + i / per_strain: build at exactly those strains.
        let step = (1u64 << U_FRAC) as f64 / per_strain as f64;
        let unit = (1u64 << FORCE_FRAC) as f64;
        // Knot i: force, and the slopes dF/dt (per segment) from below and from above,
        // all in Q20 N units, unrounded.
        let knot = |i: usize| -> Result<(f64, f64, f64), TableError> {
            let e = lo + i as f64 * step;
            let f = law.force(e);
            // At a kink, the one-sided slopes at the kink itself (the knot's strain is
            // rounded, and may sit a hair to either side). The first knot's segment lies
            // above the kink it starts at.
            let f_slope = if kink_knot == Some(i) {
                law.preload
            } else if i == 0 && at_kink && !grid_moved {
                libm::fmax(f, law.first_kink())
            } else {
                f
            };
            let below = 1.0 / law.compliance(f_slope);
            let above = 1.0 / law.compliance_above(f_slope);
            if !(libm::fabs(f * unit) < (1u64 << 31) as f64
                && below.is_finite()
                && above.is_finite())
            {
                return Err(TableError::OutOfRange);
            }
            Ok((f * unit, below * step * unit, above * step * unit))
        };
        // First pass: the largest knot value and the largest polynomial coefficient bound
        // (|c1|, |c2|, |c3| ≤ 3|secant| + 3 max|slope|) pick the two shifts.
        let (mut big_value, mut big_poly) = (1.0f64, 1.0f64);
        let mut prev = knot(0)?;
        for i in 0..=S {
            let k = if i == 0 { prev } else { knot(i)? };
            let secant = libm::fabs(k.0 - prev.0);
            let slopes = libm::fmax(libm::fabs(k.1), libm::fabs(prev.2));
            big_value = libm::fmax(big_value, libm::fabs(k.0));
            big_poly = libm::fmax(big_poly, 3.0 * secant + 3.0 * slopes);
            prev = k;
        }
        let fits = |big: f64, shift: u32| big * (1u64 << shift) as f64 <= (1u64 << 29) as f64;
        let mut value_shift = 0u32;
        while value_shift < 10 && fits(big_value, value_shift + 1) {
            value_shift += 1;
        }
        let mut poly_shift = value_shift;
        while poly_shift < 24 && fits(big_poly, poly_shift + 1) {
            poly_shift += 1;
        }
        let (vscale, pscale) = ((1u64 << value_shift) as f64, (1u64 << poly_shift) as f64);
        // Second pass: the segments, knots rounded to Q(20 + value_shift).
        let round_knot = |f: f64| -> f64 { libm::round(f * vscale) };
        let (f_first, _, m_first) = knot(0)?;
        let mut segments = [[0i32; 3]; S];
        let (mut a0, mut m0) = (round_knot(f_first), m_first);
        let a_first = a0;
        for (i, c) in segments.iter_mut().enumerate() {
            let (f1, m1, m1_above) = knot(i + 1)?;
            let a1 = round_knot(f1);
            // In the polynomial's scale: secant and end slopes.
            let secant = (a1 - a0) * (pscale / vscale);
            let (mut s0, mut s1) = (m0 * pscale, m1 * pscale);
            // Fritsch–Carlson: where the law bends harder than the grid resolves (a soft
            // cone against a stiff series spring, just below the solid point), scale the
            // end slopes of this segment into the circle α² + β² ≤ 9 that keeps the cubic
            // monotone. Smooth laws (Table 2) never reach it.
            if secant > 0.0 {
                let (al, be) = (s0 / secant, s1 / secant);
                let r2 = al * al + be * be;
                if r2 > 9.0 {
                    let tau = 3.0 / libm::sqrt(r2);
                    (s0, s1) = (tau * s0, tau * s1);
                }
            }
            let c1 = libm::round(s0);
            let c2 = libm::round(3.0 * secant - 2.0 * s0 - s1);
            let c3 = secant - c1 - c2; // exact: the segment ends on the next knot
            let limit = (1u64 << 30) as f64;
            if [a0, c1, c2, c3].iter().any(|v| libm::fabs(*v) >= limit) {
                return Err(TableError::OutOfRange);
            }
            *c = [a0 as i32, c1 as i32, c2 as i32];
            (a0, m0) = (a1, m1_above);
        }
        // The lines are anchored on the end knots floored to Q20: the table's own values
        // floor the same way, so the curve stays monotone across the anchors.
        let first_q20 = (a_first as i32) >> value_shift;
        let last_q20 = (a0 as i32) >> value_shift;
        let e_hi = lo + S as f64 * step;
        let strain_hi = q(e_hi, STRAIN_FRAC).ok_or(TableError::BadDomain)?;
        // Below the table: at the kink, the exact line `k ε` through zero, with `k` rounded
        // down so that the line never passes above the first knot (the curve stays
        // monotone; the step up at the knot is `(k − k_q) ε_lo` ≤ 2^-16 ε_lo N). Otherwise
        // the tangent at the domain edge, through the first knot. Above the table, the
        // line through the last knot: `k_p` when the table ends at the solid point, else
        // the tangent there.
        let (stiffness_lo, anchor_lo, force_lo) = if at_kink {
            let kq = libm::floor(law.k * (1u64 << STIFF_FRAC) as f64);
            if kq > i32::MAX as f64 {
                return Err(TableError::OutOfRange);
            }
            (kq as i32, 0, 0)
        } else {
            let kq =
                q(1.0 / law.compliance(law.force(lo)), STIFF_FRAC).ok_or(TableError::OutOfRange)?;
            (kq, strain_lo, first_q20)
        };
        let above = if at_solid {
            law.k_p
        } else {
            1.0 / law.compliance(law.force(e_hi))
        };
        let raw = RawTable {
            strain_lo,
            strain_hi,
            segments_per_strain: per_strain,
            anchor_lo,
            force_lo,
            stiffness_lo,
            force_hi: last_q20,
            stiffness_hi: q(above, STIFF_FRAC).ok_or(TableError::OutOfRange)?,
            value_shift,
            poly_shift,
            segments,
            knot_last: a0 as i32,
        };
        Ok(Self { raw })
    }

    /// Wraps raw contents (for tables emitted by `mccs table` and `include!`d).
    pub const fn from_raw(raw: RawTable<S>) -> Self {
        Self { raw }
    }

    /// The raw contents.
    pub const fn raw(&self) -> &RawTable<S> {
        &self.raw
    }

    /// Size of the table in bytes.
    pub const SIZE_BYTES: usize = core::mem::size_of::<RawTable<S>>();

    /// The tabulated strain range `[lo, hi]`.
    pub fn tabulated_range(&self) -> (Strain, Strain) {
        (
            Strain::from_bits(self.raw.strain_lo),
            Strain::from_bits(self.raw.strain_hi),
        )
    }

    /// The largest tangent stiffness anywhere on the curve (both lines, and every segment
    /// at its ends and middle), for stability bounds. A loop over the segments: call it
    /// at start-up, not per tick.
    pub fn max_stiffness(&self) -> Stiffness {
        let r = &self.raw;
        let mut max = r.stiffness_lo.max(r.stiffness_hi);
        let span = r.strain_hi.saturating_sub(r.strain_lo) as i64;
        for i in 0..=(2 * S) as i64 {
            let e = r.strain_lo as i64 + span * i / (2 * S) as i64;
            let (_, k) = self.force_and_stiffness(Strain::from_bits(e as i32));
            max = max.max(k.to_bits());
        }
        Stiffness::from_bits(max)
    }

    /// Force (N) at compressive strain `strain`; constant time, saturating, no panic.
    #[inline]
    pub fn force(&self, strain: Strain) -> Force {
        let r = &self.raw;
        let e = strain.to_bits();
        if e <= r.strain_lo {
            return line(r.force_lo, r.stiffness_lo, e, r.anchor_lo);
        }
        if e >= r.strain_hi {
            return line(r.force_hi, r.stiffness_hi, e, r.strain_hi);
        }
        let (c, t) = self.segment(e);
        Force::from_bits(value(r, &c, poly(&c, t)))
    }

    /// Force (N) and tangent stiffness `dF/dε` (N per unit strain) at `strain`;
    /// constant time, saturating, no panic.
    #[inline]
    pub fn force_and_stiffness(&self, strain: Strain) -> (Force, Stiffness) {
        let r = &self.raw;
        let e = strain.to_bits();
        if e <= r.strain_lo {
            let f = line(r.force_lo, r.stiffness_lo, e, r.anchor_lo);
            return (f, Stiffness::from_bits(r.stiffness_lo));
        }
        if e >= r.strain_hi {
            let f = line(r.force_hi, r.stiffness_hi, e, r.strain_hi);
            return (f, Stiffness::from_bits(r.stiffness_hi));
        }
        let (c, t) = self.segment(e);
        let f = value(r, &c, poly(&c, t));
        // dF/dt = c1 + 2 c2 t + 3 c3 t², then dF/dε = dF/dt · segments per strain.
        let c2x2 = c[2].saturating_mul(2);
        let c3x3 = c[3].saturating_mul(3);
        let dfdt = c[1].saturating_add(mul_q16(c2x2.saturating_add(mul_q16(c3x3, t)), t));
        let k = (dfdt as i64 * r.segments_per_strain as i64)
            >> (FORCE_FRAC + U_FRAC - STIFF_FRAC + r.poly_shift);
        (Force::from_bits(f), Stiffness::from_bits(sat_i32(k)))
    }

    /// The segment holding `e` (strictly inside the table) and the Q16 position in it.
    #[inline(always)]
    fn segment(&self, e: i32) -> ([i32; 4], i32) {
        let r = &self.raw;
        // e > strain_lo and segments_per_strain > 0: an unsigned 32 × 32 → 64 product.
        let u = (e.wrapping_sub(r.strain_lo) as u32 as u64 * r.segments_per_strain as u32 as u64)
            >> STRAIN_FRAC;
        let i = ((u >> U_FRAC) as usize).min(S - 1);
        let t = (u - ((i as u64) << U_FRAC)).min((1 << U_FRAC) - 1) as i32;
        let [c0, c1, c2] = r.segments[i];
        let next = if i + 1 < S {
            r.segments[i + 1][0]
        } else {
            r.knot_last
        };
        let secant = next.wrapping_sub(c0) << (r.poly_shift - r.value_shift);
        ([c0, c1, c2, secant.wrapping_sub(c1).wrapping_sub(c2)], t)
    }
}

/// `c1 t + c2 t² + c3 t³` in the polynomial's scale, Q(20 + `poly_shift`).
#[inline(always)]
fn poly(c: &[i32; 4], t: i32) -> i32 {
    let a = c[2].saturating_add(mul_q16(c[3], t));
    let a = c[1].saturating_add(mul_q16(a, t));
    mul_q16(a, t)
}

/// `c0 + poly` in Q20 N.
#[inline(always)]
fn value<const S: usize>(r: &RawTable<S>, c: &[i32; 4], poly: i32) -> i32 {
    c[0].saturating_add(poly >> (r.poly_shift - r.value_shift)) >> r.value_shift
}

/// `f0 + (k (e − e0)) >> 20` in Q20 N from a Q20 force, a Q16 slope and Q24 strains;
/// saturating. `k ≥ 0` and `|e − e0| < 2^32` keep the product within `i64`.
#[inline(always)]
fn line(f0: i32, k: i32, e: i32, e0: i32) -> Force {
    let de = e as i64 - e0 as i64;
    let df = (k as i64 * de) >> (STIFF_FRAC + STRAIN_FRAC - FORCE_FRAC);
    Force::from_bits(sat_i32(f0 as i64 + df))
}
