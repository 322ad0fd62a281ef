//! `mccs replay`: the roaming probe on a tissue with friction, its arguments, and the
//! core against the reference.

use super::*;

/// Columns of a roaming replay's rows (`mccs replay --tissue`): after the leading
/// `time_s,fx_n,fy_n,fz_n,max_disp_mm`, the proxy, the contact, slipping, the window's
/// shifts.
const MAX_DISP: usize = 4;
const PROXY: usize = 5;
const CONTACT: usize = 8;
const SLIPPING: usize = 9;
const SHIFTS: usize = 10;

/// The rows of Table 2's 64 × 64 tissue roamed along `traj`, with `extra` arguments.
fn roam_table2(traj: &Path, extra: &[&str]) -> Vec<Vec<f64>> {
    let mut args = vec![
        "replay",
        "--params",
        "params/table2.toml",
        "--probe",
        traj.to_str().unwrap(),
        "--tissue",
        "64,64",
    ];
    args.extend_from_slice(extra);
    numbers(&mccs_ok(&args))
}

/// `(|F_r|, |F_f − F_r|)`: the reference row's force and how far the other's is from it.
fn force_gap(f: &[f64], r: &[f64]) -> (f64, f64) {
    let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (
        norm([r[1], r[2], r[3]]),
        norm([f[1] - r[1], f[2] - r[2], f[3] - r[3]]),
    )
}

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
            "time_s,fx_n,fy_n,fz_n,max_disp_mm,proxy_x_mm,proxy_y_mm,proxy_z_mm,contact,slipping,window_shifts"
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
            (r[CONTACT], r[SLIPPING]),
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
    assert!(last[SHIFTS] >= 20.0, "{} window shifts", last[SHIFTS]);
    assert_eq!(
        (last[1], last[2], last[3], last[CONTACT]),
        (0.0, 0.0, 0.0, 0.0)
    );
    // The window's nodes deform under the press and are back at rest after the lift.
    let pressed = rows.iter().filter(|r| r[CONTACT] == 1.0);
    assert!(
        pressed.clone().all(|r| r[MAX_DISP] > 0.0),
        "a contact that moves no node"
    );
    let most = pressed.map(|r| r[MAX_DISP]).fold(0.0, f64::max);
    assert!(most > 0.5, "the deepest press moves a node {most} mm");
    assert!(last[MAX_DISP] < 1e-6, "not at rest: {} mm", last[MAX_DISP]);
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
        (
            &["--tissue", "2,64"],
            &["--tissue: each side must be 3 to 64 nodes (got 2,64)"],
        ),
        (&["--tissue", "64"], &["--tissue", "W,H"]),
        (&["--tissue", "64,x"], &["--tissue", "W,H"]),
        (
            &["--tissue", "64,64", "--friction", "0.3"],
            &["--friction", "MU_S,MU_K"],
        ),
        (
            &["--tissue", "64,64", "--friction", "3,1"],
            &["--friction: MU_S and MU_K must each be 0 to 2 (got 3,1)"],
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
            &["--probe-radius: must be 0 to 1.25 mm, half the spacing (got 2)"],
        ),
        (
            &["--tissue", "64,64", "--probe-radius", "NaN"],
            &["--probe-radius"],
        ),
        (
            &["--tissue", "64,64", "--cap-radius", "10"],
            &[
                "--cap-radius: must be 148.5 to 2000 mm for this tissue",
                "got 10",
            ],
        ),
        (&["--tissue", "8,8", "--grid", "9"], &["--grid"]),
        (
            &["--tissue", "64,64", "--spacing", "4"],
            &[
                "--spacing: the tissue 64 × 64 nodes at 4 mm spans 252 × 252 mm",
                "lower --spacing or --tissue",
            ],
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
        numbers(&mccs_ok(&args))
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
                let (mag, diff) = force_gap(f, r);
                assert!(
                    diff <= 0.02 + 0.02 * mag,
                    "{extra:?} t = {}: {f:?} against {r:?}",
                    r[0]
                );
                let proxy = ((f[PROXY] - r[PROXY]).powi(2)
                    + (f[PROXY + 1] - r[PROXY + 1]).powi(2)
                    + (f[PROXY + 2] - r[PROXY + 2]).powi(2))
                .sqrt();
                assert!(
                    proxy <= 0.01,
                    "{extra:?} t = {}: the proxy is {proxy} mm off",
                    r[0]
                );
                assert_eq!(
                    (f[CONTACT], f[SLIPPING], f[SHIFTS]),
                    (r[CONTACT], r[SLIPPING], r[SHIFTS]),
                    "{extra:?} t = {}: contact, slip, shifts",
                    r[0]
                );
            }
        }
    }
}

