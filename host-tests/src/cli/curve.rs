//! `mccs curve`: the law `F(ε)` and `dF/dε` on a strain grid, from the reference or from
//! the fixed-point table.

use super::table::{build, with_knots, Domain, TableArgs};

use super::{arg_error, csv_error, file_error, fmt_strain, io_error, Backend, CliError};
use crate::paramfile;
use crate::reference::Reference;
use mccs::{ForceTable, Strain};
use std::io::Write;
use std::path::PathBuf;

/// Largest number of rows `curve` prints.
pub const MAX_ROWS: usize = 10_000_000;

#[derive(clap::Args, Debug)]
pub(super) struct Args {
    /// Parameter file (the TOML schema of docs/model.md).
    #[arg(long)]
    params: PathBuf,
    /// First strain (may be negative: tension).
    #[arg(long, allow_negative_numbers = true)]
    from: f64,
    /// Last strain (inclusive when reached).
    #[arg(long, allow_negative_numbers = true)]
    to: f64,
    /// Strain step, > 0.
    #[arg(long, allow_negative_numbers = true)]
    step: f64,
    /// Evaluation backend.
    #[arg(long, value_enum, default_value_t = Backend::Reference)]
    backend: Backend,
    #[command(flatten)]
    table: TableArgs,
}

pub(super) fn run(a: Args, out: &mut dyn Write) -> Result<(), CliError> {
    let p = paramfile::read(&a.params)?;
    let strains = strain_grid(a.from, a.to, a.step)?;
    let rows = match a.backend {
        Backend::Reference => {
            a.table.only_with_fixed()?;
            let r = Reference::new(&p).map_err(|e| file_error(&a.params, e))?;
            strains
                .iter()
                .map(|&e| {
                    let (f, k) = r.force_and_stiffness(e);
                    (e, f, k)
                })
                .collect::<Vec<_>>()
        }
        Backend::Fixed => {
            let rows = with_knots!(a.table.knots(), |S| {
                let t = build::<S>(&p, &a.params, Domain::Default, a.table.accept_error, true)?;
                fixed_curve(&t, &strains)
            });
            warn_outside_domain(&p, &strains);
            rows
        }
    };
    write_curve(out, &rows)
}

/// Warns on stderr when strains lie above the fixed table's domain and the domain ends
/// before the solid point: there the table's line is the law's tangent at the domain's
/// edge, an under-estimate, before the solid point and past it alike (past it the law is
/// the line of slope `k_p`, which the tangent is not). Below the domain, and above it
/// when the domain reaches the solid point, the lines are the law's own.
fn warn_outside_domain(p: &mccs::Params, strains: &[f64]) {
    let (lo, hi) = mccs::table::DEFAULT_DOMAIN;
    let Ok(law) = mccs::Law::new(p) else { return };
    if hi >= law.strain_c() {
        return;
    }
    let above = strains.iter().filter(|&&e| e > hi).count();
    if above > 0 {
        eprintln!(
            "mccs: warning: {above} strains lie above the fixed table's domain [{lo}, {hi}], which ends before the solid point {:.6}: there the table gives the tangent at {hi}, below the law",
            law.strain_c()
        );
    }
}

/// The strains `from + i·step ≤ to`, validated.
pub fn strain_grid(from: f64, to: f64, step: f64) -> Result<Vec<f64>, CliError> {
    for (name, v) in [("--from", from), ("--to", to), ("--step", step)] {
        if !v.is_finite() {
            return Err(arg_error(name, "must be a finite number"));
        }
    }
    // The fixed point's strains, for either backend: the fixed one's printed strain must
    // be the one evaluated (none held at the format's edge), and the reference's takes
    // the same, so that the two compare (past them its force left f64: `-inf` at
    // -1e308, and the strain printed in 309 digits).
    let (min, max) = (Strain::MIN.to_num::<f64>(), Strain::MAX.to_num::<f64>());
    for (name, v) in [("--from", from), ("--to", to)] {
        if !(min..=max).contains(&v) {
            return Err(arg_error(
                name,
                "must be within the fixed point's strains, -128 … 127.99999994 (Q24)",
            ));
        }
    }
    if step <= 0.0 {
        return Err(arg_error("--step", "must be > 0"));
    }
    if to < from {
        return Err(arg_error("--to", "must be >= --from"));
    }
    let count = ((to - from) / step * (1.0 + 1e-12) + 1e-9).floor() + 1.0;
    if count > MAX_ROWS as f64 {
        return Err(arg_error("--step", "too small: more than 10,000,000 rows"));
    }
    // Rounded to 12 decimals, so that the printed strain is the one evaluated.
    Ok((0..count as usize)
        .map(|i| {
            let e = from + i as f64 * step;
            fmt_strain(e).parse().unwrap_or(e)
        })
        .collect())
}

fn fixed_curve<const S: usize>(t: &ForceTable<S>, strains: &[f64]) -> Vec<(f64, f64, f64)> {
    strains
        .iter()
        .map(|&e| {
            let (f, k) = t.force_and_stiffness(Strain::saturating_from_num(e));
            (e, f.to_num::<f64>(), k.to_num::<f64>())
        })
        .collect()
}

fn write_curve(out: &mut dyn Write, rows: &[(f64, f64, f64)]) -> Result<(), CliError> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(["strain", "force_n", "stiffness_n"])
        .map_err(csv_error)?;
    for (e, f, k) in rows {
        w.write_record([fmt_strain(*e), f.to_string(), k.to_string()])
            .map_err(csv_error)?;
    }
    w.flush().map_err(io_error)
}
