//! Out-of-line entry points into the per-tick arithmetic, so that a benchmark can count
//! the instructions of exactly one call (QEMU `-icount`, or DWT on hardware). They add
//! nothing but the call itself.

use mccs::arith::ArithTable;
use mccs::state::{Node, SpringEnds};
use mccs::{
    Arith, DefaultArith, Edge, Force, ForceTable64, Length, Proxy, Solver, Stiffness, Strain,
    Topology, Window,
};

/// [`ForceTable64::new`], never inlined: a force table built at a device's start-up, held
/// to the product's bound (the `table_new` firmware measures it).
#[inline(never)]
pub fn table_new(params: &mccs::Params) -> Result<ForceTable64, mccs::TableError> {
    ForceTable64::new(params)
}

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
/// ([`DefaultArith`]), never inlined; the end states are read through one reference, as
/// the solver reads them from its nodes. Raw formats as in [`mccs::arith`].
#[inline(never)]
pub fn spring(
    table: &ArithTable<64, DefaultArith>,
    coeffs: &<DefaultArith as Arith>::Coeffs,
    edge: &Edge,
    ends: &SpringEnds,
    warm: &mut i32,
) -> [i32; 3] {
    DefaultArith::spring(table, coeffs, edge, ends, warm)
}

/// Every spring of a patch once ([`Arith::spring_forces`], the loop a substep runs: the
/// M4F's in assembly), in this core's arithmetic, never inlined.
#[inline(never)]
pub fn spring_loop<const N: usize, const E: usize>(
    table: &ArithTable<64, DefaultArith>,
    coeffs: &<DefaultArith as Arith>::Coeffs,
    topo: &Topology<N, E>,
    warm: &mut [i32; E],
    nodes: &mut [Node; N],
) {
    DefaultArith::spring_forces(table, coeffs, topo, warm, nodes)
}

/// One substep of a solver with the probe held at `probe`, never inlined.
#[inline(never)]
pub fn substep<const N: usize, const E: usize>(solver: &mut Solver<N, E, 64>, probe: [Length; 3]) {
    solver.substep_probe(probe)
}

/// One tick of a solver, never inlined.
#[inline(never)]
pub fn tick<const N: usize, const E: usize>(
    solver: &mut Solver<N, E, 64>,
    probe: [Length; 3],
) -> [Force; 3] {
    solver.step(probe)
}

/// One tick of a solver through a proxy on its surface, never inlined.
#[inline(never)]
pub fn tick_proxy<const N: usize, const E: usize>(
    solver: &mut Solver<N, E, 64>,
    probe: [Length; 3],
    proxy: &mut Proxy,
) -> [Force; 3] {
    solver.step_proxy(probe, proxy)
}

/// One tick of a solver roaming a tissue of shape `Sh` (flat, or a cap) through a proxy,
/// never inlined.
#[inline(never)]
pub fn tick_roaming<const N: usize, const E: usize, Sh: mccs::Shape>(
    solver: &mut Solver<N, E, 64>,
    probe: [Length; 3],
    proxy: &mut Proxy,
    window: &mut Window<E, Sh>,
) -> [Force; 3] {
    solver.step_roaming(probe, proxy, window)
}
