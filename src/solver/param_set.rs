//! [`ParamSet`]: a force table with the substeps and coefficients it needs on a given
//! topology and configuration, prepared away from the tick and switched in between two.

use super::{stability, Solver, SolverConfig, SolverError};
use crate::arith::{Arith, ArithTable, DefaultArith, StepSpec};
use crate::coupling::CouplingQ;
use crate::table::ForceTable;
use crate::topology::Topology;

/// The fixed-point coefficients derived from a [`SolverConfig`] and the substep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Coeffs<A: Arith> {
    /// The arithmetic's: spring damping and integrator.
    pub arith: A::Coeffs,
    /// Tick rate, Hz (for the probe velocity).
    pub tick_hz: i32,
    pub coupling: CouplingQ,
}

/// A force table with the substeps and coefficients it needs on a given topology and
/// configuration: built by [`Solver::prepare`] (start-up or main loop, `f64`), switched in
/// by [`Solver::apply`] between two ticks (a few moves). `A`: the arithmetic of the
/// solver it is for (its coefficients differ).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParamSet<const S: usize, A: Arith = DefaultArith> {
    pub(crate) table: ArithTable<S, A>,
    pub(crate) substeps: u32,
    pub(crate) c: Coeffs<A>,
    /// The topology it was prepared for ([`Topology::fingerprint`]).
    pub(crate) fingerprint: u32,
}

impl<const S: usize, A: Arith> ParamSet<S, A> {
    /// The table.
    pub fn table(&self) -> &ForceTable<S> {
        &self.table.table
    }

    /// Substeps per tick.
    pub fn substeps(&self) -> u32 {
        self.substeps
    }
}

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith> Solver<NODES, EDGES, S, A> {
    /// Prepares a parameter set for this solver's topology: the table, the substeps the
    /// stability bound asks for with it, and the fixed-point coefficients.
    pub fn prepare(
        &self,
        table: ForceTable<S>,
        config: &SolverConfig,
    ) -> Result<ParamSet<S, A>, SolverError> {
        Self::prepare_for(&self.topo, table, config)
    }

    /// Switches to a prepared parameter set; the state (positions, velocities) is kept.
    /// A set prepared for another topology or another tick rate would run this patch at
    /// a substep its stability bound was not computed for: it is refused
    /// ([`SolverError::ForeignParamSet`]) and the solver keeps its set.
    pub fn apply(&mut self, set: ParamSet<S, A>) -> Result<(), SolverError> {
        if set.fingerprint != self.fingerprint || set.c.tick_hz != self.c.tick_hz {
            return Err(SolverError::ForeignParamSet);
        }
        self.table = set.table;
        self.substeps = set.substeps;
        self.c = set.c;
        Ok(())
    }

    /// [`Solver::prepare`] for a topology without a solver (e.g. in another context than
    /// the one owning the solver).
    #[inline(never)]
    pub fn prepare_for(
        topo: &Topology<NODES, EDGES>,
        table: ForceTable<S>,
        config: &SolverConfig,
    ) -> Result<ParamSet<S, A>, SolverError> {
        if topo
            .edges()
            .iter()
            .any(|e| Topology::<NODES, EDGES>::rest_length(e) > A::MAX_REST_LENGTH_MM)
        {
            return Err(SolverError::SpringTooLong {
                max_mm: A::MAX_REST_LENGTH_MM as u32,
            });
        }
        let substeps = stability::substeps_for(topo, &table, config)?;
        Ok(Self::build(topo, table, config, substeps))
    }

    /// [`Solver::prepare_for`] with the substeps of a finished stability check of this
    /// table and configuration on `topo` (run in pieces: [`stability::StabilityCheck`]):
    /// its outcome, or why not (a check not done, or made for another table or
    /// configuration, is refused as [`SolverError::ForeignParamSet`]).
    #[inline(never)]
    pub fn prepare_checked(
        topo: &Topology<NODES, EDGES>,
        table: ForceTable<S>,
        config: &SolverConfig,
        check: &stability::StabilityCheck<NODES, EDGES>,
    ) -> Result<ParamSet<S, A>, SolverError> {
        if !check.made_for(&table, config) {
            return Err(SolverError::ForeignParamSet);
        }
        if topo
            .edges()
            .iter()
            .any(|e| Topology::<NODES, EDGES>::rest_length(e) > A::MAX_REST_LENGTH_MM)
        {
            return Err(SolverError::SpringTooLong {
                max_mm: A::MAX_REST_LENGTH_MM as u32,
            });
        }
        let substeps = check.outcome().ok_or(SolverError::ForeignParamSet)??;
        Ok(Self::build(topo, table, config, substeps))
    }

    /// The set for `substeps` substeps a tick.
    fn build(
        topo: &Topology<NODES, EDGES>,
        table: ForceTable<S>,
        config: &SolverConfig,
        substeps: u32,
    ) -> ParamSet<S, A> {
        let h = 1.0 / (config.tick_hz * substeps as f64);
        let c = Coeffs {
            arith: A::coeffs(&StepSpec {
                h,
                node_mass: config.node_mass,
                node_damping: config.node_damping,
                spring_damping: config.spring_damping,
                integrator: config.integrator,
                damping_factor: stability::damping_factor(topo, config, h),
            }),
            tick_hz: config.tick_hz as i32,
            coupling: CouplingQ::new(&config.coupling),
        };
        ParamSet {
            table: ArithTable::new(table),
            substeps,
            c,
            fingerprint: topo.fingerprint(),
        }
    }

    /// Checks `config` and returns the substeps per tick the stability bound asks for
    /// (see [`stability`]).
    pub fn substeps_for(
        topo: &Topology<NODES, EDGES>,
        table: &ForceTable<S>,
        config: &SolverConfig,
    ) -> Result<u32, SolverError> {
        stability::substeps_for(topo, table, config)
    }
}
