//! Parameter identification from compression data, and the paper's model comparison.
//!
//! Data: CSV `strain,force_n`, the loading branch of a compression test (the paper's
//! displacement variation ratio against force on a 1 cm² sample). Three models:
//!
//! - **MCCS**, this project's law ([`crate::reference::Reference`]);
//! - **MCS**, the conical spring alone (Omar et al.; [`crate::reference::Reference::cone_only`]). The
//!   paper's eqs. 23–26 are the closed-form inverse of that law through the depressed
//!   quartic in `y = F^(1/3)`; [`crate::reference::Reference::force_closed_form`] is that closed form
//!   (Ferrari), checked against the bracketed numeric inverse in the tests;
//! - **MS**, eq. 27: `T_s(λ) = 2(λ³ − 1)/λ² · (C1 C2 exp(C2 (λ³ − 3λ + 2)/λ) + C3/λ)`,
//!   `λ = 1 − strain`, stress in MPa; force = `−T_s ·` [`SAMPLE_AREA_MM2`].
//!
//! Fitting minimises the squared *strain* differences at the measured forces — the
//! paper's displacement differences — by Levenberg–Marquardt (`levenberg-marquardt`
//! crate) from several starting points (18 for MCCS, 9 for MCS, 18 for MS), over
//! parameters transformed so that every trial point is physical: logs for positive
//! values, and logistic bounds for `D1/D2 ∈ (0.05, 0.95)` and MS's `C2 ∈ (1e-3, 1e3)`.
//!
//! Identifiability. `Δ` depends on the cone only through `G d⁴/n` (one force scale `s`),
//! `D1`, `D2` and `H`, and scaling `D1, D2` by `λ` with `s` by `λ³` leaves `Δ(F)` unchanged;
//! the series spring enters only through `k_p`. So the fit holds `d`, `n` and `D2` at
//! Table 2's values (0.1 mm, 5, 0.8 mm) and fits `D1`, `H`, `s` (reported as `G`), and
//! `k_p` (reported as `G_p`, with `d_p`, `D_p`, `n_p` at Table 2's 0.068 mm, 0.2 mm, 10).
//! The preload is the default `F_T`.

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{storage::Owned, DMatrix, DVector, Dyn};

mod data;
mod models;
mod plot;

pub use data::{
    demo_data, parse_data, parse_data_noted, read_data, read_data_noted, synthesize, to_csv,
    DataError, Point, MAX_ROWS,
};
pub use models::{ms_force, ms_strain, Fitted, ModelKind, SAMPLE_AREA_MM2};
use models::{unbounded, D2, LN_C2, RATIO};
pub use plot::plot;

/// The paper's metrics: at each measured force, the model's strain minus the measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    /// Mean absolute difference.
    pub mean_abs: f64,
    /// Largest absolute difference.
    pub max_abs: f64,
    /// Mean squared difference.
    pub mse: f64,
}

/// Metrics of `model` on `data`.
pub fn metrics(model: &Fitted, data: &[Point]) -> Metrics {
    let forces: Vec<f64> = data.iter().map(|p| p.1).collect();
    let strains = model.strains(&forces);
    let d: Vec<f64> = data.iter().zip(strains).map(|(&(e, _), s)| s - e).collect();
    let n = d.len() as f64;
    Metrics {
        mean_abs: d.iter().map(|x| x.abs()).sum::<f64>() / n,
        max_abs: d.iter().fold(0.0, |m, x| m.max(x.abs())),
        mse: d.iter().map(|x| x * x).sum::<f64>() / n,
    }
}

/// The least-squares problem for the `levenberg-marquardt` crate.
struct Problem<'a> {
    kind: ModelKind,
    data: &'a [Point],
    forces: Vec<f64>,
    theta: DVector<f64>,
}

impl Problem<'_> {
    fn residuals_at(&self, t: &[f64]) -> Option<DVector<f64>> {
        let m = Fitted::from_theta(self.kind, t);
        if let Fitted::Mccs(p) = &m {
            p.validate().ok()?;
        }
        let r: Vec<f64> = self
            .data
            .iter()
            .zip(m.strains(&self.forces))
            .map(|(&(e, _), s)| s - e)
            .collect();
        r.iter()
            .all(|x| x.is_finite())
            .then(|| DVector::from_vec(r))
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.theta.copy_from(x);
    }

    fn params(&self) -> DVector<f64> {
        self.theta.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        self.residuals_at(self.theta.as_slice())
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        if self.kind == ModelKind::Ms {
            return self.ms_jacobian();
        }
        // Central differences in fit space (the models have analytic forms, but not of
        // their derivatives in every parameter).
        let n = self.theta.len();
        let mut j = DMatrix::zeros(self.data.len(), n);
        for k in 0..n {
            let h = 1e-6 * (1.0 + self.theta[k].abs());
            let mut tp = self.theta.clone();
            tp[k] += h;
            let mut tm = self.theta.clone();
            tm[k] -= h;
            let (rp, rm) = (
                self.residuals_at(tp.as_slice())?,
                self.residuals_at(tm.as_slice())?,
            );
            j.set_column(k, &((rp - rm) / (2.0 * h)));
        }
        Some(j)
    }
}

