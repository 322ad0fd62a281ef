//! A table from its grid, its graded corner, its segments' cubics and its lines: one
//! placement of [`ForceTable::from_law_best`].

use super::corner::{corner_scale, fill_corner, magnitude, Corner, CornerEnd};
use super::cubic::{coefficient_shift, knot_units, segments, stiffness_scale, Magnitude};
use super::grid::{Align, Grid};
use super::lines::{line_slopes, lines};
use crate::law::Law;
use crate::table::{
    corner_pre_signed, slope_frac, ForceTable, RawTable, TableError, CORNER_OCTAVES_MAX,
    CORNER_PER_OCTAVE, UNMEASURED,
};
use crate::units::{FORCE_FRAC, STRAIN_FRAC};

impl<const S: usize> ForceTable<S> {
    /// The table on the grid [`Grid::place`] puts over `[from, to]` (one copy of the
    /// builder in flash, however many placements are tried; `TENSION`: `align` is
    /// [`Align::FromDomain`]). With `CORNER`, the last `4 · octaves` segments are a
    /// graded corner of `corner_len` strain ending at the solid point ([`Corner`]), and
    /// the uniform grid ends where it starts.
    // Whole on purpose (over 80 lines): the table's fields are filled in the order they
    // depend on one another (grid → shift → segments → lines → corner → line above), and
    // `RawTable` is built once, in one literal, so that no field is left to a default.
    #[inline(never)]
    pub(super) fn on_grid<const TENSION: bool, const CORNER: bool>(
        law: &Law,
        from: f64,
        to: f64,
        align: Align,
        corner_len: f64,
        corner_end: CornerEnd,
        octaves: usize,
    ) -> Result<Self, TableError> {
        let corner_segments = octaves * CORNER_PER_OCTAVE;
        let corner = if CORNER {
            Some(Self::corner_of(law, to, corner_len, corner_end, octaves)?)
        } else {
            None
        };
        let n = if CORNER { S - corner_segments } else { S };
        // A lower corner ends where the grid starts, at its first knot; any other ends
        // above the grid.
        let lower = corner.filter(Corner::under_grid);
        // (The grid's first knot on a preload's kink above a lower corner toward it.)
        let (start, end) = match corner {
            Some(c) if c.under_grid() => (Some((c.hi - 1, c.end == CornerEnd::Lower)), None),
            Some(c) => (None, Some(c.start)),
            None => (None, None),
        };
        let grid = Grid::place::<TENSION>(law, from, to, align, n, start, end)?;
        // The corner's segments' ends, from the law once (its shift, then its
        // coefficients).
        let corner_ends = match &corner {
            Some(c) => Some(c.segment_ends(law)?),
            None => None,
        };
        let corner_ends = corner_ends.as_ref().map(|e| &e[..corner_segments]);
        let magnitude = corner_ends.map_or(Magnitude::default(), magnitude);
        let shift = coefficient_shift(law, &grid, magnitude)?;
        let mut segs = segments::<S>(law, &grid, shift)?;
        let (stiff_scale, stiff_post) = stiffness_scale(&grid, shift, segs.slope_bound)?;
        // The line below is anchored where its floor rounds, never above the first knot
        // (`first`, the knot's Q20 value), so that the curve stays monotone across it; the
        // line above on the law at the first strain past the table (below).
        // Under a lower corner the line below meets the corner's first knot instead.
        let l = match (&lower, &corner_ends) {
            (Some(c), Some(ends)) => Self::lines_under_corner(law, &grid, c, ends, shift)?,
            _ => lines::<S>(
                law,
                &grid,
                (grid.at_kink, grid.strain_lo),
                segs.first >> shift,
            )?,
        };
        let mut raw = RawTable {
            strain_lo: grid.strain_lo,
            strain_hi: grid.strain_hi,
            index_pre: 1 << grid.index_shift,
            index_scale: grid.index_scale,
            anchor_lo: l.anchor_lo,
            force_lo: l.force_lo,
            stiffness_lo: l.stiffness_lo,
            slope_lo: l.slope_lo,
            // (The law's force at corner_hi: below, once the corner is placed.)
            force_hi: 0,
            stiffness_hi: l.stiffness_hi,
            slope_hi: l.slope_hi,
            shift,
            stiff_scale,
            stiff_post,
            corner_hi: grid.strain_hi,
            corner_anchor: 0,
            corner_pre: 0,
            corner_base: 0,
            corner_scale: 0,
            corner_post: 1,
            err_force_ppb: UNMEASURED,
            err_stiffness_ppb: UNMEASURED,
            segments: [[0; 4]; S],
        };
        if let (Some(c), Some(ends)) = (corner, corner_ends) {
            put_corner(
                law,
                &grid,
                (c, ends),
                octaves,
                shift,
                &mut raw,
                &mut segs.coefficients[n..],
            )?;
            raw.corner_base = n as u32;
        }
        raw.force_hi = force_hi(law, &raw, lower.is_some())?;
        raw.segments = segs.coefficients;
        Ok(Self::from_raw(raw))
    }

