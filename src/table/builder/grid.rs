//! The uniform grid: where its knots are, aligned on the law's kinks.

use crate::law::Law;
use crate::table::TableError;
use crate::units::{checked_from_f64, FORCE_FRAC, STRAIN_FRAC};

/// Whether and how a grid with a preload's kink inside it is aligned on both `Δ(F_T)`
/// and `Δ(P)` ([`Grid::place`]).
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Align {
    /// The shortest step that does it.
    Shortest,
    /// Among the 16 shortest, the one whose last knot lies closest past the solid point.
    NearSolid,
    /// Not aligned: a knot on `Δ(P)` only.
    Off,
    /// No knot on the inner corner: the grid uniform from the table's start to its end.
    Plain,
    /// The table from the domain's start (when that is below the law's first kink), not
    /// from the kink: the tension line inside the domain is tabulated (a cubic holds a
    /// straight line to its coefficients' LSB) instead of being the line of slope `k`
    /// in Q16, whose LSB, over the half strain of the default domain's tension end, is
    /// 7.6e-6 N: more than the force bound of a spring below 0.38 N at `F(0.95)`. The
    /// grid puts a knot on the preload's `Δ(P)`, the law's slope kink (on the cone's
    /// transition `Δ(F_T)` without one), with a whole number of segments below it.
    FromDomain,
}

/// Where the knots are: `lo + i · step`, `i = 0 … S`, with the grid's index in the
/// evaluation's fixed-point terms.
pub(super) struct Grid {
    /// Whether the table starts at the kink `Δ(min(F_T, P))` (the exact line below) and
    /// ends at the solid point `Δ(F_C)` (the exact line above).
    pub(super) at_kink: bool,
    pub(super) at_solid: bool,
    /// The knot on the preload's slope kink `Δ(P)` (or, on a grid from the domain's
    /// start without a preload, on `Δ(F_T)`, where `P = F_T`), if inside the table.
    kink_knot: Option<usize>,
    /// Whether the first knot moved below the table's start to put a knot on `Δ(P)`.
    grid_moved: bool,
    /// The segments in use (`S`, or fewer on a grid aligned on `Δ(F_T)` and `Δ(P)`).
    pub(super) used: usize,
    /// The first knot, rounded to the strain format (as an `f64` and in Q24).
    pub(super) lo: f64,
    pub(super) strain_lo: i32,
    /// One past the last strain inside the table (Q24).
    pub(super) strain_hi: i32,
    /// The segment width the evaluation's index implies.
    pub(super) step: f64,
    pub(super) index_shift: u32,
    pub(super) index_scale: u32,
}

/// The strains a grid must cover, before they are rounded to the strain format.
#[derive(Clone, Copy)]
struct Span {
    /// From here (the kink, the domain's start, or a lower corner's knot on `Δ(P)`).
    lo: f64,
    /// To here (the solid point, the domain's end, or a graded corner's start).
    hi: f64,
    /// `TENSION` with [`Align::FromDomain`] below the kink: the grid starts at `from`.
    from_domain: bool,
    /// The table starts at the kink, with the exact line below.
    at_kink: bool,
    /// The table ends at the solid point, with the exact line above.
    at_solid: bool,
}

impl Span {
    /// The span over `[from, to]` (a finite domain inside ±127 strain), from `start`
    /// and up to `end` as [`Grid::place`] takes them.
    fn of<const TENSION: bool>(
        law: &Law,
        (from, to): (f64, f64),
        align: Align,
        start: Option<(i32, bool)>,
        end: Option<f64>,
    ) -> Result<Self, TableError> {
        if !(from.is_finite() && to.is_finite() && from < to && from > -127.0 && to < 127.0) {
            return Err(TableError::BadDomain);
        }
        let (e_t, e_c) = (law.strain_t(), law.strain_c());
        let from_domain = TENSION && align == Align::FromDomain && from < e_t;
        // With a graded corner (`end`), the uniform grid ends where the corner starts.
        let at_kink = from <= e_t && !from_domain && start.is_none();
        let at_solid = to >= e_c && end.is_none();
        let lo = match start {
            Some((s, _)) => s as f64 / (1u64 << STRAIN_FRAC) as f64,
            None if at_kink => e_t,
            None => from,
        };
        let hi = match end {
            Some(x) => x,
            None if at_solid => e_c,
            None => to,
        };
        if hi <= lo {
            return Err(TableError::NoNonlinearPhase);
        }
        Ok(Self {
            lo,
            hi,
            from_domain,
            at_kink,
            at_solid,
        })
    }
}

