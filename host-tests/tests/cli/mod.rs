//! The `mccs` binary as a user runs it: output format, and one-line errors with exit 2.
//! Here the parameter files, help and usage, the demo check and the progress of long
//! runs; each subcommand's own in its file.

mod arm;
mod check;
mod curve;
mod fit;
mod one_table;
mod patch;
mod replay;
mod table;
mod view;
mod walks;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the CLI from the repository root (the replay tests' too).
pub(crate) fn mccs(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mccs"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("run mccs")
}

/// [`mccs`], which must succeed: a failure shows the arguments and the CLI's stderr.
pub(crate) fn mccs_ok(args: &[&str]) -> Output {
    let out = mccs(args);
    assert!(
        out.status.success(),
        "mccs {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

pub(crate) fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

pub(crate) fn temp_file(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mccs-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::File::create(&path)
        .unwrap()
        .write_all(text.as_bytes())
        .unwrap();
    path
}

/// Asserts exit 2, empty stdout, and one stderr line containing every `needle` — for a
/// mistake the argument parser finds, followed by one `usage:` hint line.
fn assert_usage_error(out: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert!(out.stdout.is_empty(), "stdout not empty");
    let lines: Vec<&str> = err.lines().collect();
    let one_line = lines.len() == 1 || (lines.len() == 2 && lines[1].starts_with("usage: mccs"));
    assert!(one_line, "not one line (and a usage hint): {err:?}");
    for n in needles {
        assert!(lines[0].contains(n), "{err:?} lacks {n:?}");
    }
    assert_plain_words(lines[0]);
}

/// Asserts exit 2, empty stdout, and exactly one stderr line containing every `needle` —
/// for a mistake found past the argument parser (no usage hint).
pub(crate) fn assert_one_line_error(out: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert!(out.stdout.is_empty(), "stdout not empty");
    assert_eq!(err.lines().count(), 1, "{err}");
    for n in needles {
        assert!(err.contains(n), "{err:?} lacks {n:?}");
    }
    assert_plain_words(&err);
}

/// A message in words a user reads: no Rust range syntax (`3..=64`), no subject said
/// twice (`--friction: friction: …`), no control character (a user's text in it is
/// shown escaped: `mccs_client::shown::Shown`).
fn assert_plain_words(err: &str) {
    assert!(!err.contains("..="), "Rust syntax in {err:?}");
    assert!(
        !err.trim_end_matches('\n').chars().any(char::is_control),
        "a control character in {err:?}"
    );
    let parts: Vec<String> = err
        .split(": ")
        .map(|p| p.trim_start_matches('-').replace('-', " ").to_lowercase())
        .collect();
    for pair in parts.windows(2) {
        assert_ne!(pair[0], pair[1], "a doubled prefix in {err:?}");
    }
}

const TABLE2: &str = include_str!("../../../params/table2.toml");

/// `mccs curve` over a parameter file: the subcommand that reads one and nothing else.
fn curve_of(params: &str) -> Output {
    mccs(&[
        "curve", "--params", params, "--from", "0", "--to", "1", "--step", "0.1",
    ])
}

#[test]
fn bad_files_name_file_and_key() {
    let cases: [(&str, String, &[&str]); 11] = [
        (
            "missing.toml",
            TABLE2.replace("active_coils = 5.0\n", ""),
            &["cone.active_coils", "missing"],
        ),
        (
            "neg.toml",
            TABLE2.replace("mean_diameter = 0.2", "mean_diameter = -0.2"),
            &["line 13: linear.mean_diameter", "> 0"],
        ),
        (
            "nan.toml",
            TABLE2.replace("shear_modulus = 1.8472e5", "shear_modulus = nan"),
            &["cone.shear_modulus", "finite"],
        ),
        (
            "order.toml",
            TABLE2.replace("large_diameter = 0.8", "large_diameter = 0.3"),
            &["cone.large_diameter"],
        ),
        (
            "text.toml",
            TABLE2.replace("active_coils = 10.0", "active_coils = \"ten\""),
            &["line 14: linear.active_coils", "number"],
        ),
        (
            "typo.toml",
            TABLE2.replace("wire_diameter = 0.1", "wire_diametr = 0.1"),
            &["line 4: cone.wire_diametr: unknown key; did you mean cone.wire_diameter?"],
        ),
        (
            "shear.toml",
            TABLE2.replace("shear_modulus = 1.8472e5", "shear_modulos = 1.8472e5"),
            &["line 9: cone.shear_modulos: unknown key; did you mean cone.shear_modulus?"],
        ),
        (
            "section.toml",
            TABLE2.replace("[linear]", "[lineal]"),
            &["line 11: lineal: unknown key; did you mean linear?"],
        ),
        (
            "far.toml",
            format!("{TABLE2}colour = 3\n"),
            &["colour: unknown key (docs/model.md lists the schema)"],
        ),
        (
            "bad.toml",
            "[cone\nwire_diameter = 1".to_string(),
            &["line 1", "TOML"],
        ),
        (
            "pre.toml",
            format!("{TABLE2}preload = 11.0\n"),
            &[
                "line 16: linear.preload: must be below",
                "(preload = 11 N, F_C = 10.26 N)",
            ],
        ),
    ];
    for (name, text, needles) in cases {
        let path = temp_file(name, &text);
        let needles: Vec<&str> = [name].iter().chain(needles).copied().collect();
        assert_usage_error(&curve_of(path.to_str().unwrap()), &needles);
    }
    assert_usage_error(&curve_of("no/such.toml"), &["no/such.toml", "cannot read"]);
}

/// Every file the CLI reads is read to its limit and no further: `/dev/zero`, which
/// never ends, given as each kind of file, is one line naming it and the limit (1 MiB
/// for configuration, 256 MiB for data), where it was read until memory ran out.
#[cfg(unix)]
#[test]
fn a_file_that_never_ends_is_refused_at_its_limit() {
    let z = "/dev/zero";
    let t2 = "params/table2.toml";
    let arm = "devices/woodenhaptics.toml";
    let cases: [(&[&str], &str); 9] = [
        (&["table", "--params", z], "1 MiB"),
        (&["check", "--params", z], "1 MiB"),
        (&["arm", "fk", "--device", z, "--counts", z], "1 MiB"),
        (
            &["link", "--connect", "tcp:127.0.0.1:1", "script", z],
            "1 MiB",
        ),
        (
            &[
                "link",
                "--connect",
                "tcp:127.0.0.1:1",
                "load",
                "--params",
                z,
            ],
            "1 MiB",
        ),
        (&["fit", "--data", z], "256 MiB"),
        (&["replay", "--params", t2, "--probe", z], "256 MiB"),
        (&["arm", "fk", "--device", arm, "--counts", z], "256 MiB"),
        (&["demo", "--core", "m4f", "--check", z], "256 MiB"),
    ];
    for (args, limit) in cases {
        assert_usage_error(
            &mccs(args),
            &[&format!(
                "{z}: cannot read: the file is larger than {limit}"
            )],
        );
    }
}

/// A file's name or a device's address with a line break and a terminal's escape
/// sequence in it is named on the error's one line, escaped (`mccs_client::shown::
/// ShownPath`): every subcommand that reads a file, and `--connect`'s address when the
/// device cannot be reached. (They were shown as given: two lines, and the escape sent
/// to the terminal.)
#[test]
fn a_name_with_a_line_break_is_named_on_one_line() {
    let name = "no/a\nb\u{1b}[31m";
    let shown = r"no/a\nb\u{1b}[31m";
    let t2 = "params/table2.toml";
    let arm = "devices/woodenhaptics.toml";
    let tcp = "tcp:127.0.0.1:1";
    let [toml, csv, bin, log] = ["toml", "csv", "bin", "log"].map(|e| format!("{name}.{e}"));
    let unix = format!("unix:{name}");
    let cases: [&[&str]; 14] = [
        &[
            "curve", "--params", &toml, "--from", "0", "--to", "1", "--step", "0.1",
        ],
        &["table", "--params", &toml],
        &["check", "--params", &toml],
        &["patch", "--params", &toml, "--indent", "1"],
        &["fit", "--data", &csv],
        &["replay", "--params", t2, "--probe", &csv],
        &["demo", "--core", "m4f", "--check", &log],
        &["arm", "fk", "--device", &toml, "--counts", &csv],
        &["arm", "fk", "--device", arm, "--counts", &csv],
        &["link", "--connect", tcp, "script", &csv],
        &["link", "--connect", tcp, "load", "--params", &toml],
        &["link", "--connect", tcp, "load", "--params", &bin],
        &["link", "--connect", &unix, "hello"],
        &["view", "--connect", &unix],
    ];
    for args in cases {
        let out = mccs(args);
        assert_usage_error(&out, &[shown]);
    }
    // A table's source names its parameter file in its first comment line, which such a
    // name ended: the rest of the name was a line of code in the including crate.
    let params = temp_file("a\nb\u{1b}[31m.toml", TABLE2);
    let out = mccs_ok(&["table", "--params", params.to_str().unwrap()]);
    let src = String::from_utf8(out.stdout).unwrap();
    let first = src.lines().next().unwrap();
    assert!(
        first.starts_with("// Generated by `mccs table --params "),
        "{first}"
    );
    assert!(first.contains(r"a\nb\u{1b}[31m.toml --knots 65"), "{first}");
    assert!(src.lines().nth(1).unwrap().starts_with("// "), "{src}");
}

/// The front door: a bare `mccs` prints its full help; a usage error names the argument
/// and gives a usage hint; `demo --check` takes only a demo log of its core whose SUMMARY
/// equals the host's run, with the exit statuses its help states.
#[test]
fn help_usage_and_the_demo_check() {
    let out = mccs(&[]);
    assert_eq!(out.status.code(), Some(2));
    let help = String::from_utf8_lossy(&out.stdout);
    for sub in ["curve", "table", "fit", "demo", "patch", "replay"] {
        assert!(help.contains(sub), "{help}");
    }
    let out = mccs(&["curve", "--params", "x", "--frm", "1"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.lines().next().unwrap().contains("--frm"), "{err}");
    assert!(
        err.contains("tip: a similar argument exists: '--from'"),
        "{err}"
    );
    assert!(
        err.lines().nth(1).unwrap().starts_with("usage: mccs curve"),
        "{err}"
    );

    let host = String::from_utf8(mccs(&["demo", "--core", "m3"]).stdout).unwrap();
    let summary = host.trim();
    let start = "INFO  mccs haptic demo: core=m3 tick=1000 Hz, …";
    let old_summary = summary.split(" window_shifts=").next().unwrap().to_owned();
    let cases: [(&str, String, Option<i32>); 8] = [
        (
            "good.log",
            format!("{start}\nINFO  tick=100 …\n{summary}\n"),
            Some(0),
        ),
        ("readme.log", format!("# README\n{summary}\n"), Some(2)),
        (
            "other-core.log",
            format!("INFO  mccs haptic demo: core=m0 …\n{summary}\n"),
            Some(2),
        ),
        (
            "unfinished.log",
            format!("{start}\nINFO  tick=100 …\n"),
            Some(2),
        ),
        (
            "overrun.log",
            format!("{start}\n{}\n", summary.replace("overruns=0", "overruns=3")),
            Some(1),
        ),
        (
            "digits.log",
            format!("{start}\n{}\n", summary.replace("ticks=4000", "ticks=3999")),
            Some(1),
        ),
        (
            "old-firmware.log",
            format!("{start}\n{old_summary}\n"),
            Some(2),
        ),
        (
            "shifts.log",
            format!(
                "{start}\n{}\n",
                summary.replace("window_shifts=", "window_shifts=9")
            ),
            Some(1),
        ),
    ];
    for (name, text, status) in cases {
        let f = temp_file(name, &text);
        let out = mccs(&["demo", "--core", "m3", "--check", f.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), status, "{name}: {err}");
        if status != Some(0) {
            assert_eq!(err.lines().count(), 1, "{name}: {err}");
            assert!(err.contains(name), "{name}: {err}");
        }
    }
}

/// A command's CSV rows as numbers (the header left out).
fn numbers(out: &Output) -> Vec<Vec<f64>> {
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect()
}

/// `mccs curve` on Table 2's spring from `from` to `to` by `step`.
fn curve_table2<'a>(from: &'a str, to: &'a str, step: &'a str) -> [&'a str; 9] {
    [
        "curve",
        "--params",
        "params/table2.toml",
        "--from",
        from,
        "--to",
        to,
        "--step",
        step,
    ]
}

/// The issue's palpation replayed on a 64 × 64 tissue with friction 0.6 / 0.4.
const PALPATION: [&str; 9] = [
    "replay",
    "--params",
    "params/table2.toml",
    "--probe",
    "params/palpation.csv",
    "--tissue",
    "64,64",
    "--friction",
    "0.6,0.4",
];

/// A run that takes long says how far it is on stderr, every period (2 s; here 1 ms, by
/// `MCCS_PROGRESS_MS`), and its stdout is the same; a short run says nothing.
#[test]
fn long_runs_report_progress_on_stderr() {
    let runs: [&[&str]; 2] = [
        &[
            "replay",
            "--params",
            "params/table2.toml",
            "--probe",
            "params/stroke.csv",
        ],
        &[
            "patch",
            "--params",
            "params/table2.toml",
            "--indent",
            "1",
            "--duration",
            "0.5",
        ],
    ];
    for (args, command, total) in [(runs[0], "replay", "3.0"), (runs[1], "patch", "0.5")] {
        let quiet = mccs(args);
        assert!(quiet.status.success());
        // A short run prints no progress: only what it simulates, and its warnings.
        let said = String::from_utf8_lossy(&quiet.stderr);
        let setup = format!("mccs {command}: patch 5 × 5 nodes");
        assert!(
            said.lines().next().unwrap_or("").starts_with(&setup),
            "{said}"
        );
        assert!(!said.contains(" s simulated, "), "{said}");
        let told = Command::new(env!("CARGO_BIN_EXE_mccs"))
            .args(args)
            .current_dir(root())
            .env("MCCS_PROGRESS_MS", "1")
            .output()
            .expect("run mccs");
        assert!(told.status.success());
        assert_eq!(told.stdout, quiet.stdout, "{command}: the same output");
        let err = String::from_utf8_lossy(&told.stderr);
        let lines: Vec<&str> = err
            .lines()
            .filter(|l| !said.lines().any(|s| s == *l))
            .collect();
        let prefix = format!("mccs {command}: ");
        let of = format!(" of {total} s simulated, ");
        assert!(
            !lines.is_empty()
                && lines
                    .iter()
                    .all(|l| l.starts_with(&prefix) && l.contains(&of) && l.ends_with(" s so far")),
            "{command}: {err}"
        );
    }
}

/// A reader that closes stdout early (`mccs … | head -1`): the run stops with no line on
/// stderr and exit status 141, what a tool killed by `SIGPIPE` gives, never 0 (it used to
/// print `mccs: stdout: Broken pipe (os error 32)` and exit 2, as for bad input, and a
/// replay ran to its end first). Both writers: the CSV of `curve`, and `replay`'s rows
/// as they are simulated.
#[test]
fn a_closed_stdout_ends_the_run_quietly() {
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;
    let runs: [&[&str]; 2] = [&curve_table2("0", "0.9", "0.00001"), &PALPATION[..7]];
    for args in runs {
        let mut child = Command::new(env!("CARGO_BIN_EXE_mccs"))
            .args(args)
            .current_dir(root())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut first = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut first)
            .unwrap();
        assert!(first.contains(','), "{first}");
        // (The reader is dropped here: the pipe is closed with most rows unwritten.)
        let out = child.wait_with_output().unwrap();
        assert_eq!(out.status.code(), Some(141), "{}: {out:?}", args[0]);
        // No error line (a replay says what it simulates before its first row).
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.lines().all(|l| l.starts_with("mccs replay: tissue ")),
            "{err}"
        );
    }
}
