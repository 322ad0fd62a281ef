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
//! power-basis coefficients in `τ ∈ [0, 1)`, stored as `[c0, 2c1, 4c2, 8c3]` (`4 × i32`
//! per segment, 1072 bytes in all for 65 knots) so that each Horner step is one product
//! by `τ/2` ([`mul_t`]). `8c3 = 8(c0' − c0) − 4(2c1) − 2(4c2)` exactly, so each segment
//! ends bit-exactly on the next knot; the straight lines are anchored on the end knots (at
//! the kink, the line through zero with `k` rounded down), so the curve is continuous and
//! monotone.
//!
//! # Formats and ranges
//! - strain: [`Strain`] = `I8F24`, range ±128, resolution 6.0e-8;
//! - force: [`Force`] = `I12F20` in N, range ±2048 N, resolution 9.5e-7 N;
//! - stiffness: [`Stiffness`] = `I16F16` in N per unit strain, range ±32768, resolution 1.5e-5;
//! - position in a segment `τ`: Q15;
//! - coefficients: Q(20 + `shift`) N, the shift (0 … 12) chosen per table so that the
//!   knots use most of an `i32` and no Horner step can overflow.
//!
//! Evaluation saturates: a force beyond the format clamps to ±2048 N (`Force::MAX`/`MIN`).
//!
//! # Cost
//! The segment and `τ` come from one subtract, one multiply by a power of two and one
//! unsigned high-word product (no search, no division); the value is three Horner steps
//! (one `smmla` each on the M3/M4), the stiffness two more and one scaling product. No
//! loop; the only branch is which of the three pieces the strain falls in. Every product
//! has exact floor semantics, and the Cortex-M0 builds them from 16-bit pieces with the
//! same bits ([`crate::q`]). Measured (QEMU, averaged over strains on both lines and the
//! cubic part, the call included): 33 instructions on a Cortex-M4F, 37 on an M3, 90 on an
//! M0.
//!
//! # Accuracy (measured by `host-tests/tests/table_accuracy.rs`, see README)
//! Table 2 spring, domain [−0.5, 0.95], 65 knots: max |ΔF| 9.4e-7 · F(0.95), stiffness
//! within 1.0e-5 relative.

use crate::law::Law;
use crate::params::{ParamError, Params};
use crate::q::{mul_s_by, mul_t, mul_wide, mulhi, mulhi_u, shr_held};
use crate::{Force, Stiffness, Strain};
use core::fmt;

const STRAIN_FRAC: u32 = 24;
const FORCE_FRAC: u32 = 20;
const STIFF_FRAC: u32 = 16;

/// The default strain domain `[ε_min, ε_max]`.
pub const DEFAULT_DOMAIN: (f64, f64) = (-0.5, 0.95);

/// The raw contents of a [`ForceTable`], as emitted by `mccs table` for `include!`.
/// In declaration order (`repr(C)`): the header before the segments, so that the
/// Cortex-M0 reaches every header field with an immediate offset (Thumb-1 loads reach
/// 124 bytes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct RawTable<const S: usize> {
    /// Lower end of the tabulated strain range (Q24).
    pub strain_lo: i32,
    /// Upper end of the tabulated strain range (Q24), exclusive.
    pub strain_hi: i32,
    /// The segment coordinate of a strain `e` inside the table, Q15 segments, is
    /// `⌊(e − strain_lo) · index_pre · index_scale / 2³²⌋` (unsigned; `index_pre` a power
    /// of two that puts the table's width at the top of a `u32`).
    pub index_pre: u32,
    /// See `index_pre`.
    pub index_scale: u32,
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
    /// The coefficients' unit: Q(20 + `shift`) N, `shift` ∈ 0 … 12.
    pub shift: u32,
    /// The stiffness in Q16 is `⌊D · stiff_scale / 2³²⌋ · stiff_post` for `D = 2 dF/dτ` in
    /// the coefficients' unit (`stiff_post` a power of two).
    pub stiff_scale: i32,
    /// See `stiff_scale`.
    pub stiff_post: i32,
    /// Per segment `[C0, C1, C2, C3] = [c0, 2 c1, 4 c2, 8 c3]` of the cubic
    /// `F(τ) = c0 + c1 τ + c2 τ² + c3 τ³`, `τ ∈ [0, 1)`: the degree-`j` coefficient carries
    /// `2^j` so that each Horner step is one product by `τ/2` ([`crate::q::mul_t`]).
    /// `c0` is the knot value and `C3 = 8 (c0' − c0) − 4 C1 − 2 C2` makes the cubic end
    /// on the next knot `c0'` exactly.
    pub segments: [[i32; 4]; S],
}

