//! The spring loop in Armv7E-M assembly: every spring's force, accumulated on its two
//! nodes, bit for bit [`crate::arith::wide`]'s portable loop (`wide_dsp/mod.rs` gives the
//! preconditions).

use crate::q::V3;
use crate::state::Node;
use crate::table::{ForceTable, RawTable};
use crate::topology::{Edge, Topology};

use super::serves;

/// What the loop reads at entry (`repr(C)`: one `ldm`). The first six words become its
/// frame: `velocities`, `stride` and `end` one `ldm` at each spring's end (node `i`'s
/// velocity is at `velocities + stride · i`; its displacement just before, one `ldmdb`,
/// its accumulator just after).
#[repr(C)]
struct LoopArgs {
    /// The first node's velocity: the nodes' address plus 12.
    velocities: *mut i32,
    /// `size_of::<Node>()`, 36.
    stride: u32,
    end: *const Edge,
    segments: *const [i32; 4],
    /// The coefficients' shift, masked as `wrapping_shr` masks it.
    shift: u32,
    damping: i32,
    edges: *const Edge,
    warm: *mut i32,
}

// The layouts the assembly reads by offset.
const _: () = {
    assert!(core::mem::size_of::<Edge>() == 20);
    assert!(core::mem::offset_of!(Edge, dir) == 0);
    assert!(core::mem::offset_of!(Edge, inv_len) == 12);
    assert!(core::mem::offset_of!(Edge, a) == 16);
    assert!(core::mem::offset_of!(Edge, b) == 18);
    assert!(core::mem::size_of::<Node>() == 36);
    assert!(core::mem::offset_of!(Node, u) == 0);
    assert!(core::mem::offset_of!(Node, v) == 12);
    assert!(core::mem::offset_of!(Node, f) == 24);
    assert!(core::mem::size_of::<V3>() == 12);
    // The graded corner's index takes two bits for the segment in an octave.
    assert!(crate::table::CORNER_PER_OCTAVE == 4);
};

/// Offsets of the table's header fields from its first segment (bytes, negative).
const fn header<const S: usize>() -> [i32; 14] {
    let seg = core::mem::offset_of!(RawTable<S>, segments) as i32;
    [
        core::mem::offset_of!(RawTable<S>, strain_lo) as i32 - seg,
        core::mem::offset_of!(RawTable<S>, strain_hi) as i32 - seg,
        core::mem::offset_of!(RawTable<S>, index_pre) as i32 - seg,
        core::mem::offset_of!(RawTable<S>, index_scale) as i32 - seg,
        core::mem::offset_of!(RawTable<S>, anchor_lo) as i32 - seg,
        core::mem::offset_of!(RawTable<S>, force_lo) as i32 - seg,
        core::mem::offset_of!(RawTable<S>, slope_lo) as i32 - seg,
        core::mem::offset_of!(RawTable<S>, force_hi) as i32 - seg,
        core::mem::offset_of!(RawTable<S>, stiffness_hi) as i32 - seg,
        core::mem::offset_of!(RawTable<S>, corner_hi) as i32 - seg,
        core::mem::offset_of!(RawTable<S>, corner_anchor) as i32 - seg,
        core::mem::offset_of!(RawTable<S>, corner_pre) as i32 - seg,
        core::mem::offset_of!(RawTable<S>, corner_base) as i32 - seg,
        core::mem::offset_of!(RawTable<S>, slope_hi) as i32 - seg,
    ]
}

/// The header as the assembly addresses it: `ldrd` pairs (`strain_lo, strain_hi`,
/// `index_pre, index_scale` and `corner_anchor, corner_pre`) and `ldr`s, word-aligned
/// within 255 bytes before the first segment.
pub(super) const fn header_fits<const S: usize>() -> bool {
    let h = header::<S>();
    let mut i = 0;
    let mut ok = h[1] == h[0] + 4 && h[3] == h[2] + 4 && h[11] == h[10] + 4;
    while i < h.len() {
        ok = ok && h[i] >= -252 && h[i] < 0 && h[i] % 4 == 0;
        i += 1;
    }
    ok
}

