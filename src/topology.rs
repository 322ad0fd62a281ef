//! `Topology`: the springs of a patch and what the per-tick loop needs of each, computed
//! once so that a step does no division and no square root.
//!
//! Node 0 is the *ground*: every fixed node (the patch's outer ring, the base layer) is
//! represented by it. Its displacement and velocity stay zero; each edge keeps its own
//! rest geometry, so one ground slot serves all fixed nodes and costs no branch per edge.
//! Nodes `1 …` are free. Positions are in mm in the patch frame: origin at the contact
//! node's rest position, `z` up, surface at `z = 0`.

use crate::q::V3;
use crate::units::{from_f64, to_f64, DIR_FRAC, INV_LEN_FRAC, LEN_FRAC};
use heapless::Vec;

/// Index of the ground node (all fixed nodes).
pub const GROUND: u16 = 0;

/// Most springs at one node: their summed forces (each within
/// [`crate::arith::SPRING_FORCE_LIMIT`]) cannot overflow the Q20 accumulator.
pub const MAX_SPRINGS_PER_NODE: usize = 20;

/// One spring of the patch. In declaration order (`repr(C)`, 20 bytes), so that the
/// ARMv7E-M spring loop loads a whole edge with one `ldm` (`arith/wide_dsp/`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct Edge {
    /// Rest vector from `a` to `b` divided by the rest length `l0`: a unit vector, Q23
    /// ([`crate::units::DIR_FRAC`]).
    pub dir: V3,
    /// `1 / l0` in 1/mm, Q31 (`l0 ≥ 1 mm`; 1 mm is stored as `i32::MAX`).
    pub inv_len: i32,
    /// First node: always a free one.
    pub a: u16,
    /// Second node (0 = ground: a spring to a fixed point has its fixed end here).
    pub b: u16,
}

/// An end of an edge being added: a free node, or a fixed point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum End {
    /// A free node, by index (from [`Topology::add_free_node`]).
    Free(u16),
    /// A fixed point at this rest position (mm, patch frame).
    Fixed([f64; 3]),
}

/// Why a topology could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TopologyError {
    /// More free nodes than the capacity `NODES − 1`.
    NodeCapacity,
    /// More edges than the capacity `EDGES`.
    EdgeCapacity,
    /// The grid size is below 3 or above 200, or the spacing is not finite and > 0.
    BadGrid,
    /// A position beyond ±100 mm (the Q24 length format holds ±128 mm).
    OutOfRange,
    /// An edge shorter than 1 mm (the solver's fixed-point ranges assume `l0 ≥ 1 mm`).
    TooShort,
    /// An edge referring to a node that does not exist, or joining two fixed points.
    BadEnd,
    /// More than [`MAX_SPRINGS_PER_NODE`] springs at one free node.
    TooManySprings,
}

impl core::fmt::Display for TopologyError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.message())
    }
}

impl TopologyError {
    /// The message: one source for `Display` and the `defmt` impl.
    pub const fn message(&self) -> &'static str {
        match self {
            Self::NodeCapacity => "topology: more free nodes than the node capacity",
            Self::EdgeCapacity => "topology: more springs than the edge capacity",
            Self::BadGrid => {
                "topology: the grid must be 3 to 200 nodes a side with a finite spacing > 0"
            }
            Self::OutOfRange => "topology: a node lies beyond ±100 mm of the contact node",
            Self::TooShort => "topology: a spring is shorter than 1 mm",
            Self::BadEnd => "topology: a spring refers to a missing node or joins two fixed points",
            Self::TooManySprings => "topology: more than 20 springs at one node",
        }
    }
}

impl core::error::Error for TopologyError {}

/// The springs and free nodes of a patch; capacities in the type.
#[derive(Clone, Debug)]
pub struct Topology<const NODES: usize, const EDGES: usize> {
    edges: Vec<Edge, EDGES>,
    /// Rest positions of the nodes (index 0: ground, unused), mm, Q24.
    rest: Vec<[i32; 3], NODES>,
    contact: u16,
}

impl<const NODES: usize, const EDGES: usize> Default for Topology<NODES, EDGES> {
    fn default() -> Self {
        Self::new()
    }
}

/// The capacities [`Topology::standard_patch`]`(n, _)` needs: `(NODES, EDGES)`, node
/// slots (the ground included: `(n − 2)² + 1`) and springs (`5n² − 14n + 6`), for `n ≥ 3`
/// (n = 5: 10 and 61; n = 8: 37 and 214).
pub const fn standard_capacity(n: usize) -> (usize, usize) {
    let inner = n.saturating_sub(2);
    (inner * inner + 1, (5 * n * n + 6).saturating_sub(14 * n))
}

impl<const NODES: usize, const EDGES: usize> Topology<NODES, EDGES> {
    /// An empty topology (the ground only). Add nodes and edges, then [`Self::set_contact`].
    pub fn new() -> Self {
        let mut rest = Vec::new();
        // NODES = 0 leaves no room for the ground: every later call reports capacity.
        let _ = rest.push([0; 3]);
        Self {
            edges: Vec::new(),
            rest,
            contact: GROUND,
        }
    }

