//! `mccs curve`: the reference's CSV, the fixed backend against it, and its ranges.

use super::*;

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

/// A negative number in scientific notation with a signed exponent is a value, as in any
/// other spelling (clap alone split `-1e-3` into short flags: `unexpected argument '-1'`),
/// and the same strains come out as from its decimal spelling; a stray one after a value
/// is still an error.
#[test]
fn negative_numbers_with_signed_exponents_are_values() {
    let run = |from: &str, step: &str| {
        String::from_utf8(mccs_ok(&curve_table2(from, "0.01", step)).stdout).unwrap()
    };
    let decimal = run("-0.01", "0.005");
    assert!(decimal.lines().nth(1).unwrap().starts_with("-0.01,"));
    for from in ["-1e-2", "-1E-2", "-10e-3", "-0.1e-1"] {
        assert_eq!(run(from, "5e-3"), decimal, "--from {from}");
    }
    // The `=` spelling, which clap always took, is unchanged.
    let out = mccs_ok(&[
        "curve",
        "--params",
        "params/table2.toml",
        "--from=-1e-2",
        "--to",
        "0.01",
        "--step",
        "0.005",
    ]);
    assert_eq!(String::from_utf8(out.stdout).unwrap(), decimal);
    assert_usage_error(
        &mccs(&[
            "curve",
            "--params",
            "params/table2.toml",
            "--from",
            "-1e-2",
            "-2e-2",
            "--to",
            "0.01",
            "--step",
            "0.005",
        ]),
        &["unexpected argument"],
    );
    // A pair whose first number is negative, named by its own check (was clap's
    // `unexpected argument '-1'`).
    assert_one_line_error(
        &mccs(&[&PALPATION[..7], &["--friction", "-1e-3,0"]].concat()),
        &["--friction: MU_S and MU_K must each be 0 to 2 (got -0.001,0)"],
    );
    // In the other subcommands' numbers too: a negative indentation, named.
    assert_one_line_error(
        &mccs(&[
            "patch",
            "--params",
            "params/table2.toml",
            "--indent",
            "-1e-9",
        ]),
        &["--indent: must be 0 … 2.5 mm"],
    );
}

/// The fixed backend off its table's domain: every strain above the domain (Table 2's
/// ends at 0.95, before its solid point 1.19) is counted in one warning, past the solid
/// point too, where the table's tangent is below the law's line of slope `k_p` (the
/// warning once stopped at the solid point and said nothing of the 4 % there); below the
/// domain, the law's own line, no warning. A strain outside the fixed point's range
/// (±128, Q24) is refused, naming the argument (it was held at ±128 and printed as
/// given, with the force of −128).
#[test]
fn fixed_curve_off_its_domain_warns_and_refuses_what_it_cannot_hold() {
    let curve = |from: &str, to: &str, step: &str| {
        mccs(&[&curve_table2(from, to, step)[..], &["--backend", "fixed"]].concat())
    };
    let above = curve("1.3", "1.5", "0.1");
    assert!(above.status.success());
    let err = String::from_utf8_lossy(&above.stderr);
    assert!(
        err.contains("warning: 3 strains lie above the fixed table's domain [-0.5, 0.95], which ends before the solid point 1.19"),
        "{err}"
    );
    let law = mccs_host::reference::Reference::new(&mccs::Params::TABLE2).unwrap();
    for r in numbers(&above) {
        // What the warning is about: the tangent, under the law by more than 1 %.
        assert!(r[1] < 0.99 * law.force(r[0]), "{r:?}");
    }
    let below = curve("-3", "-1", "0.5");
    assert!(below.status.success() && below.stderr.is_empty());
    for r in numbers(&below) {
        assert!(
            (r[1] - law.force(r[0])).abs() < 1e-5 * law.force(r[0]).abs(),
            "{r:?}"
        );
    }
    for (from, to, arg) in [
        ("-200", "0", "--from"),
        ("0", "128", "--to"),
        ("-128.5", "0", "--from"),
    ] {
        assert_one_line_error(&curve(from, to, "1"), &[arg, "-128 … 127.99999994 (Q24)"]);
    }
    // The reference takes the same strains: past them its force left f64 (`-inf` at
    // -1e308, the strain printed in 309 digits).
    for (from, to, arg) in [("-1e308", "-1e307", "--from"), ("0", "1e300", "--to")] {
        assert_one_line_error(
            &mccs(&curve_table2(from, to, "1e306")),
            &[arg, "-128 … 127.99999994 (Q24)"],
        );
    }
    let edge = curve("-128", "-127", "1");
    assert!(edge.status.success());
    assert_eq!(numbers(&edge).len(), 2);
}
