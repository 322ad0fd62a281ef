//! `spring_forces` (`spring_loop.rs`) and `integrate` (`integrate.rs`): [`crate::arith::Wide`]'s spring loop and integrator in
//! Armv7E-M assembly (the Cortex-M4F's DSP instructions: `smmla`, `smmulr`, `qadd`,
//! `ssat`, …), bit for bit the portable loops ([`crate::arith::wide::spring_forces_portable`],
//! [`crate::arith::wide::integrate_portable`]), which every other core runs and against which
//! the bench firmware checks these on random states before it measures
//! (`firmware/src/bin/bench/kernel_check.rs`).
//!
//! Why assembly: the compiler's loop spent about a fifth of each spring on moving
//! values (spills of the edge vector around the table lookup, the warm-start pointer
//! kept on the stack, masks rebuilt for every spring, node addresses from two
//! multiplies each), and small source changes moved that cost unpredictably
//! (`docs/performance.md`, "The M4F's loops in assembly"). Here every register is
//! chosen: an edge is one `ldm`, a node's three components one `ldm`/`stm`, and the
//! loop keeps the edge and warm-start pointers in registers.
//!
//! The arithmetic is [`crate::arith::wide`]'s `spring` and `integrate`, step for step; their
//! comments give the formats and ranges. One precondition the portable loop does not
//! have: no displacement or stored velocity is `i32::MIN` (a spring to the ground
//! subtracts `u_a`'s and `v_a`'s products instead of negating them). Every writer of the
//! nodes holds both within ±2³⁰ (the integrator, `Solver::set_state`, the held drive, a
//! window's shift, which copies them), so the solver never holds one. Only for tables of
//! a power-of-two segment count (the index is a bit field); others take the portable
//! loop.

//!
//! `mod.rs`: which tables and patches the loops serve, and the `asm!` the blocks share.

/// `asm!` with every register but r0, r6, r7, r13 and r15 declared written: the blocks
/// below use them all (r0 is each block's input, r6 and r7 they save themselves).
macro_rules! asm_writing_all {
    ($($operands:tt)*) => {
        asm_writing_r4_to_lr!(
            $($operands)*
            out("r1") _,
            out("r2") _,
            out("r3") _,
        )
    };
}

mod integrate;
mod spring_loop;

pub(super) use integrate::integrate;
pub(super) use spring_loop::spring_forces;

/// Whether this loop serves tables of `S` segments and topologies of `NODES` node slots
/// (the loop takes a node index as a signed halfword: below 2¹⁵).
pub(super) const fn serves<const S: usize, const NODES: usize>() -> bool {
    S.is_power_of_two() && S <= 1 << 16 && spring_loop::header_fits::<S>() && NODES <= 1 << 15
}
