//! [`VelocityTracker`]: the probe's velocity from its quantised positions, with little
//! noise and no lag — an alpha-beta tracker (a second-order observer of position and
//! velocity, constant velocity its model) whose output is the derivative of its
//! position estimate, not its velocity state.
//!
//! A one-tick difference of the arm's counts (64 µm at the probe) comes in 64 mm/s steps:
//! some 30 mm/s RMS of noise. A window that averages it down to 5 mm/s lags half its
//! length, about 2.5 ms. The tracker predicts the next position from its velocity,
//! corrects both by the error `e` to the reading (`x̂ += α e`, `ŵ += β e`, in millimetres
//! a tick), and gives `(ŵ + α e) · tick_hz`: the velocity state alone is smooth but lags
//! its own loop; with `α e` added back the low frequencies pass with no delay (the
//! output's transfer from the true velocity is `(2ζωs + ω²)/(s² + 2ζωs + ω²)`, flat with
//! zero phase near DC) while the reading's noise is weighed by `α`. The gains put the
//! loop's two poles where the continuous loop's would be, at a natural frequency `ω` and
//! damping `ζ` ([`TrackerGains::new`]). At the default, 100 rad/s and 0.7, its noise and
//! lag on the arm's counts are measured by `host-tests/tests/velocity.rs` and quoted in
//! docs/safety.md ("The probe's velocity"): under 5 mm/s RMS and 1 ms.
//!
//! Config apart from state: [`TrackerGains`] at start-up (floating point), the tick's
//! [`VelocityTracker::update`] in integers.
//!
//! A reading farther from the prediction than [`JUMP_MM_S`] would move in a tick (a
//! homing, a probe that read out of range) is a jump, not a motion: that axis starts
//! again from it, at rest, instead of ringing for a hundred milliseconds.
//!
//! # Range and cost
//! Positions are ±128 mm (I8F24); the estimate's error `e` and every sum saturate, never
//! wrap. The velocity is I16F16 mm/s, saturated at ±32,768 mm/s. `α`, `β` are Q31
//! fractions below 1. A tick per axis: two high-word products, saturating adds, one
//! 32 × 32 → 64 product by the tick rate (as the one-tick difference); no division, no
//! float, no panic path. The bench's `velocity_tracker` case measures it.

use crate::q;
use crate::units::{Length, Velocity, LEN_FRAC};

/// The loop's natural frequency `ω` by default, rad/s.
pub const DEFAULT_OMEGA: f64 = 100.0;
/// The loop's damping `ζ` by default.
pub const DEFAULT_ZETA: f64 = 0.7;
/// A reading off the prediction by more than this speed would move in a tick is a jump
/// (twice the arm's runaway limit of 1 m/s), mm/s.
pub const JUMP_MM_S: f64 = 2000.0;

/// The largest error that is not a jump, Q24 mm (2²⁹: 32 mm): the tick doubles the
/// error in an `i32`. Below 62.5 Hz, where [`JUMP_MM_S`] would move further in a tick,
/// a reading 32 mm off the prediction is a jump. (Without it, at 1 Hz a probe moving
/// 33 mm a tick read as moving the other way: the doubled error wrapped.)
pub const MAX_JUMP: u32 = 1 << 29;

/// Why gains cannot be made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackerError {
    /// The tick rate is not 1 … 1,000,000 Hz.
    TickRate,
    /// `ω` is not finite and positive, or the loop at `ω` and `ζ` is not stable at the
    /// tick rate (`ωT` at most 1, `ζ` 0.1 … 2).
    Gains,
}

/// The tracker's gains at a tick rate (start-up).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TrackerGains {
    /// `α`, the position's correction, Q31.
    alpha_q31: i32,
    /// `β`, the velocity's correction (mm a tick per mm of error), Q31.
    beta_q31: i32,
    /// The tick rate, Hz.
    tick_hz: i32,
    /// A jump: an error beyond this, Q24 mm ([`JUMP_MM_S`]'s tick, at most [`MAX_JUMP`]).
    jump: u32,
}

