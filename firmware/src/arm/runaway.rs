//! [`SpeedLimits`]: when an arm is running away — a joint or the probe faster than its
//! limit for a run of ticks — for [`super::device::ArmDevice`], which counts the run and
//! faults ([`super::device::ArmFault::Overspeed`], [`super::device::ArmFault::ProbeSpeed`]).

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
    /// No limit (what [`ArmDevice::new`] starts with).
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
