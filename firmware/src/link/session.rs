//! The device's side of the link's messages ([`Session`]): each decoded message handled
//! in the main loop, its answer written to the host, and what the tick must see returned
//! as an [`Effect`] for the server to apply ([`super::LinkServer`]).
//!
//! A tissue load is checked before anything changes: the bytes' length and hash, the
//! knot count, the friction, the table's own `validate`, its recorded error within the
//! product's bound; then its stability on the live patch and its tick against the
//! budget run in pieces ([`super::check::TissueCheck`], in the server's [`Work`]). Only
//! then is it handed to the tick; on any refusal a `Nak` says why and the live tissue
//! stays.

use super::check::{TickBudget, TissueCheck};
use super::mesh::{grid_place, Mesh};
use super::replayer::max_grid;
use super::state::Snapshot;
use super::work::Work;
use crate::black_box::{BlackBox, BLACK_BOX_TICKS};
use mccs::{Arith, ForceTable, SolverConfig, TableBound};
use mccs_link::table_bytes::{self, Assembler};
use mccs_link::{
    rates, ContactKind, Core, DeviceKind, Flags, Friction, HelloInfo, MeshPart, NakReason, Pose,
    StatusInfo, Telemetry, TissueBegin, ToDevice, ToHost, MESH_PART, PROTOCOL, SCHEMA,
};

/// The live device, as the session describes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Live {
    /// What it is.
    pub device: DeviceKind,
    /// Its plant is simulated.
    pub simulated: bool,
    /// The core.
    pub core: Core,
    /// How the probe touches the tissue.
    pub contact: ContactKind,
    /// The live patch's side, nodes.
    pub grid: usize,
    /// Its spacing, mm.
    pub spacing: f64,
    /// The tissue's size, nodes (glued: the patch's).
    pub tissue: [u8; 2],
    /// The live solver's configuration (a loaded tissue is checked with it).
    pub config: SolverConfig,
    /// Where a pose's origin may be, Q24 mm (low corner, high corner).
    pub workspace: [[i32; 3]; 2],
    /// The pose's slew limits.
    pub pose_speed_mm_s: u16,
    /// See `pose_speed_mm_s`.
    pub pose_turn_deg_s: u16,
    /// The link's baud rate.
    pub baud: u32,
    /// The tick's budget and costs.
    pub budget: TickBudget,
    /// Whether the device computes in the narrow arithmetic.
    pub narrow: bool,
}

/// What the server applies after a message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Effect {
    /// Nothing.
    None,
    /// Arm the guard.
    Arm,
    /// Disarm it.
    Disarm,
    /// Move the tissue here.
    Pose(Pose),
    /// Take a mesh every this many ticks (0: none).
    WatchMesh(u16),
}

/// A table arriving in pieces.
struct Load<const S: usize> {
    begin: TissueBegin,
    bytes: Assembler<S>,
}

/// The device's session.
pub struct Session<const S: usize> {
    live: Live,
    table: ForceTable<S>,
    tissue: u32,
    friction: Friction,
    pose: Pose,
    load: Option<Load<S>>,
    bad_frames: u32,
    watch_every: u32,
    next_watch: u32,
    seq: u32,
    dropped: u32,
    mesh_every: u32,
    last_mesh: Option<u32>,
    mesh_seq: u32,
    dropped_mesh: u32,
    /// The record kept from the device's last run, if it keeps one.
    black_box: Option<&'static LastRun>,
    /// The ticks a replay waits for its path's next sample
    /// ([`mccs_link::rates::REPLAY_STARVED_MS`] at the device's rate).
    replay_patience: u32,
}

/// The black box a session answers `BlackBox` from: the last run's, which only a boot
/// writes (before the session exists).
pub type LastRun = BlackBox<BLACK_BOX_TICKS>;

impl<const S: usize> Session<S> {
    /// The device `live` with its start-up tissue `table` and friction (`None`: a contact
    /// without friction).
    pub fn new(live: Live, table: ForceTable<S>, friction: Option<mccs::Friction>) -> Self {
        let friction = friction.map_or(Friction { mu_s: 0, mu_k: 0 }, |f| {
            let (s, k) = f.values();
            Friction::new(s, k)
        });
        Self {
            live,
            table,
            tissue: table_bytes::hash(&table),
            friction,
            pose: Pose::IDENTITY,
            load: None,
            bad_frames: 0,
            watch_every: 0,
            next_watch: 0,
            seq: 0,
            dropped: 0,
            mesh_every: 0,
            last_mesh: None,
            mesh_seq: 0,
            dropped_mesh: 0,
            black_box: None,
            replay_patience: super::guard::ticks(
                live.config.tick_hz as u32,
                rates::REPLAY_STARVED_MS,
            ),
        }
    }