/// The reference backend runs what the fixed one runs: at the largest spring damping
/// (30 N·s/m) the twin's conservative rule asks for more substeps than the core's cap
/// of 64, which it once shared (refused, `--rate: … needs N substeps`), and fewer than
/// its own (1024). Both replays of the stroke agree to 1 % of the peak force; a configuration
/// beyond the twin's cap quotes it.
#[test]
fn the_reference_backend_runs_the_heaviest_damping() {
    let run = |backend: &str| {
        let out = mccs_ok(&[
            "replay",
            "--params",
            "params/table2.toml",
            "--probe",
            "params/stroke.csv",
            "--spring-damping",
            "30",
            "--backend",
            backend,
        ]);
        numbers(&out)
    };
    // The case is over the core's cap for the twin's rule, and under the twin's own.
    let law = mccs_host::reference::Reference::new(&mccs::Params::TABLE2).unwrap();
    let cfg = mccs::SolverConfig {
        spring_damping: 30.0,
        ..mccs::SolverConfig::default()
    };
    let twin = mccs_host::patch::substeps(
        &mccs_host::patch::Mesh::standard(5, 2.5),
        mccs_host::patch::max_stiffness(&law),
        &mccs_host::patch::TwinConfig::from_solver(&cfg, 0),
    )
    .unwrap();
    assert!(
        (65..=mccs_host::patch::TWIN_MAX_SUBSTEPS).contains(&twin),
        "{twin}"
    );
    let (reference, fixed) = (run("reference"), run("fixed"));
    assert_eq!(reference.len(), fixed.len());
    let peak = reference
        .iter()
        .flat_map(|r| r[1..4].iter())
        .fold(0.0f64, |m, f| m.max(f.abs()));
    assert!(peak > 1.0, "{peak}");
    for (r, f) in reference.iter().zip(&fixed) {
        for k in 1..4 {
            assert!(
                (r[k] - f[k]).abs() <= 0.01 * peak,
                "t = {}: {r:?} vs {f:?}",
                r[0]
            );
        }
    }
    assert_one_line_error(
        &mccs(&[
            "replay",
            "--params",
            "params/table2.toml",
            "--probe",
            "params/stroke.csv",
            "--node-mass",
            "1e-6",
        ]),
        &["--rate: this spring needs", "(at most 1024)"],
    );
}

