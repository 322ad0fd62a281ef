//! `ForceTable`: the inverse MCCS law `F(ε)` tabulated for constant-time fixed-point
//! evaluation (the paper's MATLAB `finverse` step, made fit for a microcontroller).
//!
//! # Layout
//! Only where the law is curved is it tabulated: from the end of the straight line `k ε`
//! (`Δ(min(F_T, P))`) to the solid point `Δ(F_C)`, clipped to the strain domain, on a grid
//! uniform in strain with `S` segments (`S + 1` knots). Below it the law is the exact line
//! of slope `k`; above `Δ(F_C)` the exact line of slope `k_p`. Where the domain cuts the
//! curved part short, the line beyond the domain edge is the tangent there (an
//! under-estimate of the stiffening law above the edge). With a preload, the grid is
//! placed so that a knot sits on the law's inner corner `Δ(max(F_T, P))` (the slope kink
//! `Δ(P)` for a preload above `F_T`, the cone's own transition `Δ(F_T)` for one below)
//! and, where that is at least a segment above it, on the table's start too (the step
//! then grows a little, and the range may end before the last segment:
//! [`ForceTable::segments_used`]). [`ForceTable::from_law_best`] builds each placement,
//! and one more that tabulates the domain's tension end too (from the domain's start, a
//! knot on the law's first corner: for a small spring, the line's slope in Q16 costs
//! more than the coarser grid), and keeps the one with the least measured error.
//!
//! Where none meets the product's bound and the solid point is inside the domain (a soft
//! cone against a stiff series spring, whose law turns into `Δ(F_C)` like a square
//! root), the last [`CORNER_SEGMENTS`] segments become a *graded corner* ending at
//! `Δ(F_C)`: [`CORNER_OCTAVES`] octaves of distance from it, [`CORNER_PER_OCTAVE`]
//! segments each, indexed by the leading zeros of `d = (A − e) · pre`
//! ([`RawTable::corner_anchor`]), the uniform grid below it ([`ForceTable::corner`]).
//! Where every placement below missed too, a 129-knot table tries that corner again
//! with [`CORNER_OCTAVES_MAX`] octaves (its nearest `1/4096` of its length: a solid point
//! at the domain's end); the evaluation is the same ([`ForceTable::corner_octaves`]).
//! Where still none does and a preload above `F_T` puts its slope kink `Δ(P)` inside the
//! domain (near `F_C` the cone rises steeply below it toward its own solid point), the graded
//! corner takes the smooth part above the kink instead, up to `Δ(F_C)` or, when that
//! lies well past the domain, to the domain's end (the line above then the law's tangent
//! there), so that the uniform grid's segments all go below a little past `Δ(P)`. The
//! evaluation is the same either way. Where still none does, the corner ends on `Δ(P)`,
//! graded toward it from below: first with the uniform grid below it and the law's
//! tangent above, then as a *lower* corner ([`ForceTable::lower_corner`]) from the law's
//! first kink up to `Δ(P)`, under the uniform grid, which then covers the curved law
//! above `Δ(P)` (a preload on the cone's steep rise toward its own solid point, with a
//! series spring not much softer). Last, a lower corner graded toward the law's first
//! kink from *above* (a negative `corner_pre`: the same evaluation), for a preload just
//! below `F_T`, whose slope kink lies less than a segment under the cone's own transition.
//! A lower corner is marked by `corner_hi < strain_lo` and costs the line below's path
//! one compare; the solver's loops make it only for a table that has one
//! ([`ForceTable::force_within_for`]).
//!
//! Each segment holds the cubic Hermite polynomial through its two knots with the exact
//! analytic slopes `dF/dε` there (scaled down by the Fritsch–Carlson limiter only where
//! the law bends harder than the grid resolves, so that the curve stays monotone), as
//! power-basis coefficients in `τ ∈ [0, 1)`, stored as `[c0, 2c1, 4c2, 8c3]` (`4 × i32`
//! per segment, 1112 bytes in all for 65 knots with the header) so that each Horner step is one product
//! by `τ/2` ([`mul_t`](crate::q::mul_t)). `8c3 = 8(c0' − c0) − 4(2c1) − 2(4c2)` exactly, so each segment
//! ends bit-exactly on the next knot; the straight lines are anchored on the table's ends (at
//! the kink, the line through zero with `k` rounded down; each line's slope in Q28 where
//! it fits: [`RawTable::slope_lo`], [`RawTable::slope_hi`]), so the curve is continuous
//! and monotone.
//!
//! # Formats and ranges
//! - strain: [`Strain`] = `I8F24`, range ±128, resolution 6.0e-8;
//! - force: [`Force`](crate::units::Force) = `I12F20` in N, range ±2048 N, resolution 9.5e-7 N;
//! - stiffness: [`Stiffness`] = `I16F16` in N per unit strain, range ±32768, resolution 1.5e-5;
//! - position in a segment `τ`: Q15;
//! - coefficients: Q(20 + `shift`) N, the shift (0 … 12) chosen per table so that the
//!   knots use most of an `i32` and no Horner step can overflow; every knot carries half
//!   a Q20 LSB ([`knot_bias`]), so the force rounds to the nearest Q20 N;
//! - each line's slope for its force: Q28 below 8 N per unit strain, else Q16
//!   ([`RawTable::slope_lo`], [`RawTable::slope_hi`]); the stiffness rounds to the
//!   nearest Q16 value (outside the graded corner, which floors).
//!
//! Evaluation saturates: a force beyond the format clamps to ±2048 N (`Force::MAX`/`MIN`);
//! under a lower corner the line above is held where its product reaches 2048 N, at
//! `2048 N + force_hi` (1024 N at least, [`RawTable::force_hi`]).
//!
//! # Cost
//! The segment and `τ` come from one subtract, one multiply by a power of two and one
//! unsigned high-word product (no search, no division); the value is three Horner steps
//! (one `smmla` each on the M3/M4), the stiffness two more and one scaling product. No
//! loop; the only branch is which of the four pieces the strain falls in (the graded
//! corner's index adds a `clz`, a multiply and its shifts; a lower corner's check, a
//! compare on the line below's path). Every product
//! has exact floor semantics, and the Cortex-M0 builds them from 16-bit pieces with the
//! same bits ([`crate::q`]). Instruction counts per core: `docs/performance.md`.
//!
//! # Accuracy
//! Each table carries its own measured error against the `f64` law over its domain
//! ([`ForceTable::max_error`], [`TableBound`]); [`ForceTable::with_bound`] refuses a table
//! that misses a bound ([`TableError::BoundNotMet`]). Measured against the independent
//! `f64` reference by `host-tests/tests/table_accuracy.rs` and `table_bound/`:
//! `docs/accuracy.md`.

