//! [`Arm::drive`]'s every-tick part in Armv7E-M assembly (the Cortex-M4F's `smmul`,
//! `smmla`, `smull`, `qadd`, `qsub`), bit for bit the portable [`Arm::drive_portable`],
//! which every other core runs and against which the bench firmware checks this on
//! random poses and forces before it measures (`firmware/src/bin/bench/arm_check.rs`).
//! The rare part, the three duties scaled to fit when one passes 100 %, stays Rust
//! (`scale_to_full`, on the flag this returns).
//!
//! Why assembly: the compiler's drive spilled about ten of its loads to the stack and
//! back and masked each duty's shift (about 20 of its 125 instructions;
//! docs/experiments/performance.md, "The arm's pose and drive in assembly").
//!
//! The arithmetic is [`Arm::drive_portable`]'s, step for step; its comments give the
//! formats and ranges. One step differs in form, not in bits: a duty's saturating
//! product by `2^up` is checked by the 64-bit product's high word (the product overflows
//! 32 bits exactly when its high word is not the low word's sign), where the portable
//! code compares against the stored limit. The torques' saturating sums (`qsub`,
//! `qadd`, as the portable `saturating_add`) are never reached by an arm `ArmSpec`
//! allows: its torques stay within ±1.6·10⁹ (Q8 N·mm) at 1,000 mm links, gravity near its
//! limit and all of `Force`'s range, against `i32`'s ±2.1·10⁹ (`host-tests/tests/arm.rs`,
//! `the_torques_never_reach_their_saturation`): no check can tell them from plain sums.

use super::{Arm, ArmPose, Drive, Joint};
use crate::units::Force;
use core::mem::offset_of;

// The duty's parameters are read by one `ldm`: gain, up, limit, down in this order.
const _: () = {
    let gain = offset_of!(Joint, duty_gain);
    assert!(offset_of!(Joint, duty_up) == gain + 4);
    assert!(offset_of!(Joint, duty_limit) == gain + 8);
    assert!(offset_of!(Joint, duty_down) == gain + 12);
    assert!(offset_of!(Drive, torque_q8) % 4 == 0 && offset_of!(Drive, duty_q16) % 4 == 0);
};

/// One joint's duty from its torque in `$t`: `hi(torque, gain)`, times `2^up` held to
/// `i32`, shifted down `down`, stored at byte `$k` of the duties; its offset value
/// `duty + 100 %` left in r4. `$j` is the joint's byte offset in the arm. Reads r0 (the
/// arm), r3 (the drive); writes r4, r5, r8, r9.
macro_rules! duty {
    ($t:literal, $j:literal, $k:literal) => {
        concat!(
            "add r4, r0, #(",
            $j,
            " + {gain})\n",
            "ldm r4, {{r4, r5, r8, r9}}\n",
            "smmul r4, ",
            $t,
            ", r4\n",
            // m · 2^up, and where it overflows 32 bits, i32::MAX or MIN by m's sign
            // (the high word's).
            "smull r5, r8, r4, r5\n",
            "cmp r8, r5, asr #31\n",
            "itt ne\n",
            "mvnne r5, r8, asr #31\n",
            "eorne r5, r5, #0x80000000\n",
            "asr r5, r5, r9\n",
            "str r5, [r3, #({duty} + ",
            $k,
            ")]\n",
            "add r4, r5, #0x10000\n",
        )
    };
}

/// Joint B's or C's torque into `$out`: `($len · (hi(c, u) $op hi(s, fz))) >> 26` and
/// `hi($gravity, s) >> 7` joined by `$sat` (`qsub` for B, whose term is the negative,
/// `qadd` for C), its `(cos, sin)` at byte `$cs` of the pose's. Reads r0 (the arm), r1
/// (the pose), r2 (u), lr (fz); writes r4, r5, r8, r9.
macro_rules! upper_joint {
    ($cs:literal, $op:literal, $len:literal, $gravity:literal, $sat:literal, $out:literal) => {
        concat!(
            "ldrd r8, r9, [r1, #({cs} + ",
            $cs,
            ")]\n",
            "smmul r4, r8, r2\n",
            "smmul r5, r9, lr\n",
            $op,
            " r4, r4, r5\n",
            "ldr r5, [r0, #",
            $len,
            "]\n",
            "smull r4, r5, r5, r4\n",
            "lsr r4, r4, #26\n",
            "orr r4, r4, r5, lsl #6\n",
            "ldr r5, [r0, #",
            $gravity,
            "]\n",
            "smmul r5, r5, r9\n",
            "asr r5, r5, #7\n",
            $sat,
            " ",
            $out,
            ", r4, r5\n",
        )
    };
}