/// Off the tissue's edge and across it corner to corner (a slide along x past the edge,
/// then a diagonal sweep at 380 mm/s), flat and over a cap, with and without friction:
/// the reference and the core agree on contact and slip at every tick, on the window's
/// shifts to one tick's timing (ties on a grid line), at the end exactly, and on the force
/// to 0.02 N + 1 %. Two defects of the reference made them disagree: past the edge its
/// proxy jumped up to half a spacing sideways (a lateral force of up to 1.25 N where the probe pushes
/// straight out; now the point above the nearest point of the tissue, as the core), and
/// it counted a diagonal move as one shift where the core (and `docs/roaming.md`) counts
/// two.
#[test]
fn roaming_off_the_edge_and_diagonally_agrees_with_the_core() {
    let traj = temp_file(
        "off-the-edge.csv",
        "time_s,x_mm,y_mm,z_mm\n0,0.3,0.2,1\n0.5,0.3,0.2,-1\n1.5,93.7,0.2,-1\n\
         2,93.7,91.3,-3\n2.5,-92.1,-93.3,-1\n3,0.3,0.2,1\n",
    );
    let run = |extra: &[&str]| roam_table2(&traj, extra);
    for shape in [&[][..], &["--cap-radius", "300"][..]] {
        for friction in ["0,0", "0.6,0.4"] {
            let args = [shape, &["--friction", friction][..]].concat();
            let reference = run(&args);
            let fixed = run(&[&args[..], &["--backend", "fixed"][..]].concat());
            assert_eq!(fixed.len(), reference.len());
            for (f, r) in fixed.iter().zip(&reference) {
                let (mag, diff) = force_gap(f, r);
                assert!(
                    diff <= 0.02 + 0.01 * mag,
                    "{args:?} t = {}: {f:?} vs {r:?}",
                    r[0]
                );
                assert_eq!(
                    (f[CONTACT], f[SLIPPING]),
                    (r[CONTACT], r[SLIPPING]),
                    "{args:?} t = {}",
                    r[0]
                );
                assert!(
                    (f[SHIFTS] - r[SHIFTS]).abs() <= 1.0,
                    "{args:?} t = {}: shifts",
                    r[0]
                );
                // Pushed straight out past the flat edge (x > 78.75, y = 0.2), frictionless:
                // no lateral force.
                if shape.is_empty() && friction == "0,0" && (1.34..1.5).contains(&r[0]) {
                    assert!(r[2].abs() <= 1e-3, "t = {}: fy {}", r[0], r[2]);
                }
            }
            let (f, r) = (fixed.last().unwrap(), reference.last().unwrap());
            assert_eq!(f[SHIFTS], r[SHIFTS], "{args:?}: shifts at the end");
            assert!(r[SHIFTS] > 200.0, "{args:?}: {} shifts", r[SHIFTS]);
        }
    }
}

/// The fastest slide the core's window follows: one spacing per tick (2.5 m/s at 2.5 mm
/// and 1 kHz). A frictionless slide 1 mm deep, 80 mm along x, at 2.4 m/s: the core and
/// the reference both push along the normal only. At 3 m/s the reference's proxy still
/// follows the probe (past the window, on the tissue at rest), while the core's stays in
/// its window, which moves one node per tick: it lags, and the coupling drags the probe
/// back (a tangential force larger than the normal one). `docs/roaming.md` quotes both.
#[test]
fn the_core_follows_slides_up_to_one_spacing_per_tick() {
    let tangent_over_normal = |speed: f64, backend: &str| -> f64 {
        let end = 0.2 + 80.0 / speed;
        let traj = temp_file(
            &format!("slide-{speed}.csv"),
            &format!(
                "time_s,x_mm,y_mm,z_mm\n0,-40.3,0.2,1\n0.2,-40.3,0.2,-1\n{end:.6},39.7,0.2,-1\n{:.6},39.7,0.2,1\n",
                end + 0.2
            ),
        );
        let rows = roam_table2(&traj, &["--backend", backend]);
        rows.iter()
            .filter(|r| (0.22..end - 0.002).contains(&r[0]))
            .map(|r| (r[1] * r[1] + r[2] * r[2]).sqrt() / r[3])
            .fold(0.0, f64::max)
    };
    for (case, speed) in [("within", 2400.0), ("beyond", 3000.0)] {
        let (reference, fixed) = (
            tangent_over_normal(speed, "reference"),
            tangent_over_normal(speed, "fixed"),
        );
        println!(
            "ROAMSPEED case={case} speed_m_s={} reference_tangent_over_normal={reference:.1e} fixed_tangent_over_normal={fixed:.1e}",
            speed / 1000.0
        );
        assert!(reference <= 1e-3, "{case}: {reference}");
        if case == "within" {
            assert!(fixed <= 1e-3, "{case}: {fixed}");
        } else {
            assert!(fixed >= 1.0, "{case}: {fixed}");
        }
    }
}

