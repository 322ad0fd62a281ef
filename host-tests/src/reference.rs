//! The MCCS law of `docs/model.md` in `f64`: the reference every other part is held to.
//!
//! `Δ` (strain) as a function of the force `F` (N), its inverse `F(Δ)` and the tangent
//! stiffness `dF/dΔ`. The nonlinear phase is written in `y = F^(1/3)`:
//!
//! ```text
//! Δ_cone(y) = H/(D2−D1) · [D2 − ¾·A^(1/3)/y − D1⁴ y³/(4A)],   A = H G d⁴/(8n)
//! ```
//!
//! which is eq. 11 with `D_c = A^(1/3)/y` substituted, and multiplying `Δ = Δ_cone + (F−P)/k_p`
//! by `y` gives the depressed quartic `a y⁴ + b y + c = 0` solved by Ferrari's method
//! ([`Reference::force_closed_form`]). [`Reference::force_bracketed`] is a safeguarded
//! Newton/bisection on the forward law; [`Reference::force`] polishes the closed form with
//! Newton steps to ~1e-15 relative.

use mccs::{Cone, ParamError, Params};

/// The series spring of an MCCS element: stiffness `k_p` and preload `P`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Series {
    /// Stiffness (N per unit strain).
    pub k_p: f64,
    /// Preload (N).
    pub preload: f64,
}

/// An MCCS spring (`series: Some`), or the conical spring alone (MCS, `series: None`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference {
    /// Linear-phase stiffness `k` (eq. 1).
    pub k: f64,
    /// Transition force `F_T`.
    pub f_t: f64,
    /// Solid force `F_C`.
    pub f_c: f64,
    /// The series spring; `None` for the cone alone.
    pub series: Option<Series>,
    h: f64,
    d1: f64,
    d2: f64,
    /// `A = H G d⁴ / (8 n)`.
    a: f64,
    /// `A^(1/3)`, `F_T^(1/3)` and `F_C^(1/3)`, each taken once (the inverse's time is
    /// mostly cube roots).
    a3: f64,
    y_t: f64,
    y_c: f64,
}

impl Reference {
    /// The MCCS law of `params` (validated).
    pub fn new(params: &Params) -> Result<Self, ParamError> {
        params.validate()?;
        let l = &params.linear;
        let mut r = Self::cone_only(&params.cone);
        let k_p = l.shear_modulus * l.wire_diameter.powi(4)
            / (8.0 * l.active_coils * l.mean_diameter.powi(3));
        r.series = Some(Series {
            k_p,
            preload: l.preload.unwrap_or(r.f_t),
        });
        Ok(r)
    }

    /// The conical spring alone (the paper's MCS comparison model). `cone` must be valid.
    pub fn cone_only(cone: &Cone) -> Self {
        let Cone {
            wire_diameter: d,
            small_diameter: d1,
            large_diameter: d2,
            active_coils: n,
            compressible_height: h,
            shear_modulus: g,
        } = *cone;
        let gd4 = g * d.powi(4);
        let (f_t, f_c, a) = (
            gd4 * h / (8.0 * n * d2.powi(3)),
            gd4 * h / (8.0 * n * d1.powi(3)),
            h * gd4 / (8.0 * n),
        );
        Self {
            k: gd4 / (2.0 * n * (d1 * d1 + d2 * d2) * (d1 + d2)),
            f_t,
            f_c,
            series: None,
            h,
            d1,
            d2,
            a,
            a3: a.cbrt(),
            y_t: f_t.cbrt(),
            y_c: f_c.cbrt(),
        }
    }

    /// `max(0, F − P)/k_p`: the preloaded series spring moves only past its preload.
    fn series_strain(&self, f: f64) -> f64 {
        self.series
            .map_or(0.0, |s| (f - s.preload).max(0.0) / s.k_p)
    }

    /// The series spring's `dΔ/dF` (from below at the preload), 0 for the cone alone.
    fn series_compliance(&self, f: f64) -> f64 {
        self.series
            .map_or(0.0, |s| if f > s.preload { 1.0 / s.k_p } else { 0.0 })
    }

    /// The force where the law leaves the line `k Δ`: `min(F_T, P)`.
    pub fn first_kink(&self) -> f64 {
        self.series.map_or(self.f_t, |s| s.preload.min(self.f_t))
    }

    /// `Δ(min(F_T, P))`: the end of the straight line through the origin.
    pub fn strain_t(&self) -> f64 {
        self.delta(self.first_kink())
    }

