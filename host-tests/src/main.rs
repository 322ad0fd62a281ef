//! `mccs`: see `mccs --help` and docs/cli.md.

use clap::error::ErrorKind;
use clap::{CommandFactory, Parser};
use mccs_host::cli::{join_negative_values, run, Cli};
use std::process::ExitCode;

/// A usage error as one line naming what is wrong, and a short usage hint.
fn usage_error(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let mut parts = text.split("\n\n");
    let head = parts.next().unwrap_or("");
    let line: Vec<&str> = head.split_whitespace().collect();
    // (clap's ranges in words: `70000 is not in 0 … 65535`, not `0..=65535`.)
    let line = line.join(" ").replace("..=", " … ");
    let line = line.trim_start_matches("error: ");
    let usage = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("Usage: "))
        .map(|u| {
            let cmd: Vec<&str> = u.split_whitespace().take(2).collect();
            format!("\nusage: {u}  (`{} --help` for more)", cmd.join(" "))
        })
        .unwrap_or_default();
    let tip = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("tip: "))
        .map(|t| format!(" (tip: {t})"))
        .unwrap_or_default();
    format!("mccs: {line}{tip}{usage}")
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse_from(join_negative_values(std::env::args_os())) {
        Ok(cli) => cli,
        Err(e) => match e.kind() {
            ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
                let _ = e.print();
                return ExitCode::SUCCESS;
            }
            ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                // A bare `mccs` (or a bare subcommand group): the full help.
                let _ = Cli::command().print_long_help();
                return ExitCode::from(2);
            }
            _ => {
                eprintln!("{}", usage_error(&e));
                return ExitCode::from(2);
            }
        },
    };
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    match run(cli, &mut out) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            drop(out);
            // (No line when the reader closed stdout.)
            if !e.message.is_empty() {
                eprintln!("mccs: {e}");
            }
            ExitCode::from(e.status)
        }
    }
}
