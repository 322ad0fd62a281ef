//! Building a [`ForceTable`] from the `f64` law (start-up or host; never per tick): the
//! grid ([`Grid::place`]), the knots ([`Grid::knot`]), the segments' cubics
//! ([`hermite`]), the coefficients' unit ([`coefficient_shift`]), the stiffness scale
//! ([`stiffness_scale`]) and the straight lines beyond the table ([`lines`]).

use super::{
    corner_pre_signed, corner_strain, fine_line, format_floor, knot_bias, measure, slope_frac,
    ForceTable, RawTable, TableBound, TableError, CORNER_OCTAVES, CORNER_OCTAVES_MAX,
    CORNER_PER_OCTAVE, CORNER_SEGMENTS, DEFAULT_DOMAIN, FINE_SLOPE_FRAC, UNMEASURED,
};
use crate::law::Law;
use crate::params::Params;
use crate::units::{checked_from_f64, FORCE_FRAC, STIFF_FRAC, STRAIN_FRAC};

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

    /// Builds the table for `params` over `[from, to]`, and refuses it unless its
    /// measured error is within `bound` ([`TableBound::PRODUCT`] is the product's
    /// promise): [`TableError::BoundNotMet`] carries what it reached.
    pub fn with_bound(
        params: &Params,
        from: f64,
        to: f64,
        bound: &TableBound,
    ) -> Result<Self, TableError> {
        let law = Law::new(params)?;
        let t = Self::from_law_best(&law, from, to)?;
        if t.max_error().is_some_and(|e| e.within(bound)) {
            Ok(t)
        } else {
            Err(TableError::BoundNotMet {
                force_ppb: t.raw.err_force_ppb,
                stiffness_ppb: t.raw.err_stiffness_ppb,
            })
        }
    }

    /// The table with its error against `law` over `[from, to]` measured ([`measure`])
    /// and recorded ([`ForceTable::max_error`]). `law` and the domain must be the ones it
    /// was built from.
    #[inline(never)]
    pub fn measured(mut self, law: &Law, from: f64, to: f64) -> Self {
        let (force, stiffness) = measure(&self, law, from, to).to_ppb();
        self.raw.err_force_ppb = force;
        self.raw.err_stiffness_ppb = stiffness;
        self
    }

    /// Builds the table for `law` over `[from, to]` on each grid placement the builder
    /// knows (a knot on the inner corner `Δ(max(F_T, P))` or not, where the grid then
    /// ends against the solid point, and a grid from the domain's start instead of the
    /// law's first kink), measures each ([`measure`]), and keeps the one with the least
    /// error relative to [`TableBound::PRODUCT`] (the larger of its two ratios),
    /// measured. No placement is best for every spring: the knot on the corner
    /// lengthens the step, and the grid may then end past `Δ(F_C)` with the solid
    /// point's corner inside its last segment; a grid from the domain's start spends
    /// segments on the straight line, but a small spring's line slope in Q16 can cost
    /// more than that. Where none meets the bound, a graded corner (the module docs):
    /// toward the solid point under each placement (up to 24 more, and 16 between where
    /// the formats could meet the bound), then above a
    /// preload's kink near `F_C` (up to 10 more), then toward that kink from below (up to
    /// 12 more, the uniform grid below it; then 1, a *lower* corner under the grid), then
    /// toward the law's first kink from above, under the grid (up to 21 more), then, at
    /// 129 knots, toward the solid point again with [`CORNER_OCTAVES_MAX`] octaves (up to
    /// 136 more), the first within the bound kept; the last three only where the output
    /// formats could meet the bound ([`format_floor`]). Up to 289 builds and measurements
    /// (5 for a spring the uniform grid serves; the corner toward the solid point tries
    /// up to 26 lengths under each of four placements, 16 of them putting a knot on a
    /// preload's kink, 34 and 24 with twelve octaves): what `mccs table` and
    /// [`ForceTable::with_bound`] do, not for a device's start-up.
    #[inline(never)]
    pub fn from_law_best(law: &Law, from: f64, to: f64) -> Result<Self, TableError> {
        let mut best: Option<(f64, Self)> = None;
        let mut first_err = None;
        // Without an inner corner inside the table every placement is the same grid
        // (the same table: its range and index say where every knot is): each distinct
        // one is measured once.
        const PLACEMENTS: [Align; 5] = [
            Align::Shortest,
            Align::NearSolid,
            Align::Off,
            Align::Plain,
            Align::FromDomain,
        ];
        let mut tried = [None; PLACEMENTS.len()];
        for (n, align) in PLACEMENTS.into_iter().enumerate() {
            // The placement from the domain's start is its own instance of the builder,
            // so that a device's (`from_law`, which never takes it) carries no code for it.
            let built = if align == Align::FromDomain {
                Self::on_grid::<true, false>(law, from, to, align, 0.0, CornerEnd::Solid, 0)
            } else {
                Self::on_grid::<false, false>(law, from, to, align, 0.0, CornerEnd::Solid, 0)
            };
            match built {
                Ok(t) if tried[..n].contains(&Some(grid_of(&t.raw))) => {}
                Ok(t) => {
                    tried[n] = Some(grid_of(&t.raw));
                    Self::keep_best(t, law, (from, to), &mut best);
                }
                Err(e) => {
                    first_err.get_or_insert(e);
                }
            }
        }
        // Where no uniform grid meets the product's bound and the solid point is inside
        // the domain or a little past its end: a graded corner toward it, over a
        // fraction of the curved part, under each placement of the uniform grid below it.
        let missed = best.as_ref().is_none_or(|(b, _)| *b > 1.0);
        let e_c = law.strain_c();
        let lo = libm::fmax(law.strain_t(), from);
        let solid_near = solid_near(law, from, to);
        if missed {
            Self::solid_corner(law, (from, to), CORNER_OCTAVES, &mut best);
        }
        // Still missed, with a preload's slope kink Δ(P) inside the domain (a preload near
        // F_C: below Δ(P) the cone rises steeply toward its own solid point, which the
        // corner above, grading toward Δ(F_C) past Δ(P), does not follow). The graded
        // corner then takes the part above Δ(P), smooth up to the solid point (or the
        // domain's end, when that comes first), and the uniform grid's segments all go
        // below a little past Δ(P), with a knot on it.
        let missed = best.as_ref().is_none_or(|(b, _)| *b > 1.0);
        let e_p = law.delta(law.preload);
        if missed && S >= 2 * CORNER_SEGMENTS && law.preload > law.f_t && e_p > lo && e_p < to {
            let (end, e_end) = if solid_near {
                (CornerEnd::Solid, e_c)
            } else {
                (CornerEnd::DomainEnd, to)
            };
            'above_kink: for align in [Align::Shortest, Align::Off] {
                for margin in ABOVE_KINK_MARGINS {
                    let len = (e_end - e_p) * (1.0 - margin);
                    if let Ok(t) =
                        Self::on_grid::<false, true>(law, from, to, align, len, end, CORNER_OCTAVES)
                    {
                        if Self::keep_best(t, law, (from, to), &mut best) <= 1.0 {
                            break 'above_kink;
                        }
                    }
                }
            }
        }
        // Still missed, with Δ(P) inside the domain: the corner graded toward Δ(P) from
        // below, over a fraction of the curved part under it, and the law's tangent from
        // above as the line past it (`CornerEnd::Kink`).
        let missed = best.as_ref().is_none_or(|(b, _)| *b > 1.0);
        if missed && S >= 2 * CORNER_SEGMENTS && law.preload > law.f_t && e_p > lo && e_p < to {
            'to_kink: for align in [Align::Shortest, Align::Off] {
                for fraction in CORNER_FRACTIONS {
                    let len = fraction * (e_p - lo);
                    let end = CornerEnd::Kink;
                    if let Ok(t) =
                        Self::on_grid::<false, true>(law, from, to, align, len, end, CORNER_OCTAVES)
                    {
                        if Self::keep_best(t, law, (from, to), &mut best) <= 1.0 {
                            break 'to_kink;
                        }
                    }
                }
            }
        }
        // Still missed, with Δ(P) inside the domain: a lower corner, graded toward Δ(P)
        // from below over the whole curved part under it (down to Δ(F_T) or the domain's
        // start), the uniform grid above from Δ(P) (`CornerEnd::Lower`): the cone's steep
        // rise toward its own solid point below the kink, and a law still curved above it.
        // (These two only where the output formats could meet the bound at all: not for
        // a spring whose half LSB is over it, `format_floor`, which no knots serve.)
        let missed = best.as_ref().is_none_or(|(b, _)| *b > 1.0)
            && format_floor(law, from, to).within(&TableBound::PRODUCT);
        if missed && S >= 2 * CORNER_SEGMENTS && law.preload > law.f_t && e_p > lo && e_p < to {
            // (One build: the grid's place is the corner's end, whatever the alignment.)
            let len = (e_p - lo) * LOWER_CORNER_REACH;
            let end = CornerEnd::Lower;
            if let Ok(t) =
                Self::on_grid::<false, true>(law, from, to, Align::Off, len, end, CORNER_OCTAVES)
            {
                Self::keep_best(t, law, (from, to), &mut best);
            }
        }
        // Still missed: a corner graded toward the law's first kink from above, under the
        // grid (`CornerEnd::Onset`), over a fraction of the curved part, and then the
        // lengths that put one of its knots on the cone's own transition Δ(F_T) where a
        // preload just below F_T puts the first kink Δ(P) under it.
        let missed = missed && best.as_ref().is_none_or(|(b, _)| *b > 1.0);
        let e_first = law.strain_t();
        let curved = libm::fmin(e_c, to) - e_first;
        // (The kink inside the domain, as every other placement's table starts.)
        if missed && S >= 2 * CORNER_SEGMENTS && e_first >= from && curved > 0.0 {
            let e_ft = law.delta(law.f_t);
            let on_transition = (0..CORNER_OCTAVES as u32)
                .flat_map(|z| [(z, 0), (z, 2)])
                .filter_map(|knot| {
                    let len = kink_on_knot(e_ft - e_first, knot, CORNER_OCTAVES)?;
                    (law.preload < law.f_t && e_ft > e_first && len < curved).then_some(len)
                });
            let lens = ONSET_FRACTIONS.map(|f| f * curved);
            for len in lens.into_iter().chain(on_transition) {
                let end = CornerEnd::Onset;
                if let Ok(t) = Self::on_grid::<false, true>(
                    law,
                    from,
                    to,
                    Align::Off,
                    len,
                    end,
                    CORNER_OCTAVES,
                ) {
                    if Self::keep_best(t, law, (from, to), &mut best) <= 1.0 {
                        break;
                    }
                }
            }
        }
        // Still missed, where the formats could meet the bound: the corner toward the
        // solid point again with more octaves, its nearest 1/4096 of its length instead
        // of 1/256 (a stiff series spring whose solid point lies at or just short of the
        // domain's end rises into it faster than the nearest octave of eight follows).
        // Last, so that every spring another placement serves keeps its table.
        let missed = missed && best.as_ref().is_none_or(|(b, _)| *b > 1.0);
        if missed {
            Self::solid_corner(law, (from, to), CORNER_OCTAVES_MAX, &mut best);
        }
        // Without a table every placement failed (a duplicate implies one built).
        match (best, first_err) {
            (Some((_, t)), _) => Ok(t),
            (None, e) => Err(e.unwrap_or(TableError::OutOfRange)),
        }
    }

    /// The graded corner toward the solid point (`CornerEnd::Solid`) of `octaves` under
    /// each placement of the uniform grid below it: the usual lengths, the lengths
    /// between them where the output formats could meet the bound, then those that put a
    /// corner knot on a preload's kink inside it; the first within the bound kept in
    /// `best`. Only where the solid point lies inside the domain or a little past its end
    /// and the table has room (`2 · octaves` octaves of segments).
    fn solid_corner(
        law: &Law,
        (from, to): (f64, f64),
        octaves: usize,
        best: &mut Option<(f64, Self)>,
    ) {
        if S < 2 * octaves * CORNER_PER_OCTAVE || !solid_near(law, from, to) {
            return;
        }
        let e_c = law.strain_c();
        let lo = libm::fmax(law.strain_t(), from);
        let curved = e_c - lo;
        // (The lengths between, and the corner of more octaves, only where the formats
        // could meet the bound.)
        let reachable = format_floor(law, from, to).within(&TableBound::PRODUCT);
        if octaves > CORNER_OCTAVES && !reachable {
            return;
        }
        let more = if reachable {
            &MORE_CORNER_FRACTIONS[..]
        } else {
            &[]
        };
        // A preload's kink Δ(P) inside such a corner needs a knot on it (a cubic
        // across a kink misses by the slope's jump times a fraction of the segment):
        // after the usual lengths, those that put a corner knot on Δ(P).
        let e_p = law.delta(law.preload);
        let kinked = law.preload > law.f_t && e_p > lo && e_p < e_c;
        // (Each octave's outer end and midpoint.)
        let on_kink = (0..octaves as u32)
            .flat_map(|z| [(z, 0), (z, 2)])
            .filter_map(|knot| {
                let len = kink_on_knot(e_c - e_p, knot, octaves)?;
                (kinked && len < curved).then_some(len)
            });
        for align in [Align::Shortest, Align::Off, Align::Plain, Align::FromDomain] {
            let lens = CORNER_FRACTIONS.iter().chain(more).map(|f| f * curved);
            for len in lens.chain(on_kink.clone()) {
                let end = CornerEnd::Solid;
                let built = if align == Align::FromDomain {
                    Self::on_grid::<true, true>(law, from, to, align, len, end, octaves)
                } else {
                    Self::on_grid::<false, true>(law, from, to, align, len, end, octaves)
                };
                // The first within the bound is kept (each try is a build and a
                // measurement).
                if let Ok(t) = built {
                    if Self::keep_best(t, law, (from, to), best) <= 1.0 {
                        return;
                    }
                }
            }
        }
    }

    /// Measures `t` over `domain` and keeps it in `best` if it is the least far from the
    /// product's bound so far; returns its error relative to that bound (≤ 1 within it).
    fn keep_best(t: Self, law: &Law, domain: (f64, f64), best: &mut Option<(f64, Self)>) -> f64 {
        let t = t.measured(law, domain.0, domain.1);
        let e = t
            .max_error()
            .map_or(f64::INFINITY, |e| e.ratio_to(&TableBound::PRODUCT));
        if best.as_ref().is_none_or(|(b, _)| e < *b) {
            *best = Some((e, t));
        }
        e
    }

    /// Builds the table for an already derived law (not measured: see
    /// [`ForceTable::measured`]; [`ForceTable::from_law_best`] tries every placement).
    #[inline(never)]
    pub fn from_law(law: &Law, from: f64, to: f64) -> Result<Self, TableError> {
        // A grid aligned on both Δ(F_T) and Δ(P) has a longer step, and its last knot may
        // then lie far enough past the solid point, on the k_p line, to leave the formats:
        // first the shortest aligned step, then the one whose last knot is closest past
        // the solid point, then the grid on Δ(P) alone.
        let mut built = Err(TableError::OutOfRange);
        for align in [Align::Shortest, Align::NearSolid, Align::Off] {
            built = Self::on_grid::<false, false>(law, from, to, align, 0.0, CornerEnd::Solid, 0);
            if !matches!(built, Err(TableError::OutOfRange)) {
                break;
            }
        }
        built
    }

    /// The table on the grid [`Grid::place`] puts over `[from, to]` (one copy of the
    /// builder in flash, however many placements are tried; `TENSION`: `align` is
    /// [`Align::FromDomain`]). With `CORNER`, the last `4 · octaves` segments are a
    /// graded corner of `corner_len` strain ending at the solid point ([`Corner`]), and
    /// the uniform grid ends where it starts.
    #[inline(never)]
    fn on_grid<const TENSION: bool, const CORNER: bool>(
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
            if octaves == 0 || octaves > CORNER_OCTAVES_MAX || S < 2 * corner_segments {
                return Err(TableError::TooNarrow);
            }
            Some(Corner::place(law, to, corner_len, corner_end, octaves)?)
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
            (Some(c), Some(ends)) => {
                // The corner's lowest knot: (0, 4), or (octaves − 1, 0) where it lies
                // above its anchor.
                let lowest = if c.above_anchor() {
                    ends[corner_segments - CORNER_PER_OCTAVE][0]
                } else {
                    ends[CORNER_PER_OCTAVE - 1][1]
                };
                let first = knot_units(lowest, shift) as i32;
                let unit = (1u64 << STRAIN_FRAC) as f64;
                let at_kink = c.lo as f64 / unit <= law.strain_t();
                lines::<S>(law, &grid, (at_kink, c.lo), first >> shift)?
            }
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
            fill_corner(ends, shift, &mut segs.coefficients[n..])?;
            let (scale, post) = corner_scale(c.pre, shift)?;
            raw.corner_hi = if c.under_grid() { c.lo } else { c.hi };
            raw.corner_anchor = c.anchor;
            raw.corner_pre = c.pre;
            raw.corner_base = n as u32;
            raw.corner_scale = scale;
            raw.corner_post = post;
            // Past the solid point the law's own k_p line; past the domain's end the
            // law's tangent at the last knot, as a grid that ends there has.
            // (Above a lower corner the grid's own line, from `lines`.)
            let above = match c.end {
                CornerEnd::Solid => Some(law.k_p),
                CornerEnd::DomainEnd => {
                    Some(1.0 / law.compliance(law.force(c.strain(octaves - 1, 0))))
                }
                CornerEnd::Kink => Some(1.0 / law.compliance_above(law.preload)),
                CornerEnd::Lower | CornerEnd::Onset => None,
            };
            if let Some(above) = above {
                (raw.stiffness_hi, raw.slope_hi) = line_slopes(above, libm::round)?;
            }
        }
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
        let end = if lower.is_some() {
            raw.strain_hi
        } else {
            raw.corner_hi
        };
        let v = law.force(end as f64 / (1u64 << STRAIN_FRAC) as f64) * (1u64 << FORCE_FRAC) as f64;
        let f_hi = if lower.is_some() {
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
        raw.force_hi = f_hi as i32;
        raw.segments = segs.coefficients;
        Ok(Self::from_raw(raw))
    }
}

