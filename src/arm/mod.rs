//! A serial RRR arm (WoodenHaptics, Phantom Premium and their clones) as the haptic
//! device: joint counts to the probe in the tissue's frame, and the tissue's force to the
//! motors' duties, in fixed point, per tick, constant time (docs/arm.md draws the
//! convention).
//!
//! # The convention
//! - Joint angles from counts: `θᵢ = home_angleᵢ + signᵢ · 2π (countᵢ − home_countᵢ) /
//!   (counts_per_revᵢ · ratioᵢ)` (`counts_per_rev` per motor turn after ×4 quadrature,
//!   `ratio` motor turns per joint turn).
//! - A is the base's yaw; B the upper arm from vertical up; C the forearm from vertical
//!   down; both forward-positive.
//! - Forward kinematics, device frame, mm (origin on the base's axis, `z` up):
//!   `r = Lb sin B + Lc sin C`, `x = r cos A`, `y = r sin A`, `z = Ln + Lb cos B − Lc cos C`.
//! - The tissue's frame is the device frame translated by `tissue_origin_mm`.
//! - Torques `τ = Jᵀ F` (F in N in the tissue's frame) plus gravity compensation
//!   `∂U/∂θ`, `U` the potential of the upper arm's and forearm's masses at their
//!   centres of mass: `∂U/∂B = −g sin B (m_b c_b + m_c Lb)`, `∂U/∂C = g m_c c_c sin C`.
//! - Motor: `current = sign · τ / (ratio · Kt)`, `duty = current / max_current`; when any
//!   `|duty|` would pass 1, all three are scaled by the same factor, so that the force
//!   keeps its direction.
//!
//! # Fixed point
//! Every product is of two 32-bit operands, most kept as their high word (one long
//! multiply, `smmul` on the M4F). Angles are full-turn phases (`u32`, 2³² a turn);
//! `cos`/`sin` come from a table of 1,024 points and linear interpolation
//! ([`cos_sin`]: Q31 less 2.4e-7, which the lengths make up; 5e-6 at most from the true
//! values); lengths are Q17/Q18 mm, the device-frame position Q16 mm, the
//! tissue-frame probe the core's `Length`
//! (Q24 mm, ±128 mm, saturated), torques Q8 N·mm, duties Q16 (65,536 = 100 %). Every
//! constant that divides is folded into a gain when the arm is made ([`Arm::new`]); the
//! tick ([`Arm::pose`], [`Arm::drive`]) multiplies and shifts, and scales the duties by a
//! reciprocal found by Newton's iteration ([`recip`]).

/// `asm!` for the M4F's pose and drive (`pose_dsp.rs`, `drive_dsp.rs`): the operands
/// given, then the joints' byte offsets in the arm (`joint_a`, `joint_b`, `joint_c`) and
/// the registers both blocks write (r4, r5, r8–r12, lr; their own inputs in r0–r3), with
/// no stack.
#[cfg(mccs_dsp)]
macro_rules! arm_asm {
    ($($operands:tt)*) => {
        asm_writing_r4_to_lr!(
            options(nostack);
            $($operands)*
            joint_a = const core::mem::offset_of!($crate::arm::Arm, joints),
            joint_b = const core::mem::offset_of!($crate::arm::Arm, joints)
                + core::mem::size_of::<$crate::arm::Joint>(),
            joint_c = const core::mem::offset_of!($crate::arm::Arm, joints)
                + 2 * core::mem::size_of::<$crate::arm::Joint>(),
        )
    };
}

pub mod cos_sin;
mod drive;
#[cfg(mccs_dsp)]
mod drive_dsp;
pub mod inverse;
mod pose;
#[cfg(mccs_dsp)]
mod pose_dsp;
pub mod recip;
mod spec;
pub mod stable_region;

pub use drive::Drive;
pub use pose::{ArmPose, LIMITS, LIMIT_A, LIMIT_B, LIMIT_C, OUTSIDE};
pub use spec::{ArmError, ArmFieldError, ArmSpec, GravitySpec, JointSpec};

