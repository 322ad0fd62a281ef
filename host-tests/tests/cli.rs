//! The `mccs` binary as a user runs it: output format, and one-line errors with exit 2.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn mccs(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mccs"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("run mccs")
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn temp_file(name: &str, text: &str) -> PathBuf {
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
}

/// Asserts exit 2, empty stdout, and exactly one stderr line containing every `needle` —
/// for a mistake found past the argument parser (no usage hint).
fn assert_one_line_error(out: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert!(out.stdout.is_empty(), "stdout not empty");
    assert_eq!(err.lines().count(), 1, "{err}");
    for n in needles {
        assert!(err.contains(n), "{err:?} lacks {n:?}");
    }
}

const TABLE2: &str = include_str!("../../params/table2.toml");

#[test]
fn curve_prints_the_reference_csv() {
    let out = mccs(&[
        "curve",
        "--params",
        "params/table2.toml",
        "--from",
        "-0.2",
        "--to",
        "1.3",
        "--step",
        "0.1",
    ]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("strain,force_n,stiffness_n"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 16);
    assert_eq!(rows[0][0], -0.2);
    assert_eq!(rows[15][0], 1.3);
    let r = mccs_host::reference::Reference::new(&mccs::Params::TABLE2).unwrap();
    // The reference's values to their last bits: within 2 ULP, because `f64::powi` is not
    // correctly rounded and its result depends on how the compiler inlined it (a
    // release build of this test and of the CLI differ by one ULP).
    let close = |a: f64, b: f64| (a - b).abs() <= 2.0 * f64::EPSILON * b.abs();
    for row in &rows {
        assert!(close(row[1], r.force(row[0])), "{row:?}");
        assert!(close(row[2], r.stiffness(row[0])), "{row:?}");
    }
    assert!(rows.windows(2).all(|w| w[1][1] > w[0][1]));
}

#[test]
fn curve_fixed_backend_tracks_reference() {
    let args = |b| {
        mccs(&[
            "curve",
            "--params",
            "params/table2.toml",
            "--from",
            "-0.5",
            "--to",
            "0.95",
            "--step",
            "0.01",
            "--backend",
            b,
        ])
    };
    let (a, b) = (args("reference"), args("fixed"));
    assert!(a.status.success() && b.status.success());
    let (a, b) = (
        String::from_utf8(a.stdout).unwrap(),
        String::from_utf8(b.stdout).unwrap(),
    );
    assert_eq!(a.lines().count(), b.lines().count());
    for (x, y) in a.lines().zip(b.lines()).skip(1) {
        let x: Vec<f64> = x.split(',').map(|v| v.parse().unwrap()).collect();
        let y: Vec<f64> = y.split(',').map(|v| v.parse().unwrap()).collect();
        assert_eq!(x[0], y[0]);
        assert!((x[1] - y[1]).abs() < 1e-4, "{x:?} vs {y:?}");
    }
}

#[test]
fn bad_files_name_file_and_key() {
    let missing = temp_file("missing.toml", &TABLE2.replace("active_coils = 5.0\n", ""));
    let out = mccs(&[
        "curve",
        "--params",
        missing.to_str().unwrap(),
        "--from",
        "0",
        "--to",
        "1",
        "--step",
        "0.1",
    ]);
    assert_usage_error(&out, &["missing.toml", "cone.active_coils", "missing"]);

    let neg = temp_file(
        "neg.toml",
        &TABLE2.replace("mean_diameter = 0.2", "mean_diameter = -0.2"),
    );
    let out = mccs(&[
        "curve",
        "--params",
        neg.to_str().unwrap(),
        "--from",
        "0",
        "--to",
        "1",
        "--step",
        "0.1",
    ]);
    assert_usage_error(&out, &["neg.toml", "linear.mean_diameter", "> 0"]);

    let nan = temp_file(
        "nan.toml",
        &TABLE2.replace("shear_modulus = 1.8472e5", "shear_modulus = nan"),
    );
    let out = mccs(&[
        "curve",
        "--params",
        nan.to_str().unwrap(),
        "--from",
        "0",
        "--to",
        "1",
        "--step",
        "0.1",
    ]);
    assert_usage_error(&out, &["nan.toml", "cone.shear_modulus", "finite"]);

    let order = temp_file(
        "order.toml",
        &TABLE2.replace("large_diameter = 0.8", "large_diameter = 0.3"),
    );
    let out = mccs(&[
        "curve",
        "--params",
        order.to_str().unwrap(),
        "--from",
        "0",
        "--to",
        "1",
        "--step",
        "0.1",
    ]);
    assert_usage_error(&out, &["order.toml", "cone.large_diameter"]);

    let text = temp_file(
        "text.toml",
        &TABLE2.replace("active_coils = 10.0", "active_coils = \"ten\""),
    );
    let out = mccs(&[
        "curve",
        "--params",
        text.to_str().unwrap(),
        "--from",
        "0",
        "--to",
        "1",
        "--step",
        "0.1",
    ]);
    assert_usage_error(&out, &["text.toml", "linear.active_coils", "number"]);

    let typo = temp_file(
        "typo.toml",
        &TABLE2.replace("wire_diameter = 0.1", "wire_diametr = 0.1"),
    );
    let out = mccs(&[
        "curve",
        "--params",
        typo.to_str().unwrap(),
        "--from",
        "0",
        "--to",
        "1",
        "--step",
        "0.1",
    ]);
    assert_usage_error(&out, &["typo.toml", "cone.wire_diametr", "unknown"]);

    let bad = temp_file("bad.toml", "[cone\nwire_diameter = 1");
    let out = mccs(&[
        "curve",
        "--params",
        bad.to_str().unwrap(),
        "--from",
        "0",
        "--to",
        "1",
        "--step",
        "0.1",
    ]);
    assert_usage_error(&out, &["bad.toml", "line 1", "TOML"]);

    let out = mccs(&[
        "curve",
        "--params",
        "no/such.toml",
        "--from",
        "0",
        "--to",
        "1",
        "--step",
        "0.1",
    ]);
    assert_usage_error(&out, &["no/such.toml", "cannot read"]);

    let pre = temp_file("pre.toml", &format!("{TABLE2}preload = 11.0\n"));
    let out = mccs(&[
        "curve",
        "--params",
        pre.to_str().unwrap(),
        "--from",
        "0",
        "--to",
        "1",
        "--step",
        "0.1",
    ]);
    assert_usage_error(&out, &["pre.toml", "linear.preload"]);
}

#[test]
fn bad_ranges_name_the_argument() {
    let base = ["curve", "--params", "params/table2.toml"];
    for (extra, needle) in [
        (["--from", "0", "--to", "1", "--step", "0"], "--step"),
        (["--from", "0", "--to", "1", "--step", "-0.1"], "--step"),
        (["--from", "1", "--to", "0", "--step", "0.1"], "--to"),
        (["--from", "nan", "--to", "1", "--step", "0.1"], "--from"),
        (["--from", "0", "--to", "inf", "--step", "0.1"], "--to"),
        (["--from", "0", "--to", "1", "--step", "1e-12"], "--step"),
        (["--from", "0", "--to", "x", "--step", "0.1"], "--to"),
    ] {
        let args: Vec<&str> = base.iter().chain(extra.iter()).copied().collect();
        assert_usage_error(&mccs(&args), &[needle]);
    }
    assert_usage_error(&mccs(&["curve", "--from", "0"]), &["--params"]);
    assert_usage_error(&mccs(&["frobnicate"]), &["frobnicate"]);
}

fn patch_rows(args: &[&str]) -> Vec<(f64, f64)> {
    let mut all = vec!["patch", "--params", "params/table2.toml"];
    all.extend_from_slice(args);
    let out = mccs(&all);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("time_s,reaction_n"));
    lines
        .map(|l| {
            let (t, r) = l.split_once(',').unwrap();
            (t.parse().unwrap(), r.parse().unwrap())
        })
        .collect()
}