/// A graded corner: `4 · octaves` segments toward its end ([`CornerEnd`]: the solid
/// point `Δ(F_C)`, or the domain's end), each octave of distance from it ([`CORNER_OCTAVES`]
/// of them, the nearest `len/256` wide, or up to [`CORNER_OCTAVES_MAX`]) cut into
/// [`CORNER_PER_OCTAVE`]: segments about a tenth of their distance from the corner, where
/// a soft cone against a stiff series spring rises like a square root.
#[derive(Clone, Copy)]
struct Corner {
    /// The anchor `A` (Q24): the end plus the nearest octave's inner end.
    anchor: i32,
    pre: u32,
    /// One past the last strain of the corner (Q24): the last knot is its end.
    hi: i32,
    /// A corner under the grid ([`Corner::under_grid`]): the last strain below it (the
    /// table's `corner_hi`), Q24; its own last strain, `hi − 1`, is the grid's first knot.
    lo: i32,
    /// Where the uniform grid ends (a little past the corner's start), strain.
    start: f64,
    /// Where it ends: at the solid point, the last knot's force is `F_C` exactly.
    end: CornerEnd,
    /// The knot `(z, jj)` that lies on a preload's kink `Δ(P)` (within
    /// [`KINK_ON_KNOT_LSB`]), if one does: the segments on either side of it take the
    /// law's slope from their own side.
    kink: Option<(usize, usize)>,
    /// Its octaves ([`CORNER_OCTAVES`] … [`CORNER_OCTAVES_MAX`]), the nearest
    /// `2^−octaves` of its length.
    octaves: usize,
}