/// The lower line's product, `(slope_lo · d) >> 20` held to 32 bits, into r3 from
/// the Q16 slope (r5) and `d = e ⊖ anchor_lo` (r3): any slope (a long product, its high
/// word held, the two words joined).
macro_rules! lower_any {
    () => {
        concat!(
            "smull r3, r5, r5, r3\n",
            "ssat r5, #20, r5\n",
            "lsl r5, r5, #12\n",
            "orr r3, r5, r3, lsr #20\n",
        )
    };
}

/// The same for a stiffness within ±2¹⁹ (Q16: below 8 N per unit strain, Table 2's is
/// 2.3), whose `slope_lo` is Q28 ([`crate::table::fine_line`]): `hi(slope_lo ·
/// d)`, one instruction.
macro_rules! lower_gentle {
    () => {
        concat!("smmul r3, r5, r3\n",)
    };
}

/// The start of the line below's path in the loop of a table without a lower corner:
/// nothing.
macro_rules! no_lower_corner {
    () => {
        ""
    };
}

/// The same in the loop of a table with a lower corner ([`ForceTable::lower_corner`]):
/// a strain above `corner_hi` is the corner's (three instructions; the other loops
/// have none, so that a table without one pays nothing on its most common path).
macro_rules! lower_corner {
    () => {
        concat!("ldr r3, [r11, #{corner_hi}]\n", "cmp r9, r3\n", "bgt 54b\n",)
    };
}

