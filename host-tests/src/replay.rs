//! Replaying a probe trajectory against the standard patch, in the fixed-point core
//! (`mccs::Solver`, either arithmetic) or the `f64` twin (`patch::Twin`): per tick the
//! device force, the contact node's displacement, and the largest displacement of any
//! node. Or, with a tissue, against the `f64` roaming probe (`roam::RoamTwin`): per tick
//! the device force, the proxy, the contact's state and the window's shifts.

use crate::patch::{max_stiffness, substeps, Mesh, Twin, TwinConfig, TWIN_MAX_SUBSTEPS, V};
use crate::reference::Reference;
use crate::roam::{Friction, RoamConfig, RoamError, RoamTwin, Tissue};
use crate::trajectory::Trajectory;
use mccs::{
    Arith, Flat, ForceTable, Length, Params, Proxy, ProxyConfig, ProxyError, ShapeSpec, Solver,
    SolverConfig, SolverError, Sphere, Topology, WindowConfig,
};

/// Capacities of the fixed backend's solver: N = 12 has 101 node slots and 558 springs.
pub const FIXED_NODES: usize = 101;
/// See [`FIXED_NODES`].
pub const FIXED_EDGES: usize = 558;
/// The largest grid of the fixed backend.
pub const MAX_GRID_FIXED: usize = 12;

/// Which solver replays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Engine {
    /// The `f64` twin.
    Reference,
    /// The fixed-point core in the wide arithmetic.
    Wide,
    /// The fixed-point core in the narrow arithmetic (the M0's).
    Narrow,
}

/// One tick's output.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Row {
    /// The probe sample's time, s.
    pub time: f64,
    /// The probe sample's position, mm.
    pub probe: [f64; 3],
    /// The device force, N.
    pub force: [f64; 3],
    /// The contact node's displacement from rest, mm.
    pub contact: [f64; 3],
    /// The largest |displacement| from rest of any node, mm.
    pub max_disp: f64,
}

/// Why a replay could not run.
#[derive(Clone, Debug, PartialEq)]
pub enum ReplayError {
    /// The solver refused the configuration.
    Solver(SolverError),
    /// The table could not be built.
    Table(mccs::TableError),
    /// The grid or spacing.
    Topology(mccs::TopologyError),
    /// The roaming configuration.
    Roam(RoamError),
    /// The core's proxy or window refused the configuration.
    Proxy(ProxyError),
}

impl std::fmt::Display for ReplayError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Solver(e) => e.fmt(f),
            Self::Table(e) => e.fmt(f),
            Self::Topology(e) => e.fmt(f),
            Self::Roam(e) => e.fmt(f),
            Self::Proxy(e) => e.fmt(f),
        }
    }
}

/// A replay: the patch, the solver's configuration and the engine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Replay {
    /// Surface nodes per side.
    pub grid: usize,
    /// Grid spacing, mm.
    pub spacing: f64,
    /// The solver's configuration (its `tick_hz` is the sampling rate).
    pub config: SolverConfig,
    /// The engine.
    pub engine: Engine,
}

impl Replay {
    /// Runs `traj` through the patch with `params`; `row` gets each tick's output. The
    /// fixed-point engines run the table [`ForceTable::new`] builds (65 knots, held to
    /// the product's bound).
    pub fn run(
        &self,
        params: &Params,
        traj: &Trajectory,
        row: impl FnMut(Row),
    ) -> Result<(), ReplayError> {
        self.run_with::<64>(params, None, traj, row)
    }

    /// [`Replay::run`] with the fixed-point engines on `table` (built for `params`; `None`:
    /// [`ForceTable::new`]'s); the reference engine runs the law of `params`.
    pub fn run_with<const S: usize>(
        &self,
        params: &Params,
        table: Option<&ForceTable<S>>,
        traj: &Trajectory,
        mut row: impl FnMut(Row),
    ) -> Result<(), ReplayError> {
        match self.engine {
            Engine::Reference => self.run_twin(params, traj, &mut row),
            Engine::Wide => self.run_fixed(params, table, traj, mccs::Wide, &mut row),
            Engine::Narrow => self.run_fixed(params, table, traj, mccs::Narrow, &mut row),
        }
    }

