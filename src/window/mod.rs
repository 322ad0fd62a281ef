//! `Window`: the standard patch as a window onto a larger tissue that follows the contact
//! (the `f64` reference is `mccs_host::roam`, `docs/roaming.md`).
//!
//! The tissue is `W × H` nodes at the patch's spacing, centred on the origin (its top at
//! `z = 0`), of a [`Shape`]: flat, or a spherical cap (`crate::shape`); the patch
//! simulates the `n × n` of them around its centre node, outer ring fixed at rest. When
//! the contact point (out of contact: the probe) is more than `½ + hysteresis` spacings
//! from the centre along an axis, the window moves one node that way and stays inside the
//! tissue: the free nodes that stay free keep their state, the others start at rest, each
//! spring takes the warm-start value of the spring it continues (a map per direction,
//! built at start-up: `start.rs`), and the proxy keeps its place on the tissue. A shift
//! costs one pass over the nodes and one over the springs: bounded, no search. On a cap
//! the springs' rest geometry changes with the window: a shift also moves the window's
//! rest heights, computes the `n` entering ones, takes each spring's geometry from the
//! spring it continues and computes the entering springs' (about `5 (n − 2)`, one
//! reciprocal square root each: `cap_springs.rs`).
//!
//! The window owns its shift rules (`Window::step_for`, `Window::advance`); the
//! solver moves the patch's state with it (`solver/roaming.rs`).

mod cap_springs;
mod start;

use cap_springs::move_heights;
#[cfg(test)]
pub(crate) use start::DIRECTIONS;
pub(crate) use start::{Key, Placement};

use crate::q::{mul_wide, sat};
use crate::shape::{Flat, Shape};
use crate::units::Length;

/// What a window is built from (start-up), with its tissue's shape
/// ([`crate::shape::ShapeSpec`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindowConfig {
    /// Tissue nodes along `x` (the patch's `n` … 64).
    pub tissue_w: usize,
    /// Tissue nodes along `y` (the patch's `n` … 64).
    pub tissue_h: usize,
    /// How far past half a spacing the contact must go before the window moves,
    /// spacings (0.05 … 0.45).
    pub hysteresis: f64,
}

/// No warm-start value to take: the spring starts at rest.
pub(crate) const NONE: u16 = u16::MAX;
/// In a map entry: the spring continued runs the other way (its direction is negated).
pub(crate) const FLIP: u16 = 1 << 15;

/// The window: where it is on the tissue, its shape, and the start-up maps its shifts
/// use. Built by [`crate::Solver::window`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Window<const EDGES: usize, Sh: Shape = Flat> {
    n: i32,
    w: i32,
    h: i32,
    /// The window's first corner, tissue grid coordinates.
    corner: [i32; 2],
    /// `½ + hysteresis`, Q16 spacings.
    limit: i32,
    /// Spacing, Q24 mm.
    spacing: i32,
    /// Per direction (`+x`, `−x`, `+y`, `−y`): for each spring, the spring whose
    /// warm-start value (and on a cap, rest geometry) it takes at a shift ([`NONE`]: it
    /// starts at rest; with [`FLIP`]: that spring runs the other way).
    maps: [[u16; EDGES]; 4],
    /// Shifts so far.
    shifts: u32,
    /// The tissue's rest surface.
    shape: Sh,
    /// `1/s`, Q30 per mm.
    inv_s: i32,
    /// The tissue's half extents `(W − 1) s / 2`, `(H − 1) s / 2`, Q24 mm.
    half: [i32; 2],
    /// On a cap: the rest heights of the window's `n × n` surface nodes (Q24 mm, node
    /// `(a, b)` at `a n + b`), in the first `n²` slots (the standard patch has
    /// `5n² − 14n + 6 ≥ n²` springs).
    heights: [i32; EDGES],
    /// On a cap: where each spring's two ends are on the window's grid ([`pack_ends`]).
    ends: [u32; EDGES],
}

/// The spring a map entry names, and whether it runs the other way. `NONE`'s index,
/// 2¹⁵ − 1, is past every spring (a window has fewer: `start.rs` asserts it), so that a
/// lookup finds nothing and its flag is never read.
#[inline(always)]
pub(crate) fn continued(entry: u16) -> (usize, bool) {
    ((entry & !FLIP) as usize, entry & FLIP != 0)
}