    /// The session answering `BlackBox` from `last`, the record of the device's last run
    /// (without one, the answer says none is kept).
    pub fn with_black_box(mut self, last: &'static LastRun) -> Self {
        self.black_box = Some(last);
        self
    }

    /// The live tissue's table and hash.
    pub fn tissue(&self) -> (&ForceTable<S>, u32) {
        (&self.table, self.tissue)
    }

    /// The device as described.
    pub fn live(&self) -> &Live {
        &self.live
    }

    /// Counts a frame the decoder dropped.
    pub fn bad_frame(&mut self) {
        self.bad_frames = self.bad_frames.saturating_add(1);
    }

    /// The counters and state: the tick's `snap`, whether a host holds the device armed,
    /// what the main loop works on, and the receive queue's drops.
    pub fn status(
        &self,
        snap: &Snapshot,
        armed: bool,
        replaying: bool,
        checking: bool,
        rx_dropped: u32,
    ) -> StatusInfo {
        StatusInfo {
            ticks: snap.ticks,
            overruns: snap.overruns,
            bad_frames: self.bad_frames,
            dropped_telemetry: self.dropped,
            dropped_mesh: self.dropped_mesh,
            rx_dropped,
            armed,
            fault: snap.fault,
            replaying,
            checking,
            pose: self.pose,
            gain: snap.gain,
        }
    }

    /// Handles one message; answers go to `out`. `armed`: the guard's state before it.
    // Whole on purpose (over 80 lines): one arm per message of docs/protocol.md, in its
    // order, so the page and the device's one handler read side by side; each arm's work
    // is a call of its own.
    #[allow(clippy::too_many_arguments)]
    pub fn handle<const N: usize, const E: usize, A: Arith, const P: usize>(
        &mut self,
        msg: ToDevice<'_>,
        snap: &Snapshot,
        armed: bool,
        rx_dropped: u32,
        work: &mut Work<N, E, S, A, P>,
        out: &mut dyn FnMut(&ToHost),
    ) -> Effect {
        let status = |s: &Self, armed: bool, work: &Work<N, E, S, A, P>| {
            ToHost::Status(s.status(snap, armed, work.replaying(), work.checking(), rx_dropped))
        };
        match msg {
            ToDevice::Hello => out(&ToHost::Hello(self.hello::<N, E, P>(snap))),
            ToDevice::Status => out(&status(self, armed, work)),
            ToDevice::Arm => {
                out(&status(self, true, work));
                return Effect::Arm;
            }
            ToDevice::Disarm => {
                out(&status(self, false, work));
                return Effect::Disarm;
            }
            ToDevice::Keepalive => {}
            ToDevice::BlackBox { first } => {
                let part = self.black_box.map(|b| b.part(first)).unwrap_or_default();
                out(&ToHost::BlackBox(part));
            }
            ToDevice::Pose(p) => match self.check_pose(&p) {
                Ok(()) => {
                    self.pose = p;
                    return Effect::Pose(p);
                }
                Err(r) => out(&ToHost::Nak(r)),
            },
            ToDevice::Watch { every } => {
                let least =
                    rates::telemetry_least_every(self.live.config.tick_hz as u32, self.live.baud);
                self.watch_every = if every == 0 {
                    0
                } else {
                    every.max(least) as u32
                };
                self.next_watch = snap.ticks;
            }
            ToDevice::WatchMesh { every } => {
                let least = self.mesh_least_every::<N>();
                let every = if every == 0 { 0 } else { every.max(least) };
                self.mesh_every = every as u32;
                self.last_mesh = None;
                return Effect::WatchMesh(every);
            }
            ToDevice::TissueBegin(b) => {
                let refuse = if !matches!(work, Work::Idle) {
                    Some(NakReason::Busy)
                } else if b.segments as usize != S {
                    Some(NakReason::Segments)
                } else if b.len as usize != table_bytes::len(S) {
                    Some(NakReason::Length)
                } else if b.friction.is_some_and(|f| !f.valid())
                    || (b.friction.is_some() && self.live.contact != ContactKind::Roaming)
                {
                    Some(NakReason::Friction)
                } else {
                    None
                };
                self.load = None;
                match refuse {
                    Some(r) => out(&ToHost::Nak(r)),
                    None => {
                        self.load = Some(Load {
                            begin: b,
                            bytes: Assembler::new(),
                        })
                    }
                }
            }
            ToDevice::TissueChunk { offset, bytes } => {
                let ok = match self.load.as_mut() {
                    Some(l)
                        if offset as usize == l.bytes.received()
                            && l.bytes.received() + bytes.len() <= l.begin.len as usize =>
                    {
                        bytes.iter().all(|&b| l.bytes.push(b))
                    }
                    _ => false,
                };
                if !ok {
                    self.load = None;
                    out(&ToHost::Nak(NakReason::Order));
                }
            }
            ToDevice::TissueCommit => {
                if let Err(r) = self.commit(work) {
                    out(&ToHost::Nak(r));
                }
            }
            ToDevice::ReplayBegin(spec) => {
                let (narrow, patience) = (self.live.narrow, self.replay_patience);
                match work.begin_replay(&spec, self.table, narrow, snap.ticks, patience) {
                    Ok(until) => out(&ToHost::ReplayCredit { until }),
                    Err(r) => out(&ToHost::Nak(r)),
                }
            }
            ToDevice::ReplayPath { first, points } => {
                if let Err(r) = work.replay_path(first, points, snap.ticks) {
                    out(&ToHost::Nak(r));
                }
            }
        }
        Effect::None
    }

