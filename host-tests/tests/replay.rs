//! `mccs replay` and the library's replay: the repro of the wrapping spring
//! (a 20 mm stroke with a stiff coupling), and a press–stroke–lift along `y`, on both
//! backends and in both arithmetics: after lift-off every node comes back to rest.

use crate::cli::{mccs, mccs_ok};
use mccs::{Coupling, Params, SolverConfig};
use mccs_host::replay::{Engine, Replay, Row};
use mccs_host::trajectory::{self, Trajectory};
use std::path::PathBuf;

/// Press 1.2 mm, stroke `stroke` mm along `axis` at 20 mm/s, lift off, and wait 4 s.
fn press_stroke_lift(axis: usize, stroke: f64) -> Trajectory {
    let at = |s: f64, z: f64| {
        let mut p = [0.0, 0.0, z];
        p[axis] = s;
        p
    };
    let t_stroke = stroke / 20.0;
    Trajectory::new(vec![
        (0.0, at(0.0, 1.0)),
        (0.3, at(0.0, 0.0)),
        (0.7, at(0.0, -1.2)),
        (1.0, at(0.0, -1.2)),
        (1.0 + t_stroke, at(stroke, -1.2)),
        (1.3 + t_stroke, at(stroke, 5.0)),
        (5.3 + t_stroke, at(stroke, 5.0)),
    ])
    .unwrap()
}

/// The configuration: N = 5, 2.5 mm, coupling 5 N/mm and 40 N.
fn replay(engine: Engine) -> Replay {
    Replay {
        grid: 5,
        spacing: 2.5,
        config: SolverConfig {
            coupling: Coupling {
                stiffness: 5.0,
                damping: 0.5,
                max_force: 40.0,
            },
            ..SolverConfig::default()
        },
        engine,
    }
}

fn rows(engine: Engine, traj: &Trajectory) -> Vec<Row> {
    let mut out = Vec::new();
    replay(engine)
        .run(&Params::TABLE2, traj, |r| out.push(r))
        .unwrap();
    out
}

#[test]
fn every_node_returns_to_rest_after_a_long_stroke() {
    for (axis, stroke) in [(0, 20.0), (1, 20.0), (1, 2.0)] {
        let traj = press_stroke_lift(axis, stroke);
        for engine in [Engine::Reference, Engine::Wide, Engine::Narrow] {
            let r = rows(engine, &traj);
            let last = r.last().unwrap();
            // It was dragged: the contact node went along the stroke.
            let peak = r.iter().map(|r| r.contact[axis].abs()).fold(0.0, f64::max);
            assert!(
                peak > 0.5 * stroke.min(5.0),
                "{engine:?} axis {axis}: peak {peak}"
            );
            assert!(
                last.max_disp < 1e-3,
                "{engine:?} axis {axis}, stroke {stroke}: a node stays {} mm from rest (contact at {:?})",
                last.max_disp,
                last.contact
            );
            assert_eq!(last.force, [0.0; 3]);
            println!(
                "REPLAY engine={engine:?} axis={axis} stroke_mm={stroke} peak_contact_mm={peak:.3} final_max_disp_mm={:.2e}",
                last.max_disp
            );
        }
    }
}

/// The fixed backends track the twin along the stroke (where the springs are far past
/// their documented limits, the limits differ from the twin's ideal springs: the check is
/// that the force stays the same sign and bounded by the device maximum).
#[test]
fn the_replayed_forces_stay_within_the_device_maximum() {
    let traj = press_stroke_lift(0, 20.0);
    for engine in [Engine::Reference, Engine::Wide, Engine::Narrow] {
        for r in rows(engine, &traj) {
            assert!(r.force.iter().all(|f| f.abs() <= 40.0), "{engine:?}: {r:?}");
        }
    }
}

