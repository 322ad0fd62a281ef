//! Counts to the probe: the joints' phases, their cosines and sines, the forward
//! kinematics in the device frame, the probe in the tissue's frame, the joints' limits.

use super::Arm;
use crate::units::Length;

/// Bit of [`ArmPose::flags`]: joint A outside its range.
pub const LIMIT_A: u8 = 1;
/// Joint B outside its range.
pub const LIMIT_B: u8 = 2;
/// Joint C outside its range.
pub const LIMIT_C: u8 = 4;
/// The probe beyond what `Length` holds in the tissue's frame (±128 mm): held there, and
/// the tissue is not touched.
pub const OUTSIDE: u8 = 8;

/// The arm at one tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ArmPose {
    /// `(cos, sin)` of A, B, C, Q31.
    pub cos_sin: [(i32, i32); 3],
    /// `r = Lb sin B + Lc sin C`, Q20 mm.
    pub reach_q20: i64,
    /// The probe in the device frame, Q24 mm.
    pub device_q24: [i64; 3],
    /// The probe in the tissue's frame (saturated at ±128 mm).
    pub probe: [Length; 3],
    /// [`LIMIT_A`], [`LIMIT_B`], [`LIMIT_C`], [`OUTSIDE`].
    pub flags: u8,
}

impl ArmPose {
    /// The probe in the device frame, mm (for the host and the log).
    pub fn device_mm(&self) -> [f64; 3] {
        self.device_q24.map(|v| v as f64 / (1u64 << 24) as f64)
    }
}

impl Arm {
    /// The arm at joint counts `counts` (A, B, C).
    pub fn pose(&self, counts: [i32; 3]) -> ArmPose {
        let mut cos_sin = [(0i32, 0i32); 3];
        let mut flags = 0u8;
        for k in 0..3 {
            let j = &self.joints[k];
            // The phase from home, wrapping with the angle (a turn is 2³²).
            let from_home = ((counts[k].wrapping_sub(j.home_count) as i64)
                .wrapping_mul(j.phase_per_count)
                >> 16) as i32;
            if from_home < j.min_phase || from_home > j.max_phase {
                flags |= 1 << k;
            }
            let phase = j.home_phase.wrapping_add(from_home as u32);
            // idsp's amplitude is 65,535 · 2¹⁵ = 2³¹ (1 − 2⁻¹⁶): scaled up to Q31 (a
            // bias of 1.5e-5, 7 µm on a 450 mm arm, otherwise).
            let (c, s) = idsp::cossin(phase as i32);
            cos_sin[k] = (c.saturating_add(c >> 16), s.saturating_add(s >> 16));
        }
        let [(ca, sa), (cb, sb), (cc, sc)] = cos_sin.map(|(c, s)| (c as i64, s as i64));
        // Q16 mm × Q31 = Q47: r in Q20, z in Q24.
        let reach_q20 = (self.upper_q16 * sb + self.fore_q16 * sc) >> 27;
        let device_q24 = [
            (reach_q20 * ca) >> 27,
            (reach_q20 * sa) >> 27,
            self.base_q24 + ((self.upper_q16 * cb - self.fore_q16 * cc) >> 23),
        ];
        let mut probe = [Length::ZERO; 3];
        for k in 0..3 {
            let p = device_q24[k] - self.origin_q24[k];
            let held = p.max(i32::MIN as i64).min(i32::MAX as i64);
            if held != p {
                flags |= OUTSIDE;
            }
            probe[k] = Length::from_bits(held as i32);
        }
        ArmPose {
            cos_sin,
            reach_q20,
            device_q24,
            probe,
            flags,
        }
    }
}