use crate::units::{Stiffness, Strain, STIFF_FRAC, STRAIN_FRAC};

mod bound;
mod builder;
mod error;
mod eval;

pub use bound::{format_floor, measure, TableBound, KINK_MARGIN, POINTS_PER_SEGMENT, UNMEASURED};
pub use error::TableError;
pub(crate) use eval::{cubic_value, segment_at};

/// Octaves of a graded corner ([`RawTable::corner_anchor`]), as the builder first tries
/// it (every corner of a 65-knot table).
pub const CORNER_OCTAVES: usize = 8;
/// The most octaves a graded corner may have: the builder's last try toward the solid
/// point, where [`CORNER_OCTAVES`] missed, on a table of at least
/// `2 · CORNER_OCTAVES_MAX · CORNER_PER_OCTAVE` segments (129 knots); its nearest octave
/// `1/4096` of its length. The evaluation is the same for any count: the octave is the
/// coordinate's leading zeros ([`ForceTable::corner_octaves`]).
pub const CORNER_OCTAVES_MAX: usize = 12;
/// Segments in each octave of the graded corner (a power of two).
pub const CORNER_PER_OCTAVE: usize = 4;
/// Segments of a graded corner of [`CORNER_OCTAVES`].
pub const CORNER_SEGMENTS: usize = CORNER_OCTAVES * CORNER_PER_OCTAVE;
/// `log2(CORNER_PER_OCTAVE)`.
const CORNER_BITS: u32 = CORNER_PER_OCTAVE.trailing_zeros();

