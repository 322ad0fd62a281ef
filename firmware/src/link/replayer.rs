//! A replay on the device ([`ReplayRun`]): a patch and solver built for the host's
//! options, a path that arrives in pieces with flow control, one [`ReplayRow`](mccs_link::ReplayRow) per tick
//! computed by the same code as the host's `mccs replay --backend fixed`
//! ([`mccs_link::replay`]). It runs in the main loop, never in the tick, and never past
//! the samples it has received.
//!
//! Capacity: the patch of the device's topology (`NODES`, `EDGES`), its arithmetic `A`,
//! flat tissues (a cap's window is another type: refused, naming `--cap-radius`), and
//! `P` buffered samples.

use mccs::{
    Arith, Coupling, Flat, ForceTable, Integrator, Length, Proxy, ProxyConfig, Solver,
    SolverConfig, Topology, Window, WindowConfig,
};
use mccs_link::replay::PathPoint;
use mccs_link::{NakReason, ReplaySpec, SpecOption, ToHost};

/// What a replay steps.
enum Contact<const EDGES: usize> {
    Glued,
    Roaming {
        proxy: Proxy,
        window: Window<EDGES, Flat>,
    },
}

/// A replay under way: its solver and contact, its path's samples, how far it is.
///
/// Built in place ([`ReplayRun::idle`], then [`ReplayRun::start`]): the board keeps it
/// in `.bss`, and a 13 KB run built by value and moved there took two frames of 26 and
/// 31 KB of the main loop's stack (docs/safety.md, "The stack").
pub struct ReplayRun<
    const NODES: usize,
    const EDGES: usize,
    const S: usize,
    A: Arith,
    const P: usize,
> {
    /// `None` until started.
    solver: Option<Solver<NODES, EDGES, S, A>>,
    contact: Contact<EDGES>,
    path: [[i32; 3]; P],
    samples: u32,
    received: u32,
    done: u32,
    /// The link's tick of its last progress: its start, a piece of its path, a row.
    since: u32,
    /// The ticks it waits for its path's next sample before it is abandoned.
    patience: u32,
}