/// A tabulated inverse law with `S` segments (`S + 1` knots); see the module docs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct ForceTable<const S: usize> {
    // First, with the raw header next, for the same reason as [`RawTable`]'s order.
    narrow: Narrow,
    raw: RawTable<S>,
}

/// What [`ForceTable::force_narrow`] needs beyond the raw table, derived from it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Narrow {
    /// `index_scale` without its zero low bits (15 significant bits), and the shift that
    /// takes `⌊de · scale / 2¹⁶⌋` to the Q15 segment coordinate.
    scale: u32,
    scale_sh: u32,
    lo: NarrowLine,
    hi: NarrowLine,
}

/// A straight line's slope in 15 bits: `⌊Δe · k / 2^sh1⌋ >> sh2` is Q20 N for a Q24 `Δe`,
/// with `Δe` held at `hold` on the side away from the table (below it for the line
/// below, above it for the line above; the other side is the table's own range) so that
/// the product stays within 2³⁰ (1024 N) and its sum with the line's anchor force fits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct NarrowLine {
    k: i32,
    sh1: u8,
    sh2: u8,
    hold: i32,
}

impl NarrowLine {
    /// From a Q16 slope and the line's anchor force (Q20 N).
    const fn new(k: i32, f0: i32) -> Self {
        let mag = k.unsigned_abs();
        let kn = (32 - mag.leading_zeros()).saturating_sub(15);
        // Q24 · Q(16 − kn) / 2^(20 − kn) = Q20.
        let sh = 20 - kn;
        let (sh1, sh2) = if sh > 16 { (16, sh - 16) } else { (sh, 0) };
        // Rounded: within 2⁻¹⁵ of k, and at most 2¹⁵ in magnitude.
        let k16 = if kn == 0 {
            k
        } else {
            ((k as i64 + (1i64 << (kn - 1))) >> kn) as i32
        };
        let hold = if k16 == 0 {
            i32::MAX
        } else {
            // |product| ≤ min(2³⁰, 2³¹ − 1 − |f0|).
            let room = i32::MAX as i64 - f0.unsigned_abs() as i64;
            let cap = if room < (1i64 << 30) {
                room
            } else {
                1i64 << 30
            };
            let h = (cap << sh) / k16.unsigned_abs() as i64;
            if h > i32::MAX as i64 {
                i32::MAX
            } else {
                h as i32
            }
        };
        Self {
            k: k16,
            sh1: sh1 as u8,
            sh2: sh2 as u8,
            hold,
        }
    }

    /// `f0 + k (e − e0)` in Q20 N, `e − e0` held at `−hold` below (the line below the
    /// table: `e ≤ strain_lo`, so `e − e0` is at most the table's own rise above).
    #[inline(always)]
    fn below(&self, f0: i32, e: i32, e0: i32) -> i32 {
        let de = e.wrapping_sub(e0).max(-self.hold);
        f0.wrapping_add(mul_s_by(de, self.k, self.sh1 as u32) >> self.sh2)
    }

