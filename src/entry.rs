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

/// The two ends of a spring, as [`spring`] reads them: displacements (Q24 mm) and
/// velocities (as the solver stores them; Q16 mm/s for `Wide`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SpringEnds {
    /// Displacement of end `a`.
    pub ua: [i32; 3],
    /// Displacement of end `b`.
    pub ub: [i32; 3],
    /// Velocity of end `a`.
    pub va: [i32; 3],
    /// Velocity of end `b`.
    pub vb: [i32; 3],
}

/// One spring update (law + damping + Newton step) in this core's arithmetic
/// ([`crate::spring::DefaultArith`]), never inlined; the end states are read through one
/// reference, as the solver reads them from its nodes. Raw formats as in
/// [`crate::spring`].
#[inline(never)]
pub fn spring(
    table: &ForceTable64,
    edge: &Edge,
    ends: &SpringEnds,
    warm: &mut i32,
    damping: &Damping,
) -> [i32; 3] {
    let e = ends;
    if damping.unit {
        DefaultArith::force::<64, true>(table, edge, e.ua, e.ub, &e.va, &e.vb, warm, damping)
    } else {
        DefaultArith::force::<64, false>(table, edge, e.ua, e.ub, &e.va, &e.vb, warm, damping)
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
