//! The evaluation: force and stiffness at a strain, constant time, no panic, no
//! division: the lines below and above, the uniform grid's segment by one product, the
//! graded corner's by its coordinate's leading zeros, each a cubic in halving Horner
//! steps (the layout: the module docs of [`crate::table`]).

use super::{fine_line, ForceTable, RawTable, CORNER_BITS};
use crate::q::{self, mul_t, mul_wide, mulhi, mulhi_round, mulhi_u, shr_held};
use crate::units::{Force, Stiffness, Strain, FORCE_FRAC, STIFF_FRAC, STRAIN_FRAC};

impl<const S: usize> ForceTable<S> {
    /// Force (N) at compressive strain `strain`; constant time, saturating, no panic.
    #[inline]
    pub fn force(&self, strain: Strain) -> Force {
        let r = &self.raw;
        let e = strain.to_bits();
        if e <= r.strain_lo {
            if e > r.corner_hi {
                return Force::from_bits(self.corner_force(e));
            }
            return Force::from_bits(line_below::<false, S>(r, e));
        }
        if e >= r.strain_hi {
            if e >= r.corner_hi {
                return Force::from_bits(line_above::<false, S>(r, e));
            }
            return Force::from_bits(self.corner_force(e));
        }
        let (c, t) = self.segment(e);
        Force::from_bits(cubic_value(r, c, t))
    }

    /// [`ForceTable::force`] clamped to `[−2^BITS, 2^BITS)` in raw Q20 (`BITS` ≤ 30, i.e.
    /// within ±1024 N), as the solver needs it: the same values, a few instructions
    /// less (the clamp makes the saturation of the straight lines exact).
    #[inline]
    pub fn force_within<const BITS: u32>(&self, strain: Strain) -> i32 {
        self.force_within_for::<BITS, true>(strain)
    }

    /// [`ForceTable::force_within`] where the caller knows whether the table may have a
    /// lower corner ([`ForceTable::lower_corner`]; `LOWER` true serves every table): the
    /// solver's loops choose once per call, so that a table without one pays nothing for
    /// it on the line below, their most common path. `LOWER` false on a table that has
    /// one evaluates that corner as the line below (wrong values, no panic).
    #[inline(always)]
    pub fn force_within_for<const BITS: u32, const LOWER: bool>(&self, strain: Strain) -> i32 {
        const { assert!(BITS <= 30) };
        let r = &self.raw;
        let e = strain.to_bits();
        let f = if e <= r.strain_lo {
            if LOWER && e > r.corner_hi {
                self.corner_force(e)
            } else {
                line_below::<true, S>(r, e)
            }
        } else if e >= r.strain_hi {
            self.above_within(e)
        } else {
            let (c, t) = self.segment(e);
            cubic_value(r, c, t)
        };
        f.clamp(-(1 << BITS), (1 << BITS) - 1)
    }

    /// Force (N) and tangent stiffness `dF/dε` (N per unit strain) at `strain`;
    /// constant time, saturating, no panic. (Always inlined: an out-of-line caller, such
    /// as the bench's, would otherwise reach it through a tail call that costs four
    /// instructions.)
    #[inline(always)]
    pub fn force_and_stiffness(&self, strain: Strain) -> (Force, Stiffness) {
        let r = &self.raw;
        let e = strain.to_bits();
        if e <= r.strain_lo {
            if e > r.corner_hi {
                return self.lower_corner_force_and_stiffness(e);
            }
            let f = line_below::<false, S>(r, e);
            return (Force::from_bits(f), Stiffness::from_bits(r.stiffness_lo));
        }
        if e >= r.strain_hi {
            if e >= r.corner_hi {
                let f = line_above::<false, S>(r, e);
                return (Force::from_bits(f), Stiffness::from_bits(r.stiffness_hi));
            }
            return self.corner_force_and_stiffness(e);
        }
        let (c, t) = self.segment(e);
        let (sum, d) = (cubic_sum(c, t), slope(c, t));
        // (The header's shift and scales are read only here: loaded before the cubic, they
        // would hold registers across it, and the M4F's frame would save one more
        // register on every path; docs/experiments/performance.md, "Before and after issue #17". A
        // compiler fence emits no instruction.)
        core::sync::atomic::compiler_fence(core::sync::atomic::Ordering::SeqCst);
        let f = sum.wrapping_shr(r.shift);
        // Rounded to the nearest Q16 value (one `smmulr` on the M4F; an instruction more
        // on the M3, three on the M0): half an LSB where a small spring's bound needs it.
        let k = mulhi_round(d, r.stiff_scale).wrapping_mul(r.stiff_post);
        (Force::from_bits(f), Stiffness::from_bits(k))
    }

