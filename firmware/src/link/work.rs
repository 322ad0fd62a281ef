//! [`Work`]: what the main loop works on besides the link's messages — nothing, a host's
//! replay, or a new tissue's check — one at a time, in one place, so that the two share
//! their memory (the board keeps one `Work` in `.bss`: a replay's solver and path, or a
//! check's topology and runs, never both).

use super::check::{CheckedTissue, TissueCheck};
use super::replayer::ReplayRun;
use mccs::{Arith, ForceTable};
use mccs_link::{NakReason, ReplaySpec, ToHost};

/// The main loop's one job at a time.
#[derive(Default)]
pub enum Work<const N: usize, const E: usize, const S: usize, A: Arith, const P: usize> {
    /// Nothing.
    #[default]
    Idle,
    /// A host's replay.
    Replay(ReplayRun<N, E, S, A, P>),
    /// A new tissue's check.
    Check(TissueCheck<N, E, S>),
}

impl<const N: usize, const E: usize, const S: usize, A: Arith, const P: usize> Work<N, E, S, A, P> {
    /// Nothing to do.
    pub const fn new() -> Self {
        Self::Idle
    }

    /// Whether a replay runs.
    pub fn replaying(&self) -> bool {
        matches!(self, Self::Replay(_))
    }

    /// Whether a tissue is being checked.
    pub fn checking(&self) -> bool {
        matches!(self, Self::Check(_))
    }

    /// Starts a replay of `spec` on `table` (abandoning one under way) at the link's
    /// tick `now`, waiting `patience` ticks at most for each sample; its first credit,
    /// or why not. Refused during a tissue's check. The replay is built where
    /// it stays ([`ReplayRun::start`]); out of line, so that no caller's frame holds one.
    #[inline(never)]
    pub fn begin_replay(
        &mut self,
        spec: &ReplaySpec,
        table: ForceTable<S>,
        narrow: bool,
        now: u32,
        patience: u32,
    ) -> Result<u32, NakReason> {
        if self.checking() {
            return Err(NakReason::Busy);
        }
        if !self.replaying() {
            *self = Self::Replay(ReplayRun::idle());
        }
        let started = match self {
            Self::Replay(run) => run
                .start(spec, table, narrow, now, patience)
                .map(|()| run.credit()),
            _ => Err(NakReason::Busy),
        };
        if started.is_err() {
            *self = Self::Idle;
        }
        started
    }

    /// A replay's path samples at the link's tick `now`; refused (and the replay
    /// abandoned) out of order.
    pub fn replay_path(&mut self, first: u32, points: &[u8], now: u32) -> Result<(), NakReason> {
        let Self::Replay(run) = self else {
            return Err(NakReason::Order);
        };
        let r = run.path(first, points, now);
        if r.is_err() {
            *self = Self::Idle;
        }
        r
    }

    /// Starts a tissue's check (nothing else may run).
    pub fn begin_check(&mut self, check: TissueCheck<N, E, S>) -> Result<(), NakReason> {
        if !matches!(self, Self::Idle) {
            return Err(NakReason::Busy);
        }
        *self = Self::Check(check);
        Ok(())
    }

    /// A slice of the work at the link's tick `now`: up to `replay_rows` replay ticks
    /// (their rows to `out`; a replay that has waited its patience for its path ends),
    /// or up to `check_steps` steps of a tissue's check; the check's outcome when it ends.
    /// Whether anything ran. Out of line, so that the link's poll does not hold its
    /// frames (a tick's solver locals, a checked tissue) while it decodes.
    #[inline(never)]
    pub fn run(
        &mut self,
        now: u32,
        replay_rows: u32,
        check_steps: u32,
        out: &mut dyn FnMut(&ToHost),
    ) -> (bool, Option<Result<CheckedTissue<S, A>, NakReason>>) {
        match self {
            Self::Idle => (false, None),
            Self::Replay(run) => {
                let mut ran = false;
                for _ in 0..replay_rows {
                    let (stepped, over) = run.step(now, out);
                    ran |= stepped;
                    if over {
                        *self = Self::Idle;
                        break;
                    }
                    if !stepped {
                        break;
                    }
                }
                (ran, None)
            }
            Self::Check(check) => {
                let outcome = check.advance::<A>(check_steps);
                if outcome.is_some() {
                    *self = Self::Idle;
                }
                (true, outcome)
            }
        }
    }
}
