//! `mccs table`: its measured bound, its refusals and what they name.

use super::*;

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
        let out = mccs_ok(&["table", "--params", f.to_str().unwrap(), "--knots", "129"]);
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
    // knows meets the bound (docs/table.md, "The grid below a preload's kink near `F_C`").
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
                "a narrower domain meets it: mccs table --to ",
                " (measured: force ",
                " or mccs table --from ",
                "--accept-error",
            ],
        );
        let err = String::from_utf8_lossy(&out.stderr);
        let to = word_after(&err, "meets it: mccs table --to ");
        let measured = err.split("(measured: ").nth(1).unwrap();
        let measured = measured.split(") or mccs table --from").next().unwrap();
        assert!(to.parse::<f64>().unwrap() < 0.95, "{err}");
        let from = word_after(&err, " or mccs table --from ");
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
            "a narrower domain meets it: mccs table --to 0.",
            " or mccs table --from 0.",
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
    // The fixed-point paths refuse it with the same line (at their knots), and run it
    // under --accept-error, with a warning.
    let curve = |extra: &[&str]| {
        let args = [
            &[
                "curve", "--params", path, "--from", "0", "--to", "0.5", "--step", "0.25",
            ][..],
            &["--backend", "fixed"],
            extra,
        ]
        .concat();
        mccs(&args)
    };
    let table65 = mccs(&["table", "--params", path]);
    let out = curve(&[]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(out.stderr, table65.stderr);
    let out = curve(&["--accept-error"]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("misses the bound"));
    assert!(String::from_utf8_lossy(&out.stderr).contains("used anyway (--accept-error)"));
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
            "a narrower domain meets it: mccs table --from ",
            "--accept-error",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    let from = word_after(&err, "meets it: mccs table --from ");
    assert!(from.parse::<f64>().unwrap() > -0.5, "{err}");
    let ok = mccs(&["table", "--params", path, "--knots", "129", "--from", from]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
}

/// `--out` is checked before the table is built and measured, as `mccs fit` checks its
/// outputs: a folder, a missing folder or a read-only file is one line naming `--out`,
/// with no measurement on stderr (once the table was built, its measurement printed,
/// and the write failed after it as `PATH: cannot write: …`). A good path gets the table.
#[test]
fn an_unwritable_out_is_refused_before_the_table_is_built() {
    let dir = std::env::temp_dir().join(format!("mccs-table-out-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let read_only = dir.join("read-only.rs");
    std::fs::write(&read_only, "").unwrap();
    let mut perm = std::fs::metadata(&read_only).unwrap().permissions();
    perm.set_readonly(true);
    std::fs::set_permissions(&read_only, perm).unwrap();
    let dir_str = dir.to_str().unwrap();
    for (path, needle) in [
        (dir_str.to_string(), "is a folder"),
        (
            format!("{dir_str}/missing/t.rs"),
            "its folder does not exist",
        ),
        (read_only.to_str().unwrap().to_string(), "is read-only"),
    ] {
        let out = mccs(&["table", "--params", "params/table2.toml", "--out", &path]);
        assert_one_line_error(&out, &["--out", &path, needle]);
    }
    let good = dir.join("t.rs");
    let out = mccs_ok(&[
        "table",
        "--params",
        "params/table2.toml",
        "--out",
        good.to_str().unwrap(),
    ]);
    assert!(out.stdout.is_empty());
    let src = std::fs::read_to_string(&good).unwrap();
    assert!(src.starts_with("// Generated by `mccs table"), "{src}");
    std::fs::remove_dir_all(&dir).unwrap_or_else(|_| {
        let mut perm = std::fs::metadata(&read_only).unwrap().permissions();
        #[allow(clippy::permissions_set_readonly_false)]
        perm.set_readonly(false);
        std::fs::set_permissions(&read_only, perm).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    });
}