impl Grid {
    /// Places `S` segments over the law's curved part inside `[from, to]` (with
    /// `TENSION` and [`Align::FromDomain`], from `from` instead; from `start`, a Q24
    /// strain on a preload's kink `Δ(P)` with a knot on it, above a lower corner; up to
    /// `end`, below a graded corner).
    pub(super) fn place<const TENSION: bool>(
        law: &Law,
        from: f64,
        to: f64,
        align: Align,
        n: usize,
        start: Option<(i32, bool)>,
        end: Option<f64>,
    ) -> Result<Self, TableError> {
        if n == 0 {
            return Err(TableError::NoSegments);
        }
        let span = Span::of::<TENSION>(law, (from, to), align, start, end)?;
        let Span {
            lo,
            hi,
            from_domain,
            at_kink,
            at_solid,
        } = span;
        // Where the grid's knots fall round the law's kinks: [`Alignment::of`].
        let slope_kink = law.preload > law.f_t;
        let Alignment {
            lo_grid,
            width,
            kink_knot,
            aligned,
            knot_at,
        } = Alignment::of(law, &span, align, n, start)?;
        let grid_moved = lo_grid < lo;
        let (index_shift, index_scale, step) = index(width, n)?;
        // That step is a little longer than the one asked for (the scale's low bits are
        // cut, up to 6e-5 of it): with a kink, the first knot is placed from this step so
        // that the kink's knot stays on Δ(P), to a strain LSB (the table still reaches
        // `hi`: the step only grew); from the domain's start the same, so the first knot
        // lies at or a little below the domain's start.
        let first = match kink_knot {
            Some(j) if slope_kink || from_domain => knot_at - j as f64 * step,
            _ => lo_grid,
        };
        let strain_lo = checked_from_f64(first, STRAIN_FRAC).ok_or(TableError::BadDomain)?;
        let lo = strain_lo as f64 / (1u64 << STRAIN_FRAC) as f64;
        // The segments in use: all of them, unless the grid was aligned on Δ(F_T) and
        // Δ(P), whose longer step may reach `hi` before the last one (the table then
        // ends at the first knot at or above `hi`; the segments above stay zero and are
        // never reached).
        let used = if aligned {
            (libm::ceil((hi - lo) / step) as usize).clamp(1, n)
        } else {
            n
        };
        // Strains below strain_lo + d (in Q24 LSBs) have coordinates below used·2¹⁵.
        let num = (used as u128) << 47;
        let den = (index_scale as u128) << index_shift;
        let d = num.div_ceil(den);
        let strain_hi =
            i32::try_from(strain_lo as i128 + d as i128).map_err(|_| TableError::BadDomain)?;
        Ok(Self {
            at_kink,
            at_solid,
            kink_knot: kink_knot.filter(|_| slope_kink || from_domain),
            grid_moved,
            used,
            lo,
            strain_lo,
            strain_hi,
            step,
            index_shift,
            index_scale,
        })
    }

    /// Knot `i`: the force, and the slopes dF/dt (per segment) from below and from
    /// above, all in Q20 N units, unrounded.
    pub(super) fn knot(&self, law: &Law, i: usize) -> Result<Knot, TableError> {
        let unit = (1u64 << FORCE_FRAC) as f64;
        let e = self.lo + i as f64 * self.step;
        // A knot on a kink takes the law's value at the kink itself, not at its strain
        // rounded to Q24: the two segments meeting there are each one side's smooth
        // curve, and on the steep side half an LSB of strain is a force that, against a
        // soft side's rise over a segment, bends that side's cubic (a stiffness error of
        // 3.2e-3 above `Δ(P)` when `k_p ≪ k`: `the_inner_corner_is_on_a_knot_…`). The same for the first knot
        // when it sits on the first kink (an aligned grid's may lie well below it).
        let lsb = 1.0 / (1u64 << STRAIN_FRAC) as f64;
        let f = if self.kink_knot == Some(i) {
            law.preload
        } else if i == 0 && self.at_kink && libm::fabs(e - law.strain_t()) <= lsb {
            law.first_kink()
        } else {
            law.force(e)
        };
        // At a kink, the one-sided slopes at the kink itself (the knot's strain is
        // rounded, and may sit a hair to either side). The first knot's segment lies
        // above the kink it starts at.
        let f_slope = if self.kink_knot == Some(i) {
            law.preload
        } else if i == 0 && self.at_kink && !self.grid_moved {
            libm::fmax(f, law.first_kink())
        } else {
            f
        };
        let below = 1.0 / law.compliance(f_slope);
        let above = 1.0 / law.compliance_above(f_slope);
        if !(libm::fabs(f * unit) < (1u64 << 30) as f64 && below.is_finite() && above.is_finite()) {
            return Err(TableError::OutOfRange);
        }
        Ok(Knot {
            value: f * unit,
            slope_below: below * self.step * unit,
            slope_above: above * self.step * unit,
        })
    }
}