    /// Adds a free node at `rest` (mm); returns its index.
    pub fn add_free_node(&mut self, rest: [f64; 3]) -> Result<u16, TopologyError> {
        if rest.iter().any(|x| !x.is_finite() || x.abs() > 100.0) {
            return Err(TopologyError::OutOfRange);
        }
        if self.rest.is_empty() {
            return Err(TopologyError::NodeCapacity);
        }
        let index = self.rest.len();
        self.rest
            .push(rest.map(|x| from_f64(x, LEN_FRAC)))
            .map_err(|_| TopologyError::NodeCapacity)?;
        Ok(index as u16)
    }

    /// Adds a spring between two ends, at least one of them free.
    pub fn add_edge(&mut self, a: End, b: End) -> Result<(), TopologyError> {
        let end = |e: End| -> Result<(u16, [f64; 3]), TopologyError> {
            match e {
                End::Free(i) if i != GROUND && (i as usize) < self.rest.len() => {
                    Ok((i, self.rest[i as usize].map(from_q24)))
                }
                End::Free(_) => Err(TopologyError::BadEnd),
                End::Fixed(p) if p.iter().all(|x| x.is_finite() && x.abs() <= 100.0) => {
                    Ok((GROUND, p))
                }
                End::Fixed(_) => Err(TopologyError::OutOfRange),
            }
        };
        let ((ia, pa), (ib, pb)) = (end(a)?, end(b)?);
        if ia == GROUND && ib == GROUND {
            return Err(TopologyError::BadEnd);
        }
        // A spring to a fixed point keeps the ground as `b`: the solver's loop then skips
        // the ground's loads and its force accumulator.
        let ((ia, pa), (ib, pb)) = if ia == GROUND {
            ((ib, pb), (ia, pa))
        } else {
            ((ia, pa), (ib, pb))
        };
        let d = [pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]];
        let len = libm::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if len < 1.0 {
            return Err(TopologyError::TooShort);
        }
        for i in [ia, ib] {
            let degree = self
                .edges
                .iter()
                .filter(|e| i != GROUND && (e.a == i || e.b == i))
                .count();
            if degree >= MAX_SPRINGS_PER_NODE {
                return Err(TopologyError::TooManySprings);
            }
        }
        let dir = d.map(|x| from_f64(x / len, DIR_FRAC));
        self.edges
            .push(Edge {
                a: ia,
                b: ib,
                dir,
                inv_len: from_f64(1.0 / len, INV_LEN_FRAC),
            })
            .map_err(|_| TopologyError::EdgeCapacity)
    }

    /// Chooses the node the probe couples to (and indentation drives).
    pub fn set_contact(&mut self, node: u16) -> Result<(), TopologyError> {
        if node == GROUND || node as usize >= self.rest.len() {
            return Err(TopologyError::BadEnd);
        }
        self.contact = node;
        Ok(())
    }

    /// The standard patch (`docs/model.md`): `n × n` surface nodes on a square grid of spacing
    /// `spacing` mm at `z = 0`, the outer ring fixed, a fixed base layer at `z = −spacing`
    /// under every surface node; structural, shear and vertical springs, leaving out
    /// those with both ends fixed (n = 5: 61 springs, n = 8: 214). The contact node is
    /// `(n/2, n/2)`, at the origin.
    #[inline(never)]
    pub fn standard_patch(n: usize, spacing: f64) -> Result<Self, TopologyError> {
        if !(3..=200).contains(&n) || !spacing.is_finite() || spacing <= 0.0 {
            return Err(TopologyError::BadGrid);
        }
        let mut t = Self::new();
        let c = (n / 2) as f64;
        let pos =
            |i: usize, j: usize, z: f64| [(i as f64 - c) * spacing, (j as f64 - c) * spacing, z];
        let fixed = |i: usize, j: usize| i == 0 || j == 0 || i == n - 1 || j == n - 1;
        // Free surface node (i, j) gets index 1 + (i − 1)(n − 2) + (j − 1) (`surface_node`).
        for i in 1..n - 1 {
            for j in 1..n - 1 {
                t.add_free_node(pos(i, j, 0.0))?;
            }
        }
        // (A free node that is not one is a logic error here: refused, as a bad end.)
        let surface = |i: usize, j: usize| -> Result<End, TopologyError> {
            if fixed(i, j) {
                Ok(End::Fixed(pos(i, j, 0.0)))
            } else {
                let node = surface_node(n, i as i32, j as i32).ok_or(TopologyError::BadEnd)?;
                Ok(End::Free(node as u16))
            }
        };
        let both_fixed = |p: (usize, usize), q: (usize, usize)| fixed(p.0, p.1) && fixed(q.0, q.1);
        let mut pairs = |p: (usize, usize), q: (usize, usize)| -> Result<(), TopologyError> {
            if both_fixed(p, q) {
                return Ok(());
            }
            t.add_edge(surface(p.0, p.1)?, surface(q.0, q.1)?)
        };
        for i in 0..n {
            for j in 0..n {
                if i + 1 < n {
                    pairs((i, j), (i + 1, j))?;
                }
                if j + 1 < n {
                    pairs((i, j), (i, j + 1))?;
                }
                if i + 1 < n && j + 1 < n {
                    pairs((i, j), (i + 1, j + 1))?;
                    pairs((i + 1, j), (i, j + 1))?;
                }
            }
        }
        for i in 1..n - 1 {
            for j in 1..n - 1 {
                t.add_edge(surface(i, j)?, End::Fixed(pos(i, j, -spacing)))?;
            }
        }
        let contact =
            surface_node(n, (n / 2) as i32, (n / 2) as i32).ok_or(TopologyError::BadEnd)?;
        t.set_contact(contact as u16)?;
        Ok(t)
    }

    /// The springs.
    pub fn edges(&self) -> &[Edge] {
        &self.edges
    }

    /// Number of node slots in use, the ground included.
    pub fn node_count(&self) -> usize {
        self.rest.len()
    }

    /// The contact node.
    pub fn contact(&self) -> u16 {
        self.contact
    }

    /// Rest position of node `i` (Q24 mm), `None` if it does not exist.
    pub fn rest_q24(&self, i: usize) -> Option<[i32; 3]> {
        self.rest.get(i).copied()
    }

    /// The springs' rest geometry, to rewrite (a window moving over a cap): a writer
    /// that sets a spring's direction and `1/l0` and reads the springs, but cannot change
    /// an edge's ends. [`Topology::add_edge`] is the only way an edge's ends are written,
    /// so every edge's ends stay indices of existing slots, `a` never the ground and never
    /// `b` — what the spring loops' unchecked node accesses rest on
    /// (`state::for_each_spring`, `arith/wide_dsp/`).
    #[inline(always)]
    pub(crate) fn rest_geometry(&mut self) -> RestGeometry<'_> {
        RestGeometry {
            edges: &mut self.edges,
        }
    }

    /// The same springs in reverse order (a test of an order a cap's shift refuses).
    #[cfg(test)]
    pub(crate) fn reverse_edges(&mut self) {
        self.edges.reverse();
    }

    /// Sets free node `i`'s rest height (Q24 mm; a window moving over a cap).
    pub(crate) fn set_rest_z(&mut self, i: usize, z: i32) {
        if let Some(p) = self.rest.get_mut(i) {
            p[2] = z;
        }
    }

    /// Rest position of node `i` (mm), `None` if it does not exist.
    pub fn rest(&self, i: u16) -> Option<[f64; 3]> {
        self.rest.get(i as usize).map(|p| p.map(from_q24))
    }

    /// A 32-bit FNV-1a digest of the topology (node slots, contact node, and every edge's
    /// ends and rest geometry as stored): what a [`crate::ParamSet`] is tied to, so that a
    /// set prepared for one topology is refused by a solver on another (start-up only:
    /// a loop over the edges).
    pub fn fingerprint(&self) -> u32 {
        let mut h = crate::fnv::Fnv1a::new();
        let mut eat = |x: u32| h.update(&x.to_le_bytes());
        eat(self.rest.len() as u32);
        eat(self.contact as u32);
        for e in self.edges.iter() {
            eat(e.a as u32 | (e.b as u32) << 16);
            e.dir.iter().for_each(|&d| eat(d as u32));
            eat(e.inv_len as u32);
        }
        h.value()
    }

    /// Rest length of edge `e` (mm), from its stored `1/l0`.
    pub fn rest_length(e: &Edge) -> f64 {
        rest_length(e)
    }
}

