//! A device on the host, tick by tick: the board's own link server, link state and
//! controller (the arm board's roaming contact, or the 1-DOF board's glued one) on a
//! probe the test moves, frames in and out as bytes. What the board does in each tick
//! and each poll of its main loop, in the tests' hands.

use haptic_f405::device::{linked, roaming, BoardRoaming, EDGES, NODES, SPACING_MM};
use haptic_f405::BOARD;
use mccs::{Force, ForceTable64, Length, Solver, Topology, Wide};
use mccs_firmware::link::{
    Guard, GuardTimes, LinkServer, LinkState, LinkedDevice, Live, Session, Work,
};
use mccs_firmware::{Contact, Controller, Glued, HapticDevice};
use mccs_link::{
    encode, parse, ContactKind, Core, Decoder, DeviceKind, TissueBegin, ToDevice, ToHost,
    MAX_FRAME, TISSUE_CHUNK,
};
use std::collections::VecDeque;

/// Path samples a replay buffers (the board's).
pub const P: usize = 128;

/// A probe the test places; the forces it was asked to render.
#[derive(Default)]
pub struct Probe {
    /// Where it is, device frame, mm.
    pub at: [f64; 3],
    /// What it rendered, device frame.
    pub rendered: Vec<[Force; 3]>,
    /// Its next read fails.
    pub fail: bool,
    /// Calls of its safe state.
    pub safe_states: u32,
}

impl HapticDevice for Probe {
    type Error = ();
    fn read_position(&mut self) -> Result<[Length; 3], ()> {
        if self.fail {
            return Err(());
        }
        Ok(self.at.map(Length::from_num))
    }
    fn write_force(&mut self, force: [Force; 3]) -> Result<(), ()> {
        self.rendered.push(force);
        Ok(())
    }
    fn safe_state(&mut self) -> Result<(), ()> {
        self.safe_states += 1;
        Ok(())
    }
}

/// The device on the host.
pub struct Rig<C: Contact<NODES, EDGES, 64, Wide>> {
    pub state: &'static LinkState<NODES, 64, Wide>,
    pub server: LinkServer<'static, NODES, EDGES, 64, Wide, P>,
    pub ctl: Controller<LinkedDevice<Probe>, NODES, EDGES, 64, Wide, C>,
    rx: VecDeque<u8>,
    decoder: Decoder,
    /// Everything the device sent, in order.
    pub out: Vec<ToHost>,
}

/// The live device: the board's, roaming or glued.
pub fn live(contact: ContactKind) -> Live {
    Live {
        device: if contact == ContactKind::Roaming {
            DeviceKind::Arm
        } else {
            DeviceKind::OneDof
        },
        simulated: true,
        core: Core::M4f,
        contact,
        grid: BOARD.grid,
        spacing: SPACING_MM,
        tissue: if contact == ContactKind::Roaming {
            BOARD.tissue_nodes.map(|n| n as u8)
        } else {
            [BOARD.grid as u8; 2]
        },
        config: BOARD.solver(),
        workspace: BOARD.workspace_q24(),
        pose_speed_mm_s: BOARD.pose_speed_mm_s,
        pose_turn_deg_s: BOARD.pose_turn_deg_s,
        baud: BOARD.baud,
        budget: BOARD.budget(),
        narrow: false,
    }
}

fn parts(
    table: ForceTable64,
    clock: u32,
) -> (
    &'static LinkState<NODES, 64, Wide>,
    &'static mut Work<NODES, EDGES, 64, Wide, P>,
    Solver<NODES, EDGES, 64, Wide>,
) {
    let state = Box::leak(Box::new(LinkState::with_clock(
        Guard::new(GuardTimes::at_rate(BOARD.tick_hz, BOARD.ramp_ms)),
        clock,
    )));
    let work = Box::leak(Box::default());
    let topo = Topology::standard_patch(BOARD.grid, SPACING_MM).unwrap();
    let solver = Solver::new(topo, table, &BOARD.solver()).unwrap();
    (state, work, solver)
}

impl Rig<BoardRoaming> {
    /// The arm board's device (roaming with friction) with `table` live, the probe
    /// 5 mm above the tissue.
    pub fn roaming(table: ForceTable64) -> Self {
        Self::roaming_from(table, 0)
    }

    /// [`Rig::roaming`], the link's clock starting at `clock`.
    pub fn roaming_from(table: ForceTable64, clock: u32) -> Self {
        let (state, work, mut solver) = parts(table, clock);
        let contact = roaming(&BOARD, &mut solver).unwrap();
        let mut ctl = Controller::with_contact(
            solver,
            contact,
            linked(
                &BOARD,
                Probe {
                    at: [0.0, 0.0, 5.0],
                    ..Probe::default()
                },
            ),
            u32::MAX,
        );
        ctl.set_overrun_limit(BOARD.max_overruns_in_row);
        let friction = mccs::Friction::new(BOARD.mu_s, BOARD.mu_k).ok();
        let session = Session::new(live(ContactKind::Roaming), table, friction);
        Self::of(state, work, session, ctl)
    }
}

impl Rig<Glued> {
    /// The 1-DOF board's device (glued) with `table` live, the probe 5 mm above.
    pub fn glued(table: ForceTable64) -> Self {
        Self::glued_from(table, 0)
    }