impl Problem<'_> {
    /// The MS model's strain is a root of `F(e; θ) = f`: its derivatives follow from the
    /// implicit function theorem, `∂e/∂θ = −(∂F/∂θ)/(∂F/∂e)`, both by central differences
    /// of the force at the solved strain — one root solve per row instead of seven.
    fn ms_jacobian(&self) -> Option<DMatrix<f64>> {
        let t = self.theta.as_slice();
        let m = Fitted::from_theta(self.kind, t);
        let strains = m.strains(&self.forces);
        let n = t.len();
        let mut j = DMatrix::zeros(self.data.len(), n);
        let shifted: Vec<(Fitted, Fitted, f64)> = (0..n)
            .map(|k| {
                let h = 1e-6 * (1.0 + t[k].abs());
                let (mut tp, mut tm) = (t.to_vec(), t.to_vec());
                tp[k] += h;
                tm[k] -= h;
                (
                    Fitted::from_theta(self.kind, &tp),
                    Fitted::from_theta(self.kind, &tm),
                    h,
                )
            })
            .collect();
        for (i, &e) in strains.iter().enumerate() {
            let he = 1e-7 * (1.0 - e).max(1e-9);
            let d_e = (m.force_at(e + he) - m.force_at(e - he)) / (2.0 * he);
            if !(d_e.is_finite() && d_e > 0.0) {
                return None;
            }
            for (k, (mp, mm, h)) in shifted.iter().enumerate() {
                let d_t = (mp.force_at(e) - mm.force_at(e)) / (2.0 * h);
                j[(i, k)] = -d_t / d_e;
            }
        }
        j.iter().all(|x| x.is_finite()).then_some(j)
    }
}

/// A fit: the model and its metrics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// The fitted model.
    pub model: Fitted,
    /// Its metrics on the data.
    pub metrics: Metrics,
}

/// Starting points in fit space, from the data's scale.
fn starts(kind: ModelKind, data: &[Point]) -> Vec<Vec<f64>> {
    let (e0, f0) = data[0];
    let (e_max, _) = data[data.len() - 1];
    let k0 = f0 / e0.max(1e-9);
    let mut out = Vec::new();
    match kind {
        ModelKind::Mccs | ModelKind::Mcs => {
            for ratio in [0.2, 0.4, 0.6] {
                for h in [0.5 * e_max, e_max, 2.0 * e_max] {
                    let d1 = ratio * D2;
                    // k = s / (2 (D1² + D2²)(D1 + D2))
                    let s = 2.0 * k0 * (d1 * d1 + D2 * D2) * (d1 + D2);
                    let mut t = vec![unbounded(ratio, RATIO), h.ln(), s.ln()];
                    if kind == ModelKind::Mccs {
                        // The series spring: as stiff as the cone's linear phase, or as
                        // Table 2's (7×).
                        for kp in [k0, 7.0 * k0] {
                            let mut tt = t.clone();
                            tt.push(kp.max(1e-6).ln());
                            out.push(tt);
                        }
                    } else {
                        out.push(std::mem::take(&mut t));
                    }
                }
            }
        }
        ModelKind::Ms => {
            for c1 in [1e-4f64, 1e-3, 1e-2] {
                for c2 in [0.3f64, 1.0, 3.0] {
                    for c3 in [1e-4f64, 1e-3] {
                        out.push(vec![c1.ln(), unbounded(c2.ln(), LN_C2), c3.ln()]);
                    }
                }
            }
        }
    }
    out
}

/// The most rows a fit runs on: more are decimated, evenly by row, to this many (the
/// metrics are still taken on every row).
pub const FIT_ROWS: usize = 1_000;

/// Where a fit is, for progress reports: the model and its starting point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// The model.
    pub kind: ModelKind,
    /// The starting point being fitted (0-based) and how many there are.
    pub start: usize,
    /// See `start`.
    pub starts: usize,
}

/// At most [`FIT_ROWS`] of `data`, evenly by row, the first and last kept.
pub fn decimate(data: &[Point]) -> Vec<Point> {
    if data.len() <= FIT_ROWS {
        return data.to_vec();
    }
    let last = data.len() - 1;
    (0..FIT_ROWS)
        .map(|i| data[i * last / (FIT_ROWS - 1)])
        .collect()
}

/// Fits `kind` to `data`: Levenberg–Marquardt from every starting point, best kept.
/// `None` if no start converged to a finite fit.
pub fn fit(kind: ModelKind, data: &[Point]) -> Option<Fit> {
    fit_rows(kind, data, &mut |_| {})
}

/// [`fit`] on at most [`FIT_ROWS`] rows of `data` ([`decimate`]), the metrics on all of
/// them; `progress` hears of every starting point.
pub fn fit_rows(
    kind: ModelKind,
    data: &[Point],
    progress: &mut dyn FnMut(Progress),
) -> Option<Fit> {
    let rows = decimate(data);
    let found = fit_on(kind, &rows, progress)?;
    Some(Fit {
        metrics: metrics(&found.model, data),
        model: found.model,
    })
}

fn fit_on(kind: ModelKind, data: &[Point], progress: &mut dyn FnMut(Progress)) -> Option<Fit> {
    let mut best: Option<(f64, Vec<f64>)> = None;
    let all = starts(kind, data);
    let n = all.len();
    for (i, start) in all.into_iter().enumerate() {
        progress(Progress {
            kind,
            start: i,
            starts: n,
        });
        let problem = Problem {
            kind,
            data,
            forces: data.iter().map(|p| p.1).collect(),
            theta: DVector::from_vec(start),
        };
        if problem.residuals().is_none() {
            continue;
        }
        let (problem, _report) = LevenbergMarquardt::new()
            .with_xtol(1e-15)
            .with_ftol(1e-15)
            .with_gtol(1e-15)
            .with_patience(400)
            .minimize(problem);
        let Some(r) = problem.residuals() else {
            continue;
        };
        let cost = r.norm_squared();
        if cost.is_finite() && best.as_ref().is_none_or(|(c, _)| cost < *c) {
            best = Some((cost, problem.theta.as_slice().to_vec()));
        }
    }
    let (_, theta) = best?;
    let model = Fitted::from_theta(kind, &theta);
    Some(Fit {
        metrics: metrics(&model, data),
        model,
    })
}