/// Where a graded corner ends: its last knot, where the line above starts.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum CornerEnd {
    /// At the solid point `Δ(F_C)`: past it the law's own `k_p` line, exact.
    Solid,
    /// At the domain's end, the solid point lying past it: the corner then covers the
    /// smooth part above a preload's kink `Δ(P)` near `F_C`, so that the uniform grid's
    /// knots go below that kink, where the cone rises steeply toward its own solid
    /// point. Past the domain's end the line above is the law's tangent there (as on a
    /// grid that ends there).
    DomainEnd,
    /// At a preload's kink `Δ(P)`, graded toward it from below, where the cone rises
    /// steeply toward its own solid point (`P` near `F_C`); past it the law's tangent
    /// from above as the line above, which holds where the series spring is much softer
    /// than the cone there (the law above `Δ(P)` then nearly straight). Its last knot is
    /// `P` with the slope from below.
    Kink,
    /// At a preload's kink `Δ(P)`, as [`CornerEnd::Kink`], but under the uniform grid,
    /// which starts there (a *lower* corner, [`ForceTable::lower_corner`]): it reaches down
    /// to the law's first kink (or the domain's start), the line below under it, and the
    /// grid follows the law above `Δ(P)` where the series spring is not much softer.
    Lower,
    /// At the law's first kink `Δ(min(F_T, P))`, graded toward it from *above* (a
    /// negative `pre`), under the grid, which starts where it ends: the line below up
    /// to the kink, exact, and knots dense where the law starts to bend. For a preload
    /// just below `F_T`, whose slope kink `Δ(P)` lies less than a segment below the
    /// cone's own transition `Δ(F_T)` (a jump in curvature: the grid's first segment
    /// across it missed the stiffness bound just above it).
    Onset,
}

