//! [`Arm::pose`] in Armv7E-M assembly (the Cortex-M4F's `smmul`, `smmla`, `ssat`), bit for
//! bit the portable [`Arm::pose_portable`], which every other core runs and against which
//! the bench firmware checks this on random counts before it measures
//! (`firmware/src/bin/bench/arm_check.rs`; the arm demo's duties, equal to the host's run,
//! check it again end to end).
//!
//! Why assembly: the compiler's pose kept the joints' limit checks for after the three
//! `cos`/`sin` calls (their loads ahead of each call, as the call might write memory, and
//! spilled across it), and inlining the calls spilled the six values instead (the M4F's
//! chain 331 and 334 instructions; docs/experiments/performance.md, "The arm's pose and
//! drive in assembly"). Here each joint runs start to end in five scratch registers: its phase,
//! its limit check, its `cos`/`sin` from the table, stored, and its share of the forward
//! kinematics kept in a register (B's and C's in the reach and the height, A's last).
//!
//! The arithmetic is [`Arm::pose_portable`]'s and [`super::cos_sin::cos_sin`]'s, step for
//! step; their comments give the formats and ranges. Every sum wraps, as theirs do in
//! the release build.

use super::cos_sin::SINE;
use super::{Arm, ArmPose, Joint};
use core::mem::{offset_of, MaybeUninit};

// OUTSIDE is the flag's bit 3, where the Q flag's read puts it.
const _: () = assert!(super::pose::OUTSIDE == 1 << 3);
// The stores pair words (`strd`), which needs each pair's layout: `(cos, sin)` as two
// consecutive words, and `reach_q17` then `device_q16` (`ArmPose` is `repr(C)`).
const _: () = assert!(offset_of!((i32, i32), 0) == 0 && offset_of!((i32, i32), 1) == 4);
const _: () = assert!(offset_of!(ArmPose, device_q16) == offset_of!(ArmPose, reach_q17) + 4);

/// One joint's part: its phase from its count, its limit check (bit `$bit` of the flags
/// in r11), its `cos`/`sin` at byte offset `$cs` of the pose, left in r8 and r3. `$j` is
/// the joint's byte offset in the arm, `$count` its count's in the counts. Reads r0 (the
/// arm), r1 (the counts), r2 (the pose), r12 (the table); writes r3–r5, r8, r9.
macro_rules! joint {
    ($j:literal, $count:literal, $bit:literal, $cs:literal) => {
        concat!(
            // delta = count − home_count; from_home = delta · whole + (delta · fraction) >> 16
            "ldr r3, [r1, #",
            $count,
            "]\n",
            "ldr r4, [r0, #(",
            $j,
            " + {home_count})]\n",
            "sub r3, r3, r4\n",
            "ldr r4, [r0, #(",
            $j,
            " + {fraction})]\n",
            "smull r4, r5, r3, r4\n",
            "lsr r4, r4, #16\n",
            "orr r4, r4, r5, lsl #16\n",
            "ldr r5, [r0, #(",
            $j,
            " + {whole})]\n",
            "mla r4, r3, r5, r4\n",
            // outside: (from_home − min_phase) as u32 > phase_span
            "ldr r5, [r0, #(",
            $j,
            " + {min_phase})]\n",
            "sub r5, r4, r5\n",
            "ldr r3, [r0, #(",
            $j,
            " + {phase_span})]\n",
            "cmp r5, r3\n",
            "it hi\n",
            "orrhi r11, r11, #",
            $bit,
            "\n",
            // phase = home_phase + from_home; the point k = phase >> 22, within it 15 bits
            "ldr r5, [r0, #(",
            $j,
            " + {home_phase})]\n",
            "add r4, r4, r5\n",
            "lsr r5, r4, #22\n",
            "ubfx r4, r4, #7, #15\n",
            "add r5, r12, r5, lsl #2\n",
            // sin = S[k] + ((((S[k+1] − S[k]) >> 8) · within) >> 7), in r3
            "ldrd r3, r8, [r5]\n",
            "sub r8, r8, r3\n",
            "asr r8, r8, #8\n",
            "mul r8, r8, r4\n",
            "add r3, r3, r8, asr #7\n",
            // cos the same a quarter turn on (256 points, 1,024 bytes), in r8
            "ldr r8, [r5, #1024]\n",
            "ldr r9, [r5, #1028]\n",
            "sub r9, r9, r8\n",
            "asr r9, r9, #8\n",
            "mul r9, r9, r4\n",
            "add r8, r8, r9, asr #7\n",
            "strd r8, r3, [r2, #(",
            $cs,
            ")]\n",
        )
    };
}