    fn run_fixed<A: Arith, const S: usize>(
        &self,
        params: &Params,
        table: Option<&ForceTable<S>>,
        traj: &Trajectory,
        arith: A,
        row: &mut dyn FnMut(Row),
    ) -> Result<(), ReplayError> {
        let mut s = self.solver(params, table, self.spacing, arith)?;
        for (tick, (time, p)) in traj.ticks(self.config.tick_hz).enumerate() {
            let raw = mccs_link::replay::glued(&mut s, tick as u32, probe_bits(p));
            row(Row::of_raw(time, p, &raw));
        }
        Ok(())
    }

    fn run_twin(
        &self,
        params: &Params,
        traj: &Trajectory,
        row: &mut dyn FnMut(Row),
    ) -> Result<(), ReplayError> {
        let law = Reference::new(params).map_err(|e| ReplayError::Table(e.into()))?;
        let tc = self.twin_dynamics(&law, self.spacing)?;
        let mut twin = Twin::new(Mesh::standard(self.grid, self.spacing), law, tc);
        let c = twin.mesh.contact;
        for (time, p) in traj.ticks(self.config.tick_hz) {
            let force = twin.step(p);
            let disp = |i: usize| -> [f64; 3] {
                std::array::from_fn(|k| twin.x[i][k] - twin.mesh.rest[i][k])
            };
            row(Row {
                time,
                probe: p,
                force,
                contact: disp(c),
                max_disp: max_disp_twin(&twin),
            });
        }
        Ok(())
    }
}

impl Replay {
    /// The substeps per tick this replay's engine takes on its patch (the core's
    /// stability bound, or the twin's rule), or why it cannot run: what a replay checks
    /// before its first tick.
    pub fn substeps<const S: usize>(
        &self,
        params: &Params,
        table: Option<&ForceTable<S>>,
    ) -> Result<u32, ReplayError> {
        match self.engine {
            Engine::Reference => {
                let law = Reference::new(params).map_err(|e| ReplayError::Table(e.into()))?;
                Ok(self.twin_dynamics(&law, self.spacing)?.substeps)
            }
            Engine::Wide => Ok(self
                .solver(params, table, self.spacing, mccs::Wide)?
                .substeps()),
            Engine::Narrow => Ok(self
                .solver(params, table, self.spacing, mccs::Narrow)?
                .substeps()),
        }
    }

    /// The fixed-point solver of the standard patch at `spacing`, on `table` (`None`:
    /// [`ForceTable::new`]'s for `params`).
    fn solver<A: Arith, const S: usize>(
        &self,
        params: &Params,
        table: Option<&ForceTable<S>>,
        spacing: f64,
        arith: A,
    ) -> Result<Solver<FIXED_NODES, FIXED_EDGES, S, A>, ReplayError> {
        let table = match table {
            Some(t) => *t,
            None => ForceTable::<S>::new(params).map_err(ReplayError::Table)?,
        };
        let topo = Topology::<FIXED_NODES, FIXED_EDGES>::standard_patch(self.grid, spacing)
            .map_err(ReplayError::Topology)?;
        Solver::with_arith(topo, table, &self.config, arith).map_err(ReplayError::Solver)
    }

    /// The twin's dynamics for the standard patch at `spacing`, at the substeps the twin's
    /// rule gives it.
    fn twin_dynamics(&self, law: &Reference, spacing: f64) -> Result<TwinConfig, ReplayError> {
        let mesh = Mesh::standard(self.grid, spacing);
        let mut tc = TwinConfig::from_solver(&self.config, 0);
        let k_max = max_stiffness(law);
        let n = substeps(&mesh, k_max, &tc).ok_or(ReplayError::Solver(SolverError::NoDamping))?;
        if n > TWIN_MAX_SUBSTEPS {
            return Err(ReplayError::Solver(SolverError::TooManySubsteps {
                needed: n,
            }));
        }
        tc.substeps = n;
        Ok(tc)
    }
}

