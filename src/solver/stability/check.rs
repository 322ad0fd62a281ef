//! [`StabilityCheck`]: the estimated bound of [`super::bounds`] run in pieces, so that a
//! device can check a new tissue between other work (its link, its replays) without
//! holding its main loop for the whole estimate; and the check of a proposed substep
//! count, which takes two runs of the linearised step instead of the search's ten (twelve
//! for the symplectic option).
//!
//! Searching, it makes the same decisions on the same runs as [`super::bounds`] and
//! ends with the same substeps (tested). Verifying `n` substeps (a host's, computed by
//! the same search in `f64` time): the substep `h = 1/(f n)` is taken when it is within
//! the conservative bound (no run), or else when the step at `h / ESTIMATE_MARGIN` does
//! not grow (`growth ≤ 1`: the margin the search keeps below the edge) and the step at
//! `h` visibly dies out (`growth ≤ TRUSTED_DECAY`, the search's own trust test); it is
//! refused otherwise. Either way the device decides on its own runs: a number it is
//! given only says where to look.

use super::linearised::{Linearised, Run, STEPS_PER_RUN};
use super::{closed_form, substeps_of, Bound, CONSERVATIVE_FACTOR, ESTIMATE_MARGIN, TRUSTED_DECAY};
use crate::arith::Integrator;
use crate::solver::{SolverConfig, SolverError};
use crate::table::ForceTable;
use crate::topology::Topology;

/// Steps of the linearised patch a whole check runs at most: the search's runs (its top,
/// its bottom, its bisections — 7 for the paper's integrator, 9 for the symplectic
/// option — and the trust test: 10 or 12).
pub const MAX_CHECK_STEPS: u32 = 12 * STEPS_PER_RUN;

/// What the check runs next.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Next {
    /// The search's top, `top · closed`.
    Top,
    /// Its bottom, `closed / 4`.
    Bottom,
    /// Bisection step `k` at `sqrt(lo · hi)`.
    Bisect(u32),
    /// The trust test at `ESTIMATE_MARGIN · e`.
    Trust {
        /// The estimated edge.
        e: f64,
    },
    /// A proposal's margin: the step at `h / ESTIMATE_MARGIN` must not grow.
    Edge,
    /// A proposal's trust test at `h`.
    Decay,
}

/// A stability check in progress ([`StabilityCheck::advance`] until it is done).
#[derive(Clone, Debug)]
pub struct StabilityCheck<const NODES: usize, const EDGES: usize> {
    k_max: f64,
    config: SolverConfig,
    closed: f64,
    lo: f64,
    hi: f64,
    /// A proposal: its substeps and their substep, s.
    proposal: Option<(u32, f64)>,
    next: Next,
    /// The run under way, with its `h`, or its outcome known at once (infinite).
    run: Option<(f64, Result<Run<NODES, EDGES>, f32>)>,
    done: Option<Result<u32, SolverError>>,
    steps: u32,
    /// The search's estimated edge and the substep it chose, once known.
    estimated: Option<f64>,
    chosen: f64,
}

impl<const NODES: usize, const EDGES: usize> StabilityCheck<NODES, EDGES> {
    /// A check of `table` on `topo` with `config`: the search for the substeps
    /// (`proposal` `None`), or the check of a proposed count. Fails at once on a
    /// configuration out of range or a patch without damping.
    pub fn new<const S: usize>(
        topo: &Topology<NODES, EDGES>,
        table: &ForceTable<S>,
        config: &SolverConfig,
        proposal: Option<u32>,
    ) -> Result<Self, SolverError> {
        config.validate()?;
        let k_max = table.max_stiffness().to_num::<f64>();
        let closed = closed_form(topo, k_max, config)?;
        let top = match config.integrator {
            Integrator::ImprovedEuler => 4.0,
            Integrator::SymplecticDamped => 16.0,
        };
        let mut check = Self {
            k_max,
            config: *config,
            closed,
            lo: closed / 4.0,
            hi: top * closed,
            proposal: None,
            next: Next::Top,
            run: None,
            done: None,
            steps: 0,
            estimated: None,
            chosen: CONSERVATIVE_FACTOR * closed,
        };
        match (proposal, config.bound) {
            (Some(n), _) => {
                let n = n.max(1);
                if n > config.max_substeps {
                    return Err(SolverError::TooManySubsteps { needed: n });
                }
                let h = 1.0 / (config.tick_hz * n as f64);
                check.proposal = Some((n, h));
                if h <= CONSERVATIVE_FACTOR * closed {
                    check.done = Some(substeps_of(h, config));
                } else {
                    check.next = Next::Edge;
                }
            }
            (None, Bound::Conservative) => {
                check.done = Some(substeps_of(CONSERVATIVE_FACTOR * closed, config));
            }
            (None, Bound::Estimated) => {}
        }
        Ok(check)
    }

