//! The arm's counts-to-duties chain without the solver (`case=arm_kinematics`: the core's
//! fixed point, `Arm::pose` then `Arm::drive`) and its `f32` peer with `micromath`'s
//! `sin`/`cos` (`case=arm_kinematics_f32`), at a pose in the workspace with a force that
//! saturates no duty, averaged over 4.

use super::fw_common::exit;
use super::harness::Harness;
use core::hint::black_box;
use mccs::{Arm, Force, Length, PassivityLimits, PassivityObserver, TrackerGains, VelocityTracker};
use mccs_firmware::arm::device::WOODENHAPTICS;
use mccs_firmware::arm::float::ArmF32;

/// B 20°, C 38° (the probe near the tissue's origin), A at 5°.
const COUNTS: [i32; 3] = [222, 1333, 2533];

/// The fixed-point chain.
#[inline(never)]
pub fn arm_kinematics(h: &Harness) -> u32 {
    let Ok(arm) = Arm::new(&WOODENHAPTICS) else {
        exit(false)
    };
    let force = [
        Force::from_num(0.3),
        Force::from_num(-0.2),
        Force::from_num(1.0),
    ];
    let mut counts = COUNTS;
    h.measure(4, || {
        counts[0] = counts[0].wrapping_add(1);
        let pose = arm.pose(black_box(counts));
        black_box(arm.drive(&pose, black_box(force)));
    })
}

/// One tick of the passivity observer (`case=passivity_observer`), the probe moving and
/// the force on, averaged over 4.
#[inline(never)]
pub fn passivity_observer(h: &Harness) -> u32 {
    let limits = PassivityLimits::new(2.0, 10.0);
    let mut observer = PassivityObserver::default();
    let force = [
        Force::from_num(0.3),
        Force::from_num(-0.2),
        Force::from_num(1.0),
    ];
    let mut probe = [Length::from_num(1.5), Length::ZERO, Length::from_num(-0.7)];
    h.measure(4, || {
        probe[2] -= Length::from_num(0.01);
        black_box(observer.tick(black_box(probe), black_box(force), black_box(limits)));
    })
}

/// One tick of the velocity tracker (`case=velocity_tracker`, three axes), the probe
/// moving, averaged over 4.
#[inline(never)]
pub fn velocity_tracker(h: &Harness) -> u32 {
    let Ok(gains) = TrackerGains::default_at(1000) else {
        exit(false)
    };
    let mut tracker = VelocityTracker::new();
    let mut probe = [Length::from_num(1.5), Length::ZERO, Length::from_num(-0.7)];
    tracker.update(&gains, probe);
    h.measure(4, || {
        probe[2] -= Length::from_num(0.01);
        black_box(tracker.update(&gains, black_box(probe)));
    })
}

/// The `f32` peer.
#[inline(never)]
pub fn arm_kinematics_f32(h: &Harness) -> u32 {
    let arm = ArmF32::new(&WOODENHAPTICS);
    let force = [0.3f32, -0.2, 1.0];
    let mut counts = COUNTS;
    h.measure(4, || {
        counts[0] = counts[0].wrapping_add(1);
        black_box(arm.chain(black_box(counts), black_box(force)));
    })
}