/// A roaming replay's tissue, friction and probe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Roaming {
    /// The tissue (its spacing is the window's).
    pub tissue: Tissue,
    /// Friction.
    pub friction: Friction,
    /// Probe radius, mm.
    pub probe_radius: f64,
}

/// One tick of a roaming replay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoamRow {
    /// The probe sample's time, s.
    pub time: f64,
    /// The probe sample's position (tissue frame), mm.
    pub probe: V,
    /// The device force, N.
    pub force: V,
    /// The proxy's centre, mm (the probe out of contact).
    pub proxy: V,
    /// Whether the probe touches.
    pub contact: bool,
    /// Whether the contact slips.
    pub slipping: bool,
    /// Window shifts so far.
    pub window_shifts: u32,
    /// The largest |displacement| from rest of any node of the window, mm.
    pub max_disp: f64,
}

impl Replay {
    /// Runs `traj` (tissue frame: origin at the tissue's centre, its top at z = 0)
    /// through the `f64` roaming probe: an `grid × grid` window of `roaming.tissue`,
    /// centred at the first sample, at the substeps the patch twin's rule gives the flat
    /// window.
    pub fn roam(
        &self,
        params: &Params,
        traj: &Trajectory,
        roaming: &Roaming,
        row: impl FnMut(RoamRow),
    ) -> Result<(), ReplayError> {
        self.roam_with::<64>(params, None, traj, roaming, row)
    }

    /// [`Replay::roam`] with the fixed-point engines on `table`, as [`Replay::run_with`].
    pub fn roam_with<const S: usize>(
        &self,
        params: &Params,
        table: Option<&ForceTable<S>>,
        traj: &Trajectory,
        roaming: &Roaming,
        mut row: impl FnMut(RoamRow),
    ) -> Result<(), ReplayError> {
        match self.engine {
            Engine::Reference => self.roam_twin(params, traj, roaming, &mut row),
            Engine::Wide => self.roam_fixed(params, table, traj, roaming, mccs::Wide, &mut row),
            Engine::Narrow => self.roam_fixed(params, table, traj, roaming, mccs::Narrow, &mut row),
        }
    }

    /// The core's roaming ([`mccs::Solver::step_roaming`]).
    fn roam_fixed<A: Arith, const S: usize>(
        &self,
        params: &Params,
        table: Option<&ForceTable<S>>,
        traj: &Trajectory,
        roaming: &Roaming,
        arith: A,
        row: &mut dyn FnMut(RoamRow),
    ) -> Result<(), ReplayError> {
        let spacing = roaming.tissue.spacing;
        let mut s = self.solver(params, table, spacing, arith)?;
        let mut proxy = s
            .proxy(&ProxyConfig {
                grid: self.grid,
                spacing,
                mu_s: roaming.friction.mu_s,
                mu_k: roaming.friction.mu_k,
                probe_radius: roaming.probe_radius,
            })
            .map_err(ReplayError::Proxy)?;
        let window_config = WindowConfig {
            tissue_w: roaming.tissue.w,
            tissue_h: roaming.tissue.h,
            hysteresis: 0.1,
        };
        match roaming.tissue.shape {
            crate::roam::Shape::Flat => {
                Self::roam_window(&mut s, &mut proxy, &window_config, &Flat, traj, self, row)
            }
            crate::roam::Shape::Cap { radius } => {
                let cap = Sphere { radius_mm: radius };
                Self::roam_window(&mut s, &mut proxy, &window_config, &cap, traj, self, row)
            }
        }
    }

    /// [`Replay::roam_fixed`]'s run on a window of `shape`.
    fn roam_window<A: Arith, const S: usize, Spec: ShapeSpec>(
        s: &mut Solver<FIXED_NODES, FIXED_EDGES, S, A>,
        proxy: &mut Proxy,
        window_config: &WindowConfig,
        shape: &Spec,
        traj: &Trajectory,
        replay: &Replay,
        row: &mut dyn FnMut(RoamRow),
    ) -> Result<(), ReplayError> {
        let mut ticks = traj.ticks(replay.config.tick_hz).peekable();
        let start = ticks.peek().map_or([0.0; 3], |(_, p)| *p);
        let mut window = s
            .window(window_config, shape, proxy, start[0], start[1])
            .map_err(ReplayError::Proxy)?;
        for (tick, (time, p)) in ticks.enumerate() {
            let raw = mccs_link::replay::roaming(s, proxy, &mut window, tick as u32, probe_bits(p));
            row(RoamRow::of_raw(time, p, &raw));
        }
        Ok(())
    }