/// The part of one spring both of its kinds share: from `dir + d/l0` (r0–r2, Q23) to
/// the edge vector `w` (r0–r2, Q30), the advanced warm-start `l0/l` (r10, stored
/// through r7, which moves on) and `f l0/l` (r8, Q22); r3 is the damping. Keeps r4
/// (node b), r6 (node a), r7, r12. `$lower`: the lower line's product
/// ([`lower_any`] or [`lower_gentle`]); `$below`: what comes before it
/// ([`no_lower_corner`] or [`lower_corner`]).
macro_rules! spring_body {
    ($lower:ident, $below:ident) => {
        concat!(
            // w held within ±2 (Q23), then Q30.
            "ssat r0, #25, r0\n",
            "ssat r1, #25, r1\n",
            "ssat r2, #25, r2\n",
            "lsl r0, r0, #7\n",
            "lsl r1, r1, #7\n",
            "lsl r2, r2, #7\n",
            // a = |w|² (u32, Q28).
            "smmul r3, r0, r0\n",
            "smmla r3, r1, r1, r3\n",
            "smmla r3, r2, r2, r3\n",
            // Newton: ar = hi_u(a r) held below 4, Q28; arr = hi(ar r) held in [0, 2);
            // g = (arr << 8) ^ i32::MAX; r' = r + hi(r g) held below 8.
            "ldr r5, [r7]\n",
            "umull r8, r9, r3, r5\n",
            "usat r9, #25, r9\n",
            "lsl r9, r9, #5\n",
            "smmul r8, r9, r5\n",
            "usat r8, #24, r8\n",
            "mvn r10, #0x80000000\n",
            "eor r8, r10, r8, lsl #8\n",
            "smmla r10, r5, r8, r5\n",
            "usat r10, #30, r10\n",
            "str r10, [r7], #4\n",
            // |w| = ar + hi(ar g) (Q28); the strain (1 − |w|) in Q24.
            "smmla r9, r9, r8, r9\n",
            "rsb r9, r9, #0x10000000\n",
            "asr r9, r9, #4\n",
            // The table: below, above, or in a segment.
            "ldr r11, [sp, #12]\n",
            "ldrd r3, r5, [r11, #{strain_lo}]\n",
            "cmp r9, r3\n",
            "ble 51f\n",
            "cmp r9, r5\n",
            "bge 52f\n",
            // pos = hi_u((e − lo) · pre, scale): segment index above bit 15, τ below.
            "ldrd r5, r8, [r11, #{index_pre}]\n",
            "sub r3, r9, r3\n",
            "mul r3, r3, r5\n",
            "umull r5, r3, r3, r8\n",
            "ubfx r5, r3, #15, #{log2s}\n",
            "add r5, r11, r5, lsl #4\n",
            "ldm r5, {{r5, r8, r11, lr}}\n",
            "lsl r3, r3, #17\n",
            "lsr r3, r3, #1\n",
            // Three halving Horner steps, then the coefficients' shift.
            "55:\n",
            "smmla r11, lr, r3, r11\n",
            "smmla r8, r11, r3, r8\n",
            "smmla r5, r8, r3, r5\n",
            "ldr r3, [sp, #16]\n",
            "asr r5, r5, r3\n",
            "b 53f\n",
            // The graded corner: d = (A − e) · pre, z = clz(d); the segment is
            // corner_base + 4 z + the two bits after d's leading one (masked as the
            // portable index is), τ the next 15; then the same Horner steps.
            "54:\n",
            "ldrd r3, r5, [r11, #{corner_anchor}]\n",
            "sub r3, r3, r9\n",
            "mul r3, r3, r5\n",
            "clz r5, r3\n",
            "lsl r3, r3, r5\n",
            "ldr r8, [r11, #{corner_base}]\n",
            "add r8, r8, r5, lsl #2\n",
            "ubfx r5, r3, #29, #2\n",
            "add r5, r8, r5\n",
            "ubfx r5, r5, #0, #{log2s}\n",
            "add r5, r11, r5, lsl #4\n",
            "ldm r5, {{r5, r8, r11, lr}}\n",
            "ubfx r3, r3, #14, #15\n",
            "lsl r3, r3, #16\n",
            "b 55b\n",
            // At or above strain_hi: the graded corner below corner_hi; above it
            // force_hi + hi(slope_hi · (e ⊖ corner_hi)) where stiffness_hi is within
            // ±2¹⁹ (slope_hi is then Q28: `fine_line`), else
            // force_hi + (slope_hi · (e ⊖ corner_hi)) >> 20, held.
            "52:\n",
            "ldr r5, [r11, #{corner_hi}]\n",
            "cmp r9, r5\n",
            "blt 54b\n",
            "qsub r3, r9, r5\n",
            "ldr r8, [r11, #{stiffness_hi}]\n",
            "ldr r5, [r11, #{slope_hi}]\n",
            "add r8, r8, #0x80000\n",
            "cmp r8, #0x100000\n",
            "bhs 56f\n",
            "smmul r3, r5, r3\n",
            "b 57f\n",
            "56:\n",
            "smull r3, r5, r5, r3\n",
            "ssat r5, #20, r5\n",
            "lsl r5, r5, #12\n",
            "orr r3, r5, r3, lsr #20\n",
            "57:\n",
            "ldr r5, [r11, #{force_hi}]\n",
            "qadd r5, r5, r3\n",
            "b 53f\n",
            // Below: force_lo + the slope's product with e ⊖ anchor_lo (or first, in
            // the loop of a table with a lower corner, that corner above corner_hi).
            // Last, falling through: the pressed patch's springs mostly take it.
            "51:\n",
            $below!(),
            "ldr r3, [r11, #{anchor_lo}]\n",
            "qsub r3, r9, r3\n",
            "ldr r5, [r11, #{slope_lo}]\n",
            $lower!(),
            "ldr r5, [r11, #{force_lo}]\n",
            "qadd r5, r5, r3\n",
            // f within ±64 N; f r' >> 25 (Q22; the law's product subtracts it); the
            // damping.
            "53:\n",
            "ssat r5, #27, r5\n",
            "smull r3, r8, r5, r10\n",
            "lsl r8, r8, #7\n",
            "orr r8, r8, r3, lsr #25\n",
            "ldr r3, [sp, #20]\n",
        )
    };
}