    /// The graded corner of `octaves` octaves and `corner_len` strain ending at `to`'s
    /// side `corner_end`; too narrow a table (or octaves out of 1 …
    /// [`CORNER_OCTAVES_MAX`]) refused.
    fn corner_of(
        law: &Law,
        to: f64,
        corner_len: f64,
        corner_end: CornerEnd,
        octaves: usize,
    ) -> Result<Corner, TableError> {
        if octaves == 0 || octaves > CORNER_OCTAVES_MAX || S < 2 * octaves * CORNER_PER_OCTAVE {
            return Err(TableError::TooNarrow);
        }
        Corner::place(law, to, corner_len, corner_end, octaves)
    }

    /// The lines of a table whose lower corner `c` (its segments' `ends`) lies under the
    /// grid: the line below meets the corner's lowest knot — (0, 4), or (octaves − 1, 0)
    /// where it lies above its anchor.
    fn lines_under_corner(
        law: &Law,
        grid: &Grid,
        c: &Corner,
        ends: &[[f64; 4]],
        shift: u32,
    ) -> Result<super::lines::Lines, TableError> {
        let lowest = if c.above_anchor() {
            ends[ends.len() - CORNER_PER_OCTAVE][0]
        } else {
            ends[CORNER_PER_OCTAVE - 1][1]
        };
        let first = knot_units(lowest, shift) as i32;
        let unit = (1u64 << STRAIN_FRAC) as f64;
        let at_kink = c.lo as f64 / unit <= law.strain_t();
        lines::<S>(law, grid, (at_kink, c.lo), first >> shift)
    }
}

/// The graded corner `c` (its segments' `ends`) put into `raw` and its `coefficients`
/// (the table's last segments): where it lies against the uniform grid checked, its
/// index, and the line past it. The caller sets `corner_base`.
fn put_corner<const S: usize>(
    law: &Law,
    grid: &Grid,
    (c, ends): (Corner, &[[f64; 4]]),
    octaves: usize,
    shift: u32,
    raw: &mut RawTable<S>,
    coefficients: &mut [[i32; 4]],
) -> Result<(), TableError> {
    // The corner starts inside the uniform grid's last segment (its coordinate
    // below 2³² there) and ends past it; a lower one ends on the grid's first
    // strain (its coordinate at least 2^(32 − octaves) there) and starts below it.
    let pre = corner_pre_signed(c.pre) as i64;
    let d = |e: i32| (c.anchor as i64 - e as i64) * pre;
    let inner = 1i64 << (32 - octaves);
    let fits = if c.above_anchor() {
        d(grid.strain_lo) < 1 << 32 && d(c.lo + 1) >= inner && c.lo < grid.strain_lo
    } else if c.under_grid() {
        d(grid.strain_lo) >= inner && c.lo < grid.strain_lo
    } else {
        d(grid.strain_hi) < 1 << 32 && grid.strain_hi < c.hi
    };
    if !fits {
        return Err(TableError::TooNarrow);
    }
    fill_corner(ends, shift, coefficients)?;
    let (scale, post) = corner_scale(c.pre, shift)?;
    raw.corner_hi = if c.under_grid() { c.lo } else { c.hi };
    raw.corner_anchor = c.anchor;
    raw.corner_pre = c.pre;
    raw.corner_scale = scale;
    raw.corner_post = post;
    // Past the solid point the law's own k_p line; past the domain's end the
    // law's tangent at the last knot, as a grid that ends there has.
    // (Above a lower corner the grid's own line, from `lines`.)
    let above = match c.end {
        CornerEnd::Solid => Some(law.k_p),
        CornerEnd::DomainEnd => Some(1.0 / law.compliance(law.force(c.strain(octaves - 1, 0)))),
        CornerEnd::Kink => Some(1.0 / law.compliance_above(law.preload)),
        CornerEnd::Lower | CornerEnd::Onset => None,
    };
    if let Some(above) = above {
        (raw.stiffness_hi, raw.slope_hi) = line_slopes(above, libm::round)?;
    }
    Ok(())
}