/// A full turn in phase units (2³²), as `f64`.
const TURN: f64 = 4_294_967_296.0;

/// `k` (Q16 duty per Q8 N·mm, sign included) as `(gain, up, down)` with `k ≈ gain ·
/// 2^(up − down − 32)`, `|gain|` in `[2³⁰, 2³¹)` (31 bits), `up` ≤ 30 and `down` ≤ 31,
/// one of them 0. Past those ends (`|k|` ≥ 2²⁹ or < 2⁻³³: no motor's) the gain is held
/// at its end: every duty then saturates, or is within a quarter of its last bit of 0.
fn duty_gain(k: f64) -> (i32, u32, u32) {
    let (mut g, mut e) = (k.abs() * TURN, 0i32);
    while g >= TURN / 2.0 && e < 30 {
        g /= 2.0;
        e += 1;
    }
    while g < TURN / 4.0 && e > -31 {
        g *= 2.0;
        e -= 1;
    }
    let g = libm::round(g).min(i32::MAX as f64) * k.signum();
    (g as i32, e.max(0) as u32, (-e).max(0) as u32)
}

/// One joint's gains, from its [`JointSpec`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Joint {
    /// The angle at the home count, full-turn phase.
    home_phase: u32,
    /// The home count.
    home_count: i32,
    /// Phase per count (sign included) as `whole + fraction / 2¹⁶`: `whole` its floor
    /// (wrapping: a count's phase is taken modulo a turn), `fraction` in `[0, 2¹⁶)`.
    phase_per_count_whole: i32,
    phase_per_count_fraction: i32,
    /// The joint's range, phases relative to home (signed): from `min_phase`, `phase_span`
    /// more.
    min_phase: i32,
    phase_span: u32,
    /// Duty (Q16) per torque (Q8 N·mm): `⌊τ · gain / 2³²⌋`, saturated times `2^up`,
    /// then shifted down `duty_down` (one of `up` and `duty_down` is 0): `|gain|` in
    /// `[2³⁰, 2³¹)` but where the shifts reach their ends ([`duty_gain`]). `2^up` is
    /// held as `duty_up`, a factor, and `i32::MAX >> up` as `duty_limit`, the high word's
    /// largest that the factor keeps in `i32`.
    duty_gain: i32,
    duty_up: i32,
    duty_limit: i32,
    duty_down: u32,
}

/// An arm, its constants folded into gains (start-up code: floating point).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Arm {
    joints: [Joint; 3],
    /// `Ln`, Q16 mm.
    base_q16: i32,
    /// `Lb`, `Lc`, Q18 mm (for the reach, Q17) and Q17 mm (for the height, Q16); ≤ 1,000
    /// mm: each product's high word is the value (one long multiply).
    upper_q18: i32,
    fore_q18: i32,
    upper_q17: i32,
    fore_q17: i32,
    /// The tissue's origin in the device frame, Q16 mm.
    origin_q16: [i32; 3],
    /// Gravity: `g (m_b c_b + m_c Lb)` and `g m_c c_c`, Q16 N·mm (< 32,768 N·mm).
    gravity_b_q16: i32,
    gravity_c_q16: i32,
}

impl Arm {
    /// The joints' counts at the home pose.
    pub fn home_counts(&self) -> [i32; 3] {
        self.joints.map(|j| j.home_count)
    }

