//! `mccs arm`: the device file's errors (one line naming the file, line and key, the
//! nearest key for a typo), the counts' and inputs' errors by row, and both backends.

use super::*;

const WOODEN: &str = include_str!("../../../devices/woodenhaptics.toml");

fn fk(device: &str, counts: &str, backend: &str) -> std::process::Output {
    mccs(&[
        "arm",
        "fk",
        "--device",
        device,
        "--counts",
        counts,
        "--backend",
        backend,
    ])
}

#[test]
fn bad_device_files_name_the_file_line_and_key() {
    let counts = temp_file("arm-counts.csv", "count_a,count_b,count_c\n0,1000,2000\n");
    let c = counts.to_str().unwrap();
    let cases: [(&str, String, &[&str]); 16] = [
        (
            "typo.toml",
            WOODEN.replace("upper_arm_mm = 205.0", "upper_arm_mn = 205.0"),
            &["line 6: arm.upper_arm_mn: unknown key; did you mean arm.upper_arm_mm?"],
        ),
        (
            "missing.toml",
            WOODEN.replace("forearm_mm = 245.0", ""),
            &["arm.forearm_mm: missing"],
        ),
        (
            "zero_kt.toml",
            WOODEN.replacen(
                "torque_constant_nm_per_a = 0.0603",
                "torque_constant_nm_per_a = 0",
                1,
            ),
            &["joint.b.torque_constant_nm_per_a: must be > 0"],
        ),
        (
            "negative_length.toml",
            WOODEN.replace("upper_arm_mm = 205.0", "upper_arm_mm = -205.0"),
            &["line 6: arm.upper_arm_mm: must be > 0 and ≤ 1000 mm"],
        ),
        (
            "sign.toml",
            WOODEN.replacen("sign = 1", "sign = 2", 1),
            &["joint.a.sign: must be 1 or -1"],
        ),
        (
            "ratio.toml",
            WOODEN.replace("ratio = 16.0", "ratio = 0"),
            &["joint.a.ratio: must be > 0"],
        ),
        (
            "joint.toml",
            WOODEN.replace("[joint.c]", "[joint.d]"),
            &["joint.d: unknown key"],
        ),
        (
            "no_thermal.toml",
            WOODEN.replacen("thermal_time_constant_s = 41.6\n", "", 1),
            &["joint.a.thermal_time_constant_s: missing"],
        ),
        (
            "hot.toml",
            WOODEN.replacen(
                "continuous_current_a = 1.0",
                "continuous_current_a = 4.0",
                1,
            ),
            &["joint.a.continuous_current_a: must be at most max_current_a"],
        ),
        (
            "tau.toml",
            WOODEN.replacen(
                "thermal_time_constant_s = 41.6",
                "thermal_time_constant_s = 0.1",
                1,
            ),
            &["joint.a.thermal_time_constant_s: must be 1 … 10000 s"],
        ),
        (
            "no_trim.toml",
            WOODEN.replacen("dead_band = 0.0\n", "", 2),
            &["joint.a.dead_band: missing"],
        ),
        (
            "offset.toml",
            WOODEN.replacen("duty_offset = 0.0 ", "duty_offset = 0.3 ", 1),
            &["joint.a.duty_offset: must be -0.2 … 0.2 (of full duty)"],
        ),
        (
            "band.toml",
            WOODEN.replacen("dead_band = 0.0", "dead_band = -0.01", 1),
            &["joint.a.dead_band: must be 0 … 0.2 (of full duty)"],
        ),
        // The core's rules (`ArmSpec::check`) reach the file's line too: `g` within
        // ±100 m/s², and the gravity torques under 32768 N·mm, which only the core
        // checked before (with no line).
        (
            "g.toml",
            WOODEN.replace("g = 9.81", "g = 981"),
            &["line 71: gravity.g: must be within ±100 m/s²"],
        ),
        (
            "heavy.toml",
            WOODEN.replace("forearm_com_mm = 91.0", "forearm_com_mm = 40000.0"),
            &["line 69: gravity.forearm_mass_kg: with the other masses, asks a gravity torque of 32768 N·mm or more"],
        ),
        (
            "range.toml",
            WOODEN.replacen("min_angle_deg = ", "min_angle_deg = 170 #", 1),
            &["joint.a.min_angle_deg: must be below home_angle_deg, and max_angle_deg above it"],
        ),
    ];
    for (name, text, needles) in cases {
        let path = temp_file(name, &text);
        let needles: Vec<&str> = [name].iter().chain(needles).copied().collect();
        assert_one_line_error(&fk(path.to_str().unwrap(), c, "fixed"), &needles);
    }
}

