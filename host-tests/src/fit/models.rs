//! The three models (MCCS, MCS, MS) with their fitted parameters, and the parameter
//! transforms that keep every trial point physical.

use crate::reference::Reference;
use mccs::{Cone, Linear, Params};

/// Sample cross-section for the MS model's force, mm²: the paper's 1 cm × 1 cm cubes.
pub const SAMPLE_AREA_MM2: f64 = 100.0;

/// The three models.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModelKind {
    /// Multi-component conical spring (this project).
    Mccs,
    /// Mass–conical-spring: the cone alone.
    Mcs,
    /// Exponential mass-spring, eq. 27.
    Ms,
}

impl ModelKind {
    /// All, in the paper's table order.
    pub const ALL: [ModelKind; 3] = [ModelKind::Ms, ModelKind::Mcs, ModelKind::Mccs];

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Mccs => "mccs",
            Self::Mcs => "mcs",
            Self::Ms => "ms",
        }
    }
}

/// Table 2's values for what the fit holds fixed.
pub(super) const D: f64 = 0.1;
pub(super) const N: f64 = 5.0;
pub(super) const D2: f64 = 0.8;
pub(super) const DP: f64 = 0.068;
pub(super) const DMP: f64 = 0.2;
pub(super) const NP: f64 = 10.0;

/// Bounds that keep fitted parameters physical: `D1/D2`, and `ln C2` for MS.
pub(super) const RATIO: (f64, f64) = (0.05, 0.95);
pub(super) const LN_C2: (f64, f64) = (-6.907755278982137, 6.907755278982137); // 1e-3 … 1e3

/// `t ∈ ℝ` to `(lo, hi)`, smoothly.
pub(super) fn bounded(t: f64, (lo, hi): (f64, f64)) -> f64 {
    lo + (hi - lo) / (1.0 + (-t).exp())
}

/// The inverse of [`bounded`].
pub(super) fn unbounded(x: f64, (lo, hi): (f64, f64)) -> f64 {
    let p = (x - lo) / (hi - lo);
    (p / (1.0 - p)).ln()
}

/// A model with concrete parameters: what it predicts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fitted {
    /// An MCCS spring.
    Mccs(Params),
    /// A cone alone.
    Mcs(Cone),
    /// Eq. 27's constants (MPa, 1, MPa).
    Ms {
        /// C1.
        c1: f64,
        /// C2.
        c2: f64,
        /// C3.
        c3: f64,
    },
}

impl Fitted {
    /// The model.
    pub fn kind(&self) -> ModelKind {
        match self {
            Self::Mccs(_) => ModelKind::Mccs,
            Self::Mcs(_) => ModelKind::Mcs,
            Self::Ms { .. } => ModelKind::Ms,
        }
    }

    /// The model's strain at force `f` (N), `f ≥ 0`. NaN where it has none (the cone
    /// alone is solid past `F_C`: it returns `H`).
    pub fn strain_at(&self, f: f64) -> f64 {
        self.strains(&[f])[0]
    }

    /// The model's strains at forces `forces`, its law derived once.
    pub fn strains(&self, forces: &[f64]) -> Vec<f64> {
        match self {
            Self::Mccs(p) => match Reference::new(p) {
                Ok(r) => forces.iter().map(|&f| r.delta(f)).collect(),
                Err(_) => vec![f64::NAN; forces.len()],
            },
            Self::Mcs(c) => {
                let r = Reference::cone_only(c);
                forces.iter().map(|&f| r.delta(f)).collect()
            }
            Self::Ms { c1, c2, c3 } => forces
                .iter()
                .map(|&f| ms_strain(*c1, *c2, *c3, f))
                .collect(),
        }
    }

    /// The model's force at strain `e` (N).
    pub fn force_at(&self, e: f64) -> f64 {
        match self {
            Self::Mccs(p) => Reference::new(p).map_or(f64::NAN, |r| r.force(e)),
            Self::Mcs(c) => Reference::cone_only(c).force(e),
            Self::Ms { c1, c2, c3 } => ms_force(*c1, *c2, *c3, e),
        }
    }

    /// The parameters the fit chooses (the others are held at Table 2's: the module
    /// docs), by their parameter-file keys (`c1`, `c2`, `c3` for MS, MPa, 1, MPa).
    pub fn fitted_params(&self) -> Vec<(&'static str, f64)> {
        let cone = |c: &Cone| {
            vec![
                ("cone.small_diameter", c.small_diameter),
                ("cone.compressible_height", c.compressible_height),
                ("cone.shear_modulus", c.shear_modulus),
            ]
        };
        match self {
            Self::Mccs(p) => {
                let mut v = cone(&p.cone);
                v.push(("linear.shear_modulus", p.linear.shear_modulus));
                v
            }
            Self::Mcs(c) => cone(c),
            Self::Ms { c1, c2, c3 } => vec![("c1", *c1), ("c2", *c2), ("c3", *c3)],
        }
    }

