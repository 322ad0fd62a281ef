//! Out-of-line entry points into the per-tick arithmetic, so that a benchmark can count
//! the instructions of exactly one call (QEMU `-icount`, or DWT on hardware). They add
//! nothing but the call itself.

use crate::{Force, ForceTable64, Stiffness, Strain};

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

/// One spring update (law + damping + Newton step), never inlined. Raw Q formats as in
/// [`crate::solver::spring_force`].
#[inline(never)]
#[allow(clippy::too_many_arguments)]
pub fn spring(
    table: &ForceTable64,
    dir: [i32; 3],
    inv_len: i32,
    ua: [i32; 3],
    ub: [i32; 3],
    va: [i32; 3],
    vb: [i32; 3],
    r: &mut i32,
    damping: i32,
) -> [i32; 3] {
    crate::solver::spring_force(table, dir, inv_len, ua, ub, &va, &vb, r, damping)
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