#[test]
fn patch_defaults_end_settled() {
    let base = ["--grid", "5", "--spacing", "2.5", "--indent", "0.8"];
    let run = |backend: &str, extra: &[&str]| {
        let mut a: Vec<&str> = base.to_vec();
        a.extend_from_slice(&["--backend", backend]);
        a.extend_from_slice(extra);
        patch_rows(&a)
    };
    let short = run("reference", &[]);
    assert_eq!(short.len(), 1000);
    assert_eq!(short[0].0, 0.001);
    assert_eq!(short[999].0, 1.0);
    // The ramp: the reaction grows over the first half.
    assert!(short[100].1 < short[400].1);
    let long = run("reference", &["--duration", "4"]);
    let settled = long.last().unwrap().1;
    let last = short.last().unwrap().1;
    assert!(
        (last - settled).abs() <= 1e-4 * settled,
        "{last} vs {settled}"
    );
    let fixed = run("fixed", &[]);
    let f = fixed.last().unwrap().1;
    assert!((f - settled).abs() <= 5e-3 * settled, "{f} vs {settled}");
}

#[test]
fn patch_errors_name_the_argument() {
    let base = [
        "patch",
        "--params",
        "params/table2.toml",
        "--backend",
        "fixed",
    ];
    for (extra, needle) in [
        (
            ["--grid", "2", "--spacing", "2.5", "--indent", "0.8"],
            "--grid",
        ),
        (
            ["--grid", "13", "--spacing", "2.5", "--indent", "0.8"],
            "--grid",
        ),
        (
            ["--grid", "5", "--spacing", "0", "--indent", "0.8"],
            "--spacing",
        ),
        (
            ["--grid", "5", "--spacing", "nan", "--indent", "0.8"],
            "--spacing",
        ),
        (
            ["--grid", "5", "--spacing", "2.5", "--indent", "-1"],
            "--indent",
        ),
        (
            ["--grid", "5", "--spacing", "2.5", "--indent", "9"],
            "--indent: must be 0 … 2.5 mm",
        ),
    ] {
        let args: Vec<&str> = base.iter().chain(extra.iter()).copied().collect();
        assert_usage_error(&mccs(&args), &[needle]);
    }
    let ok = ["--grid", "5", "--spacing", "2.5", "--indent", "0.8"];
    for (extra, needle) in [
        (["--rate", "0"], "--rate"),
        (["--rate", "1.5"], "--rate"),
        (["--duration", "0"], "--duration"),
        (["--duration", "100"], "--duration"),
    ] {
        let args: Vec<&str> = base
            .iter()
            .chain(ok.iter())
            .chain(extra.iter())
            .copied()
            .collect();
        assert_usage_error(&mccs(&args), &[needle]);
    }
    // The patch has defaults (N = 5, 2.5 mm, the reference backend); the depth has none.
    assert_usage_error(
        &mccs(&["patch", "--params", "params/table2.toml", "--grid", "5"]),
        &["--indent"],
    );
    // --arith is for the fixed backend only.
    assert_usage_error(
        &mccs(&[
            "patch",
            "--params",
            "params/table2.toml",
            "--indent",
            "1",
            "--arith",
            "narrow",
        ]),
        &["--arith"],
    );
}

