//! [`Thermal`]: each joint's I²t model, and `Heat`, a joint's state in it, which
//! [`super::device::ArmDevice`] runs on every duty it writes.

/// Each joint's I²t model, per tick: the heat `h` (the current's square over the
/// maximum's, Q32) moves toward the duty's square by `α = 1 / (τ f)` a tick; at the
/// continuous current's square the duty is held to the continuous current.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Thermal {
    /// `α`, Q32 (at most 2³⁰: τ f ≥ 4).
    pub alpha_q32: [i64; 3],
    /// The continuous current over the maximum, as a duty, Q16.
    pub limit_q16: [i32; 3],
    /// The heat at which the duty folds back (the limit's square), and below which it
    /// comes back (81 % of that: 0.9 of the current), Q32.
    pub trip_q32: [(i64, i64); 3],
}

impl Thermal {
    /// The model of `spec`'s joints at `tick_hz` (start-up: floating point).
    pub fn of(spec: &mccs::ArmSpec, tick_hz: u32) -> Self {
        let f = tick_hz.max(1) as f64;
        let j = &spec.joints;
        let alpha = |k: usize| {
            let a = 4_294_967_296.0 / (j[k].thermal_time_constant_s * f);
            libm::round(a).clamp(1.0, (1u64 << 30) as f64) as i64
        };
        let limit = |k: usize| {
            let r = j[k].continuous_current_a / j[k].max_current_a;
            libm::round(r * 65_536.0).clamp(1.0, 65_536.0) as i32
        };
        let limit_q16 = [limit(0), limit(1), limit(2)];
        let trip = |l: i32| {
            let t = l as i64 * l as i64;
            (t, libm::round(t as f64 * 0.81) as i64)
        };
        Thermal {
            alpha_q32: [alpha(0), alpha(1), alpha(2)],
            limit_q16,
            trip_q32: limit_q16.map(trip),
        }
    }
}

/// A joint's heat ([`Thermal`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Heat {
    /// The current's square over the maximum's, Q32 (0 … 2³²).
    pub(crate) q32: i64,
    /// Held to the continuous current.
    pub(crate) folded: bool,
}

impl Heat {
    /// One tick at `duty` (Q16, ±65,536) of a joint whose model is `alpha` (Q32), `limit`
    /// (Q16) and `(trip, release)` (Q32): the duty, folded back if the heat says so.
    #[inline(always)]
    pub(crate) fn tick(
        &mut self,
        duty: i32,
        alpha: i64,
        limit: i32,
        (trip, release): (i64, i64),
    ) -> i32 {
        if self.q32 >= trip {
            self.folded = true;
        } else if self.q32 < release {
            self.folded = false;
        }
        // (`max`/`min`, not `clamp`: no panic path, whatever `limit` is.)
        let d = if self.folded {
            duty.max(-limit).min(limit)
        } else {
            duty
        };
        let square = d as i64 * d as i64;
        self.q32 += ((square - self.q32) * alpha) >> 32;
        d
    }
}