    /// [`ForceTable::force_within`] at or above `strain_hi` (before its clamp): the
    /// graded corner or the line above, out of line (past the solid point: rare).
    #[inline(never)]
    fn above_within(&self, e: i32) -> i32 {
        let r = &self.raw;
        if e >= r.corner_hi {
            line_above::<true, S>(r, e)
        } else {
            self.corner_force(e)
        }
    }

    /// The force (Q20 N) in the graded corner (in [`ForceTable::corner`]'s range), out of line
    /// and cold: the solver's loops keep the uniform part's registers.
    #[inline(never)]
    #[cold]
    pub(crate) fn corner_force(&self, e: i32) -> i32 {
        let (c, t, _) = self.corner_segment(e);
        cubic_value(&self.raw, c, t)
    }

    /// [`ForceTable::force_and_stiffness`] in a lower corner, out of line: inlined, its
    /// registers would be saved on every path of every table's evaluation; a lower
    /// corner is a rare table's.
    #[inline(never)]
    fn lower_corner_force_and_stiffness(&self, e: i32) -> (Force, Stiffness) {
        self.corner_force_and_stiffness(e)
    }

    /// [`ForceTable::force_and_stiffness`] in the graded corner (in
    /// [`ForceTable::corner`]'s range).
    #[inline(always)]
    fn corner_force_and_stiffness(&self, e: i32) -> (Force, Stiffness) {
        let r = &self.raw;
        let (c, t, z) = self.corner_segment(e);
        let (sum, d) = (cubic_sum(c, t), slope(c, t));
        // (The header's fields after the cubic, as in the uniform part.)
        core::sync::atomic::compiler_fence(core::sync::atomic::Ordering::SeqCst);
        let f = sum.wrapping_shr(r.shift);
        // ⌊(D << z) · scale / 2³²⌋: the builder keeps D << z within ±2³¹ (z ≤ 11 on a
        // valid table; the shift wraps at 32 on any other, without a panic). Floored, not
        // rounded as the uniform part's: a graded corner's stiffness (a stiff series
        // spring's) is thousands of LSBs, and rounding costs the M0 nine instructions.
        let k = mulhi(d.wrapping_shl(z), r.corner_scale);
        (
            Force::from_bits(f),
            Stiffness::from_bits(k.wrapping_mul(r.corner_post)),
        )
    }

    /// The graded corner's segment holding `e` (in [`ForceTable::corner`]'s range), the Q15
    /// position in it and the octave: `d = (A − e) · pre`, `z = clz(d)`; the two bits
    /// after `d`'s leading one are the segment in the octave, the next 15 `τ`. On a
    /// table that fails [`ForceTable::validate`] the segment is any (masked), never out
    /// of bounds.
    #[inline(always)]
    fn corner_segment(&self, e: i32) -> (&[i32; 4], u32, u32) {
        let r = &self.raw;
        let d = (r.corner_anchor.wrapping_sub(e) as u32).wrapping_mul(r.corner_pre);
        // (`q::leading_zeros`: a byte table on the M0, which has no `clz`.)
        let z = q::leading_zeros(d);
        let pos = (d.wrapping_shl(z) << 1) >> (17 - CORNER_BITS);
        let i = r
            .corner_base
            .wrapping_add(z << CORNER_BITS)
            .wrapping_add(pos >> 15);
        (segment_at(r, i as usize), pos & 0x7FFF, z)
    }

    /// The position of `e` (`strain_lo < e < strain_hi`) in Q15 segments from `strain_lo`.
    #[inline(always)]
    pub(super) fn position(&self, e: i32) -> u32 {
        let r = &self.raw;
        let de = (e.wrapping_sub(r.strain_lo) as u32).wrapping_mul(r.index_pre);
        mulhi_u(de, r.index_scale)
    }

    /// The segment holding `e` (`strain_lo < e < strain_hi`) and the Q15 position in it.
    #[inline(always)]
    fn segment(&self, e: i32) -> (&[i32; 4], u32) {
        let r = &self.raw;
        let pos = self.position(e);
        // strain_hi is placed so that pos < S · 2¹⁵ here: the mask (or min) only keeps
        // the compiler from adding a bounds check.
        (segment_at(r, (pos >> 15) as usize), pos & 0x7FFF)
    }
}

/// Segment `i`, masked into the table (`S` a power of two) or held at its last: never
/// out of bounds, with no bounds check once the compiler sees `i < S`; a table of no
/// segments (only from `from_raw`) reads zeros instead of panicking.
#[inline(always)]
pub(crate) fn segment_at<const S: usize>(r: &RawTable<S>, i: usize) -> &[i32; 4] {
    let i = if S.is_power_of_two() {
        i & (S - 1)
    } else {
        i.min(S.saturating_sub(1))
    };
    r.segments.get(i).unwrap_or(&NO_SEGMENT)
}