/// The defect 9: with the default domain (no --from/--to given), a table error
/// named `--to`. It names the parameter file now, in every subcommand that has no domain
/// arguments.
#[test]
fn table_errors_without_domain_arguments_name_the_file() {
    // A stiff series spring with a preload near the cone's solid force: linear up to a
    // strain beyond 0.95.
    let f = temp_file(
        "late-kink.toml",
        "[cone]\nwire_diameter = 0.1\nsmall_diameter = 0.3\nlarge_diameter = 0.8\nactive_coils = 5.0\ncompressible_height = 3.0\nshear_modulus = 1.8472e5\n[linear]\nwire_diameter = 0.068\nmean_diameter = 0.2\nactive_coils = 10.0\nshear_modulus = 4.9151e5\n",
    );
    let path = f.to_str().unwrap();
    for args in [
        vec![
            "patch",
            "--params",
            path,
            "--indent",
            "1",
            "--backend",
            "fixed",
        ],
        vec![
            "curve",
            "--params",
            path,
            "--from",
            "0",
            "--to",
            "1",
            "--step",
            "0.5",
            "--backend",
            "fixed",
        ],
    ] {
        let out = mccs(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("late-kink.toml"), "{args:?}: {err}");
        assert!(
            !err.contains("--to") && !err.contains("--from"),
            "{args:?}: {err}"
        );
        assert_eq!(err.lines().count(), 1);
    }
}