    /// The fitted parameters that sit on a bound the fit holds them within (within
    /// 1e-3 of the bound's range): `(key, the bound, "lower" or "upper", what it is)`.
    pub fn on_bounds(&self) -> Vec<(&'static str, f64, &'static str, &'static str)> {
        let near = |x: f64, (lo, hi): (f64, f64)| {
            let tol = 1e-3 * (hi - lo);
            if x - lo <= tol {
                Some((lo, "lower"))
            } else if hi - x <= tol {
                Some((hi, "upper"))
            } else {
                None
            }
        };
        let mut out = Vec::new();
        let cone = match self {
            Self::Mccs(p) => Some(p.cone),
            Self::Mcs(c) => Some(*c),
            Self::Ms { .. } => None,
        };
        if let Some(c) = cone {
            if let Some((b, side)) = near(c.small_diameter / D2, RATIO) {
                out.push(("cone.small_diameter", b * D2, side, "0.05 … 0.95 of D2"));
            }
        }
        if let Self::Ms { c2, .. } = self {
            if let Some((b, side)) = near(c2.ln(), LN_C2) {
                out.push(("c2", b.exp(), side, "1e-3 … 1e3"));
            }
        }
        out
    }

    /// Parameters in fit space: MCCS `[logit(D1/D2), ln H, ln s, ln k_p]`, MCS the first
    /// three, MS `[ln C1, ln C2, ln C3]`.
    pub fn theta(&self) -> Vec<f64> {
        match self {
            Self::Mccs(p) => {
                let r = Reference::new(p).expect("valid");
                vec![
                    unbounded(p.cone.small_diameter / D2, RATIO),
                    p.cone.compressible_height.ln(),
                    (p.cone.shear_modulus * D.powi(4) / N).ln(),
                    r.series.expect("series").k_p.ln(),
                ]
            }
            Self::Mcs(c) => vec![
                unbounded(c.small_diameter / D2, RATIO),
                c.compressible_height.ln(),
                (c.shear_modulus * D.powi(4) / N).ln(),
            ],
            Self::Ms { c1, c2, c3 } => vec![c1.ln(), unbounded(c2.ln(), LN_C2), c3.ln()],
        }
    }

    /// A model of `kind` from fit-space parameters (each clamped to ±40, so that a wild
    /// trial step still gives finite, valid parameters).
    pub fn from_theta(kind: ModelKind, t: &[f64]) -> Fitted {
        let t: Vec<f64> = t.iter().map(|x| x.clamp(-40.0, 40.0)).collect();
        let t = t.as_slice();
        let cone = |t: &[f64]| Cone {
            wire_diameter: D,
            small_diameter: D2 * bounded(t[0], RATIO),
            large_diameter: D2,
            active_coils: N,
            compressible_height: t[1].exp(),
            shear_modulus: t[2].exp() * N / D.powi(4),
        };
        match kind {
            ModelKind::Mccs => Fitted::Mccs(Params {
                cone: cone(t),
                linear: Linear {
                    wire_diameter: DP,
                    mean_diameter: DMP,
                    active_coils: NP,
                    shear_modulus: t[3].exp() * 8.0 * NP * DMP.powi(3) / DP.powi(4),
                    preload: None,
                },
            }),
            ModelKind::Mcs => Fitted::Mcs(cone(t)),
            ModelKind::Ms => Fitted::Ms {
                c1: t[0].exp(),
                c2: bounded(t[1], LN_C2).exp(),
                c3: t[2].exp(),
            },
        }
    }
}

/// Eq. 27's compressive force (N) at strain `e` ∈ [0, 1): `−T_s(1 − e) · area`.
pub fn ms_force(c1: f64, c2: f64, c3: f64, e: f64) -> f64 {
    let l = 1.0 - e;
    let ts = 2.0 * (l.powi(3) - 1.0) / (l * l)
        * (c1 * c2 * (c2 * (l.powi(3) - 3.0 * l + 2.0) / l).exp() + c3 / l);
    -ts * SAMPLE_AREA_MM2
}

/// Eq. 27's strain at force `f` (the force grows with strain on [0, 1)): the root in a
/// bracket, by the Illinois variant of regula falsi with a bisection step whenever the
/// bracket fails to halve — superlinear, about 10 evaluations to full precision where
/// bisection took 100.
pub fn ms_strain(c1: f64, c2: f64, c3: f64, f: f64) -> f64 {
    if f <= 0.0 {
        return 0.0;
    }
    let g = |e: f64| ms_force(c1, c2, c3, e) - f;
    let (mut lo, mut hi) = (0.0, 1.0 - 1e-12);
    let (mut g_lo, mut g_hi) = (g(lo), g(hi));
    if g_hi.is_nan() || g_hi < 0.0 {
        return hi;
    }
    if g_lo.is_nan() || g_lo >= 0.0 {
        return lo;
    }
    // Which end was kept last (−1 low, +1 high), for the Illinois halving.
    let mut side = 0;
    for _ in 0..200 {
        let width = hi - lo;
        let mut x = hi - g_hi * width / (g_hi - g_lo);
        if !(x > lo && x < hi) {
            x = 0.5 * (lo + hi);
        }
        let gx = g(x);
        if gx.is_nan() {
            return f64::NAN;
        }
        if gx < 0.0 {
            (lo, g_lo) = (x, gx);
            if side == -1 {
                g_hi *= 0.5;
            }
            side = -1;
        } else {
            (hi, g_hi) = (x, gx);
            if side == 1 {
                g_lo *= 0.5;
            }
            side = 1;
        }
        if gx == 0.0 || hi - lo <= 1e-15 * hi.max(1e-300) {
            return x;
        }
        if hi - lo > 0.5 * width {
            // The secant crawled: bisect once.
            let mid = 0.5 * (lo + hi);
            let gm = g(mid);
            if gm < 0.0 {
                (lo, g_lo) = (mid, gm);
            } else {
                (hi, g_hi) = (mid, gm);
            }
            side = 0;
        }
    }
    0.5 * (lo + hi)
}
