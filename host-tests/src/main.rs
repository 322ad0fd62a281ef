//! `mccs`: see `mccs --help` and docs/cli.md.

use clap::Parser;
use mccs_host::cli::{run, Cli};
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help and --version
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            // clap's message, folded onto one line, without its usage block.
            let text = e.to_string();
            let head = text.split("\n\nUsage:").next().unwrap_or(&text);
            let line: Vec<&str> = head.split_whitespace().collect();
            let line = line.join(" ");
            eprintln!("mccs: {}", line.trim_start_matches("error: "));
            return ExitCode::from(2);
        }
    };
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    match run(cli, &mut out) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            drop(out);
            eprintln!("mccs: {e}");
            ExitCode::from(2)
        }
    }
}
