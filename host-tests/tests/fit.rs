//! Parameter identification and the model comparison (issue: fitting).

use mccs::{ForceTable64, Params, Strain};
use mccs_host::fit::{self, demo_data, fit, metrics, synthesize, Fitted, ModelKind};
use mccs_host::reference::Reference;
use std::path::Path;

fn forces() -> Vec<f64> {
    (1..=40).map(|i| i as f64 * 0.025).collect()
}

fn truths() -> [Fitted; 3] {
    [
        Fitted::Mccs(Params::TABLE2),
        Fitted::Mcs(Params::TABLE2.cone),
        Fitted::Ms {
            c1: 0.002,
            c2: 2.0,
            c3: 0.001,
        },
    ]
}

#[test]
fn shipped_demo_data_is_what_demo_data_generates() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../params/demo-data.csv");
    let committed = std::fs::read_to_string(&path).unwrap();
    assert_eq!(
        committed,
        fit::to_csv(&demo_data()),
        "regenerate params/demo-data.csv"
    );
    assert_eq!(fit::read_data(&path).unwrap().len(), 40);
}

#[test]
fn each_model_recovers_its_own_parameters_noise_free() {
    for truth in truths() {
        let data = synthesize(&truth, &forces(), 0.0, 1);
        let got = fit(truth.kind(), &data).unwrap();
        for (a, b) in truth.theta().iter().zip(got.model.theta()) {
            assert!(
                (a - b).abs() <= 1e-6 * a.abs().max(1.0),
                "{:?}: {a} vs {b}",
                truth.kind()
            );
        }
        assert!(got.metrics.max_abs < 1e-9);
    }
}

#[test]
fn with_one_percent_noise_the_fitted_curve_stays_close() {
    // Individual parameters are ill-conditioned under noise (several combinations fit a
    // loading curve this short almost equally well), so the tolerance is on the curve:
    // the fitted strain at every measured force within 1 % of the largest strain of the
    // noise-free curve, for five noise seeds.
    for truth in truths() {
        let e_max = truth.strain_at(1.0);
        for seed in 1..=5 {
            let data = synthesize(&truth, &forces(), 0.01, seed);
            let got = fit(truth.kind(), &data).unwrap();
            let worst = forces()
                .iter()
                .map(|&f| (got.model.strain_at(f) - truth.strain_at(f)).abs())
                .fold(0.0, f64::max);
            println!(
                "{:?} seed {seed}: worst curve error {:.2e} = {:.2} % of e_max",
                truth.kind(),
                worst,
                100.0 * worst / e_max
            );
            assert!(
                worst <= 0.01 * e_max,
                "{:?} seed {seed}: {worst}",
                truth.kind()
            );
        }
    }
}

#[test]
fn every_model_on_every_model_s_data() {
    println!("| data from | MS mean/max | MCS mean/max | MCCS mean/max |");
    for truth in truths() {
        let data = synthesize(&truth, &forces(), 0.0, 1);
        let fits: Vec<_> = ModelKind::ALL
            .iter()
            .map(|&k| fit(k, &data).unwrap())
            .collect();
        let cells: Vec<String> = fits
            .iter()
            .map(|f| format!("{:.2e} / {:.2e}", f.metrics.mean_abs, f.metrics.max_abs))
            .collect();
        println!("| {} | {} |", truth.kind().name(), cells.join(" | "));
        // The generating model fits its own noise-free data best.
        let own = fits
            .iter()
            .find(|f| f.model.kind() == truth.kind())
            .unwrap();
        assert!(fits.iter().all(|f| f.metrics.mse >= own.metrics.mse));
    }
}

#[test]
fn mcs_closed_form_inverse_matches_the_numeric_one() {
    // The paper's eqs. 23–26: the cone alone inverted in closed form.
    let r = Reference::cone_only(&Params::TABLE2.cone);
    for i in 1..200 {
        let e = r.strain_t() + (r.strain_c() - r.strain_t()) * i as f64 / 200.0;
        let (a, b) = (r.force_closed_form(e), r.force_bracketed(e));
        assert!((a - b).abs() <= 1e-9 * b, "{e}: {a} vs {b}");
    }
}

#[test]
fn a_fitted_parameter_file_round_trips_to_the_fixed_point_core() {
    let data = synthesize(&Fitted::Mccs(Params::TABLE2), &forces(), 0.0, 1);
    let Fitted::Mccs(p) = fit(ModelKind::Mccs, &data).unwrap().model else {
        panic!()
    };
    let text = mccs_host::paramfile::to_toml(&p);
    let back = mccs_host::paramfile::parse(&text, Path::new("fitted.toml")).unwrap();
    assert_eq!(back, p);
    let r = Reference::new(&back).unwrap();
    let t = ForceTable64::new(&back).unwrap();
    let scale = r.force(0.95);
    for i in 0..100_000 {
        let e = -0.5 + 1.45 * i as f64 / 99_999.0;
        let f = t.force(Strain::from_num(e)).to_num::<f64>();
        assert!((f - r.force(e)).abs() <= 2e-5 * scale, "{e}");
    }
}

#[test]
fn bad_data_names_the_row() {
    let ok = "strain,force_n\n0.1,0.1\n0.2,0.2\n0.3,0.3\n0.4,0.4\n0.5,0.5\n";
    assert_eq!(fit::parse_data(ok, "d.csv").unwrap().len(), 5);
    for (text, needle) in [
        ("force,strain\n0.1,0.1\n", "row 1"),
        (
            "strain,force_n\n0.1,0.1\n0.2,x\n0.3,0.3\n0.4,0.4\n0.5,0.5\n",
            "row 3",
        ),
        (
            "strain,force_n\n0.1,0.1\n0.2,NaN\n0.3,0.3\n0.4,0.4\n0.5,0.5\n",
            "row 3",
        ),
        (
            "strain,force_n\n0.1,0.1\n0.2,0.2\n0.3,0.3\n0.4,0.4\n",
            "at least 5",
        ),
        (
            "strain,force_n\n0.1,0.1\n0.2,0.2\n0.15,0.3\n0.4,0.4\n0.5,0.5\n",
            "row 4",
        ),
        (
            "strain,force_n\n0.1,0.1\n0.2,0.2\n0.3,0.2\n0.4,0.4\n0.5,0.5\n",
            "row 4",
        ),
        ("strain,force_n\n0.1,0.1,9\n", "row 2"),
    ] {
        let e = fit::parse_data(text, "d.csv").unwrap_err().to_string();
        assert!(e.contains(needle) && e.starts_with("d.csv"), "{e}");
    }
}

#[test]
fn metrics_are_the_paper_s_displacement_differences() {
    let m = Fitted::Mccs(Params::TABLE2);
    let data: Vec<_> = forces()
        .iter()
        .map(|&f| (m.strain_at(f) + 0.01, f))
        .collect();
    let x = metrics(&m, &data);
    assert!((x.mean_abs - 0.01).abs() < 1e-12 && (x.max_abs - 0.01).abs() < 1e-12);
    assert!((x.mse - 1e-4).abs() < 1e-12);
}
