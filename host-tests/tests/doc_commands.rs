//! Every `mccs …` command line in README.md and docs/ (in a shell block, or in inline
//! code) against the CLI's definition: each subcommand named exists, and each `--flag`
//! is one of the subcommand's (or `--help`, `--version`). What a line writes for the
//! reader — `ADDR`, `FILE`, `[--opt V]`, `a|b` for one of the subcommands — is read as
//! such. (docs/experiments/ is the record of what was run then: left out.)

use clap::CommandFactory;
use mccs_host::cli::Cli;
use std::path::{Path, PathBuf};

fn pages() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut out = vec![root.join("README.md")];
    for e in std::fs::read_dir(root.join("docs")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "md") {
            out.push(p);
        }
    }
    out.sort();
    out
}

/// `(line number, command)` of each `mccs …` line: in fenced shell blocks (a `\`-ended
/// line joined to the next, a `#` comment dropped) and in inline code.
fn command_lines(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fence: Option<String> = None;
    let mut pending: Option<(usize, String)> = None;
    for (i, line) in text.lines().enumerate() {
        let n = i + 1;
        let t = line.trim();
        if let Some(rest) = t.strip_prefix("```") {
            fence = match fence {
                None => Some(rest.to_string()),
                Some(_) => None,
            };
            continue;
        }
        match &fence {
            Some(lang) if matches!(lang.as_str(), "sh" | "bash" | "console" | "") => {
                let t = t.strip_prefix("$ ").unwrap_or(t);
                let code = t.split(" #").next().unwrap_or(t).trim();
                if let Some((start, mut acc)) = pending.take() {
                    acc.push(' ');
                    acc.push_str(code.trim_end_matches('\\'));
                    if code.ends_with('\\') {
                        pending = Some((start, acc));
                    } else {
                        out.push((start, acc));
                    }
                } else if code.starts_with("mccs ") {
                    if code.ends_with('\\') {
                        pending = Some((n, code.trim_end_matches('\\').to_string()));
                    } else {
                        out.push((n, code.to_string()));
                    }
                }
            }
            Some(_) => {}
            None => {
                for (k, span) in line.split('`').enumerate() {
                    if k % 2 == 1 && span.starts_with("mccs ") {
                        out.push((n, span.to_string()));
                    }
                }
            }
        }
    }
    out
}

/// A word the reader fills in, or that stands for more: `FILE`, `X,Y,Z`, `…`, `<name>`.
fn placeholder(w: &str) -> bool {
    w.contains('…')
        || w.contains("...")
        || w.starts_with('<')
        || w.chars().any(|c| c.is_ascii_uppercase()) && !w.chars().any(|c| c.is_ascii_lowercase())
}

/// Why `line` does not match the CLI, if it does not.
fn check(line: &str) -> Result<(), String> {
    if line
        .split_whitespace()
        .nth(1)
        .is_some_and(|w| w.ends_with(':'))
    {
        return Ok(()); // what a run prints (`mccs replay: warning: …`), not a command
    }
    let root = Cli::command();
    let mut at: Vec<clap::Command> = vec![root];
    let mut words = line.split_whitespace().skip(1).peekable();
    while let Some(raw) = words.next() {
        if matches!(raw, "|" | ">" | ">>" | "&" | "&&" | ";" | "2>" | "2>&1")
            || raw.starts_with('>')
        {
            break;
        }
        let w = raw.trim_matches(|c| c == '[' || c == ']' || c == '(' || c == ')');
        if w.is_empty() || placeholder(w) {
            continue;
        }
        if let Some(flag) = w.strip_prefix("--") {
            let name = flag.split('=').next().unwrap_or(flag);
            if name == "help" || name == "version" {
                continue;
            }
            let arg = at
                .iter()
                .find_map(|c| {
                    c.get_arguments()
                        .find(|a| a.get_long() == Some(name))
                        .cloned()
                })
                .ok_or_else(|| {
                    let names: Vec<&str> = at.iter().map(|c| c.get_name()).collect();
                    format!("--{name} is not an option of {}", names.join("|"))
                })?;
            let takes = arg.get_action().takes_values();
            if takes && !flag.contains('=') && !raw.ends_with(']') {
                words.next();
            }
            continue;
        }
        if w.starts_with('-') {
            continue; // a value: a negative number
        }
        if at[0].has_subcommands() {
            let mut next = Vec::new();
            for alt in w.split('|') {
                let found = at
                    .iter()
                    .find_map(|c| c.find_subcommand(alt).cloned())
                    .ok_or_else(|| format!("no subcommand {alt:?} under {}", at[0].get_name()))?;
                next.push(found);
            }
            at = next;
        }
        // Otherwise a positional value (a script's file, a subcommand's argument).
    }
    Ok(())
}

#[test]
fn every_mccs_command_line_in_the_docs_matches_the_cli() {
    let mut bad = Vec::new();
    let mut seen = 0;
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for (n, line) in command_lines(&text) {
            seen += 1;
            if let Err(why) = check(&line) {
                bad.push(format!("{}:{n}: `{line}`: {why}", page.display()));
            }
        }
    }
    assert!(
        seen > 100,
        "only {seen} command lines found: the reader is broken"
    );
    eprintln!("{seen} command lines checked");
    assert!(
        bad.is_empty(),
        "{} stale command lines:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn the_checker_finds_a_stale_subcommand_and_a_stale_flag() {
    assert!(check("mccs curve --params p.toml --from 0").is_ok());
    assert!(check("mccs link --connect ADDR hello|status").is_ok());
    assert!(check("mccs link --connect ADDR load --params FILE [--friction MU_S,MU_K]").is_ok());
    assert!(check("mccs replay: warning: the force was at the clamp").is_ok());
    assert!(check("mccs curvy --params p.toml")
        .unwrap_err()
        .contains("curvy"));
    assert!(check("mccs curve --parms p.toml")
        .unwrap_err()
        .contains("--parms"));
    assert!(check("mccs link --connect A hello|stats")
        .unwrap_err()
        .contains("stats"));
    assert!(check("mccs link --connect A watch --secs 2")
        .unwrap_err()
        .contains("--secs"));
}
