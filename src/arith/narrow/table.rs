//! [`NarrowTable`]: the force table's lookup with one 16-bit operand per product, for the
//! narrow spring.

use super::Narrow;
use crate::arith::ArithTable;
use crate::q;
use crate::table::{cubic_value, segment_at, RawTable};
use crate::units::Strain;

/// What [`table_force`] needs beyond the raw table, derived from it: the index scale and
/// the straight lines' slopes as 16-bit operands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NarrowTable {
    /// `index_scale` without its zero low bits (15 significant bits), and the shift that
    /// takes `⌊de · scale / 2¹⁶⌋` to the Q15 segment coordinate.
    scale: u32,
    scale_sh: u32,
    lo: NarrowLine,
    hi: NarrowLine,
}

impl NarrowTable {
    /// From the raw table (start-up).
    pub const fn new<const S: usize>(raw: &RawTable<S>) -> Self {
        // A built table's scale has at most 31 significant bits (k ≤ 16); a raw one from
        // elsewhere may have 32, and then gets a meaningless index, not a panic.
        let k = (32 - raw.index_scale.leading_zeros()).saturating_sub(15);
        Self {
            scale: raw.index_scale >> k,
            scale_sh: 16u32.saturating_sub(k),
            lo: NarrowLine::new(raw.slope_lo, raw.slope_lo_frac(), raw.force_lo),
            hi: NarrowLine::new(raw.slope_hi, raw.slope_hi_frac(), raw.force_hi),
        }
    }
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
    /// From a slope in Q`frac` (16 or 28) and the line's anchor force (Q20 N).
    const fn new(k: i32, frac: u32, f0: i32) -> Self {
        let mag = k.unsigned_abs();
        let kn = (32 - mag.leading_zeros()).saturating_sub(15);
        // Q24 · Q(frac − kn) / 2^(frac + 4 − kn) = Q20.
        let sh = frac + 4 - kn;
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
        f0.wrapping_add(q::mul_s_by(de, self.k, self.sh1 as u32) >> self.sh2)
    }

    /// `f0 + k (e − e0)` in Q20 N, `e − e0 ≥ 0` held at `hold` above (the line above).
    #[inline(always)]
    fn above(&self, f0: i32, e: i32, e0: i32) -> i32 {
        let de = e.wrapping_sub(e0).min(self.hold);
        f0.wrapping_add(q::mul_s_by(de, self.k, self.sh1 as u32) >> self.sh2)
    }
}

/// [`ForceTable::force_within::<26>`](crate::table::ForceTable::force_within) for the
/// narrow spring: the same segment, position and cubic (in the graded corner the same
/// index, whose only product is a 32-bit multiply; the uniform index scale has 15
/// significant bits, so its product is two 32-bit multiplies), and the straight lines
/// with their slopes to 15 bits (2⁻¹⁵ relative), held at ±1024 N. Raw Q24 strain in, within ±8 (a spring's strain is within (−2.5, 1));
/// raw Q20 N out, within ±64 N.
#[inline(always)]
pub fn table_force<const S: usize>(table: &ArithTable<S, Narrow>, strain: Strain) -> i32 {
    table_force_for::<S, true>(table, strain)
}

/// [`table_force`] where the caller knows whether the table may have a lower corner
/// (`LOWER`, as [`ForceTable::force_within_for`](crate::table::ForceTable::force_within_for)).
#[inline(always)]
pub fn table_force_for<const S: usize, const LOWER: bool>(
    table: &ArithTable<S, Narrow>,
    strain: Strain,
) -> i32 {
    let r = table.table.raw();
    let n = &table.aux;
    let e = strain.to_bits();
    let f = if e <= r.strain_lo {
        if LOWER && e > r.corner_hi {
            // A lower corner (`ForceTable::lower_corner`).
            table.table.corner_force(e)
        } else {
            n.lo.below(r.force_lo, e, r.anchor_lo)
        }
    } else if e >= r.strain_hi {
        if e >= r.corner_hi {
            n.hi.above(r.force_hi, e, r.corner_hi)
        } else {
            table.table.corner_force(e)
        }
    } else {
        let de = (e.wrapping_sub(r.strain_lo) as u32).wrapping_mul(r.index_pre);
        // ⌊de · scale / 2¹⁶⌋ from 16-bit pieces (< 2³¹), then to Q15 segments.
        let (d1, d0) = (de >> 16, de & 0xFFFF);
        let p = d1
            .wrapping_mul(n.scale)
            .wrapping_add(d0.wrapping_mul(n.scale) >> 16);
        let pos = p >> n.scale_sh;
        cubic_value(r, segment_at(r, (pos >> 15) as usize), pos & 0x7FFF)
    };
    q::hold::<26>(f)
}