#[test]
fn bad_rows_are_named() {
    let d = "devices/woodenhaptics.toml";
    for (text, needle) in [
        (
            "a,b,c\n0,0,0\n",
            "row 1: the header must be `count_a,count_b,count_c`, not `a,b,c`",
        ),
        (
            "count_a,count_b,count_c\n0,0.5,0\n",
            "row 2: count_b: must be a whole number of counts",
        ),
        (
            "count_a,count_b,count_c\n-2147483648,0,2147483648\n",
            "row 2: count_c: must be within −2147483648 … 2147483647 counts (an i32)",
        ),
        (
            "count_a,count_b,count_c\n0,0\n",
            "row 2: 2 fields, 3 expected",
        ),
        (
            "count_a,count_b,count_c\n0,0,nan\n",
            "row 2: count_c: `nan` is not a finite number",
        ),
    ] {
        let p = temp_file("arm-bad.csv", text);
        assert_one_line_error(&fk(d, p.to_str().unwrap(), "fixed"), &[needle]);
    }
    let p = temp_file(
        "arm-bad-force.csv",
        "count_a,count_b,count_c,fx_n,fy_n,fz_n\n0,0,0,0,0,1e6\n",
    );
    assert_one_line_error(
        &mccs(&[
            "arm",
            "torque",
            "--device",
            d,
            "--input",
            p.to_str().unwrap(),
        ]),
        &["row 2: fz_n: must be within ±2000 N"],
    );
}

/// The arm's `--backend` values say what they compute: its kinematics, fixed or f64;
/// they once read as the law's (a "force table", which the arm does not use).
#[test]
fn the_arms_backends_are_described_as_the_arms() {
    for sub in ["fk", "torque"] {
        let out = mccs(&["arm", sub, "--help"]);
        assert!(out.status.success());
        let help = String::from_utf8(out.stdout).unwrap();
        assert!(
            help.contains("fixed:     The core's fixed-point kinematics and torques")
                && help.contains("reference: The arm's f64 twin")
                && !help.contains("table"),
            "mccs arm {sub} --help:\n{help}"
        );
        assert!(
            help.contains("A CSV file of "),
            "mccs arm {sub} --help:\n{help}"
        );
    }
}

#[test]
fn both_backends_agree() {
    let d = "devices/woodenhaptics.toml";
    let mut counts = String::from("count_a,count_b,count_c\n");
    let mut input = String::from("count_a,count_b,count_c,fx_n,fy_n,fz_n\n");
    for i in 0..50i32 {
        let c = [
            (i * 97) % 5000 - 2500,
            (i * 131) % 6000 - 1000,
            (i * 173) % 7000,
        ];
        counts.push_str(&format!("{},{},{}\n", c[0], c[1], c[2]));
        input.push_str(&format!(
            "{},{},{},{},{},{}\n",
            c[0],
            c[1],
            c[2],
            i % 7 - 3,
            i % 5 - 2,
            -(i % 11)
        ));
    }
    let parse = |o: std::process::Output| -> Vec<Vec<f64>> {
        assert!(o.status.success(), "{o:?}");
        String::from_utf8(o.stdout)
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect()
    };
    let cp = temp_file("arm-counts-50.csv", &counts);
    let (fixed, exact) = (
        parse(fk(d, cp.to_str().unwrap(), "fixed")),
        parse(fk(d, cp.to_str().unwrap(), "reference")),
    );
    for (a, b) in fixed.iter().zip(&exact) {
        let dist = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
        assert!(dist < 0.01, "{a:?} against {b:?}");
    }
    let ip = temp_file("arm-input-50.csv", &input);
    let torque = |b: &str| {
        parse(mccs(&[
            "arm",
            "torque",
            "--device",
            d,
            "--input",
            ip.to_str().unwrap(),
            "--backend",
            b,
        ]))
    };
    for (a, b) in torque("fixed").iter().zip(&torque("reference")) {
        for k in 0..3 {
            assert!(
                (a[k] - b[k]).abs() <= 0.005 * b[k].abs() + 1e-5,
                "torque {k}: {a:?} against {b:?}"
            );
            assert!(
                (a[k + 3] - b[k + 3]).abs() <= 1e-3,
                "duty {k}: {a:?} against {b:?}"
            );
        }
    }
}

