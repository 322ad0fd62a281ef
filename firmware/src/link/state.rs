//! [`LinkState`]: what the tick and the main loop share for the link, and the tick's
//! side of it ([`LinkState::run_tick`]): the guard's gain and the host's pose to the
//! device, a checked tissue swapped in at the tick's start, the controller's tick, the
//! mesh when one is due, and a [`Snapshot`] of the tick for the main loop's telemetry and
//! status. The main loop changes what the tick will see only through these methods
//! (shared cells and mailboxes: the tick never waits on the main loop).

use super::guard::Guard;
use super::linked::LinkedDevice;
use super::mesh::{Mesh, MeshClock};
use crate::controller::{Contact, Controller, Fault};
use crate::device::HapticDevice;
use crate::{Mailbox, Shared};
use mccs::{Arith, Force, ParamSet};
use mccs_link::scale::GAIN_FULL;
use mccs_link::{FaultReason, Flags, Pose};

/// A checked tissue for the tick to swap in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Swap<const S: usize, A: Arith> {
    /// Its parameter set.
    pub set: ParamSet<S, A>,
    /// Its friction (`None`: the live one's).
    pub friction: Option<mccs::Friction>,
}

/// The tick as the main loop sees it: what the last tick did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Snapshot {
    /// The link's clock after the tick: ticks run, wrapping at 2³² (49.7 days at 1 kHz).
    pub ticks: u32,
    /// Overruns.
    pub overruns: u32,
    /// Why the device is in its safe state.
    pub fault: FaultReason,
    /// The probe, tissue frame, Q24 mm.
    pub probe: [i32; 3],
    /// The force rendered, device frame, gain applied, Q20 N.
    pub force: [i32; 3],
    /// The link's gain, Q15.
    pub gain: u16,
    /// The tick's flags (all but `CHECKING`, which the main loop knows).
    pub flags: Flags,
    /// The joints' duties, Q16.
    pub duties: [i32; 3],
    /// The proxy, tissue frame, Q24 mm.
    pub proxy: [i32; 3],
    /// The window's origin, tissue frame, Q24 mm.
    pub window: [i32; 2],
    /// Tissues swapped in so far.
    pub swaps: u32,
    /// Tissues the tick refused (prepared for another patch).
    pub rejected_swaps: u32,
    /// Substeps a tick of the live tissue.
    pub substeps: u16,
}

/// A controller fault as the link reports it.
pub fn fault_reason(f: Option<Fault>) -> FaultReason {
    match f {
        None => FaultReason::None,
        Some(Fault::Read) => FaultReason::Read,
        Some(Fault::Write) => FaultReason::Write,
        Some(Fault::Overruns) => FaultReason::Overruns,
        Some(Fault::Amplifier) => FaultReason::Amplifier,
    }
}

/// What the tick and the main loop share for the link. A `static` on the board.
pub struct LinkState<const N: usize, const S: usize, A: Arith> {
    guard: Shared<Guard>,
    pose: Shared<Option<Pose>>,
    swap: Mailbox<Swap<S, A>>,
    swap_ready: Shared<bool>,
    mesh_clock: MeshClock,
    mesh: Mailbox<Mesh<N>>,
    contact: Shared<bool>,
    /// Whether the device was homed at the last tick (a homing restarts the ramp).
    homed: Shared<bool>,
    snapshot: Shared<Snapshot>,
    /// The link's clock: the next tick's number, wrapping at 2³². The guard's, the
    /// frames' and the streams' time. Not the controller's count of ticks, which
    /// saturates: fed that, after 2³² − 1 ticks (49.7 days at 1 kHz, 5 at 10 kHz) every
    /// frame and every tick would have the same time, and an armed host's silence
    /// would never fade.
    clock: Shared<u32>,
}

impl<const N: usize, const S: usize, A: Arith> LinkState<N, S, A> {
    /// Standalone (the guard's gain ramps once the probe is out of contact), the tissue
    /// at the origin, nothing to swap; the clock at 0.
    pub const fn new(guard: Guard) -> Self {
        Self::with_clock(guard, 0)
    }

    /// As [`LinkState::new`], the clock starting at `start`: the tests', which run the
    /// clock across its wrap without 2³² ticks.
    pub const fn with_clock(guard: Guard, start: u32) -> Self {
        Self {
            guard: Shared::new(guard),
            pose: Shared::new(None),
            swap: Mailbox::new(),
            swap_ready: Shared::new(false),
            mesh_clock: MeshClock::new(),
            mesh: Mailbox::new(),
            contact: Shared::new(false),
            homed: Shared::new(false),
            clock: Shared::new(start),
            snapshot: Shared::new(Snapshot {
                ticks: start,
                overruns: 0,
                fault: FaultReason::None,
                probe: [0; 3],
                force: [0; 3],
                gain: 0,
                flags: Flags::NONE,
                duties: [0; 3],
                proxy: [0; 3],
                window: [0; 2],
                swaps: 0,
                rejected_swaps: 0,
                substeps: 0,
            }),
        }
    }

