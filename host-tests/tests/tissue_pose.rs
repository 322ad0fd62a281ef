//! The tissue's pose as the tick slews it (`mccs::TissuePose`) over arbitrary runs of
//! targets: any origin the link takes and any rotation it takes (unit within `is_unit`'s
//! 2⁻¹⁰ on `|q|²`, made unit as the target is set), at any speed and turn rate
//! and tick rate, held in `f64` at every tick to what its documentation promises — the
//! origin moves at most its step an axis, the rotation at most its chord, the
//! quaternion stays unit and the matrix a rotation, and the pose reaches its target
//! exactly, within the ticks its limits take. (`link::device` holds an example run's
//! figures at 1 kHz.)

use mccs::tissue_pose::{is_unit, QUAT_FRAC};
use mccs::{Force, TissuePose};
use proptest::prelude::*;

/// Q30 to `f64`.
fn q30(c: i32) -> f64 {
    c as f64 / (1u64 << QUAT_FRAC) as f64
}

/// A unit quaternion in Q30 from any four numbers (not all near zero), as a host would
/// send it.
fn unit(v: [f64; 4]) -> Option<[i32; 4]> {
    let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if n < 1e-3 {
        return None;
    }
    let q = v.map(|x| (x / n * (1u64 << QUAT_FRAC) as f64).round() as i32);
    is_unit(q).then_some(q)
}

/// The chord between two rotations: the nearer of `b` and `−b` to `a`.
fn chord(a: [f64; 4], b: [f64; 4]) -> f64 {
    let dot: f64 = (0..4).map(|k| a[k] * b[k]).sum();
    let s = if dot < 0.0 { -1.0 } else { 1.0 };
    (0..4)
        .map(|k| (a[k] - s * b[k]).powi(2))
        .sum::<f64>()
        .sqrt()
}

#[derive(Clone, Debug)]
struct Target {
    origin: [i32; 3],
    rotation: [f64; 4],
    /// Added to the rotation's Q30 components: a host's quaternion off unit by up to
    /// the 2⁻¹⁰ on `|q|²` that `is_unit` allows (and some past it, which it refuses).
    nudge: [i32; 4],
    /// Ticks to run toward it (fewer than it needs, sometimes: a new target mid-way).
    ticks: u32,
}