/// A deep press with high friction (μ_s = 2, μ_k = 1.5, the probe 4 mm in), slid 30 mm:
/// the friction cone is wider than the core's window. The core slips when the reference
/// does, at every tick, and its tangential force stays within μ_s times the normal one,
/// flat and over a cap. Before, the core measured the proxy's offset from the goal held
/// to its window's edge: the offset never passed the cone, the proxy stuck for good, the
/// window (which follows the proxy) never moved, and the tangential force grew to the
/// device's maximum, up to 17 times the normal one.
#[test]
fn a_friction_cone_wider_than_the_window_still_slips() {
    let traj = temp_file(
        "deep-friction.csv",
        "time_s,x_mm,y_mm,z_mm\n0,0.3,0.2,1\n0.5,0.3,0.2,-4\n3.5,30.3,0.2,-4\n4,30.3,0.2,1\n",
    );
    for shape in [&[][..], &["--cap-radius", "300"][..]] {
        let args = [shape, &["--friction", "2,1.5"][..]].concat();
        let reference = roam_table2(&traj, &args);
        let fixed = roam_table2(&traj, &[&args[..], &["--backend", "fixed"][..]].concat());
        let ratio = |r: &Vec<f64>| {
            if r[3] > 0.1 {
                (r[1] * r[1] + r[2] * r[2]).sqrt() / r[3]
            } else {
                0.0
            }
        };
        let most = fixed.iter().map(ratio).fold(0.0, f64::max);
        assert!(most <= 2.0 * 1.01, "{args:?}: tangential {most} × normal");
        assert!(
            fixed.iter().any(|r| r[SLIPPING] == 1.0),
            "{args:?}: never slipped"
        );
        for (f, r) in fixed.iter().zip(&reference) {
            assert_eq!(
                (f[CONTACT], f[SLIPPING]),
                (r[CONTACT], r[SLIPPING]),
                "{args:?} t = {}",
                r[0]
            );
        }
        assert!(
            fixed.last().unwrap()[SHIFTS] >= 9.0,
            "{args:?}: the window stayed"
        );
    }
}

/// The core's surface search at deep presses, measured: it finds the point under a goal
/// by two corrections, which converge more slowly where the surface is pressed far in
/// (its nodes moved sideways by a large part of a spacing); a slid proxy's search starts
/// from where the proxy was. Sliding 30 mm at 10 mm/s with the probe 2 and 4 mm in, with
/// friction 0.6 / 0.4 and 2 / 1.5: the largest gap between the core's and the reference's
/// sideways force, against the normal force. Its searches from the rest grid once left a
/// sideways force of 0.3 N at 4 mm (0.6 / 0.4), a tenth of the normal one.
/// `docs/roaming.md` quotes the lines; the bounds hold them.
#[test]
fn the_core_surface_search_at_deep_presses() {
    for (case, depth, friction, bound) in [
        ("d2", 2.0, "0.6,0.4", 0.01),
        ("d4", 4.0, "0.6,0.4", 0.05),
        ("d4_mu2", 4.0, "2,1.5", 0.2),
    ] {
        let traj = temp_file(
            &format!("deep-{case}.csv"),
            &format!(
                "time_s,x_mm,y_mm,z_mm\n0,0.3,0.2,1\n0.5,0.3,0.2,-{depth}\n3.5,30.3,0.2,-{depth}\n4,30.3,0.2,1\n"
            ),
        );
        let args = ["--friction", friction];
        let reference = roam_table2(&traj, &args);
        let fixed = roam_table2(&traj, &[&args[..], &["--backend", "fixed"][..]].concat());
        let gap = fixed
            .iter()
            .zip(&reference)
            .map(|(f, r)| (f[2] - r[2]).abs())
            .fold(0.0, f64::max);
        // The same while it slides (from 1 s after the slide starts to its end).
        let sliding_gap = fixed
            .iter()
            .zip(&reference)
            .filter(|(_, r)| (1.5..3.5).contains(&r[0]))
            .map(|(f, r)| (f[2] - r[2]).abs())
            .fold(0.0, f64::max);
        let normal = reference.iter().map(|r| r[3]).fold(0.0, f64::max);
        println!(
            "ROAMDEEP case={case} probe_depth_mm={depth} sideways_gap_n={gap:.2e} sliding_gap_n={sliding_gap:.2e} normal_n={normal:.2}"
        );
        assert!(gap <= bound, "{case}: {gap} N");
    }
}

