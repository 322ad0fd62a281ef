//! Parameter identification from compression data, and the paper's model comparison.
//!
//! Data: CSV `strain,force_n`, the loading branch of a compression test (the paper's
//! displacement variation ratio against force on a 1 cm² sample). Three models:
//!
//! - **MCCS**, this project's law ([`Reference`]);
//! - **MCS**, the conical spring alone (Omar et al.; [`Reference::cone_only`]). The
//!   paper's eqs. 23–26 are the closed-form inverse of that law through the depressed
//!   quartic in `y = F^(1/3)`; [`Reference::force_closed_form`] is that closed form
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

use crate::reference::Reference;
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use mccs::{Cone, Linear, Params};
use nalgebra::{storage::Owned, DMatrix, DVector, Dyn};
use std::fmt;
use std::path::Path;

/// Sample cross-section for the MS model's force, mm²: the paper's 1 cm × 1 cm cubes.
pub const SAMPLE_AREA_MM2: f64 = 100.0;

/// One measurement: strain (dimensionless) and force (N).
pub type Point = (f64, f64);

/// Why a data file was rejected. `Display` is one line naming the file and row.
#[derive(Debug, Clone, PartialEq)]
pub struct DataError {
    /// The file.
    pub file: String,
    /// 1-based row number in the file (the header is row 1), when it is about a row.
    pub row: Option<usize>,
    /// What is wrong.
    pub what: String,
}

impl fmt::Display for DataError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.row {
            Some(r) => write!(f, "{}: row {r}: {}", self.file, self.what),
            None => write!(f, "{}: {}", self.file, self.what),
        }
    }
}

impl std::error::Error for DataError {}

/// Reads and checks a data file: header `strain,force_n`, at least 5 rows, every value
/// a finite number, strain and force both strictly increasing.
pub fn read_data(path: &Path) -> Result<Vec<Point>, DataError> {
    let file = path.display().to_string();
    let err = |row: Option<usize>, what: &str| DataError {
        file: file.clone(),
        row,
        what: what.to_owned(),
    };
    let text =
        std::fs::read_to_string(path).map_err(|e| err(None, &format!("cannot read: {e}")))?;
    parse_data(&text, &file)
}

/// [`read_data`] on text; `file` names it in errors.
pub fn parse_data(text: &str, file: &str) -> Result<Vec<Point>, DataError> {
    let err = |row: Option<usize>, what: String| DataError {
        file: file.to_owned(),
        row,
        what,
    };
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let header = reader
        .headers()
        .map_err(|e| err(Some(1), format!("unreadable header: {e}")))?;
    if header.iter().collect::<Vec<_>>() != ["strain", "force_n"] {
        return Err(err(Some(1), "the header must be `strain,force_n`".into()));
    }
    let mut points: Vec<Point> = Vec::new();
    for (i, record) in reader.records().enumerate() {
        let row = i + 2;
        let record = record.map_err(|e| err(Some(row), format!("unreadable: {e}")))?;
        if record.len() != 2 {
            return Err(err(
                Some(row),
                format!("{} fields, expected 2", record.len()),
            ));
        }
        let value = |k: usize, name: &str| -> Result<f64, DataError> {
            let v: f64 = record[k].parse().map_err(|_| {
                err(
                    Some(row),
                    format!("{name} `{}` is not a number", &record[k]),
                )
            })?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(err(Some(row), format!("{name} must be finite")))
            }
        };
        let (e, f) = (value(0, "strain")?, value(1, "force_n")?);
        if let Some(&(e0, f0)) = points.last() {
            if e <= e0 {
                return Err(err(Some(row), "strain must increase strictly".into()));
            }
            if f <= f0 {
                return Err(err(Some(row), "force_n must increase strictly".into()));
            }
        }
        points.push((e, f));
    }
    if points.len() < 5 {
        return Err(err(
            None,
            format!("{} data rows, at least 5 needed", points.len()),
        ));
    }
    Ok(points)
}

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
const D: f64 = 0.1;
const N: f64 = 5.0;
const D2: f64 = 0.8;
const DP: f64 = 0.068;
const DMP: f64 = 0.2;
const NP: f64 = 10.0;

/// Bounds that keep fitted parameters physical: `D1/D2`, and `ln C2` for MS.
const RATIO: (f64, f64) = (0.05, 0.95);
const LN_C2: (f64, f64) = (-6.907755278982137, 6.907755278982137); // 1e-3 … 1e3

/// `t ∈ ℝ` to `(lo, hi)`, smoothly.
fn bounded(t: f64, (lo, hi): (f64, f64)) -> f64 {
    lo + (hi - lo) / (1.0 + (-t).exp())
}

