//! The straight lines beyond the table, below and above it.

use super::grid::Grid;
use crate::law::Law;
use crate::table::{fine_line, slope_frac, TableError, FINE_SLOPE_FRAC};
use crate::units::{FORCE_FRAC, STIFF_FRAC, STRAIN_FRAC};

/// The straight lines beyond the table.
pub(super) struct Lines {
    pub(super) anchor_lo: i32,
    pub(super) force_lo: i32,
    pub(super) stiffness_lo: i32,
    pub(super) slope_lo: i32,
    pub(super) stiffness_hi: i32,
    pub(super) slope_hi: i32,
}

/// Below the table: at the kink, the exact line `k ε` through zero, with `k` rounded
/// down so that the line never passes above the first knot (the curve stays monotone;
/// the step up at the knot is `(k − k_q) ε_lo`: at most 2⁻²⁸ ε_lo N with the Q28 slope
/// of [`RawTable::slope_lo`](crate::table::RawTable::slope_lo), 2⁻¹⁶ ε_lo N
/// without); otherwise the tangent at the domain
/// edge, through the law at the first knot; either anchored by [`rounding_anchor`] and
/// held at or below the first knot's value (`first_q20`). The table starts at `bottom
/// = (at_kink, strain)` (Q24): the grid's start, or a lower corner's `corner_hi`. Above
/// the table, the line through the grid's last knot: `k_p` when the table ends at the
/// solid point, else the tangent there.
pub(super) fn lines<const S: usize>(
    law: &Law,
    grid: &Grid,
    (at_kink, strain_lo): (bool, i32),
    first_q20: i32,
) -> Result<Lines, TableError> {
    let e_lo = strain_lo as f64 / (1u64 << STRAIN_FRAC) as f64;
    let (k, round): (f64, fn(f64) -> f64) = if at_kink {
        (law.k, libm::floor)
    } else {
        (1.0 / law.compliance(law.force(e_lo)), libm::round)
    };
    let (stiffness_lo, slope_lo) = line_slopes(k, round)?;
    // The line's exact point: the origin on a table that starts at the kink, else the
    // law at the first knot (whose rounded force, `first_q20`, the table starts from).
    let (e_a, f_a) = if at_kink {
        (0, 0.0)
    } else {
        (strain_lo, law.force(e_lo) * (1u64 << FORCE_FRAC) as f64)
    };
    let (anchor_lo, mut force_lo) = rounding_anchor(e_a, f_a, slope_lo, stiffness_lo)?;
    // Never above the first knot at strain_lo, so that the curve stays monotone across
    // it (the nearest Q20 values of the law there may differ by one LSB from the knot's).
    let p = slope_frac(stiffness_lo) + STRAIN_FRAC - FORCE_FRAC;
    let at_lo = force_lo as i64 + ((slope_lo as i64 * (strain_lo as i64 - anchor_lo as i64)) >> p);
    if at_lo > first_q20 as i64 {
        force_lo = i32::try_from(force_lo as i64 - (at_lo - first_q20 as i64))
            .map_err(|_| TableError::OutOfRange)?;
    }
    let e_hi = grid.lo + grid.used as f64 * grid.step;
    let above = if grid.at_solid {
        law.k_p
    } else {
        1.0 / law.compliance(law.force(e_hi))
    };
    let (stiffness_hi, slope_hi) = line_slopes(above, libm::round)?;
    Ok(Lines {
        anchor_lo,
        force_lo,
        stiffness_lo,
        slope_lo,
        stiffness_hi,
        slope_hi,
    })
}

/// An anchor `(e0, f0)` (Q24 strain, Q20 N) for the line through `(e_a, f_a)` (Q24,
/// Q20 units, exact) with this slope, such that the evaluation's
/// `f0 + ⌊slope · (e − e0) / 2^P⌋` (`P` = 32 for a Q28 slope, 20 for a Q16 one: the
/// product's high word, or its floor shifted) rounds the line to the nearest Q20 N instead
/// of flooring it (a floor puts every force on the line up to a whole LSB below the law,
/// which costs small springs their bound). With `s_j = slope · j / 2^P`, the
/// table is `⌊L(e) + ½ − r⌋` for `e0 = e_a + j`, `f0 = ⌊f_a + ½ + s_j⌋` and
/// `r = frac(f_a + ½ + s_j)`: the search takes the `j` (within ±1,024 strain LSBs) with
/// the least `r`, stopping below 1/64, so that a force on the line is within
/// `½ + r` LSB of it (and never above its rounding: a table at the kink stays below its
/// first knot). No cost per evaluation: only where the line is anchored moves.
pub(super) fn rounding_anchor(
    e_a: i32,
    f_a: f64,
    slope: i32,
    stiffness: i32,
) -> Result<(i32, i32), TableError> {
    // The product's shift to Q20 N: 32 with a Q28 slope (its high word), 20 with Q16.
    let p = slope_frac(stiffness) + STRAIN_FRAC - FORCE_FRAC;
    // `f_a + ½ + s_j`, and its fraction `r`.
    let x = |j: i32| f_a + 0.5 + libm::ldexp(slope as f64 * j as f64, -(p as i32));
    let residual = |j: i32| x(j) - libm::floor(x(j));
    let fits = |j: i32| e_a.checked_add(j).is_some();
    let mut best = 0;
    for step in 1..=1024 {
        if residual(best) < 1.0 / 64.0 {
            break;
        }
        for j in [step, -step] {
            if fits(j) && residual(j) < residual(best) {
                best = j;
            }
        }
    }
    let f0 = libm::floor(x(best));
    if !(f0 >= i32::MIN as f64 && f0 <= i32::MAX as f64) {
        return Err(TableError::OutOfRange);
    }
    Ok((e_a + best, f0 as i32))
}

/// A line's `(stiffness, slope)` for the slope `k` (N per unit strain), `round`ed: the
/// stiffness in Q16; the force's slope in Q28 where it fits (below 8 N per unit strain:
/// `k · 2²⁸` < 2³¹, [`fine_line`]), the stiffness then the nearest Q16 value, within one
/// LSB of it; else the stiffness again.
pub(super) fn line_slopes(k: f64, round: fn(f64) -> f64) -> Result<(i32, i32), TableError> {
    let kq = round(k * (1u64 << STIFF_FRAC) as f64);
    if !(kq >= 0.0 && kq <= i32::MAX as f64) {
        return Err(TableError::OutOfRange);
    }
    Ok(if fine_line(kq as i32) {
        let fine = round(libm::ldexp(k, FINE_SLOPE_FRAC as i32)) as i32;
        let nearest = libm::round(k * (1u64 << STIFF_FRAC) as f64) as i32;
        // (Not rounded up out of the fine range, where the slope would read as Q16.)
        let stiffness = if fine_line(nearest) {
            nearest
        } else {
            kq as i32
        };
        (stiffness, fine)
    } else {
        (kq as i32, kq as i32)
    })
}
