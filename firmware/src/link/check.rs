//! A new tissue checked in pieces ([`TissueCheck`]): the stability of its substeps on the
//! device's live patch ([`mccs::solver::stability::StabilityCheck`]: the search, or the
//! check of the host's proposal), run a slice at a time between the link's other work,
//! then its tick against the device's budget. The live tissue renders meanwhile; the
//! device never takes a host's number unchecked.

use mccs::solver::stability::StabilityCheck;
use mccs::{Arith, ForceTable, ParamSet, Solver, SolverConfig, SolverError, Topology};
use mccs_link::NakReason;

/// What a tick of the device costs, instructions: a tissue needing `n` substeps runs in
/// `base + n × per_substep`, held to `tick` (the device's measured costs: the bench's).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TickBudget {
    /// Instructions a tick may take.
    pub tick: u32,
    /// What a tick costs besides its substeps.
    pub base: u32,
    /// What one substep costs.
    pub per_substep: u32,
}

impl TickBudget {
    /// The instructions a tick of `substeps` takes.
    pub const fn cost(&self, substeps: u32) -> u32 {
        self.base
            .saturating_add(self.per_substep.saturating_mul(substeps))
    }

    /// What a tick of `substeps` would take where that passes the budget: the one rule
    /// a tissue is refused by, over the link (`NakReason::Budget`) and at a board's
    /// start-up.
    pub const fn over(&self, substeps: u32) -> Option<u32> {
        let cost = self.cost(substeps);
        if cost > self.tick {
            Some(cost)
        } else {
            None
        }
    }

    /// The most substeps within the budget.
    pub const fn most_substeps(&self) -> u32 {
        match self
            .tick
            .saturating_sub(self.base)
            .checked_div(self.per_substep)
        {
            Some(n) => n,
            None => u32::MAX,
        }
    }
}

/// A tissue that passed its check: what the tick swaps in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CheckedTissue<const S: usize, A: Arith> {
    /// Its parameter set on the live patch.
    pub set: ParamSet<S, A>,
    /// Its friction (`None`: the live one's).
    pub friction: Option<mccs::Friction>,
    /// Its hash.
    pub hash: u32,
}

/// A tissue's check in progress.
pub struct TissueCheck<const N: usize, const E: usize, const S: usize> {
    topo: Topology<N, E>,
    table: ForceTable<S>,
    config: SolverConfig,
    friction: Option<mccs::Friction>,
    hash: u32,
    budget: TickBudget,
    stability: StabilityCheck<N, E>,
}

impl<const N: usize, const E: usize, const S: usize> TissueCheck<N, E, S> {
    /// The check of `table` (already validated and within its bound) on the live patch
    /// (`grid` nodes a side at `spacing` mm) with `config`; `proposal`: the host's
    /// substeps (0: search). Out of line: its topology is built on this frame alone.
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        grid: usize,
        spacing: f64,
        table: ForceTable<S>,
        config: &SolverConfig,
        friction: Option<mccs::Friction>,
        hash: u32,
        budget: TickBudget,
        proposal: u16,
    ) -> Result<Self, NakReason> {
        let topo =
            Topology::<N, E>::standard_patch(grid, spacing).map_err(|_| NakReason::Solver)?;
        let proposal = (proposal != 0).then_some(proposal as u32);
        let stability =
            StabilityCheck::new(&topo, &table, config, proposal).map_err(|e| nak(e, budget))?;
        Ok(Self {
            topo,
            table,
            config: *config,
            friction,
            hash,
            budget,
            stability,
        })
    }

    /// Steps of the linearised patch run so far.
    pub fn steps_run(&self) -> u32 {
        self.stability.steps_run()
    }

    /// Runs up to `steps` more steps of the check; its outcome once known.
    pub fn advance<A: Arith>(
        &mut self,
        steps: u32,
    ) -> Option<Result<CheckedTissue<S, A>, NakReason>> {
        let outcome = self.stability.advance(&self.topo, steps)?;
        Some(self.finish(outcome))
    }

    fn finish<A: Arith>(
        &self,
        outcome: Result<u32, SolverError>,
    ) -> Result<CheckedTissue<S, A>, NakReason> {
        let substeps = outcome.map_err(|e| nak(e, self.budget))?;
        if let Some(cost) = self.budget.over(substeps) {
            return Err(NakReason::Budget {
                substeps: substeps.min(u16::MAX as u32) as u16,
                instructions: cost,
                budget: self.budget.tick,
            });
        }
        let set = Solver::<N, E, S, A>::prepare_checked(
            &self.topo,
            self.table,
            &self.config,
            &self.stability,
        )
        .map_err(|e| nak(e, self.budget))?;
        Ok(CheckedTissue {
            set,
            friction: self.friction,
            hash: self.hash,
        })
    }
}

/// A solver's refusal as the host hears it: too many substeps is over the budget (with
/// the figures), a proposal that failed its check says so, the rest is the solver's.
fn nak(e: SolverError, budget: TickBudget) -> NakReason {
    match e {
        SolverError::TooManySubsteps { needed } => NakReason::Budget {
            substeps: needed.min(u16::MAX as u32) as u16,
            instructions: budget.cost(needed),
            budget: budget.tick,
        },
        SolverError::Unverified { substeps } => NakReason::Stability {
            substeps: substeps.min(u16::MAX as u32) as u16,
        },
        _ => NakReason::Solver,
    }
}
