//! `mccs fit`: the MCCS, MCS and MS models fitted to compression data.
//!
//! The output paths are checked before anything is fitted; a data file of more than
//! [`fit::FIT_ROWS`] rows is fitted on that many (evenly spread, said on stderr) and
//! measured on all of them; a fit that runs for more than 2 s says where it is on stderr
//! every 2 s.

use super::progress::Ticker;
use super::{arg_error, check_writable, fmt_given, io_error, CliError};
use crate::fit::{self, ModelKind, Progress};
use crate::paramfile;
use mccs_client::shown::ShownPath;
use std::io::Write;
use std::path::{Path, PathBuf};

#[derive(clap::Args, Debug)]
pub(super) struct Args {
    /// Data file, CSV with the header `strain,force_n` (the loading branch: strain in
    /// (0, 1) and force > 0, both strictly increasing; 5 … 1,000,000 rows; a first row
    /// at (0, 0), the unloaded sample, is dropped with a note).
    #[arg(long)]
    data: PathBuf,
    /// mccs, mcs, ms or all.
    #[arg(long, default_value = "all")]
    model: String,
    /// Write the fitted MCCS parameters here (the TOML schema of docs/model.md).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Draw the data and the fitted curves here, as SVG (the file must end in .svg).
    #[arg(long)]
    plot: Option<PathBuf>,
}

pub(super) fn run(a: Args, out: &mut dyn Write) -> Result<(), CliError> {
    let kinds = models_asked(&a)?;
    let (points, note) = fit::read_data_noted(&a.data).map_err(|e| CliError::new(e.to_string()))?;
    if let Some(note) = note {
        eprintln!("mccs: {note}");
    }
    if points.len() > fit::FIT_ROWS {
        eprintln!(
            "mccs: {}: {} rows: fitting on {} of them, evenly spread; the metrics are on all",
            ShownPath(&a.data),
            points.len(),
            fit::FIT_ROWS
        );
    }
    let fits = fit_all(&a.data, &points, kinds)?;
    print_fits(&fits, &points, out)?;
    let fits: Vec<fit::Fit> = fits.into_iter().map(|(_, f)| f).collect();
    let mccs_params = fits.iter().find_map(|f| match f.model {
        fit::Fitted::Mccs(p) => Some(p),
        _ => None,
    });
    if let (Some(path), Some(p)) = (a.out, mccs_params) {
        let text = format!(
            "# MCCS parameters fitted by `mccs fit` to {}\n{}",
            ShownPath(&a.data),
            paramfile::to_toml(&p)
        );
        std::fs::write(&path, text)
            .map_err(|e| CliError::new(format!("{}: cannot write: {e}", ShownPath(&path))))?;
    }
    if let Some(path) = a.plot {
        let title = format!("{}: fitted models", ShownPath(&a.data));
        fit::plot(&path, &points, &fits, &title)
            .map_err(|e| CliError::new(format!("{}: cannot draw: {e}", ShownPath(&path))))?;
    }
    Ok(())
}

/// The models `--model` names, with `--out` and `--plot` checked against them and
/// writable, before any fitting.
fn models_asked(a: &Args) -> Result<Vec<ModelKind>, CliError> {
    let kinds: Vec<ModelKind> = match a.model.as_str() {
        "all" => ModelKind::ALL.to_vec(),
        name => vec![ModelKind::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| arg_error("--model", "must be mccs, mcs, ms or all"))?],
    };
    if a.out.is_some() && !kinds.contains(&ModelKind::Mccs) {
        return Err(arg_error(
            "--out",
            "needs the mccs model (--model mccs or all)",
        ));
    }
    if let Some(p) = &a.out {
        check_writable("--out", p)?;
    }
    if let Some(p) = &a.plot {
        let svg = p.extension().is_some_and(|x| x.eq_ignore_ascii_case("svg"));
        if !svg {
            return Err(arg_error(
                "--plot",
                &format!(
                    "{}: the plot is drawn as SVG only: name it .svg (PNG would need a font built in)",
                    ShownPath(p)
                ),
            ));
        }
        check_writable("--plot", p)?;
    }
    Ok(kinds)
}

