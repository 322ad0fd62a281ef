//! The `mccs` command-line tool: one module per subcommand, each owning its arguments
//! (`clap::Args`) and its run. Every failure is a [`CliError`]: one line, exit status 2
//! for bad input, 1 for a check that ran and failed (`mccs demo --check`).

use crate::paramfile;
use clap::{Parser, Subcommand, ValueEnum};
use mccs_client::shown::ShownPath;
use std::ffi::OsString;
use std::io::Write;
use std::path::{Path, PathBuf};

mod arm;
mod check;
pub use check::bench_figure;
mod curve;
mod demo;
mod fit;
mod link;
pub(crate) mod link_script;
mod patch;
mod patch_args;
mod progress;
mod replay;
mod table;
mod view;
mod watch;

pub use demo::{parse_summary, FirmwareSummary};
pub use patch::PatchRun;
pub use patch_args::MAX_GRID_REFERENCE;
pub use table::render_table;

/// One-line error for the user, and the exit status it gets.
#[derive(Debug, Clone, PartialEq)]
pub struct CliError {
    /// The line.
    pub message: String,
    /// 2: bad input (a file, a row, an argument); 1: a check ran and failed; 141: the
    /// reader of stdout closed it ([`CliError::output_closed`]).
    pub status: u8,
}

impl CliError {
    /// Bad input: exit status 2.
    pub fn new(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            status: 2,
        }
    }

    /// The reader closed stdout (`mccs curve … | head`): no line, and exit status 141,
    /// what a tool killed by `SIGPIPE` gives (never 0: `demo --check` does not pass).
    pub fn output_closed() -> Self {
        Self {
            message: String::new(),
            status: OUTPUT_CLOSED,
        }
    }

    /// A check that ran and failed: exit status 1.
    pub fn check_failed(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            status: 1,
        }
    }
}

impl std::fmt::Display for CliError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl From<paramfile::ParamFileError> for CliError {
    fn from(e: paramfile::ParamFileError) -> Self {
        CliError::new(e.to_string())
    }
}

/// `ARG: what`.
pub(crate) fn arg_error(arg: &str, what: &str) -> CliError {
    CliError::new(format!("{arg}: {what}"))
}

/// `FILE: what`, for a parameter file whose values break a rule.
pub(crate) fn file_error(file: &Path, e: impl std::fmt::Display) -> CliError {
    CliError::new(format!("{}: {e}", ShownPath(file)))
}

/// The exit status when the reader closed stdout: 128 + `SIGPIPE`.
pub const OUTPUT_CLOSED: u8 = 141;

/// A failure writing the output: [`CliError::output_closed`] when the reader closed it,
/// else `stdout: …`.
pub(crate) fn io_error(e: std::io::Error) -> CliError {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        return CliError::output_closed();
    }
    CliError::new(format!("stdout: {e}"))
}

/// A failure of the CSV writer on stdout, as [`io_error`].
pub(crate) fn csv_error(e: csv::Error) -> CliError {
    let line = format!("stdout: {e}");
    match e.into_kind() {
        csv::ErrorKind::Io(io) => io_error(io),
        _ => CliError::new(line),
    }
}

/// Multi-component conical spring soft tissue: curves, tables, fits, patch runs and
/// replays on the host; the firmware's demo and its check. Every subcommand has --help;
/// docs/cli.md has the whole tour.
#[derive(Parser, Debug)]
#[command(name = "mccs", version, arg_required_else_help = true)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// How a force is evaluated.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    /// The f64 reference law (host only).
    Reference,
    /// The no_std core's fixed-point table, as the firmware evaluates it.
    Fixed,
}

/// The fixed-point solver's arithmetic (`mccs::arith`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArithArg {
    /// 32 × 32 → 64 products: the M3/M4F firmware.
    Wide,
    /// One 16-bit operand per product: the M0 firmware.
    Narrow,
}

/// The solver's integrator (`mccs::Integrator`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorArg {
    /// The paper's improved Euler (eqs. 21–22).
    ImprovedEuler,
    /// Symplectic Euler with one implicit damping factor: a larger stable substep.
    SymplecticDamped,
}

