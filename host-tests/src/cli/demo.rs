//! `mccs demo`: the firmware's demo run on the host, and the check of a firmware log
//! against it.

use super::{arg_error, io_error, CliError};
use mccs_firmware::demo::{self, Summary};
use std::io::Write;
use std::path::{Path, PathBuf};

#[derive(clap::Args, Debug)]
pub(super) struct Args {
    /// Which core's demo: m4f, m3 or m0.
    #[arg(long, default_value = "m4f")]
    core: String,
    /// A decoded firmware log to check: exit 1 unless its SUMMARY has overruns=0 and
    /// the same ticks, and steady and max force within 1 % of the host's.
    #[arg(long)]
    check: Option<PathBuf>,
}

pub(super) fn run(a: Args, out: &mut dyn Write) -> Result<(), CliError> {
    let spec = demo::spec(&a.core).ok_or_else(|| arg_error("--core", "must be m4f, m3 or m0"))?;
    let host = demo::run_on_host(&spec).map_err(|e| CliError(format!("demo: {e:?}")))?;
    let line = format!(
        "SUMMARY ticks={} overruns={} max_force_n={} steady_force_n={}",
        host.ticks, host.overruns, host.max_force, host.steady_force
    );
    match a.check {
        None => writeln!(out, "{line}").map_err(io_error),
        Some(log) => check_demo_log(&log, &host, &line, out),
    }
}

/// A firmware SUMMARY line, parsed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FirmwareSummary {
    /// Ticks run.
    pub ticks: u32,
    /// Ticks over budget.
    pub overruns: u32,
    /// Largest force, N.
    pub max_force: f64,
    /// Steady force, N.
    pub steady_force: f64,
}

/// Parses the last `SUMMARY ticks=… overruns=… max_force_n=… steady_force_n=…` line.
pub fn parse_summary(log: &str) -> Option<FirmwareSummary> {
    let line = log
        .lines()
        .rev()
        .find(|l| l.trim_start().starts_with("SUMMARY "))?;
    let field = |name: &str| -> Option<&str> {
        line.split_whitespace()
            .find_map(|kv| kv.strip_prefix(name).and_then(|v| v.strip_prefix('=')))
    };
    Some(FirmwareSummary {
        ticks: field("ticks")?.parse().ok()?,
        overruns: field("overruns")?.parse().ok()?,
        max_force: field("max_force_n")?.parse().ok()?,
        steady_force: field("steady_force_n")?.parse().ok()?,
    })
}

fn check_demo_log(
    log: &Path,
    host: &Summary,
    host_line: &str,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    let text = std::fs::read_to_string(log)
        .map_err(|e| CliError(format!("{}: cannot read: {e}", log.display())))?;
    let fw = parse_summary(&text)
        .ok_or_else(|| CliError(format!("{}: no SUMMARY line", log.display())))?;
    let within = |a: f64, b: f64| (a - b).abs() <= 0.01 * b.abs();
    let ok = fw.overruns == 0
        && fw.ticks == host.ticks
        && within(fw.steady_force, host.steady_force as f64)
        && within(fw.max_force, host.max_force as f64);
    writeln!(out, "host:     {host_line}").map_err(io_error)?;
    writeln!(
        out,
        "firmware: SUMMARY ticks={} overruns={} max_force_n={} steady_force_n={}",
        fw.ticks, fw.overruns, fw.max_force, fw.steady_force
    )
    .map_err(io_error)?;
    if ok {
        writeln!(out, "demo check: ok").map_err(io_error)
    } else {
        Err(CliError(format!(
            "{}: SUMMARY does not match the host (needs overruns=0, the same ticks, forces within 1 %)",
            log.display()
        )))
    }
}
