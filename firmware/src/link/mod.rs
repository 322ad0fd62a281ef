//! The device's side of the host link (docs/link.md; the protocol is `mccs-link`):
//!
//! - [`guard`]: the safety rule — an armed host's silence fades the force to zero;
//! - [`linked`]: the device as the link sees it, with the host's pose and the guard's
//!   gain;
//! - [`session`]: each message handled in the main loop, a tissue load checked whole
//!   before the tick sees it;
//! - [`replayer`]: a host's replay run on the device's own solver;
//! - [`mesh`]: the live patch's node positions for the host's visuals.

pub mod guard;
pub mod linked;
pub mod mesh;
pub mod replayer;
pub mod session;

pub use guard::Guard;
pub use linked::LinkedDevice;
pub use mesh::{Mesh, MeshClock};
pub use replayer::Replayer;
pub use session::{Effect, Live, Now, Session};

use crate::{Controller, Mailbox, Shared};
use mccs::{Arith, Force, ParamSet};

/// What the tick shares with the main loop for the link: the guard (the tick steps its
/// gain, the main loop arms and disarms it), the pose the host asked for, whether a
/// checked tissue waits in the swap mailbox (a flag, so that the tick copies a parameter
/// set only when there is one), and when a mesh is due for the visuals. The board's
/// statics; the bench measures the same.
pub struct TickLink {
    /// The guard.
    pub guard: Shared<Guard>,
    /// The tissue's origin the host asked for, Q24 mm.
    pub pose: Shared<[i32; 3]>,
    /// A parameter set waits in the swap mailbox.
    pub swap_ready: Shared<bool>,
    /// When the tick takes a mesh.
    pub mesh: MeshClock,
}

impl TickLink {
    /// Standalone, at the origin, nothing to swap; the guard's times at `tick_hz`.
    pub const fn new(tick_hz: u32) -> Self {
        Self {
            guard: Shared::new(Guard::at_rate(tick_hz)),
            pose: Shared::new([0; 3]),
            swap_ready: Shared::new(false),
            mesh: MeshClock::new(),
        }
    }

    /// One tick of `ctl` with the link: the guard's gain and the pose to the device,
    /// then the controller's tick with the set waiting in `swap`, if any, then, when one
    /// is due, the patch's mesh posted to `mesh` for the main loop. Returns the force the
    /// controller computed (the device renders it times the gain) and the gain.
    pub fn tick<
        D: crate::HapticDevice,
        const N: usize,
        const E: usize,
        const S: usize,
        A: Arith,
        C: crate::Contact<N, E, S, A>,
    >(
        &self,
        ctl: &mut Controller<LinkedDevice<D>, N, E, S, A, C>,
        swap: &Mailbox<ParamSet<S, A>>,
        mesh: &Mailbox<Mesh<N>>,
    ) -> ([Force; 3], u16) {
        let ticks = ctl.telemetry().ticks;
        let gain = self.guard.update(|g| g.gain(ticks));
        let d = ctl.device_mut();
        d.set_gain(gain);
        d.set_target(self.pose.get());
        let set = if self.swap_ready.get() {
            self.swap_ready.set(false);
            swap.take()
        } else {
            None
        };
        let force = ctl.tick(set);
        if self.mesh.due() {
            let _ = mesh.post(Mesh::of(ctl.solver(), ticks));
        }
        (force, gain)
    }

    /// Posts a checked parameter set for the next tick.
    pub fn post_swap<const S: usize, A: Arith>(
        &self,
        swap: &Mailbox<ParamSet<S, A>>,
        set: ParamSet<S, A>,
    ) {
        let _ = swap.post(set);
        self.swap_ready.set(true);
    }
}