/// A knot's force and its one-sided slopes per segment (Q20 N units, unrounded).
#[derive(Clone, Copy)]
pub(super) struct Knot {
    pub(super) value: f64,
    pub(super) slope_below: f64,
    pub(super) slope_above: f64,
}

/// On a grid aligned on `Δ(F_T)` and `Δ(P)` (`j` segments over `to_kink`, `j` ≤ `most`)
/// that ends at the solid point (`span` from the start): the `j`, among the 16 largest,
/// whose last knot lies closest past `Δ(F_C)`. The segment across it holds the law's
/// corner, and the knot past it sits on the steep `k_p` line.
pub(super) fn aligned_on_solid(to_kink: f64, span: f64, most: f64) -> f64 {
    let past = |j: f64| {
        let h = to_kink / j;
        libm::ceil(span / h) * h - span
    };
    let mut best = most;
    let mut j = most - 1.0;
    while j >= 1.0 && j > most - 16.0 {
        if past(j) < past(best) {
            best = j;
        }
        j -= 1.0;
    }
    best
}

/// The force at the law's inner corner, the second of its two changes of phase above the
/// line `k ε`: `max(F_T, P)`. With a preload above `F_T` it is the slope kink `Δ(P)`,
/// where the series spring starts to move; with one below, the cone's own transition
/// `Δ(F_T)`, a jump in curvature (the stiffness starts to climb) that a cubic across it
/// follows only to second order (a stiffness error of 2.3e-3 with no knot on it:
/// `the_inner_corner_is_on_a_knot_…`). With no preload (`P = F_T`) there is none: it is the first kink itself.
pub(super) fn inner_corner(law: &Law) -> f64 {
    libm::fmax(law.f_t, law.preload)
}

/// `x` with all but its 15 most significant bits cleared.
pub(super) const fn narrow_scale(x: u32) -> u32 {
    let k = (32 - x.leading_zeros()).saturating_sub(15);
    (x >> k) << k
}

/// Where the uniform grid's knots go against a kink inside it (see [`Grid::place`]).
struct Alignment {
    /// The grid's first knot before the step is rounded to the index.
    lo_grid: f64,
    /// The grid's width (`n` steps).
    width: f64,
    /// The knot on the kink, if any.
    kink_knot: Option<usize>,
    /// Aligned on two strains: fewer than `n` segments may be in use.
    aligned: bool,
    /// The strain the aligned knot sits on.
    knot_at: f64,
}

