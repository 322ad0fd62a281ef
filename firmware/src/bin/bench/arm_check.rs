//! The M4F's arm pose is assembly (`mccs/src/arm/pose_dsp.rs`); this checks it, returned
//! (`Arm::pose`) and written over the last pose (`Arm::pose_into`), against the portable
//! Rust it replaces ([`mccs::Arm::pose_portable`]), bit for bit (every field:
//! the `cos`/`sin`, the reach, the device frame, the probe and the flags), on the core
//! itself, before anything is measured.
//!
//! The arms: the WoodenHaptics arm (`WOODENHAPTICS`), then variants at the ends of what
//! `ArmSpec::validate` allows: every joint's sign reversed and its home moved (count and
//! angle), 16 counts a joint turn (the coarsest; its ranges ±90°, four counts exactly, so
//! that the limit's compare is met at its edge) and 2³⁰ (the finest: the fraction of a
//! phase per count in use), 1,000 mm links with the tissue's origin 2,000 mm off in every
//! axis (the probe held at ±128 mm, `OUTSIDE`), and the narrowest and widest ranges
//! (every count outside, then none), and motors so weak that every duty's gain saturates
//! its product and so strong that it shifts down, and masses near the gravity terms'
//! limit. The counts: random at every magnitude from 2⁰ to
//! 2³¹ (the phase wraps), within a turn of home, and each joint's range's ends ± 2.
//! At each pose, the drive (`Arm::drive` against `Arm::drive_portable`) at a random force
//! of any magnitude up to `Force`'s ±2,048 N; at 20 poses an arm, 500 forces across all
//! of that range; and at 24 poses an arm, on a random
//! direction, the forces each side of where the duties come to be scaled (found by
//! halving), two steps beyond. Prints `ARMCHECK core=<c> arms=<n> poses=<n>
//! full_forces=<n> scale_edges=<n> mismatches=<n>`; a mismatch exits with failure. On the M4F only: elsewhere both sides are the same function.

use super::fw_common::exit;
use super::rng::Rng;
use mccs::{Arm, ArmPose, ArmSpec, Force};
use mccs_firmware::arm::device::WOODENHAPTICS;
use mccs_firmware::target::{Core, CORE};

/// Random poses per arm.
const POSES: u32 = 3_000;

/// The arms checked ([module docs](self)).
fn arms() -> [ArmSpec; 9] {
    let base = WOODENHAPTICS;
    let mut reversed = base;
    for (k, j) in reversed.joints.iter_mut().enumerate() {
        j.sign = -1.0;
        j.home_count = [-5_000, 77, 123_456][k];
        j.home_angle_deg = [10.0, -20.0, 45.0][k];
    }
    let mut coarse = base;
    let mut fine = base;
    for (c, f) in coarse.joints.iter_mut().zip(fine.joints.iter_mut()) {
        (c.counts_per_rev, c.ratio) = (4.0, 4.0);
        // Ends a whole number of counts from home, each phase exact: the limit's
        // compare decides at its very edge.
        (c.min_angle_deg, c.max_angle_deg) = (-90.0, 90.0);
        (f.counts_per_rev, f.ratio) = (65_536.0, 16_384.0);
    }
    let mut long = base;
    long.upper_arm_mm = 1_000.0;
    long.forearm_mm = 1_000.0;
    long.base_height_mm = 1_000.0;
    long.tissue_origin_mm = [-2_000.0, 2_000.0, -2_000.0];
    let mut narrow = base;
    let mut wide = base;
    for (n, w) in narrow.joints.iter_mut().zip(wide.joints.iter_mut()) {
        (n.min_angle_deg, n.max_angle_deg) = (-0.01, 0.01);
        (w.min_angle_deg, w.max_angle_deg) = (-179.0, 179.0);
    }
    // Motors so weak that each duty's gain takes the most shifts up (its product
    // saturates), and so strong that it takes shifts down.
    let mut weak = base;
    let mut strong = base;
    for (w, s) in weak.joints.iter_mut().zip(strong.joints.iter_mut()) {
        (
            w.torque_constant_nm_per_a,
            w.max_current_a,
            w.continuous_current_a,
        ) = (1e-6, 1e-3, 1e-3);
        (
            s.torque_constant_nm_per_a,
            s.max_current_a,
            s.continuous_current_a,
        ) = (50.0, 500.0, 1.0);
    }
    // Masses near the gravity terms' limit (32,768 N·mm at the shoulder).
    let mut heavy = base;
    heavy.gravity = Some(mccs::GravitySpec {
        upper_arm_mass_kg: 8.0,
        upper_arm_com_mm: 300.0,
        forearm_mass_kg: 4.0,
        forearm_com_mm: 300.0,
        g: 9.81,
    });
    [
        reversed, coarse, fine, long, narrow, wide, weak, strong, heavy,
    ]
}

/// Random poses an arm at which the drive takes forces across `Force`'s whole range, and
/// the forces at each.
const WIDE_POSES: u32 = 20;
const WIDE_FORCES: u32 = 500;

/// Random poses whose duties are checked where they come to be scaled, per arm.
const EDGES: u32 = 24;

/// A force at every magnitude up to all of `Force`'s ±2,048 N, each axis its own.
fn force(rng: &mut Rng) -> [Force; 3] {
    core::array::from_fn(|_| {
        let x = rng.next();
        Force::from_bits((rng.next() as i32) >> (x & 31))
    })
}

