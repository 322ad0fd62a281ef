//! The live patch's node positions for the host's visuals (`ToDevice::WatchMesh`): the
//! tick takes a [`Mesh`] every `every` ticks (a countdown, [`MeshClock`]: no division in
//! the tick) and posts it for the main loop, which sends it in parts of
//! [`MESH_PART`] nodes with each node's place in the surface grid
//! ([`super::Session::mesh`]). The rate is held to the link's byte budget
//! (`mccs_link::rates::mesh_least_every`); a mesh the main loop has not sent when the
//! next is taken is replaced (the newest wins) and counted as dropped.

use crate::Shared;
use mccs::{Arith, Solver};
pub use mccs_link::MESH_PART;

/// The nodes' positions at one tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Mesh<const N: usize> {
    /// The tick.
    pub tick: u32,
    /// The patch's free nodes (at most `N`).
    pub nodes: u16,
    /// The patch frame's origin in the tissue's frame (`x, y`), Q24 mm.
    pub origin: [i32; 2],
    /// Free node `k + 1`'s rest position plus its displacement at `k` (the ground's slot,
    /// node 0, is left out), patch frame, Q24 mm.
    pub positions: [[i32; 3]; N],
}

impl<const N: usize> Mesh<N> {
    /// `solver`'s nodes at `tick`, the patch's origin at `origin` in the tissue's frame:
    /// one pass over them, saturating adds (the tick's path).
    pub fn of<const E: usize, const S: usize, A: Arith>(
        solver: &Solver<N, E, S, A>,
        tick: u32,
        origin: [i32; 2],
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
            origin,
            positions,
        }
    }
}

/// Free node `k`'s (0-based, the mesh's order) place `(i, j)` in the standard patch's
/// `grid × grid` surface grid (`Topology::standard_patch` numbers the free nodes row
/// by row inside the fixed ring). The main loop's, not the tick's: it divides.
pub fn grid_place(grid: usize, k: usize) -> [u8; 2] {
    let inner = grid.saturating_sub(2).max(1);
    [(1 + k / inner) as u8, (1 + k % inner) as u8]
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
