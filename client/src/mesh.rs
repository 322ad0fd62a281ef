//! [`Mesh`]: the device's live patch, put together from its `Mesh` parts — each node's
//! place `(i, j)` in the patch's surface grid and its position — with the triangles a
//! scene draws ([`Mesh::triangles`]: each grid cell split along its `(i, j)`–`(i+1, j+1)`
//! diagonal, as the device's contact splits it).

use mccs_link::{scale, MeshPart};

/// One node of the mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshNode {
    /// Its place in the surface grid (the fixed outer ring at 0 and `grid − 1`).
    pub grid: [u8; 2],
    /// Its position in the tissue's frame, mm.
    pub position_mm: [f64; 3],
}

/// The live patch at one tick.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Counts meshes: a gap is a drop.
    pub seq: u32,
    /// The tick it is from.
    pub tick: u32,
    /// The patch frame's origin in the tissue's frame, mm (`x, y`).
    pub origin_mm: [f64; 2],
    /// The free nodes.
    pub nodes: Vec<MeshNode>,
}

impl Mesh {
    /// The triangles between free nodes, as indices into `nodes`.
    pub fn triangles(&self) -> Vec<[usize; 3]> {
        let at = |i: u8, j: u8| self.nodes.iter().position(|n| n.grid == [i, j]);
        let mut out = Vec::new();
        for n in &self.nodes {
            let [i, j] = n.grid;
            let (Some(a), Some(b), Some(c), Some(d)) = (
                at(i, j),
                at(i.saturating_add(1), j),
                at(i.saturating_add(1), j.saturating_add(1)),
                at(i, j.saturating_add(1)),
            ) else {
                continue;
            };
            out.push([a, b, c]);
            out.push([a, c, d]);
        }
        out
    }
}

/// Parts of the mesh under way.
#[derive(Default)]
pub(crate) struct MeshAssembly {
    building: Option<Mesh>,
    got: usize,
}

impl MeshAssembly {
    /// Takes a part; the mesh once whole.
    pub(crate) fn add(&mut self, p: &MeshPart) -> Option<Mesh> {
        let nodes = p.nodes as usize;
        if p.first == 0 || self.building.as_ref().is_none_or(|m| m.seq != p.seq) {
            let origin = p.origin.map(scale::mm);
            self.building = Some(Mesh {
                seq: p.seq,
                tick: p.tick,
                origin_mm: origin,
                nodes: vec![
                    MeshNode {
                        grid: [0, 0],
                        position_mm: [0.0; 3]
                    };
                    nodes
                ],
            });
            self.got = 0;
        }
        let m = self.building.as_mut()?;
        let count = nodes
            .saturating_sub(p.first as usize)
            .min(p.positions.len());
        for k in 0..count {
            let idx = p.first as usize + k;
            if let Some(n) = m.nodes.get_mut(idx) {
                let q = p.positions[k].map(scale::mm);
                *n = MeshNode {
                    grid: p.grid[k],
                    position_mm: [q[0] + m.origin_mm[0], q[1] + m.origin_mm[1], q[2]],
                };
            }
        }
        self.got += count;
        if self.got >= nodes {
            self.got = 0;
            return self.building.take();
        }
        None
    }
}
