//! [`DirectionCheck`]: whether each motor turns its joint the way it is driven, before
//! the arm renders any force.
//!
//! A motor (or an encoder) wired the wrong way round turns the tissue's spring into a
//! negative one: the deeper the probe, the harder the arm pulls it in. Nothing the
//! device sees in use tells that from a hand pressing in (the passivity observer weighs
//! the force asked for, not the force given: on the simulated arm a reversed shoulder
//! pulled a hand 20 mm in at the force limit while the observer counted energy taken
//! in). So the arm is asked, once, while nobody presses anything.
//!
//! Once the arm is homed and its home input released, each joint in turn is nudged: a
//! small duty one way (toward the middle of its range first) until its count has moved
//! [`DirectionCheck::counts`], then the other way as far. Between nudges, zero duty for
//! the settle. The count moving the way it is driven passes; moving the other way is
//! [`ArmFault::Reversed`]; not moving within the timeout is [`ArmFault::Unmoved`] (the
//! arm held or jammed, a motor or amplifier not connected: let go of the handle and home
//! again). Two nudges, opposite ways, so that a hand moving the arm by chance does not
//! pass a reversed joint. The counts are a motor's (8 of 2000 a motor turn are under
//! 0.1° at the joint on the shipped arm).

use crate::arm::device::ArmFault;

/// The nudges' sizes and times.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DirectionCheck {
    /// Each joint's nudge, Q16 duty (65,536: 100 %), positive: the way the count grows.
    pub duty_q16: [i32; 3],
    /// Each joint's first nudge: `true` the way its count grows (toward the middle of
    /// its range).
    pub first_up: [bool; 3],
    /// Counts a nudge must move its joint, the way it drives (at least 1).
    pub counts: u32,
    /// Ticks a nudge may take to move them.
    pub timeout_ticks: u32,
    /// Ticks of zero duty before each nudge.
    pub settle_ticks: u32,
}

impl DirectionCheck {
    /// The check of `spec` at `tick_hz` (start-up: floating point): each joint nudged
    /// with `torque_nm` N·m at the joint (its duty through the joint's ratio, torque
    /// constant and current, at most 100 %) until it moves `counts`, within
    /// `timeout_ms`, after `settle_ms` at rest.
    pub fn of(
        spec: &mccs::ArmSpec,
        tick_hz: u32,
        torque_nm: f64,
        counts: u32,
        timeout_ms: u32,
        settle_ms: u32,
    ) -> Self {
        let ticks = |ms: u32| (ms as u64 * tick_hz as u64).div_ceil(1000).max(1) as u32;
        let duty = |j: &mccs::JointSpec| {
            let full_nm =
                libm::fabs(j.ratio * j.torque_constant_nm_per_a * j.max_current_a).max(1e-9);
            libm::round((torque_nm / full_nm).clamp(0.0, 1.0) * 65_536.0) as i32
        };
        // The count grows with the angle when the sign is +1: toward the middle first.
        let up = |j: &mccs::JointSpec| {
            let middle = (j.min_angle_deg + j.max_angle_deg) / 2.0;
            (middle >= j.home_angle_deg) == (j.sign > 0.0)
        };
        let [a, b, c] = &spec.joints;
        DirectionCheck {
            duty_q16: [duty(a), duty(b), duty(c)],
            first_up: [up(a), up(b), up(c)],
            counts: counts.max(1),
            timeout_ticks: ticks(timeout_ms),
            settle_ticks: ticks(settle_ms),
        }
    }
}

/// What a check asks of the tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Nudge {
    /// These duties, Q16, on top of the arm's own (no tissue force yet).
    Drive([i32; 3]),
    /// Every joint turned the way it was driven.
    Passed,
    /// A joint did not.
    Failed(ArmFault),
}

/// Where a check is: six nudges, two a joint.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Nudges {
    /// 0 … 6 (joint `nudge / 2`; the second of a joint's goes back).
    nudge: u8,
    /// Ticks into this nudge, its settle first.
    ticks: u32,
    /// The joint's count when the settle ended.
    from: i32,
}

impl Nudges {
    /// The joint being driven now (its nudge past its settle), if any.
    pub fn driving(&self, check: &DirectionCheck) -> Option<u8> {
        let k = self.nudge / 2;
        (k < 3 && self.ticks > check.settle_ticks).then_some(k)
    }