/// Every model fitted before anything is printed: a model that cannot be fitted leaves
/// stdout empty, as every other error does, and its line says which did fit. A progress
/// line every few seconds on stderr.
fn fit_all(
    data: &Path,
    points: &[fit::Point],
    kinds: Vec<ModelKind>,
) -> Result<Vec<(ModelKind, fit::Fit)>, CliError> {
    let mut ticker = Ticker::new();
    let mut progress = |p: Progress| {
        if let Some(t) = ticker.due() {
            eprintln!(
                "mccs: fitting {} (starting point {} of {}), {:.0} s so far",
                p.kind.name(),
                p.start + 1,
                p.starts,
                t.as_secs_f64()
            );
        }
    };
    let mut fits = Vec::new();
    let mut failed = Vec::new();
    for kind in kinds {
        match fit::fit_rows(kind, points, &mut progress) {
            Some(f) => fits.push((kind, f)),
            None => failed.push(kind),
        }
    }
    if !failed.is_empty() {
        return Err(not_fitted(data, points, &failed, &fits));
    }
    Ok(fits)
}

/// The `FIT` and `PARAMS` lines of each fit, and its warnings on stderr.
fn print_fits(
    fits: &[(ModelKind, fit::Fit)],
    points: &[fit::Point],
    out: &mut dyn Write,
) -> Result<(), CliError> {
    for (kind, f) in fits {
        let m = f.metrics;
        writeln!(
            out,
            "FIT model={} mean_abs={:.6} max_abs={:.6} mse={:.3e}",
            kind.name(),
            m.mean_abs,
            m.max_abs,
            m.mse
        )
        .map_err(io_error)?;
        let params: Vec<String> = f
            .model
            .fitted_params()
            .iter()
            .map(|(k, v)| format!("{k}={}", fmt_param(*v)))
            .collect();
        writeln!(out, "PARAMS model={} {}", kind.name(), params.join(" ")).map_err(io_error)?;
        for warning in warnings(&f.model, points) {
            eprintln!("mccs: warning: the {} fit: {warning}", kind.name());
        }
    }
    out.flush().map_err(io_error)
}

/// The one line for models that could not be fitted: which, why (no starting point
/// ended on parameters the model accepts: for MCCS, within the fixed point's ranges,
/// docs/model.md), the data's forces, and the models that did fit.
fn not_fitted(
    data: &Path,
    points: &[fit::Point],
    failed: &[ModelKind],
    fitted: &[(ModelKind, fit::Fit)],
) -> CliError {
    // "the mccs model", "the ms and mcs models".
    let models = |kinds: &[ModelKind]| {
        let names: Vec<&str> = kinds.iter().map(|k| k.name()).collect();
        let s = if names.len() > 1 { "s" } else { "" };
        format!("the {} model{s}", names.join(" and "))
    };
    let (lo, hi) = (points[0].1, points[points.len() - 1].1);
    let why = if failed.contains(&ModelKind::Mccs) {
        "parameters within the model's ranges (for mccs, the fixed point's: docs/model.md)"
    } else {
        "parameters that give a strain at every force"
    };
    let mut line = format!(
        "{}: {} could not be fitted: no starting point ended on {why}, for forces {} … {} N",
        ShownPath(data),
        models(failed),
        fmt_given(lo),
        fmt_given(hi),
    );
    if !fitted.is_empty() {
        let ok: Vec<ModelKind> = fitted.iter().map(|(k, _)| *k).collect();
        let each: Vec<String> = ok.iter().map(|k| format!("--model {}", k.name())).collect();
        line.push_str(&format!("; {} fitted ({})", models(&ok), each.join(", ")));
    }
    CliError::new(line)
}