impl Corner {
    /// The corner of `len` strain ending at `end`; it must start inside the domain (which
    /// may end before the solid point).
    fn place(
        law: &Law,
        to: f64,
        len: f64,
        end: CornerEnd,
        octaves: usize,
    ) -> Result<Self, TableError> {
        if end == CornerEnd::Onset {
            return Self::above(law, to, len, octaves);
        }
        let inner_d = corner_inner(octaves);
        let e_end = match end {
            CornerEnd::Solid => law.strain_c(),
            CornerEnd::DomainEnd => to,
            // (`Onset` is placed by `Corner::above`, before this.)
            CornerEnd::Kink | CornerEnd::Lower | CornerEnd::Onset => law.delta(law.preload),
        };
        // Every other placement has knots up to the domain's end, each held within the
        // format's range (`Corner::knot`, `Grid::knot`); this one's line must be too.
        // (`within` is false for a NaN too.)
        if end == CornerEnd::Kink {
            let within =
                libm::fabs(law.force(to)) * ((1u64 << FORCE_FRAC) as f64) < (1u64 << 30) as f64;
            if !within {
                return Err(TableError::OutOfRange);
            }
        }
        let unit = (1u64 << STRAIN_FRAC) as f64;
        // (A lower corner's length at least `len`: it must reach the line below.)
        let pre = libm::ldexp(1.0, 32) / (len * unit);
        let pre = if end == CornerEnd::Lower {
            libm::floor(pre)
        } else {
            libm::round(pre)
        };
        // The nearest octave's inner end at least a strain LSB from the anchor.
        if !(pre >= 1.0 && pre <= inner_d) {
            return Err(TableError::TooNarrow);
        }
        let inner = inner_d / pre;
        let anchor =
            checked_from_f64(e_end + inner / unit, STRAIN_FRAC).ok_or(TableError::BadDomain)?;
        // The last strain e with (A − e) · pre ≥ 2^(32 − octaves), plus one.
        let hi = libm::floor(anchor as f64 - inner) + 1.0;
        let start = (anchor as f64 - libm::ldexp(1.0, 32) / pre + 2.0) / unit;
        // (Also when either is NaN.)
        if start.partial_cmp(&to) != Some(core::cmp::Ordering::Less) {
            return Err(TableError::TooNarrow);
        }
        let pre = pre as u32;
        let kink = if law.preload > law.f_t {
            let e_p = law.delta(law.preload) * unit;
            (0..octaves)
                .flat_map(|z| (0..CORNER_PER_OCTAVE).map(move |jj| (z, jj)))
                .find(|&(z, jj)| {
                    let e = corner_strain(anchor, pre, z, jj) * unit;
                    libm::fabs(e - e_p) < KINK_ON_KNOT_LSB
                })
        } else {
            None
        };
        // Under the grid: the last strain whose coordinate (A − e) · pre is 2³² or more
        // (within the format: the corner's start is a strain below its anchor).
        let lo = libm::floor(anchor as f64 - libm::ldexp(1.0, 32) / pre as f64);
        Ok(Self {
            anchor,
            pre,
            hi: hi as i32,
            lo: lo.max(i32::MIN as f64) as i32,
            start,
            end,
            kink,
            octaves,
        })
    }

    /// [`CornerEnd::Onset`]: `len` of strain above the law's first kink, graded toward it
    /// from above: the anchor `A` lies the nearest octave's inner end below the kink,
    /// and a strain `e` in the corner has `d = (e − A) · |pre|` in
    /// `[2^(32 − octaves), 2³²)`.
    fn above(law: &Law, to: f64, len: f64, octaves: usize) -> Result<Self, TableError> {
        let unit = (1u64 << STRAIN_FRAC) as f64;
        let e_kink = law.strain_t();
        let inner_d = corner_inner(octaves);
        let p = libm::round(libm::ldexp(1.0, 32) / (len * unit));
        if !(p >= 1.0 && p <= inner_d) {
            return Err(TableError::TooNarrow);
        }
        let inner = inner_d / p;
        let anchor =
            checked_from_f64(e_kink - inner / unit, STRAIN_FRAC).ok_or(TableError::BadDomain)?;
        // The last strain with d < 2^(32 − octaves) (the line below's), and the last
        // with d < 2³² (the corner's own last, the grid's first knot).
        let lo = anchor as f64 + libm::ceil(inner) - 1.0;
        let top = anchor as f64 + libm::ceil(libm::ldexp(1.0, 32) / p) - 1.0;
        if !(top / unit < to && top <= i32::MAX as f64) {
            return Err(TableError::TooNarrow);
        }
        Ok(Self {
            anchor,
            pre: (p as u32).wrapping_neg(),
            hi: top as i32 + 1,
            lo: lo as i32,
            start: top / unit,
            end: CornerEnd::Onset,
            // Its nearest knot (octaves − 1, 0) on the kink: the segment above it takes
            // the law's slope from above.
            kink: Some((octaves - 1, 0)),
            octaves,
        })
    }