    /// `f0 + k (e − e0)` in Q20 N, `e − e0 ≥ 0` held at `hold` above (the line above).
    #[inline(always)]
    fn above(&self, f0: i32, e: i32, e0: i32) -> i32 {
        let de = e.wrapping_sub(e0).min(self.hold);
        f0.wrapping_add(mul_s_by(de, self.k, self.sh1 as u32) >> self.sh2)
    }
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

fn q(x: f64, frac: u32) -> Option<i32> {
    let v = libm::round(x * (1u64 << frac) as f64);
    if v.is_finite() && v >= i32::MIN as f64 && v <= i32::MAX as f64 {
        Some(v as i32)
    } else {
        None
    }
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
        // The segment coordinate is ((e − strain_lo) << index_shift) · index_scale / 2³²
        // in Q15 segments: the shift puts the table's width at the top of a `u32`, so the
        // scale keeps about 21 significant bits.
        let span = libm::ceil(width * (1u64 << STRAIN_FRAC) as f64) + 2.0;
        if span.is_nan() || span >= (1u64 << 32) as f64 {
            return Err(TableError::BadDomain);
        }
        let mut index_shift = 0u32;
        while index_shift < 31 && span * (2u64 << index_shift) as f64 <= (1u64 << 32) as f64 {
            index_shift += 1;
        }
        let scale = libm::floor(S as f64 / width * libm::ldexp(1.0, 23 - index_shift as i32));
        if !(scale >= 1.0 && scale < (1u64 << 32) as f64) {
            return Err(TableError::TooNarrow);
        }
        // Kept to 15 significant bits (the low bits zero), so that the M0's narrow index
        // ([`ForceTable::force_narrow`]: two 32-bit multiplies) is the same number.
        let index_scale = narrow_scale(scale as u32);
        // The evaluation places knot i at lo + i · step: build at exactly those strains.
        let step = libm::ldexp(1.0, 23 - index_shift as i32) / index_scale as f64;
        // Strains below strain_lo + d (in Q24 LSBs) have coordinates below S·2¹⁵.
        let num = (S as u128) << 47;
        let den = (index_scale as u128) << index_shift;
        let d = num.div_ceil(den);
        let strain_hi =
            i32::try_from(strain_lo as i128 + d as i128).map_err(|_| TableError::BadDomain)?;
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
            if !(libm::fabs(f * unit) < (1u64 << 30) as f64
                && below.is_finite()
                && above.is_finite())
            {
                return Err(TableError::OutOfRange);
            }
            Ok((f * unit, below * step * unit, above * step * unit))
        };
        // The cubic of one segment from its end values `a0, a1` and end slopes `m0, m1`
        // (same unit): `[C1, C2, C3]` unrounded, with the Fritsch–Carlson limiter where the
        // law bends harder than the grid resolves (a soft cone against a stiff series
        // spring, just below the solid point): the end slopes are scaled into the circle
        // α² + β² ≤ 9 that keeps the cubic monotone. Smooth laws (Table 2) never reach it.
        let cubic = |a0: f64, a1: f64, m0: f64, m1: f64| -> [f64; 3] {
            let secant = a1 - a0;
            let (mut s0, mut s1) = (m0, m1);
            if secant > 0.0 {
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
        };
        // First pass, in Q20: the largest knot and the largest |C1| + |C2| + |C3| pick the
        // unit: knots within 2³⁰ and that sum within 2²⁹, so that no Horner step of the
        // value or the stiffness can overflow.
        let (mut big_value, mut big_poly) = (1e-30f64, 1e-30f64);
        let mut prev = knot(0)?;
        big_value = libm::fmax(big_value, libm::fabs(prev.0));
        for i in 1..=S {
            let k = knot(i)?;
            let c = cubic(prev.0, k.0, prev.2, k.1);
            big_value = libm::fmax(big_value, libm::fabs(k.0));
            big_poly = libm::fmax(
                big_poly,
                libm::fabs(c[0]) + libm::fabs(c[1]) + libm::fabs(c[2]),
            );
            prev = k;
        }
        let fits = |shift: u32| {
            let x = (1u64 << shift) as f64;
            big_value * x <= (1u64 << 30) as f64 - 64.0
                && 1.01 * big_poly * x <= (1u64 << 29) as f64 - 64.0
        };
        if !fits(0) {
            return Err(TableError::OutOfRange);
        }
        let mut shift = 0u32;
        while shift < 12 && fits(shift + 1) {
            shift += 1;
        }
        let scale = (1u64 << shift) as f64;
        // Second pass: the segments, knots rounded to Q(20 + shift).
        let (f_first, _, m_first) = knot(0)?;
        let mut segments = [[0i32; 4]; S];
        let (mut a0, mut m0) = (libm::round(f_first * scale), m_first);
        let a_first = a0;
        let mut slope_bound = 0.0f64;
        for (i, c) in segments.iter_mut().enumerate() {
            let (f1, m1, m1_above) = knot(i + 1)?;
            let a1 = libm::round(f1 * scale);
            // C1, C2 rounded at full resolution; C3 = 8 (a1 − a0) − 4 C1 − 2 C2 exact,
            // so that c0 + c1 + c2 + c3 is the next knot.
            let [c1, c2, _] = cubic(a0, a1, m0 * scale, m1 * scale);
            let (c1, c2) = (libm::round(c1), libm::round(c2));
            let c3 = 8.0 * (a1 - a0) - 4.0 * c1 - 2.0 * c2;
            if libm::fabs(a0) >= (1u64 << 30) as f64
                || libm::fabs(c1) + libm::fabs(c2) + libm::fabs(c3) > (1u64 << 29) as f64
            {
                return Err(TableError::OutOfRange);
            }
            // |dF/dτ| ≤ |c1| + 2|c2| + 3|c3|, in the unit.
            slope_bound = libm::fmax(
                slope_bound,
                libm::fabs(c1) / 2.0 + libm::fabs(c2) / 2.0 + 3.0 * libm::fabs(c3) / 8.0,
            );
            *c = [a0 as i32, c1 as i32, c2 as i32, c3 as i32];
            (a0, m0) = (a1, m1_above);
        }
        // Stiffness: dF/dε (Q16) = (D / 2) · sps · 2^(16 − 20 − shift) for D = 2 dF/dτ,
        // sps = 1/step segments per strain: ⌊D · M / 2³²⌋ with M = sps · 2^(27 − shift)
        // (at least sps · 2¹⁵ significant: `shift` ≤ 12), a power of two moved into
        // `stiff_post` while M would not fit.
        let sps = 1.0 / step;
        let k_bound = slope_bound / (scale * unit) * sps * (1u64 << STIFF_FRAC) as f64;
        if k_bound.is_nan() || k_bound > (1u64 << 30) as f64 {
            return Err(TableError::OutOfRange);
        }
        let mut v = sps * libm::ldexp(1.0, 27 - shift as i32);
        let mut post = 0u32;
        while v >= (1u64 << 31) as f64 - 1.0 && post < 30 {
            v /= 2.0;
            post += 1;
        }
        if v >= (1u64 << 31) as f64 - 1.0 {
            return Err(TableError::OutOfRange);
        }
        let stiff_scale = libm::round(v) as i32;
        let stiff_post = 1i32 << post;
        // The lines are anchored on the end knots floored to Q20: the table's own values
        // floor the same way, so the curve stays monotone across the anchors.
        let first_q20 = (a_first as i32) >> shift;
        let last_q20 = (a0 as i32) >> shift;
        let e_hi = lo + S as f64 * step;
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
            index_pre: 1 << index_shift,
            index_scale,
            anchor_lo,
            force_lo,
            stiffness_lo,
            force_hi: last_q20,
            stiffness_hi: q(above, STIFF_FRAC).ok_or(TableError::OutOfRange)?,
            shift,
            stiff_scale,
            stiff_post,
            segments,
        };
        Ok(Self::from_raw(raw))
    }

    /// Wraps raw contents (for tables emitted by `mccs table` and `include!`d).
    pub const fn from_raw(raw: RawTable<S>) -> Self {
        let k = (32 - raw.index_scale.leading_zeros()).saturating_sub(15);
        let narrow = Narrow {
            scale: raw.index_scale >> k,
            scale_sh: 16 - k,
            lo: NarrowLine::new(raw.stiffness_lo, raw.force_lo),
            hi: NarrowLine::new(raw.stiffness_hi, raw.force_hi),
        };
        Self { narrow, raw }
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
            return Force::from_bits(line(r.force_lo, r.stiffness_lo, e, r.anchor_lo));
        }
        if e >= r.strain_hi {
            return Force::from_bits(line(r.force_hi, r.stiffness_hi, e, r.strain_hi));
        }
        let (c, t) = self.segment(e);
        Force::from_bits(value(r, c, t))
    }

    /// [`ForceTable::force`] clamped to `[−2^BITS, 2^BITS)` in raw Q20 (`BITS` ≤ 30, i.e.
    /// within ±1024 N), as the solver needs it: the same values, a few instructions
    /// less (the clamp makes the saturation of the straight lines exact).
    #[inline]
    pub fn force_within<const BITS: u32>(&self, strain: Strain) -> i32 {
        const { assert!(BITS <= 30) };
        let r = &self.raw;
        let e = strain.to_bits();
        let f = if e <= r.strain_lo {
            line_held(r.force_lo, r.stiffness_lo, e, r.anchor_lo)
        } else if e >= r.strain_hi {
            line_held(r.force_hi, r.stiffness_hi, e, r.strain_hi)
        } else {
            let (c, t) = self.segment(e);
            value(r, c, t)
        };
        f.clamp(-(1 << BITS), (1 << BITS) - 1)
    }

    /// [`ForceTable::force_within::<26>`] for the Cortex-M0's spring
    /// ([`crate::spring::Narrow`]): the same segment, position and cubic (the index scale
    /// has 15 significant bits, so its product is two 32-bit multiplies), and the straight
    /// lines with their slopes to 15 bits (2⁻¹⁵ relative), held at ±1024 N. Raw Q24 strain
    /// in, within ±8 (a spring's strain is within (−2.5, 1)); raw Q20 N out, within
    /// ±64 N.
    #[inline(always)]
    pub fn force_narrow(&self, strain: Strain) -> i32 {
        let r = &self.raw;
        let n = &self.narrow;
        let e = strain.to_bits();
        let f = if e <= r.strain_lo {
            n.lo.below(r.force_lo, e, r.anchor_lo)
        } else if e >= r.strain_hi {
            n.hi.above(r.force_hi, e, r.strain_hi)
        } else {
            let de = (e.wrapping_sub(r.strain_lo) as u32).wrapping_mul(r.index_pre);
            // ⌊de · scale / 2¹⁶⌋ from 16-bit pieces (< 2³¹), then to Q15 segments.
            let (d1, d0) = (de >> 16, de & 0xFFFF);
            let p = d1
                .wrapping_mul(n.scale)
                .wrapping_add(d0.wrapping_mul(n.scale) >> 16);
            let pos = p >> n.scale_sh;
            let i = (pos >> 15) as usize;
            let i = if S.is_power_of_two() {
                i & (S - 1)
            } else {
                i.min(S - 1)
            };
            value(r, &r.segments[i], pos & 0x7FFF)
        };
        f.clamp(-(1 << 26), (1 << 26) - 1)
    }

    /// Force (N) and tangent stiffness `dF/dε` (N per unit strain) at `strain`;
    /// constant time, saturating, no panic.
    #[inline]
    pub fn force_and_stiffness(&self, strain: Strain) -> (Force, Stiffness) {
        let r = &self.raw;
        let e = strain.to_bits();
        if e <= r.strain_lo {
            let f = line(r.force_lo, r.stiffness_lo, e, r.anchor_lo);
            return (Force::from_bits(f), Stiffness::from_bits(r.stiffness_lo));
        }
        if e >= r.strain_hi {
            let f = line(r.force_hi, r.stiffness_hi, e, r.strain_hi);
            return (Force::from_bits(f), Stiffness::from_bits(r.stiffness_hi));
        }
        let (c, t) = self.segment(e);
        let f = value(r, c, t);
        // D = 2 dF/dτ = C1 + C2 τ + ¾ C3 τ², in the same halving Horner form.
        let c3x3 = c[3].wrapping_mul(3);
        let c2x2 = c[2].wrapping_mul(2);
        let d = c[1].wrapping_add(mul_t(c2x2.wrapping_add(mul_t(c3x3, t)), t));
        let k = mulhi(d, r.stiff_scale).wrapping_mul(r.stiff_post);
        (Force::from_bits(f), Stiffness::from_bits(k))
    }

    /// The segment holding `e` (`strain_lo < e < strain_hi`) and the Q15 position in it.
    #[inline(always)]
    fn segment(&self, e: i32) -> (&[i32; 4], u32) {
        let r = &self.raw;
        let de = (e.wrapping_sub(r.strain_lo) as u32).wrapping_mul(r.index_pre);
        let pos = mulhi_u(de, r.index_scale);
        // strain_hi is placed so that pos < S · 2¹⁵ here: the mask (or min) only keeps
        // the compiler from adding a bounds check.
        let i = (pos >> 15) as usize;
        let i = if S.is_power_of_two() {
            i & (S - 1)
        } else {
            i.min(S - 1)
        };
        (&r.segments[i], pos & 0x7FFF)
    }
}