/// The probe's axis at byte offset `$k` of the device frame (its value in `$reg`): less
/// the origin, held to ±2²³ (Q16: ±128 mm) by `ssat`, which sets the sticky Q flag where
/// that changed it (cleared at the start, read into [`super::pose::OUTSIDE`] at the end),
/// shifted to the core's `Length` (Q24) and stored.
macro_rules! probe_axis {
    ($reg:literal, $k:literal) => {
        concat!(
            "ldr r3, [r0, #({origin} + ",
            $k,
            ")]\n",
            "sub r3, ",
            $reg,
            ", r3\n",
            "ssat r4, #24, r3\n",
            "lsl r4, r4, #8\n",
            "str r4, [r2, #({probe} + ",
            $k,
            ")]\n",
        )
    };
}

/// [`Arm::pose_portable`] in assembly, written into `out` (the caller's pose, with no
/// copy after).
#[inline(always)]
#[allow(unsafe_code)]
pub(super) fn pose_into(arm: &Arm, counts: &[i32; 3], out: &mut ArmPose) {
    // SAFETY: `out` is a pose, valid for writes.
    unsafe { write(arm, counts, out) }
}

/// [`Arm::pose_portable`] in assembly.
#[inline(always)]
#[allow(unsafe_code)]
pub(super) fn pose(arm: &Arm, counts: &[i32; 3]) -> ArmPose {
    let mut pose = MaybeUninit::<ArmPose>::uninit();
    // SAFETY: `write` writes every field of the pose.
    unsafe {
        write(arm, counts, pose.as_mut_ptr());
        pose.assume_init()
    }
}

/// The pose at `counts` written into `*out`.
///
/// # Safety
/// `out` must be valid for writes of an [`ArmPose`].
#[inline(always)]
#[allow(unsafe_code)]
unsafe fn write(arm: &Arm, counts: &[i32; 3], out: *mut ArmPose) {
    // SAFETY: reads `arm`, `counts` and the table `SINE` (at the index `phase >> 22`
    // and 1, 256 and 257 points on: at most 1,024 + 257 < its 1,281 points) at the offsets
    // asserted above and given by `offset_of!`; writes every field of `*out` (its six
    // `cos`/`sin`, the reach, the device frame's three, the probe's three and the flags)
    // and nothing else. Every register it writes is declared (here and by `arm_asm!`); the
    // stack is untouched.
    unsafe {
        arm_asm!(
            "movw r12, :lower16:{sine}",
            "movt r12, :upper16:{sine}",
            "mov r11, #0",
            // Q cleared (and the other flags, which nothing reads): the probe's holds set it.
            "msr APSR_nzcvq, r11",
            // B: reach = hi(upper_q18, sB) in r10, height = base + hi(upper_q17, cB) in lr.
            joint!("{joint_b}", "4", "2", "{cs} + 8"),
            "ldr r4, [r0, #{upper_q18}]",
            "smmul r10, r4, r3",
            "ldr r4, [r0, #{upper_q17}]",
            "ldr r5, [r0, #{base_q16}]",
            "smmla lr, r4, r8, r5",
            // C: reach += hi(fore_q18, sC), height −= hi(fore_q17, cC).
            joint!("{joint_c}", "8", "4", "{cs} + 16"),
            "ldr r4, [r0, #{fore_q18}]",
            "smmla r10, r4, r3, r10",
            "ldr r4, [r0, #{fore_q17}]",
            "smmul r4, r4, r8",
            "sub lr, lr, r4",
            // A: x = hi(reach, cA), y = hi(reach, sA).
            joint!("{joint_a}", "0", "1", "{cs}"),
            "smmul r8, r10, r8",
            "smmul r9, r10, r3",
            "strd r10, r8, [r2, #{reach}]",
            "strd r9, lr, [r2, #({reach} + 8)]",
            probe_axis!("r8", "0"),
            probe_axis!("r9", "4"),
            probe_axis!("lr", "8"),
            // OUTSIDE (bit 3) from Q (APSR bit 27).
            "mrs r3, APSR",
            "ubfx r3, r3, #27, #1",
            "orr r11, r11, r3, lsl #3",
            "strb r11, [r2, #{flags}]",
            sine = sym SINE,
            home_count = const offset_of!(Joint, home_count),
            fraction = const offset_of!(Joint, phase_per_count_fraction),
            whole = const offset_of!(Joint, phase_per_count_whole),
            min_phase = const offset_of!(Joint, min_phase),
            phase_span = const offset_of!(Joint, phase_span),
            home_phase = const offset_of!(Joint, home_phase),
            upper_q18 = const offset_of!(Arm, upper_q18),
            fore_q18 = const offset_of!(Arm, fore_q18),
            upper_q17 = const offset_of!(Arm, upper_q17),
            fore_q17 = const offset_of!(Arm, fore_q17),
            base_q16 = const offset_of!(Arm, base_q16),
            origin = const offset_of!(Arm, origin_q16),
            cs = const offset_of!(ArmPose, cos_sin),
            reach = const offset_of!(ArmPose, reach_q17),
            probe = const offset_of!(ArmPose, probe),
            flags = const offset_of!(ArmPose, flags),
            in("r0") core::ptr::from_ref(arm),
            in("r1") counts.as_ptr(),
            in("r2") out,
            out("r3") _,
        );
    }
}
