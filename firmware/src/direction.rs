//! [`DirectionCheck`]: whether each of a device's `J` motors turns its joint the way it
//! is driven, before the device renders any force (the arm's three joints, the lever's
//! one).
//!
//! A motor (or an encoder) wired the wrong way round turns the tissue's spring into a
//! negative one: the deeper the probe, the harder the device pulls it in. Nothing the
//! device sees in use tells that from a hand pressing in (the passivity observer weighs
//! the force asked for, not the force given: on the simulated arm a reversed shoulder
//! pulled a hand 20 mm in at the force limit while the observer counted energy taken
//! in). So the device is asked, once, while nobody presses anything.
//!
//! Each joint in turn is nudged: a small duty one way (on the arm toward the middle of
//! its range first) until its count has moved [`DirectionCheck::counts`], then the other
//! way as far. Between nudges, zero duty for the settle. The count moving the way it is
//! driven passes; moving the other way is [`NudgeFault::Reversed`]; not moving within
//! the timeout is [`NudgeFault::Unmoved`] (the device held or jammed, a motor or
//! amplifier not connected). Two nudges, opposite ways, so that a hand moving the device
//! by chance does not pass a reversed joint. The arm's counts are a motor's (8 of 2000 a
//! motor turn are under 0.1° at the joint on the shipped arm); the lever's are its
//! position's (`OneDofDevice::with_direction_check`).

/// Why a check failed: joint `k` (`0..J`) turned against its nudge, or did not move.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NudgeFault {
    /// It turned the other way: its motor or encoder reversed.
    Reversed(u8),
    /// It did not move within the timeout: held, jammed, or its drive not connected.
    Unmoved(u8),
}

/// The nudges' sizes and times, for `J` joints.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DirectionCheck<const J: usize = 3> {
    /// Each joint's nudge, Q16 duty (65,536: 100 %), positive: the way the count grows.
    pub duty_q16: [i32; J],
    /// Each joint's first nudge: `true` the way its count grows (on the arm toward the
    /// middle of its range).
    pub first_up: [bool; J],
    /// Counts a nudge must move its joint, the way it drives (at least 1).
    pub counts: u32,
    /// Ticks a nudge may take to move them.
    pub timeout_ticks: u32,
    /// Ticks of zero duty before each nudge.
    pub settle_ticks: u32,
}

impl DirectionCheck<3> {
    /// The arm's check: of `spec` at `tick_hz` (start-up: floating point): each joint nudged
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
        let ticks = |ms: u32| ticks_of(tick_hz, ms);
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

impl DirectionCheck<1> {
    /// A one-joint device's check (the lever's): a nudge of `duty_q16` up first (the
    /// way its count grows), until it moves `counts`, within `timeout_ms`, after
    /// `settle_ms` at rest, at `tick_hz`.
    pub const fn one(
        tick_hz: u32,
        duty_q16: i32,
        counts: u32,
        timeout_ms: u32,
        settle_ms: u32,
    ) -> Self {
        DirectionCheck {
            duty_q16: [duty_q16],
            first_up: [true],
            counts: if counts < 1 { 1 } else { counts },
            timeout_ticks: ticks_of(tick_hz, timeout_ms),
            settle_ticks: ticks_of(tick_hz, settle_ms),
        }
    }
}

/// `ms` at `tick_hz`, rounded up, 1 … `u32::MAX` ticks.
const fn ticks_of(tick_hz: u32, ms: u32) -> u32 {
    let t = (ms as u64 * tick_hz as u64).div_ceil(1000);
    if t < 1 {
        1
    } else if t > u32::MAX as u64 {
        u32::MAX
    } else {
        t as u32
    }
}

/// What a check asks of the tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Nudge<const J: usize = 3> {
    /// These duties, Q16 (on the arm on top of its own gravity compensation; no tissue
    /// force yet).
    Drive([i32; J]),
    /// Every joint turned the way it was driven.
    Passed,
    /// A joint did not.
    Failed(NudgeFault),
}

/// Where a check is: two nudges a joint.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Nudges {
    /// 0 … 2J (joint `nudge / 2`; the second of a joint's goes back).
    nudge: u8,
    /// Ticks into this nudge, its settle first.
    ticks: u32,
    /// The joint's count when the settle ended.
    from: i32,
}

