//! Building a [`ForceTable`] from the `f64` law (start-up or host; never per tick).
//! [`ForceTable::from_law_best`] (here) tries the placements in order, and
//! [`assemble`] builds the table of one: the uniform grid and its knots ([`grid`]), the
//! graded corner ([`corner`]), the segments' cubics, their unit and the stiffness scale
//! ([`cubic`]) and the straight lines beyond the table ([`lines`]).

mod assemble;
mod corner;
mod cubic;
mod grid;
mod lines;

use super::{
    format_floor, measure, ForceTable, RawTable, TableBound, TableError, CORNER_OCTAVES,
    CORNER_OCTAVES_MAX, CORNER_PER_OCTAVE, CORNER_SEGMENTS, DEFAULT_DOMAIN,
};
use crate::law::Law;
use crate::params::Params;
use crate::units::STRAIN_FRAC;
use corner::{corner_inner, CornerEnd};
use grid::Align;

impl<const S: usize> ForceTable<S> {
    /// Builds the table the product ships for `params`, over the default domain
    /// [−0.5, 0.95] ([`DEFAULT_DOMAIN`]): the best placement of its knots
    /// ([`ForceTable::from_law_best`]), measured against the `f64` law, and refused
    /// unless within the product's bound ([`TableBound::PRODUCT`]):
    /// [`TableError::BoundNotMet`] carries what it reached. The table `mccs table`
    /// emits for the same parameters and knots, bit for bit.
    ///
    /// Runs the `f64` law: 5 builds and measurements for a spring like Table 2, up to
    /// 289 for one whose law bends hard. On a device, `include!` what `mccs table` emits
    /// instead (no build, no start-up time); `docs/firmware.md` gives what a build at
    /// start-up costs in flash and instructions.
    pub fn new(params: &Params) -> Result<Self, TableError> {
        Self::with_domain(params, DEFAULT_DOMAIN.0, DEFAULT_DOMAIN.1)
    }

    /// [`ForceTable::new`] over the strain domain `[from, to]`.
    pub fn with_domain(params: &Params, from: f64, to: f64) -> Result<Self, TableError> {
        Self::with_bound(params, from, to, &TableBound::PRODUCT)
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
        Self::from_law_best(&law, from, to)?.within(bound)
    }