/// An edge's rest length, mm, from its `1 / l0` (start-up: `f64`).
pub fn rest_length(e: &Edge) -> f64 {
    (1u64 << INV_LEN_FRAC) as f64 / e.inv_len as f64
}

/// The springs of a [`Topology`] with their rest geometry open to rewriting and their ends
/// not ([`Topology::rest_geometry`]).
pub(crate) struct RestGeometry<'a> {
    edges: &'a mut [Edge],
}

impl RestGeometry<'_> {
    /// The springs.
    #[inline(always)]
    pub(crate) fn edges(&self) -> &[Edge] {
        self.edges
    }

    /// Sets spring `e`'s rest direction `dir` (Q23) and `1/l0` (Q31 per mm); no spring
    /// `e`: nothing.
    #[inline(always)]
    pub(crate) fn set(&mut self, e: usize, dir: V3, inv_len: i32) {
        if let Some(edge) = self.edges.get_mut(e) {
            edge.dir = dir;
            edge.inv_len = inv_len;
        }
    }
}

/// The node index of the standard patch's surface node `(a, b)` (grid coordinates,
/// `0 … n − 1`): `1 + (a − 1)(n − 2) + (b − 1)` for a free node, `None` on the fixed
/// outer ring or off the grid. One source for the layout `standard_patch` builds and the
/// proxy and the window read.
#[inline(always)]
pub(crate) fn surface_node(n: usize, a: i32, b: i32) -> Option<usize> {
    let inner = n as i32 - 2;
    (a >= 1 && b >= 1 && a <= inner && b <= inner).then(|| (1 + (a - 1) * inner + (b - 1)) as usize)
}

fn from_q24(x: i32) -> f64 {
    to_f64(x, LEN_FRAC)
}
