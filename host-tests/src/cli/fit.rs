//! `mccs fit`: the MCCS, MCS and MS models fitted to compression data.

use super::{arg_error, io_error, CliError};
use crate::fit::{self, ModelKind};
use crate::paramfile;
use std::io::Write;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub(super) struct Args {
    /// Data file, CSV with the header `strain,force_n`.
    #[arg(long)]
    data: PathBuf,
    /// mccs, mcs, ms or all.
    #[arg(long, default_value = "all")]
    model: String,
    /// Write the fitted MCCS parameters here (the TOML schema of docs/model.md).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Draw the data and the fitted curves here (SVG).
    #[arg(long)]
    plot: Option<PathBuf>,
}

pub(super) fn run(a: Args, out: &mut dyn Write) -> Result<(), CliError> {
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
    let points = fit::read_data(&a.data).map_err(|e| CliError(e.to_string()))?;
    let mut fits = Vec::new();
    for kind in kinds {
        let f = fit::fit(kind, &points).ok_or_else(|| {
            CliError(format!(
                "{}: the {} model could not be fitted",
                a.data.display(),
                kind.name()
            ))
        })?;
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
        fits.push(f);
    }
    let mccs_params = fits.iter().find_map(|f| match f.model {
        fit::Fitted::Mccs(p) => Some(p),
        _ => None,
    });
    if let (Some(path), Some(p)) = (a.out, mccs_params) {
        let text = format!(
            "# MCCS parameters fitted by `mccs fit` to {}\n{}",
            a.data.display(),
            paramfile::to_toml(&p)
        );
        std::fs::write(&path, text)
            .map_err(|e| CliError(format!("{}: cannot write: {e}", path.display())))?;
    }
    if let Some(path) = a.plot {
        let title = format!("{}: fitted models", a.data.display());
        fit::plot(&path, &points, &fits, &title)
            .map_err(|e| CliError(format!("{}: cannot draw: {e}", path.display())))?;
    }
    Ok(())
}