impl TrackerGains {
    /// The gains whose loop has the continuous loop's poles at natural frequency `omega`
    /// (rad/s) and damping `zeta`, at `tick_hz`: `α = 1 − e^(−2ζωT)`,
    /// `β = 2 − α − 2 e^(−ζωT) cos(ω√(1−ζ²) T)` (`cosh` for `ζ > 1`).
    pub fn new(tick_hz: u32, omega: f64, zeta: f64) -> Result<Self, TrackerError> {
        if !(1..=1_000_000).contains(&tick_hz) {
            return Err(TrackerError::TickRate);
        }
        let wt = omega / tick_hz as f64;
        if !(wt.is_finite() && wt > 0.0 && wt <= 1.0 && (0.1..=2.0).contains(&zeta)) {
            return Err(TrackerError::Gains);
        }
        let alpha = 1.0 - libm::exp(-2.0 * zeta * wt);
        let d = libm::sqrt(libm::fabs(1.0 - zeta * zeta)) * wt;
        let c = if zeta <= 1.0 {
            libm::cos(d)
        } else {
            libm::cosh(d)
        };
        let beta = 2.0 - alpha - 2.0 * libm::exp(-zeta * wt) * c;
        let q31 = |x: f64| libm::round(x * 2_147_483_648.0) as i64;
        let (a, b) = (q31(alpha), q31(beta));
        if !(1..i32::MAX as i64).contains(&a) || !(1..i32::MAX as i64).contains(&b) {
            return Err(TrackerError::Gains);
        }
        Ok(Self {
            alpha_q31: a as i32,
            beta_q31: b as i32,
            tick_hz: tick_hz as i32,
            jump: crate::units::from_f64(JUMP_MM_S / tick_hz as f64, LEN_FRAC)
                .unsigned_abs()
                .min(MAX_JUMP),
        })
    }

    /// The default gains ([`DEFAULT_OMEGA`], [`DEFAULT_ZETA`]) at `tick_hz` (at least
    /// 100 Hz: `ωT ≤ 1`).
    pub fn default_at(tick_hz: u32) -> Result<Self, TrackerError> {
        Self::new(tick_hz, DEFAULT_OMEGA, DEFAULT_ZETA)
    }

    /// `α` and `β` as fractions.
    pub fn alpha_beta(&self) -> (f64, f64) {
        let f = |q: i32| q as f64 / 2_147_483_648.0;
        (f(self.alpha_q31), f(self.beta_q31))
    }
}

/// The tracker's state: each axis's position estimate (Q24 mm) and velocity (Q24 mm a
/// tick).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VelocityTracker {
    x: [i32; 3],
    w: [i32; 3],
    started: bool,
}

impl VelocityTracker {
    /// At rest, not started: the first reading is taken as it is.
    pub const fn new() -> Self {
        Self {
            x: [0; 3],
            w: [0; 3],
            started: false,
        }
    }

    /// Back to not started (a jump of the probe: homing, a new frame).
    pub fn reset(&mut self) {
        *self = Self::new();
    }

    /// The probe read at `p` this tick: its velocity, mm/s per axis. The first reading
    /// after a start, a reset or a jump gives zero.
    pub fn update(&mut self, gains: &TrackerGains, p: [Length; 3]) -> [Velocity; 3] {
        const SH: u32 = LEN_FRAC - 16;
        let started = self.started;
        self.started = true;
        let p = p.map(Length::to_bits);
        core::array::from_fn(|i| {
            let predicted = self.x[i].saturating_add(self.w[i]);
            let e = p[i].saturating_sub(predicted);
            if !started || e.unsigned_abs() > gains.jump {
                // A start or a jump: from here, at rest.
                self.x[i] = p[i];
                self.w[i] = 0;
                return Velocity::ZERO;
            }
            // |e| ≤ the jump, at most 2²⁹ (`MAX_JUMP`): `2e` fits.
            let step = q::mulhi(e << 1, gains.alpha_q31);
            self.x[i] = predicted.saturating_add(step);
            self.w[i] = self.w[i].saturating_add(q::mulhi(e << 1, gains.beta_q31));
            // The estimate's move this tick, `ŵ + α e`, times the tick rate.
            let moved = self.w[i].saturating_add(step);
            Velocity::from_bits(q::sat(q::mul_wide(moved, gains.tick_hz) >> SH))
        })
    }
}