/// The default strain domain `[ε_min, ε_max]`: every table the solvers run on the host,
/// and `mccs table` without `--from`/`--to`.
pub const DEFAULT_DOMAIN: (f64, f64) = (-0.5, 0.95);

/// The default knot count, everywhere (`mccs table`, every `--backend fixed`, the
/// firmware's [`ForceTable64`]): 64 segments.
pub const DEFAULT_KNOTS: usize = 65;

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
    /// The line below `strain_lo` is `force_lo + ⌊slope_lo · (e − anchor_lo)⌋` (Q24,
    /// Q20 N; the product in Q20): a floor, so a built table puts the anchor where the
    /// exact line is half an LSB below `force_lo`, within 1,024 strain LSBs of its own
    /// point (zero when the table starts at the kink, else the law at the first knot),
    /// and the line rounds to the nearest Q20 N (`docs/accuracy.md`).
    pub anchor_lo: i32,
    /// See `anchor_lo`.
    pub force_lo: i32,
    /// Slope of the line below `strain_lo` (Q16 N per unit strain): its stiffness (the
    /// nearest Q16 value where `slope_lo` is Q28).
    pub stiffness_lo: i32,
    /// The same slope for the line's force, finer where it fits: Q28 N per unit strain
    /// when `stiffness_lo` is within ±2¹⁹ (below 8 N per unit strain,
    /// [`fine_line`]), the force then `force_lo + hi(slope_lo · (e ⊖ anchor_lo))`;
    /// else Q16, equal to `stiffness_lo`. A Q16 slope alone is off by up to 2⁻¹⁶ N per
    /// unit strain, which over the tension end of the domain is up to 8 force LSBs: more
    /// than the product's bound for a spring below 0.4 N at `F(0.95)`.
    pub slope_lo: i32,
    /// The line above the tabulated range is `force_hi + ⌊slope_hi · (e − corner_hi)⌋`
    /// (Q20 N): on a built table `force_hi` is the law's force at `corner_hi` (the first
    /// strain past the last knot) floored, plus one LSB, which balances the product's
    /// floor (the line within (−1, 1) LSB of the law). Under a lower corner
    /// ([`ForceTable::lower_corner`]) `corner_hi` lies below the table: `force_hi` is
    /// then the same line extrapolated down to it, exactly in the product's terms (so
    /// that the line is the same from `strain_hi` up), and at least −1024 N: the line
    /// is exact up to `2048 N + force_hi` (1024 N at least), where its product is held,
    /// and the force with it (monotone, never past 2048 N).
    pub force_hi: i32,
    /// Slope of the line above (Q16 N per unit strain): its stiffness (the nearest Q16
    /// value where `slope_hi` is Q28).
    pub stiffness_hi: i32,
    /// The same slope for the line's force, as `slope_lo` is the line below's: Q28 when
    /// `stiffness_hi` is within ±2¹⁹ ([`fine_line`]), the force then `force_hi +
    /// hi(slope_hi · (e ⊖ corner_hi))`; else Q16, equal to `stiffness_hi`. A soft series
    /// spring's `k_p` line from a solid point well inside the domain drifts, with a Q16
    /// slope, by half an LSB per unit strain: 2.5 force LSBs over 0.33 strain, more than
    /// the product's bound for a spring of 0.07 N at `F(0.95)`.
    pub slope_hi: i32,
    /// The coefficients' unit: Q(20 + `shift`) N, `shift` ∈ 0 … 12.
    pub shift: u32,
    /// The stiffness in Q16 is `⌊(D · stiff_scale + 2³¹) / 2³²⌋ · stiff_post` (rounded)
    /// for `D = 2 dF/dτ` in the coefficients' unit (`stiff_post` a power of two).
    pub stiff_scale: i32,
    /// See `stiff_scale`.
    pub stiff_post: i32,
    /// The end of the graded corner (Q24), exclusive: the line above starts here.
    /// `strain_hi` when the table has no graded corner (see [`ForceTable::corner`]).
    /// Below `strain_lo` for a *lower* corner ([`ForceTable::lower_corner`]): the corner
    /// is then `(corner_hi, strain_lo]`, the line below at and under `corner_hi`.
    pub corner_hi: i32,
    /// The graded corner's anchor `A` (Q24), just past its end: a strain `e` in it has
    /// the coordinate `d = (A − e) · corner_pre` (`u32`; `corner_pre` the negative of a
    /// factor, as an `i32`, where the corner lies above its anchor) in
    /// `[2^(32 − octaves), 2³²)`, octave `z = clz(d)` (0 … octaves − 1, at most
    /// [`CORNER_OCTAVES_MAX`]), [`CORNER_PER_OCTAVE`] segments in each.
    pub corner_anchor: i32,
    /// See `corner_anchor`.
    pub corner_pre: u32,
    /// The corner's first segment: `corner_base + 4 z + j` (`j` the two bits after `d`'s
    /// leading one).
    pub corner_base: u32,
    /// The stiffness in the corner, in Q16: `⌊(D · 2^z) · corner_scale / 2³²⌋ ·
    /// corner_post` for `D = 2 dF/dτ` in the coefficients' unit, which the builder keeps
    /// within ±2³¹ times `2^−z` in octave `z` (`τ` runs down in strain, so the scale is
    /// negative; positive where the corner lies above its anchor; `corner_post` a power
    /// of two).
    pub corner_scale: i32,
    /// See `corner_scale`.
    pub corner_post: i32,
    /// The largest force error against the `f64` law over the domain, measured when the
    /// table was built: parts per 10⁹ of `F(to)` ([`ForceTable::max_error`]);
    /// [`UNMEASURED`] in both fields when it was not measured.
    pub err_force_ppb: u32,
    /// The largest stiffness error (relative, away from the law's kinks), parts per 10⁹.
    pub err_stiffness_ppb: u32,
    /// Per segment `[C0, C1, C2, C3] = [c0, 2 c1, 4 c2, 8 c3]` of the cubic
    /// `F(τ) = c0 + c1 τ + c2 τ² + c3 τ³`, `τ ∈ [0, 1)`: the degree-`j` coefficient carries
    /// `2^j` so that each Horner step is one product by `τ/2` ([`crate::q::mul_t`]).
    /// `c0` is the knot value (plus [`knot_bias`], for rounding) and `C3 = 8 (c0' − c0) −
    /// 4 C1 − 2 C2` makes the cubic end on the next knot `c0'` exactly.
    pub segments: [[i32; 4]; S],
}

