//! The demo on the arm (`mccs_firmware::arm::sim`, `demo::run_arm_on_host`, the firmware
//! built `--features arm`): the configuration-time inverse kinematics held to the host's
//! twin, the probe the simulated arm reads each tick held to the palpation it replays,
//! the arm demo's forces to the Cartesian demo's, and `mccs demo --arm --check`'s
//! answers. Figures as `ARMDEMO` lines.

use crate::cli::{mccs, mccs_ok, temp_file};
use mccs::arm::inverse;
use mccs::Arm;
use mccs_firmware::arm::sim::SimulatedArm;
use mccs_firmware::demo::{self, ARM};
use mccs_firmware::palpation_path;
use mccs_host::arm::ArmTwin;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The one inverse kinematics (`mccs::arm::inverse`, the simulations' and the twin's)
/// held to the twin's own forward kinematics: every point it reaches lands within the
/// counts' rounding of the point; joint angles on the working branch within the ranges
/// come back as themselves.
#[test]
fn the_inverse_kinematics_lands_within_a_count_of_the_point() {
    let twin = ArmTwin { spec: ARM };
    let mut rng = ChaCha8Rng::seed_from_u64(53);
    let origin = ARM.tissue_origin_mm;
    // Points of a 160 mm cube about the tissue's origin (the demo's tissue and beyond).
    let (mut worst_mm, mut reached) = (0.0f64, 0);
    for _ in 0..100_000 {
        let p: [f64; 3] = std::array::from_fn(|k| origin[k] + rng.random_range(-80.0..80.0));
        let Some(counts) = inverse::counts(&ARM, p) else {
            continue;
        };
        reached += 1;
        let back = twin.fk(twin.angles(counts.map(f64::from)));
        worst_mm = worst_mm.max(dist(back, p));
    }
    // Angles back from their own point.
    let mut worst_rad = 0.0f64;
    let mut tried = 0;
    for _ in 0..20_000 {
        let t: [f64; 3] = std::array::from_fn(|k| {
            let j = &ARM.joints[k];
            rng.random_range(j.min_angle_deg..j.max_angle_deg)
                .to_radians()
        });
        if (t[1] + t[2]).sin() <= 0.05 {
            continue;
        }
        tried += 1;
        let back = inverse::angles(&ARM, twin.fk(t)).expect("a point the arm reached");
        for k in 0..3 {
            worst_rad = worst_rad.max((back[k] - t[k]).abs());
        }
    }
    println!("ARMDEMO case=ik points=100000 reached={reached} max_mm={worst_mm:.4} angles={tried} max_rad={worst_rad:.2e}");
    assert!(reached > 50_000, "{reached}");
    // A count of joints B or C moves the probe up to 64 µm: rounding, half of that each.
    assert!(worst_mm < 0.08, "{worst_mm} mm");
    assert!(worst_rad < 1e-9, "{worst_rad} rad");
}

#[test]
fn the_simulated_arm_follows_the_palpation_within_a_tenth_of_a_mm() {
    let path = palpation_path(1000).unwrap();
    let sim = SimulatedArm::<{ demo::ARM_SAMPLES }>::from_path(&ARM, &path, 4000, 499).unwrap();
    let arm = Arm::new(&ARM).unwrap();
    let mut worst = 0.0f64;
    for tick in 0..4000 {
        let pose = arm.pose(sim.counts(tick));
        assert_eq!(pose.flags, 0, "tick {tick}: a joint's limit or outside");
        let got = pose.probe.map(|x| x.to_num::<f64>());
        let want = path.at(tick).map(|x| x.to_num::<f64>());
        worst = worst.max(dist(got, want));
    }
    println!("ARMDEMO case=path ticks=4000 max_mm={worst:.4}");
    assert!(worst < 0.1, "{worst} mm");
}

#[test]
fn the_arm_demo_feels_as_the_cartesian_demo() {
    for spec in [demo::M4F, demo::M3] {
        let (arm, duties) = demo::run_arm_on_host(&spec).unwrap();
        let cart = demo::run_on_host(&spec).unwrap();
        let steady = (arm.steady_force / cart.steady_force - 1.0).abs();
        let max = (arm.max_force / cart.max_force - 1.0).abs();
        println!(
            "ARMDEMO case=forces core={} steady_rel={steady:.4} max_rel={max:.4} max_duty={}",
            spec.core, duties.max_duty
        );
        assert_eq!((arm.ticks, arm.overruns), (cart.ticks, 0));
        assert_eq!(arm.window_shifts, cart.window_shifts);
        assert!(steady < 0.02, "{}: steady {steady}", spec.core);
        assert!(max < 0.06, "{}: max {max}", spec.core);
        // Pressing down: B pulls back and C forward against the tissue's push, both
        // within full scale.
        assert!(
            duties.steady_duty[1] < 0.0 && duties.steady_duty[2] > 0.0,
            "{duties:?}"
        );
        assert!(
            duties.max_duty > 0.0 && duties.max_duty <= 1.0,
            "{duties:?}"
        );
    }
}

#[test]
fn mccs_demo_arm_checks_the_arm_demo_s_log_and_no_other() {
    let line = String::from_utf8(mccs_ok(&["demo", "--core", "m4f", "--arm"]).stdout).unwrap();
    assert!(
        line.starts_with("SUMMARY ticks=4000 overruns=0 ") && line.contains(" max_duty="),
        "{line}"
    );
    let log = |name: &str, first: &str, summary: &str| {
        temp_file(
            &format!("arm-demo-{name}"),
            &format!("INFO  {first}\n{summary}\n"),
        )
    };
    let arm_start = "mccs haptic demo: core=m4f on the arm (WoodenHaptics) tick=1000 Hz, …";
    let plain_start = "mccs haptic demo: core=m4f tick=1000 Hz, …";
    let good = log("arm.log", arm_start, line.trim());
    let check = |args: &[&str]| mccs(args);
    let ok = check(&[
        "demo",
        "--core",
        "m4f",
        "--arm",
        "--check",
        good.to_str().unwrap(),
    ]);
    assert_eq!(ok.status.code(), Some(0));
    // The same log without --arm: refused, naming the flag.
    let no_flag = check(&["demo", "--core", "m4f", "--check", good.to_str().unwrap()]);
    assert_eq!(no_flag.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&no_flag.stderr).contains("check it with --arm"));
    // A Cartesian demo's log with --arm: refused.
    let plain = log("plain.log", plain_start, line.trim());
    let wrong = check(&[
        "demo",
        "--core",
        "m4f",
        "--arm",
        "--check",
        plain.to_str().unwrap(),
    ]);
    assert_eq!(wrong.status.code(), Some(2));
    // A duty off by one digit: the check fails (exit 1).
    let off = line.trim().replace(" max_duty=0.", " max_duty=0.9");
    let changed = log("changed.log", arm_start, &off);
    let differs = check(&[
        "demo",
        "--core",
        "m4f",
        "--arm",
        "--check",
        changed.to_str().unwrap(),
    ]);
    assert_eq!(differs.status.code(), Some(1), "{off}");
    // The M0 has no arm demo.
    let m0 = check(&["demo", "--core", "m0", "--arm"]);
    assert_eq!(m0.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&m0.stderr).starts_with("mccs: --arm: "));
}