/// Whether the drive differs from the portable one at `pose` and `force`.
fn differs(arm: &Arm, pose: &ArmPose, force: [Force; 3]) -> bool {
    arm.drive(pose, force) != arm.drive_portable(pose, force)
}

/// Runs the check and exits with failure on a mismatch.
#[inline(never)]
pub fn check() {
    if CORE == Core::M4F {
        run();
    }
}

/// What the check did, and how often the assembly differed.
#[derive(Default)]
struct Tally {
    arms: u32,
    poses: u32,
    full_forces: u32,
    scale_edges: u32,
    mismatches: u32,
}

/// The check itself.
#[inline(never)]
fn run() {
    let mut rng = Rng(0x1B87_3593);
    let mut t = Tally::default();
    for spec in [WOODENHAPTICS].into_iter().chain(arms()) {
        let Ok(arm) = Arm::new(&spec) else {
            exit(false)
        };
        t.arms += 1;
        poses(&arm, &spec, &mut rng, &mut t);
        full_forces(&arm, &spec, &mut rng, &mut t);
        scale_edges(&arm, &spec, &mut rng, &mut t);
    }
    defmt::println!(
        "ARMCHECK core={=str} arms={=u32} poses={=u32} full_forces={=u32} scale_edges={=u32} mismatches={=u32}",
        CORE.name(),
        t.arms,
        t.poses,
        t.full_forces,
        t.scale_edges,
        t.mismatches
    );
    if t.mismatches != 0 {
        exit(false)
    }
}

/// Counts a joint turn (joint A's), for the counts near home.
fn turn(spec: &ArmSpec) -> i32 {
    (spec.joints[0].counts_per_rev * spec.joints[0].ratio) as i32
}

/// Counts within half a turn of home.
fn near_home(arm: &Arm, spec: &ArmSpec, rng: &mut Rng) -> [i32; 3] {
    let (home, turn) = (arm.home_counts(), turn(spec).max(1));
    core::array::from_fn(|k| home[k].wrapping_add((rng.next() % turn as u32) as i32 - turn / 2))
}

/// The pose (returned and written over the last) and the drive at a random force, at each
/// range's ends and at random counts.
fn poses(arm: &Arm, spec: &ArmSpec, rng: &mut Rng, t: &mut Tally) {
    let home = arm.home_counts();
    // `pose_into` writes over the last pose: a field it left would show.
    let mut into = ArmPose::default();
    let mut one = |counts: [i32; 3], force: [Force; 3], t: &mut Tally| {
        t.poses += 1;
        let portable = arm.pose_portable(counts);
        arm.pose_into(counts, &mut into);
        t.mismatches += (arm.pose(counts) != portable || into != portable) as u32;
        t.mismatches += differs(arm, &portable, force) as u32;
    };
    // Each joint's range's ends (in counts, from the spec), ± 2, the others at home.
    for (k, j) in spec.joints.iter().enumerate() {
        let per_degree = j.counts_per_rev * j.ratio / 360.0 * j.sign;
        for angle in [j.min_angle_deg, j.max_angle_deg] {
            let at = j.home_count as f64 + (angle - j.home_angle_deg) * per_degree;
            for d in -2..=2 {
                let mut counts = home;
                counts[k] = (at as i32).wrapping_add(d);
                one(counts, force(rng), t);
            }
        }
    }
    let turn = turn(spec);
    for i in 0..POSES {
        let counts = core::array::from_fn(|k| {
            if i % 2 == 0 {
                // Every magnitude, the phase wrapping.
                let x = rng.next();
                (x as i32) >> (x & 31)
            } else {
                // Within a turn of home.
                home[k].wrapping_add((rng.next() % (2 * turn.max(1) as u32)) as i32 - turn)
            }
        });
        one(counts, force(rng), t);
    }
}

/// The drive at forces across all of `Force`'s range (the most scaled duties, the weak
/// arm's saturated products).
fn full_forces(arm: &Arm, spec: &ArmSpec, rng: &mut Rng, t: &mut Tally) {
    for _ in 0..WIDE_POSES {
        let pose = arm.pose_portable(near_home(arm, spec, rng));
        for _ in 0..WIDE_FORCES {
            let f = core::array::from_fn(|_| Force::from_bits(rng.next() as i32));
            t.full_forces += 1;
            t.mismatches += differs(arm, &pose, f) as u32;
        }
    }
}

/// The drive each side of where the duties come to be scaled, on a random direction
/// (found by halving the force on it), two steps beyond.
fn scale_edges(arm: &Arm, spec: &ArmSpec, rng: &mut Rng, t: &mut Tally) {
    for _ in 0..EDGES {
        let pose = arm.pose_portable(near_home(arm, spec, rng));
        let dir: [i32; 3] = core::array::from_fn(|_| (rng.next() % 3) as i32 - 1);
        let at = |s: i32| dir.map(|d| Force::from_bits(d.wrapping_mul(s)));
        let scaled = |s: i32| arm.drive_portable(&pose, at(s)).scaled;
        let (mut lo, mut hi) = (0, i32::MAX);
        if scaled(lo) || !scaled(hi) {
            continue;
        }
        while hi - lo > 1 {
            let mid = lo + ((hi - lo) >> 1);
            if scaled(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        for s in lo.saturating_sub(2)..=hi.saturating_add(2) {
            t.scale_edges += 1;
            t.mismatches += differs(arm, &pose, at(s)) as u32;
        }
    }
}