    /// The arm of `spec`, checked ([`ArmSpec::validate`]).
    pub fn new(spec: &ArmSpec) -> Result<Arm, ArmError> {
        spec.validate()?;
        let joint = |j: &JointSpec| {
            let per_turn = j.counts_per_rev * j.ratio;
            let phase = |deg: f64| libm::round(deg / 360.0 * TURN);
            // Q16 duty per Q8 N·mm: sign / (ratio · Kt · Imax · 1000 N·mm per N·m), then
            // raised to 2²⁰ … 2²¹ with a shift, for the product's precision.
            let k = j.sign / (j.ratio * j.torque_constant_nm_per_a * j.max_current_a * 1000.0);
            let (duty_gain, duty_up, duty_down) = duty_gain(k * 256.0);
            let phase_per_count = libm::round(j.sign * TURN * 65_536.0 / per_turn) as i64;
            Joint {
                home_phase: phase(j.home_angle_deg) as i64 as u32,
                home_count: j.home_count,
                phase_per_count_whole: (phase_per_count >> 16) as i32,
                phase_per_count_fraction: (phase_per_count & 0xFFFF) as i32,
                min_phase: phase(j.min_angle_deg - j.home_angle_deg) as i32,
                phase_span: (phase(j.max_angle_deg - j.home_angle_deg) as i32)
                    .wrapping_sub(phase(j.min_angle_deg - j.home_angle_deg) as i32)
                    as u32,
                duty_gain,
                duty_up: 1 << duty_up,
                duty_limit: i32::MAX >> duty_up,
                duty_down,
            }
        };
        let q = |mm: f64, bits: u32| libm::round(mm * (1u64 << bits) as f64) as i64;
        // The table's cos and sin have the amplitude 2³¹ − 512 (`cos_sin::AMPLITUDE`), not
        // 2³¹: a length that multiplies one of them is raised by its inverse, the reach's
        // (x and y multiply two) by its square. The torques' 2.4e-7 is left (their bound
        // is 0.5 %).
        let amp = 1.0 / cos_sin::AMPLITUDE;
        let g = spec.gravity.unwrap_or(GravitySpec::NONE);
        Ok(Arm {
            joints: [
                joint(&spec.joints[0]),
                joint(&spec.joints[1]),
                joint(&spec.joints[2]),
            ],
            base_q16: q(spec.base_height_mm, 16) as i32,
            upper_q18: q(spec.upper_arm_mm * amp * amp, 18) as i32,
            fore_q18: q(spec.forearm_mm * amp * amp, 18) as i32,
            upper_q17: q(spec.upper_arm_mm * amp, 17) as i32,
            fore_q17: q(spec.forearm_mm * amp, 17) as i32,
            origin_q16: spec.tissue_origin_mm.map(|v| q(v, 16) as i32),
            gravity_b_q16: q(
                g.g * (g.upper_arm_mass_kg * g.upper_arm_com_mm
                    + g.forearm_mass_kg * spec.upper_arm_mm),
                16,
            ) as i32,
            gravity_c_q16: q(g.g * g.forearm_mass_kg * g.forearm_com_mm, 16) as i32,
        })
    }
}

#[cfg(test)]
mod test_duty_gain {
    use super::{duty_gain, TURN};

    /// Every gain from 2⁻³³ to 2²⁹ (each sign) is held to 31 bits: `|gain|` in `[2³⁰,
    /// 2³¹)`, one shift 0, `gain · 2^(up − down − 32)` within 2⁻³⁰ of it; past the ends the
    /// gain is held there.
    #[test]
    fn each_gain_keeps_31_bits_and_its_ends_hold() {
        for e in -33..29 {
            for f in [1.0, 1.1, 1.5, 1.999_999_999] {
                for sign in [1.0, -1.0] {
                    let k = sign * f * libm::exp2(e as f64);
                    let (g, up, down) = duty_gain(k);
                    assert!(up == 0 || down == 0, "{k}");
                    assert!(up <= 30 && down <= 31, "{k}");
                    let m = g.unsigned_abs() as f64;
                    assert!((TURN / 4.0..TURN / 2.0).contains(&m), "{k}: {g}");
                    let back = g as f64 * libm::exp2(up as f64 - down as f64 - 32.0);
                    assert!(((back - k) / k).abs() <= libm::exp2(-30.0), "{k}: {back}");
                }
            }
        }
        assert_eq!(duty_gain(libm::exp2(40.0)), (i32::MAX, 30, 0));
        assert_eq!(duty_gain(-libm::exp2(-70.0)), (0, 0, 31));
    }
}