/// A joint-space replay is the Cartesian replay at the fixed kinematics: the same forces
/// (within 1e-3 N) with the probe at `FK − origin` each tick, and the duties the arm's
/// drive gives for them.
#[test]
fn a_joint_space_replay_is_the_cartesian_replay_at_the_fixed_kinematics() {
    let d = "devices/woodenhaptics.toml";
    let joints = temp_file(
        "arm-joints.csv",
        "time_s,count_a,count_b,count_c\n0,0,1300,2450\n0.3,0,1333,2533\n1.0,400,1333,2533\n",
    );
    // The probe each tick: the counts interpolated and rounded, the core's kinematics.
    let spec =
        mccs_host::arm::device_file::read(std::path::Path::new("../devices/woodenhaptics.toml"))
            .unwrap();
    let arm = mccs::Arm::new(&spec).unwrap();
    let mut probe = String::from("time_s,x_mm,y_mm,z_mm\n");
    let keys = [
        (0.0, [0.0, 1300.0, 2450.0]),
        (0.3, [0.0, 1333.0, 2533.0]),
        (1.0, [400.0, 1333.0, 2533.0]),
    ];
    for k in 0..=1000 {
        let t = k as f64 / 1000.0;
        let i = keys.iter().rposition(|(kt, _)| *kt <= t).unwrap().min(1);
        let ((ta, a), (tb, b)) = (keys[i], keys[i + 1]);
        let u = (t - ta) / (tb - ta);
        let c: [i32; 3] = std::array::from_fn(|j| (a[j] + (b[j] - a[j]) * u).round() as i32);
        let p = arm.pose(c).probe.map(|l| l.to_num::<f64>());
        probe.push_str(&format!("{t:?},{:?},{:?},{:?}\n", p[0], p[1], p[2]));
    }
    let probe = temp_file("arm-probe.csv", &probe);
    let common = [
        "--params",
        "params/table2.toml",
        "--backend",
        "fixed",
        "--tissue",
        "64,64",
        "--friction",
        "0.3,0.2",
    ];
    let rows = |o: std::process::Output| -> (String, Vec<Vec<f64>>) {
        assert!(o.status.success(), "{o:?}");
        let text = String::from_utf8(o.stdout).unwrap();
        let mut lines = text.lines();
        let header = lines.next().unwrap().to_string();
        (
            header,
            lines
                .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
                .collect(),
        )
    };
    let (jh, jr) = rows(mccs(
        &[
            &[
                "replay",
                "--device",
                d,
                "--joints",
                joints.to_str().unwrap(),
            ][..],
            &common,
        ]
        .concat(),
    ));
    let (ph, pr) = rows(mccs(
        &[&["replay", "--probe", probe.to_str().unwrap()][..], &common].concat(),
    ));
    assert_eq!(jh, format!("{ph},duty_a,duty_b,duty_c"));
    assert_eq!(jr.len(), pr.len());
    let mut pressed = 0;
    for (j, p) in jr.iter().zip(&pr) {
        for k in 1..4 {
            assert!(
                (j[k] - p[k]).abs() <= 1e-3,
                "t = {}: {j:?} against {p:?}",
                j[0]
            );
        }
        assert!(j[p.len()..].iter().all(|d| d.abs() <= 1.0));
        if p[3] > 0.01 {
            pressed += 1;
            assert!(
                j[p.len()..].iter().any(|d| *d != 0.0),
                "a press without a duty"
            );
        }
    }
    assert!(pressed > 100, "{pressed} ticks in contact");
}

/// `--device` without `--joints` is refused, not ignored: a `--probe` replay with it
/// once ran as if it were not there.
#[test]
fn a_device_without_joints_is_refused() {
    let out = mccs(&[
        "replay",
        "--params",
        "params/table2.toml",
        "--probe",
        "params/palpation.csv",
        "--device",
        "devices/woodenhaptics.toml",
    ]);
    assert_one_line_error(&out, &["--device: only with --joints"]);
}

