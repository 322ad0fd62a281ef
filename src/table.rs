//! `ForceTable`: the inverse MCCS law `F(ε)` tabulated for constant-time fixed-point
//! evaluation (the paper's MATLAB `finverse` step, made fit for a microcontroller).
//!
//! # Layout
//! Only the nonlinear phase `Δ(F_T) < ε < Δ(F_C)`, clipped to the strain domain, is
//! tabulated, on a grid uniform in strain with `S` segments (`S + 1` knots). Below it the
//! law is the exact line of slope `k`; above `Δ(F_C)` the exact line of slope `k_p`.
//! Where the domain cuts the nonlinear phase short, the line beyond the domain edge is
//! the tangent there (an under-estimate of the stiffening law above the edge).
//!
//! Each segment holds the cubic Hermite polynomial through its two knots with the exact
//! analytic slopes `dF/dε` there, stored as power-basis coefficients in `t ∈ [0, 1)`
//! (`4 × i32`, 16 bytes per segment: 1 KiB for 65 knots). The last coefficient is
//! rounded so that each segment ends bit-exactly on the next knot, and the straight
//! lines are anchored on the end knots, so the fixed-point curve is continuous.
//!
//! # Formats and ranges
//! - strain: [`Strain`] = `I8F24`, range ±128, resolution 6.0e-8;
//! - force: [`Force`] = `I12F20` in N, range ±2048 N, resolution 9.5e-7 N;
//! - stiffness: [`Stiffness`] = `I16F16` in N per unit strain, range ±32768, resolution 1.5e-5.
//!
//! Evaluation saturates: a force beyond the format clamps to ±2048 N (`Force::MAX`/`MIN`).
//!
//! # Cost
//! Segment lookup is one subtract and one multiply (no search, no division); the value is
//! a 3-multiply Horner step in a Q16 segment parameter, the stiffness 3 more multiplies.
//! Every multiply is 32 × 16 → 32 bits ([`mul_q16`]). No branch depends on more than
//! which of the three pieces the strain falls in.
//!
//! # Accuracy (measured by `host-tests/tests/table_accuracy.rs`, see README)
//! Table 2 spring, domain [−0.5, 0.95], 65 knots: max |ΔF| 2.2e-6 · F(0.95).

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
    /// The line below `strain_lo` is `(stiffness_lo · ε) >> 20 + offset_lo` (Q20 N).
    pub offset_lo: i32,
    /// Slope of the line below `strain_lo` (Q16 N per unit strain).
    pub stiffness_lo: i32,
    /// The line above `strain_hi` is `(stiffness_hi · ε) >> 20 + offset_hi` (Q20 N).
    pub offset_hi: i32,
    /// Slope of the line above `strain_hi` (Q16 N per unit strain).
    pub stiffness_hi: i32,
    /// Per segment: `F(t) = c0 + c1 t + c2 t² + c3 t³`, Q20 N, `t ∈ [0, 1)`.
    pub coeffs: [[i32; 4]; S],
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