/// One axis of a spring between two nodes: `p = round(C dv) + round(w (−f r))` (one
/// `smmlsr`: `t − w (f r)` rounded is `t + round(w (−f r))`), held within ±64 N, into
/// the axis' `w` register. `$w`: w's register; `$dv`: the register holding the axis'
/// `v_b − v_a`.
macro_rules! axis_two {
    ($w:literal, $dv:literal) => {
        concat!(
            "smmulr ", $dv, ", ", $dv, ", r3\n", "smmlsr ", $w, ", ", $w, ", r8, ", $dv, "\n",
            "ssat ", $w, ", #27, ", $w, "\n",
        )
    };
}

/// The same for a spring to the ground (at rest): `dv = −v_a`, its rounded product
/// subtracted (`smmlsr`: `t − round(v_a C)` is `t + round(−v_a C)`; `v_a` is never
/// `i32::MIN`, see [`spring_forces`]).
macro_rules! axis_ground {
    ($w:literal, $va:literal) => {
        concat!(
            "smmulr ", $w, ", ", $w, ", r8\n", "smmlsr ", $w, ", ", $va, ", r3, ", $w, "\n",
            "ssat ", $w, ", #27, ", $w, "\n",
        )
    };
}

/// Node a's accumulator (r6, moved past its velocity) takes `p` (r0–r2); the next
/// spring, until the end (which the frame's first words, the velocities' base and
/// stride, come with: the next spring's addresses take them in r5 and r11).
macro_rules! a_takes_p_and_loops {
    () => {
        concat!(
            "ldm r6, {{r5, r9, r10}}\n",
            "add r5, r5, r0\n",
            "add r9, r9, r1\n",
            "add r10, r10, r2\n",
            "stm r6, {{r5, r9, r10}}\n",
            "ldm sp, {{r5, r11, lr}}\n",
            "cmp r12, lr\n",
            "bne 20b\n",
        )
    };
}

/// The spring loop over [`LoopArgs`] `$args`, with `$lower` the lower line's product
/// ([`lower_any`] or [`lower_gentle`]) and `$below` what comes before it
/// ([`no_lower_corner`] or [`lower_corner`]); in `spring_forces`, whose generics the
/// constants name.
macro_rules! spring_loop {
    ($args:ident, $lower:ident, $below:ident) => {
        asm_writing_all!(
            "push {{r6, r7}}",
            "ldm r0, {{r1, r2, r3, r4, r5, r6, r7, r8}}",
            "push {{r1, r2, r3, r4, r5, r6}}",
            "mov r12, r7",
            "mov r7, r8",
            "mov r5, r1",
            "mov r11, r2",
            "cmp r12, r3",
            "beq 90f",
            // One spring: the edge (dir, 1/l0, a | b << 16) and its nodes' velocity
            // addresses.
            "20:",
            "ldm r12!, {{r0, r1, r2, r3, r4}}",
            // a's: base + 36 a (r5 + r11 r4, the base and the stride from the loop's
            // end), one multiply-accumulate of the low half (a node index below 2¹⁵,
            // so the signed half is the index); then b's of the high half, unless b is
            // the ground. Their displacements: the three words before.
            "smlabb r6, r4, r11, r5",
            "lsrs lr, r4, #16",
            "beq 30f",
            "smlatb r4, r4, r11, r5",
            "ldmdb r4, {{r5, r8, r9}}",
            "ldmdb r6, {{r10, r11, lr}}",
            "sub r5, r5, r10",
            "sub r8, r8, r11",
            "sub r9, r9, lr",
            // dir + hi(d / l0).
            "smmla r0, r5, r3, r0",
            "smmla r1, r8, r3, r1",
            "smmla r2, r9, r3, r2",
            spring_body!($lower, $below),
            // dv = v_b − v_a: a's velocity (r6 on to its accumulator), b's by two
            // post-indexed loads (r4 on to its accumulator).
            "ldm r6!, {{r5, r9, r10}}",
            "ldrd r11, lr, [r4], #8",
            "sub r5, r11, r5",
            "sub r9, lr, r9",
            "ldr r11, [r4], #4",
            "sub r10, r11, r10",
            axis_two!("r0", "r5"),
            axis_two!("r1", "r9"),
            axis_two!("r2", "r10"),
            // b's accumulator takes −p, a's p.
            "ldm r4, {{r5, r9, r10}}",
            "sub r5, r5, r0",
            "sub r9, r9, r1",
            "sub r10, r10, r2",
            "stm r4, {{r5, r9, r10}}",
            a_takes_p_and_loops!(),
            "b 90f",
            // A spring to the ground: b at rest, d = −u_a, so dir − hi(u_a / l0)
            // (`smmls`, exact: u_a is never i32::MIN).
            "30:",
            "ldmdb r6, {{r10, r11, lr}}",
            "smmls r0, r10, r3, r0",
            "smmls r1, r11, r3, r1",
            "smmls r2, lr, r3, r2",
            spring_body!($lower, $below),
            // −f r' for the ground's axes.
            "rsb r8, r8, #0",
            "ldm r6!, {{r5, r9, r10}}",
            axis_ground!("r0", "r5"),
            axis_ground!("r1", "r9"),
            axis_ground!("r2", "r10"),
            a_takes_p_and_loops!(),
            "90:",
            "add sp, sp, #24",
            "pop {{r6, r7}}",
            log2s = const if serves::<S, NODES>() { S.trailing_zeros() } else { 1 },
            strain_lo = const header::<S>()[0],
            index_pre = const header::<S>()[2],
            anchor_lo = const header::<S>()[4],
            force_lo = const header::<S>()[5],
            slope_lo = const header::<S>()[6],
            force_hi = const header::<S>()[7],
            stiffness_hi = const header::<S>()[8],
            slope_hi = const header::<S>()[13],
            corner_hi = const header::<S>()[9],
            corner_anchor = const header::<S>()[10],
            corner_base = const header::<S>()[12],
            inout("r0") core::ptr::addr_of!($args) => _,
        )
    };
}

