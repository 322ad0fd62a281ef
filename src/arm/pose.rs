//! Counts to the probe: the joints' phases, their cosines and sines, the forward
//! kinematics in the device frame, the probe in the tissue's frame, the joints' limits.

use super::{Arm, Joint};
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

/// The arm at one tick. `repr(C)`: the M4F's pose (`pose_dsp.rs`) stores its fields by
/// their offsets, pairs of them at once.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(C)]
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

impl Joint {
    /// The joint's phase at `count` (full turn), and whether it is outside its range.
    #[inline(always)]
    fn phase(&self, count: i32) -> (u32, bool) {
        let from_home = from_home(count.wrapping_sub(self.home_count), self);
        // Outside `min_phase ..= max_phase`, as one unsigned compare.
        let outside = from_home.wrapping_sub(self.min_phase) as u32 > self.phase_span;
        (self.home_phase.wrapping_add(from_home as u32), outside)
    }
}

/// The phase from home of a count `delta` from it, wrapping with the angle (a turn is
/// 2³²): `delta` times the phase per count (Q16), shifted down 16. As the phase per
/// count's whole part (a wrapping product) and its fraction's (one long product): the
/// same bits as the 64-bit product gives, which takes three (`test_from_home`).
#[inline(always)]
fn from_home(delta: i32, joint: &Joint) -> i32 {
    let fraction = ((delta as i64 * joint.phase_per_count_fraction as i64) >> 16) as i32;
    delta
        .wrapping_mul(joint.phase_per_count_whole)
        .wrapping_add(fraction)
}

/// 128 mm in Q16, the tissue frame's end: the probe is held within `[−HOLD_Q16,
/// HOLD_Q16 − 1]`, `Length`'s own range (one `ssat` on the M3/M4F).
const HOLD_Q16: i32 = 1 << 23;

impl Arm {
    /// The arm at joint counts `counts` (A, B, C). On the M4F in assembly
    /// (`pose_dsp.rs`), bit for bit [`Arm::pose_portable`], which every other core runs.
    pub fn pose(&self, counts: [i32; 3]) -> ArmPose {
        #[cfg(mccs_dsp)]
        return super::pose_dsp::pose(self, &counts);
        #[cfg(not(mccs_dsp))]
        self.pose_portable(counts)
    }

    /// [`Arm::pose`] written into `out`: on the M4F the assembly stores its fields there
    /// (where a returned pose is stored by a copy after it).
    pub fn pose_into(&self, counts: [i32; 3], out: &mut ArmPose) {
        #[cfg(mccs_dsp)]
        super::pose_dsp::pose_into(self, &counts, out);
        #[cfg(not(mccs_dsp))]
        {
            *out = self.pose_portable(counts);
        }
    }

    /// [`Arm::pose`] in portable Rust: what the M3 and M0 (and the host) run, and what
    /// the M4F's assembly must equal (public so that the bench firmware checks it).
    pub fn pose_portable(&self, counts: [i32; 3]) -> ArmPose {
        let mut cos_sin = [(0i32, 0i32); 3];
        let mut flags = 0u8;
        for k in 0..3 {
            let (phase, outside) = self.joints[k].phase(counts[k]);
            cos_sin[k] = super::cos_sin::cos_sin(phase);
            flags |= (outside as u8) << k;
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
            let held = p.clamp(-HOLD_Q16, HOLD_Q16 - 1);
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

#[cfg(test)]
mod test_from_home {
    use super::{from_home, Joint};

    /// [`from_home`] is the 64-bit product's bits 16 … 47, for phases per count of every
    /// magnitude and sign and counts over all of `i32`.
    #[test]
    fn the_split_product_is_the_64_bit_one() {
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        for _ in 0..200_000 {
            let bits = next() % 49;
            let per_count =
                (next() >> (64 - bits.max(1))) as i64 * if next() & 1 == 0 { 1 } else { -1 };
            let delta = next() as i32 >> (next() % 32);
            let joint = Joint {
                phase_per_count_whole: (per_count >> 16) as i32,
                phase_per_count_fraction: (per_count & 0xFFFF) as i32,
                home_phase: 0,
                home_count: 0,
                min_phase: 0,
                phase_span: 0,
                duty_gain: 0,
                duty_up: 1,
                duty_limit: i32::MAX,
                duty_down: 0,
            };
            let wide = ((delta as i64).wrapping_mul(per_count) >> 16) as i32;
            assert_eq!(from_home(delta, &joint), wide, "{delta} × {per_count}");
        }
    }
}