impl Nudges {
    /// The joint being driven now (its nudge past its settle), if any.
    pub fn driving<const J: usize>(&self, check: &DirectionCheck<J>) -> Option<u8> {
        let k = self.nudge / 2;
        ((k as usize) < J && self.ticks > check.settle_ticks).then_some(k)
    }

    /// The next tick's duties, the joints at `counts`; a verdict once there is one.
    pub fn step<const J: usize>(
        &mut self,
        check: &DirectionCheck<J>,
        counts: [i32; J],
    ) -> Nudge<J> {
        let k = (self.nudge / 2) as usize;
        let (Some(&count), Some(&first_up), Some(&duty)) =
            (counts.get(k), check.first_up.get(k), check.duty_q16.get(k))
        else {
            return Nudge::Passed;
        };
        if self.ticks < check.settle_ticks {
            self.ticks += 1;
            self.from = count;
            return Nudge::Drive([0; J]);
        }
        let up = first_up == self.nudge.is_multiple_of(2);
        let moved = count.wrapping_sub(self.from);
        let along = if up { moved } else { moved.wrapping_neg() };
        if along >= check.counts as i32 {
            self.nudge += 1;
            // This tick's zero duty is the next nudge's first of its settle.
            self.ticks = check.settle_ticks.min(1);
            if let Some(&c) = counts.get((self.nudge / 2) as usize) {
                self.from = c;
            }
            return if self.nudge as usize >= 2 * J {
                Nudge::Passed
            } else {
                Nudge::Drive([0; J])
            };
        }
        if along <= -(check.counts as i32) {
            return Nudge::Failed(NudgeFault::Reversed(k as u8));
        }
        if self.ticks - check.settle_ticks >= check.timeout_ticks {
            return Nudge::Failed(NudgeFault::Unmoved(k as u8));
        }
        self.ticks += 1;
        let mut drive = [0; J];
        if let Some(d) = drive.get_mut(k) {
            *d = if up { duty } else { -duty };
        }
        Nudge::Drive(drive)
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
            assert_eq!(run(wiring).0, Nudge::Failed(NudgeFault::Reversed(k as u8)));
            wiring[k] = 0;
            let (verdict, ticks) = run(wiring);
            assert_eq!(verdict, Nudge::Failed(NudgeFault::Unmoved(k as u8)));
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
        assert_eq!(verdict, Nudge::Failed(NudgeFault::Reversed(1)));
    }

    #[test]
    fn a_one_joint_check_passes_its_two_nudges_and_names_its_failures() {
        let check = DirectionCheck::one(1000, 500, 3, 20, 5);
        assert_eq!((check.timeout_ticks, check.settle_ticks), (20, 5));
        for (wiring, want) in [
            (1, Nudge::Passed),
            (-1, Nudge::Failed(NudgeFault::Reversed(0))),
            (0, Nudge::Failed(NudgeFault::Unmoved(0))),
        ] {
            let (mut nudges, mut count) = (Nudges::default(), [0i32]);
            let mut drives = Vec::new();
            let verdict = loop {
                match nudges.step(&check, count) {
                    Nudge::Drive(d) => {
                        drives.push(d[0]);
                        count[0] += d[0].signum() * wiring;
                    }
                    v => break v,
                }
            };
            assert_eq!(verdict, want, "wiring {wiring}");
            if wiring == 1 {
                // Up first, then down, each as far, with zero between.
                let up = drives.iter().position(|&d| d == 500).unwrap();
                let down = drives.iter().position(|&d| d == -500).unwrap();
                assert!(up < down && drives.iter().all(|d| [0, 500, -500].contains(d)));
                assert_eq!(count[0], 0, "back where it started");
            }
        }
        // Limits: no zero-tick timeout, no zero-count nudge.
        let c = DirectionCheck::one(1000, 1, 0, 0, 0);
        assert_eq!((c.counts, c.timeout_ticks, c.settle_ticks), (1, 1, 1));
        let c = DirectionCheck::one(u32::MAX, 1, 1, u32::MAX, 1);
        assert_eq!(c.timeout_ticks, u32::MAX);
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
