//! The device's side of the link, in the main loop: each decoded message handled, its
//! answer written to the host, and what the tick must see returned as an [`Effect`] for
//! the firmware to apply (through its mailbox and shared state: the tick never waits on
//! the link).
//!
//! A tissue load is checked here before anything changes: the bytes' length and hash,
//! the knot count, the table's own `validate`, its recorded error within the product's
//! bound, the solver's parameter set for the live patch (its substeps). Only then is the
//! set handed to the tick ([`Effect::Swap`]); on any refusal a `Nak` says why and the
//! live tissue stays.

use super::replayer::Replayer;
use mccs::{Arith, ForceTable, ParamSet, RawTable, Solver, SolverConfig, TableBound, Topology};
use mccs_link::message::{
    HelloInfo, MeshPart, NakReason, StatusInfo, Telemetry, ToDevice, ToHost, MESH_PART,
};
use mccs_link::{table_bytes, Core, PROTOCOL, SCHEMA};

/// The live device, as the session describes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Live {
    /// The core.
    pub core: Core,
    /// The live patch's side, nodes.
    pub grid: usize,
    /// Its spacing, mm.
    pub spacing: f64,
    /// The live solver's configuration (a loaded tissue is prepared with it).
    pub config: SolverConfig,
}

/// The tick's state, as the main loop last read it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Now {
    /// Ticks run.
    pub ticks: u32,
    /// Overruns.
    pub overruns: u32,
    /// In the safe state after a fault.
    pub fault: bool,
    /// A host holds the device armed.
    pub armed: bool,
    /// The tissue's origin the host last set (Q24 mm).
    pub pose: [i32; 3],
}

/// What the firmware applies after a message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Effect<const S: usize, A: Arith> {
    /// Nothing.
    None,
    /// Swap this parameter set in at the next tick; `Ack` the tissue once it is in.
    Swap {
        /// The set, prepared for the live patch.
        set: ParamSet<S, A>,
        /// The tissue's hash.
        tissue: u32,
    },
    /// Arm the guard.
    Arm,
    /// Disarm it.
    Disarm,
    /// Move the tissue's origin here (Q24 mm).
    Pose([i32; 3]),
    /// Take a mesh every this many ticks (0: none; [`super::MeshClock::set`]).
    WatchMesh(u16),
}

/// A table arriving in pieces: its words as they are written.
struct Load<const S: usize> {
    header: [i32; table_bytes::HEADER_WORDS],
    segments: [[i32; 4]; S],
    len: u32,
    hash: u32,
    got: u32,
    running_hash: u32,
}

/// The device's session.
pub struct Session<const S: usize> {
    live: Live,
    table: ForceTable<S>,
    tissue: u32,
    load: Option<Load<S>>,
    bad_frames: u32,
    watch_every: u32,
    next_watch: u32,
    seq: u32,
    dropped: u32,
    mesh_every: u32,
    last_mesh: Option<u32>,
    mesh_seq: u32,
}

impl<const S: usize> Session<S> {
    /// The device `live` with its start-up tissue `table`.
    pub fn new(live: Live, table: ForceTable<S>) -> Self {
        Self {
            live,
            table,
            tissue: table_bytes::hash(&table),
            load: None,
            bad_frames: 0,
            watch_every: 0,
            next_watch: 0,
            seq: 0,
            dropped: 0,
            mesh_every: 0,
            last_mesh: None,
            mesh_seq: 0,
        }
    }

    /// The live tissue's table and hash.
    pub fn tissue(&self) -> (&ForceTable<S>, u32) {
        (&self.table, self.tissue)
    }

    /// Counts a frame the decoder dropped.
    pub fn bad_frame(&mut self) {
        self.bad_frames = self.bad_frames.saturating_add(1);
    }

    /// The counters.
    pub fn status(&self, now: Now, replaying: bool) -> StatusInfo {
        StatusInfo {
            ticks: now.ticks,
            overruns: now.overruns,
            bad_frames: self.bad_frames,
            dropped_telemetry: self.dropped,
            armed: now.armed,
            fault: now.fault,
            replaying,
            pose: now.pose,
        }
    }