/// The force where the line above is anchored, Q20 (`lower`: under a lower corner).
fn force_hi<const S: usize>(law: &Law, raw: &RawTable<S>, lower: bool) -> Result<i32, TableError> {
    // The line above passes through (corner_hi, force_hi): from the law's force at
    // corner_hi itself, not the last knot's (as the segments round it), which lies up
    // to a strain LSB below corner_hi (a knot is rarely a Q24 strain).
    // Along a steep line that LSB is many force LSBs: k_p = 222 N per unit strain
    // makes it 14, all along the line (`the_line_above_starts_where_it_is_anchored`).
    // Its anchor cannot move (corner_hi ends the table), so the floor of the line's
    // product is balanced in its force instead: `⌊F + 1⌋` LSBs, which puts the line
    // within (−1, 1) LSB of the law where the nearest Q20 value put it within
    // [−1.5, 0.5) (the anchor below is placed for a true rounding: `rounding_anchor`).
    // Under a lower corner the table ends at strain_hi, and the line's anchor
    // corner_hi lies below it: force_hi is the line extrapolated there in the
    // evaluation's own terms, `⌊v + 1 − frac(a)⌋ − ⌊a⌋` for the law's force `v`
    // (LSBs) at strain_hi and the product `a = slope_hi · (strain_hi − corner_hi)`
    // (LSBs), so that from strain_hi up the line is `⌊v + 1 − frac(a)⌋ + ⌊frac(a) +
    // b⌋` for the rise `b` beyond it: within (−1, 1] LSB of the law, as above. At
    // least −1024 N, so that the line is exact up to 1024 N at least: beyond
    // `2048 N + force_hi` its product is held (`line_at`), and so is the force.
    let end = if lower { raw.strain_hi } else { raw.corner_hi };
    let v = law.force(end as f64 / (1u64 << STRAIN_FRAC) as f64) * (1u64 << FORCE_FRAC) as f64;
    let f_hi = if lower {
        let p = slope_frac(raw.stiffness_hi) + STRAIN_FRAC - FORCE_FRAC;
        let a = raw.slope_hi as i64 * (raw.strain_hi as i64 - raw.corner_hi as i64);
        let frac = (a & ((1i64 << p) - 1)) as f64 / (1u64 << p) as f64;
        let f = libm::floor(v + 1.0 - frac) - (a >> p) as f64;
        // (Also when it is NaN.)
        if f.is_nan() || f < -((1u64 << 30) as f64) {
            return Err(TableError::OutOfRange);
        }
        f
    } else {
        libm::floor(v) + 1.0
    };
    if !(f_hi >= i32::MIN as f64 && f_hi <= i32::MAX as f64) {
        return Err(TableError::OutOfRange);
    }
    Ok(f_hi as i32)
}