fn temp(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mccs-replay-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Every mode of `mccs replay` (glued, roaming flat and on a cap; either backend) prints
/// the same leading columns, `time_s,fx_n,fy_n,fz_n,max_disp_mm`, and its own after them:
/// a script that checks the tissue came back to rest reads `max_disp_mm` in every mode.
#[test]
fn every_mode_prints_the_same_leading_columns() {
    let traj = temp(
        "modes.csv",
        "time_s,x_mm,y_mm,z_mm\n0,0,0,1\n0.05,0,0,-1\n0.1,0,0,1\n",
    );
    let glued: &[&str] = &[];
    let flat: &[&str] = &["--tissue", "16,16"];
    let cap: &[&str] = &["--tissue", "16,16", "--cap-radius", "100"];
    for (mode, own) in [
        (glued, "contact_dx_mm,contact_dy_mm,contact_dz_mm"),
        (
            flat,
            "proxy_x_mm,proxy_y_mm,proxy_z_mm,contact,slipping,window_shifts",
        ),
        (
            cap,
            "proxy_x_mm,proxy_y_mm,proxy_z_mm,contact,slipping,window_shifts",
        ),
    ] {
        for backend in ["reference", "fixed"] {
            let mut args = vec![
                "replay",
                "--params",
                "params/table2.toml",
                "--probe",
                traj.to_str().unwrap(),
                "--backend",
                backend,
            ];
            args.extend(mode);
            let out = mccs_ok(&args);
            let text = String::from_utf8(out.stdout).unwrap();
            let header = text.lines().next().unwrap();
            assert_eq!(
                header,
                format!("time_s,fx_n,fy_n,fz_n,max_disp_mm,{own}"),
                "{mode:?} {backend}"
            );
            let rows: Vec<Vec<f64>> = text
                .lines()
                .skip(1)
                .map(|l| l.split(',').map(|f| f.parse().unwrap()).collect())
                .collect();
            // Pressed 1 mm at 0.05 s: nodes moved; every row has every column.
            let pressed = rows.iter().find(|r| r[0] == 0.05).unwrap();
            assert!(pressed[4] > 0.1, "{mode:?} {backend}: {pressed:?}");
            assert!(rows.iter().all(|r| r.len() == header.split(',').count()));
        }
    }
}

#[test]
fn the_cli_prints_one_row_per_tick() {
    let traj = temp(
        "ok.csv",
        "time_s,x_mm,y_mm,z_mm\n0,0,0,1\n0.1,0,0,-1\n0.2,0,0,-1\n",
    );
    for backend in [
        vec!["--backend", "reference"],
        vec!["--backend", "fixed", "--arith", "narrow"],
    ] {
        let mut args = vec![
            "replay",
            "--params",
            "params/table2.toml",
            "--probe",
            traj.to_str().unwrap(),
        ];
        args.extend(backend);
        let out = mccs_ok(&args);
        let text = String::from_utf8(out.stdout).unwrap();
        let mut lines = text.lines();
        assert_eq!(
            lines.next(),
            Some("time_s,fx_n,fy_n,fz_n,max_disp_mm,contact_dx_mm,contact_dy_mm,contact_dz_mm")
        );
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|f| f.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), 201);
        assert_eq!(rows[0][0], 0.0);
        assert_eq!(rows[200][0], 0.2);
        assert!(
            rows[200][3] > 0.3,
            "pressed 1 mm: the force pushes up: {:?}",
            rows[200]
        );
    }
}

#[test]
fn bad_trajectories_name_the_file_and_row() {
    for (text, needle) in [
        ("", "empty file"),
        (
            "t,x,y,z\n0,0,0,0\n",
            "row 1: the header must be `time_s,x_mm,y_mm,z_mm`, not `t,x,y,z`",
        ),
        ("time_s,x_mm,y_mm,z_mm\n", "no rows"),
        ("time_s,x_mm,y_mm,z_mm\n0,0,0\n", "row 2"),
        (
            "time_s,x_mm,y_mm,z_mm\n0,0,0,0\n0,0,0,1\n",
            "row 3: times must increase",
        ),
        ("time_s,x_mm,y_mm,z_mm\n0,0,0,0\n1,nan,0,0\n", "row 3"),
        (
            "time_s,x_mm,y_mm,z_mm\n0,0,0,0\n1,0,0,500\n",
            "row 3: a position beyond",
        ),
        (
            "time_s,x_mm,y_mm,z_mm\n0,0,0,0\n1e9,0,0,0\n",
            "row 3: longer than",
        ),
    ] {
        let p = temp("bad.csv", text);
        let out = mccs(&[
            "replay",
            "--params",
            "params/table2.toml",
            "--probe",
            p.to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(2), "{text:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.contains("bad.csv") && err.contains(needle),
            "{text:?}: {err}"
        );
        assert!(out.stdout.is_empty());
    }
    // The parser alone, for the fuzz target's invariants: a good file round-trips.
    let t = trajectory::parse("time_s,x_mm,y_mm,z_mm\n0,1,2,3\n0.5,1,2,4\n", "f").unwrap();
    assert_eq!(t.at(0.25), [1.0, 2.0, 3.5]);
    assert_eq!(t.span(), (0.0, 0.5));
}

#[test]
fn bad_arguments_name_the_argument() {
    let traj = temp("short.csv", "time_s,x_mm,y_mm,z_mm\n0,0,0,1\n0.01,0,0,1\n");
    let t = traj.to_str().unwrap();
    for (extra, needle) in [
        (vec!["--coupling-stiffness", "0"], "--coupling-stiffness"),
        (vec!["--coupling-damping", "-1"], "--coupling-damping"),
        (vec!["--max-force", "5000"], "--max-force"),
        (vec!["--node-mass", "0"], "--node-mass"),
        (vec!["--spring-damping", "99"], "--spring-damping"),
        (vec!["--rate", "0"], "--rate"),
        (vec!["--grid", "2"], "--grid"),
        (vec!["--arith", "narrow"], "--arith"),
        (
            vec!["--backend", "fixed", "--arith", "narrow", "--spacing", "20"],
            "--spacing",
        ),
        (vec!["--node-mass", "0.001", "--rate", "100"], "--rate"),
    ] {
        let mut args = vec!["replay", "--params", "params/table2.toml", "--probe", t];
        args.extend(extra.iter());
        let out = mccs(&args);
        assert_eq!(out.status.code(), Some(2), "{extra:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{extra:?}: {err}");
    }
}