/// A tabulated inverse law with `S` segments (`S + 1` knots); see the module docs. It is
/// built and held to the product's bound by [`ForceTable::new`] or
/// [`ForceTable::with_domain`] (`builder/`: what `mccs table` emits), or wraps a table
/// emitted by `mccs table` ([`ForceTable::from_raw`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(transparent)]
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

impl<const S: usize> ForceTable<S> {
    /// Wraps raw contents (for tables emitted by `mccs table` and `include!`d).
    pub const fn from_raw(raw: RawTable<S>) -> Self {
        Self { raw }
    }

    /// Checks the invariants every built table keeps (a raw table from elsewhere may not):
    /// a tabulated range of at least one strain LSB per segment, a power-of-two index
    /// prefactor, an index scale of 1 … 31 significant bits, a coefficient shift of at
    /// most 12, a power-of-two stiffness post-factor, non-negative slopes on the lines,
    /// and a graded corner's coordinate within its octaves over its range (above the
    /// grid, or under it as a lower corner, whose line above then starts from a force of
    /// at least −1024 N). Evaluation never panics either way; on a table that fails this
    /// check its values mean nothing.
    pub fn validate(&self) -> Result<(), TableError> {
        let r = &self.raw;
        let span = r.strain_hi as i64 - r.strain_lo as i64;
        let ok = S > 0
            && span >= S as i64
            && r.index_pre.is_power_of_two()
            && r.index_scale > 0
            && r.index_scale < 1 << 31
            && r.shift <= 12
            && r.stiff_post > 0
            && (r.stiff_post as u32).is_power_of_two()
            && r.stiff_scale >= 0
            && r.stiffness_lo >= 0
            && self.slope_fits()
            && r.stiffness_hi >= 0
            && (r.corner_hi >= r.strain_hi || r.corner_hi < r.strain_lo)
            && (r.corner_hi == r.strain_hi || self.corner_fits())
            && (!self.lower_corner() || r.force_hi >= -(1 << 30));
        if ok {
            Ok(())
        } else {
            Err(TableError::Inconsistent)
        }
    }