    /// Whether the corner lies under the grid (a lower corner,
    /// [`ForceTable::lower_corner`]).
    fn under_grid(&self) -> bool {
        matches!(self.end, CornerEnd::Lower | CornerEnd::Onset)
    }

    /// Whether the corner lies above its anchor (graded toward it from above).
    fn above_anchor(&self) -> bool {
        self.end == CornerEnd::Onset
    }

    /// The strain of coordinate `(z, jj)` ([`corner_strain`]).
    fn strain(&self, z: usize, jj: usize) -> f64 {
        corner_strain(self.anchor, self.pre, z, jj)
    }

    /// The force and stiffness at `(z, jj)`, in Q20 N and N per unit strain: at the
    /// solid point (the last knot of a corner ending there) the law's own `F_C` and
    /// slope from below; at a preload's kink (the last knot of [`CornerEnd::Kink`]) `P`
    /// and the slope from below.
    fn knot(&self, law: &Law, z: usize, jj: usize) -> Result<(f64, f64), TableError> {
        let last = z == self.octaves - 1 && jj == 0;
        let f = match self.end {
            CornerEnd::Solid if last => law.f_c,
            CornerEnd::Kink | CornerEnd::Lower if last => law.preload,
            CornerEnd::Onset if last => law.first_kink(),
            _ => law.force(self.strain(z, jj)),
        };
        let k = 1.0 / law.compliance(f);
        let unit = (1u64 << FORCE_FRAC) as f64;
        if !(libm::fabs(f * unit) < (1u64 << 30) as f64 && k.is_finite()) {
            return Err(TableError::OutOfRange);
        }
        Ok((f * unit, k * unit))
    }

    /// Every segment's ends `[a0, a1, m0, m1]`, in segment order (`4 z + j`): the values
    /// `(a0, a1)` and slopes per `τ` `(m0, m1)` in Q20 N units, `τ` running from `(z, j)`
    /// down in strain to `(z, j + 1)` (up, where the corner lies above its anchor). Each
    /// knot from the law once (`(z, 4)` is the next octave's start, `(z − 1, 0)`).
    /// The first `4 · octaves` are the corner's; the rest zeros.
    fn segment_ends(&self, law: &Law) -> Result<[[f64; 4]; CORNER_SEGMENTS_MAX], TableError> {
        let mut knots = [[(0.0, 0.0); CORNER_PER_OCTAVE + 1]; CORNER_OCTAVES_MAX];
        for z in 0..self.octaves {
            for jj in 0..CORNER_PER_OCTAVE {
                knots[z][jj] = self.knot(law, z, jj)?;
            }
            knots[z][CORNER_PER_OCTAVE] = match z {
                0 => self.knot(law, 0, CORNER_PER_OCTAVE)?,
                _ => knots[z - 1][0],
            };
        }
        // On a preload's kink: the slope from below for the segment under the knot, from
        // above for the one over it (a knot is in both). A segment's first end `(z, j)`
        // is its upper end, or its lower where the corner lies above its anchor (on the
        // law's first kink).
        let unit = (1u64 << FORCE_FRAC) as f64;
        let kink = if self.above_anchor() {
            law.first_kink()
        } else {
            law.preload
        };
        let below = 1.0 / law.compliance(kink) * unit;
        let above = 1.0 / law.compliance_above(kink) * unit;
        let (below, above) = if self.above_anchor() {
            (above, below)
        } else {
            (below, above)
        };
        let is_kink = |z: usize, jj: usize| {
            self.kink == Some((z, jj))
                || (jj == CORNER_PER_OCTAVE && z >= 1 && self.kink == Some((z - 1, 0)))
        };
        Ok(core::array::from_fn(|i| {
            let (z, j) = (i / CORNER_PER_OCTAVE, i % CORNER_PER_OCTAVE);
            if z >= self.octaves {
                return [0.0; 4];
            }
            let ((a0, mut k0), (a1, mut k1)) = (knots[z][j], knots[z][j + 1]);
            if is_kink(z, j) {
                k0 = below;
            }
            if is_kink(z, j + 1) {
                k1 = above;
            }
            let w = self.strain(z, j) - self.strain(z, j + 1);
            [a0, a1, -k0 * w, -k1 * w]
        }))
    }
}

/// A graded corner's largest values in Q20 N units (for the coefficients' shift).
#[derive(Clone, Copy, Default)]
struct Magnitude {
    /// The largest knot.
    value: f64,
    /// The largest `|C1| + |C2| + |C3|`.
    poly: f64,
    /// The largest `(|C1| + |C2| + |C3|) · 2^z` in octave `z`: the stiffness takes
    /// `D << z`.
    stiff: f64,
}

/// The corner's [`Magnitude`], from its segments' ends.
fn magnitude(ends: &[[f64; 4]]) -> Magnitude {
    let mut m = Magnitude::default();
    for (i, &[a0, a1, m0, m1]) in ends.iter().enumerate() {
        let c = hermite(a0, a1, m0, m1);
        m.value = libm::fmax(m.value, libm::fmax(libm::fabs(a0), libm::fabs(a1)));
        let sum = libm::fabs(c[0]) + libm::fabs(c[1]) + libm::fabs(c[2]);
        m.poly = libm::fmax(m.poly, sum);
        m.stiff = libm::fmax(m.stiff, libm::ldexp(sum, (i / CORNER_PER_OCTAVE) as i32));
    }
    m
}

/// The corner's coefficients in the unit of `shift`, rounded as [`segments`] rounds
/// them ([`rounded_cubic`], with octave `z`'s `2^z`).
fn fill_corner(ends: &[[f64; 4]], shift: u32, out: &mut [[i32; 4]]) -> Result<(), TableError> {
    let scale = (1u64 << shift) as f64;
    for (i, (c, &[a0, a1, m0, m1])) in out.iter_mut().zip(ends).enumerate() {
        let (a0, a1) = (knot_units(a0, shift), knot_units(a1, shift));
        let z = (i / CORNER_PER_OCTAVE) as i32;
        *c = rounded_cubic(a0, a1, m0 * scale, m1 * scale, z)?;
    }
    Ok(())
}

