//! `mccs patch`: the indentation run, its arguments, and its integrators.

use super::*;

fn patch_rows(args: &[&str]) -> Vec<(f64, f64)> {
    let mut all = vec!["patch", "--params", "params/table2.toml"];
    all.extend_from_slice(args);
    let out = mccs_ok(&all);
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

/// The patch's spacing at its edges names `--spacing` (or the rate it would need) in
/// both backends and both commands, never another argument or the parameter file, and a
/// tiny spacing is written as given: a spacing below the fixed core's 1 mm springs
/// (once `--grid: topology: …` from `patch` and `PARAMS: topology: …` from `replay`),
/// and one so small that the twin's stable step is zero (once `--spring-damping: the
/// integrator needs damping`, with the damping at its default).
#[test]
fn tiny_spacings_name_the_spacing() {
    let patch = |extra: &[&str]| {
        let mut a = vec!["patch", "--params", "params/table2.toml"];
        a.extend_from_slice(extra);
        mccs(&a)
    };
    let replay = |extra: &[&str]| {
        let mut a = vec![
            "replay",
            "--params",
            "params/table2.toml",
            "--probe",
            "params/stroke.csv",
        ];
        a.extend_from_slice(extra);
        mccs(&a)
    };
    let fixed_short = ["--spacing", "0.5", "--backend", "fixed"];
    let needle = "--spacing: must be ≥ 1 mm with --backend fixed";
    assert_one_line_error(
        &patch(&[&fixed_short[..], &["--indent", "0.2"]].concat()),
        &[needle],
    );
    assert_one_line_error(&replay(&fixed_short), &[needle]);
    let zero_step = ["--spacing", "1e-300", "--backend", "reference"];
    for out in [
        patch(&[&zero_step[..], &["--indent", "0"]].concat()),
        replay(&zero_step),
    ] {
        assert_one_line_error(
            &out,
            &[
                "--rate: this spring needs 4294967295 or more substeps",
                "--spacing",
            ],
        );
    }
    assert_one_line_error(
        &patch(&[&zero_step[..], &["--indent", "0.5"]].concat()),
        &["--indent: must be 0 … 1e-300 mm (the --spacing)"],
    );
    // A rate too low for the stable step: raise it (the advice once said to lower it).
    let slow = patch(&["--indent", "0.5", "--rate", "5", "--backend", "fixed"]);
    assert_one_line_error(
        &slow,
        &[
            "--rate: this spring needs",
            "at 5 Hz (at most 64): raise the rate",
        ],
    );
    // Small but stable: the twin runs it at its substeps, or says how many it needs.
    let out = patch(&["--spacing", "0.5", "--indent", "0.1", "--duration", "0.01"]);
    assert!(out.status.success(), "{out:?}");
}

/// `patch` takes the patch's dynamics as `replay` does (its substeps message names
/// `--node-mass`), and they change the run: a heavier node lags the ramp.
#[test]
fn patch_takes_the_dynamics_options_replay_takes() {
    let run = |extra: &[&str]| {
        let mut a = vec![
            "patch",
            "--params",
            "params/table2.toml",
            "--indent",
            "0.5",
            "--duration",
            "0.01",
            "--backend",
            "fixed",
        ];
        a.extend_from_slice(extra);
        let out = mccs(&a);
        assert!(out.status.success(), "{out:?}");
        String::from_utf8(out.stdout).unwrap()
    };
    let light = run(&[]);
    let heavy = run(&["--node-mass", "20"]);
    let third = |s: &str| s.lines().nth(3).unwrap().to_string();
    assert_ne!(third(&light), third(&heavy), "--node-mass changed nothing");
    assert_ne!(
        run(&["--spring-damping", "5"]),
        light,
        "--spring-damping changed nothing"
    );
    assert_one_line_error(
        &mccs(&[
            "patch",
            "--params",
            "params/table2.toml",
            "--indent",
            "0.5",
            "--node-mass",
            "0",
        ]),
        &["--node-mass: must be > 0 g"],
    );
}

/// The example of docs/accuracy.md: a 0.8 mm indentation of the default patch, in both
/// backends, its last reaction printed for the doc (`PATCHRUN`) and the two within 1e-6.
#[test]
fn the_docs_indentation_example() {
    let last = |backend: &str| -> f64 {
        let out = mccs_ok(&[
            "patch",
            "--params",
            "params/table2.toml",
            "--indent",
            "0.8",
            "--backend",
            backend,
        ]);
        let text = String::from_utf8(out.stdout).unwrap();
        let f = text.lines().last().unwrap().split(',').nth(1).unwrap();
        println!("PATCHRUN backend={backend} final_n={f}");
        f.parse().unwrap()
    };
    let (fixed, reference) = (last("fixed"), last("reference"));
    assert!(
        (fixed - reference).abs() < 1e-6 * reference,
        "{fixed} against {reference}"
    );
}
