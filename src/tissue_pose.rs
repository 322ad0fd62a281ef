//! [`TissuePose`]: where a tissue lies in the device's frame — its origin and rotation —
//! and how the tick moves it toward where a host asked, at bounded speed, in fixed
//! point: a point `p` of the tissue's frame is at `origin + R p` in the device's frame,
//! so the probe is read into the tissue's frame as `Rᵀ (probe − origin)` and the force
//! the tissue returns is rendered as `R f`. A tilted organ surface then pushes along its
//! own normal.
//!
//! Per tick ([`TissuePose::step`]): each axis of the origin moves toward its target by
//! at most the step a tick allows (the speed limit, per axis); the rotation's unit
//! quaternion moves toward its target by the chord a tick allows (a rotation of `θ` is a
//! chord `s = 2 sin(θ/4)` between unit quaternions), then is renormalised (two Newton
//! steps: `|q|²` within `7 s⁴` of 1, and Q30's rounding, 2e-8; the push back onto the
//! sphere makes the chord at most a relative `s²/4` longer), and the matrix is rebuilt
//! from it. At the board's 180°/s and 1 kHz (`s` = 1.6e-3) that is 2e-8 and 6e-7; at
//! 13.6° a tick (2,714°/s at 200 Hz) a force's size is off by 1.4e-3. The bounds are
//! held over arbitrary targets, rates and half turns by `tests/tissue_pose.rs`. No division,
//! one reciprocal square root ([`crate::q`]'s, 2e-8) when the rotation moves, none when
//! it holds; the unrotated pose skips the matrix.
//!
//! Formats: origin Q24 mm, quaternion and matrix Q30, forces Q20 N.

use crate::q::{self, V3};
use crate::units::{Force, Length, LEN_FRAC};

/// A quaternion's or the matrix's fraction bits.
pub const QUAT_FRAC: u32 = 30;
const ONE: i32 = 1 << QUAT_FRAC;
const IDENTITY_Q: [i32; 4] = [ONE, 0, 0, 0];
const IDENTITY_R: [[i32; 3]; 3] = [[ONE, 0, 0], [0, ONE, 0], [0, 0, ONE]];

/// Whether `q` (Q30) is a unit quaternion within 2⁻¹⁰ of its squared norm: what a pose
/// from a host must be ([`TissuePose::set_target`] makes it unit to Q30's rounding). Any
/// four `i32`s: the squares in `u64`, their sum saturated (four of `i32::MIN` make 2⁶⁴;
/// summed in `i64`, `[MIN, MIN, 2³⁰, 0]` wrapped to a difference of `i64::MIN`, whose
/// `abs` passed it as a unit).
pub fn is_unit(q: [i32; 4]) -> bool {
    let n2 = q.iter().fold(0u64, |s, &c| {
        let a = c.unsigned_abs() as u64;
        s.saturating_add(a * a)
    });
    n2.abs_diff(1u64 << 60) <= 1u64 << 50
}

/// `q (3 − |q|²)/2`: one Newton step toward unit length, for a `q` within 2⁻¹⁰ of it
/// (`|q|²` in `i64` below 2⁶¹; the factor below 2³¹; each product below 2⁶²).
fn renormalised(q: [i32; 4]) -> [i32; 4] {
    let n2: i64 = q.iter().map(|&c| c as i64 * c as i64).sum();
    let f = ((3i64 << 60) - n2) >> (QUAT_FRAC + 1);
    q.map(|c| ((c as i64 * f) >> QUAT_FRAC) as i32)
}

/// A tissue's pose in the device's frame, moving toward a target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TissuePose {
    origin: V3,
    target_origin: V3,
    q: [i32; 4],
    target_q: [i32; 4],
    r: [[i32; 3]; 3],
    rotated: bool,
    /// The largest move of each axis of the origin a tick, Q24 mm.
    max_step: i32,
    /// The largest chord between the quaternion before and after a tick, Q30.
    max_chord: i32,
}

impl TissuePose {
    /// At the device's origin, unrotated; moving at most `speed_mm_s` per axis and
    /// `turn_deg_s` at `tick_hz` (start-up: `f64`).
    pub fn new(speed_mm_s: f64, turn_deg_s: f64, tick_hz: f64) -> Self {
        let step = crate::units::from_f64(speed_mm_s / tick_hz, LEN_FRAC).max(1);
        let theta = (turn_deg_s / tick_hz).to_radians();
        let chord = crate::units::from_f64(2.0 * libm::sin(theta / 4.0), QUAT_FRAC).max(1);
        Self {
            origin: [0; 3],
            target_origin: [0; 3],
            q: IDENTITY_Q,
            target_q: IDENTITY_Q,
            r: IDENTITY_R,
            rotated: false,
            max_step: step,
            max_chord: chord,
        }
    }