    /// `Δ(F_C)`.
    pub fn strain_c(&self) -> f64 {
        self.delta(self.f_c)
    }

    /// The cone's strain in its nonlinear phase, in `y = F^(1/3)`.
    fn cone_strain(&self, y: f64) -> f64 {
        self.h / (self.d2 - self.d1)
            * (self.d2 - 0.75 * self.a3 / y - self.d1.powi(4) * y.powi(3) / (4.0 * self.a))
    }

    /// The cone's `dΔ/dF` in its nonlinear phase at `f`, `y = F^(1/3)`.
    fn cone_compliance(&self, f: f64, y: f64) -> f64 {
        // d/dF of H/(D2−D1)[−¾ A^(1/3) F^(−1/3) − D1⁴ F/(4A)]
        self.h / (self.d2 - self.d1) * (0.25 * self.a3 / (y * f) - self.d1.powi(4) / (4.0 * self.a))
    }

    /// Forward law `Δ(F) = Δ_cone(F) + max(0, F − P)/k_p`, every phase (`F < 0` is
    /// tension on the line `F/k`).
    pub fn delta(&self, f: f64) -> f64 {
        let cone = if f <= self.f_t {
            f / self.k
        } else if f < self.f_c {
            self.cone_strain(f.cbrt())
        } else {
            self.h
        };
        cone + self.series_strain(f)
    }

    /// `dΔ/dF`, analytic; at a kink, the derivative from below (so `1/k` at `F_T`).
    /// For the cone alone it is 0 from `F_C` on (solid).
    pub fn compliance(&self, f: f64) -> f64 {
        let cone = if f <= self.f_t {
            1.0 / self.k
        } else if f <= self.f_c {
            self.cone_compliance(f, f.cbrt())
        } else {
            0.0
        };
        cone + self.series_compliance(f)
    }

    /// Inverse law `F(Δ)`, to ~1e-15 relative. `+∞` for the cone alone past solid.
    pub fn force(&self, delta: f64) -> f64 {
        if !self.is_curved(delta) {
            return self.force_closed_form(delta);
        }
        let (lo, hi) = (self.first_kink(), self.f_c);
        let mut f = self.force_closed_form(delta);
        if !(f > lo && f < hi) {
            return self.force_bracketed(delta);
        }
        for _ in 0..3 {
            let (strain, slope) = self.delta_and_compliance(f);
            let next = f - (strain - delta) / slope;
            if !(next > lo && next < hi) {
                break;
            }
            f = next;
        }
        f
    }

    /// [`Reference::delta`] and [`Reference::compliance`] at `f`, one cube root for
    /// both inside the nonlinear phase.
    fn delta_and_compliance(&self, f: f64) -> (f64, f64) {
        if f > self.f_t && f < self.f_c {
            let y = f.cbrt();
            (
                self.cone_strain(y) + self.series_strain(f),
                self.cone_compliance(f, y) + self.series_compliance(f),
            )
        } else {
            (self.delta(f), self.compliance(f))
        }
    }

    /// Tangent stiffness `dF/dΔ = 1/Δ'(F)` at strain `delta` (`k` at the kink `F_T`).
    pub fn stiffness(&self, delta: f64) -> f64 {
        self.force_and_stiffness(delta).1
    }

    /// [`Reference::force`] and [`Reference::stiffness`] at `delta`, the inverse taken
    /// once for both.
    pub fn force_and_stiffness(&self, delta: f64) -> (f64, f64) {
        let f = self.force(delta);
        (f, 1.0 / self.compliance(f))
    }

    /// Whether `delta` lies where the law is curved (the cone's nonlinear phase).
    fn is_curved(&self, delta: f64) -> bool {
        delta > self.delta(self.f_t) && delta < self.strain_c()
    }

