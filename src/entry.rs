//! Out-of-line entry points into the per-tick arithmetic, so that a benchmark can count
//! the instructions of exactly one call (QEMU `-icount`, or DWT on hardware). They add
//! nothing but the call itself.

use crate::spring::{Arith, Damping, DefaultArith};
use crate::{Edge, Force, ForceTable64, Stiffness, Strain};

/// One [`ForceTable64::force_and_stiffness`] evaluation, never inlined.
#[inline(never)]
pub fn force_and_stiffness(table: &ForceTable64, strain: Strain) -> (Force, Stiffness) {
    table.force_and_stiffness(strain)
}

/// One [`ForceTable64::force`] evaluation, never inlined.
#[inline(never)]
pub fn force(table: &ForceTable64, strain: Strain) -> Force {
    table.force(strain)
}

/// One spring update (law + damping + Newton step) in this core's arithmetic
/// ([`crate::spring::DefaultArith`]), never inlined; the end states are read through
/// references, as the solver reads them from its nodes. Raw formats as in
/// [`crate::spring`].
#[inline(never)]
#[allow(clippy::too_many_arguments)]
pub fn spring(
    table: &ForceTable64,
    edge: &Edge,
    ua: &[i32; 3],
    ub: &[i32; 3],
    va: &[i32; 3],
    vb: &[i32; 3],
    warm: &mut i32,
    damping: &Damping,
) -> [i32; 3] {
    if damping.unit {
        DefaultArith::force::<64, true>(table, edge, *ua, *ub, va, vb, warm, damping)
    } else {
        DefaultArith::force::<64, false>(table, edge, *ua, *ub, va, vb, warm, damping)
    }
}

/// One substep of a solver with the probe held at `probe`, never inlined.
#[inline(never)]
pub fn substep<const N: usize, const E: usize>(
    solver: &mut crate::Solver<N, E, 64>,
    probe: [crate::Length; 3],
) {
    solver.substep_probe(probe)
}

/// One tick of a solver, never inlined.
#[inline(never)]
pub fn tick<const N: usize, const E: usize>(
    solver: &mut crate::Solver<N, E, 64>,
    probe: [crate::Length; 3],
) -> [Force; 3] {
    solver.step(probe)
}
