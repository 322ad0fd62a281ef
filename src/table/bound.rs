//! [`TableBound`]: how far a [`ForceTable`] is from the `f64` law it tabulates, measured
//! when it is built for emission or against a bound ([`ForceTable::measured`],
//! [`ForceTable::with_bound`]; every table `mccs table` emits) and carried with it
//! (`RawTable::err_force_ppb`, `err_stiffness_ppb`; [`ForceTable::max_error`]), and the
//! bound the product promises ([`TableBound::PRODUCT`]). Every table [`ForceTable::new`]
//! builds is measured: about `65 S + 1000` evaluations of the `f64` law per placement
//! tried.
//!
//! The measurement ([`measure`]) evaluates the table and the law at every knot and at
//! [`POINTS_PER_SEGMENT`] points inside each segment, at as many points on the lines
//! between the table and the domain's ends, and on each side of each kink just outside
//! its margin (densely over the first 5 % of a margin beyond it), over the whole domain `[from, to]`:
//! - force: `max |F_table − F_law| / F_law(to)`, the law clamped to the force format
//!   (±2048 N: beyond it the table saturates, as documented);
//! - stiffness: `max |k_table − k_law| / k_law`, leaving out the strains within
//!   [`KINK_MARGIN`] of the law's kinks (`Δ(min(F_T, P))`, `Δ(P)`, `Δ(F_C)`), where the
//!   table may take either side's slope.
//!
//! `f64` and a loop over the segments: start-up or host, never per tick.

use super::ForceTable;
use crate::law::Law;
use crate::units::{Strain, FORCE_FRAC, STIFF_FRAC, STRAIN_FRAC};

/// Strains this close to a kink of the law are left out of the stiffness error.
pub const KINK_MARGIN: f64 = 2e-3;
/// Points measured inside each segment (and on each line beyond the table), besides the
/// knots.
pub const POINTS_PER_SEGMENT: usize = 64;

/// A table's largest errors against the law over its domain (relative: see the module
/// docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TableBound {
    /// Largest force error, relative to `F(to)`.
    pub force: f64,
    /// Largest stiffness error, relative to the law's stiffness there.
    pub stiffness: f64,
}

impl TableBound {
    /// What the product promises for every table it emits: force within 2e-5 of
    /// `F(to)`, stiffness within 1e-3 relative.
    pub const PRODUCT: Self = Self {
        force: 2e-5,
        stiffness: 1e-3,
    };

    /// Whether `self` is within `bound` on both counts.
    pub fn within(&self, bound: &Self) -> bool {
        self.force <= bound.force && self.stiffness <= bound.stiffness
    }

    /// How far `self` is from `bound`: the larger of its two ratios to it (at most 1
    /// exactly when [`TableBound::within`]).
    pub fn ratio_to(&self, bound: &Self) -> f64 {
        libm::fmax(self.force / bound.force, self.stiffness / bound.stiffness)
    }

    /// In parts per 10⁹, saturating (as stored in the raw table).
    pub fn to_ppb(&self) -> (u32, u32) {
        (ppb(self.force), ppb(self.stiffness))
    }

    /// From parts per 10⁹.
    pub fn from_ppb(force: u32, stiffness: u32) -> Self {
        Self {
            force: force as f64 * 1e-9,
            stiffness: stiffness as f64 * 1e-9,
        }
    }
}

/// The raw tables' mark for "not measured" (both fields).
pub const UNMEASURED: u32 = u32::MAX;

/// `x` in parts per 10⁹, rounded up, saturating below [`UNMEASURED`] (NaN saturates too).
fn ppb(x: f64) -> u32 {
    let v = libm::ceil(x * 1e9);
    let top = (UNMEASURED - 1) as f64;
    if v >= 0.0 && v < top {
        v as u32
    } else if v < 0.0 {
        0
    } else {
        UNMEASURED - 1
    }
}

/// The least error the output formats allow a table of `law` over `[from, to]`, in the
/// terms of [`measure`]: half a Q20 force LSB relative to `F(to)`, and half a Q16
/// stiffness LSB relative to the law's least stiffness on the domain (sampled at 1,001
/// strains). No placement of knots can bring a table's largest force error below the
/// first (the force runs continuously through many LSBs, and its rounding error reaches
/// half of one), nor its stiffness error below the second unless the table happens to
/// hold the least stiffness exactly (on a line, a constant): a bound below them is out of
/// the formats' reach.
pub fn format_floor(law: &Law, from: f64, to: f64) -> TableBound {
    let half_lsb = |frac: u32| 0.5 / (1u64 << frac) as f64;
    let mut least = f64::INFINITY;
    for i in 0..=1000 {
        let (_, k) = law.force_and_stiffness(from + (to - from) * i as f64 / 1000.0);
        least = libm::fmin(least, k);
    }
    TableBound {
        force: half_lsb(FORCE_FRAC) / libm::fabs(law.force(to)),
        stiffness: half_lsb(STIFF_FRAC) / least,
    }
}