impl From<IntegratorArg> for mccs::Integrator {
    fn from(a: IntegratorArg) -> Self {
        match a {
            IntegratorArg::ImprovedEuler => mccs::Integrator::ImprovedEuler,
            IntegratorArg::SymplecticDamped => mccs::Integrator::SymplecticDamped,
        }
    }
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Print F(ε) and dF/dε as CSV `strain,force_n,stiffness_n` for ε = FROM, FROM+STEP, … ≤ TO.
    Curve(curve::Args),
    /// Emit the fixed-point force table as Rust source for `include!`, its measured error
    /// in its header; a table over the product's bound is refused (exit 2) with the knots
    /// or the narrower domain that meets it, measured.
    Table(table::Args),
    /// Fit models to compression data (CSV `strain,force_n`) and compare them: one line
    /// `FIT model=<name> mean_abs=<f> max_abs=<f> mse=<f>` per model.
    Fit(fit::Args),
    /// Print the shipped synthetic demo data set (`params/demo-data.csv`): the Table 2
    /// MCCS law at 40 forces to 1 N, strains with 1 % Gaussian noise (seed 2020).
    DemoData,
    /// Run the firmware's demo on the host (the same code, fixed point) and print its
    /// SUMMARY line; with `--check LOG`, compare a firmware log's SUMMARY line with it.
    Demo(demo::Args),
    /// Indent the standard patch: ramp the contact node down to DEPTH over the first half
    /// of the run, hold it there, and print CSV `time_s,reaction_n` per tick.
    Patch(patch::Args),
    /// Replay a recorded probe trajectory against the standard patch (or, with --tissue,
    /// a tissue it roams) and print CSV per tick: `time_s,fx_n,fy_n,fz_n,max_disp_mm`,
    /// then the mode's own columns (see --help).
    #[command(after_help = replay::COLUMNS_HELP)]
    Replay(replay::Args),
    /// Will a tissue run on a core? One line `substeps=<s> tick_instructions=<i>
    /// budget=<b> fits=yes|no`: the core's stability bound's substeps, the tick estimated
    /// from the bench's measured costs (exit 1 when it does not fit).
    Check(check::Args),
    /// The 3-DOF arm (docs/arm.md): `fk` (counts to the probe) and `torque` (counts and a
    /// force to the joints' torques and duties), fixed point or the f64 twin.
    Arm(arm::Args),
    /// Talk to a device over the host link (docs/link.md): hello, status, load a tissue,
    /// replay a trajectory on the device, watch its live telemetry, pose, arm, disarm.
    Link(link::Args),
    /// A live view of a device in the browser (docs/view.md): the patch in 3-D, the
    /// force and flags over the last 10 s, the device's facts and counters, and its
    /// controls, served on 127.0.0.1 from this binary; `--demo` needs no board.
    View(view::Args),
}

/// Runs the parsed command, writing its output to `out`.
pub fn run(cli: Cli, out: &mut dyn Write) -> Result<(), CliError> {
    match cli.command {
        Command::Curve(a) => curve::run(a, out),
        Command::Table(a) => table::run(a, out),
        Command::Fit(a) => fit::run(a, out),
        Command::DemoData => out
            .write_all(crate::fit::to_csv(&crate::fit::demo_data()).as_bytes())
            .map_err(io_error),
        Command::Demo(a) => demo::run(a, out),
        Command::Patch(a) => patch::run(a, out),
        Command::Replay(a) => replay::run(a, out),
        Command::Check(a) => check::run(a, out),
        Command::Link(a) => link::run(a, out),
        Command::Arm(a) => arm::run(a, out),
        Command::View(a) => view::run(a, out),
    }
}

/// The command line with each negative number (or pair of numbers, the first negative)
/// that follows a long option joined to it (`--from -1e-3` → `--from=-1e-3`). clap takes
/// `-1e3` or `-0.5` as a value, but not a negative number with a signed exponent
/// (`-1e-3`, `-5E-2`) or a pair (`--friction -0.1,0`), which it would split into short
/// flags (`unexpected argument '-1'`). Other arguments pass unchanged.
pub fn join_negative_values(args: impl IntoIterator<Item = OsString>) -> Vec<OsString> {
    let mut out: Vec<OsString> = Vec::new();
    for arg in args {
        let number = arg.to_str().is_some_and(|a| {
            a.starts_with('-') && a.split(',').all(|x| x.trim().parse::<f64>().is_ok())
        });
        let after_long = out
            .last()
            .and_then(|p| p.to_str())
            .is_some_and(|p| p.len() > 2 && p.starts_with("--") && !p.contains('='));
        match out.last_mut() {
            Some(prev) if number && after_long => {
                prev.push("=");
                prev.push(&arg);
            }
            _ => out.push(arg),
        }
    }
    out
}

/// Fails unless `path` can be written: its folder exists and takes a new file, and it is
/// not a folder or a read-only file itself.
pub(crate) fn check_writable(arg: &str, path: &Path) -> Result<(), CliError> {
    let bad = |what: &str| arg_error(arg, &format!("{}: {what}", ShownPath(path)));
    if path.is_dir() {
        return Err(bad("is a folder"));
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.is_dir() {
        return Err(bad("its folder does not exist"));
    }
    if let Ok(meta) = std::fs::metadata(path) {
        if meta.permissions().readonly() {
            return Err(bad("is read-only"));
        }
    }
    let probe = dir.join(format!(".mccs-write-check-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| bad(&format!("its folder cannot be written: {e}")))?;
    let _ = std::fs::remove_file(probe);
    Ok(())
}

/// A number a user gave, for a message: as written for everyday magnitudes (`2.5`), in
/// scientific notation outside 1e-4 … 1e9 (`1e-300`, not three hundred zeros).
pub(crate) fn fmt_given(x: f64) -> String {
    if x == 0.0 || (1e-4..1e9).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// A grid strain with the float noise of `from + i·step` removed (12 decimals at most).
pub(crate) fn fmt_strain(e: f64) -> String {
    let s = format!("{e:.12}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}