/// A tracker with its gains: what a contact holds to give the solver the probe's
/// velocity ([`crate::Solver::step_roaming_at`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TrackedVelocity {
    /// The gains.
    pub gains: TrackerGains,
    /// The state.
    pub tracker: VelocityTracker,
}

impl TrackedVelocity {
    /// A tracker with `gains`, not started.
    pub const fn new(gains: TrackerGains) -> Self {
        Self {
            gains,
            tracker: VelocityTracker::new(),
        }
    }

    /// [`VelocityTracker::update`] with its gains.
    #[inline(always)]
    pub fn update(&mut self, p: [Length; 3]) -> [Velocity; 3] {
        self.tracker.update(&self.gains, p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mm(x: f64) -> Length {
        Length::from_num(x)
    }

    #[test]
    fn a_constant_velocity_is_tracked_exactly_once_settled() {
        let g = TrackerGains::default_at(1000).unwrap();
        let mut t = VelocityTracker::new();
        let mut v = [Velocity::ZERO; 3];
        for k in 0..2000 {
            // 25 mm/s along x, −10 along z: 0.025 and −0.010 mm a tick.
            let s = k as f64 / 1000.0;
            v = t.update(&g, [mm(25.0 * s), mm(0.0), mm(-10.0 * s)]);
        }
        assert!((v[0].to_num::<f64>() - 25.0).abs() < 0.01, "{v:?}");
        assert_eq!(v[1], Velocity::ZERO);
        assert!((v[2].to_num::<f64>() + 10.0).abs() < 0.01, "{v:?}");
    }

    #[test]
    fn the_gains_follow_the_poles_and_refuse_an_unstable_loop() {
        let (a, b) = TrackerGains::default_at(1000).unwrap().alpha_beta();
        assert!(
            (a - 0.1306).abs() < 1e-4 && (b - 0.00937).abs() < 1e-4,
            "{a} {b}"
        );
        assert_eq!(
            TrackerGains::new(0, 100.0, 0.7),
            Err(TrackerError::TickRate)
        );
        for (w, z) in [
            (0.0, 0.7),
            (-1.0, 0.7),
            (f64::NAN, 0.7),
            (2000.0, 0.7),
            (100.0, 0.0),
            (100.0, 3.0),
        ] {
            assert_eq!(
                TrackerGains::new(1000, w, z),
                Err(TrackerError::Gains),
                "{w} {z}"
            );
        }
        assert!(TrackerGains::new(1000, 100.0, 1.5).is_ok());
    }

    #[test]
    fn a_jump_starts_again_at_rest_and_a_fast_move_does_not() {
        let g = TrackerGains::default_at(1000).unwrap();
        let mut t = VelocityTracker::new();
        for _ in 0..50 {
            t.update(&g, [mm(0.0); 3]);
        }
        // 2.5 mm in a tick (2.5 m/s): a jump.
        assert_eq!(
            t.update(&g, [mm(2.5), mm(0.0), mm(0.0)]),
            [Velocity::ZERO; 3]
        );
        // 1.5 mm in a tick (1.5 m/s): a motion, read as fast.
        let v = t.update(&g, [mm(4.0), mm(0.0), mm(0.0)]);
        assert!(v[0].to_num::<f64>() > 100.0, "{v:?}");
    }

    #[test]
    fn jumps_and_extremes_saturate_and_never_wrap() {
        let g = TrackerGains::new(1000, 1000.0, 0.7).unwrap();
        let mut t = VelocityTracker::new();
        let ends = [
            Length::MIN,
            Length::MAX,
            Length::ZERO,
            Length::MAX,
            Length::MIN,
        ];
        for k in 0..200 {
            let p = ends[k % ends.len()];
            let v = t.update(&g, [p, Length::MAX, Length::MIN]);
            for x in v {
                // A jump of the whole range reads fast, either way, never the other way
                // round from a wrap.
                assert!(x.to_num::<f64>().abs() <= 32_768.0);
            }
        }
        t.reset();
        assert_eq!(t.update(&g, [Length::MAX; 3]), [Velocity::ZERO; 3]);
    }
}
