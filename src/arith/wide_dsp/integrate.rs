//! The integrator in Armv7E-M assembly, bit for bit [`crate::arith::wide`]'s portable one.

use crate::state::Node;

/// What [`integrate`] reads at entry (`repr(C)`: one `ldm`).
#[repr(C)]
struct IntegrateArgs {
    begin: *mut Node,
    end: *mut Node,
    keep: i32,
    h_over_m: i32,
    half_h: i32,
}

/// The integrator's loop over [`IntegrateArgs`] `$args`; `$x`, `$y` and `$z` put what the
/// position step multiplies by `h/2` in r3, r4 and r5 (`v + v'` or `v' + v'`, from v in
/// r3–r5 and v' in r6, r8, r9).
macro_rules! integrate_loop {
    ($args:ident, $x:literal, $y:literal, $z:literal) => {
        asm_writing_all!(
            "push {{r6, r7}}",
            "ldm r0, {{r1, r2, r10, r11, r12}}",
            "mov lr, r1",
            "push {{r2}}",
            "cmp lr, r2",
            "beq 99f",
            "70:",
            "ldm lr, {{r0, r1, r2, r3, r4, r5}}",
            // Per axis: v' = (v keep + f h/m) >> 24, held within ±2³⁰ through the high
            // word; u' = u + hi((v + v') h/2) (or (v' + v') h/2), held within ±2³⁰. v0'
            // in r6, v1' in r8, v2' in r9 (so that u and v' go back in one `stm`).
            "ldr r7, [lr, #24]",
            "smull r6, r8, r3, r10",
            "smlal r6, r8, r7, r11",
            "ssat r8, #23, r8",
            "lsl r8, r8, #8",
            "orr r6, r8, r6, lsr #24",
            $x,
            "smmla r0, r3, r12, r0",
            "ssat r0, #31, r0",
            "ldr r7, [lr, #28]",
            "smull r8, r9, r4, r10",
            "smlal r8, r9, r7, r11",
            "ssat r9, #23, r9",
            "lsl r9, r9, #8",
            "orr r8, r9, r8, lsr #24",
            $y,
            "smmla r1, r4, r12, r1",
            "ssat r1, #31, r1",
            "ldr r3, [lr, #32]",
            "smull r9, r7, r5, r10",
            "smlal r9, r7, r3, r11",
            "ssat r7, #23, r7",
            "lsl r7, r7, #8",
            "orr r9, r7, r9, lsr #24",
            $z,
            "smmla r2, r5, r12, r2",
            "ssat r2, #31, r2",
            "mov r3, #0",
            "stm lr!, {{r0, r1, r2, r6, r8, r9}}",
            "strd r3, r3, [lr]",
            "str r3, [lr, #8]",
            "add lr, lr, #12",
            "ldr r7, [sp]",
            "cmp lr, r7",
            "bne 70b",
            "99:",
            "add sp, sp, #4",
            "pop {{r6, r7}}",
            inout("r0") core::ptr::addr_of!($args) => _,
        )
    };
}

/// The integrator on every node of `free` and its accumulator cleared:
/// [`crate::arith::wide`]'s `integrate`, in assembly (one `ldm` of a node's displacement and
/// velocity, one `stm` back). `keep`, `h_over_m` and `half_h` are [`crate::arith::WideCoeffs`]'
/// (Q24, Q20, Q40); `symplectic` chooses, once per call, the loop whose position step
/// adds `v' + v'` instead of `v + v'` (the one instruction per axis the two differ by).
#[inline(always)]
#[allow(unsafe_code)]
pub(crate) fn integrate(
    keep: i32,
    h_over_m: i32,
    half_h: i32,
    symplectic: bool,
    free: &mut [Node],
) {
    let range = free.as_mut_ptr_range();
    let args = IntegrateArgs {
        begin: range.start,
        end: range.end,
        keep,
        h_over_m,
        half_h,
    };
    // SAFETY (both loops): reads and writes the nodes of `free` (from `begin` up to
    // `end`) only, at the offsets asserted above. r6 and r7 are saved and restored by the
    // block itself, every other register it writes is declared, and the stack is left as
    // it was found.
    if symplectic {
        unsafe { integrate_loop!(args, "add r3, r6, r6", "add r4, r8, r8", "add r5, r9, r9") }
    } else {
        unsafe { integrate_loop!(args, "add r3, r3, r6", "add r4, r4, r8", "add r5, r5, r9") }
    }
}