/// Measures `table` against `law` over `[from, to]` (see the module docs).
pub fn measure<const S: usize>(table: &ForceTable<S>, law: &Law, from: f64, to: f64) -> TableBound {
    let scale = libm::fabs(law.force(to));
    let mut kinks = [law.strain_t(), law.strain_c(), f64::NAN];
    if law.preload > law.f_t {
        kinks[2] = law.delta(law.preload);
    }
    // Raw bits to f64 by hand: the `fixed` conversions cost kilobytes of flash on a
    // Cortex-M0, and this runs there at start-up.
    let unit = |frac: u32| 1.0 / (1u64 << frac) as f64;
    let (u_strain, u_force, u_stiff) = (unit(STRAIN_FRAC), unit(FORCE_FRAC), unit(STIFF_FRAC));
    let (f_lim, k_lim) = (i32::MAX as f64 * u_force, i32::MAX as f64 * u_stiff);
    let mut worst = TableBound {
        force: 0.0,
        stiffness: 0.0,
    };
    let mut at = |e: f64| {
        if !(e >= from && e <= to) {
            return;
        }
        let bits = libm::round(e / u_strain) as i32;
        let e = bits as f64 * u_strain;
        let (f, k) = table.force_and_stiffness(Strain::from_bits(bits));
        let (f, k) = (f.to_bits() as f64 * u_force, k.to_bits() as f64 * u_stiff);
        let (fl, kl) = law.force_and_stiffness(e);
        let ef = libm::fabs(f - libm::fmax(-f_lim, libm::fmin(fl, f_lim))) / scale;
        worst.force = libm::fmax(worst.force, ef);
        // A kink that is NaN (no preload kink) is far from everything.
        if kinks
            .iter()
            .all(|&x| x.is_nan() || libm::fabs(e - x) > KINK_MARGIN)
        {
            let kl = libm::fmin(kl, k_lim);
            let ek = libm::fabs(k - kl) / kl;
            worst.stiffness = libm::fmax(worst.stiffness, ek);
        }
    };
    visit_points(table, law, (from, to), &kinks, &mut at);
    // A NaN anywhere (it cannot come from a valid law) must not pass for zero.
    if worst.force.is_nan() || worst.stiffness.is_nan() || scale.is_nan() || scale <= 0.0 {
        worst = TableBound {
            force: f64::INFINITY,
            stiffness: f64::INFINITY,
        };
    }
    worst
}

/// Where [`measure`] compares: the lines beyond the table over `[from, to]`, every
/// segment, the graded corner's segments, [`POINTS_PER_SEGMENT`] apart; densely round the
/// cone's transition and just outside the margin round each of `kinks`.
fn visit_points<const S: usize>(
    table: &ForceTable<S>,
    law: &Law,
    (from, to): (f64, f64),
    kinks: &[f64; 3],
    at: &mut dyn FnMut(f64),
) {
    let u_strain = 1.0 / (1u64 << STRAIN_FRAC) as f64;
    let r = table.raw();
    let (lo, hi) = (r.strain_lo as f64 * u_strain, r.strain_hi as f64 * u_strain);
    let (bottom, top) = table.tabulated_range();
    let (bottom, top) = (
        bottom.to_bits() as f64 * u_strain,
        top.to_bits() as f64 * u_strain,
    );
    let n = POINTS_PER_SEGMENT;
    // The lines beyond the table, then every segment, then the graded corner's.
    for (a, b) in [(from, bottom), (top, to)] {
        if b > a {
            for j in 0..=n {
                at(a + (b - a) * j as f64 / n as f64);
            }
        }
    }
    let used = table.segments_used();
    let step = (hi - lo) / used as f64;
    for i in 0..used {
        for j in 0..=n {
            at(lo + step * (i as f64 + j as f64 / n as f64));
        }
    }
    if table.corner().is_some() {
        for i in 0..table.corner_segments() {
            let (a, b) = table.corner_segment_range(i);
            for j in 0..=n {
                at(a + (b - a) * j as f64 / n as f64);
            }
        }
    }
    // At and round the cone's own transition Δ(F_T) (a jump in curvature, not in slope,
    // when the preload is not F_T): the error has a corner there.
    let e_t = law.delta(law.f_t);
    for j in 0..=2 * n {
        for side in [-1.0, 1.0] {
            at(e_t + side * KINK_MARGIN * 0.05 * j as f64 / (2 * n) as f64);
        }
    }
    // Just outside the margin round each kink, where a corner the grid cannot follow
    // leaves its largest stiffness error, changing fast: densely over the first 5 % of a
    // margin beyond it (2 n points, 1.6e-6 strain apart), then out to 2.3 margins.
    for &x in kinks {
        for j in 0..2 * n {
            for side in [-1.0, 1.0] {
                at(x + side * KINK_MARGIN * (1.0 + 1e-6 + 0.05 * j as f64 / (2 * n) as f64));
                if j < n {
                    at(x + side * KINK_MARGIN * (1.05 + 0.02 * j as f64));
                }
            }
        }
    }
}