/// `D = 2 dF/dτ = C1 + C2 τ + ¾ C3 τ²` in the coefficients' unit, in the same halving
/// Horner form as the value.
#[inline(always)]
fn slope(c: &[i32; 4], t: u32) -> i32 {
    let c3x3 = c[3].wrapping_mul(3);
    let c2x2 = c[2].wrapping_mul(2);
    c[1].wrapping_add(mul_t(c2x2.wrapping_add(mul_t(c3x3, t)), t))
}

/// What a table with no segments evaluates to between its ends.
const NO_SEGMENT: [i32; 4] = [0; 4];

/// `C0 + C1 τ + … ` in Q20 N: three halving Horner steps, then the unit's shift.
#[inline(always)]
pub(crate) fn cubic_value<const S: usize>(r: &RawTable<S>, c: &[i32; 4], t: u32) -> i32 {
    cubic_sum(c, t).wrapping_shr(r.shift)
}

/// [`cubic_value`] before the unit's shift.
#[inline(always)]
fn cubic_sum(c: &[i32; 4], t: u32) -> i32 {
    let a = c[2].wrapping_add(mul_t(c[3], t));
    let a = c[1].wrapping_add(mul_t(a, t));
    c[0].wrapping_add(mul_t(a, t))
}

/// `p >> 20` for the product `p` of a Q16 slope and a Q24 strain difference, saturated
/// to `i32` exactly.
#[inline(always)]
fn line_product(p: i64) -> i32 {
    const SH: u32 = STIFF_FRAC + STRAIN_FRAC - FORCE_FRAC;
    let hi = (p >> 32) as i32;
    if (hi >> (SH - 1)) == (hi >> 31) {
        (hi << (32 - SH)) | ((p as u32) >> SH) as i32
    } else if hi < 0 {
        i32::MIN
    } else {
        i32::MAX
    }
}

/// The line below the table in Q20 N at a Q24 strain `e`: `force_lo + hi(slope_lo · (e ⊖
/// anchor_lo))` with a Q28 slope (a product's high word always fits), else the product
/// of the Q16 slope `>> 20`, saturated exactly ([`line_product`]), or with `HELD` held
/// through its high word ([`shr_held`]: a held value is ±2048 N to within its low 12
/// bits, beyond the clamp of every caller that holds)
/// (the same values within ±1024 N). On the M4F one product and a select of its bits; on
/// the other cores a branch between the two products (so their loops keep their
/// registers: the bench's substep and `force_and_stiffness` figures hold it).
#[inline(always)]
fn line_below<const HELD: bool, const S: usize>(r: &RawTable<S>, e: i32) -> i32 {
    line_at::<HELD, false, S>(r, e)
}

/// The line above the table, as [`line_below`]: `force_hi + hi(slope_hi · (e ⊖
/// corner_hi))` with a Q28 slope, else the Q16 slope's product (past the solid point:
/// off every loop's hot path).
#[inline(always)]
fn line_above<const HELD: bool, const S: usize>(r: &RawTable<S>, e: i32) -> i32 {
    line_at::<HELD, true, S>(r, e)
}

/// The line below the table, or with `UPPER` the line above ([`line_below`]). (Each
/// field read where it is used: read up front, the anchor and the force would be one
/// `ldrd` into a register the M4F's `force_and_stiffness` then saves on every path.)
#[inline(always)]
fn line_at<const HELD: bool, const UPPER: bool, const S: usize>(r: &RawTable<S>, e: i32) -> i32 {
    let f0 = || if UPPER { r.force_hi } else { r.force_lo };
    let slope = || if UPPER { r.slope_hi } else { r.slope_lo };
    let stiffness = if UPPER {
        r.stiffness_hi
    } else {
        r.stiffness_lo
    };
    let e0 = || if UPPER { r.corner_hi } else { r.anchor_lo };
    const SH: u32 = STIFF_FRAC + STRAIN_FRAC - FORCE_FRAC;
    let q16 = |p: i64| {
        if HELD {
            shr_held::<SH, 31>(p)
        } else {
            line_product(p)
        }
    };
    // (The sum in each branch, so that the M3's loop keeps its registers: a sum after the
    // branch spills them.)
    let d = || e.saturating_sub(e0());
    if cfg!(mccs_dsp) {
        let p = mul_wide(slope(), d());
        let df = if fine_line(stiffness) {
            (p >> 32) as i32
        } else {
            q16(p)
        };
        f0().saturating_add(df)
    } else if fine_line(stiffness) {
        f0().saturating_add(mulhi(slope(), d()))
    } else {
        f0().saturating_add(q16(mul_wide(slope(), d())))
    }
}