/// `count_a,count_b,count_c,duty_b,duty_c` rows of `n` poses held still by the arm
/// `truth`, spread over B's and C's ranges (5° inside them), each duty off by up to
/// `noise` (a fixed pseudo-random draw).
fn held_poses(truth: &mccs_host::arm::ArmTwin, n: usize, spread: f64, noise: f64) -> String {
    let mut csv = String::from("count_a,count_b,count_c,duty_b,duty_c\n");
    let mut seed = 0x9E37_79B9u32;
    let j = &truth.spec.joints;
    for i in 0..n {
        let at = |k: usize, phase: f64| {
            let (lo, hi) = (j[k].min_angle_deg + 5.0, j[k].max_angle_deg - 5.0);
            let mid = 0.5 * (lo + hi);
            let u = ((i as f64 + phase) / n as f64 * std::f64::consts::TAU).sin();
            (mid + spread * u * 0.5 * (hi - lo)).to_radians()
        };
        let counts = truth
            .counts([0.0, at(1, 0.0), at(2, 0.37 * n as f64)])
            .map(f64::round);
        let t = truth.angles(counts);
        let (d, _) = truth.duties(truth.gravity(t));
        let mut jitter = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            noise * ((seed >> 8) as f64 / (1u32 << 24) as f64 * 2.0 - 1.0)
        };
        let (b, c) = (d[1] + jitter(), d[2] + jitter());
        csv += &format!("{},{},{},{b},{c}\n", counts[0], counts[1], counts[2]);
    }
    csv
}

/// A `GRAVITY …` line's value of `key`.
fn gravity_value(line: &str, key: &str) -> f64 {
    line.split_whitespace()
        .find_map(|kv| kv.strip_prefix(&format!("{key}=")))
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{key} in {line}"))
}

#[test]
fn calibrate_recovers_the_masses_from_held_poses_and_writes_them() {
    let wooden = root().join("devices/woodenhaptics.toml");
    let spec = mccs_host::arm::device_file::read(&wooden).unwrap();
    // The arm as it is: heavier than the file says (the file's masses are wrong).
    let mut truth = spec;
    let g = truth.gravity.as_mut().unwrap();
    (g.upper_arm_mass_kg, g.forearm_mass_kg) = (0.23, 0.15);
    let truth = mccs_host::arm::ArmTwin { spec: truth };
    // Holding duties measured to ±0.002 of full duty.
    let poses = temp_file("held.csv", &held_poses(&truth, 12, 1.0, 0.002));
    let written = root().join("target/tmp-calibrated.toml");
    let out = mccs_ok(&[
        "arm",
        "calibrate",
        "--device",
        wooden.to_str().unwrap(),
        "--poses",
        poses.to_str().unwrap(),
        "--out",
        written.to_str().unwrap(),
    ]);
    let line = String::from_utf8(out.stdout).unwrap();
    let upper = gravity_value(&line, "upper_arm_mass_kg");
    let fore = gravity_value(&line, "forearm_mass_kg");
    println!(
        "CALIBRATE case=heavier upper_arm_mass_kg={upper} forearm_mass_kg={fore} true_upper_arm_mass_kg=0.23 true_forearm_mass_kg=0.15"
    );
    assert!((upper / 0.23 - 1.0).abs() < 0.05, "{line}");
    assert!((fore / 0.15 - 1.0).abs() < 0.05, "{line}");
    assert!(
        gravity_value(&line, "offset_duty_b").abs() < 0.005,
        "{line}"
    );
    // The written file reads back with those masses, everything else the same.
    let back = mccs_host::arm::device_file::read(&written).unwrap();
    let bg = back.gravity.unwrap();
    assert!(
        (bg.upper_arm_mass_kg - upper).abs() < 1e-4 && (bg.forearm_mass_kg - fore).abs() < 1e-4
    );
    assert_eq!(back.joints, spec.joints);
    let text = std::fs::read_to_string(&written).unwrap();
    assert!(
        text.contains("# mass_body_b, mass_body_c"),
        "the file's comments are kept"
    );
}