    /// Handles one message; answers go to `out`.
    pub fn handle<const N: usize, const E: usize, A: Arith, const P: usize>(
        &mut self,
        msg: ToDevice<'_>,
        now: Now,
        replay: &mut Replayer<N, E, S, A, P>,
        out: &mut dyn FnMut(&ToHost),
    ) -> Effect<S, A> {
        match msg {
            ToDevice::Hello => {
                out(&ToHost::Hello(self.hello::<N, E, P>()));
                Effect::None
            }
            ToDevice::Status => {
                out(&ToHost::Status(self.status(now, replay.running())));
                Effect::None
            }
            ToDevice::Arm => {
                out(&ToHost::Status(
                    self.status(Now { armed: true, ..now }, replay.running()),
                ));
                Effect::Arm
            }
            ToDevice::Disarm => {
                out(&ToHost::Status(self.status(
                    Now {
                        armed: false,
                        ..now
                    },
                    replay.running(),
                )));
                Effect::Disarm
            }
            ToDevice::Pose { origin } => Effect::Pose(origin),
            ToDevice::Watch { every } => {
                self.watch_every = every as u32;
                self.next_watch = now.ticks;
                Effect::None
            }
            ToDevice::WatchMesh { every } => {
                // 60 meshes a second at most.
                let least = super::mesh::least_every(self.live.config.tick_hz as u32);
                let every = if every == 0 { 0 } else { every.max(least) };
                self.mesh_every = every as u32;
                self.last_mesh = None;
                Effect::WatchMesh(every)
            }
            ToDevice::TissueBegin {
                segments,
                len,
                hash,
            } => {
                let refuse = if replay.running() {
                    Some(NakReason::Busy)
                } else if segments as usize != S {
                    Some(NakReason::Segments)
                } else if len as usize != table_bytes::len(S) {
                    Some(NakReason::Length)
                } else {
                    None
                };
                match refuse {
                    Some(r) => {
                        self.load = None;
                        out(&ToHost::Nak(r));
                    }
                    None => {
                        self.load = Some(Load {
                            header: [0; table_bytes::HEADER_WORDS],
                            segments: [[0; 4]; S],
                            len,
                            hash,
                            got: 0,
                            running_hash: 0x811C_9DC5,
                        })
                    }
                }
                Effect::None
            }
            ToDevice::TissueChunk { offset, bytes } => {
                let ok = match self.load.as_mut() {
                    Some(l)
                        if offset == l.got && l.got as usize + bytes.len() <= l.len as usize =>
                    {
                        for &b in bytes {
                            l.put(b);
                        }
                        true
                    }
                    _ => false,
                };
                if !ok {
                    self.load = None;
                    out(&ToHost::Nak(NakReason::Order));
                }
                Effect::None
            }
            ToDevice::TissueCommit => match self.commit::<N, E, A>() {
                Ok((set, tissue)) => Effect::Swap { set, tissue },
                Err(r) => {
                    out(&ToHost::Nak(r));
                    Effect::None
                }
            },
            ToDevice::ReplayBegin(spec) => {
                if replay.running() {
                    replay.abort();
                }
                match replay.begin(&spec, self.table) {
                    Ok(until) => out(&ToHost::ReplayCredit { until }),
                    Err(r) => out(&ToHost::Nak(r)),
                }
                Effect::None
            }
            ToDevice::ReplayPath { first, points } => {
                if let Err(r) = replay.path(first, points) {
                    out(&ToHost::Nak(r));
                }
                Effect::None
            }
        }
    }

    /// The tissue swapped in: the live one from now.
    pub fn swapped(&mut self, table: ForceTable<S>, tissue: u32, out: &mut dyn FnMut(&ToHost)) {
        self.table = table;
        self.tissue = tissue;
        out(&ToHost::Ack { tissue });
    }

    /// The load checked whole: the parameter set for the live patch, or why not.
    fn commit<const N: usize, const E: usize, A: Arith>(
        &mut self,
    ) -> Result<(ParamSet<S, A>, u32), NakReason> {
        let l = self.load.take().ok_or(NakReason::Order)?;
        if l.got != l.len {
            return Err(NakReason::Length);
        }
        if l.running_hash != l.hash {
            return Err(NakReason::Hash);
        }
        let table = ForceTable::from_raw(l.raw());
        table.validate().map_err(|_| NakReason::Table)?;
        match table.max_error() {
            Some(e) if e.within(&TableBound::PRODUCT) => {}
            _ => return Err(NakReason::Bound),
        }
        let topo = Topology::<N, E>::standard_patch(self.live.grid, self.live.spacing)
            .map_err(|_| NakReason::Solver)?;
        let set = Solver::<N, E, S, A>::prepare_for(&topo, table, &self.live.config)
            .map_err(|_| NakReason::Solver)?;
        Ok((set, l.hash))
    }