    /// Inverse by Ferrari's closed form of the depressed quartic `a y⁴ + b y + c = 0`
    /// where the cone is nonlinear; the straight pieces are inverted exactly.
    pub fn force_closed_form(&self, delta: f64) -> f64 {
        let (preload, k_p) = match self.series {
            Some(s) if delta > self.delta(s.preload) => (s.preload, s.k_p),
            _ => (0.0, f64::INFINITY), // the series spring has not moved
        };
        if delta <= self.delta(self.f_t) {
            // Cone linear, series spring possibly past its preload: Δ = F/k + (F − P)/k_p.
            return (delta + preload / k_p) / (1.0 / self.k + 1.0 / k_p);
        }
        if delta >= self.strain_c() {
            return match self.series {
                Some(s) => s.preload + (delta - self.h) * s.k_p,
                None if delta > self.h => f64::INFINITY,
                None => self.f_c,
            };
        }
        let w = self.d2 - self.d1;
        let qa = 1.0 / k_p - self.h * self.d1.powi(4) / (4.0 * self.a * w);
        let qb = self.h * self.d2 / w - preload / k_p - delta;
        let qc = -0.75 * self.h * self.a3 / w;
        let (lo, hi) = (self.y_t, self.y_c);
        let roots = depressed_quartic_roots(qa, qb, qc);
        // The root inside [F_T^(1/3), F_C^(1/3)]; rounding may put it a hair outside.
        let y = roots
            .into_iter()
            .flatten()
            .min_by(|p, q| dist(*p, lo, hi).total_cmp(&dist(*q, lo, hi)))
            .unwrap_or(f64::NAN);
        y.powi(3)
    }

    /// Inverse by safeguarded Newton/bisection on `F`, bracketed between the first kink
    /// and `F_C`; the straight pieces are inverted exactly.
    pub fn force_bracketed(&self, delta: f64) -> f64 {
        let (mut lo, mut hi) = (self.first_kink(), self.f_c);
        if delta <= self.delta(lo) || delta >= self.delta(hi) {
            return self.force_closed_form(delta);
        }
        let mut f = 0.5 * (lo + hi);
        for _ in 0..400 {
            let r = self.delta(f) - delta;
            if r == 0.0 {
                return f;
            }
            if r > 0.0 {
                hi = f;
            } else {
                lo = f;
            }
            let newton = f - r / self.compliance(f);
            let next = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if (next - f).abs() <= 4.0 * f64::EPSILON * f {
                return next;
            }
            f = next;
        }
        f
    }
}

fn dist(y: f64, lo: f64, hi: f64) -> f64 {
    if y < lo {
        lo - y
    } else if y > hi {
        y - hi
    } else {
        0.0
    }
}

/// Real roots of `a y⁴ + b y + c = 0` by Ferrari's method (up to four).
pub fn depressed_quartic_roots(a: f64, b: f64, c: f64) -> [Option<f64>; 4] {
    if a == 0.0 {
        return [Some(-c / b), None, None, None];
    }
    let (p, q) = (b / a, c / a);
    if p == 0.0 {
        // y⁴ = −q
        let r = (-q).sqrt().sqrt();
        return [Some(r), Some(-r), None, None];
    }
    // Resolvent: (y² + m)² = 2m y² − p y + m² − q is a square iff 8m³ − 8qm − p² = 0.
    let m = largest_cubic_root(-q, -p * p / 8.0);
    let s = (2.0 * m).sqrt();
    let e = p / (2.0 * s);
    let (r1, r2) = quadratic_roots(-s, m + e);
    let (r3, r4) = quadratic_roots(s, m - e);
    [r1, r2, r3, r4]
}

/// Largest real root of `t³ + P t + Q = 0`.
fn largest_cubic_root(pp: f64, qq: f64) -> f64 {
    let disc = (qq / 2.0).powi(2) + (pp / 3.0).powi(3);
    if disc >= 0.0 {
        let sd = disc.sqrt();
        // Pick the cancellation-free cube root first.
        let u = (-qq / 2.0 - sd.copysign(qq)).cbrt();
        if u == 0.0 {
            return 0.0;
        }
        let v = -pp / (3.0 * u);
        if pp > 0.0 {
            // u and v have opposite signs: u + v cancels. u³ + v³ = −Q, so
            // u + v = −Q / (u² − uv + v²), a sum of positive terms.
            -qq / (u * u + pp / 3.0 + v * v)
        } else {
            u + v
        }
    } else {
        let r = (-pp / 3.0).sqrt();
        let phi = (-qq / (2.0 * r.powi(3))).clamp(-1.0, 1.0).acos();
        2.0 * r * (phi / 3.0).cos()
    }
}

/// Real roots of `y² + b y + c = 0`, without cancellation.
fn quadratic_roots(b: f64, c: f64) -> (Option<f64>, Option<f64>) {
    let disc = b * b - 4.0 * c;
    if disc < 0.0 {
        // A double root nudged negative by rounding is still the root.
        if disc > -1e-12 * b * b {
            return (Some(-b / 2.0), None);
        }
        return (None, None);
    }
    let qv = -0.5 * (b + disc.sqrt().copysign(b));
    if qv == 0.0 {
        return (Some(0.0), None);
    }
    (Some(qv), Some(c / qv))
}