    /// A pose the device takes: its origin inside the workspace, a unit quaternion.
    fn check_pose(&self, p: &Pose) -> Result<(), NakReason> {
        let [lo, hi] = self.live.workspace;
        for axis in 0..3 {
            let o = p.origin[axis];
            if o < lo[axis] {
                return Err(NakReason::Pose {
                    axis: axis as u8,
                    limit: lo[axis],
                });
            }
            if o > hi[axis] {
                return Err(NakReason::Pose {
                    axis: axis as u8,
                    limit: hi[axis],
                });
            }
        }
        if !mccs::tissue_pose::is_unit(p.rotation) {
            return Err(NakReason::Rotation);
        }
        Ok(())
    }

    /// The load checked whole, and its stability check started in `work`; or why not.
    /// Out of line: the check's 8 KB is built on this frame, not the link's poll.
    #[inline(never)]
    fn commit<const N: usize, const E: usize, A: Arith, const P: usize>(
        &mut self,
        work: &mut Work<N, E, S, A, P>,
    ) -> Result<(), NakReason> {
        let l = self.load.take().ok_or(NakReason::Order)?;
        if l.bytes.received() != l.begin.len as usize {
            return Err(NakReason::Length);
        }
        if l.bytes.hash() != l.begin.hash {
            return Err(NakReason::Hash);
        }
        let raw = l.bytes.finish().ok_or(NakReason::Length)?;
        let table = ForceTable::from_raw(raw);
        table.validate().map_err(|_| NakReason::Table)?;
        match table.max_error() {
            Some(e) if e.within(&TableBound::PRODUCT) => {}
            _ => return Err(NakReason::Bound),
        }
        let friction = match l.begin.friction {
            Some(f) => {
                let (s, k) = f.values();
                Some(mccs::Friction::new(s, k).map_err(|_| NakReason::Friction)?)
            }
            None => None,
        };
        let check = TissueCheck::new(
            self.live.grid,
            self.live.spacing,
            table,
            &self.live.config,
            friction,
            l.begin.hash,
            self.live.budget,
            l.begin.substeps,
        )?;
        work.begin_check(check)
    }

    /// The tissue `table` (hash `tissue`, friction `friction` or the live one's) is the
    /// live one from now: `Ack`.
    pub fn swapped(
        &mut self,
        table: ForceTable<S>,
        tissue: u32,
        friction: Option<mccs::Friction>,
        out: &mut dyn FnMut(&ToHost),
    ) {
        self.table = table;
        self.tissue = tissue;
        if let Some(f) = friction {
            let (s, k) = f.values();
            self.friction = Friction::new(s, k);
        }
        out(&ToHost::Ack { tissue });
    }

    fn mesh_least_every<const N: usize>(&self) -> u16 {
        let nodes = self.live.grid.saturating_sub(2).pow(2).min(N);
        rates::mesh_least_every(self.live.config.tick_hz as u32, self.live.baud, nodes)
    }