    /// [`Rig::glued`], the link's clock starting at `clock`.
    pub fn glued_from(table: ForceTable64, clock: u32) -> Self {
        let (state, work, solver) = parts(table, clock);
        let mut ctl = Controller::new(
            solver,
            linked(
                &BOARD,
                Probe {
                    at: [0.0, 0.0, 5.0],
                    ..Probe::default()
                },
            ),
            u32::MAX,
        );
        ctl.set_overrun_limit(BOARD.max_overruns_in_row);
        let session = Session::new(live(ContactKind::Glued), table, None);
        Self::of(state, work, session, ctl)
    }
}

impl<C: Contact<NODES, EDGES, 64, Wide>> Rig<C> {
    fn of(
        state: &'static LinkState<NODES, 64, Wide>,
        work: &'static mut Work<NODES, EDGES, 64, Wide, P>,
        session: Session<64>,
        ctl: Controller<LinkedDevice<Probe>, NODES, EDGES, 64, Wide, C>,
    ) -> Self {
        Self {
            state,
            server: LinkServer::new(state, work, session, BOARD.check_steps_per_poll),
            ctl,
            rx: VecDeque::new(),
            decoder: Decoder::new(),
            out: Vec::new(),
        }
    }

    /// A frame from the host, queued.
    pub fn send(&mut self, m: &ToDevice) {
        let mut buf = [0u8; MAX_FRAME];
        self.rx.extend(encode(m, &mut buf).unwrap());
    }

    /// Raw bytes from the host, queued.
    pub fn send_raw(&mut self, bytes: &[u8]) {
        self.rx.extend(bytes);
    }

    /// Bytes queued, not yet read by the device.
    pub fn queued(&self) -> usize {
        self.rx.len()
    }

    /// One poll of the main loop; whether it had more to do.
    pub fn poll(&mut self) -> bool {
        let rx = &mut self.rx;
        let mut sent: Vec<u8> = Vec::new();
        let busy = self.server.poll(&mut || rx.pop_front(), 0, &mut |f| {
            sent.extend_from_slice(f);
            true
        });
        for b in sent {
            if let Some(frame) = self.decoder.push(b) {
                self.out.push(parse::<ToHost>(frame.unwrap()).unwrap());
            }
        }
        busy
    }

    /// One tick (its overrun, or not, the caller's to note).
    pub fn tick(&mut self) {
        self.state.run_tick(&mut self.ctl);
    }

    /// A tick on time, then a poll.
    pub fn step(&mut self) {
        self.tick();
        self.ctl.note_on_time();
        self.poll();
    }

    /// The probe, to move it.
    pub fn probe(&mut self) -> &mut Probe {
        self.ctl.device_mut().inner_mut()
    }

    /// Sends `m`, steps until an answer `want` takes (or a `Nak`) arrives, within
    /// `ticks`; returns it and drops what came before it.
    pub fn ask(&mut self, m: &ToDevice, ticks: u32, want: impl Fn(&ToHost) -> bool) -> ToHost {
        self.send(m);
        self.wait(ticks, want)
    }

    /// Steps until an answer `want` takes (or a `Nak`) arrives, within `ticks`.
    pub fn wait(&mut self, ticks: u32, want: impl Fn(&ToHost) -> bool) -> ToHost {
        for _ in 0..ticks {
            self.step();
            if let Some(i) = self
                .out
                .iter()
                .position(|m| want(m) || matches!(m, ToHost::Nak(_)))
            {
                let m = self.out[i];
                self.out.drain(..=i);
                return m;
            }
        }
        panic!("no answer in {ticks} ticks; sent {:?}", self.out);
    }
}

/// A replay of `samples` on the standard 5-node patch at 1 kHz with the solver's
/// defaults, its first sample at `start` (`x, y`, mm), glued or `roaming`.
pub fn replay_spec(
    samples: u32,
    start: [f64; 3],
    roaming: Option<mccs_link::RoamSpec>,
) -> mccs_link::ReplaySpec {
    let c = mccs::SolverConfig::default();
    mccs_link::ReplaySpec {
        grid: 5,
        spacing_mm: 2.5,
        tick_hz: 1000.0,
        node_mass_kg: c.node_mass,
        spring_damping: c.spring_damping,
        coupling_stiffness: c.coupling.stiffness,
        coupling_damping: c.coupling.damping,
        max_force: c.coupling.max_force,
        symplectic: false,
        narrow: false,
        samples,
        start: [start[0], start[1]],
        roaming,
    }
}

/// Sends `t` to the rig as a host does, proposing `substeps` (0: none); the answer.
pub fn load<C: Contact<NODES, EDGES, 64, Wide>>(
    rig: &mut Rig<C>,
    t: &mccs_client::Tissue,
    substeps: u16,
    hash: u32,
) -> ToHost {
    rig.send(&ToDevice::TissueBegin(TissueBegin {
        segments: t.segments(),
        len: t.bytes().len() as u32,
        hash,
        friction: t.friction(),
        substeps,
    }));
    for (i, c) in t.bytes().chunks(TISSUE_CHUNK).enumerate() {
        rig.send(&ToDevice::TissueChunk {
            offset: (i * TISSUE_CHUNK) as u32,
            bytes: c,
        });
    }
    rig.send(&ToDevice::TissueCommit);
    rig.wait(20_000, |m| matches!(m, ToHost::Ack { .. }))
}
