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
    /// A decoded firmware log (scripts/firmware.sh's output) to check against the host's
    /// run: exit 0 when it is this core's demo log and its SUMMARY line has the host's
    /// ticks, forces (to the printed digit) and window shifts, and overruns=0; exit 1 when it does not;
    /// exit 2 when the file cannot be read or is not this core's demo log.
    #[arg(long)]
    check: Option<PathBuf>,
}

pub(super) fn run(a: Args, out: &mut dyn Write) -> Result<(), CliError> {
    let spec = demo::spec(&a.core).ok_or_else(|| arg_error("--core", "must be m4f, m3 or m0"))?;
    let host = demo::run_on_host(&spec).map_err(|e| CliError::new(format!("demo: {e}")))?;
    let line = format!(
        "SUMMARY ticks={} overruns={} max_force_n={} steady_force_n={} window_shifts={}",
        host.ticks, host.overruns, host.max_force, host.steady_force, host.window_shifts
    );
    match a.check {
        None => writeln!(out, "{line}").map_err(io_error),
        Some(log) => check_demo_log(&log, &a.core, &host, &line, out),
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
    pub max_force: f32,
    /// Steady force, N.
    pub steady_force: f32,
    /// Window shifts.
    pub window_shifts: u32,
}

/// Parses a `SUMMARY ticks=… overruns=… max_force_n=… steady_force_n=… window_shifts=…`
/// line: exactly these five fields, in this order.
pub fn parse_summary(line: &str) -> Option<FirmwareSummary> {
    let mut fields = line.trim().strip_prefix("SUMMARY ")?.split_whitespace();
    let mut next = |name: &str| -> Option<String> {
        let kv = fields.next()?;
        Some(kv.strip_prefix(name)?.strip_prefix('=')?.to_owned())
    };
    let s = FirmwareSummary {
        ticks: next("ticks")?.parse().ok()?,
        overruns: next("overruns")?.parse().ok()?,
        max_force: next("max_force_n")?.parse().ok()?,
        steady_force: next("steady_force_n")?.parse().ok()?,
        window_shifts: next("window_shifts")?.parse().ok()?,
    };
    fields.next().is_none().then_some(s)
}

/// The demo log's checks: it is `core`'s demo log (its first line is the firmware's
/// start line for that core), it ends with one well-formed SUMMARY line, and that line
/// equals the host's run.
fn check_demo_log(
    log: &Path,
    core: &str,
    host: &Summary,
    host_line: &str,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    let name = log.display();
    let text = std::fs::read_to_string(log)
        .map_err(|e| CliError::new(format!("{name}: cannot read: {e}")))?;
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    let start = format!("mccs haptic demo: core={core} ");
    if !lines.first().is_some_and(|l| {
        l.trim_start_matches("INFO")
            .trim_start()
            .starts_with(&start)
    }) {
        return Err(CliError::new(format!(
            "{name}: not a {core} demo log (its first line is not the firmware's `{}…`)",
            start.trim_end()
        )));
    }
    let summaries = lines.iter().filter(|l| l.starts_with("SUMMARY")).count();
    let last = lines.last().copied().unwrap_or_default();
    let fw = match (summaries, parse_summary(last)) {
        (1, Some(fw)) => fw,
        (0, _) => {
            return Err(CliError::new(format!(
                "{name}: no SUMMARY line: the firmware did not finish"
            )))
        }
        (1, None) if last.starts_with("SUMMARY") => {
            return Err(CliError::new(format!(
                "{name}: its SUMMARY line is not `SUMMARY ticks=… overruns=… max_force_n=… steady_force_n=… window_shifts=…` (a firmware older than this mccs? rebuild it)"
            )))
        }
        _ => {
            return Err(CliError::new(format!(
                "{name}: the log must end with its one SUMMARY line"
            )))
        }
    };
    let ok = fw.overruns == 0
        && fw.ticks == host.ticks
        && fw.steady_force == host.steady_force
        && fw.max_force == host.max_force
        && fw.window_shifts == host.window_shifts;
    writeln!(out, "host:     {host_line}").map_err(io_error)?;
    writeln!(out, "firmware: {last}").map_err(io_error)?;
    if ok {
        writeln!(out, "demo check: ok").map_err(io_error)
    } else {
        Err(CliError::check_failed(format!(
            "{name}: SUMMARY differs from the host's run (needs overruns=0, the same ticks, forces to the printed digit and window shifts)"
        )))
    }
}