    fn hello<const N: usize, const E: usize, const P: usize>(&self, snap: &Snapshot) -> HelloInfo {
        let l = &self.live;
        let tick_hz = l.config.tick_hz as u32;
        HelloInfo {
            protocol: PROTOCOL,
            schema: SCHEMA,
            device: l.device,
            simulated: l.simulated,
            core: l.core,
            tick_hz,
            contact: l.contact,
            grid: l.grid as u8,
            max_grid: max_grid::<N, E>() as u8,
            spacing: mccs_link::scale::mm_bits(l.spacing),
            tissue_w: l.tissue[0],
            tissue_h: l.tissue[1],
            knots: S as u16 + 1,
            tissue: self.tissue,
            friction: self.friction,
            substeps: snap.substeps,
            solver: mccs_link::SolverInfo {
                node_mass_kg: l.config.node_mass,
                spring_damping: l.config.spring_damping,
                node_damping: l.config.node_damping,
                coupling_stiffness: l.config.coupling.stiffness,
                coupling_damping: l.config.coupling.damping,
                symplectic: l.config.integrator == mccs::Integrator::SymplecticDamped,
                max_substeps: l.config.max_substeps.min(u16::MAX as u32) as u16,
            },
            path_capacity: P as u32,
            force_clamp: mccs_link::scale::newton_bits(l.config.coupling.max_force),
            workspace: l.workspace,
            pose_speed_mm_s: l.pose_speed_mm_s,
            pose_turn_deg_s: l.pose_turn_deg_s,
            baud: l.baud,
            telemetry_least_every: rates::telemetry_least_every(tick_hz, l.baud),
            mesh_least_every: self.mesh_least_every::<N>(),
            tick_budget: l.budget.tick,
            substep_cost: l.budget.per_substep,
            tick_base_cost: l.budget.base,
        }
    }

    /// Live telemetry of the tick `snap`, if one is due: every `Watch` period, numbered;
    /// a due one the main loop missed, and one `send` could not take (it returns false),
    /// is counted as dropped. `checking`: a tissue check runs.
    pub fn telemetry(
        &mut self,
        snap: &Snapshot,
        checking: bool,
        send: &mut dyn FnMut(&ToHost) -> bool,
    ) {
        let (every, tick) = (self.watch_every, snap.ticks);
        // On the link's clock, which wraps: due once `tick` has reached `next_watch`
        // (within half the clock's range; the main loop polls far more often).
        let since = tick.wrapping_sub(self.next_watch);
        if every == 0 || since > i32::MAX as u32 {
            return;
        }
        // The due slots since the last: all but this one were missed. (`since + every`
        // is below 2³¹ + 2¹⁶: no overflow.)
        let missed = since / every;
        self.dropped = self.dropped.saturating_add(missed);
        self.seq = self.seq.wrapping_add(missed);
        self.next_watch = self.next_watch.wrapping_add((missed + 1) * every);
        let msg = ToHost::Telemetry(Telemetry {
            seq: self.seq,
            tick,
            probe: snap.probe,
            force: snap.force,
            gain: snap.gain,
            flags: snap.flags.with(Flags::CHECKING, checking),
            fault: snap.fault,
            duties: snap.duties,
            proxy: snap.proxy,
            window: snap.window,
            dropped: self.dropped,
        });
        self.seq = self.seq.wrapping_add(1);
        if !send(&msg) {
            self.dropped = self.dropped.saturating_add(1);
        }
    }

    /// Sends a mesh the tick took, in parts of [`MESH_PART`] nodes with their places in
    /// the surface grid (`send` returns false when it could not take one: the mesh is
    /// counted as dropped). Meshes the tick took but the main loop never sent (the gap
    /// in their ticks) are counted as dropped and their numbers skipped.
    pub fn mesh<const N: usize>(&mut self, m: &Mesh<N>, send: &mut dyn FnMut(&ToHost) -> bool) {
        let every = self.mesh_every;
        if every == 0 {
            return;
        }
        if let Some(last) = self.last_mesh {
            let missed = (m.tick.wrapping_sub(last) / every).saturating_sub(1);
            self.mesh_seq = self.mesh_seq.wrapping_add(missed);
            self.dropped_mesh = self.dropped_mesh.saturating_add(missed);
        }
        self.last_mesh = Some(m.tick);
        let nodes = (m.nodes as usize).min(N);
        let mut sent = true;
        for first in (0..nodes).step_by(MESH_PART) {
            let mut part = MeshPart {
                seq: self.mesh_seq,
                tick: m.tick,
                first: first as u16,
                nodes: nodes as u16,
                origin: m.origin,
                ..MeshPart::default()
            };
            let src = m.positions.get(first..nodes).unwrap_or(&[]);
            for (k, (p, q)) in part.positions.iter_mut().zip(src).enumerate() {
                *p = *q;
                if let Some(g) = part.grid.get_mut(k) {
                    *g = grid_place(self.live.grid, first + k);
                }
            }
            sent &= send(&ToHost::Mesh(part));
        }
        if !sent {
            self.dropped_mesh = self.dropped_mesh.saturating_add(1);
        }
        self.mesh_seq = self.mesh_seq.wrapping_add(1);
    }
}