/// `mccs table` states the table's measured error in its header and on stderr, and
/// refuses a table over the product's bound with one line (exit 2) naming the file, what
/// the table reaches and what to change; `--accept-error` emits it, marked.
#[test]
fn table_states_its_measured_bound_and_refuses_what_misses_it() {
    let out = mccs(&["table", "--params", "params/table2.toml"]);
    assert!(out.status.success());
    let src = String::from_utf8(out.stdout).unwrap();
    let second = src.lines().nth(1).unwrap();
    assert!(
        second.starts_with(
            "// Accuracy, measured against the f64 law over [-0.5, 0.95]: force error "
        ) && second.ends_with("within the product's bound (force 2e-5, stiffness 1e-3)."),
        "{second}"
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with("mccs table: measured against the f64 law"),
        "{err}"
    );
    // Table 2 with a cone 10× softer against a series spring 2000 times stiffer than it
    // (issue 16's spring): refused before the graded corner, now within the bound, and
    // the header says where the corner is.
    let stiff_series = TABLE2
        .replace("shear_modulus = 1.8472e5", "shear_modulus = 1.8472e4")
        .replace("shear_modulus = 4.9151e5", "shear_modulus = 1.386e7");
    assert_ne!(stiff_series, TABLE2);
    // A near-cylindrical cone against a soft series spring preloaded to 0.9 F_C (a random
    // spring of `table_bound/`): the graded corner takes the smooth part above the
    // preload's kink, up to the domain's end (the solid point lies far past it).
    let near_solid = "[cone]\nwire_diameter = 0.0630138115362447\nsmall_diameter = 0.3519773312502775\nlarge_diameter = 0.4222780483510128\nactive_coils = 1.6042596549155683\ncompressible_height = 0.35952497526300037\nshear_modulus = 248660.54999980563\n\n[linear]\nwire_diameter = 0.19740203691142258\nmean_diameter = 0.1616103995851277\nactive_coils = 7.837305368448284\nshear_modulus = 10.711463844770453\npreload = 2.2667975385647203\n";
    // A preload on the cone's steep rise toward its own solid point (spring 261 of
    // table_bound/): refused before the lower corner, now within the bound, and the
    // header says that the corner lies under the grid.
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let steep = std::fs::read_to_string(format!("{root}/params/steep-kink.toml")).unwrap();
    // A stiff series spring whose solid point lies 8e-5 strain short of the domain's end
    // (spring 43,342 of table_bound/'s long draw): its corner has twelve octaves.
    let deep = "[cone]\nwire_diameter = 0.08841261262983599\nsmall_diameter = 0.8856937931006725\nlarge_diameter = 2.1354017962062777\nactive_coils = 1.7330631953425195\ncompressible_height = 0.9491764266538272\nshear_modulus = 75368.21771890546\n\n[linear]\nwire_diameter = 0.021732733900039335\nmean_diameter = 0.2840336966862483\nactive_coils = 3.353250298619566\nshear_modulus = 1566611236.3573682\n";
    for (name, params, layout) in [
        (
            "stiff-series.toml",
            stiff_series.as_str(),
            &["then 32 graded toward the solid point"][..],
        ),
        (
            "near-solid.toml",
            near_solid,
            &["then 32 graded toward the domain's end"],
        ),
        (
            "deep-corner.toml",
            deep,
            &[
                "// Layout: 80 segments uniform over [",
                "then 48 graded toward the solid point",
            ],
        ),
        (
            "steep-kink.toml",
            steep.as_str(),
            &[
                "// Layout: 32 segments graded toward the preload's kink over [",
                "), then 96 uniform over [",
            ],
        ),
    ] {
        let f = temp_file(name, params);
        let out = mccs(&["table", "--params", f.to_str().unwrap(), "--knots", "129"]);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let src = String::from_utf8(out.stdout).unwrap();
        let lines: Vec<&str> = src.lines().collect();
        assert!(
            lines[1].ends_with("within the product's bound (force 2e-5, stiffness 1e-3).")
                && layout.iter().all(|l| lines[3].contains(l))
                && lines[3].starts_with("// Layout: "),
            "{name}: {src}"
        );
    }
    // With 33 knots the stiff series spring misses the bound, and the refusal names the
    // fewest knots it measured to meet it over the same domain (65, not 129).
    let f = temp_file("stiff-series.toml", &stiff_series);
    let out = mccs(&["table", "--params", f.to_str().unwrap(), "--knots", "33"]);
    assert_one_line_error(
        &out,
        &[
            "stiff-series.toml",
            "the 33-knot table misses the bound",
            "more knots meet it: --knots 65 (measured: force ",
            "of F(0.95)",
            "--accept-error",
        ],
    );
    let out = mccs(&["table", "--params", f.to_str().unwrap(), "--knots", "65"]);
    assert!(out.status.success());
    // Table 2 with its preload at 15 F_T (0.79 F_C), its slope kink Δ(P) on the cone's
    // steep rise toward its own solid point, far above Δ(F_T): no placement the builder
    // knows meets the bound (docs/accuracy.md, "The grid below a preload's kink").
    let kinked = TABLE2.replace(
        "shear_modulus = 4.9151e5",
        "shear_modulus = 4.9151e5\npreload = 8.1175",
    );
    assert_ne!(kinked, TABLE2);
    let f = temp_file("kinked.toml", &kinked);
    let path = f.to_str().unwrap();
    // The refusal names a remedy it built and measured: 129 knots do not meet the bound
    // either, a lower `--to` does, and the command it names builds that table.
    for knots in ["65", "129"] {
        let out = mccs(&["table", "--params", path, "--knots", knots]);
        assert_one_line_error(
            &out,
            &[
                "kinked.toml",
                "misses the bound",
                "k_p/k = 7.14e0",
                "a narrower domain meets it: --to ",
                " (measured: force ",
                " or --from ",
                "--accept-error",
            ],
        );
        let err = String::from_utf8_lossy(&out.stderr);
        let to = word_after(&err, "meets it: --to ");
        let measured = err.split("(measured: ").nth(1).unwrap();
        let measured = measured.split(") or --from").next().unwrap();
        assert!(to.parse::<f64>().unwrap() < 0.95, "{err}");
        let from = word_after(&err, " or --from ");
        assert!(from.parse::<f64>().unwrap() > -0.5, "{err}");
        let ok = mccs(&["table", "--params", path, "--knots", knots, "--from", from]);
        assert!(
            ok.status.success(),
            "{}",
            String::from_utf8_lossy(&ok.stderr)
        );
        let ok = mccs(&["table", "--params", path, "--knots", knots, "--to", to]);
        assert!(
            ok.status.success(),
            "{}",
            String::from_utf8_lossy(&ok.stderr)
        );
        // The same figures (`force 4.1e-6 of F(0.587), stiffness 1.7e-4`).
        let emitted = String::from_utf8_lossy(&ok.stderr);
        let (force, stiffness) = measured.split_once(", stiffness ").unwrap();
        let force = force.trim_start_matches("force ");
        assert!(
            emitted.contains(&format!(
                "force error {force}, stiffness error {stiffness} "
            )),
            "{err} / {emitted}"
        );
    }
    // A domain reaching far past where the law bends: the search steps across the bend,
    // not across the domain (sixths of [-100, 100] would step over it).
    let out = mccs(&[
        "table", "--params", path, "--knots", "129", "--from", "-100", "--to", "100",
    ]);
    assert_one_line_error(
        &out,
        &[
            "kinked.toml",
            "a narrower domain meets it: --to 0.",
            " or --from 0.",
        ],
    );
    // A spring 1,000 times weaker than Table 2: half an LSB of the output formats is over
    // the bound, and the refusal says that no knot count or domain helps.
    let weak = TABLE2
        .replace("shear_modulus = 1.8472e5", "shear_modulus = 1.8472e2")
        .replace("shear_modulus = 4.9151e5", "shear_modulus = 4.9151e2");
    let weak_file = temp_file("weak.toml", &weak);
    let out = mccs(&[
        "table",
        "--params",
        weak_file.to_str().unwrap(),
        "--knots",
        "129",
    ]);
    assert_one_line_error(
        &out,
        &[
            "weak.toml",
            "misses the bound",
            "the fixed-point formats cannot hold this spring",
            "no knot count or domain meets it",
            "--accept-error",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !err.contains("more knots") && !err.contains("narrower"),
        "{err}"
    );
    let out = mccs(&[
        "table",
        "--params",
        path,
        "--knots",
        "129",
        "--accept-error",
    ]);
    assert!(out.status.success());
    let src = String::from_utf8(out.stdout).unwrap();
    assert!(
        src.lines()
            .nth(1)
            .unwrap()
            .contains("OVER the product's bound"),
        "{src}"
    );
    // The solvers run it, with a warning.
    let out = mccs(&[
        "curve",
        "--params",
        path,
        "--from",
        "0",
        "--to",
        "0.5",
        "--step",
        "0.25",
        "--backend",
        "fixed",
    ]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("misses the accuracy bound"));
}

/// The word after `marker` in `text` (an option's value in a refusal's advice).
fn word_after<'a>(text: &'a str, marker: &str) -> &'a str {
    text.split(marker)
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .unwrap_or_else(|| panic!("no {marker:?} in {text}"))
}