    /// The `f64` reference's roaming.
    fn roam_twin(
        &self,
        params: &Params,
        traj: &Trajectory,
        roaming: &Roaming,
        row: &mut dyn FnMut(RoamRow),
    ) -> Result<(), ReplayError> {
        let law = Reference::new(params).map_err(|e| ReplayError::Table(e.into()))?;
        let cfg = RoamConfig {
            tissue: roaming.tissue,
            n: self.grid,
            dynamics: self.twin_dynamics(&law, roaming.tissue.spacing)?,
            friction: roaming.friction,
            probe_radius: roaming.probe_radius,
            window_hysteresis: 0.1,
        };
        let mut ticks = traj.ticks(self.config.tick_hz).peekable();
        let start = ticks.peek().map_or([0.0; 3], |(_, p)| *p);
        let mut twin = RoamTwin::new(cfg, law, start[0], start[1]).map_err(ReplayError::Roam)?;
        for (time, p) in ticks {
            let out = twin.step(p);
            let contact = twin.contact();
            row(RoamRow {
                time,
                probe: p,
                force: out.force,
                proxy: out.proxy,
                contact: contact.is_some(),
                slipping: contact.is_some_and(|c| c.slip.0),
                window_shifts: twin.shifts,
                max_disp: max_disp_twin(twin.window()),
            });
        }
        Ok(())
    }
}

/// A probe sample as the core's lengths (saturated at ±128 mm): what the fixed-point
/// engines step on, here and on a device over the link.
pub fn probe_bits(p: [f64; 3]) -> [Length; 3] {
    p.map(Length::saturating_from_num)
}

/// Q24 mm bits as mm.
fn mm(bits: [i32; 3]) -> [f64; 3] {
    bits.map(|b| Length::from_bits(b).to_num::<f64>())
}

impl Row {
    /// A glued tick's row from the core's raw outputs (here or from a device), at the
    /// sample's `time` and position `probe`.
    pub fn of_raw(time: f64, probe: [f64; 3], raw: &mccs_link::ReplayRow) -> Row {
        Row {
            time,
            probe,
            force: raw.force.map(|b| mccs::Force::from_bits(b).to_num::<f64>()),
            contact: mm(raw.point),
            max_disp: norm(mm(raw.max_disp)),
        }
    }
}

impl RoamRow {
    /// A roaming tick's row from the core's raw outputs, as [`Row::of_raw`]: the proxy
    /// in the tissue's frame (the probe out of contact).
    pub fn of_raw(time: f64, probe: [f64; 3], raw: &mccs_link::ReplayRow) -> RoamRow {
        use mccs_link::replay::{CONTACT, PROXY, SLIPPING};
        let proxy = if raw.flags & PROXY != 0 {
            let q = mm(raw.point);
            let o = raw.origin.map(|b| Length::from_bits(b).to_num::<f64>());
            [q[0] + o[0], q[1] + o[1], q[2]]
        } else {
            probe
        };
        RoamRow {
            time,
            probe,
            force: raw.force.map(|b| mccs::Force::from_bits(b).to_num::<f64>()),
            proxy,
            contact: raw.flags & CONTACT != 0,
            slipping: raw.flags & SLIPPING != 0,
            window_shifts: raw.shifts,
            max_disp: norm(mm(raw.max_disp)),
        }
    }
}

/// The largest |displacement| from rest of the twin's nodes, mm.
fn max_disp_twin(twin: &Twin) -> f64 {
    (0..twin.x.len())
        .map(|i| norm(std::array::from_fn(|k| twin.x[i][k] - twin.mesh.rest[i][k])))
        .fold(0.0, f64::max)
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}
