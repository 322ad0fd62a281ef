//! The arm's fixed point held to its `f64` twin (docs/arm.md): the forward kinematics
//! over a grid of the joints' ranges and 10⁶ random count triples (≤ 10 µm), `Jᵀ F`
//! against the virtual work of the twin's forward kinematics, gravity against the
//! gradient of the potential, counts → fixed FK → `f64` IK → counts (±1), the
//! saturation (every duty within ±1, the force's direction kept), the reciprocal over
//! its whole domain. Figures as `ARM` lines.

use mccs::{Arm, ArmSpec, Force};
use mccs_host::arm::{device_file, ArmTwin};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

fn woodenhaptics() -> ArmSpec {
    device_file::read(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../devices/woodenhaptics.toml"))
        .unwrap()
}

/// The shipped arm with no gravity term (so that its torques are `Jᵀ F` alone), its
/// fixed-point chain and its `f64` twin.
fn without_gravity() -> (ArmSpec, Arm, ArmTwin) {
    let spec = ArmSpec {
        gravity: None,
        ..woodenhaptics()
    };
    (spec, Arm::new(&spec).unwrap(), ArmTwin { spec })
}

/// Random counts within the joints' ranges.
fn counts_in(spec: &ArmSpec, twin: &ArmTwin, rng: &mut ChaCha8Rng) -> [i32; 3] {
    let angles: [f64; 3] = std::array::from_fn(|k| {
        let j = &spec.joints[k];
        rng.random_range(j.min_angle_deg..j.max_angle_deg)
            .to_radians()
    });
    twin.counts(angles).map(|c| c.round() as i32)
}

/// Random counts within the ranges, on the working branch and away from its edges
/// (`10° < B + C < 170°`): where the inverse kinematics has one answer.
fn counts_on_branch(spec: &ArmSpec, twin: &ArmTwin, rng: &mut ChaCha8Rng) -> [i32; 3] {
    loop {
        let c = counts_in(spec, twin, rng);
        let t = twin.angles(c.map(f64::from));
        let bc = (t[1] + t[2]).to_degrees();
        if (10.0..170.0).contains(&bc) {
            return c;
        }
    }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[test]
fn the_fixed_forward_kinematics_is_the_twins_within_10_um() {
    let spec = woodenhaptics();
    let arm = Arm::new(&spec).unwrap();
    let twin = ArmTwin { spec };
    let err = |c: [i32; 3]| {
        let fixed = arm.pose(c).device_mm();
        let exact = twin.fk(twin.angles(c.map(f64::from)));
        dist(fixed, exact)
    };
    let mut worst = 0.0f64;
    // A grid over the ranges, ends included.
    let steps = 24;
    for i in 0..=steps {
        for j in 0..=steps {
            for k in 0..=steps {
                let t: [f64; 3] = std::array::from_fn(|n| {
                    let js = &spec.joints[n];
                    let u = [i, j, k][n] as f64 / steps as f64;
                    (js.min_angle_deg + u * (js.max_angle_deg - js.min_angle_deg)).to_radians()
                });
                worst = worst.max(err(twin.counts(t).map(|c| c.round() as i32)));
            }
        }
    }
    let grid = worst;
    let mut rng = ChaCha8Rng::seed_from_u64(53);
    for _ in 0..1_000_000 {
        worst = worst.max(err(counts_in(&spec, &twin, &mut rng)));
    }
    println!(
        "ARM case=fk grid_um={:.2} random_um={:.2} points=1000000",
        grid * 1000.0,
        worst * 1000.0
    );
    assert!(worst <= 0.010, "{} mm", worst);
}

#[test]
fn torques_are_the_virtual_work_of_the_forward_kinematics() {
    let (spec, arm, twin) = without_gravity();
    let mut rng = ChaCha8Rng::seed_from_u64(54);
    let mut worst = 0.0f64;
    for _ in 0..20_000 {
        let c = counts_in(&spec, &twin, &mut rng);
        let f: [f64; 3] = std::array::from_fn(|_| rng.random_range(-5.0..5.0));
        let fixed = arm
            .drive(&arm.pose(c), f.map(Force::from_num))
            .torque_q8
            .map(|t| t as f64 / 256.0);
        let fd = virtual_work(&twin, twin.angles(c.map(f64::from)), f);
        worst = worst.max(assert_torques(fixed, fd, &format!("{f:?}")));
    }
    println!("ARM case=jt max_rel_err={worst:.2e}");
}

/// The torques `F · ∂p/∂θ` that render `f` at angles `t`: central differences of the
/// twin's forward kinematics.
fn virtual_work(twin: &ArmTwin, t: [f64; 3], f: [f64; 3]) -> [f64; 3] {
    let h = 1e-6;
    std::array::from_fn(|k| {
        let (mut a, mut b) = (t, t);
        a[k] += h;
        b[k] -= h;
        let (pa, pb) = (twin.fk(a), twin.fk(b));
        (0..3).map(|n| f[n] * (pa[n] - pb[n])).sum::<f64>() / (2.0 * h)
    })
}

/// Holds the fixed torques to the virtual work `fd` within 0.5 % of its largest and 4 of
/// the torque's LSBs (1/256 N·mm: its products' truncations); the worst error relative
/// to the largest.
fn assert_torques(fixed: [f64; 3], fd: [f64; 3], at: &str) -> f64 {
    let scale = fd.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut worst = 0.0f64;
    for k in 0..3 {
        let err = (fixed[k] - fd[k]).abs();
        assert!(
            err <= 0.005 * scale + 4.0 / 256.0,
            "joint {k} at {at}: {} against {} N·mm",
            fixed[k],
            fd[k]
        );
        worst = worst.max(err / scale.max(1e-9));
    }
    worst
}

/// `drive` takes all of `Force`'s range (±2,048 N): at every corner of it, the torques
/// are the virtual work of the twin's kinematics (no product wraps; it held the force to
/// ±1,024 N until its sums were taken in Q18 N, 2026-11-30).
#[test]
fn the_drive_takes_the_whole_force_range() {
    let (spec, arm, twin) = without_gravity();
    let mut rng = ChaCha8Rng::seed_from_u64(59);
    for _ in 0..2_000 {
        let c = counts_in(&spec, &twin, &mut rng);
        let t = twin.angles(c.map(f64::from));
        for corner in 0..8 {
            let f: [Force; 3] = std::array::from_fn(|k| {
                if corner >> k & 1 == 1 {
                    Force::MAX
                } else {
                    Force::MIN
                }
            });
            let fixed = arm
                .drive(&arm.pose(c), f)
                .torque_q8
                .map(|t| t as f64 / 256.0);
            let f = f.map(|x| x.to_num::<f64>());
            assert_torques(fixed, virtual_work(&twin, t, f), &format!("{f:?}"));
        }
    }
}

/// The torques' saturating sums (`Jᵀ F` plus gravity, `saturating_add`; `qadd`/`qsub` in
/// the M4F's assembly, `src/arm/drive_dsp.rs`) are never reached by an arm `ArmSpec`
/// allows: on the longest links (1,000 mm), with masses whose gravity torques come near
/// the 32,768 N·mm limit, at every pose of a whole turn of each joint and every force
/// at the corners, edges and faces of `Force`'s range (`Jᵀ F` is linear in the force, so
/// its most is at a corner), each torque stays within ±1.6·10⁹ (Q8 N·mm; gravity's term
/// is within ±2²³), against `i32`'s ±2.1·10⁹.
#[test]
fn the_torques_never_reach_their_saturation() {
    let mut spec = woodenhaptics();
    (spec.upper_arm_mm, spec.forearm_mm) = (1_000.0, 1_000.0);
    spec.gravity = Some(mccs::GravitySpec {
        upper_arm_mass_kg: 1.0,
        upper_arm_com_mm: 1_000.0,
        forearm_mass_kg: 2.3,
        forearm_com_mm: 1_000.0,
        g: 9.81,
    });
    let arm = Arm::new(&spec).unwrap();
    let twin = ArmTwin { spec };
    let mut most = 0i64;
    for a in 0..16 {
        for b in 0..64 {
            for c in 0..64 {
                let turn = |k: i32, n: i32| (k as f64 / n as f64 * 360.0 - 180.0).to_radians();
                let counts = twin
                    .counts([turn(a, 16), turn(b, 64), turn(c, 64)])
                    .map(|x| x.round() as i32);
                let pose = arm.pose(counts);
                for corner in 0..27 {
                    let f: [Force; 3] = std::array::from_fn(|k| {
                        [Force::MIN, Force::ZERO, Force::MAX][(corner / 3usize.pow(k as u32)) % 3]
                    });
                    for t in arm.drive(&pose, f).torque_q8 {
                        most = most.max((t as i64).abs());
                    }
                }
            }
        }
    }
    println!("ARM case=torque_bound max_q8={most}");
    assert!(most <= 1_600_000_000, "{most}");
}

#[test]
fn gravity_is_the_gradient_of_the_potential() {
    let spec = woodenhaptics();
    let arm = Arm::new(&spec).unwrap();
    let twin = ArmTwin { spec };
    let mut rng = ChaCha8Rng::seed_from_u64(55);
    let mut worst = 0.0f64;
    for _ in 0..20_000 {
        let c = counts_in(&spec, &twin, &mut rng);
        let fixed = arm
            .drive(&arm.pose(c), [Force::ZERO; 3])
            .torque_q8
            .map(|t| t as f64 / 256.0);
        let t = twin.angles(c.map(f64::from));
        let h = 1e-6;
        for k in 0..3 {
            let mut a = t;
            let mut b = t;
            a[k] += h;
            b[k] -= h;
            let grad = (twin.potential(a) - twin.potential(b)) / (2.0 * h);
            let err = (fixed[k] - grad).abs();
            assert!(
                err <= 0.005 * grad.abs() + 4.0 / 256.0,
                "joint {k}: {} against {grad} N·mm",
                fixed[k]
            );
            worst = worst.max(err);
        }
    }
    println!("ARM case=gravity max_err_nmm={worst:.2e}");
}

#[test]
fn counts_survive_the_fixed_forward_and_the_f64_inverse_kinematics() {
    let spec = woodenhaptics();
    let arm = Arm::new(&spec).unwrap();
    let twin = ArmTwin { spec };
    let mut rng = ChaCha8Rng::seed_from_u64(56);
    let mut worst = 0i32;
    for _ in 0..100_000 {
        let c = counts_on_branch(&spec, &twin, &mut rng);
        let p = arm.pose(c).device_mm();
        let back = twin
            .counts(twin.ik(p).expect("in reach"))
            .map(|x| x.round() as i32);
        let off = (0..3).map(|k| (back[k] - c[k]).abs()).max().unwrap();
        assert!(off <= 1, "{c:?} came back {back:?}");
        worst = worst.max(off);
    }
    println!("ARM case=ik round_trip_counts={worst}");
}

#[test]
fn saturated_duties_keep_the_force_s_direction() {
    let (spec, arm, twin) = without_gravity();
    let mut rng = ChaCha8Rng::seed_from_u64(57);
    let mut worst_deg = 0.0f64;
    let mut scaled = 0;
    for _ in 0..20_000 {
        let c = counts_in(&spec, &twin, &mut rng);
        let f: [f64; 3] = std::array::from_fn(|_| rng.random_range(-200.0..200.0));
        let d = arm.drive(&arm.pose(c), f.map(Force::from_num));
        assert!(
            d.duty_q16.iter().all(|x| x.abs() <= 65_536),
            "{:?}",
            d.duty_q16
        );
        if !d.scaled {
            continue;
        }
        scaled += 1;
        // The force the scaled duties render: back through the joints' gains and Jᵀ.
        let t = twin.angles(c.map(f64::from));
        let tau: [f64; 3] = std::array::from_fn(|k| {
            let j = &spec.joints[k];
            d.duty_q16[k] as f64 / 65_536.0
                * j.max_current_a
                * j.torque_constant_nm_per_a
                * j.ratio
                * 1000.0
                * j.sign
        });
        let jac = twin.jacobian(t);
        let m = nalgebra::Matrix3::from_fn(|r, col| jac[col][r]);
        // Where the arm is near a singularity a duty's last bit turns the force: the
        // direction is checked where the Jacobian is well conditioned (σ_max/σ_min ≤ 20).
        let sv = m.singular_values();
        if sv.max() > 20.0 * sv.min() {
            continue;
        }
        let Some(inv) = m.try_inverse() else { continue };
        let rendered = inv * nalgebra::Vector3::from(tau);
        let want = nalgebra::Vector3::from(f);
        let cos = rendered.dot(&want) / (rendered.norm() * want.norm());
        let deg = cos.clamp(-1.0, 1.0).acos().to_degrees();
        worst_deg = worst_deg.max(deg);
    }
    assert!(scaled > 1000, "{scaled} saturated cases");
    assert!(worst_deg <= 1.0, "{worst_deg}°");
    println!("ARM case=saturation cases={scaled} max_direction_deg={worst_deg:.2e}");
}

#[test]
fn the_reciprocal_holds_over_its_domain() {
    let mut worst = 0.0f64;
    let mut m = 1i64 << 30;
    while m < 1i64 << 31 {
        let y = mccs::arm::recip::recip(m);
        let exact = (1u128 << 62) as f64 / m as f64;
        worst = worst.max(((y as f64) - exact).abs() / exact);
        m += 997;
    }
    println!("ARM case=recip max_rel_err={worst:.2e}");
    assert!(worst < 1e-8, "{worst}");
}

/// The table's `cos` and `sin` at every 2⁻²⁰ of a turn, and at each table point's
/// neighbours, against `f64`'s of the same amplitude: within 5e-6 (the chord's sag,
/// 4.7e-6, and the truncations).
#[test]
fn cos_sin_is_within_5e_6() {
    use mccs::arm::cos_sin::{cos_sin, AMPLITUDE};
    let scale = AMPLITUDE * 2_147_483_648.0;
    let mut worst = 0.0f64;
    let mut check = |phase: u32| {
        let (c, s) = cos_sin(phase);
        let x = phase as f64 / 4_294_967_296.0 * std::f64::consts::TAU;
        let err = ((c as f64 / scale - x.cos()).abs()).max((s as f64 / scale - x.sin()).abs());
        worst = worst.max(err);
    };
    for k in 0..1u32 << 20 {
        check(k << 12);
    }
    for k in 0..1024u32 {
        for d in [1u32, 2, u32::MAX, u32::MAX - 1] {
            check((k << 22).wrapping_add(d));
        }
    }
    println!("ARM case=cos_sin max_err={worst:.2e} points=1024");
    assert!(worst <= 5e-6, "{worst}");
}

/// The firmware's WoodenHaptics constant is the shipped device file.
#[test]
fn the_firmware_s_arm_is_the_device_file() {
    assert_eq!(mccs_firmware::arm::device::WOODENHAPTICS, woodenhaptics());
}

/// The f32 peer the bench measures computes the same chain (within micromath's error).
#[test]
fn the_f32_peer_computes_the_same_chain() {
    let spec = woodenhaptics();
    let arm = Arm::new(&spec).unwrap();
    let peer = mccs_firmware::arm::float::ArmF32::new(&spec);
    let twin = ArmTwin { spec };
    let mut rng = ChaCha8Rng::seed_from_u64(58);
    let mut worst = 0.0f64;
    for _ in 0..100_000 {
        let c = counts_on_branch(&spec, &twin, &mut rng);
        let (p, _) = peer.chain(c, [0.0; 3]);
        let exact = twin.fk(twin.angles(c.map(f64::from)));
        let tissue: [f64; 3] = std::array::from_fn(|k| exact[k] - spec.tissue_origin_mm[k]);
        worst = worst.max(dist(p.map(f64::from), tissue));
        let fixed = arm.pose(c).probe.map(|l| l.to_num::<f64>());
        for k in 0..3 {
            if fixed[k].abs() < 127.0 {
                assert!(
                    (p[k] as f64 - fixed[k]).abs() < 2.0,
                    "{p:?} against {fixed:?}"
                );
            }
        }
    }
    println!("ARM case=f32_peer fk_max_um={:.0}", worst * 1000.0);
}
