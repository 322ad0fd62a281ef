//! The MCCS law in `f64`, used only when a [`ForceTable`](crate::ForceTable) is built.
//!
//! Never called per tick. It follows `docs/model.md`:
//! `Δ(F) = Δ_cone(F) + max(0, F − P)/k_p`, where the cone is linear (`F/k`) up to `F_T`,
//! follows eq. 11 up to `F_C`, and is solid (`H`) beyond, and the series spring, preloaded
//! with `P`, moves only once the load exceeds `P` (see the departures from the paper
//! there: the printed eq. 14 would jump at `F_T`).
//!
//! `Δ` is the compressive strain of an edge; `F` its force in N.
//!
//! The inverse `F(Δ)` is exact on the lines and, on the cone's curve, a bracketed Newton
//! iteration in `y = F^(1/3)` with a bisection fallback (at most 200 steps, typically 5;
//! no cube root per step); the host reference
//! (`mccs-host`) inverts the same law by a different route (Ferrari's closed form) and
//! the tests hold the two against each other.

use crate::params::{ParamError, Params};

/// A validated spring with its derived constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Law {
    /// Linear-phase stiffness `k` (N per unit strain), eq. 1.
    pub k: f64,
    /// Transition force `F_T` (N): the largest coil closes.
    pub f_t: f64,
    /// Solid force `F_C` (N): the smallest coil closes.
    pub f_c: f64,
    /// Series-spring stiffness `k_p` (N per unit strain).
    pub k_p: f64,
    /// Series-spring preload `P` (N), below `F_C`.
    pub preload: f64,
    /// `H`, compressible height.
    h: f64,
    d1: f64,
    d2: f64,
    /// `H G d^4 / (8 n)`: `D_c^3 · F`.
    a: f64,
    /// `a^(1/3)`: `D_c = a^(1/3) / F^(1/3)`, so that the inverse, which works in
    /// `y = F^(1/3)`, takes no cube root per step.
    a3: f64,
    /// `2 n / (G d^4 (D2 - D1))`.
    b: f64,
}

impl Law {
    /// Validates `params` and derives the constants of `docs/model.md`.
    pub fn new(params: &Params) -> Result<Self, ParamError> {
        params.validate()?;
        let c = &params.cone;
        let l = &params.linear;
        let gd4 = c.shear_modulus * pow4(c.wire_diameter);
        let (d1, d2, n, h) = (
            c.small_diameter,
            c.large_diameter,
            c.active_coils,
            c.compressible_height,
        );
        let k = gd4 / (2.0 * n * (d1 * d1 + d2 * d2) * (d1 + d2));
        let f_t = gd4 * h / (8.0 * n * d2 * d2 * d2);
        let f_c = gd4 * h / (8.0 * n * d1 * d1 * d1);
        let dp = l.mean_diameter;
        let k_p = l.shear_modulus * pow4(l.wire_diameter) / (8.0 * l.active_coils * dp * dp * dp);
        Ok(Self {
            k,
            f_t,
            f_c,
            k_p,
            preload: l.preload.unwrap_or(f_t),
            h,
            d1,
            d2,
            a: h * gd4 / (8.0 * n),
            a3: libm::cbrt(h * gd4 / (8.0 * n)),
            b: 2.0 * n / (gd4 * (d2 - d1)),
        })
    }

    /// The force where the law first leaves the line `k ε`: `min(F_T, P)`.
    pub fn first_kink(&self) -> f64 {
        libm::fmin(self.f_t, self.preload)
    }

    /// Strain where the law first leaves the line `k ε`, `Δ(min(F_T, P))`.
    pub fn strain_t(&self) -> f64 {
        self.delta(self.first_kink())
    }

    /// Strain at which the cone is solid, `Δ(F_C)`.
    pub fn strain_c(&self) -> f64 {
        self.delta(self.f_c)
    }

    /// Diameter above which coils are closed at force `f` (eq. 5), `f > 0`.
    fn closed_diameter(&self, f: f64) -> f64 {
        libm::cbrt(self.a / f)
    }

    /// Forward law `Δ(F)`: strain at force `f` (N). Defined for every finite `f`.
    pub fn delta(&self, f: f64) -> f64 {
        let cone = if f <= self.f_t {
            f / self.k
        } else if f < self.f_c {
            let dc = self.closed_diameter(f);
            self.b * f * (pow4(dc) - pow4(self.d1)) + self.h * (self.d2 - dc) / (self.d2 - self.d1)
        } else {
            self.h
        };
        cone + libm::fmax(f - self.preload, 0.0) / self.k_p
    }