    /// The largest force and stiffness errors against the `f64` law over the table's
    /// domain, measured when it was built ([`measure`]): what the firmware runs with.
    /// `None` for a table built without measuring
    /// ([`ForceTable::one_placement_unmeasured`]).
    pub fn max_error(&self) -> Option<TableBound> {
        let r = &self.raw;
        if r.err_force_ppb == UNMEASURED && r.err_stiffness_ppb == UNMEASURED {
            None
        } else {
            Some(TableBound::from_ppb(r.err_force_ppb, r.err_stiffness_ppb))
        }
    }

    /// The raw contents.
    pub const fn raw(&self) -> &RawTable<S> {
        &self.raw
    }

    /// Size of the table in bytes.
    pub const SIZE_BYTES: usize = core::mem::size_of::<RawTable<S>>();

    /// The tabulated strain range `(lo, hi)` (with the graded corner, if any): the line
    /// below at and under `lo`, the line above at and over `hi`.
    pub fn tabulated_range(&self) -> (Strain, Strain) {
        let r = &self.raw;
        let (lo, hi) = if self.lower_corner() {
            (r.corner_hi, r.strain_hi)
        } else {
            (r.strain_lo, r.corner_hi)
        };
        (Strain::from_bits(lo), Strain::from_bits(hi))
    }

    /// The graded corner's range `[lo, hi)`, if the table has one: knots graded
    /// geometrically toward its anchor (the solid point `Δ(F_C)`, a preload's kink
    /// `Δ(P)`, or the law's first kink), where the law bends hardest (see the module
    /// docs). Above the uniform grid
    /// `[strain_hi, corner_hi)`; a lower corner ([`ForceTable::lower_corner`])
    /// `[corner_hi + 1, strain_lo + 1)`.
    pub fn corner(&self) -> Option<(Strain, Strain)> {
        // (The end saturates only on a table that fails `validate`.)
        let (first, last) = self.corner_strains()?;
        let end = (last + 1).min(i32::MAX as i64);
        Some((
            Strain::from_bits(first as i32),
            Strain::from_bits(end as i32),
        ))
    }

    /// The graded corner's octaves: its segments are the table's last, from
    /// `corner_base` on, [`CORNER_PER_OCTAVE`] in each ([`CORNER_OCTAVES`] as the builder
    /// first places it, up to [`CORNER_OCTAVES_MAX`] where that missed). Meaningful only
    /// for a table with a corner ([`ForceTable::corner`]).
    pub fn corner_octaves(&self) -> usize {
        S.saturating_sub(self.raw.corner_base as usize) / CORNER_PER_OCTAVE
    }

    /// The graded corner's segments: [`CORNER_PER_OCTAVE`] in each of its
    /// [`ForceTable::corner_octaves`]; 0 without a corner.
    pub fn corner_segments(&self) -> usize {
        if self.corner_strains().is_some() {
            self.corner_octaves() * CORNER_PER_OCTAVE
        } else {
            0
        }
    }

    /// The graded corner's first and last strains (Q24, `first ≤ last`), if it has one.
    fn corner_strains(&self) -> Option<(i64, i64)> {
        let r = &self.raw;
        if self.lower_corner() {
            Some((r.corner_hi as i64 + 1, r.strain_lo as i64))
        } else {
            (r.corner_hi > r.strain_hi).then_some((r.strain_hi as i64, r.corner_hi as i64 - 1))
        }
    }