/// A large spring (spring 3,375 of table_bound/'s long draw: 808 N at `F(0.95)`) whose
/// tension line leaves the force format, ±2048 N, inside the default domain (−2066 N at
/// −0.5): the table saturates there, and the refusal names the narrower domain that
/// meets the bound, whose command builds it.
#[test]
fn a_large_springs_refusal_names_a_narrower_domain() {
    let big = "[cone]\nwire_diameter = 0.17501070207013303\nsmall_diameter = 0.09615100550108081\nlarge_diameter = 0.19637874923178744\nactive_coils = 2.778251175114531\ncompressible_height = 0.3673528334865556\nshear_modulus = 342260.1536697008\n\n[linear]\nwire_diameter = 0.1110636377590376\nmean_diameter = 0.16621659605281017\nactive_coils = 10.998570469449042\nshear_modulus = 376093.43190201226\n";
    let f = temp_file("big.toml", big);
    let path = f.to_str().unwrap();
    let out = mccs(&["table", "--params", path, "--knots", "129"]);
    assert_one_line_error(
        &out,
        &[
            "big.toml",
            "the 129-knot table misses the bound",
            "a narrower domain meets it: --from ",
            "--accept-error",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    let from = word_after(&err, "meets it: --from ");
    assert!(from.parse::<f64>().unwrap() > -0.5, "{err}");
    let ok = mccs(&["table", "--params", path, "--knots", "129", "--from", from]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
}
#[test]
fn fit_prints_one_line_per_model_and_writes_usable_parameters() {
    let dir = std::env::temp_dir().join(format!("mccs-fit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (toml, svg) = (dir.join("fitted.toml"), dir.join("fit.svg"));
    let out = mccs(&[
        "fit",
        "--data",
        "params/demo-data.csv",
        "--model",
        "all",
        "--out",
        toml.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 3);
    for (line, model) in lines.iter().zip(["ms", "mcs", "mccs"]) {
        assert!(
            line.starts_with(&format!("FIT model={model} mean_abs=")),
            "{line}"
        );
        assert!(line.contains(" max_abs=") && line.contains(" mse="));
    }
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    // The fitted file feeds `mccs table` directly.
    let out = mccs(&["table", "--params", toml.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let one = mccs(&["fit", "--data", "params/demo-data.csv", "--model", "mcs"]);
    assert_eq!(String::from_utf8(one.stdout).unwrap().lines().count(), 1);
}

#[test]
fn fit_errors_name_the_file_and_row() {
    let bad = temp_file(
        "bad.csv",
        "strain,force_n\n0.1,0.1\n0.2,0.2\n0.15,0.3\n0.4,0.4\n0.5,0.5\n",
    );
    assert_usage_error(
        &mccs(&["fit", "--data", bad.to_str().unwrap()]),
        &["bad.csv", "row 4", "strain"],
    );
    let short = temp_file("short.csv", "strain,force_n\n0.1,0.1\n");
    assert_usage_error(
        &mccs(&["fit", "--data", short.to_str().unwrap()]),
        &["short.csv", "at least 5"],
    );
    assert_usage_error(
        &mccs(&["fit", "--data", "params/demo-data.csv", "--model", "fem"]),
        &["--model"],
    );
    assert_usage_error(
        &mccs(&[
            "fit",
            "--data",
            "params/demo-data.csv",
            "--model",
            "ms",
            "--out",
            "x.toml",
        ]),
        &["--out"],
    );
    assert_usage_error(
        &mccs(&["fit", "--data", "no/such.csv"]),
        &["no/such.csv", "cannot read"],
    );
}

/// The defect 8: a (0, 0) row gave nonsense metrics with exit 0; output paths
/// were checked only after the fit; there was no size limit or decimation.
#[test]
fn fit_rejects_what_the_models_cannot_take_and_checks_outputs_first() {
    let good = std::fs::read_to_string(root().join("params/demo-data.csv")).unwrap();
    let zero_row = good.replacen("strain,force_n\n", "strain,force_n\n0,0\n", 1);
    for (name, text, needle) in [
        (
            "zero.csv",
            zero_row.as_str(),
            "row 2: strain 0 is outside (0, 1)",
        ),
        (
            "neg.csv",
            "strain,force_n\n0.1,-1\n0.2,1\n0.3,2\n0.4,3\n0.5,4\n",
            "row 2: force_n -1 must be > 0",
        ),
        (
            "one.csv",
            "strain,force_n\n0.1,1\n0.2,2\n0.3,3\n0.4,4\n1.5,5\n",
            "row 6: strain 1.5 is outside (0, 1)",
        ),
    ] {
        let f = temp_file(name, text);
        let out = mccs(&["fit", "--data", f.to_str().unwrap()]);
        assert_usage_error(&out, &[name, needle]);
    }
    // An unwritable output is refused before any fitting (no FIT line on stdout).
    let data = root().join("params/demo-data.csv");
    for (arg, path) in [("--out", "/nonexistent/dir/x.toml"), ("--plot", "/")] {
        let out = mccs(&["fit", "--data", data.to_str().unwrap(), arg, path]);
        assert_usage_error(&out, &[arg, path]);
    }
    // More rows than a fit runs on: decimated, said on stderr, the metrics on all rows.
    let mut big = String::from("strain,force_n\n");
    let law = mccs_host::reference::Reference::new(&mccs::Params::TABLE2).unwrap();
    for i in 1..=3000 {
        let f = i as f64 / 3000.0;
        big.push_str(&format!("{:.9},{f:.9}\n", law.delta(f)));
    }
    let f = temp_file("big.csv", &big);
    let out = mccs(&["fit", "--data", f.to_str().unwrap(), "--model", "mccs"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("3000 rows: fitting on 1000"), "{err}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let mean: f64 = stdout
        .split_whitespace()
        .find_map(|kv| kv.strip_prefix("mean_abs="))
        .unwrap()
        .parse()
        .unwrap();
    assert!(mean < 1e-6, "noise-free data fit exactly: {stdout}");
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

/// The palpation replayed on a 64 × 64 tissue with friction 0.6 / 0.4.
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

#[test]
fn replay_roams_a_tissue_with_friction() {
    let out = mccs(&PALPATION);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "stderr: {err}");
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some(
            "time_s,fx_n,fy_n,fz_n,proxy_x_mm,proxy_y_mm,proxy_z_mm,contact,slipping,window_shifts"
        )
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 7401);
    // Sliding +x at 10 mm/s (t = 1 … 3.5 s): slipping, the friction against the motion
    // at μ_k = 0.4 of the normal force (the rest normal is z on a flat tissue).
    for r in rows.iter().filter(|r| (1.0..3.5).contains(&r[0])) {
        assert_eq!(
            (r[7], r[8]),
            (1.0, 1.0),
            "t = {}: not a slipping contact",
            r[0]
        );
        let ratio = -r[1] / r[3];
        assert!(
            (ratio - 0.4).abs() < 0.4 * 0.02,
            "t = {}: ratio {ratio}",
            r[0]
        );
    }
    // 30 mm out and back across a 2.5 mm grid: the window moved at every node.
    let last = rows.last().unwrap();
    assert!(last[9] >= 20.0, "{} window shifts", last[9]);
    assert_eq!((last[1], last[2], last[3], last[7]), (0.0, 0.0, 0.0, 0.0));
}

#[test]
fn replay_roaming_errors_name_the_argument() {
    let base = [
        "replay",
        "--params",
        "params/table2.toml",
        "--probe",
        "params/palpation.csv",
    ];
    for (extra, needles) in [
        (
            &[
                "--backend",
                "fixed",
                "--tissue",
                "64,64",
                "--cap-radius",
                "2500",
            ][..],
            &["--cap-radius", "2000 mm"][..],
        ),
        (
            // A cap whose corner cell's diagonal is longer than the M0's arithmetic takes.
            &[
                "--backend",
                "fixed",
                "--arith",
                "narrow",
                "--tissue",
                "21,21",
                "--spacing",
                "10",
                "--cap-radius",
                "189",
            ][..],
            &["--cap-radius", "the arithmetic's longest"][..],
        ),
        (&["--tissue", "2,64"], &["--tissue", "3..=64"]),
        (&["--tissue", "64"], &["--tissue", "W,H"]),
        (&["--tissue", "64,x"], &["--tissue", "W,H"]),
        (
            &["--tissue", "64,64", "--friction", "0.3"],
            &["--friction", "MU_S,MU_K"],
        ),
        (
            &["--tissue", "64,64", "--friction", "3,1"],
            &["--friction", "[0, 2]"],
        ),
        (
            &["--friction", "0.3,0.2"],
            &["--friction", "only with --tissue"],
        ),
        (
            &["--probe-radius", "1"],
            &["--probe-radius", "only with --tissue"],
        ),
        (
            &["--tissue", "64,64", "--probe-radius", "2"],
            &["--probe-radius"],
        ),
        (
            &["--tissue", "64,64", "--probe-radius", "NaN"],
            &["--probe-radius"],
        ),
        (
            &["--tissue", "64,64", "--cap-radius", "10"],
            &["--cap-radius"],
        ),
        (&["--tissue", "8,8", "--grid", "9"], &["--grid"]),
        (
            &["--tissue", "64,64", "--spacing", "4"],
            &["--spacing", "100 mm"],
        ),
    ] {
        let args: Vec<&str> = base.iter().chain(extra).copied().collect();
        assert_usage_error(&mccs(&args), needles);
    }
}

#[test]
fn replay_roams_in_the_core_as_in_the_reference() {
    let run = |extra: &[&str]| -> Vec<Vec<f64>> {
        let mut args = PALPATION.to_vec();
        args.extend_from_slice(extra);
        let out = mccs(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "stderr: {err}");
        String::from_utf8(out.stdout)
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect()
    };
    // Flat, and over a cap (R = 200 mm: the path's 1 mm below the top is 0.44 … 1 mm
    // deep); and flat with the symplectic integrator option in both backends.
    for shape in [
        &[][..],
        &["--cap-radius", "200"][..],
        &["--integrator", "symplectic-damped"][..],
    ] {
        let reference = run(shape);
        for extra in [
            &["--backend", "fixed"][..],
            &["--backend", "fixed", "--arith", "narrow"],
        ] {
            let extra = [extra, shape].concat();
            let fixed = run(&extra);
            assert_eq!(fixed.len(), reference.len());
            for (f, r) in fixed.iter().zip(&reference) {
                let mag = (r[1] * r[1] + r[2] * r[2] + r[3] * r[3]).sqrt();
                let diff =
                    ((f[1] - r[1]).powi(2) + (f[2] - r[2]).powi(2) + (f[3] - r[3]).powi(2)).sqrt();
                assert!(
                    diff <= 0.02 + 0.02 * mag,
                    "{extra:?} t = {}: {f:?} against {r:?}",
                    r[0]
                );
                let proxy =
                    ((f[4] - r[4]).powi(2) + (f[5] - r[5]).powi(2) + (f[6] - r[6]).powi(2)).sqrt();
                assert!(
                    proxy <= 0.01,
                    "{extra:?} t = {}: the proxy is {proxy} mm off",
                    r[0]
                );
                assert_eq!(
                    (f[7], f[8], f[9]),
                    (r[7], r[8], r[9]),
                    "{extra:?} t = {}: contact, slip, shifts",
                    r[0]
                );
            }
        }
    }
}

/// `--integrator symplectic-damped` runs the option in either backend: the settled force
/// of an indentation is the paper's integrator's (the same equilibrium), and a name
/// that is not an integrator is a usage error naming the argument.
#[test]
fn patch_runs_either_integrator_to_the_same_settled_force() {
    let settled = |backend: &str, integrator: &str| -> f64 {
        let out = mccs(&[
            "patch",
            "--params",
            "params/table2.toml",
            "--indent",
            "1.2",
            "--backend",
            backend,
            "--integrator",
            integrator,
        ]);
        assert!(out.status.success(), "{backend} {integrator}: {out:?}");
        let text = String::from_utf8(out.stdout).unwrap();
        let last = text.lines().last().unwrap();
        last.split(',').nth(1).unwrap().parse().unwrap()
    };
    for backend in ["reference", "fixed"] {
        let paper = settled(backend, "improved-euler");
        let option = settled(backend, "symplectic-damped");
        assert!(
            (paper - option).abs() <= 1e-5 * paper,
            "{backend}: {paper} vs {option}"
        );
    }
    assert_usage_error(
        &mccs(&[
            "patch",
            "--params",
            "params/table2.toml",
            "--indent",
            "1",
            "--integrator",
            "heun",
        ]),
        &["--integrator"],
    );
}

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
        assert!(
            quiet.stderr.is_empty(),
            "{}",
            String::from_utf8_lossy(&quiet.stderr)
        );
        let told = Command::new(env!("CARGO_BIN_EXE_mccs"))
            .args(args)
            .current_dir(root())
            .env("MCCS_PROGRESS_MS", "1")
            .output()
            .expect("run mccs");
        assert!(told.status.success());
        assert_eq!(told.stdout, quiet.stdout, "{command}: the same output");
        let err = String::from_utf8_lossy(&told.stderr);
        let lines: Vec<&str> = err.lines().collect();
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
