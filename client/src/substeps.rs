//! The substeps a tissue needs on a device, computed here the way the device's own
//! search would (the core's stability estimate on the device's patch and solver
//! configuration, from its hello), so that a load can propose them: the device then
//! checks them with two runs of its linearised patch instead of searching with ten
//! (docs/protocol.md, "Tissue loads"). The device decides either way.

use crate::tissue::Tissue;
use mccs::{Coupling, ForceTable, Integrator, SolverConfig, Topology};
use mccs_link::{table_bytes, HelloInfo};

/// The solver configuration a device runs, from its hello.
pub fn config_of(h: &HelloInfo) -> SolverConfig {
    SolverConfig {
        tick_hz: h.tick_hz as f64,
        node_mass: h.solver.node_mass_kg,
        spring_damping: h.solver.spring_damping,
        node_damping: h.solver.node_damping,
        max_substeps: h.solver.max_substeps as u32,
        coupling: Coupling {
            stiffness: h.solver.coupling_stiffness,
            damping: h.solver.coupling_damping,
            max_force: mccs_link::scale::newtons(h.force_clamp),
        },
        integrator: if h.solver.symplectic {
            Integrator::SymplecticDamped
        } else {
            Integrator::ImprovedEuler
        },
        ..SolverConfig::default()
    }
}

/// The substeps `tissue` needs on the device its hello describes; `None` where they
/// cannot be computed here (a patch or table size this client does not hold, or the
/// solver refuses: the device then says why).
pub fn for_device(hello: &HelloInfo, tissue: &Tissue) -> Option<u32> {
    let config = config_of(hello);
    let grid = hello.grid as usize;
    let spacing = mccs_link::scale::mm(hello.spacing);
    macro_rules! on_grid {
        ($($n:literal),*) => {
            match grid {
                $($n => {
                    const C: (usize, usize) = mccs::topology::standard_capacity($n);
                    on_table::<{ C.0 }, { C.1 }>(grid, spacing, tissue, &config)
                })*
                _ => None,
            }
        };
    }
    on_grid!(3, 4, 5, 6, 7, 8, 9, 10, 11, 12)
}

fn on_table<const N: usize, const E: usize>(
    grid: usize,
    spacing: f64,
    tissue: &Tissue,
    config: &SolverConfig,
) -> Option<u32> {
    let topo = Topology::<N, E>::standard_patch(grid, spacing).ok()?;
    macro_rules! on_segments {
        ($($s:literal),*) => {
            match tissue.segments() {
                $($s => {
                    let table = ForceTable::<$s>::from_raw(table_bytes::read::<$s>(tissue.bytes())?);
                    mccs::Solver::<N, E, $s>::substeps_for(&topo, &table, config).ok()
                })*
                _ => None,
            }
        };
    }
    on_segments!(16, 32, 64, 128)
}