/// A fitted parameter: 7 significant digits, in scientific notation outside 1e-4 … 1e9.
fn fmt_param(x: f64) -> String {
    let v = format!("{x:.6e}").parse::<f64>().unwrap_or(x);
    fmt_given(v)
}

/// What a fit's numbers do not say: a parameter on a bound the fit holds it within (the
/// data want it past the bound: the model cannot place it there), and a degenerate fit
/// (the data never leave the law's linear phase, or the cone closes at once), whose
/// other parameters the data do not determine.
fn warnings(model: &fit::Fitted, points: &[fit::Point]) -> Vec<String> {
    let max_strain = points.iter().map(|p| p.0).fold(0.0, f64::max);
    let max_force = points.iter().map(|p| p.1).fold(0.0, f64::max);
    let solid = match model {
        fit::Fitted::Mccs(p) => Some(mccs::Derived::Fc.of(p)),
        // F_C is the cone's alone.
        fit::Fitted::Mcs(c) => Some(mccs::Derived::Fc.of(&mccs::Params {
            cone: *c,
            ..mccs::Params::TABLE2
        })),
        fit::Fitted::Ms { .. } => None,
    };
    let mut out: Vec<String> = model
        .on_bounds()
        .into_iter()
        .map(|(key, bound, side, range)| {
            let why = match solid {
                // D1 shapes the law only near the solid force, where the smallest coils close.
                Some(f_c) if key == "cone.small_diameter" && max_force < 0.5 * f_c => format!(
                    "the data stop at {} N, well below the cone's solid force F_C = {} N, and say little of D1",
                    fmt_param(max_force),
                    fmt_param(f_c)
                ),
                _ => "the data want it past what the model takes, or do not decide it".to_string(),
            };
            format!(
                "{key} sits on its {side} bound ({}, of {range}): {why}; treat its value as unknown",
                fmt_param(bound)
            )
        })
        .collect();
    if let fit::Fitted::Ms { c1, c2, c3 } = *model {
        // Eq. 27's two terms at each row: one that never reaches 1e-6 of the other is a
        // parameter the fit dropped.
        let terms = |e: f64| {
            let l = 1.0 - e;
            (
                c1 * c2 * (c2 * (l * l * l - 3.0 * l + 2.0) / l).exp(),
                c3 / l,
            )
        };
        let (most1, most3) = points.iter().fold((0.0f64, 0.0f64), |(a, b), p| {
            let (t1, t3) = terms(p.0);
            (a.max(t1 / t3), b.max(t3 / t1))
        });
        for (key, value, most) in [("c3", c3, most3), ("c1", c1, most1)] {
            if most < 1e-6 {
                out.push(format!(
                    "degenerate: {key} = {} scales a term under 1e-6 of the other's at every row: the fit dropped it",
                    fmt_param(value)
                ));
            }
        }
    }
    let cone = match model {
        fit::Fitted::Mccs(p) => Some((p.cone, crate::reference::Reference::new(p).ok())),
        fit::Fitted::Mcs(c) => Some((*c, Some(crate::reference::Reference::cone_only(c)))),
        fit::Fitted::Ms { .. } => None,
    };
    if let Some((c, Some(law))) = cone {
        let linear_end = law.delta(law.f_t);
        if c.compressible_height < 1e-3 * max_strain {
            out.push(format!(
                "degenerate: cone.compressible_height {} is under 1e-3 of the data's largest strain {}: the cone closes at once, and the data say nothing of its geometry",
                fmt_param(c.compressible_height),
                fmt_param(max_strain)
            ));
        } else {
            let past = points.iter().filter(|p| p.0 > linear_end).count();
            if past < 3 {
                out.push(format!(
                    "degenerate: {past} of the {} rows lie past the law's linear phase (which ends at strain {}): the data fix its stiffness and say little of the rest",
                    points.len(),
                    fmt_param(linear_end)
                ));
            }
        }
    }
    out
}