/// The inverse of [`bounded`].
fn unbounded(x: f64, (lo, hi): (f64, f64)) -> f64 {
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
        match self {
            Self::Mccs(p) => Reference::new(p).map_or(f64::NAN, |r| r.delta(f)),
            Self::Mcs(c) => Reference::cone_only(c).delta(f),
            Self::Ms { c1, c2, c3 } => ms_strain(*c1, *c2, *c3, f),
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

/// Eq. 27's strain at force `f` by bisection (the force grows with strain on [0, 1)).
pub fn ms_strain(c1: f64, c2: f64, c3: f64, f: f64) -> f64 {
    if f <= 0.0 {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0, 1.0 - 1e-12);
    let top = ms_force(c1, c2, c3, hi);
    if top.is_nan() || top < f {
        return hi;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if ms_force(c1, c2, c3, mid) < f {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

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
    let d: Vec<f64> = data.iter().map(|&(e, f)| model.strain_at(f) - e).collect();
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
    theta: DVector<f64>,
}

impl Problem<'_> {
    fn residuals_at(&self, t: &[f64]) -> Option<DVector<f64>> {
        let m = Fitted::from_theta(self.kind, t);
        if let Fitted::Mccs(p) = &m {
            p.validate().ok()?;
        }
        let r: Vec<f64> = self.data.iter().map(|&(e, f)| m.strain_at(f) - e).collect();
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

/// Fits `kind` to `data`: Levenberg–Marquardt from every starting point, best kept.
/// `None` if no start converged to a finite fit.
pub fn fit(kind: ModelKind, data: &[Point]) -> Option<Fit> {
    let mut best: Option<(f64, Vec<f64>)> = None;
    for start in starts(kind, data) {
        let problem = Problem {
            kind,
            data,
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

/// Data generated by `model` at `forces`, with multiplicative Gaussian noise of relative
/// size `noise` on the strain (seeded, reproducible).
pub fn synthesize(model: &Fitted, forces: &[f64], noise: f64, seed: u64) -> Vec<Point> {
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let normal = Normal::new(0.0, 1.0).expect("unit normal");
    let mut out: Vec<Point> = Vec::new();
    for &f in forces {
        let e = model.strain_at(f) * (1.0 + noise * normal.sample(&mut rng));
        // Keep the strain increasing (noise may not reorder a compression test).
        let e = out.last().map_or(e, |&(prev, _)| e.max(prev + 1e-9));
        out.push((e, f));
    }
    out
}

/// The shipped demo data set (`params/demo-data.csv`): synthetic, not measured. The
/// Table 2 MCCS spring loaded to 1 N (the paper's test) at 40 forces from 0.025 N,
/// strains with 1 % Gaussian noise, seed 2020.
pub fn demo_data() -> Vec<Point> {
    let forces: Vec<f64> = (1..=40).map(|i| i as f64 * 0.025).collect();
    synthesize(&Fitted::Mccs(Params::TABLE2), &forces, 0.01, 2020)
}

/// Writes points as CSV text.
pub fn to_csv(points: &[Point]) -> String {
    let mut s = String::from("strain,force_n\n");
    for (e, f) in points {
        s.push_str(&format!("{e:.9},{f:.6}\n"));
    }
    s
}

/// Draws the data and every fitted curve (strain against force) as SVG.
pub fn plot(path: &Path, data: &[Point], fits: &[Fit], title: &str) -> Result<(), String> {
    use plotters::prelude::*;
    let f_max = data.iter().map(|p| p.1).fold(0.0, f64::max) * 1.05;
    let e_max = data.iter().map(|p| p.0).fold(0.0, f64::max) * 1.15;
    let root = SVGBackend::new(path, (800, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(44)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..f_max, 0.0..e_max)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc("force (N)")
        .y_desc("strain (displacement variation ratio)")
        .draw()
        .map_err(|e| e.to_string())?;
    chart
        .draw_series(
            data.iter()
                .map(|&(e, f)| Circle::new((f, e), 3, BLACK.filled())),
        )
        .map_err(|e| e.to_string())?
        .label("data")
        .legend(|(x, y)| Circle::new((x + 10, y), 3, BLACK.filled()));
    let colours = [RED, BLUE, GREEN];
    for (fit, colour) in fits.iter().zip(colours) {
        let curve: Vec<(f64, f64)> = (0..=200)
            .map(|i| f_max * i as f64 / 200.0)
            .map(|f| (f, fit.model.strain_at(f)))
            .filter(|(_, e)| e.is_finite())
            .collect();
        let m = fit.metrics;
        chart
            .draw_series(LineSeries::new(curve, colour.stroke_width(2)))
            .map_err(|e| e.to_string())?
            .label(format!(
                "{} (mean {:.4}, max {:.4})",
                fit.model.kind().name().to_uppercase(),
                m.mean_abs,
                m.max_abs
            ))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.9))
        .draw()
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}