#[test]
fn calibrate_refuses_what_cannot_give_masses() {
    let wooden = root().join("devices/woodenhaptics.toml");
    let spec = mccs_host::arm::device_file::read(&wooden).unwrap();
    let truth = mccs_host::arm::ArmTwin { spec };
    let run = |name: &str, csv: &str| {
        let poses = temp_file(name, csv);
        mccs(&[
            "arm",
            "calibrate",
            "--device",
            wooden.to_str().unwrap(),
            "--poses",
            poses.to_str().unwrap(),
        ])
    };
    assert_one_line_error(
        &run("few.csv", &held_poses(&truth, 7, 1.0, 0.0)),
        &["few.csv: 7 poses; the fit needs at least 8"],
    );
    assert_one_line_error(
        &run("bunched.csv", &held_poses(&truth, 10, 0.02, 0.0)),
        &[
            "bunched.csv: joint B: the poses' sin θ spans",
            "spread the poses",
        ],
    );
    let flipped: String = held_poses(&truth, 10, 1.0, 0.0)
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 0 {
                format!("{l}\n")
            } else {
                let f: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
                format!("{},{},{},{},{}\n", f[0], f[1], f[2], -f[3], -f[4])
            }
        })
        .collect();
    assert_one_line_error(
        &run("flipped.csv", &flipped),
        &[
            "flipped.csv: the fit gives negative masses",
            "check the joints' signs",
        ],
    );
    assert_one_line_error(
        &run(
            "over.csv",
            "count_a,count_b,count_c,duty_b,duty_c\n0,0,0,1.5,0\n",
        ),
        &["over.csv: row 2: duty_b: must be within ±1"],
    );
    let no_gravity = temp_file(
        "no-gravity.toml",
        &WOODEN[..WOODEN.find("# mass_body_b").unwrap()],
    );
    let poses = temp_file("ok.csv", &held_poses(&truth, 10, 1.0, 0.0));
    assert_one_line_error(
        &mccs(&[
            "arm",
            "calibrate",
            "--device",
            no_gravity.to_str().unwrap(),
            "--poses",
            poses.to_str().unwrap(),
        ]),
        &["ok.csv: the device file has no [gravity] section"],
    );
}

/// A device file's [stability] out of its rules is exit 2 and one line naming the file,
/// the line and the key (read by `mccs check --device arm --arm-file`).
#[test]
fn a_bad_stable_region_names_the_file_line_and_key() {
    let good_b = "coupling_damping_n_s_m = [0.0, 0.5, 1.0, 2.0, 5.0]";
    let good_k = "max_coupling_n_mm = [64.0, 90.51, 90.51, 128.0, 181.019]";
    assert!(WOODEN.contains(good_b) && WOODEN.contains(good_k));
    let cases: [(&str, String, &str); 5] = [
        (
            "region_short.toml",
            WOODEN.replace(good_k, "max_coupling_n_mm = [16.0, 64.0]"),
            "stability.max_coupling_n_mm: must have one value for each of coupling_damping_n_s_m's 5",
        ),
        (
            "region_falling.toml",
            WOODEN.replace(good_b, "coupling_damping_n_s_m = [0.0, 0.5, 1.0, 5.0, 2.0]"),
            "stability.coupling_damping_n_s_m: the dampings must rise",
        ),
        (
            "region_zero.toml",
            WOODEN.replace(good_k, "max_coupling_n_mm = [0.0, 64.0, 64.0, 64.0, 64.0]"),
            "stability.max_coupling_n_mm: must be a list of 1 to 16 numbers, each > 0 and ≤ 1000 N/mm",
        ),
        (
            "region_missing.toml",
            WOODEN.replace(good_k, ""),
            "stability.max_coupling_n_mm: missing",
        ),
        (
            "region_typo.toml",
            WOODEN.replace("max_coupling_n_mm", "max_coupling_n_m"),
            "stability.max_coupling_n_m: unknown key; did you mean stability.max_coupling_n_mm?",
        ),
    ];
    for (name, text, needle) in cases {
        let path = temp_file(name, &text);
        let out = mccs(&[
            "check",
            "--params",
            "params/table2.toml",
            "--device",
            "arm",
            "--arm-file",
            path.to_str().unwrap(),
        ]);
        // (A missing key has no line of its own.)
        let line = if name == "region_missing.toml" {
            name
        } else {
            "line "
        };
        assert_one_line_error(&out, &[name, line, needle]);
    }
}

/// `--damping` out of its rules is exit 2 naming it, before any simulation runs.
#[test]
fn stability_refuses_bad_dampings() {
    for bad in ["1,0.5", "-1", "2000"] {
        let out = mccs(&[
            "arm",
            "stability",
            "--device",
            "devices/woodenhaptics.toml",
            "--damping",
            bad,
        ]);
        assert_one_line_error(&out, &["--damping", "rising, each 0 … 1000 N·s/m"]);
    }
}
