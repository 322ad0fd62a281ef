//! A replay on the device: a patch and solver built for the host's options, a path that
//! arrives in pieces with flow control, one [`ReplayRow`] per tick computed by the same
//! code as the host's `mccs replay --backend fixed` ([`mccs_link::replay`]). It runs in
//! the main loop, never in the tick, and never past the samples it has received.
//!
//! Capacity: the patch of the device's topology (`NODES`, `EDGES`), its arithmetic `A`,
//! flat tissues (a cap's window is another type: refused, naming `--cap-radius`), and
//! `P` buffered samples.

use mccs::{
    Arith, Coupling, Flat, ForceTable, Integrator, Length, Proxy, ProxyConfig, Solver,
    SolverConfig, Topology, Window, WindowConfig,
};
use mccs_link::message::{NakReason, ReplaySpec, SpecOption, ToHost};

/// What a replay steps.
enum Contact<const EDGES: usize> {
    Glued,
    Roaming {
        proxy: Proxy,
        window: Window<EDGES, Flat>,
    },
}

/// The solver and contact of a replay under way.
struct Run<const NODES: usize, const EDGES: usize, const S: usize, A: Arith> {
    solver: Solver<NODES, EDGES, S, A>,
    contact: Contact<EDGES>,
}

/// A device's replays.
pub struct Replayer<
    const NODES: usize,
    const EDGES: usize,
    const S: usize,
    A: Arith,
    const P: usize,
> {
    run: Option<Run<NODES, EDGES, S, A>>,
    path: [[i32; 3]; P],
    samples: u32,
    received: u32,
    done: u32,
    narrow: bool,
}

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith, const P: usize>
    Replayer<NODES, EDGES, S, A, P>
{
    /// Idle; `narrow`: whether `A` is the narrow arithmetic (what a spec must ask for).
    pub const fn new(narrow: bool) -> Self {
        Self {
            run: None,
            path: [[0; 3]; P],
            samples: 0,
            received: 0,
            done: 0,
            narrow,
        }
    }

    /// Whether a replay runs.
    pub fn running(&self) -> bool {
        self.run.is_some()
    }

    /// The first tick the device has no room for.
    pub fn credit(&self) -> u32 {
        self.done.saturating_add(P as u32).min(self.samples)
    }

    /// Starts a replay of `spec` on `table`; the first credit, or why not.
    pub fn begin(&mut self, spec: &ReplaySpec, table: ForceTable<S>) -> Result<u32, NakReason> {
        let option = |option, limit| NakReason::Option { option, limit };
        if spec.narrow != self.narrow {
            return Err(option(SpecOption::Arith, self.narrow as i32));
        }
        let config = SolverConfig {
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
        };
        let grid = spec.grid as usize;
        let topo = Topology::<NODES, EDGES>::standard_patch(grid, spec.spacing_mm)
            .map_err(|_| option(SpecOption::Grid, max_grid::<NODES, EDGES>() as i32))?;
        let mut solver =
            Solver::<NODES, EDGES, S, A>::with_arith(topo, table, &config, A::default())
                .map_err(|_| option(SpecOption::Config, 0))?;
        let contact = match &spec.roaming {
            None => Contact::Glued,
            Some(r) if r.cap_radius.is_some() => return Err(option(SpecOption::CapRadius, 0)),
            Some(r) => {
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
                Contact::Roaming { proxy, window }
            }
        };
        self.run = Some(Run { solver, contact });
        self.samples = spec.samples;
        self.received = 0;
        self.done = 0;
        Ok(self.credit())
    }

    /// Samples for ticks `first …` (12 bytes each); refused out of order or past the
    /// credit (the replay is then abandoned).
    pub fn path(&mut self, first: u32, points: &[u8]) -> Result<(), NakReason> {
        let n = (points.len() / 12) as u32;
        if self.run.is_none()
            || first != self.received
            || !points.len().is_multiple_of(12)
            || self.received.saturating_add(n) > self.credit()
        {
            self.run = None;
            return Err(NakReason::Order);
        }
        for (k, p) in points.chunks_exact(12).enumerate() {
            let w = |i: usize| i32::from_le_bytes([p[i], p[i + 1], p[i + 2], p[i + 3]]);
            self.path[(first as usize + k) % P] = [w(0), w(4), w(8)];
        }
        self.received += n;
        Ok(())
    }

    /// One tick, if its sample has arrived: its row to `out` (then, after the last, the
    /// end). Returns whether it ran.
    pub fn step(&mut self, out: &mut dyn FnMut(&ToHost)) -> bool {
        let Some(run) = self.run.as_mut() else {
            return false;
        };
        if self.done >= self.received {
            return false;
        }
        let tick = self.done;
        let probe = self.path[tick as usize % P].map(Length::from_bits);
        let row = match &mut run.contact {
            Contact::Glued => mccs_link::replay::glued(&mut run.solver, tick, probe),
            Contact::Roaming { proxy, window } => {
                mccs_link::replay::roaming(&mut run.solver, proxy, window, tick, probe)
            }
        };
        out(&ToHost::ReplayRow(row));
        self.done += 1;
        if self.done == self.samples {
            out(&ToHost::ReplayEnd { ticks: self.done });
            self.run = None;
        } else if self.done.is_multiple_of((P as u32 / 2).max(1)) {
            out(&ToHost::ReplayCredit {
                until: self.credit(),
            });
        }
        true
    }

    /// Abandons a replay.
    pub fn abort(&mut self) {
        self.run = None;
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