    fn hello<const N: usize, const E: usize, const P: usize>(&self) -> HelloInfo {
        HelloInfo {
            protocol: PROTOCOL,
            schema: SCHEMA,
            core: self.live.core,
            tick_hz: self.live.config.tick_hz as u32,
            grid: self.live.grid as u8,
            max_grid: super::replayer::max_grid::<N, E>() as u8,
            tissue_w: self.live.grid as u8,
            tissue_h: self.live.grid as u8,
            knots: S as u16 + 1,
            tissue: self.tissue,
            path_capacity: P as u32,
        }
    }

    /// Live telemetry at tick `tick` (the probe and force as the tick left them), if one
    /// is due: every `Watch` period, numbered; a due one the main loop missed, and one
    /// `send` could not take (it returns false), is counted as dropped.
    pub fn telemetry(
        &mut self,
        tick: u32,
        probe: [i32; 3],
        force: [i32; 3],
        gain: u16,
        flags: u8,
        send: &mut dyn FnMut(&ToHost) -> bool,
    ) {
        let every = self.watch_every;
        if every == 0 || tick < self.next_watch {
            return;
        }
        // The due slots since the last: all but this one were missed.
        let missed = (tick - self.next_watch) / every;
        self.dropped = self.dropped.saturating_add(missed);
        self.seq = self.seq.wrapping_add(missed);
        self.next_watch = self.next_watch.saturating_add((missed + 1) * every);
        let msg = ToHost::Telemetry(Telemetry {
            seq: self.seq,
            tick,
            probe,
            force,
            gain,
            flags,
            dropped: self.dropped,
        });
        self.seq = self.seq.wrapping_add(1);
        if !send(&msg) {
            self.dropped = self.dropped.saturating_add(1);
        }
    }
}

impl<const S: usize> Session<S> {
    /// Sends a mesh the tick took, in parts of [`MESH_PART`] nodes (`send` returns false
    /// when it could not take one: the mesh is counted as dropped). Meshes the tick took
    /// but the main loop never sent (the gap in their ticks) are counted as dropped and
    /// their numbers skipped.
    pub fn mesh<const N: usize>(
        &mut self,
        m: &super::Mesh<N>,
        send: &mut dyn FnMut(&ToHost) -> bool,
    ) {
        let every = self.mesh_every;
        if every == 0 {
            return;
        }
        if let Some(last) = self.last_mesh {
            let missed = (m.tick.saturating_sub(last) / every).saturating_sub(1);
            self.mesh_seq = self.mesh_seq.wrapping_add(missed);
            self.dropped = self.dropped.saturating_add(missed);
        }
        self.last_mesh = Some(m.tick);
        let nodes = (m.nodes as usize).min(N);
        let mut sent = true;
        for first in (0..nodes).step_by(MESH_PART) {
            let mut positions = [[0i32; 3]; MESH_PART];
            let part = m.positions.get(first..nodes).unwrap_or(&[]);
            for (p, q) in positions.iter_mut().zip(part) {
                *p = *q;
            }
            sent &= send(&ToHost::Mesh(MeshPart {
                seq: self.mesh_seq,
                tick: m.tick,
                first: first as u16,
                nodes: nodes as u16,
                positions,
            }));
        }
        if !sent {
            self.dropped = self.dropped.saturating_add(1);
        }
        self.mesh_seq = self.mesh_seq.wrapping_add(1);
    }
}

impl<const S: usize> Load<S> {
    /// The next byte.
    fn put(&mut self, b: u8) {
        let i = self.got as usize;
        let (word, shift) = (i / 4, 8 * (i % 4));
        let slot = if word < table_bytes::HEADER_WORDS {
            &mut self.header[word]
        } else {
            let k = word - table_bytes::HEADER_WORDS;
            &mut self.segments[k / 4][k % 4]
        };
        *slot |= (b as i32) << shift;
        self.running_hash = (self.running_hash ^ b as u32).wrapping_mul(0x0100_0193);
        self.got += 1;
    }

    /// The table the words hold.
    fn raw(&self) -> RawTable<S> {
        table_bytes::from_words(&self.header, self.segments)
    }
}
