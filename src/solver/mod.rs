//! `Solver`: the MCCS patch in fixed point, one call per haptic tick.
//!
//! Each spring applies the tabulated law ([`ForceTable`]) to its compressive strain
//! `ε = (l0 − l)/l0` along the edge, plus the paper's relative-velocity damping (eq. 17);
//! each free node integrates `m a = f_ext − Σ F_spring − Σ C (v_i − v_j) − c v_i` with the
//! paper's improved Euler: velocity by an explicit Euler step (eq. 21), position by the
//! trapezoid of old and new velocity (eq. 22). The probe drives the contact node through a
//! virtual [`crate::Coupling`]; the device renders the coupling force.
//!
//! - `config.rs`: [`SolverConfig`] and its ranges; `error.rs`: [`SolverError`];
//! - `stability/`: the substeps per tick the integrator needs (the one-step matrix, a
//!   closed-form and an estimated bound; the estimate's linearised step in block fixed
//!   point in `linearised.rs`);
//! - `param_set.rs`: [`ParamSet`], prepared away from the tick and switched in between two;
//! - `step.rs`: the tick itself.
//!
//! # Per tick
//! [`Solver::step`] runs a fixed number of substeps (chosen at construction), each a loop
//! over the springs and one over the nodes: constant time, no division, no square root
//! (the length comes from a warm-started Newton step for `1/l`), no floating point, no
//! heap, no panic; every step saturates or works within ranges the clamps bound (see
//! [`crate::arith`]).
//!
//! # Units and formats
//! Displacements from rest in mm, Q24, kept within ±64 mm; velocities in mm/s, Q16, kept
//! within ±16384 mm/s (stored as the arithmetic chooses, [`crate::state`]); forces in N,
//! Q20 (±2048 N; one spring's force, law and damping, within ±64 N). Positions are in the
//! patch frame (origin at the contact node's rest position, `z` up).

use crate::arith::{Arith, ArithTable, DefaultArith};
use crate::q::V3;
use crate::state::{Node, DISP_LIMIT, VEL_LIMIT};
use crate::table::ForceTable;
use crate::topology::{Topology, GROUND};
use crate::units::{Length, Velocity};

mod config;
mod contact;
mod error;
mod param_set;
mod roaming;
pub mod stability;
mod step;
#[cfg(test)]
mod test_patch;
mod window;

pub use config::{ConfigKey, SolverConfig};
pub use error::SolverError;
use param_set::Coeffs;
pub use param_set::ParamSet;
pub use stability::{Bound, Bounds};

/// The patch solver: topology, force table and state. `NODES` counts the ground slot;
/// `A` is the arithmetic ([`crate::arith`]: [`crate::arith::Wide`] by default,
/// [`crate::arith::Narrow`] on the Cortex-M0).
#[derive(Clone, Debug)]
#[repr(C)]
pub struct Solver<const NODES: usize, const EDGES: usize, const S: usize, A: Arith = DefaultArith> {
    c: Coeffs<A>,
    substeps: u32,
    contact: usize,
    /// The topology's fingerprint, which a [`ParamSet`] must carry to be applied.
    fingerprint: u32,
    table: ArithTable<S, A>,
    topo: Topology<NODES, EDGES>,
    /// Per node: displacement, velocity, force accumulator.
    nodes: [Node; NODES],
    /// Each spring's warm-started `l0 / l` in the arithmetic's format.
    warm: [i32; EDGES],
    /// Last probe position, Q24 mm.
    probe_prev: V3,
    /// Spring force on the contact node in the last substep, Q20 N.
    reaction: V3,
    /// Coupling force on the contact node in the last substep, Q20 N.
    coupling_force: V3,
}

impl<const NODES: usize, const EDGES: usize, const S: usize> Solver<NODES, EDGES, S> {
    /// Builds a solver at rest in this core's arithmetic ([`DefaultArith`]); computes the
    /// substeps per tick from the stability bound.
    #[inline(never)]
    pub fn new(
        topo: Topology<NODES, EDGES>,
        table: ForceTable<S>,
        config: &SolverConfig,
    ) -> Result<Self, SolverError> {
        Self::with_arith(topo, table, config, DefaultArith::default())
    }
}

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith> Solver<NODES, EDGES, S, A> {
    /// [`Solver::new`] in a chosen arithmetic (e.g. [`crate::arith::Narrow`] on a host,
    /// to see what the M0 computes).
    #[inline(never)]
    pub fn with_arith(
        topo: Topology<NODES, EDGES>,
        table: ForceTable<S>,
        config: &SolverConfig,
        _arith: A,
    ) -> Result<Self, SolverError> {
        let contact = topo.contact() as usize;
        if contact == GROUND as usize {
            return Err(SolverError::NoContact);
        }
        let set = Self::prepare_for(&topo, table, config)?;
        Ok(Self {
            topo,
            table: set.table,
            c: set.c,
            substeps: set.substeps,
            contact,
            fingerprint: set.fingerprint,
            nodes: [Node::ZERO; NODES],
            warm: [A::REST; EDGES],
            probe_prev: [0; 3],
            reaction: [0; 3],
            coupling_force: [0; 3],
        })
    }

    /// Substeps per tick.
    pub fn substeps(&self) -> u32 {
        self.substeps
    }

    /// The largest force the coupling renders (`Coupling::max_force`): per axis glued,
    /// in magnitude through a proxy.
    pub fn max_force(&self) -> crate::units::Force {
        crate::units::Force::from_bits(self.c.coupling.max_force)
    }

    /// The topology.
    pub fn topology(&self) -> &Topology<NODES, EDGES> {
        &self.topo
    }

    /// The force table.
    pub fn table(&self) -> &ForceTable<S> {
        &self.table.table
    }

    /// Displacement of node `i` from rest (mm), `None` if it does not exist.
    pub fn displacement(&self, i: u16) -> Option<[Length; 3]> {
        self.nodes
            .get(i as usize)
            .map(|n| n.u.map(Length::from_bits))
    }

    /// Velocity of node `i` (mm/s), `None` if it does not exist.
    pub fn velocity(&self, i: u16) -> Option<[Velocity; 3]> {
        self.nodes
            .get(i as usize)
            .map(|_| self.node_vel(i as usize).map(Velocity::from_bits))
    }

    /// Puts node `i` at displacement `disp` (mm) with velocity `vel` (mm/s), clamped to
    /// the solver's limits (±64 mm, ±16384 mm/s); the ground and missing nodes are
    /// ignored. For tests and for starting from a known state.
    pub fn set_state(&mut self, i: u16, disp: [Length; 3], vel: [Velocity; 3]) {
        if i == GROUND {
            return;
        }
        let v = vel.map(|x| self.stored_velocity(x.to_bits().clamp(-VEL_LIMIT, VEL_LIMIT - 1)));
        if let Some(n) = self.nodes.get_mut(i as usize) {
            // Within the integrator's limits, which the spring's ranges rely on.
            n.u = disp.map(|x| x.to_bits().clamp(-DISP_LIMIT, DISP_LIMIT - 1));
            n.v = v;
        }
    }

    /// Back to rest.
    pub fn reset(&mut self) {
        self.nodes = [Node::ZERO; NODES];
        self.warm = [A::REST; EDGES];
        self.probe_prev = [0; 3];
        self.reaction = [0; 3];
        self.coupling_force = [0; 3];
    }
}