    /// The next tick's duties, the joints at `counts`; a verdict once there is one.
    pub fn step(&mut self, check: &DirectionCheck, counts: [i32; 3]) -> Nudge {
        let k = (self.nudge / 2) as usize;
        if k >= 3 {
            return Nudge::Passed;
        }
        if self.ticks < check.settle_ticks {
            self.ticks += 1;
            self.from = counts[k];
            return Nudge::Drive([0; 3]);
        }
        let up = check.first_up[k] == self.nudge.is_multiple_of(2);
        let moved = counts[k].wrapping_sub(self.from);
        let along = if up { moved } else { moved.wrapping_neg() };
        if along >= check.counts as i32 {
            self.nudge += 1;
            // This tick's zero duty is the next nudge's first of its settle.
            self.ticks = check.settle_ticks.min(1);
            if let Some(&c) = counts.get((self.nudge / 2) as usize) {
                self.from = c;
            }
            return if self.nudge >= 6 {
                Nudge::Passed
            } else {
                Nudge::Drive([0; 3])
            };
        }
        if along <= -(check.counts as i32) {
            return Nudge::Failed(ArmFault::Reversed(k as u8));
        }
        if self.ticks - check.settle_ticks >= check.timeout_ticks {
            return Nudge::Failed(ArmFault::Unmoved(k as u8));
        }
        self.ticks += 1;
        let mut duty = [0; 3];
        duty[k] = if up {
            check.duty_q16[k]
        } else {
            -check.duty_q16[k]
        };
        Nudge::Drive(duty)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CHECK: DirectionCheck = DirectionCheck {
        duty_q16: [1000, 2000, 3000],
        first_up: [true, false, true],
        counts: 4,
        timeout_ticks: 10,
        settle_ticks: 2,
    };

    /// Runs a check on joints that each move a count a tick the way `wiring` turns the
    /// drive (+1 right, −1 reversed, 0 held); the verdict and the ticks it took.
    fn run(wiring: [i32; 3]) -> (Nudge, u32) {
        let (mut nudges, mut counts) = (Nudges::default(), [0i32; 3]);
        for tick in 0..1000 {
            match nudges.step(&CHECK, counts) {
                Nudge::Drive(d) => (0..3).for_each(|k| counts[k] += d[k].signum() * wiring[k]),
                verdict => return (verdict, tick),
            }
        }
        panic!("no verdict");
    }

    #[test]
    fn joints_that_turn_the_way_they_are_driven_pass_each_nudged_both_ways() {
        let (verdict, ticks) = run([1, 1, 1]);
        assert_eq!(verdict, Nudge::Passed);
        // Six nudges, each a settle and four counts, and a tick to see the last.
        assert_eq!(ticks, 6 * (2 + 4));
    }

    #[test]
    fn a_reversed_joint_fails_by_name_and_a_held_one_times_out() {
        for k in 0..3 {
            let mut wiring = [1; 3];
            wiring[k] = -1;
            assert_eq!(run(wiring).0, Nudge::Failed(ArmFault::Reversed(k as u8)));
            wiring[k] = 0;
            let (verdict, ticks) = run(wiring);
            assert_eq!(verdict, Nudge::Failed(ArmFault::Unmoved(k as u8)));
            assert_eq!(ticks, k as u32 * 12 + 2 + 10, "joint {k}'s timeout");
        }
    }

    #[test]
    fn a_joint_moved_along_its_first_nudge_by_a_hand_still_fails_the_second() {
        // A hand that turns joint B up whatever the drive says: its first nudge (down)
        // reads reversed at once.
        let (mut nudges, mut counts) = (Nudges::default(), [0i32; 3]);
        let verdict = loop {
            match nudges.step(&CHECK, counts) {
                Nudge::Drive(d) => {
                    counts[0] += d[0].signum();
                    counts[1] += 1;
                    counts[2] += d[2].signum();
                }
                v => break v,
            }
        };
        assert_eq!(verdict, Nudge::Failed(ArmFault::Reversed(1)));
    }

    #[test]
    fn the_shipped_arm_s_nudges_are_small_and_go_toward_the_middle_first() {
        let c = DirectionCheck::of(&crate::arm::device::WOODENHAPTICS, 1000, 0.2, 8, 200, 30);
        // Joint A: 0.2 N·m of 16 × 0.321 × 3 A; B and C of 12 × 0.0603 × 3 A.
        assert_eq!(c.duty_q16, [851, 6038, 6038]);
        assert_eq!(c.first_up, [true, true, true]);
        assert_eq!((c.timeout_ticks, c.settle_ticks), (200, 30));
    }
}
