//! The live patch's node positions for the host's visuals (`ToDevice::WatchMesh`): the
//! tick takes a [`Mesh`] every `every` ticks (a countdown, [`MeshClock`]: no division in
//! the tick) and posts it for the main loop, which sends it in parts of
//! [`MESH_PART`] nodes ([`super::Session::mesh`]). At most 60 meshes a second
//! ([`least_every`]); a mesh the main loop has not sent when the next is taken is
//! replaced (the newest wins) and counted as dropped.

use crate::Shared;
use mccs::{Arith, Solver};
pub use mccs_link::message::MESH_PART;

/// The nodes' positions at one tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Mesh<const N: usize> {
    /// The tick.
    pub tick: u32,
    /// The patch's free nodes (at most `N`).
    pub nodes: u16,
    /// Free node `k + 1`'s rest position plus its displacement at `k` (the ground's slot,
    /// node 0, is left out), patch frame, Q24 mm.
    pub positions: [[i32; 3]; N],
}

impl<const N: usize> Mesh<N> {
    /// `solver`'s nodes at `tick`: one pass over them, saturating adds (the tick's path).
    pub fn of<const E: usize, const S: usize, A: Arith>(
        solver: &Solver<N, E, S, A>,
        tick: u32,
    ) -> Self {
        let topo = solver.topology();
        // The free nodes, 1 … (node 0 is the ground's slot).
        let nodes = topo.node_count().saturating_sub(1).min(N);
        let mut positions = [[0i32; 3]; N];
        for (k, p) in positions.iter_mut().enumerate().take(nodes) {
            let rest = topo.rest_q24(k + 1).unwrap_or([0; 3]);
            let u = solver
                .displacement(k as u16 + 1)
                .map_or([0; 3], |d| d.map(|x| x.to_bits()));
            *p = [0, 1, 2].map(|j| rest[j].saturating_add(u[j]));
        }
        Self {
            tick,
            nodes: nodes as u16,
            positions,
        }
    }
}

/// The fewest ticks between two meshes at `tick_hz`: 60 meshes a second at most.
pub const fn least_every(tick_hz: u32) -> u16 {
    let every = tick_hz.div_ceil(60);
    if every > u16::MAX as u32 {
        u16::MAX
    } else {
        every as u16
    }
}

/// When the tick takes a mesh: every `every` ticks (0: never), by a countdown. One
/// shared `(every, left)`, so that the main loop's `set` takes it whole; a tick that is
/// not asked for meshes reads it once.
pub struct MeshClock {
    every_left: Shared<(u16, u16)>,
}

impl MeshClock {
    /// Never.
    pub const fn new() -> Self {
        Self {
            every_left: Shared::new((0, 0)),
        }
    }

    /// Every `every` ticks from the next (0: never); the main loop sets it.
    pub fn set(&self, every: u16) {
        self.every_left.set((every, 0));
    }

    /// The tick asks: is a mesh due now? (The tick preempts the main loop, never the
    /// other way round: its read and write of the state cannot be split by a `set`.)
    pub fn due(&self) -> bool {
        let (every, left) = self.every_left.get();
        if every == 0 {
            return false;
        }
        let due = left == 0;
        self.every_left
            .set((every, if due { every - 1 } else { left - 1 }));
        due
    }
}

impl Default for MeshClock {
    fn default() -> Self {
        Self::new()
    }
}