fn targets() -> impl Strategy<Value = Vec<Target>> {
    let mm = (100i32 << 24) as i64;
    prop::collection::vec(
        (
            prop::array::uniform3((-mm..=mm).prop_map(|x| x as i32)),
            prop_oneof![
                3 => prop::array::uniform4(-1.0f64..1.0),
                // A half turn about an axis (a component of ±1), and the identity.
                1 => (0usize..4, prop_oneof![Just(1.0f64), Just(-1.0)]).prop_map(|(k, s)| {
                    let mut v = [0.0; 4];
                    v[k] = s;
                    v
                }),
            ],
            prop_oneof![Just([0; 4]), prop::array::uniform4(-(1i32 << 21)..1 << 21),],
            prop_oneof![1u32..50, 50u32..3000],
        )
            .prop_map(|(origin, rotation, nudge, ticks)| Target {
                origin,
                rotation,
                nudge,
                ticks,
            }),
        1..8,
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn the_pose_slews_within_its_limits_and_arrives(
        run in targets(),
        speed in 1.0f64..1000.0,
        turn in 1.0f64..3600.0,
        hz in prop_oneof![Just(1000.0f64), 200.0f64..20_000.0],
    ) {
        let mut pose = TissuePose::new(speed, turn, hz);
        // The limits as the pose takes them (its step and chord, rounded to its bits).
        let step = ((speed / hz) * (1u64 << 24) as f64).round().max(1.0) as i64;
        let theta = (turn / hz).to_radians();
        let max_chord = ((2.0 * (theta / 4.0).sin()) * (1u64 << QUAT_FRAC) as f64).round().max(1.0) / (1u64 << QUAT_FRAC) as f64;
        for (i, t) in run.iter().enumerate() {
            let Some(q) = unit(t.rotation) else { continue };
            let q: [i32; 4] = core::array::from_fn(|k| q[k].saturating_add(t.nudge[k]));
            if !is_unit(q) {
                continue;
            }
            pose.set_target(t.origin, q);
            let target = q.map(q30);
            for k in 0..t.ticks {
                let (o0, q0) = (pose.origin(), pose.rotation().map(q30));
                pose.step();
                let (o1, q1) = (pose.origin(), pose.rotation().map(q30));
                for a in 0..3 {
                    prop_assert!((o1[a] as i64 - o0[a] as i64).abs() <= step, "target {} tick {}: axis {} moved {} bits (step {})", i, k, a, o1[a] as i64 - o0[a] as i64, step);
                }
                // The chord a tick, but for the renormalisation's push outward: a
                // relative s²/8 at most (s the chord a tick), and the rounding of Q30.
                let moved = chord(q0, q1);
                let most = max_chord * (1.0 + max_chord.powi(2) / 4.0) + 1e-8;
                prop_assert!(moved <= most, "target {} tick {}: chord {} (at most {})", i, k, moved, most);
                let n2: f64 = q1.iter().map(|c| c * c).sum();
                // Two Newton steps from within 2s of unit (s the chord a tick): 7 s⁴, and
                // the rounding of Q30.
                let unit_within = 7.0 * max_chord.powi(4) + 2e-8;
                prop_assert!((n2 - 1.0).abs() <= unit_within, "target {} tick {}: |q|² = {} (within {})", i, k, n2, unit_within);
                // The rotation's matrix turns a force without changing its size, but for
                // the quaternion's distance from unit.
                let f = [1.0f64, -2.0, 0.5];
                let r = pose.to_device(f.map(Force::from_num)).map(|x| x.to_num::<f64>());
                let (nf, nr) = (f.iter().map(|x| x * x).sum::<f64>(), r.iter().map(|x| x * x).sum::<f64>());
                // (|R f| = |q|² |f|, and the rounding of Q20.)
                let size_within = nf.sqrt() * unit_within + 1e-5;
                prop_assert!((nf.sqrt() - nr.sqrt()).abs() <= size_within, "target {} tick {}: |R f| = {} for {}", i, k, nr.sqrt(), nf.sqrt());
            }
            // Given the ticks its limits take, it arrives, exactly.
            let far = (0..3).map(|a| (t.origin[a] as i64 - pose.origin()[a] as i64).abs()).max().unwrap();
            let turn_left = chord(pose.rotation().map(q30), target);
            let need = (far / step) as f64 + 2.0 * turn_left / max_chord + 10.0;
            for _ in 0..need as u32 {
                pose.step();
            }
            prop_assert!(pose.settled(), "target {}: not there after {} ticks more", i, need);
            prop_assert_eq!(pose.origin(), t.origin);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4096))]

    /// `is_unit`, the check of a host's rotation, over any four `i32`s (the extremes
    /// among them): unit within 2⁻¹⁰ of the squared norm, exactly as in `i128`. Summed in
    /// `i64`, `[MIN, MIN, 2³⁰, 0]` wrapped to a difference of `i64::MIN`, whose `abs`
    /// passed it (and panicked with overflow checks).
    #[test]
    fn a_host_s_rotation_is_unit_exactly_when_its_norm_says_so(
        q in prop::array::uniform4(prop_oneof![
            any::<i32>(),
            Just(i32::MIN),
            Just(i32::MAX),
            Just(1 << 30),
            Just(-(1 << 30)),
            Just(0),
            (-(1i32 << 30)..=(1 << 30)),
        ])
    ) {
        let n2: i128 = q.iter().map(|&c| c as i128 * c as i128).sum();
        let want = (n2 - (1i128 << 60)).abs() <= 1i128 << 50;
        prop_assert_eq!(is_unit(q), want, "{:?}", q);
    }
}

#[test]
fn the_wrapping_rotation_is_not_unit() {
    assert!(!is_unit([i32::MIN, i32::MIN, 1 << 30, 0]));
    assert!(!is_unit([i32::MIN; 4]));
    assert!(is_unit([1 << 30, 0, 0, 0]));
}