/// `x` with all but its 15 most significant bits cleared.
const fn narrow_scale(x: u32) -> u32 {
    let k = (32 - x.leading_zeros()).saturating_sub(15);
    (x >> k) << k
}

/// `C0 + C1 τ + … ` in Q20 N: three halving Horner steps, then the unit's shift.
#[inline(always)]
fn value<const S: usize>(r: &RawTable<S>, c: &[i32; 4], t: u32) -> i32 {
    let a = c[2].wrapping_add(mul_t(c[3], t));
    let a = c[1].wrapping_add(mul_t(a, t));
    c[0].wrapping_add(mul_t(a, t)).wrapping_shr(r.shift)
}

/// `f0 + (k (e − e0)) >> 20` in Q20 N from a Q20 force, a Q16 slope and Q24 strains;
/// saturating exactly.
#[inline(always)]
fn line(f0: i32, k: i32, e: i32, e0: i32) -> i32 {
    const SH: u32 = STIFF_FRAC + STRAIN_FRAC - FORCE_FRAC;
    let p = mul_wide(k, e.saturating_sub(e0));
    let hi = (p >> 32) as i32;
    let df = if (hi >> (SH - 1)) == (hi >> 31) {
        (hi << (32 - SH)) | ((p as u32) >> SH) as i32
    } else if hi < 0 {
        i32::MIN
    } else {
        i32::MAX
    };
    f0.saturating_add(df)
}

/// [`line`] for callers that clamp the result to well inside ±2048 N: the product is held
/// through its high word ([`shr_held`]), so a held value is ±2048 N to within its low 12
/// bits (4 mN) — beyond any such clamp.
#[inline(always)]
fn line_held(f0: i32, k: i32, e: i32, e0: i32) -> i32 {
    const SH: u32 = STIFF_FRAC + STRAIN_FRAC - FORCE_FRAC;
    let df = shr_held::<SH, 31>(mul_wide(k, e.saturating_sub(e0)));
    f0.saturating_add(df)
}
