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
/// Any joint outside its range.
pub const LIMITS: u8 = LIMIT_A | LIMIT_B | LIMIT_C;
/// The probe beyond what `Length` holds in the tissue's frame (±128 mm): held there, and
/// the tissue is not touched.
pub const OUTSIDE: u8 = 8;

/// The arm at one tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ArmPose {
    /// `(cos, sin)` of A, B, C, Q31.
    pub cos_sin: [(i32, i32); 3],
    /// `r = Lb sin B + Lc sin C`, Q17 mm (within ±2,000 mm).
    pub reach_q17: i32,
    /// The probe in the device frame, Q16 mm.
    pub device_q16: [i32; 3],
    /// The probe in the tissue's frame (saturated at ±128 mm).
    pub probe: [Length; 3],
    /// [`LIMIT_A`], [`LIMIT_B`], [`LIMIT_C`], [`OUTSIDE`].
    pub flags: u8,
}

impl ArmPose {
    /// The probe in the device frame, mm (for the host and the log).
    pub fn device_mm(&self) -> [f64; 3] {
        self.device_q16.map(|v| v as f64 / 65_536.0)
    }
}

/// The high word of a 32 × 32-bit product, `⌊a b / 2³²⌋`: the core's one
/// [`crate::q::mulhi`] (one `smull` on the M3/M4F, four 16-bit products on the M0).
pub(super) use crate::q::mulhi as hi;

/// 128 mm in Q16, the tissue frame's end.
const HOLD_Q16: i32 = (1 << 23) - 1;

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
            // (idsp's amplitude, 2³¹ (1 − 2⁻¹⁶), is folded into the lengths.)
            cos_sin[k] = idsp::cossin(phase as i32);
        }
        let [(ca, sa), (cb, sb), (cc, sc)] = cos_sin;
        // Q18 mm × Q31 / 2³² = Q17; Q17 × Q31 / 2³² = Q16.
        let reach_q17 = hi(self.upper_q18, sb) + hi(self.fore_q18, sc);
        let device_q16 = [
            hi(reach_q17, ca),
            hi(reach_q17, sa),
            self.base_q16 + hi(self.upper_q17, cb) - hi(self.fore_q17, cc),
        ];
        let mut probe = [Length::ZERO; 3];
        for k in 0..3 {
            let p = device_q16[k] - self.origin_q16[k];
            let held = p.clamp(-HOLD_Q16, HOLD_Q16);
            if held != p {
                flags |= OUTSIDE;
            }
            probe[k] = Length::from_bits(held << 8);
        }
        ArmPose {
            cos_sin,
            reach_q17,
            device_q16,
            probe,
            flags,
        }
    }
}