    /// A valid frame arrived (the guard's keepalive).
    pub fn frame(&self, now: u32) {
        self.guard.update(|g| g.frame(now));
    }

    /// `Arm`.
    pub fn arm(&self, now: u32) {
        self.guard.update(|g| g.arm(now));
    }

    /// `Disarm`.
    pub fn disarm(&self) {
        self.guard.update(|g| g.disarm());
    }

    /// Whether a host holds the device armed.
    pub fn armed(&self) -> bool {
        self.guard.get().armed()
    }

    /// The force drops to zero and ramps again once the probe is out of contact.
    pub fn restart_ramp(&self) {
        self.guard.update(|g| g.restart_ramp());
    }

    /// Where the tissue should lie (checked by the caller: inside the workspace, a unit
    /// quaternion).
    pub fn set_pose(&self, pose: Pose) {
        self.pose.set(Some(pose));
    }

    /// A checked tissue for the next tick.
    pub fn post_swap(&self, swap: Swap<S, A>) {
        let _ = self.swap.post(swap);
        self.swap_ready.set(true);
    }

    /// A mesh every `every` ticks (0: none).
    pub fn set_mesh_every(&self, every: u16) {
        self.mesh_clock.set(every);
    }

    /// The mesh the tick took, if one waits.
    pub fn take_mesh(&self) -> Option<Mesh<N>> {
        self.mesh.take()
    }

    /// The last tick.
    pub fn snapshot(&self) -> Snapshot {
        self.snapshot.get()
    }

    /// One tick of `ctl` with the link: the guard's gain and the pose to the device, a
    /// checked tissue swapped in if one waits, the controller's tick, the mesh if one is
    /// due, the snapshot. Returns the force the device rendered (device frame, gain
    /// applied).
    pub fn run_tick<D: HapticDevice, const E: usize, C: Contact<N, E, S, A>>(
        &self,
        ctl: &mut Controller<LinkedDevice<D>, N, E, S, A, C>,
    ) -> [Force; 3] {
        let now = self.clock.get();
        let gain = self.guard.update(|g| g.gain(now, self.contact.get()));
        let d = ctl.device_mut();
        d.set_gain(gain);
        if let Some(p) = self.pose.update(|p| p.take()) {
            d.set_target(p.origin, p.rotation);
        }
        if self.swap_ready.get() {
            self.swap_ready.set(false);
            if let Some(s) = self.swap.take() {
                ctl.swap_tissue(s.set, s.friction);
            }
        }
        ctl.tick(None);
        let t = ctl.telemetry();
        let contact = ctl.contact_state();
        let rendered = ctl.device().rendered();
        let dev = ctl.device().status();
        // Homed this tick (the arm's position just became known): the force starts again
        // from zero, and ramps once the probe is out of contact.
        if dev.homed && !self.homed.get() {
            self.restart_ramp();
        }
        self.homed.set(dev.homed);
        let touching = match contact {
            Some(c) => c.touching,
            None => t.force != [Force::ZERO; 3],
        };
        self.contact.set(touching);
        let flags = Flags::NONE
            .with(Flags::CONTACT, touching)
            .with(Flags::SLIPPING, contact.is_some_and(|c| c.slipping))
            .with(Flags::ARMED, self.guard.get().armed())
            .with(Flags::FAULT, t.fault.is_some())
            .with(Flags::CLAMPED, t.clamped)
            .with(Flags::HOMED, dev.homed)
            .with(Flags::AT_LIMIT, dev.at_limit)
            .with(Flags::THERMAL, dev.thermal)
            .with(Flags::GAIN_LIMITED, gain < GAIN_FULL);
        let window = contact.map_or([0; 2], |c| c.window);
        if self.mesh_clock.due() {
            let _ = self.mesh.post(Mesh::of(ctl.solver(), now, window));
        }
        let next = now.wrapping_add(1);
        self.clock.set(next);
        self.snapshot.set(Snapshot {
            ticks: next,
            overruns: t.overruns,
            fault: fault_reason(t.fault),
            probe: ctl.device().probe().map(|c| c.to_bits()),
            force: rendered.map(|c| c.to_bits()),
            gain,
            flags,
            duties: dev.duties,
            proxy: contact.map_or([0; 3], |c| c.proxy),
            window,
            swaps: t.swaps,
            rejected_swaps: t.rejected_swaps,
            substeps: ctl.solver().substeps().min(u16::MAX as u32) as u16,
        });
        rendered
    }
}
