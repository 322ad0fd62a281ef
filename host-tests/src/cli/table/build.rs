//! The one force-table builder of the command line: `mccs table` and every
//! `--backend fixed` path (`curve`, `patch`, `replay`) build their table here, by one
//! call ([`build`]), so that the table a user sees on the host is the table `mccs table`
//! emits for the firmware, and a table over the product's bound is refused by all of them
//! with the same line ([`refusal`]).

use super::remedy::remedy;
use crate::cli::{arg_error, file_error, CliError};
use mccs::{ForceTable, Params, TableBound, TableError};
use mccs_client::shown::ShownPath;
use std::path::Path;

/// The table options every fixed-point path shares, with the same defaults.
#[derive(clap::Args, Debug, Clone, Copy, Default)]
pub(crate) struct TableArgs {
    /// Knots of the fixed-point force table: 17, 33, 65 or 129 (default 65; with
    /// --backend fixed).
    #[arg(long)]
    pub knots: Option<usize>,
    /// Use the force table even if its measured error is over the product's bound
    /// (force 2e-5 of F(to), stiffness 1e-3 relative), with a warning (with --backend
    /// fixed).
    #[arg(long)]
    pub accept_error: bool,
}

impl TableArgs {
    /// The knots asked for, or the default ([`mccs::table::DEFAULT_KNOTS`]).
    pub fn knots(&self) -> usize {
        self.knots.unwrap_or(mccs::table::DEFAULT_KNOTS)
    }

    /// Refuses the options where no fixed-point table is built (`--backend reference`).
    pub fn only_with_fixed(&self) -> Result<(), CliError> {
        if self.knots.is_some() {
            return Err(arg_error("--knots", "only with --backend fixed"));
        }
        if self.accept_error {
            return Err(arg_error("--accept-error", "only with --backend fixed"));
        }
        Ok(())
    }
}

/// Where a table's domain comes from: the `--from`/`--to` of `mccs table` (its errors
/// name them), or the default domain (its errors name the parameter file).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Domain {
    Args(f64, f64),
    Default,
}

impl Domain {
    fn bounds(self) -> (f64, f64) {
        match self {
            Self::Args(from, to) => (from, to),
            Self::Default => mccs::table::DEFAULT_DOMAIN,
        }
    }
}

/// Runs `$body` with the const `$s` the segment count for `knots` (17, 33, 65 or 129
/// knots); another count is refused, naming `--knots`.
macro_rules! with_knots {
    ($knots:expr, |$s:ident| $body:expr) => {{
        match $knots {
            17 => {
                const $s: usize = 16;
                $body
            }
            33 => {
                const $s: usize = 32;
                $body
            }
            65 => {
                const $s: usize = 64;
                $body
            }
            129 => {
                const $s: usize = 128;
                $body
            }
            _ => {
                return Err($crate::cli::arg_error(
                    "--knots",
                    "must be 17, 33, 65 or 129",
                ))
            }
        }
    }};
}
pub(crate) use with_knots;

/// The table for `p` with `S` segments over `domain`: the best placement of its knots,
/// measured against the `f64` law ([`ForceTable::from_law_best`]); refused with
/// [`refusal`]'s line unless within the product's bound, or used with a warning on
/// stderr under `--accept-error` (`warn`: the paths that do not print the table's
/// figures themselves). Errors name the argument or the file at fault.
pub(crate) fn build<const S: usize>(
    p: &Params,
    file: &Path,
    domain: Domain,
    accept_error: bool,
    warn: bool,
) -> Result<ForceTable<S>, CliError> {
    let (from, to) = domain.bounds();
    if let Domain::Args(..) = domain {
        for (name, v) in [("--from", from), ("--to", to)] {
            if !v.is_finite() || v.abs() >= 127.0 {
                return Err(arg_error(name, "must be a finite strain within ±127"));
            }
        }
        if from >= to {
            return Err(arg_error("--to", "must be > --from"));
        }
    }
    let law = mccs::Law::new(p).map_err(|e| file_error(file, e))?;
    let t = ForceTable::<S>::from_law_best(&law, from, to)
        .map_err(|e| build_error(e, &law, file, domain))?;
    let reached = t.max_error().unwrap_or(UNKNOWN);
    if !reached.within(&TableBound::PRODUCT) {
        if !accept_error {
            return Err(file_error(file, refusal::<S>(&law, from, to, &reached)));
        }
        if warn {
            eprintln!(
                "mccs: warning: {}: the {}-knot force table misses the bound ({}): it reaches force {:.1e} of F({to:?}) and stiffness {:.1e}; used anyway (--accept-error)",
                ShownPath(file),
                S + 1,
                product_bound(),
                reached.force,
                reached.stiffness
            );
        }
    }
    Ok(t)
}

/// A builder's error, naming `--from`/`--to` where the user gave them, else the file.
fn build_error(e: TableError, law: &mccs::Law, file: &Path, domain: Domain) -> CliError {
    let (from, to) = domain.bounds();
    let args = matches!(domain, Domain::Args(..));
    match e {
        TableError::NoNonlinearPhase if to <= law.strain_t() => {
            let what = format!(
                "must exceed {:.6}, where this spring's law stops being linear",
                law.strain_t()
            );
            if args {
                arg_error("--to", &what)
            } else {
                file_error(
                    file,
                    format!(
                        "this spring stays linear up to strain {:.6}, beyond the table's domain [{from}, {to}]",
                        law.strain_t()
                    ),
                )
            }
        }
        TableError::NoNonlinearPhase => {
            if args {
                arg_error(
                    "--from",
                    &format!(
                        "must be below {:.6}, where this spring's cone is solid",
                        law.strain_c()
                    ),
                )
            } else {
                file_error(
                    file,
                    format!(
                        "this spring's cone is solid from strain {:.6}, below the table's domain [{from}, {to}]",
                        law.strain_c()
                    ),
                )
            }
        }
        TableError::TooNarrow if args => arg_error(
            "--from/--to",
            "the nonlinear phase inside them is too narrow for this many knots",
        ),
        other => file_error(file, other),
    }
}

/// Why a table that reached `reached` over `[from, to]` is refused, and what meets the
/// bound (after the file's name): the one line of every fixed-point path.
fn refusal<const S: usize>(law: &mccs::Law, from: f64, to: f64, reached: &TableBound) -> String {
    let bound = TableBound::PRODUCT;
    let floor = mccs::table::format_floor(law, from, to);
    let advice = if !floor.within(&bound) {
        // No knots or domain help: say so, not "more knots".
        format!(
            "the fixed-point formats cannot hold this spring to it (half an output LSB is {:.1e} of F({to:?}) and {:.1e} of its least stiffness): no knot count or domain meets it; use it anyway with --accept-error",
            floor.force, floor.stiffness
        )
    } else {
        format!(
            "{}; or use it anyway with --accept-error",
            remedy::<S>(law, from, to)
        )
    };
    format!(
        "the {}-knot table misses the bound ({}): it reaches force {:.1e} of F({to:?}) and stiffness {:.1e} (k_p/k = {:.2e}); {advice}",
        S + 1,
        product_bound(),
        reached.force,
        reached.stiffness,
        law.k_p / law.k,
    )
}

/// The product's bound in words: `force 2e-5, stiffness 1e-3`.
pub(super) fn product_bound() -> String {
    let b = TableBound::PRODUCT;
    format!("force {:.0e}, stiffness {:.0e}", b.force, b.stiffness)
}

/// What an unmeasured table is taken to reach (every table here is measured).
pub(super) const UNKNOWN: TableBound = TableBound {
    force: f64::INFINITY,
    stiffness: f64::INFINITY,
};