/// The solver configuration a spec asks for.
fn config_of(spec: &ReplaySpec) -> SolverConfig {
    SolverConfig {
        tick_hz: spec.tick_hz,
        node_mass: spec.node_mass_kg,
        spring_damping: spec.spring_damping,
        integrator: if spec.symplectic {
            Integrator::SymplecticDamped
        } else {
            Integrator::ImprovedEuler
        },
        coupling: Coupling {
            stiffness: spec.coupling_stiffness,
            damping: spec.coupling_damping,
            max_force: spec.max_force,
        },
        ..SolverConfig::default()
    }
}

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith, const P: usize>
    ReplayRun<NODES, EDGES, S, A, P>
{
    /// A run with nothing to replay (built where it stays; [`ReplayRun::start`] fills it).
    pub const fn idle() -> Self {
        Self {
            solver: None,
            contact: Contact::Glued,
            path: [[0; 3]; P],
            samples: 0,
            received: 0,
            done: 0,
            since: 0,
            patience: 0,
        }
    }

    /// Starts a replay of `spec` on `table` in this run (abandoning the one under way);
    /// `narrow`: whether `A` is the narrow arithmetic (what a spec must ask for); `now`
    /// the link's tick, `patience` the ticks it waits for its path's next sample
    /// ([`mccs_link::rates::REPLAY_STARVED_MS`]). On a refusal the run replays nothing.
    /// Out of line: the solver is built on this frame alone, and into its place.
    #[inline(never)]
    pub fn start(
        &mut self,
        spec: &ReplaySpec,
        table: ForceTable<S>,
        narrow: bool,
        now: u32,
        patience: u32,
    ) -> Result<(), NakReason> {
        self.solver = None;
        self.contact = Contact::Glued;
        self.samples = 0;
        self.received = 0;
        self.done = 0;
        self.since = now;
        self.patience = patience;
        let option = |option, limit| NakReason::Option { option, limit };
        if spec.narrow != narrow {
            return Err(option(SpecOption::Arith, narrow as i32));
        }
        if matches!(&spec.roaming, Some(r) if r.cap_radius.is_some()) {
            return Err(option(SpecOption::CapRadius, 0));
        }
        let config = config_of(spec);
        let grid = spec.grid as usize;
        let topo = Topology::<NODES, EDGES>::standard_patch(grid, spec.spacing_mm)
            .map_err(|_| option(SpecOption::Grid, max_grid::<NODES, EDGES>() as i32))?;
        let solver = self.solver.insert(
            Solver::<NODES, EDGES, S, A>::with_arith(topo, table, &config, A::default())
                .map_err(|_| option(SpecOption::Config, 0))?,
        );
        if let Some(r) = &spec.roaming {
            let proxy = solver
                .proxy(&ProxyConfig {
                    grid,
                    spacing: spec.spacing_mm,
                    mu_s: r.mu_s,
                    mu_k: r.mu_k,
                    probe_radius: r.probe_radius,
                })
                .map_err(|_| option(SpecOption::Tissue, 64))?;
            let window = solver
                .window(
                    &WindowConfig {
                        tissue_w: r.tissue_w as usize,
                        tissue_h: r.tissue_h as usize,
                        hysteresis: 0.1,
                    },
                    &Flat,
                    &proxy,
                    spec.start[0],
                    spec.start[1],
                )
                .map_err(|_| option(SpecOption::Tissue, 64))?;
            self.contact = Contact::Roaming { proxy, window };
        }
        self.samples = spec.samples;
        Ok(())
    }

    /// The first tick the device has no room for.
    pub fn credit(&self) -> u32 {
        self.done.saturating_add(P as u32).min(self.samples)
    }

    /// Samples for ticks `first …` ([`PathPoint`]s) at the link's tick `now`; refused
    /// out of order or past the credit (the caller then abandons the replay).
    pub fn path(&mut self, first: u32, points: &[u8], now: u32) -> Result<(), NakReason> {
        let n = (points.len() / PathPoint::BYTES) as u32;
        let all = PathPoint::all(points);
        let (Some(all), true) = (
            all,
            first == self.received && self.received.saturating_add(n) <= self.credit(),
        ) else {
            return Err(NakReason::Order);
        };
        for (k, p) in all.enumerate() {
            if let Some(slot) = self.path.get_mut((first as usize + k) % P) {
                *slot = p.0;
            }
        }
        self.received += n;
        self.since = now;
        Ok(())
    }

    /// One tick, if its sample has arrived: its row to `out` (then, after the last, the
    /// end). Without its sample, at the link's tick `now`: the end, where it has no
    /// samples or has waited its patience for the next (`ReplayEnd` with the ticks it
    /// ran), else nothing. Whether it ran, and whether the replay is over.
    pub fn step(&mut self, now: u32, out: &mut dyn FnMut(&ToHost)) -> (bool, bool) {
        let Some(solver) = self.solver.as_mut() else {
            return (false, false);
        };
        if self.done >= self.received {
            let over = self.done == self.samples || now.wrapping_sub(self.since) > self.patience;
            if over {
                out(&ToHost::ReplayEnd { ticks: self.done });
            }
            return (false, over);
        }
        let tick = self.done;
        let probe = self
            .path
            .get(tick as usize % P)
            .copied()
            .unwrap_or([0; 3])
            .map(Length::from_bits);
        let row = match &mut self.contact {
            Contact::Glued => mccs_link::replay::glued(solver, tick, probe),
            Contact::Roaming { proxy, window } => {
                mccs_link::replay::roaming(solver, proxy, window, tick, probe)
            }
        };
        out(&ToHost::ReplayRow(row));
        self.done += 1;
        self.since = now;
        if self.done == self.samples {
            out(&ToHost::ReplayEnd { ticks: self.done });
            return (true, true);
        }
        if self.done.is_multiple_of((P as u32 / 2).max(1)) {
            out(&ToHost::ReplayCredit {
                until: self.credit(),
            });
        }
        (true, false)
    }
}

/// The largest standard patch a topology of these capacities holds.
pub fn max_grid<const NODES: usize, const EDGES: usize>() -> usize {
    (3..=64)
        .take_while(|&n| {
            let (nodes, edges) = mccs::topology::standard_capacity(n);
            nodes <= NODES && edges <= EDGES
        })
        .last()
        .unwrap_or(0)
}