    /// Where to move: an origin (Q24 mm) and a unit quaternion (Q30, [`is_unit`]: the
    /// caller checks it; one that is not leaves the target's rotation as it was). The
    /// nearer of `q` and `−q` (the same rotation) is taken, and made unit to Q30's
    /// rounding (two Newton steps): `is_unit` takes `|q|²` within 2⁻¹⁰ of 1, and the
    /// matrix of such a quaternion, reached as it was sent, scaled a force by as much
    /// (a roaming force past its clamp by 0.5 mN in 3 N: found by
    /// `tests/link/any_run.rs`).
    pub fn set_target(&mut self, origin: V3, rotation: [i32; 4]) {
        self.target_origin = origin;
        let dot: i64 = (0..4).map(|k| self.q[k] as i64 * rotation[k] as i64).sum();
        let q = if dot < 0 {
            rotation.map(|c| c.saturating_neg())
        } else {
            rotation
        };
        if is_unit(q) {
            self.target_q = renormalised(renormalised(q));
        }
    }

    /// The origin now, Q24 mm.
    pub fn origin(&self) -> V3 {
        self.origin
    }

    /// The rotation now, Q30.
    pub fn rotation(&self) -> [i32; 4] {
        self.q
    }

    /// Whether the pose has reached its target.
    pub fn settled(&self) -> bool {
        self.origin == self.target_origin && self.q == self.target_q
    }

    /// One tick's move toward the target.
    pub fn step(&mut self) {
        for k in 0..3 {
            let d = self.target_origin[k].saturating_sub(self.origin[k]);
            // (Not `clamp`, which asserts its bounds: a panic path in the tick.)
            self.origin[k] =
                self.origin[k].saturating_add(d.max(-self.max_step).min(self.max_step));
        }
        if self.q == self.target_q {
            return;
        }
        let d: [i32; 4] = core::array::from_fn(|k| self.target_q[k].saturating_sub(self.q[k]));
        let d2: i64 = d.iter().map(|&c| c as i64 * c as i64).sum();
        let s = self.max_chord as i64;
        if d2 <= s * s {
            self.q = self.target_q;
        } else {
            // λ = s / |d| in Q30 (below 1): s · y · 2^(e/2 − 62) · 2^30.
            let (y, e) = q::rsqrt(d2);
            let lambda = ((self.max_chord as u64 * y as u64) >> (32 - e / 2)) as i64;
            for k in 0..4 {
                let m = (d[k] as i64 * lambda) >> QUAT_FRAC;
                self.q[k] = self.q[k].saturating_add(m as i32);
            }
            // A step moves the quaternion up to `s sin(β/2)` inside the sphere (β its arc
            // to the target): n² within 1 − 2 s; two Newton steps bring it within 7 s⁴.
            self.q = renormalised(renormalised(self.q));
        }
        self.rebuild();
    }

    /// The matrix of the quaternion now.
    fn rebuild(&mut self) {
        let [w, x, y, z] = self.q;
        // 2ab in Q30: a b / 2²⁹, in `i64`: `2a²` alone is 2³¹ for a component of ±1 (a
        // half turn about an axis), past an `i32`, where the entry it makes,
        // `1 − 2a² − 2b²`, is −1. Every entry is within ±1 (+ rounding): it fits.
        let p = |a: i32, b: i32| (a as i64 * b as i64) >> (QUAT_FRAC - 1);
        let one = ONE as i64;
        let e = |v: i64| v as i32;
        self.r = [
            [
                e(one - p(y, y) - p(z, z)),
                e(p(x, y) - p(w, z)),
                e(p(x, z) + p(w, y)),
            ],
            [
                e(p(x, y) + p(w, z)),
                e(one - p(x, x) - p(z, z)),
                e(p(y, z) - p(w, x)),
            ],
            [
                e(p(x, z) - p(w, y)),
                e(p(y, z) + p(w, x)),
                e(one - p(x, x) - p(y, y)),
            ],
        ];
        self.rotated = self.q != IDENTITY_Q;
    }

    /// A point of the device's frame in the tissue's: `Rᵀ (p − origin)`.
    pub fn to_tissue(&self, p: [Length; 3]) -> [Length; 3] {
        let d: V3 = core::array::from_fn(|k| p[k].to_bits().saturating_sub(self.origin[k]));
        if !self.rotated {
            return d.map(Length::from_bits);
        }
        core::array::from_fn(|i| {
            let s: i64 = (0..3).map(|j| self.r[j][i] as i64 * d[j] as i64).sum();
            Length::from_bits(q::sat(s >> QUAT_FRAC))
        })
    }

    /// A force of the tissue's frame in the device's: `R f`.
    pub fn to_device(&self, f: [Force; 3]) -> [Force; 3] {
        if !self.rotated {
            return f;
        }
        let b = f.map(Force::to_bits);
        core::array::from_fn(|i| {
            let s: i64 = (0..3).map(|j| self.r[i][j] as i64 * b[j] as i64).sum();
            Force::from_bits(q::sat(s >> QUAT_FRAC))
        })
    }
}