    /// The cone's `dΔ/dF` in its nonlinear phase.
    fn cone_compliance(&self, f: f64) -> f64 {
        let dc = self.closed_diameter(f);
        self.b * (pow4(dc) - pow4(self.d1))
    }

    /// `dΔ/dF` at force `f`, analytic; at a kink, the derivative from below.
    pub fn compliance(&self, f: f64) -> f64 {
        let cone = if f <= self.f_t {
            1.0 / self.k
        } else if f <= self.f_c {
            self.cone_compliance(f)
        } else {
            0.0
        };
        cone + if f > self.preload {
            1.0 / self.k_p
        } else {
            0.0
        }
    }

    /// `dΔ/dF` at force `f`, analytic; at a kink, the derivative from above.
    pub fn compliance_above(&self, f: f64) -> f64 {
        let cone = if f < self.f_t {
            1.0 / self.k
        } else if f < self.f_c {
            self.cone_compliance(f)
        } else {
            0.0
        };
        cone + if f >= self.preload {
            1.0 / self.k_p
        } else {
            0.0
        }
    }

    /// Inverse law `F(Δ)`: force (N) at strain `strain`, and the tangent stiffness
    /// `dF/dΔ` (N per unit strain) there; at a kink, the stiffness from below.
    pub fn force_and_stiffness(&self, strain: f64) -> (f64, f64) {
        let (f, y, _) = self.inverse(strain);
        let compliance = match y {
            // On the cone's curve: its closed diameter from `y`, no cube root.
            Some(y) => self.slope_in_y(y).1 / (3.0 * y * y),
            None => self.compliance(f),
        };
        (f, 1.0 / compliance)
    }

    /// Inverse law `F(Δ)` (N).
    pub fn force(&self, strain: f64) -> f64 {
        self.inverse(strain).0
    }

    /// The inverse: `F(Δ)`, `y = F^(1/3)` where it lies on the cone's curve (`None` on
    /// the lines), and the Newton steps it took (0 on the lines).
    ///
    /// On the lines it is exact: `k ε` below the first kink, `P + (ε − H) k_p` above
    /// `Δ(F_C)`, and between a preload under `F_T` and `F_T` both springs' lines,
    /// `Δ = F/k + (F − P)/k_p`. On the curve, bracketed Newton in `y` over
    /// `(a^(1/3)/D2, a^(1/3)/D1)` (the closed diameter `D_c = a^(1/3)/y` runs from `D2`
    /// at `F_T` to `D1` at `F_C`), from the tangent at `F_T`, with a bisection fallback:
    /// no cube root per step. It stops on a step that leaves `y` where it is, or a step
    /// or a bracket under 1e-15/3 relative (1e-15 in `F`); at most 200 steps.
    fn inverse(&self, strain: f64) -> (f64, Option<f64>, u32) {
        let f1 = self.first_kink();
        let (e_1, e_c) = (self.delta(f1), self.strain_c());
        if strain <= e_1 {
            return (strain * self.k, None, 0);
        }
        if strain >= e_c {
            return (self.preload + (strain - self.h) * self.k_p, None, 0);
        }
        let e_t = self.delta(self.f_t);
        if strain <= e_t {
            // (Only with the preload under `F_T`: then `e_1 < e_t`.)
            let f = (strain + self.preload / self.k_p) / (1.0 / self.k + 1.0 / self.k_p);
            return (libm::fmin(libm::fmax(f, f1), self.f_t), None, 0);
        }
        const TOLERANCE: f64 = 1e-15 / 3.0;
        let on_curve = |y: f64, steps| (y * y * y, Some(y), steps);
        let (mut lo, mut hi) = (self.a3 / self.d2, self.a3 / self.d1);
        let mut y = lo + (strain - e_t) / self.slope_in_y(lo).1;
        if !(y > lo && y < hi) {
            y = 0.5 * (lo + hi);
        }
        for steps in 1..=200 {
            let (at, slope) = self.slope_in_y(y);
            let r = at - strain;
            if r == 0.0 {
                return on_curve(y, steps);
            }
            let mut next = y - r / slope;
            if next == y {
                // On the root to the last bit (a step below half of `y`'s last bit).
                // (Taken for a step, it would sit on the bracket's end and bisect on
                // from the far one: `the_inverse_takes_few_newton_steps`.)
                return on_curve(y, steps);
            }
            if r > 0.0 {
                hi = y;
            } else {
                lo = y;
            }
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            if libm::fabs(next - y) <= TOLERANCE * y || hi - lo <= TOLERANCE * hi {
                return on_curve(next, steps);
            }
            y = next;
        }
        on_curve(y, 200)
    }

