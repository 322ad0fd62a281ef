//! `Window`: the standard patch as a window onto a larger tissue that follows the contact
//! (issue #19; the `f64` reference is `mccs_host::roam`, `docs/roaming.md`).
//!
//! The tissue is `W × H` nodes at the patch's spacing, centred on the origin (its top at
//! `z = 0`), flat or a spherical cap (`src/cap.rs`); the patch simulates the `n × n` of
//! them around its centre node, outer ring fixed at rest. When the contact point (out of contact: the probe) is more than
//! `½ + hysteresis` spacings from the centre along an axis, the window moves one node
//! that way and stays inside the tissue: the free nodes that stay free keep their state,
//! the others start at rest, each spring takes the warm-start value of the spring it
//! continues (a map per direction, built at start-up), and the proxy keeps its place on
//! the tissue. A shift costs one pass over the nodes and one over the springs: bounded,
//! no search. On a cap the springs' rest geometry changes with the window: a shift also
//! moves the window's rest heights, computes the `n` entering ones, takes each spring's
//! geometry from the spring it continues and computes the entering springs' (about
//! `5 (n − 2)`, one reciprocal square root each).

/// What a window is built from (start-up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindowConfig {
    /// Tissue nodes along `x` (the patch's `n` … 64).
    pub tissue_w: usize,
    /// Tissue nodes along `y` (the patch's `n` … 64).
    pub tissue_h: usize,
    /// How far past half a spacing the contact must go before the window moves,
    /// spacings (0.05 … 0.45).
    pub hysteresis: f64,
    /// A spherical cap of this radius, mm (4/3 of the tissue's half-diagonal … 2000 mm;
    /// its base within ±100 mm); `None`: flat.
    pub cap_radius: Option<f64>,
}

/// No warm-start value to take: the spring starts at rest.
pub(crate) const NONE: u16 = u16::MAX;
/// In a map entry: the spring continued runs the other way (its direction is negated).
pub(crate) const FLIP: u16 = 1 << 15;

/// The window: where it is on the tissue, and the start-up maps its shifts use. `CAP`:
/// whether it may lie on a cap ([`crate::Solver::shaped_window`]); a flat-only window
/// ([`crate::Solver::window`], the default) compiles its tick without the cap's code (on
/// the M0 about 19 KiB of flash).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Window<const EDGES: usize, const CAP: bool = false> {
    pub(crate) n: i32,
    pub(crate) w: i32,
    pub(crate) h: i32,
    /// The window's first corner, tissue grid coordinates.
    pub(crate) corner: [i32; 2],
    /// `½ + hysteresis`, Q16 spacings.
    pub(crate) limit: i32,
    /// Spacing, Q24 mm.
    pub(crate) spacing: i32,
    /// Per direction (`+x`, `−x`, `+y`, `−y`): for each spring, the spring whose
    /// warm-start value (and on a cap, rest geometry) it takes at a shift ([`NONE`]: it
    /// starts at rest; with [`FLIP`]: that spring runs the other way).
    pub(crate) maps: [[u16; EDGES]; 4],
    /// Shifts so far.
    pub(crate) shifts: u32,
    /// The tissue's cap (`None`: flat).
    pub(crate) cap: Option<crate::cap::Cap>,
    /// `1/s`, Q30 per mm.
    pub(crate) inv_s: i32,
    /// The tissue's half extents `(W − 1) s / 2`, `(H − 1) s / 2`, Q24 mm.
    pub(crate) half: [i32; 2],
    /// On a cap: the rest heights of the window's `n × n` surface nodes (Q24 mm, node
    /// `(a, b)` at `a n + b`), in the first `n²` slots (the standard patch has
    /// `5n² − 14n + 6 ≥ n²` springs).
    pub(crate) heights: [i32; EDGES],
    /// On a cap: where each spring's two ends are on the window's grid ([`pack_ends`]).
    pub(crate) ends: [u32; EDGES],
}

/// The spring a map entry names, and whether it runs the other way. `NONE`'s index,
/// 2¹⁵ − 1, is past every spring (a window has fewer: `Solver::window_as` asserts it),
/// so that a lookup finds nothing and its flag is never read.
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

impl<const EDGES: usize, const CAP: bool> Window<EDGES, CAP> {
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
    pub fn origin_mm(&self) -> [crate::units::Length; 2] {
        self.origin().map(crate::units::Length::from_bits)
    }

    /// Whether the tissue is a cap.
    pub fn is_cap(&self) -> bool {
        self.cap.is_some()
    }

    /// The centre node's rest position in the tissue frame, Q24 mm: the patch frame's
    /// origin.
    pub(crate) fn origin(&self) -> [i32; 2] {
        let c = self.centre();
        // (i − (W − 1)/2) s = (2i − W + 1) s / 2, exact for an odd raw spacing too.
        let at = |i: usize, w: i32| {
            crate::q::sat(crate::q::mul_wide(2 * i as i32 - w + 1, self.spacing) >> 1)
        };
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
}
