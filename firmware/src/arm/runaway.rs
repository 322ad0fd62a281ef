//! [`SpeedLimits`]: when an arm is running away — a joint or the probe faster than its
//! limit for a run of ticks — for [`super::device::ArmDevice`], which counts the run and
//! faults ([`super::device::ArmFault::Overspeed`], [`super::device::ArmFault::ProbeSpeed`]).

use super::device::ArmFault;
use mccs::Length;

/// The speeds beyond which the arm is running away, per tick (counts and probe travel
/// between two reads), and how many ticks in a row make a fault.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SpeedLimits {
    /// Each joint's largest change of count in one tick.
    pub joint_counts: [u32; 3],
    /// The probe's largest move in one tick, along any axis (Q of [`Length`]).
    pub probe: Length,
    /// Ticks in a row over a limit that make a fault (at least 1).
    pub ticks: u8,
}

impl SpeedLimits {
    /// No limit (what [`ArmDevice::new`](crate::arm::device::ArmDevice::new) starts with).
    pub const NONE: SpeedLimits = SpeedLimits {
        joint_counts: [u32::MAX; 3],
        probe: Length::MAX,
        ticks: u8::MAX,
    };

    /// The limits of `spec` at `tick_hz` (start-up: floating point): a joint at
    /// `joint_rev_s` turns a second, the probe at `probe_mm_s`, for `ticks` ticks.
    pub fn of(
        spec: &mccs::ArmSpec,
        tick_hz: u32,
        joint_rev_s: f64,
        probe_mm_s: f64,
        ticks: u8,
    ) -> Self {
        let hz = tick_hz.max(1) as f64;
        let per_tick = |j: &mccs::JointSpec| {
            let c = libm::ceil(libm::fabs(j.counts_per_rev * j.ratio) * joint_rev_s / hz);
            c.clamp(1.0, u32::MAX as f64) as u32
        };
        SpeedLimits {
            joint_counts: [
                per_tick(&spec.joints[0]),
                per_tick(&spec.joints[1]),
                per_tick(&spec.joints[2]),
            ],
            probe: Length::from_bits(mccs::units::from_f64(probe_mm_s / hz, 24)),
            ticks: ticks.max(1),
        }
    }
}

/// The limits and the runs of ticks over them: each joint's, the probe's.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Runaway {
    limits: SpeedLimits,
    over: [u8; 4],
    /// The probe at the last read (None: not yet, or the homing tick).
    last_probe: Option<[Length; 3]>,
}

impl Runaway {
    /// No run over yet.
    pub(crate) const fn new(limits: SpeedLimits) -> Self {
        Self {
            limits,
            over: [0; 4],
            last_probe: None,
        }
    }

    /// The probe jumped (homing): no speed from its last place.
    pub(crate) fn forget_probe(&mut self) {
        self.last_probe = None;
    }

    /// Counts a tick over or within each limit: `deltas` the joints' changes of count,
    /// `probe` where the probe is now; the fault once a run of ticks over reaches the
    /// limit's.
    pub(crate) fn check(&mut self, deltas: [i32; 3], probe: [Length; 3]) -> Result<(), ArmFault> {
        let mut fast = [false; 4];
        for k in 0..3 {
            fast[k] = deltas[k].unsigned_abs() > self.limits.joint_counts[k];
        }
        if let Some(last) = self.last_probe {
            fast[3] = (0..3)
                .any(|i| probe[i].saturating_sub(last[i]).saturating_abs() > self.limits.probe);
        }
        self.last_probe = Some(probe);
        for k in 0..4 {
            self.over[k] = if fast[k] {
                self.over[k].saturating_add(1)
            } else {
                0
            };
            if self.over[k] >= self.limits.ticks {
                return Err(if k < 3 {
                    ArmFault::Overspeed(k as u8)
                } else {
                    ArmFault::ProbeSpeed
                });
            }
        }
        Ok(())
    }
}
