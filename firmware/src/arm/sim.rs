//! [`SimulatedArm`]: the arm's whole chain on a recorded motion, for the demo firmware in
//! QEMU (whose timers cannot be driven as encoders) and its twin on the host. A probe
//! path is converted to joint counts once, when the device is built — one sample every
//! [`SAMPLE_TICKS`] ticks by `mccs::arm::inverse` (inverse kinematics, `f64`) — and each tick
//! interpolates the counts between two samples (integers, no division), then runs the
//! core's [`Arm`]: counts → the probe in the tissue's frame, and the force → duties. The
//! arm is homed from the start; the duties are recorded, not rendered.
//!
//! The samples' interpolation is linear in counts: a path that moves along a smoothstep
//! leaves it by at most `h² max|p''| / 8` between samples (16 ms: under 10 µm for the
//! demo's 30 mm slide in about a second), below the encoder's own step (one count of
//! WoodenHaptics' joints B and C moves the probe up to 64 µm).

use crate::device::HapticDevice;
use crate::probe_path::ProbePath;
use mccs::arm::OUTSIDE;
use mccs::{Arm, ArmError, ArmPose, ArmSpec, Force, Length};

/// Ticks between two samples of the counts (a power of two: the interpolation shifts).
pub const SAMPLE_TICKS: u32 = 1 << SAMPLE_SHIFT;
/// `log2(SAMPLE_TICKS)`.
pub const SAMPLE_SHIFT: u32 = 4;

/// The samples a path of `ticks` ticks needs (one past its end, for the interpolation).
pub const fn samples_for(ticks: u32) -> usize {
    (ticks >> SAMPLE_SHIFT) as usize + 2
}

/// Why a simulated arm could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SimArmError {
    /// The arm's description.
    Arm(ArmError),
    /// A point of the path the arm cannot reach within its joints' ranges (its tick).
    Unreachable(u32),
    /// The path is longer than the samples hold.
    TooLong,
}

impl SimArmError {
    /// The message.
    pub const fn message(&self) -> &'static str {
        match self {
            Self::Arm(e) => e.message(),
            Self::Unreachable(_) => {
                "arm: a point of the path is out of the arm's reach or its joints' ranges"
            }
            Self::TooLong => "arm: the path is longer than the simulated arm's samples",
        }
    }
}

impl core::fmt::Display for SimArmError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Unreachable(t) => write!(f, "{} (tick {t})", self.message()),
            _ => f.write_str(self.message()),
        }
    }
}

/// A simulated arm of up to `S` samples of counts.
#[derive(Clone, Debug)]
pub struct SimulatedArm<const S: usize> {
    arm: Arm,
    samples: [[i32; 3]; S],
    len: usize,
    tick: u32,
    pose: Option<ArmPose>,
    duty: [i32; 3],
    steady_tick: u32,
    steady_duty: [i32; 3],
    max_duty: i32,
}

impl<const S: usize> SimulatedArm<S> {
    /// The arm of `spec` moving its probe along `path` (the tissue's frame) for `ticks`
    /// ticks; the duties of tick `steady_tick` kept.
    pub fn from_path<const K: usize>(
        spec: &ArmSpec,
        path: &ProbePath<K>,
        ticks: u32,
        steady_tick: u32,
    ) -> Result<Self, SimArmError> {
        let arm = Arm::new(spec).map_err(SimArmError::Arm)?;
        let len = samples_for(ticks);
        if len > S {
            return Err(SimArmError::TooLong);
        }
        let mut samples = [[0i32; 3]; S];
        for (i, s) in samples.iter_mut().enumerate().take(len) {
            let tick = (i as u32) << SAMPLE_SHIFT;
            let p = path.at(tick);
            let device = core::array::from_fn(|k| p[k].to_num::<f64>() + spec.tissue_origin_mm[k]);
            *s = mccs::arm::inverse::counts(spec, device).ok_or(SimArmError::Unreachable(tick))?;
        }
        Ok(Self {
            arm,
            samples,
            len,
            tick: 0,
            pose: None,
            duty: [0; 3],
            steady_tick,
            steady_duty: [0; 3],
            max_duty: 0,
        })
    }

    /// The counts at `tick`: linear between its two samples, to the nearest count (held
    /// after the last).
    pub fn counts(&self, tick: u32) -> [i32; 3] {
        let i = ((tick >> SAMPLE_SHIFT) as usize).min(self.len.saturating_sub(2));
        let frac = (tick & (SAMPLE_TICKS - 1)) as i64;
        let (Some(a), Some(b)) = (self.samples.get(i), self.samples.get(i + 1)) else {
            return [0; 3];
        };
        core::array::from_fn(|k| {
            // Rounded to the nearest count (a floor would add up to one count).
            let step = (b[k] as i64 - a[k] as i64) * frac + (SAMPLE_TICKS / 2) as i64;
            (a[k] as i64 + (step >> SAMPLE_SHIFT)) as i32
        })
    }

    /// The duties last computed, Q16 (±65,536: ±100 %).
    pub fn duties(&self) -> [i32; 3] {
        self.duty
    }

    /// The duties of the steady tick, Q16.
    pub fn steady_duties(&self) -> [i32; 3] {
        self.steady_duty
    }

    /// The largest |duty| of any joint so far, Q16.
    pub fn max_duty(&self) -> i32 {
        self.max_duty
    }

    /// The last pose's flags (`mccs::arm::LIMIT_*`, `OUTSIDE`).
    pub fn flags(&self) -> u8 {
        self.pose.map_or(0, |p| p.flags)
    }
}

impl<const S: usize> HapticDevice for SimulatedArm<S> {
    type Error = core::convert::Infallible;

    fn read_position(&mut self) -> Result<[Length; 3], Self::Error> {
        let pose = self.arm.pose(self.counts(self.tick));
        self.pose = Some(pose);
        if pose.flags & OUTSIDE != 0 {
            return Ok([Length::ZERO, Length::ZERO, Length::MAX]);
        }
        Ok(pose.probe)
    }

    fn write_force(&mut self, force: [Force; 3]) -> Result<(), Self::Error> {
        self.duty = match self.pose {
            Some(pose) => self.arm.drive(&pose, force).duty_q16,
            None => [0; 3],
        };
        for d in self.duty {
            self.max_duty = self.max_duty.max(d.saturating_abs());
        }
        if self.tick == self.steady_tick {
            self.steady_duty = self.duty;
        }
        self.tick = self.tick.saturating_add(1);
        Ok(())
    }

    fn safe_state(&mut self) -> Result<(), Self::Error> {
        self.duty = [0; 3];
        self.tick = self.tick.saturating_add(1);
        Ok(())
    }
}