    /// The table if its measured error is within `bound`, else
    /// [`TableError::BoundNotMet`] with what it reached (an unmeasured table reaches
    /// nothing: [`crate::table::UNMEASURED`] in both fields).
    pub fn within(self, bound: &TableBound) -> Result<Self, TableError> {
        if self.max_error().is_some_and(|e| e.within(bound)) {
            Ok(self)
        } else {
            Err(TableError::BoundNotMet {
                force_ppb: self.raw.err_force_ppb,
                stiffness_ppb: self.raw.err_stiffness_ppb,
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
        let first_err = Self::uniform_placements(law, (from, to), &mut best);
        let missed = |best: &Option<(f64, Self)>| best.as_ref().is_none_or(|(b, _)| *b > 1.0);
        // Where no uniform grid meets the product's bound and the solid point is inside
        // the domain or a little past its end: a graded corner toward it, over a
        // fraction of the curved part, under each placement of the uniform grid below it.
        if missed(&best) {
            Self::solid_corner(law, (from, to), CORNER_OCTAVES, &mut best);
        }
        let e_p = law.delta(law.preload);
        let lo = libm::fmax(law.strain_t(), from);
        // A preload's slope kink Δ(P) inside the domain, and room for a corner.
        let kink_inside = S >= 2 * CORNER_SEGMENTS && law.preload > law.f_t && e_p > lo && e_p < to;
        if missed(&best) && kink_inside {
            Self::above_kink(law, (from, to), e_p, &mut best);
        }
        if missed(&best) && kink_inside {
            Self::toward_kink(law, (from, to), e_p - lo, &mut best);
        }
        // Still missed, with Δ(P) inside the domain: a lower corner, graded toward Δ(P)
        // from below over the whole curved part under it (down to Δ(F_T) or the domain's
        // start), the uniform grid above from Δ(P) (`CornerEnd::Lower`): the cone's steep
        // rise toward its own solid point below the kink, and a law still curved above it.
        // (This and the two after only where the output formats could meet the bound at
        // all: not for a spring whose half LSB is over it, `format_floor`, which no knots
        // serve.)
        let formats_can = missed(&best) && format_floor(law, from, to).within(&TableBound::PRODUCT);
        if formats_can && kink_inside {
            // (One build: the grid's place is the corner's end, whatever the alignment.)
            let len = (e_p - lo) * LOWER_CORNER_REACH;
            let end = CornerEnd::Lower;
            Self::try_corner::<false>(law, (from, to), Align::Off, len, end, &mut best);
        }
        if formats_can && missed(&best) {
            Self::onset_corner(law, (from, to), &mut best);
        }
        // Still missed, where the formats could meet the bound: the corner toward the
        // solid point again with more octaves, its nearest 1/4096 of its length instead
        // of 1/256 (a stiff series spring whose solid point lies at or just short of the
        // domain's end rises into it faster than the nearest octave of eight follows).
        // Last, so that every spring another placement serves keeps its table.
        if formats_can && missed(&best) {
            Self::solid_corner(law, (from, to), CORNER_OCTAVES_MAX, &mut best);
        }
        // Without a table every placement failed (a duplicate implies one built).
        match (best, first_err) {
            (Some((_, t)), _) => Ok(t),
            (None, e) => Err(e.unwrap_or(TableError::OutOfRange)),
        }
    }

    /// Every placement of the uniform grid, each distinct one measured once (without an
    /// inner corner inside the table every placement is the same grid: its range and
    /// index say where every knot is); the first error, if any.
    fn uniform_placements(
        law: &Law,
        domain: (f64, f64),
        best: &mut Option<(f64, Self)>,
    ) -> Option<TableError> {
        const PLACEMENTS: [Align; 5] = [
            Align::Shortest,
            Align::NearSolid,
            Align::Off,
            Align::Plain,
            Align::FromDomain,
        ];
        let mut first_err = None;
        let mut tried = [None; PLACEMENTS.len()];
        for (n, align) in PLACEMENTS.into_iter().enumerate() {
            // The placement from the domain's start is its own instance of the builder,
            // so that `one_placement_unmeasured`, which never takes it, carries no code for
            // it.
            let (seen, now) = tried.split_at_mut(n);
            let built = if align == Align::FromDomain {
                Self::try_uniform::<true>(law, domain, align, seen, &mut now[0], best)
            } else {
                Self::try_uniform::<false>(law, domain, align, seen, &mut now[0], best)
            };
            if let Err(e) = built {
                first_err.get_or_insert(e);
            }
        }
        first_err
    }

    /// Still missed, with a preload's slope kink Δ(P) = `e_p` inside the domain (a
    /// preload near F_C: below Δ(P) the cone rises steeply toward its own solid point,
    /// which the corner toward the solid point, grading toward Δ(F_C) past Δ(P), does
    /// not follow). The graded corner then takes the part above Δ(P), smooth up to the
    /// solid point (or the domain's end, when that comes first), and the uniform grid's
    /// segments all go below a little past Δ(P), with a knot on it.
    fn above_kink(law: &Law, (from, to): (f64, f64), e_p: f64, best: &mut Option<(f64, Self)>) {
        let (end, e_end) = if solid_near(law, from, to) {
            (CornerEnd::Solid, law.strain_c())
        } else {
            (CornerEnd::DomainEnd, to)
        };
        for align in [Align::Shortest, Align::Off] {
            for margin in ABOVE_KINK_MARGINS {
                let len = (e_end - e_p) * (1.0 - margin);
                if Self::try_corner::<false>(law, (from, to), align, len, end, best) <= 1.0 {
                    return;
                }
            }
        }
    }

    /// Still missed, with Δ(P) inside the domain: the corner graded toward Δ(P) from
    /// below, over a fraction of the curved part under it (`below`: its length), and the
    /// law's tangent from above as the line past it (`CornerEnd::Kink`).
    fn toward_kink(law: &Law, domain: (f64, f64), below: f64, best: &mut Option<(f64, Self)>) {
        for align in [Align::Shortest, Align::Off] {
            for fraction in CORNER_FRACTIONS {
                let len = fraction * below;
                if Self::try_corner::<false>(law, domain, align, len, CornerEnd::Kink, best) <= 1.0
                {
                    return;
                }
            }
        }
    }

    /// Still missed: a corner graded toward the law's first kink from above, under the
    /// grid (`CornerEnd::Onset`), over a fraction of the curved part, and then the
    /// lengths that put one of its knots on the cone's own transition Δ(F_T) where a
    /// preload just below F_T puts the first kink Δ(P) under it. (The kink inside the
    /// domain, as every other placement's table starts.)
    fn onset_corner(law: &Law, (from, to): (f64, f64), best: &mut Option<(f64, Self)>) {
        let e_first = law.strain_t();
        let curved = libm::fmin(law.strain_c(), to) - e_first;
        if !(S >= 2 * CORNER_SEGMENTS && e_first >= from && curved > 0.0) {
            return;
        }
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
            if Self::try_corner::<false>(law, (from, to), Align::Off, len, end, best) <= 1.0 {
                return;
            }
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
                let domain = (from, to);
                // The first within the bound is kept (each try is a build and a
                // measurement).
                let e = if align == Align::FromDomain {
                    Self::try_corner_of::<true>(law, domain, align, len, end, octaves, best)
                } else {
                    Self::try_corner_of::<false>(law, domain, align, len, end, octaves, best)
                };
                if e <= 1.0 {
                    return;
                }
            }
        }
    }

    /// One placement of the uniform grid over `domain`, measured and kept in `best` where
    /// it is the best so far, unless its grid is one of `seen` (the same table); its grid
    /// recorded in `now`. Out of line, as [`Self::try_corner_of`].
    #[inline(never)]
    fn try_uniform<const TENSION: bool>(
        law: &Law,
        (from, to): (f64, f64),
        align: Align,
        seen: &[Option<(i32, i32, u32, u32)>],
        now: &mut Option<(i32, i32, u32, u32)>,
        best: &mut Option<(f64, Self)>,
    ) -> Result<(), TableError> {
        let t = Self::on_grid::<TENSION, false>(law, from, to, align, 0.0, CornerEnd::Solid, 0)?;
        let grid = grid_of(&t.raw);
        if !seen.contains(&Some(grid)) {
            *now = Some(grid);
            Self::keep_best(t, law, (from, to), best);
        }
        Ok(())
    }

    /// [`Self::try_corner_of`] with [`CORNER_OCTAVES`], the grid from the law's first
    /// kink.
    fn try_corner<const TENSION: bool>(
        law: &Law,
        domain: (f64, f64),
        align: Align,
        len: f64,
        end: CornerEnd,
        best: &mut Option<(f64, Self)>,
    ) -> f64 {
        Self::try_corner_of::<TENSION>(law, domain, align, len, end, CORNER_OCTAVES, best)
    }

    /// One placement with a graded corner ([`Self::on_grid`]), measured and kept in
    /// `best` where it is the best so far: its error relative to the product's bound
    /// (≤ 1 within it; infinite where it did not build). Out of line, so that the
    /// candidate table lives in this frame only, not in its caller's beside `best` (a
    /// device's stack: `docs/firmware.md`).
    #[inline(never)]
    fn try_corner_of<const TENSION: bool>(
        law: &Law,
        (from, to): (f64, f64),
        align: Align,
        len: f64,
        end: CornerEnd,
        octaves: usize,
        best: &mut Option<(f64, Self)>,
    ) -> f64 {
        match Self::on_grid::<TENSION, true>(law, from, to, align, len, end, octaves) {
            Ok(t) => Self::keep_best(t, law, (from, to), best),
            Err(_) => f64::INFINITY,
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

    /// One placement of the uniform grid for an already derived law, the first that
    /// builds: **not measured and held to no bound**. That serves Table 2 and springs
    /// like it; a spring whose law bends hard (a stiff series spring near its solid
    /// point, a preload near `F_C`) can be far outside the product's bound
    /// (`docs/accuracy.md`). For the tests that hold one placement to the reference;
    /// a device calls [`ForceTable::new`] or includes what `mccs table` emits.
    /// [`ForceTable::measured`] tells what it reaches.
    #[inline(never)]
    pub fn one_placement_unmeasured(law: &Law, from: f64, to: f64) -> Result<Self, TableError> {
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
}

/// The graded corner's lengths [`ForceTable::from_law_best`] tries, as fractions of the
/// law's curved part.
const CORNER_FRACTIONS: [f64; 6] = [0.05, 0.1, 0.02, 0.2, 0.35, 0.5];

/// And the lengths between those it tries after them, toward the solid point, where the
/// output formats could meet the bound at all: a stiff series spring whose solid point
/// lies just short of the domain's end may need a corner long enough to take the law's
/// rise before it and short enough to keep its nearest octave fine (five of the 13
/// springs a scratch classification found refused for where their knots are, 2026-11-26).
const MORE_CORNER_FRACTIONS: [f64; 4] = [0.03, 0.07, 0.14, 0.28];

/// Whether the solid point `Δ(F_C)` lies inside `[from, to]` or a little past its end
/// (within half the curved part's reach into the domain): the rise toward it is then
/// inside the domain, and a corner toward it ([`CornerEnd::Solid`]) is worth trying.
fn solid_near(law: &Law, from: f64, to: f64) -> bool {
    let lo = libm::fmax(law.strain_t(), from);
    law.strain_c() <= to + 0.5 * (to - lo)
}

/// The corner length (strain) whose knot `(z, jj)` lies `below` (strain) under its end:
/// with `D` = `below` in Q24 LSBs, `I = 2^(32 − octaves)`, the anchor `I/pre` past the end
/// and the knot at `2^(31 − z) (1 + jj/4) / pre` under the anchor,
/// `pre = (2^(31 − z)(1 + jj/4) − I)/D`
/// (rounded: the knot then lies within a few strain LSBs of the kink), and the length
/// `2³²/pre` LSBs. `None` where `pre` is out of [`corner::Corner::place`]'s range.
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

/// How far a lower corner reaches below `Δ(P)`, as a factor of the way down to the
/// law's first kink (or the domain's start): its nearest octave's `1/256` lies past
/// `Δ(P)`, so `256/255` (and a little more) puts its first knot at or below that start.
const LOWER_CORNER_REACH: f64 = 256.0 / 255.0 * (1.0 + 1e-9);

/// Where the graded corner above a preload's kink starts, as fractions of the way from
/// `Δ(P)` to its end ([`ForceTable::from_law_best`]): the uniform grid ends there.
const ABOVE_KINK_MARGINS: [f64; 5] = [0.02, 0.05, 0.1, 0.2, 0.35];

/// Where a table's knots are: its range and index.
fn grid_of<const S: usize>(r: &RawTable<S>) -> (i32, i32, u32, u32) {
    (r.strain_lo, r.strain_hi, r.index_pre, r.index_scale)
}
