//! `mccs fit`: one line per model, usable parameters, and the data's errors.

use super::*;

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
    mccs_ok(&["table", "--params", toml.to_str().unwrap()]);
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