/// A knot's value (Q20 N, as an `f64`) in the coefficients' unit Q(20 + `shift`):
/// rounded, plus [`knot_bias`], so that the evaluation's final `>> shift` rounds to the
/// nearest Q20 N instead of flooring.
fn knot_units(value: f64, shift: u32) -> f64 {
    libm::round(libm::ldexp(value, shift as i32)) + knot_bias(shift) as f64
}

/// The corner's stiffness scale `(corner_scale, corner_post)`: in octave `z`,
/// `dτ/dε = −pre · 2^(z − 5)`, so dF/dε (Q16) `= −D · pre · 2^(z − 10 − shift)` `=
/// (D · scale) >> (32 − z)` with `scale = −pre · 2^(22 − shift)`, a power of two moved
/// into the post-factor while it would not fit (`pre` signed: positive for a corner
/// above its anchor, [`corner_pre_signed`]).
fn corner_scale(pre: u32, shift: u32) -> Result<(i32, i32), TableError> {
    let pre = corner_pre_signed(pre) as f64;
    let (v, post) = with_post(libm::ldexp(libm::fabs(pre), 22 - shift as i32))?;
    Ok((if pre > 0.0 { -v } else { v }, post))
}

/// A positive scale `v` as `(⌊v / 2^p⌉, 2^p)`, the least power `p` (< 30) that brings it
/// below 2³¹ − 1.
fn with_post(mut v: f64) -> Result<(i32, i32), TableError> {
    let mut post = 0u32;
    while v >= (1u64 << 31) as f64 - 1.0 && post < 30 {
        v /= 2.0;
        post += 1;
    }
    if v >= (1u64 << 31) as f64 - 1.0 {
        return Err(TableError::OutOfRange);
    }
    Ok((libm::round(v) as i32, 1i32 << post))
}

/// Segments of a graded corner of [`CORNER_OCTAVES_MAX`].
const CORNER_SEGMENTS_MAX: usize = CORNER_OCTAVES_MAX * CORNER_PER_OCTAVE;

/// The graded corner's lengths [`ForceTable::from_law_best`] tries, as fractions of the
/// law's curved part.
const CORNER_FRACTIONS: [f64; 6] = [0.05, 0.1, 0.02, 0.2, 0.35, 0.5];

/// And the lengths between those it tries after them, toward the solid point, where the
/// output formats could meet the bound at all: a stiff series spring whose solid point
/// lies just short of the domain's end may need a corner long enough to take the law's
/// rise before it and short enough to keep its nearest octave fine (five of the 13
/// springs a scratch classification found refused for where their knots are, 2026-11-26).
const MORE_CORNER_FRACTIONS: [f64; 4] = [0.03, 0.07, 0.14, 0.28];

/// The coordinate `d` of a graded corner's nearest octave's inner end, `2^(32 − octaves)`:
/// a corner's `d` lies in `[corner_inner, 2³²)`.
fn corner_inner(octaves: usize) -> f64 {
    libm::ldexp(1.0, 32 - octaves as i32)
}

/// Whether the solid point `Δ(F_C)` lies inside `[from, to]` or a little past its end
/// (within half the curved part's reach into the domain): the rise toward it is then
/// inside the domain, and a corner toward it ([`CornerEnd::Solid`]) is worth trying.
fn solid_near(law: &Law, from: f64, to: f64) -> bool {
    let lo = libm::fmax(law.strain_t(), from);
    law.strain_c() <= to + 0.5 * (to - lo)
}

/// How near (Q24 LSBs) a corner knot must lie to a preload's kink to take the law's
/// one-sided slopes there ([`Corner::kink`]).
const KINK_ON_KNOT_LSB: f64 = 64.0;

/// The corner length (strain) whose knot `(z, jj)` lies `below` (strain) under its end:
/// with `D` = `below` in Q24 LSBs, `I = 2^(32 − octaves)`, the anchor `I/pre` past the end
/// and the knot at `2^(31 − z) (1 + jj/4) / pre` under the anchor,
/// `pre = (2^(31 − z)(1 + jj/4) − I)/D`
/// (rounded: the knot then lies within a few strain LSBs of the kink), and the length
/// `2³²/pre` LSBs. `None` where `pre` is out of [`Corner::place`]'s range.
/// [`ForceTable::from_law_best`] tries each octave's outer end and midpoint.
fn kink_on_knot(below: f64, (z, jj): (u32, u32), octaves: usize) -> Option<f64> {
    let unit = (1u64 << STRAIN_FRAC) as f64;
    let inner = corner_inner(octaves);
    let d = libm::ldexp(1.0 + jj as f64 / CORNER_PER_OCTAVE as f64, 31 - z as i32);
    let pre = libm::round((d - inner) / (below * unit));
    (pre >= 1.0 && pre <= inner).then(|| libm::ldexp(1.0, 32) / (pre * unit))
}

/// The lengths of a corner above the law's first kink ([`CornerEnd::Onset`]) that
/// [`ForceTable::from_law_best`] tries first, as fractions of the law's curved part.
const ONSET_FRACTIONS: [f64; 5] = [0.02, 0.05, 0.1, 0.2, 0.35];

/// The bound on a graded corner's `(|C1| + |C2| + |C3|) · 2^z` in octave `z` (the
/// coefficients' unit): `D << z` within `i32` (`|D| ≤ |C1| + |C2| + ¾ |C3|`), with room
/// for the halving Horner steps' flooring. Up to 2026-11-27 it was 2²⁹, the sum's own
/// bound, which held a corner's steepest stiffness times its length to about 2,048 N in
/// Q20 (`the_long_runs_soft_series_spring_meets_the_bound_with_its_lower_corner`).
const CORNER_STIFF_MAX: f64 = (1u64 << 31) as f64 - (1u64 << 24) as f64;

/// How far a lower corner reaches below `Δ(P)`, as a factor of the way down to the
/// law's first kink (or the domain's start): its nearest octave's `1/256` lies past
/// `Δ(P)`, so `256/255` (and a little more) puts its first knot at or below that start.
const LOWER_CORNER_REACH: f64 = 256.0 / 255.0 * (1.0 + 1e-9);

/// Where the graded corner above a preload's kink starts, as fractions of the way from
/// `Δ(P)` to its end ([`ForceTable::from_law_best`]): the uniform grid ends there.
const ABOVE_KINK_MARGINS: [f64; 5] = [0.02, 0.05, 0.1, 0.2, 0.35];