/// `Jᵀ F` plus gravity, the three torques and duties into `out`; whether any duty passes
/// 100 % (then `out`'s duties are to be scaled).
#[inline(always)]
#[allow(unsafe_code)]
pub(super) fn torques_and_duties(
    arm: &Arm,
    pose: &ArmPose,
    force: &[Force; 3],
    out: &mut Drive,
) -> bool {
    let most: u32;
    // SAFETY: reads `arm`, `pose` and `force` at the offsets given by `offset_of!` (the
    // duty's four parameters one `ldm`, asserted above); writes `out`'s torques and
    // duties and nothing else. Every register it writes is declared (here and by
    // `arm_asm!`); the stack is untouched.
    unsafe {
        arm_asm!(
            // F in Q19 N (x, y) and Q18 N (z), in r4, r5, lr.
            "ldm r2, {{r4, r5, lr}}",
            "asr r4, r4, #1",
            "asr r5, r5, #1",
            "asr lr, lr, #2",
            // u = hi(cA, fx) + hi(sA, fy) in r2; v = hi(cA, fy) − hi(sA, fx) in r10.
            "ldrd r8, r9, [r1, #{cs}]",
            "smmul r2, r8, r4",
            "smmla r2, r9, r5, r2",
            "smmul r10, r8, r5",
            "smmul r11, r9, r4",
            "sub r10, r10, r11",
            // A: (reach · v) >> 27, in r12 (its gravity is 0).
            "ldr r11, [r1, #{reach}]",
            "smull r8, r9, r11, r10",
            "lsr r8, r8, #27",
            "orr r12, r8, r9, lsl #5",
            // B: (upper · (hi(cB, u) − hi(sB, fz))) >> 26, less hi(gravity_b, sB) >> 7
            // saturating, in r11; C: (fore · (hi(cC, u) + hi(sC, fz))) >> 26, plus
            // hi(gravity_c, sC) >> 7 saturating, in r10.
            upper_joint!("8", "sub", "{upper_q17}", "{gravity_b}", "qsub", "r11"),
            upper_joint!("16", "add", "{fore_q17}", "{gravity_c}", "qadd", "r10"),
            "strd r12, r11, [r3, #{torque}]",
            "str r10, [r3, #({torque} + 8)]",
            // The duties; the largest offset value (unsigned) in r1.
            duty!("r12", "{joint_a}", "0"),
            "mov r1, r4",
            duty!("r11", "{joint_b}", "4"),
            "cmp r4, r1",
            "it hi",
            "movhi r1, r4",
            duty!("r10", "{joint_c}", "8"),
            "cmp r4, r1",
            "it hi",
            "movhi r1, r4",
            cs = const offset_of!(ArmPose, cos_sin),
            reach = const offset_of!(ArmPose, reach_q17),
            upper_q17 = const offset_of!(Arm, upper_q17),
            fore_q17 = const offset_of!(Arm, fore_q17),
            gravity_b = const offset_of!(Arm, gravity_b_q16),
            gravity_c = const offset_of!(Arm, gravity_c_q16),
            gain = const offset_of!(Joint, duty_gain),
            torque = const offset_of!(Drive, torque_q8),
            duty = const offset_of!(Drive, duty_q16),
            in("r0") core::ptr::from_ref(arm),
            inout("r1") core::ptr::from_ref(pose) => most,
            inout("r2") force.as_ptr() => _,
            in("r3") core::ptr::from_mut(out),
        );
    }
    most > 2 * super::drive::FULL_DUTY_Q16 as u32
}