/// Over a cap's edge and past it (R = 150 mm: the probe follows the cap 1 mm in from
/// 60 mm out to the edge at 78.75 mm, then on out at the edge's height): the core and the
/// reference agree on contact at every tick (past the edge the cap falls away and the
/// contact ends), and on the force to 0.15 N (the largest gap, at touch-down). A goal
/// held to the tissue's rectangle on a cap as on a flat tissue (tried on 2026-11-27)
/// kept the core in contact past the edge with no force, for 1,327 ticks.
#[test]
fn over_a_caps_edge_the_core_and_the_reference_agree() {
    let r = 150.0f64;
    let mut text = String::from("time_s,x_mm,y_mm,z_mm\n0,60,0.2,0\n");
    for i in 0..=60 {
        let x = 60.0 + 0.6 * i as f64;
        let xs = x.min(78.75);
        let z = -(r - (r * r - xs * xs - 0.04).sqrt()) - 1.0;
        text.push_str(&format!("{:.3},{x:.3},0.2,{z:.4}\n", 0.5 + 0.05 * i as f64));
    }
    text.push_str("4.05,96,0.2,0\n");
    let traj = temp_file("cap-edge.csv", &text);
    for friction in ["0,0", "0.6,0.4"] {
        let args = ["--cap-radius", "150", "--friction", friction];
        let reference = roam_table2(&traj, &args);
        let fixed = roam_table2(&traj, &[&args[..], &["--backend", "fixed"][..]].concat());
        assert_eq!(fixed.len(), reference.len());
        let mut slips = 0;
        for (f, r) in fixed.iter().zip(&reference) {
            assert_eq!(f[CONTACT], r[CONTACT], "{friction} t = {}: contact", r[0]);
            slips += usize::from(f[SLIPPING] != r[SLIPPING]);
            let (_, gap) = force_gap(f, r);
            assert!(gap <= 0.15, "{friction} t = {}: {f:?} vs {r:?}", r[0]);
        }
        assert!(slips <= 1, "{friction}: {slips} ticks slip apart");
        assert!(reference.iter().any(|r| r[0] > 3.0 && r[CONTACT] == 0.0));
    }
}

