//! The graded corner: segments graded by octaves of distance toward the solid point, a
//! preload's kink or the law's first kink, and its coefficients' bounds and scale.

use super::cubic::{hermite, knot_units, rounded_cubic, with_post, Magnitude};
use crate::law::Law;
use crate::table::{
    corner_pre_signed, corner_strain, TableError, CORNER_OCTAVES_MAX, CORNER_PER_OCTAVE,
};
use crate::units::{checked_from_f64, FORCE_FRAC, STRAIN_FRAC};

/// A graded corner: `4 · octaves` segments toward its end ([`CornerEnd`]: the solid
/// point `Δ(F_C)`, or the domain's end), each octave of distance from it
/// ([`CORNER_OCTAVES`](crate::table::CORNER_OCTAVES)
/// of them, the nearest `len/256` wide, or up to [`CORNER_OCTAVES_MAX`]) cut into
/// [`CORNER_PER_OCTAVE`]: segments about a tenth of their distance from the corner, where
/// a soft cone against a stiff series spring rises like a square root.
#[derive(Clone, Copy)]
pub(super) struct Corner {
    /// The anchor `A` (Q24): the end plus the nearest octave's inner end.
    pub(super) anchor: i32,
    pub(super) pre: u32,
    /// One past the last strain of the corner (Q24): the last knot is its end.
    pub(super) hi: i32,
    /// A corner under the grid ([`Corner::under_grid`]): the last strain below it (the
    /// table's `corner_hi`), Q24; its own last strain, `hi − 1`, is the grid's first knot.
    pub(super) lo: i32,
    /// Where the uniform grid ends (a little past the corner's start), strain.
    pub(super) start: f64,
    /// Where it ends: at the solid point, the last knot's force is `F_C` exactly.
    pub(super) end: CornerEnd,
    /// The knot `(z, jj)` that lies on a preload's kink `Δ(P)` (within
    /// [`KINK_ON_KNOT_LSB`]), if one does: the segments on either side of it take the
    /// law's slope from their own side.
    kink: Option<(usize, usize)>,
    /// Its octaves ([`CORNER_OCTAVES`](crate::table::CORNER_OCTAVES) …
    /// [`CORNER_OCTAVES_MAX`]), the nearest
    /// `2^−octaves` of its length.
    octaves: usize,
}

/// Where a graded corner ends: its last knot, where the line above starts.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum CornerEnd {
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
    /// which starts there (a *lower* corner,
    /// [`ForceTable::lower_corner`](crate::table::ForceTable::lower_corner)): it reaches down
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
    pub(super) fn place(
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
    /// [`ForceTable::lower_corner`](crate::table::ForceTable::lower_corner)).
    pub(super) fn under_grid(&self) -> bool {
        matches!(self.end, CornerEnd::Lower | CornerEnd::Onset)
    }

    /// Whether the corner lies above its anchor (graded toward it from above).
    pub(super) fn above_anchor(&self) -> bool {
        self.end == CornerEnd::Onset
    }

    /// The strain of coordinate `(z, jj)` ([`corner_strain`]).
    pub(super) fn strain(&self, z: usize, jj: usize) -> f64 {
        corner_strain(self.anchor, self.pre, z, jj)
    }

    /// The force and stiffness at `(z, jj)`, in Q20 N and N per unit strain: at the
    /// solid point (the last knot of a corner ending there) the law's own `F_C` and
    /// slope from below; at a preload's kink (the last knot of [`CornerEnd::Kink`]) `P`
    /// and the slope from below.
    pub(super) fn knot(&self, law: &Law, z: usize, jj: usize) -> Result<(f64, f64), TableError> {
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
    pub(super) fn segment_ends(
        &self,
        law: &Law,
    ) -> Result<[[f64; 4]; CORNER_SEGMENTS_MAX], TableError> {
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

/// The corner's [`Magnitude`], from its segments' ends.
pub(super) fn magnitude(ends: &[[f64; 4]]) -> Magnitude {
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

/// The corner's coefficients in the unit of `shift`, rounded as
/// [`segments`](super::cubic::segments) rounds
/// them ([`rounded_cubic`], with octave `z`'s `2^z`).
pub(super) fn fill_corner(
    ends: &[[f64; 4]],
    shift: u32,
    out: &mut [[i32; 4]],
) -> Result<(), TableError> {
    let scale = (1u64 << shift) as f64;
    for (i, (c, &[a0, a1, m0, m1])) in out.iter_mut().zip(ends).enumerate() {
        let (a0, a1) = (knot_units(a0, shift), knot_units(a1, shift));
        let z = (i / CORNER_PER_OCTAVE) as i32;
        *c = rounded_cubic(a0, a1, m0 * scale, m1 * scale, z)?;
    }
    Ok(())
}

/// The corner's stiffness scale `(corner_scale, corner_post)`: in octave `z`,
/// `dτ/dε = −pre · 2^(z − 5)`, so dF/dε (Q16) `= −D · pre · 2^(z − 10 − shift)` `=
/// (D · scale) >> (32 − z)` with `scale = −pre · 2^(22 − shift)`, a power of two moved
/// into the post-factor while it would not fit (`pre` signed: positive for a corner
/// above its anchor, [`corner_pre_signed`]).
pub(super) fn corner_scale(pre: u32, shift: u32) -> Result<(i32, i32), TableError> {
    let pre = corner_pre_signed(pre) as f64;
    let (v, post) = with_post(libm::ldexp(libm::fabs(pre), 22 - shift as i32))?;
    Ok((if pre > 0.0 { -v } else { v }, post))
}

/// Segments of a graded corner of [`CORNER_OCTAVES_MAX`].
pub(super) const CORNER_SEGMENTS_MAX: usize = CORNER_OCTAVES_MAX * CORNER_PER_OCTAVE;

/// The coordinate `d` of a graded corner's nearest octave's inner end, `2^(32 − octaves)`:
/// a corner's `d` lies in `[corner_inner, 2³²)`.
pub(super) fn corner_inner(octaves: usize) -> f64 {
    libm::ldexp(1.0, 32 - octaves as i32)
}

/// How near (Q24 LSBs) a corner knot must lie to a preload's kink to take the law's
/// one-sided slopes there ([`Corner::kink`]).
pub(super) const KINK_ON_KNOT_LSB: f64 = 64.0;