/// Two ends `(a, b, layer)` (grid coordinates 0 … 127, layer 1: the base) in one word.
pub(crate) fn pack_ends(k: [[i32; 3]; 2]) -> u32 {
    let one =
        |e: [i32; 3]| (e[0] as u32 & 0x7F) | (e[1] as u32 & 0x7F) << 7 | (e[2] as u32 & 1) << 14;
    one(k[0]) | one(k[1]) << 15
}

/// The ends [`pack_ends`] packed.
pub(crate) fn unpack_ends(x: u32) -> [[i32; 3]; 2] {
    let one = |e: u32| {
        [
            (e & 0x7F) as i32,
            (e >> 7 & 0x7F) as i32,
            (e >> 14 & 1) as i32,
        ]
    };
    [one(x), one(x >> 15)]
}

impl<const EDGES: usize, Sh: Shape> Window<EDGES, Sh> {
    /// The window's centre node, tissue grid coordinates.
    pub fn centre(&self) -> (usize, usize) {
        (
            (self.corner[0] + self.n / 2) as usize,
            (self.corner[1] + self.n / 2) as usize,
        )
    }

    /// Shifts so far.
    pub fn shifts(&self) -> u32 {
        self.shifts
    }

    /// The patch frame's origin (the centre node's rest position) in the tissue frame,
    /// mm (`x`, `y`; the frames share `z`).
    pub fn origin_mm(&self) -> [Length; 2] {
        self.origin().map(Length::from_bits)
    }

    /// The tissue's shape.
    pub fn shape(&self) -> &Sh {
        &self.shape
    }

    /// The patch's side `n`.
    pub(crate) fn side(&self) -> i32 {
        self.n
    }

    /// The centre node's rest position in the tissue frame, Q24 mm: the patch frame's
    /// origin.
    pub(crate) fn origin(&self) -> [i32; 2] {
        let c = self.centre();
        // (i − (W − 1)/2) s = (2i − W + 1) s / 2, exact for an odd raw spacing too.
        let at = |i: usize, w: i32| sat(mul_wide(2 * i as i32 - w + 1, self.spacing) >> 1);
        [at(c.0, self.w), at(c.1, self.h)]
    }

    /// The tissue's rectangle in the patch frame whose origin is `o` ([`Window::origin`]),
    /// Q24 mm (`[x_lo, x_hi, y_lo, y_hi]`).
    pub(crate) fn tissue_rect(&self, o: [i32; 2]) -> [i32; 4] {
        let h = self.half;
        [
            h[0].saturating_neg().saturating_sub(o[0]),
            h[0].saturating_sub(o[0]),
            h[1].saturating_neg().saturating_sub(o[1]),
            h[1].saturating_sub(o[1]),
        ]
    }

    /// The shift for a point `g` (window grid coordinates, Q16): −1, 0 or +1 per axis,
    /// kept inside the tissue.
    pub(crate) fn step_for(&self, g: [i32; 2]) -> [i32; 2] {
        let centre = (self.n / 2) << 16;
        let side = [self.w, self.h];
        core::array::from_fn(|k| {
            let d = g[k].saturating_sub(centre);
            let s = if d > self.limit {
                1
            } else if d < -self.limit {
                -1
            } else {
                0
            };
            let c = self.corner[k] + s;
            if c < 0 || c > side[k] - self.n {
                0
            } else {
                s
            }
        })
    }

    /// The map of shifts along direction `dir` (`+x`, `−x`, `+y`, `−y`), for each
    /// spring the entry [`continued`] reads (a `dir` past the four: none continues).
    #[inline(always)]
    pub(crate) fn map(&self, dir: usize) -> Option<&[u16; EDGES]> {
        self.maps.get(dir)
    }

    /// The rest heights of the window's surface nodes, node `(a, b)` at `a n + b` (a
    /// flat window's: zeros, never read).
    #[inline(always)]
    pub(crate) fn heights(&self) -> &[i32; EDGES] {
        &self.heights
    }

    /// Moves the window one node along `d` (one axis, each −1, 0 or +1): on a cap its
    /// rest heights move with it and the entering ones are the cap's; its corner and its
    /// count of shifts. The solver moves the patch's nodes, springs and proxy with it.
    pub(crate) fn advance(&mut self, d: [i32; 2]) {
        if let Some(cap) = self.shape.cap() {
            move_heights(&mut self.heights, cap, self.n, self.corner, d);
        }
        self.corner = [self.corner[0] + d[0], self.corner[1] + d[1]];
        self.shifts = self.shifts.saturating_add(1);
    }
}
