//! `mccs demo`: the firmware's demo run on the host, and the check of a firmware log
//! against it.

use super::{arg_error, io_error, CliError};
use mccs_client::shown::ShownPath;
use mccs_firmware::demo::{self, ArmSummary, Summary};
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
    /// The demo on the arm (the firmware built `--features arm`; m4f and m3): the
    /// palpation through the WoodenHaptics arm's joint counts, its SUMMARY with the
    /// joints' duties at the steady tick and the largest.
    #[arg(long)]
    arm: bool,
}

pub(super) fn run(a: Args, out: &mut dyn Write) -> Result<(), CliError> {
    let spec = demo::spec(&a.core).ok_or_else(|| arg_error("--core", "must be m4f, m3 or m0"))?;
    let failed = |e: demo::DemoError| CliError::new(format!("demo: {e}"));
    let (host, arm) = if a.arm {
        if spec.core == "m0" {
            return Err(arg_error(
                "--arm",
                "the arm demo runs on m4f and m3 (the M0's 16 KiB of RAM do not hold its samples of counts)",
            ));
        }
        let (s, arm) = demo::run_arm_on_host(&spec).map_err(failed)?;
        (s, Some(arm))
    } else {
        (demo::run_on_host(&spec).map_err(failed)?, None)
    };
    let mut line = format!(
        "SUMMARY ticks={} overruns={} max_force_n={} steady_force_n={} window_shifts={}",
        host.ticks, host.overruns, host.max_force, host.steady_force, host.window_shifts
    );
    if let Some(arm) = arm {
        let [a, b, c] = arm.steady_duty;
        line += &format!(
            " steady_duty_a={a} steady_duty_b={b} steady_duty_c={c} max_duty={}",
            arm.max_duty
        );
    }
    match a.check {
        None => writeln!(out, "{line}").map_err(io_error),
        Some(log) => check_demo_log(&log, &a.core, (&host, arm.as_ref()), &line, out),
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
    /// The arm demo's duties: at the steady tick (A, B, C) and the largest.
    pub arm: Option<ArmSummary>,
}

/// Parses a `SUMMARY ticks=… overruns=… max_force_n=… steady_force_n=… window_shifts=…`
/// line: exactly these five fields, in this order, and after them, in the arm demo's,
/// `steady_duty_a=… steady_duty_b=… steady_duty_c=… max_duty=…`.
pub fn parse_summary(line: &str) -> Option<FirmwareSummary> {
    let mut fields = line.trim().strip_prefix("SUMMARY ")?.split_whitespace();
    let mut next = |name: &str| -> Option<String> {
        let kv = fields.next()?;
        Some(kv.strip_prefix(name)?.strip_prefix('=')?.to_owned())
    };
    let mut s = FirmwareSummary {
        ticks: next("ticks")?.parse().ok()?,
        overruns: next("overruns")?.parse().ok()?,
        max_force: next("max_force_n")?.parse().ok()?,
        steady_force: next("steady_force_n")?.parse().ok()?,
        window_shifts: next("window_shifts")?.parse().ok()?,
        arm: None,
    };
    let first = next("steady_duty_a");
    if let Some(a) = first {
        s.arm = Some(ArmSummary {
            steady_duty: [
                a.parse().ok()?,
                next("steady_duty_b")?.parse().ok()?,
                next("steady_duty_c")?.parse().ok()?,
            ],
            max_duty: next("max_duty")?.parse().ok()?,
        });
    }
    fields.next().is_none().then_some(s)
}

/// The demo log's checks: it is `core`'s demo log (its first line is the firmware's
/// start line for that core), it ends with one well-formed SUMMARY line, and that line
/// equals the host's run.
fn check_demo_log(
    log: &Path,
    core: &str,
    (host, arm): (&Summary, Option<&ArmSummary>),
    host_line: &str,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    let name = ShownPath(log);
    let text = mccs_client::input::read_text(log, mccs_client::input::DATA_BYTES)
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
    let on_arm = lines[0].contains(&format!("core={core} on the arm"));
    if on_arm != arm.is_some() {
        return Err(CliError::new(if on_arm {
            format!("{name}: the arm demo's log (the firmware built --features arm): check it with --arm")
        } else {
            format!("{name}: not the arm demo's log (build the firmware --features arm), or check it without --arm")
        }));
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
        && fw.window_shifts == host.window_shifts
        && fw.arm.as_ref() == arm;
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