/// The stderr of a successful replay: its setup line, then its warnings.
fn replay_said(extra: &[&str], probe: &Path) -> Vec<String> {
    let mut a = vec![
        "replay",
        "--params",
        "params/table2.toml",
        "--probe",
        probe.to_str().unwrap(),
    ];
    a.extend_from_slice(extra);
    let out = mccs(&a);
    assert!(out.status.success(), "{out:?}");
    String::from_utf8(out.stderr)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

/// A replay says what it simulates in one line on stderr, and each way the probe left
/// what the model represents in one counted line: past the patch's depth, off its side
/// or the tissue's edge while pressing, at the force clamp.
#[test]
fn replays_say_what_they_simulate_and_where_the_model_ends() {
    // Down to 3 mm on the 2.5 mm-deep patch: below it from t = 0.15 s (z = −2.5 mm) to
    // the end, 150 ticks at 1 kHz.
    let deep = temp_file(
        "deep.csv",
        "time_s,x_mm,y_mm,z_mm\n0,0,0,1\n0.1,0,0,-2\n0.2,0,0,-3\n0.3,0,0,-3\n",
    );
    let said = replay_said(&["--max-force", "100"], &deep);
    assert_eq!(
        said[0],
        "mccs replay: patch 5 × 5 nodes (10 × 10 mm, 2.5 mm deep) at 2.5 mm; the f64 twin, \
         1000 Hz × 6 substeps, node mass 5 g, spring damping 1 N·s/m; coupling 1 N/mm and \
         0.5 N·s/m, force clamp 100 N"
    );
    assert_eq!(said.len(), 2, "{said:#?}");
    assert!(
        said[1].starts_with(
            "mccs replay: warning: the probe was below the patch's depth (2.5 mm under the rest \
             surface, where its base is fixed) on 150 ticks, first at t = 0.151 s: "
        ),
        "{}",
        said[1]
    );
    // Slid off a 21 × 21 tissue's edge (±25 mm) at 1 mm deep, pulled back at a 3 N clamp.
    let edge = temp_file(
        "edge.csv",
        "time_s,x_mm,y_mm,z_mm\n0,20,0,1\n0.2,20,0,-1\n0.7,30,0,-1\n",
    );
    let said = replay_said(
        &[
            "--backend",
            "fixed",
            "--tissue",
            "21,21",
            "--max-force",
            "3",
        ],
        &edge,
    );
    assert!(
        said[0].starts_with(
            "mccs replay: tissue 21 × 21 nodes at 2.5 mm (50 × 50 mm, flat), window 5 × 5 nodes"
        ),
        "{}",
        said[0]
    );
    assert!(
        said[0].contains("the fixed-point core (wide)"),
        "{}",
        said[0]
    );
    let warned = |what: &str| {
        said.iter()
            .any(|l| l.contains(what) && l.contains(" ticks, first at t = "))
    };
    assert!(
        warned("the probe pressed off the tissue's edge (x within ±25 mm, y within ±25 mm) on 250 ticks, first at t = 0.451 s"),
        "{said:#?}"
    );
    assert!(warned("the force was at the clamp (3 N)"), "{said:#?}");
    // A press within the tissue, under the clamp: the setup line alone.
    let said = replay_said(
        &["--tissue", "21,21"],
        &temp_file(
            "gentle.csv",
            "time_s,x_mm,y_mm,z_mm\n0,0,0,1\n0.2,0,0,-1\n0.4,0,0,-1\n",
        ),
    );
    assert_eq!(said.len(), 1, "{said:#?}");
}

/// `patch` says what it simulates too: the held contact node, no coupling.
#[test]
fn patch_says_what_it_simulates() {
    let out = mccs(&[
        "patch",
        "--params",
        "params/table2.toml",
        "--indent",
        "1",
        "--duration",
        "0.01",
        "--node-mass",
        "2",
    ]);
    assert!(out.status.success(), "{out:?}");
    assert_eq!(
        String::from_utf8_lossy(&out.stderr),
        "mccs patch: patch 5 × 5 nodes (10 × 10 mm, 2.5 mm deep) at 2.5 mm; the f64 twin, \
         1000 Hz × 9 substeps, node mass 2 g, spring damping 1 N·s/m; the contact node held \
         at the indentation (no coupling)\n"
    );
}

/// `replay --help` names the columns of every mode as the runs print them.
#[test]
fn replay_help_names_every_modes_columns() {
    let help = String::from_utf8(mccs(&["replay", "--help"]).stdout).unwrap();
    let header = |extra: &[&str]| {
        let mut a = vec![
            "replay",
            "--params",
            "params/table2.toml",
            "--probe",
            "params/palpation.csv",
        ];
        a.extend_from_slice(extra);
        let out = mccs(&a);
        assert!(out.status.success(), "{out:?}");
        String::from_utf8(out.stdout)
            .unwrap()
            .lines()
            .next()
            .unwrap()
            .to_string()
    };
    let (glued, roaming) = (header(&[]), header(&["--tissue", "64,64"]));
    let (lead, glued_own) = glued.split_at(glued.match_indices(',').nth(4).unwrap().0);
    let roaming_own = roaming.strip_prefix(lead).unwrap();
    for columns in [lead, &glued_own[1..], &roaming_own[1..]] {
        assert!(help.contains(columns), "--help lacks {columns:?}:\n{help}");
    }
}