    /// Whether the graded corner lies below the uniform grid (`corner_hi < strain_lo`):
    /// over `(corner_hi, strain_lo]`, graded toward a preload's kink `Δ(P)` at the grid's
    /// first knot, or from above toward the law's first kink at its own first, the line
    /// below under it, and the line above anchored at `corner_hi` ([`RawTable::force_hi`]).
    pub fn lower_corner(&self) -> bool {
        self.raw.corner_hi < self.raw.strain_lo
    }

    /// Whether each line's force slope is its stiffness: to within one Q16 LSB in Q28
    /// ([`fine_line`]), else the same.
    fn slope_fits(&self) -> bool {
        let fits = |slope: i32, stiffness: i32| {
            if fine_line(stiffness) {
                let q16 = slope >> (FINE_SLOPE_FRAC - STIFF_FRAC);
                slope >= 0 && (q16 - stiffness).abs() <= 1
            } else {
                slope == stiffness
            }
        };
        let r = &self.raw;
        fits(r.slope_lo, r.stiffness_lo) && fits(r.slope_hi, r.stiffness_hi)
    }

    /// Whether the graded corner's coordinate stays in `[2^(32 − octaves), 2³²)` over its
    /// range and its segments are the table's last ones, 1 to [`CORNER_OCTAVES_MAX`]
    /// octaves of them ([`ForceTable::corner_octaves`]). `corner_pre` is signed (a corner
    /// graded toward its anchor from above has a negative one: the evaluation's `u32`
    /// product is the same), and the stiffness scale has the other sign.
    fn corner_fits(&self) -> bool {
        let r = &self.raw;
        let pre = corner_pre_signed(r.corner_pre) as i64;
        let d = |e: i64| (r.corner_anchor as i64 - e) * pre;
        let Some((first, last)) = self.corner_strains() else {
            return false;
        };
        let (d0, d1) = (d(first), d(last));
        let octaves = self.corner_octaves();
        (1..=CORNER_OCTAVES_MAX).contains(&octaves)
            && r.corner_base as usize + octaves * CORNER_PER_OCTAVE == S
            && d0.max(d1) < 1 << 32
            && d0.min(d1) >= 1i64 << (32 - octaves)
            && r.corner_post > 0
            && (r.corner_post as u32).is_power_of_two()
            && ((pre > 0 && r.corner_scale <= 0) || (pre < 0 && r.corner_scale >= 0))
    }

    /// The strain range of the graded corner's segment `i` (`4 z + j`, octave `z`,
    /// segment `j` in it): `(lower, upper)`; `τ` runs from the end nearer the anchor
    /// (the upper end, or the lower where the corner is graded toward its anchor from
    /// above). For measuring; `f64`.
    pub fn corner_segment_range(&self, i: usize) -> (f64, f64) {
        let r = &self.raw;
        let (z, j) = (i / CORNER_PER_OCTAVE, i % CORNER_PER_OCTAVE);
        let a = corner_strain(r.corner_anchor, r.corner_pre, z, j + 1);
        let b = corner_strain(r.corner_anchor, r.corner_pre, z, j);
        (libm::fmin(a, b), libm::fmax(a, b))
    }

    /// The largest tangent stiffness anywhere on the curve (both lines, and every segment
    /// at its ends and middle), for stability bounds. A loop over the segments: call it
    /// at start-up, not per tick.
    pub fn max_stiffness(&self) -> Stiffness {
        let r = &self.raw;
        let mut max = r.stiffness_lo.max(r.stiffness_hi);
        let span = r.strain_hi.saturating_sub(r.strain_lo) as i64;
        let used = self.segments_used().max(1) as i64;
        for i in 0..=2 * used {
            let e = r.strain_lo as i64 + span * i / (2 * used);
            let (_, k) = self.force_and_stiffness(Strain::from_bits(e as i32));
            max = max.max(k.to_bits());
        }
        if let Some((first, last)) = self.corner_strains() {
            for i in 0..self.corner_segments() {
                let (a, b) = self.corner_segment_range(i);
                for x in [a, (a + b) / 2.0, b] {
                    let e = libm::round(x * (1u64 << STRAIN_FRAC) as f64) as i64;
                    let e = e.clamp(first, last);
                    let (_, k) = self.force_and_stiffness(Strain::from_bits(e as i32));
                    max = max.max(k.to_bits());
                }
            }
        }
        Stiffness::from_bits(max)
    }