    /// Whether the check is of `table` with `config`.
    pub fn made_for<const S: usize>(&self, table: &ForceTable<S>, config: &SolverConfig) -> bool {
        self.k_max == table.max_stiffness().to_num::<f64>() && self.config == *config
    }

    /// The outcome, once known: the substeps, or why not.
    pub fn outcome(&self) -> Option<Result<u32, SolverError>> {
        self.done
    }

    /// The bounds the search found (once done; a proposal's check reports the substep
    /// it verified as chosen).
    pub fn bounds(&self) -> super::Bounds {
        super::Bounds {
            closed: self.closed,
            estimated: self.estimated,
            chosen: self.proposal.map_or(self.chosen, |(_, h)| h),
        }
    }

    /// Steps of the linearised patch run so far.
    pub fn steps_run(&self) -> u32 {
        self.steps
    }

    /// Runs up to `steps` more steps of the linearised patch (`topo` must be the one the
    /// check was made for); the outcome once known.
    pub fn advance(
        &mut self,
        topo: &Topology<NODES, EDGES>,
        steps: u32,
    ) -> Option<Result<u32, SolverError>> {
        let lin = Linearised::new(topo, self.k_max, &self.config);
        let mut left = steps;
        while self.done.is_none() && left > 0 {
            let h = self.h_of(self.next);
            let (_, run) = self.run.get_or_insert_with(|| (h, lin.start(h)));
            let growth = match run {
                Err(g) => Some(*g),
                Ok(r) => {
                    let before = r.steps();
                    let out = lin.advance(r, left);
                    // (A run ends early where it overflowed or its energy moved past `DECIDED`.)
                    let ran = r.steps() - before;
                    self.steps = self.steps.saturating_add(ran);
                    left -= ran.min(left);
                    out
                }
            };
            if let Some(g) = growth {
                self.run = None;
                self.decide(g);
            }
        }
        self.done
    }

    /// The substep a step of the check runs.
    fn h_of(&self, next: Next) -> f64 {
        match next {
            Next::Top => self.hi,
            Next::Bottom => self.lo,
            Next::Bisect(_) => libm::sqrt(self.lo * self.hi),
            Next::Trust { e } => ESTIMATE_MARGIN * e,
            Next::Edge => self.proposal.map_or(0.0, |(_, h)| h / ESTIMATE_MARGIN),
            Next::Decay => self.proposal.map_or(0.0, |(_, h)| h),
        }
    }

    /// The search's or the proposal's next step after a run that grew by `g`.
    fn decide(&mut self, g: f32) {
        let stable = g <= 1.0;
        let steps = match self.config.integrator {
            Integrator::ImprovedEuler => 7,
            Integrator::SymplecticDamped => 9,
        };
        match self.next {
            Next::Top if stable => self.next = Next::Trust { e: self.hi },
            Next::Top => self.next = Next::Bottom,
            Next::Bottom if stable => self.next = Next::Bisect(0),
            Next::Bottom => self.next = Next::Trust { e: 0.5 * self.lo },
            Next::Bisect(k) => {
                let mid = libm::sqrt(self.lo * self.hi);
                if stable {
                    self.lo = mid;
                } else {
                    self.hi = mid;
                }
                self.next = if k + 1 < steps {
                    Next::Bisect(k + 1)
                } else {
                    Next::Trust { e: self.lo }
                };
            }
            Next::Trust { e } => {
                let h = if g <= TRUSTED_DECAY {
                    ESTIMATE_MARGIN * e
                } else {
                    CONSERVATIVE_FACTOR * self.closed
                };
                self.estimated = Some(e);
                self.chosen = h;
                self.done = Some(substeps_of(h, &self.config));
            }
            Next::Edge if stable => self.next = Next::Decay,
            Next::Edge | Next::Decay => {
                let (n, h) = self.proposal.unwrap_or((0, 0.0));
                self.done = Some(if g <= TRUSTED_DECAY && self.next == Next::Decay {
                    substeps_of(h, &self.config)
                } else {
                    Err(SolverError::Unverified { substeps: n })
                });
            }
        }
    }
}