/// Every spring's force, accumulated on its two nodes: [`crate::arith::wide`]'s loop, in
/// assembly. Only for tables it [`serves`] (the caller's choice, a constant).
#[inline(always)]
#[allow(unsafe_code)]
pub(crate) fn spring_forces<const S: usize, const NODES: usize, const EDGES: usize>(
    table: &ForceTable<S>,
    damping: i32,
    topo: &Topology<NODES, EDGES>,
    warm: &mut [i32; EDGES],
    nodes: &mut [Node; NODES],
) {
    let edges = topo.edges();
    let n = edges.len().min(EDGES);
    let raw = table.raw();
    let args = LoopArgs {
        velocities: nodes.as_mut_ptr().cast::<i32>().wrapping_add(3),
        stride: core::mem::size_of::<Node>() as u32,
        end: edges.as_ptr().wrapping_add(n),
        segments: raw.segments.as_ptr(),
        shift: raw.shift & 31,
        damping,
        edges: edges.as_ptr(),
        warm: warm.as_mut_ptr(),
    };
    // The lower line's product as its slope allows, and a lower corner's check only
    // where the table has one (constants per call).
    let gentle = crate::table::fine_line(raw.stiffness_lo);
    let lower = table.lower_corner();
    // SAFETY (all four loops): the loop reads the `n` edges of `topo` (`edges` up to `end`)
    // and as many warm-start values (n ≤ EDGES), writes only those values and the nodes' force
    // accumulators, and reads the table's header and segments. Every node index is in
    // bounds of `nodes` and `a` is never the ground nor equal to `b`, as
    // `Topology::add_edge`, the only writer of an edge's ends, guarantees (see
    // `state::for_each_spring`);
    // the segment index is masked to `S − 1` and `S` is a power of two; the layouts it
    // reads are asserted above. It saves and restores r6 and r7 itself (the registers
    // the compiler reserves), declares every other register it writes, and leaves the
    // stack as it found it.
    match (gentle, lower) {
        (true, false) => unsafe { spring_loop!(args, lower_gentle, no_lower_corner) },
        (false, false) => unsafe { spring_loop!(args, lower_any, no_lower_corner) },
        (true, true) => unsafe { spring_loop!(args, lower_gentle, lower_corner) },
        (false, true) => unsafe { spring_loop!(args, lower_any, lower_corner) },
    }
}