impl Alignment {
    /// The alignment of `n` segments over `span`, from `start` above a lower corner.
    ///
    /// A preload above F_T puts the law's one slope kink, Δ(P), inside the table. The
    /// grid is then placed so that a knot falls on it, and the two segments meeting
    /// there get the two one-sided slopes. With `align` on, and Δ(P) at least a segment
    /// above the table's start (the cone's own transition Δ(F_T), a jump in curvature
    /// that a cubic across it follows only to second order; or the domain's edge), the
    /// step is chosen so that a whole number j of segments spans the two, and both
    /// are knots. The step grows by at most a factor 1 + 1/j, which costs less than
    /// that corner (the smooth parts' fourth-order error grows at most 16×, from
    /// ~1e-7), and the table ends at the first knot at or above `hi`, with fewer than
    /// `S` segments in use. Otherwise the first knot moves down (into the exact linear
    /// phase, or below the domain) by less than a segment, and the step grows only if
    /// the table would otherwise end short of `hi`.
    /// A preload below F_T puts the cone's own transition Δ(F_T) inside instead, above
    /// the slope kink Δ(P) where the table starts: a jump in curvature only. The
    /// grid is aligned on both as above, but anchored on the table's start (a slope
    /// kink, which the first knot must not leave), so that the knot near Δ(F_T) lies
    /// within the narrowed step's drift of it and is an ordinary knot; no aligned
    /// grid, no knot on it (moving the first knot below Δ(P) would cost more).
    fn of(
        law: &Law,
        span: &Span,
        align: Align,
        n: usize,
        start: Option<(i32, bool)>,
    ) -> Result<Self, TableError> {
        let Span {
            lo,
            hi,
            from_domain,
            at_solid,
            ..
        } = *span;
        let kink_force = inner_corner(law);
        let slope_kink = law.preload > law.f_t;
        let e_p = law.delta(kink_force);
        let mut kink_knot = None;
        let mut lo_grid = lo;
        let mut width = hi - lo;
        let mut aligned = false;
        // The strain the aligned knot sits on: Δ(P) (Δ(F_T) without a preload, where
        // P = F_T) from the domain's start, else the inner corner.
        let mut knot_at = e_p;
        if let Some((_, on_kink)) = start {
            // Above a lower corner: the first knot where the corner ends (on Δ(P), for
            // one graded toward it), the grid uniform from there.
            knot_at = lo;
            kink_knot = on_kink.then_some(0);
        } else if from_domain {
            // j segments from the domain's start to that knot, the most that still
            // reach `hi` with S; the step grows by at most a factor 1 + 1/j.
            knot_at = law.delta(law.preload);
            let most = libm::floor(n as f64 * (knot_at - lo) / (hi - lo));
            if !(most >= 1.0 && knot_at < hi) {
                return Err(TableError::TooNarrow);
            }
            width = n as f64 * (knot_at - lo) / most;
            kink_knot = Some(most as usize);
            aligned = true;
        } else if !matches!(align, Align::Plain | Align::FromDomain)
            && kink_force > law.first_kink()
            && e_p > lo
            && e_p < hi
        {
            let most = libm::floor(n as f64 * (e_p - lo) / (hi - lo));
            if align != Align::Off && most >= 1.0 {
                let fit = if at_solid && align == Align::NearSolid {
                    aligned_on_solid(e_p - lo, hi - lo, most)
                } else {
                    most
                };
                width = n as f64 * (e_p - lo) / fit;
                kink_knot = Some(fit as usize);
                aligned = true;
            } else if slope_kink {
                let mut step = width / n as f64;
                let j = libm::ceil((e_p - lo) / step);
                if j < n as f64 {
                    step = libm::fmax(step, (hi - e_p) / (n as f64 - j));
                    lo_grid = e_p - j * step;
                    width = n as f64 * step;
                    kink_knot = Some(j as usize);
                }
            }
        }
        Ok(Self {
            lo_grid,
            width,
            kink_knot,
            aligned,
            knot_at,
        })
    }
}

/// The evaluation's index for `n` segments over `width`: `(index_shift, index_scale,
/// step)`, the step the index implies.
fn index(width: f64, n: usize) -> Result<(u32, u32, f64), TableError> {
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
    let scale = libm::floor(n as f64 / width * libm::ldexp(1.0, 23 - index_shift as i32));
    // At most 31 significant bits (the narrow index keeps 15 of them), and each segment
    // at least one strain LSB wide (below that the knots are not strains the format
    // holds).
    if !(scale >= 1.0 && scale < (1u64 << 31) as f64) || span - 2.0 < n as f64 {
        return Err(TableError::TooNarrow);
    }
    // Kept to 15 significant bits (the low bits zero), so that the M0's narrow index
    // ([`crate::arith::narrow::table_force`]: two 32-bit multiplies) is the same number.
    let index_scale = narrow_scale(scale as u32);
    // The evaluation places knot i at lo + i · step: build at exactly those strains.
    let step = libm::ldexp(1.0, 23 - index_shift as i32) / index_scale as f64;
    Ok((index_shift, index_scale, step))
}