/// `(a · t) >> 16` for a Q16 `t ∈ [0, 65535]`, exact floor, in 32-bit arithmetic only.
#[inline(always)]
pub fn mul_q16(a: i32, t: i32) -> i32 {
    // a = hi·2^16 + lo with lo ∈ [0, 65535]: (a·t) >> 16 = hi·t + (lo·t) >> 16 exactly,
    // and neither product overflows 32 bits for t ≤ 65535.
    let hi = a >> 16;
    let lo = (a & 0xFFFF) as u32;
    hi.wrapping_mul(t)
        .wrapping_add(((lo * t as u32) >> 16) as i32)
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
        let strain_lo = q(lo, STRAIN_FRAC).ok_or(TableError::BadDomain)?;
        let lo = strain_lo as f64 / (1u64 << STRAIN_FRAC) as f64;
        let per_strain = q(S as f64 / (hi - lo), U_FRAC).ok_or(TableError::TooNarrow)?;
        if per_strain <= 0 {
            return Err(TableError::TooNarrow);
        }
        // The evaluation places knot i at lo + i / per_strain: build at exactly those strains.
        let step = (1u64 << U_FRAC) as f64 / per_strain as f64;
        let knot = |i: usize| -> Result<(i32, f64), TableError> {
            let e = lo + i as f64 * step;
            let f = law.force(e);
            // The right-hand slope (at F_T the nonlinear phase starts).
            let slope = 1.0 / law.compliance_above(f);
            let fq = q(f, FORCE_FRAC).ok_or(TableError::OutOfRange)?;
            Ok((fq, slope * step * (1u64 << FORCE_FRAC) as f64))
        };
        let below = if at_kink {
            law.k
        } else {
            1.0 / law.compliance(law.force(lo))
        };
        let stiffness_lo = q(below, STIFF_FRAC).ok_or(TableError::OutOfRange)?;
        let mut coeffs = [[0i32; 4]; S];
        let (mut f0, mut m0) = knot(0)?;
        // At the kink the line below is `k ε` exactly (zero force at zero strain), and the
        // first knot takes the line's value so that the curve is continuous bit for bit.
        let offset_lo = if at_kink {
            f0 = sat_i32(line_bits(stiffness_lo, strain_lo));
            0
        } else {
            f0.wrapping_sub(sat_i32(line_bits(stiffness_lo, strain_lo)))
        };
        for (i, c) in coeffs.iter_mut().enumerate() {
            let (f1, m1) = knot(i + 1)?;
            let df = f1 as f64 - f0 as f64;
            let c1 = libm::round(m0);
            let c2 = libm::round(3.0 * df - 2.0 * m0 - m1);
            let c3 = df - c1 - c2; // exact: the segment ends on the next knot
            if libm::fabs(c1) > 1.0e9 || libm::fabs(c2) > 1.0e9 || libm::fabs(c3) > 1.0e9 {
                return Err(TableError::OutOfRange);
            }
            *c = [f0, c1 as i32, c2 as i32, c3 as i32];
            (f0, m0) = (f1, m1);
        }
        let e_hi = lo + S as f64 * step;
        let strain_hi = q(e_hi, STRAIN_FRAC).ok_or(TableError::BadDomain)?;
        // Line below: exact `k` when the table starts at the kink, else the tangent.
        let above = if at_solid {
            law.k_p
        } else {
            1.0 / law.compliance(law.force(e_hi))
        };
        let stiffness_hi = q(above, STIFF_FRAC).ok_or(TableError::OutOfRange)?;
        let raw = RawTable {
            strain_lo,
            strain_hi,
            segments_per_strain: per_strain,
            offset_lo,
            stiffness_lo,
            offset_hi: f0.wrapping_sub(sat_i32(line_bits(stiffness_hi, strain_hi))),
            stiffness_hi,
            coeffs,
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

    /// The largest tangent stiffness of the law at or below strain `strain`, for
    /// stability bounds: the law stiffens monotonically, so this is the stiffness at
    /// `strain` (or the larger line slope beyond the table).
    pub fn max_stiffness_up_to(&self, strain: Strain) -> Stiffness {
        let (_, s) = self.force_and_stiffness(strain);
        let s = s.max(Stiffness::from_bits(self.raw.stiffness_lo));
        s.max(if strain.to_bits() >= self.raw.strain_hi {
            Stiffness::from_bits(self.raw.stiffness_hi)
        } else {
            Stiffness::ZERO
        })
    }

    /// Force (N) at compressive strain `strain`; constant time, saturating, no panic.
    #[inline]
    pub fn force(&self, strain: Strain) -> Force {
        let r = &self.raw;
        let e = strain.to_bits();
        if e <= r.strain_lo {
            return line(r.stiffness_lo, e, r.offset_lo);
        }
        if e >= r.strain_hi {
            return line(r.stiffness_hi, e, r.offset_hi);
        }
        let (c, t) = self.segment(e);
        Force::from_bits(horner(c, t))
    }

    /// Force (N) and tangent stiffness `dF/dε` (N per unit strain) at `strain`;
    /// constant time, saturating, no panic.
    #[inline]
    pub fn force_and_stiffness(&self, strain: Strain) -> (Force, Stiffness) {
        let r = &self.raw;
        let e = strain.to_bits();
        if e <= r.strain_lo {
            let f = line(r.stiffness_lo, e, r.offset_lo);
            return (f, Stiffness::from_bits(r.stiffness_lo));
        }
        if e >= r.strain_hi {
            let f = line(r.stiffness_hi, e, r.offset_hi);
            return (f, Stiffness::from_bits(r.stiffness_hi));
        }
        let (c, t) = self.segment(e);
        let f = horner(c, t);
        // dF/dt = c1 + 2 c2 t + 3 c3 t², then dF/dε = dF/dt · segments per strain.
        let c2x2 = c[2].saturating_mul(2);
        let c3x3 = c[3].saturating_mul(3);
        let dfdt = c[1].saturating_add(mul_q16(c2x2.saturating_add(mul_q16(c3x3, t)), t));
        let k = (dfdt as i64 * r.segments_per_strain as i64) >> (FORCE_FRAC + U_FRAC - STIFF_FRAC);
        (Force::from_bits(f), Stiffness::from_bits(sat_i32(k)))
    }

    /// The segment holding `e` (strictly inside the table) and the Q16 position in it.
    #[inline(always)]
    fn segment(&self, e: i32) -> (&[i32; 4], i32) {
        let r = &self.raw;
        let u = ((e.wrapping_sub(r.strain_lo) as u32 as i64 * r.segments_per_strain as i64)
            >> STRAIN_FRAC) as u64;
        let i = ((u >> U_FRAC) as usize).min(S - 1);
        let t = (u - ((i as u64) << U_FRAC)).min((1 << U_FRAC) - 1) as i32;
        (&r.coeffs[i], t)
    }
}

#[inline(always)]
fn horner(c: &[i32; 4], t: i32) -> i32 {
    let a = c[2].saturating_add(mul_q16(c[3], t));
    let a = c[1].saturating_add(mul_q16(a, t));
    c[0].saturating_add(mul_q16(a, t))
}

/// `(k · e) >> 20` in Q20 N from a Q16 slope and a Q24 strain, unsaturated.
#[inline(always)]
fn line_bits(k: i32, e: i32) -> i64 {
    (k as i64 * e as i64) >> (STIFF_FRAC + STRAIN_FRAC - FORCE_FRAC)
}

/// `(k · e) >> 20 + offset` in Q20 N; saturating.
#[inline(always)]
fn line(k: i32, e: i32, offset: i32) -> Force {
    Force::from_bits(sat_i32(line_bits(k, e) + offset as i64))
}
