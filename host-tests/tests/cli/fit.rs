//! `mccs fit`: one line per model, usable parameters, and the data's errors.

use super::*;

/// Per model a `FIT` line (its metrics) and a `PARAMS` line (what it fitted, by the
/// parameter file's keys); the fitted file feeds `mccs table`.
#[test]
fn fit_prints_one_line_per_model_and_writes_usable_parameters() {
    let dir = std::env::temp_dir().join(format!("mccs-fit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (toml, svg) = (dir.join("fitted.toml"), dir.join("fit.svg"));
    let out = mccs_ok(&[
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
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 6);
    for (pair, model) in lines.chunks(2).zip(["ms", "mcs", "mccs"]) {
        let (fit, params) = (pair[0], pair[1]);
        assert!(
            fit.starts_with(&format!("FIT model={model} mean_abs=")),
            "{fit}"
        );
        assert!(fit.contains(" max_abs=") && fit.contains(" mse="));
        assert!(
            params.starts_with(&format!("PARAMS model={model} ")),
            "{params}"
        );
    }
    // The MCCS parameters printed are the file's.
    let mccs_params = lines[5];
    let file = std::fs::read_to_string(&toml).unwrap();
    let fitted = mccs_host::paramfile::parse(&file, &toml).unwrap();
    for (key, value) in [
        ("cone.small_diameter", fitted.cone.small_diameter),
        ("cone.compressible_height", fitted.cone.compressible_height),
        ("cone.shear_modulus", fitted.cone.shear_modulus),
        ("linear.shear_modulus", fitted.linear.shear_modulus),
    ] {
        let printed: f64 = mccs_params
            .split_whitespace()
            .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('='))
            .unwrap_or_else(|| panic!("no {key}: {mccs_params}"))
            .parse()
            .unwrap();
        assert!(
            (printed - value).abs() <= 1e-6 * value,
            "{key}: {printed} {value}"
        );
    }
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    // The fitted file feeds `mccs table` directly.
    mccs_ok(&["table", "--params", toml.to_str().unwrap()]);
    let one = mccs(&["fit", "--data", "params/demo-data.csv", "--model", "mcs"]);
    assert_eq!(String::from_utf8(one.stdout).unwrap().lines().count(), 2);
}

/// What a fit's numbers do not say, each one warning line: a parameter on a bound the
/// fit holds it within (the shipped demo data put `D1` on `0.05 D2`, and MS's `C2` on
/// 1e-3), and a degenerate fit (linear data: the law's linear phase holds all but one
/// row). Data without those warn of nothing.
#[test]
fn fit_warns_of_a_bound_and_of_a_degenerate_fit() {
    let out = mccs_ok(&["fit", "--data", "params/demo-data.csv"]);
    let err = String::from_utf8_lossy(&out.stderr);
    for needle in [
        "mccs: warning: the mccs fit: cone.small_diameter sits on its lower bound (0.04, of 0.05 … 0.95 of D2): the data stop at 1 N, well below the cone's solid force F_C = ",
        "mccs: warning: the ms fit: c2 sits on its lower bound (0.001, of 1e-3 … 1e3)",
        "mccs: warning: the ms fit: degenerate: c3 = ",
        "scales a term under 1e-6 of the other's at every row: the fit dropped it",
    ] {
        assert!(err.contains(needle), "{err}");
    }
    let mut linear = String::from("strain,force_n\n");
    for i in 1..=40 {
        let f = i as f64 * 0.025;
        linear.push_str(&format!("{:.6},{f:.6}\n", f / 2.0));
    }
    let f = temp_file("linear.csv", &linear);
    let out = mccs_ok(&["fit", "--data", f.to_str().unwrap(), "--model", "mccs"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(
            "warning: the mccs fit: degenerate: 1 of the 40 rows lie past the law's linear phase"
        ),
        "{err}"
    );
    // Table 2's own law, noise free, loaded well into its nonlinear phase: no warning.
    let law = mccs_host::reference::Reference::new(&mccs::Params::TABLE2).unwrap();
    let mut clean = String::from("strain,force_n\n");
    for i in 1..=40 {
        let f = i as f64 * 0.05;
        clean.push_str(&format!("{:.9},{f:.9}\n", law.delta(f)));
    }
    let f = temp_file("clean.csv", &clean);
    let out = mccs_ok(&["fit", "--data", f.to_str().unwrap(), "--model", "mccs"]);
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The plot is SVG: a `--plot` that does not end in `.svg` is refused before anything is
/// fitted (it once wrote SVG into a `.png`).
#[test]
fn a_plot_is_svg_by_its_name() {
    for name in ["fit.png", "fit", "fit.pdf"] {
        let path = std::env::temp_dir().join(name);
        let out = mccs(&[
            "fit",
            "--data",
            "params/demo-data.csv",
            "--plot",
            path.to_str().unwrap(),
        ]);
        assert_one_line_error(&out, &["--plot", name, "SVG only: name it .svg"]);
    }
}

/// A bad header says what it read.
#[test]
fn fit_errors_name_the_file_and_row() {
    let header = temp_file("header.csv", "strain;force\n0.1;0.1\n");
    assert_usage_error(
        &mccs(&["fit", "--data", header.to_str().unwrap()]),
        &[
            "header.csv",
            "row 1",
            "must be `strain,force_n`, not `strain;force`",
        ],
    );
    let bad = temp_file(
        "bad.csv",
        "strain,force_n\n0.1,0.1\n0.2,0.2\n0.15,0.3\n0.4,0.4\n0.5,0.5\n",
    );
    assert_usage_error(
        &mccs(&["fit", "--data", bad.to_str().unwrap()]),
        &["bad.csv", "row 4", "strain"],
    );
    // An empty file (or only blank lines) says so, not that its header is ``.
    let empty = temp_file("empty.csv", " \n\n");
    assert_usage_error(
        &mccs(&["fit", "--data", empty.to_str().unwrap()]),
        &["empty.csv: empty file", "`strain,force_n`"],
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
    // A quoted field over two lines (a fuzzing run's find): its line break shown escaped,
    // the message one line.
    let quoted = temp_file("quoted.csv", "strain,force_n\n0.1,\"0.05\n0.1\"\n");
    assert_usage_error(
        &mccs(&["fit", "--data", quoted.to_str().unwrap()]),
        &[
            "quoted.csv",
            "row 2",
            r"force_n `0.05\n0.1` is not a number",
        ],
    );
}

/// A first row at (0, 0), the unloaded sample every compression test starts from, is
/// dropped with a note, the fit the same as without it; a zero strain elsewhere, a
/// force ≤ 0, a strain of 1 or more are refused naming the row; output paths are checked
/// before the fit; a large file is decimated.
#[test]
fn fit_rejects_what_the_models_cannot_take_and_checks_outputs_first() {
    let good = std::fs::read_to_string(root().join("params/demo-data.csv")).unwrap();
    let zero_row = good.replacen("strain,force_n\n", "strain,force_n\n0,0\n", 1);
    let f = temp_file("zero.csv", &zero_row);
    let out = mccs_ok(&["fit", "--data", f.to_str().unwrap(), "--model", "mccs"]);
    let without = mccs_ok(&["fit", "--data", "params/demo-data.csv", "--model", "mccs"]);
    assert_eq!(out.stdout, without.stdout);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.lines().next().unwrap().ends_with(
            "zero.csv: row 2: (0, 0), the unloaded sample: dropped (every model passes through it)"
        ),
        "{err}"
    );
    let zero_strain = good.replacen("strain,force_n\n", "strain,force_n\n0,0.001\n", 1);
    for (name, text, needle) in [
        (
            "zero-strain.csv",
            zero_strain.as_str(),
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
    let out = mccs_ok(&["fit", "--data", f.to_str().unwrap(), "--model", "mccs"]);
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

/// Data no MCCS parameters within the fixed point's ranges can fit (forces of 1e-300 N,
/// or up to 1e9 N): exit 2 and one line that names the file and the model, gives the
/// data's forces and the models that did fit, with nothing on stdout (once the models
/// fitted before it were printed, and the line said only "could not be fitted").
#[test]
fn a_model_that_cannot_be_fitted_is_one_line_naming_the_others() {
    let rows = |forces: [f64; 5]| {
        let mut s = String::from("strain,force_n\n");
        for (i, f) in forces.iter().enumerate() {
            s.push_str(&format!("0.{},{f:e}\n", i + 1));
        }
        s
    };
    for (name, forces, range) in [
        (
            "tiny-forces.csv",
            [1e-300, 2e-300, 3e-300, 4e-300, 5e-300],
            "forces 1e-300 … 5e-300 N",
        ),
        (
            "huge-forces.csv",
            [1.0, 2.0, 1e5, 1.00001e5, 1e9],
            "forces 1 … 1e9 N",
        ),
    ] {
        let f = temp_file(name, &rows(forces));
        let path = f.to_str().unwrap();
        assert_one_line_error(
            &mccs(&["fit", "--data", path]),
            &[
                name,
                "the mccs model could not be fitted",
                "within the model's ranges",
                range,
                "the ms and mcs models fitted (--model ms, --model mcs)",
            ],
        );
        // The one model alone: the same line without the others.
        let out = mccs(&["fit", "--data", path, "--model", "mccs"]);
        assert_one_line_error(&out, &[name, "the mccs model could not be fitted"]);
        assert!(!String::from_utf8_lossy(&out.stderr).contains("fitted ("));
        // The models that fit print their line.
        let ms = mccs_ok(&["fit", "--data", path, "--model", "ms"]);
        assert!(String::from_utf8_lossy(&ms.stdout).starts_with("FIT model=ms "));
    }
}