    /// On the cone's curve, at `y = F^(1/3)` (`F_T < F < F_C`): the strain `Δ` and its
    /// slope `dΔ/dy = 3 y² dΔ/dF` (the series spring's from below at its preload).
    fn slope_in_y(&self, y: f64) -> (f64, f64) {
        let f = y * y * y;
        let dc = self.a3 / y;
        let coiled = pow4(dc) - pow4(self.d1);
        let (series, series_compliance) = if f > self.preload {
            ((f - self.preload) / self.k_p, 1.0 / self.k_p)
        } else {
            (0.0, 0.0)
        };
        let strain = self.b * f * coiled + self.h * (self.d2 - dc) / (self.d2 - self.d1) + series;
        (strain, 3.0 * y * y * (self.b * coiled + series_compliance))
    }
}

fn pow4(x: f64) -> f64 {
    let x2 = x * x;
    x2 * x2
}

#[cfg(test)]
mod tests {
    use super::Law;
    use crate::Params;

    /// Newton steps of [`Law::force`] over the nonlinear phase: at most `max` and
    /// `mean` on average, on strains spread evenly and on strains that are `Δ(F)` of a
    /// force, where an iterate often lands on the root exactly (a residual of zero).
    fn steps(p: &Params) -> (u32, f64) {
        let law = Law::new(p).unwrap();
        let (a, b) = (law.strain_t(), law.strain_c());
        let (fa, fb) = (law.first_kink(), law.f_c);
        let even = (1..2000).map(|i| a + (b - a) * i as f64 / 2000.0);
        let on_a_force = (1..2000).map(|i| law.delta(fa + (fb - fa) * i as f64 / 2000.0));
        let (mut max, mut sum, mut n) = (0, 0u64, 0u64);
        for e in even.chain(on_a_force) {
            let (f, _, steps) = law.inverse(e);
            assert!(f.is_finite() && f >= fa && f <= fb, "{e}: {f}");
            max = max.max(steps);
            sum += u64::from(steps);
            n += 1;
        }
        (max, sum as f64 / n as f64)
    }

    /// A Newton step that leaves the iterate where it is ends the search: on the root to
    /// its last bit (bisecting on from the bracket's far end takes several times as many
    /// steps). Held here to at most 32 steps per strain and 10 on average on each of
    /// Table 2, two of its variants and 1,000 random springs.
    #[test]
    fn the_inverse_takes_few_newton_steps() {
        let mut preloaded = Params::TABLE2;
        preloaded.linear.preload = Some(4.0);
        let mut stiff_series = Params::TABLE2;
        stiff_series.cone.shear_modulus *= 0.1;
        stiff_series.linear.shear_modulus *= 28.2;
        // Random springs: the cone's wire, modulus and coils within a decade of Table
        // 2's each way, `D2/D1` 1.05 … 4.05, the series spring's modulus 1e-3 … 1e4
        // times Table 2's, and half of them preloaded at 0.3 … 3 `F_T` (below 0.9 `F_C`).
        let mut seed = 12345u64;
        let mut uniform = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let random = core::iter::repeat_with(|| {
            let mut p = Params::TABLE2;
            let decade = |u: f64| libm::pow(10.0, 2.0 * u - 1.0);
            p.cone.wire_diameter *= decade(uniform());
            p.cone.shear_modulus *= decade(uniform());
            p.cone.active_coils *= decade(uniform());
            p.cone.large_diameter = p.cone.small_diameter * (1.05 + 3.0 * uniform());
            p.linear.shear_modulus *= libm::pow(10.0, 7.0 * uniform() - 3.0);
            let (preloaded, load) = (uniform() < 0.5, 0.3 + 2.7 * uniform());
            if let (true, Ok(law)) = (preloaded, Law::new(&p)) {
                p.linear.preload = Some(libm::fmin(load * law.f_t, 0.9 * law.f_c));
            }
            p
        })
        .filter(|p| Law::new(p).is_ok())
        .take(1000);
        let mut checked = 0;
        let (table2, mut worst_max, mut worst_mean) = (steps(&Params::TABLE2), 0, 0.0f64);
        for p in [Params::TABLE2, preloaded, stiff_series]
            .into_iter()
            .chain(random)
        {
            let (max, mean) = steps(&p);
            assert!(
                max <= 32 && mean <= 10.0,
                "{max} steps at most, {mean} on average: {p:?}"
            );
            (worst_max, worst_mean) = (worst_max.max(max), worst_mean.max(mean));
            checked += 1;
        }
        assert_eq!(checked, 1003);
        println!(
            "LAW case=newton_steps table2_mean={:.1} table2_max={} worst_mean={worst_mean:.1} worst_max={worst_max}",
            table2.1, table2.0
        );
    }
}