    /// The segments the tabulated range spans (1 … `S`): `S`, unless the grid was
    /// aligned on both the cone's transition and the preload's kink, whose longer step
    /// may cover the range with fewer (the others are never reached).
    pub fn segments_used(&self) -> usize {
        let r = &self.raw;
        if r.strain_hi <= r.strain_lo {
            return S.min(1);
        }
        // The segment of the range's last strain, as the evaluation finds it.
        ((self.position(r.strain_hi.wrapping_sub(1)) >> 15) as usize + 1).clamp(S.min(1), S)
    }
}

/// The strain (`f64`) of the graded corner's coordinate `d = 2^(31 − z) (1 + jj/4)`
/// (`jj` ≤ 4: `jj = 4` is the next octave's start), for a corner anchored at `anchor`
/// (Q24) with `pre` (signed: [`corner_pre_signed`]).
pub(crate) fn corner_strain(anchor: i32, pre: u32, z: usize, jj: usize) -> f64 {
    let d = libm::ldexp(1.0 + jj as f64 / CORNER_PER_OCTAVE as f64, 31 - z as i32);
    (anchor as f64 - d / corner_pre_signed(pre) as f64) / (1u64 << STRAIN_FRAC) as f64
}

/// A corner's `pre` as the signed factor it is: a corner graded toward its anchor from
/// below has one of 1 … 2^(32 − octaves), one graded toward it from above (its strains
/// above the anchor) the negative of one, as a `u32` (the evaluation's wrapping product
/// `(A − e) · pre` is `(e − A) · |pre|` then).
pub(crate) const fn corner_pre_signed(pre: u32) -> i32 {
    pre as i32
}

/// What every knot carries above its rounded value in the coefficients' unit Q(20 +
/// `shift`): half a Q20 LSB, `2^(shift − 1)` (none for `shift` 0), so that the
/// evaluation's final `>> shift` rounds a knot, and the cubic between, to the nearest
/// Q20 N instead of flooring it (the output's share of the error half an LSB, not one).
/// A constant on every knot: the cubics' differences, and so their ends, are unchanged.
#[inline(always)]
pub const fn knot_bias(shift: u32) -> i32 {
    if shift == 0 || shift > 12 {
        0
    } else {
        1 << (shift - 1)
    }
}

/// Fraction bits of a line's force slope where it is fine ([`fine_line`]).
pub const FINE_SLOPE_FRAC: u32 = 28;

impl<const S: usize> RawTable<S> {
    /// Fraction bits of [`RawTable::slope_lo`]: [`FINE_SLOPE_FRAC`] where
    /// [`fine_line`], else `STIFF_FRAC` (16).
    pub const fn slope_lo_frac(&self) -> u32 {
        slope_frac(self.stiffness_lo)
    }

    /// Fraction bits of [`RawTable::slope_hi`], as [`RawTable::slope_lo_frac`].
    pub const fn slope_hi_frac(&self) -> u32 {
        slope_frac(self.stiffness_hi)
    }
}

/// Fraction bits of a line's force slope with this stiffness (Q16).
pub(crate) const fn slope_frac(stiffness: i32) -> u32 {
    if fine_line(stiffness) {
        FINE_SLOPE_FRAC
    } else {
        STIFF_FRAC
    }
}

/// Whether a line (below or above the table) with this stiffness carries its force's
/// slope in Q28 ([`RawTable::slope_lo`], [`RawTable::slope_hi`]): within ±2¹⁹ (below 8
/// N per unit strain in Q16), where the Q28 slope fits an `i32`.
#[inline(always)]
pub const fn fine_line(stiffness: i32) -> bool {
    stiffness >= -(1 << 19) && stiffness < 1 << 19
}