/// Whether and how a grid with a preload's kink inside it is aligned on both `Δ(F_T)`
/// and `Δ(P)` ([`Grid::place`]).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Align {
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
struct Grid {
    /// Whether the table starts at the kink `Δ(min(F_T, P))` (the exact line below) and
    /// ends at the solid point `Δ(F_C)` (the exact line above).
    at_kink: bool,
    at_solid: bool,
    /// The knot on the preload's slope kink `Δ(P)` (or, on a grid from the domain's
    /// start without a preload, on `Δ(F_T)`, where `P = F_T`), if inside the table.
    kink_knot: Option<usize>,
    /// Whether the first knot moved below the table's start to put a knot on `Δ(P)`.
    grid_moved: bool,
    /// The segments in use (`S`, or fewer on a grid aligned on `Δ(F_T)` and `Δ(P)`).
    used: usize,
    /// The first knot, rounded to the strain format (as an `f64` and in Q24).
    lo: f64,
    strain_lo: i32,
    /// One past the last strain inside the table (Q24).
    strain_hi: i32,
    /// The segment width the evaluation's index implies.
    step: f64,
    index_shift: u32,
    index_scale: u32,
}

impl Grid {
    /// Places `S` segments over the law's curved part inside `[from, to]` (with
    /// `TENSION` and [`Align::FromDomain`], from `from` instead; from `start`, a Q24
    /// strain on a preload's kink `Δ(P)` with a knot on it, above a lower corner; up to
    /// `end`, below a graded corner).
    fn place<const TENSION: bool>(
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
        if !(from.is_finite() && to.is_finite() && from < to && from > -127.0 && to < 127.0) {
            return Err(TableError::BadDomain);
        }
        let (e_t, e_c) = (law.strain_t(), law.strain_c());
        // Whether the table starts at the kink and ends at the solid point (exact lines
        // beyond), decided before the ends are rounded to the strain format.
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
        // A preload above F_T puts the law's one slope kink, Δ(P), inside the table. The
        // grid is then placed so that a knot falls on it, and the two segments meeting
        // there get the two one-sided slopes. With `align` on, and Δ(P) at least a segment
        // above the table's start (the cone's own transition Δ(F_T), a jump in curvature
        // that a cubic across it follows only to second order; or the domain's edge), the
        // step is chosen so that a whole number j of segments spans the two, and both
        // are knots. The step grows by at most a factor 1 + 1/j, which costs less than
        // that corner (the smooth parts' fourth-order error grows at most 16×, from
        // ~1e-7), and the table ends at the first knot at or above `hi`, with fewer than
        // `S` segments in use. Otherwise the first knot moves down (into the exact linear
        // phase, or below the domain) by less than a segment, and the step grows only if
        // the table would otherwise end short of `hi`.
        // A preload below F_T puts the cone's own transition Δ(F_T) inside instead, above
        // the slope kink Δ(P) where the table starts: a jump in curvature only. The
        // grid is aligned on both as above, but anchored on the table's start (a slope
        // kink, which the first knot must not leave), so that the knot near Δ(F_T) lies
        // within the narrowed step's drift of it and is an ordinary knot; no aligned
        // grid, no knot on it (moving the first knot below Δ(P) would cost more).
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
        let grid_moved = lo_grid < lo;
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
    fn knot(&self, law: &Law, i: usize) -> Result<Knot, TableError> {
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
struct Knot {
    value: f64,
    slope_below: f64,
    slope_above: f64,
}

/// The cubic of one segment from its end values `a0, a1` and end slopes `m0, m1` (same
/// unit): `[C1, C2, C3]` unrounded, with the Fritsch–Carlson limiter where the law bends
/// harder than the grid resolves (a soft cone against a stiff series spring, just below
/// the solid point): the end slopes are scaled into the circle α² + β² ≤ 9 that keeps
/// the cubic monotone. Smooth laws (Table 2) never reach it.
fn hermite(a0: f64, a1: f64, m0: f64, m1: f64) -> [f64; 3] {
    let secant = a1 - a0;
    let (mut s0, mut s1) = (m0, m1);
    if secant != 0.0 {
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
}

/// The coefficients' unit, Q(20 + shift) N: the largest shift (≤ 12) that keeps every knot
/// within 2³⁰, every segment's |C1| + |C2| + |C3| within 2²⁹, so that no Horner step of
/// the value or the stiffness can overflow, and, in the graded corner's octave `z`,
/// that sum times `2^z` within [`CORNER_STIFF_MAX`], so that `D << z` cannot.
fn coefficient_shift(law: &Law, grid: &Grid, corner: Magnitude) -> Result<u32, TableError> {
    let (mut big_value, mut big_poly) = (
        libm::fmax(1e-30, corner.value),
        libm::fmax(1e-30, corner.poly),
    );
    let mut prev = grid.knot(law, 0)?;
    big_value = libm::fmax(big_value, libm::fabs(prev.value));
    for i in 1..=grid.used {
        let k = grid.knot(law, i)?;
        let c = hermite(prev.value, k.value, prev.slope_above, k.slope_below);
        big_value = libm::fmax(big_value, libm::fabs(k.value));
        big_poly = libm::fmax(
            big_poly,
            libm::fabs(c[0]) + libm::fabs(c[1]) + libm::fabs(c[2]),
        );
        prev = k;
    }
    let fits = |shift: u32| {
        let x = (1u64 << shift) as f64;
        big_value * x + knot_bias(shift) as f64 <= (1u64 << 30) as f64 - 64.0
            && 1.01 * big_poly * x <= (1u64 << 29) as f64 - 64.0
            && 1.01 * corner.stiff * x <= CORNER_STIFF_MAX
    };
    if !fits(0) {
        return Err(TableError::OutOfRange);
    }
    let mut shift = 0u32;
    while shift < 12 && fits(shift + 1) {
        shift += 1;
    }
    Ok(shift)
}

/// The segments' coefficients in the unit of `shift`, with the first knot and a bound on
/// `|dF/dτ|` (in the unit).
struct Segments<const S: usize> {
    coefficients: [[i32; 4]; S],
    first: i32,
    slope_bound: f64,
}

/// The segments: knots rounded to Q(20 + shift); `C1`, `C2` rounded at full resolution,
/// `C3 = 8 (a1 − a0) − 4 C1 − 2 C2` exact, so that `c0 + c1 + c2 + c3` is the next knot.
fn segments<const S: usize>(law: &Law, grid: &Grid, shift: u32) -> Result<Segments<S>, TableError> {
    let scale = (1u64 << shift) as f64;
    let first = grid.knot(law, 0)?;
    let mut coefficients = [[0i32; 4]; S];
    let (mut a0, mut m0) = (knot_units(first.value, shift), first.slope_above);
    let a_first = a0;
    let mut slope_bound = 0.0f64;
    for (i, c) in coefficients.iter_mut().enumerate().take(grid.used) {
        let k = grid.knot(law, i + 1)?;
        let a1 = knot_units(k.value, shift);
        *c = rounded_cubic(a0, a1, m0 * scale, k.slope_below * scale, 0)?;
        let [c1, c2, c3] = [c[1], c[2], c[3]].map(|x| libm::fabs(x as f64));
        // |dF/dτ| ≤ |c1| + 2|c2| + 3|c3|, in the unit.
        slope_bound = libm::fmax(slope_bound, c1 / 2.0 + c2 / 2.0 + 3.0 * c3 / 8.0);
        (a0, m0) = (a1, k.slope_above);
    }
    Ok(Segments {
        coefficients,
        first: a_first as i32,
        slope_bound,
    })
}

/// One segment's `[C0, C1, C2, C3]` from its rounded end values `a0, a1` and its end
/// slopes `m0, m1` (the coefficients' unit): `C1`, `C2` rounded, `C3 = 8 (a1 − a0) − 4 C1
/// − 2 C2` exact, so that the cubic ends on `a1`; refused unless `|a0| < 2³⁰`,
/// `|C1| + |C2| + |C3| ≤ 2²⁹` and that sum times `2^z` within [`CORNER_STIFF_MAX`] (`z` =
/// 0 on the uniform grid, the octave in the graded corner, whose stiffness takes
/// `D << z`, `|D| ≤ |C1| + |C2| + ¾ |C3|`).
fn rounded_cubic(a0: f64, a1: f64, m0: f64, m1: f64, z: i32) -> Result<[i32; 4], TableError> {
    let [c1, c2, _] = hermite(a0, a1, m0, m1);
    let (c1, c2) = (libm::round(c1), libm::round(c2));
    let c3 = 8.0 * (a1 - a0) - 4.0 * c1 - 2.0 * c2;
    let sum = libm::fabs(c1) + libm::fabs(c2) + libm::fabs(c3);
    if libm::fabs(a0) >= (1u64 << 30) as f64
        || sum > (1u64 << 29) as f64
        || libm::ldexp(sum, z) > CORNER_STIFF_MAX
    {
        return Err(TableError::OutOfRange);
    }
    Ok([a0 as i32, c1 as i32, c2 as i32, c3 as i32])
}

/// The stiffness scale `(stiff_scale, stiff_post)`: dF/dε (Q16) = (D / 2) · sps ·
/// 2^(16 − 20 − shift) for D = 2 dF/dτ, sps = 1/step segments per strain:
/// ⌊D · M / 2³²⌋ with M = sps · 2^(27 − shift) (at least sps · 2¹⁵ significant: `shift`
/// ≤ 12), a power of two moved into `stiff_post` while M would not fit.
fn stiffness_scale(grid: &Grid, shift: u32, slope_bound: f64) -> Result<(i32, i32), TableError> {
    let (unit, scale) = ((1u64 << FORCE_FRAC) as f64, (1u64 << shift) as f64);
    let sps = 1.0 / grid.step;
    let k_bound = slope_bound / (scale * unit) * sps * (1u64 << STIFF_FRAC) as f64;
    if k_bound.is_nan() || k_bound > (1u64 << 30) as f64 {
        return Err(TableError::OutOfRange);
    }
    with_post(sps * libm::ldexp(1.0, 27 - shift as i32))
}

/// The straight lines beyond the table.
struct Lines {
    anchor_lo: i32,
    force_lo: i32,
    stiffness_lo: i32,
    slope_lo: i32,
    stiffness_hi: i32,
    slope_hi: i32,
}

/// Below the table: at the kink, the exact line `k ε` through zero, with `k` rounded
/// down so that the line never passes above the first knot (the curve stays monotone;
/// the step up at the knot is `(k − k_q) ε_lo`: at most 2⁻²⁸ ε_lo N with the Q28 slope
/// of [`RawTable::slope_lo`], 2⁻¹⁶ ε_lo N without); otherwise the tangent at the domain
/// edge, through the law at the first knot; either anchored by [`rounding_anchor`] and
/// held at or below the first knot's value (`first_q20`). The table starts at `bottom
/// = (at_kink, strain)` (Q24): the grid's start, or a lower corner's `corner_hi`. Above
/// the table, the line through the grid's last knot: `k_p` when the table ends at the
/// solid point, else the tangent there.
fn lines<const S: usize>(
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
/// of flooring it (issue #16: the floor put every force on the line up to a whole LSB
/// below the law, which cost small springs their bound). With `s_j = slope · j / 2^P`, the
/// table is `⌊L(e) + ½ − r⌋` for `e0 = e_a + j`, `f0 = ⌊f_a + ½ + s_j⌋` and
/// `r = frac(f_a + ½ + s_j)`: the search takes the `j` (within ±1,024 strain LSBs) with
/// the least `r`, stopping below 1/64, so that a force on the line is within
/// `½ + r` LSB of it (and never above its rounding: a table at the kink stays below its
/// first knot). No cost per evaluation: only where the line is anchored moves.
fn rounding_anchor(
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
fn line_slopes(k: f64, round: fn(f64) -> f64) -> Result<(i32, i32), TableError> {
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

/// On a grid aligned on `Δ(F_T)` and `Δ(P)` (`j` segments over `to_kink`, `j` ≤ `most`)
/// that ends at the solid point (`span` from the start): the `j`, among the 16 largest,
/// whose last knot lies closest past `Δ(F_C)`. The segment across it holds the law's
/// corner, and the knot past it sits on the steep `k_p` line.
fn aligned_on_solid(to_kink: f64, span: f64, most: f64) -> f64 {
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

/// Where a table's knots are: its range and index.
fn grid_of<const S: usize>(r: &RawTable<S>) -> (i32, i32, u32, u32) {
    (r.strain_lo, r.strain_hi, r.index_pre, r.index_scale)
}

/// The force at the law's inner corner, the second of its two changes of phase above the
/// line `k ε`: `max(F_T, P)`. With a preload above `F_T` it is the slope kink `Δ(P)`,
/// where the series spring starts to move; with one below, the cone's own transition
/// `Δ(F_T)`, a jump in curvature (the stiffness starts to climb) that a cubic across it
/// follows only to second order (a stiffness error of 2.3e-3 with no knot on it:
/// `the_inner_corner_is_on_a_knot_…`). With no preload (`P = F_T`) there is none: it is the first kink itself.
fn inner_corner(law: &Law) -> f64 {
    libm::fmax(law.f_t, law.preload)
}

/// `x` with all but its 15 most significant bits cleared.
const fn narrow_scale(x: u32) -> u32 {
    let k = (32 - x.leading_zeros()).saturating_sub(15);
    (x >> k) << k
}
