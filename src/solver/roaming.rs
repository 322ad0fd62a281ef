//! The solver as a window onto a larger tissue ([`Window`]), flat or a cap, driven
//! through a [`Proxy`]: the window's start-up maps, its shifts, and the tick.

use super::step::tick_velocity;
use super::Solver;
use crate::arith::Arith;
use crate::cap::Cap;
use crate::proxy::{CapFrame, Proxy, ProxyError};
use crate::q::{self, mul_wide, sat, V3};
use crate::state::Node;
use crate::topology::{surface_node, Edge, GROUND};
use crate::units::{from_f64, to_f64, Force, Length, DIR_FRAC, LEN_FRAC};
use crate::window::{continued, pack_ends, unpack_ends, Window, WindowConfig, FLIP, NONE};

/// Where a spring's end is on the patch's grid: `(a, b, layer)` (layer 1: the base).
type Key = [i32; 3];

/// The shift directions, in the order of [`Window`]'s maps.
const DIRECTIONS: [[i32; 2]; 4] = [[1, 0], [-1, 0], [0, 1], [0, -1]];

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith> Solver<NODES, EDGES, S, A> {
    /// A window of this solver's patch onto a flat tissue of `config`'s size, centred on
    /// the tissue node nearest `(x, y)` (mm, tissue frame: origin at its centre), for a
    /// proxy from [`Solver::proxy`] (start-up: the maps take `4 E²` comparisons). A cap
    /// (`config.cap_radius`) is refused ([`ProxyError::FlatWindow`]): it needs
    /// [`Solver::shaped_window`]. On a cap the patch takes the window's rest geometry (its
    /// substeps and [`crate::ParamSet`] fingerprint stay the flat patch's: the cap's
    /// springs are no shorter, so no stiffer).
    pub fn window(
        &mut self,
        config: &WindowConfig,
        proxy: &Proxy,
        x: f64,
        y: f64,
    ) -> Result<Window<EDGES>, ProxyError> {
        self.window_as(config, proxy, x, y)
    }

    /// [`Solver::window`] onto a flat tissue or a cap (`config.cap_radius`): a
    /// `Window<EDGES, true>`, whose tick carries the cap's code.
    pub fn shaped_window(
        &mut self,
        config: &WindowConfig,
        proxy: &Proxy,
        x: f64,
        y: f64,
    ) -> Result<Window<EDGES, true>, ProxyError> {
        self.window_as(config, proxy, x, y)
    }

    /// [`Solver::window`] (`CAP` false) or [`Solver::shaped_window`] (`CAP` true), for
    /// code generic over the window's kind.
    #[inline(never)]
    pub fn window_as<const CAP: bool>(
        &mut self,
        config: &WindowConfig,
        proxy: &Proxy,
        x: f64,
        y: f64,
    ) -> Result<Window<EDGES, CAP>, ProxyError> {
        if !CAP && config.cap_radius.is_some() {
            return Err(ProxyError::FlatWindow);
        }
        let (n, spacing) = proxy.grid();
        let (w, h) = (config.tissue_w, config.tissue_h);
        let s = to_f64(spacing, LEN_FRAC);
        let half = (w.max(h) - 1) as f64 * s / 2.0;
        if w < n || h < n || w > 64 || h > 64 || half > 100.0 {
            return Err(ProxyError::Window);
        }
        if !(0.05..=0.45).contains(&config.hysteresis) {
            return Err(ProxyError::Window);
        }
        let cap = match config.cap_radius {
            None => None,
            Some(r) => Some(Self::cap_for(r, w, h, s)?),
        };
        let corner = |p: f64, side: usize| {
            let u = libm::round(p / s + (side - 1) as f64 / 2.0) - (n / 2) as f64;
            u.clamp(0.0, (side - n) as f64) as i32
        };
        let place = Placement {
            n,
            w,
            h,
            s,
            spacing,
            corner: [corner(x, w), corner(y, h)],
            limit: from_f64(0.5 + config.hysteresis, 16),
            cap,
        };
        self.build_window(&place)
    }

    /// The window [`Solver::window_as`] checked and placed: its maps, and on a cap its
    /// rest heights and the springs' geometry (start-up).
    ///
    /// Apart from the checks so that this function's large frame (the maps of every
    /// spring: some 36 KiB on a host's N = 9 patch) is set up on entry. An x86-64 host
    /// build with link-time optimisation otherwise moved the checks before the frame's
    /// stack probe loop, which takes `r11` as its scratch register without checking that
    /// it is free, and lost the tissue's height held there (an LLVM defect of the same
    /// kind as llvm/llvm-project#198699 on RISC-V): the window then started at the
    /// tissue's edge. `scripts/long.sh` checks a release build for it.
    #[inline(never)]
    fn build_window<const CAP: bool>(
        &mut self,
        place: &Placement,
    ) -> Result<Window<EDGES, CAP>, ProxyError> {
        let &Placement {
            n,
            w,
            h,
            s,
            spacing,
            corner,
            limit,
            cap,
        } = place;
        let keys: [[Key; 2]; EDGES] = core::array::from_fn(|e| {
            self.topo
                .edges()
                .get(e)
                .map_or([[-9; 3]; 2], |edge| self.keys(edge, n, s))
        });
        let count = self.topo.edges().len().min(EDGES);
        // A map entry is a spring's index below `FLIP`, and `NONE`'s index names none.
        const { assert!(EDGES < (NONE & !FLIP) as usize) };
        let maps = DIRECTIONS.map(|d| {
            core::array::from_fn(|e| {
                if e >= count {
                    return NONE;
                }
                let moved = keys[e].map(|k| [k[0] + d[0], k[1] + d[1], k[2]]);
                (0..count)
                    .find_map(|o| {
                        let k = keys[o];
                        if k[0] == moved[0] && k[1] == moved[1] {
                            Some(o as u16)
                        } else if k[0] == moved[1] && k[1] == moved[0] {
                            Some(o as u16 | FLIP)
                        } else {
                            None
                        }
                    })
                    .unwrap_or(NONE)
            })
        });
        // A shift on a cap moves the springs' geometry and warm-start values in place
        // (`move_cap_springs`):
        // forwards along +x and +y, where every spring's source comes after it, and
        // backwards along −x and −y. The standard patch's springs are laid out cell by
        // cell, so this holds; a topology for which it would not is refused.
        let ordered = || {
            maps.iter().enumerate().all(|(dir, map)| {
                map.iter().enumerate().all(|(e, &m)| {
                    let (source, _) = continued(m);
                    m == NONE || (dir % 2 == 0 && source > e) || (dir % 2 == 1 && source < e)
                })
            })
        };
        if cap.is_some() && !ordered() {
            return Err(ProxyError::Grid);
        }
        let mut window = Window::<EDGES, CAP> {
            n: n as i32,
            w: w as i32,
            h: h as i32,
            corner,
            limit,
            spacing,
            maps,
            shifts: 0,
            cap,
            inv_s: from_f64(1.0 / s, 30),
            half: [w, h].map(|k| sat(mul_wide(k as i32 - 1, spacing) >> 1)),
            heights: [0; EDGES],
            ends: core::array::from_fn(|e| pack_ends(keys[e])),
        };
        if let Some(cap) = cap.filter(|_| CAP) {
            if n * n > EDGES {
                return Err(ProxyError::Window);
            }
            for a in 0..n as i32 {
                for b in 0..n as i32 {
                    let z = cap.height(window.corner[0] + a, window.corner[1] + b);
                    if let Some(slot) = window.heights.get_mut((a * n as i32 + b) as usize) {
                        *slot = z;
                    }
                }
            }
            self.set_cap_heights(&window);
            for e in 0..self.topo.edges().len() {
                let (dir, inv_len) =
                    edge_geometry(&window, window.ends.get(e).copied().unwrap_or(0));
                self.topo.set_rest_geometry(e, dir, inv_len);
            }
        }
        Ok(window)
    }

    /// The cap of radius `r` mm over a `w × h` tissue at spacing `s` mm, if the core can
    /// run it: its base above −100 mm and its longest spring (at the tissue's corner)
    /// within the arithmetic's (start-up).
    fn cap_for(r: f64, w: usize, h: usize, s: f64) -> Result<Cap, ProxyError> {
        let cap = Cap::new(r, w, h, s).ok_or(ProxyError::Cap)?;
        let (hx, hy) = ((w - 1) as f64 * s / 2.0, (h - 1) as f64 * s / 2.0);
        let z = |x: f64, y: f64| libm::sqrt(r * r - x * x - y * y) - r;
        // The steepest cell is the corner's: its diagonal is the longest spring.
        let dz = z(hx, hy) - z(hx - s, hy - s);
        let longest = libm::sqrt(2.0 * s * s + dz * dz);
        if z(hx, hy) - s < -100.0 || longest > A::MAX_REST_LENGTH_MM {
            return Err(ProxyError::Cap);
        }
        Ok(cap)
    }

    /// On a cap: the free nodes' rest heights from the window's.
    fn set_cap_heights<const CAP: bool>(&mut self, window: &Window<EDGES, CAP>) {
        let n = window.n;
        for a in 1..n - 1 {
            for b in 1..n - 1 {
                if let (Some(i), Some(&z)) = (
                    surface_node(n as usize, a, b),
                    window.heights.get((a * n + b) as usize),
                ) {
                    self.topo.set_rest_z(i, z);
                }
            }
        }
    }

    /// On a cap, at a shift along direction `dir`: each spring's rest geometry and
    /// warm-start value taken from the spring it continues (its direction negated if that
    /// one runs the other way), else the geometry computed from the window's rest heights
    /// and the value at rest. In place, in the order [`Solver::window_as`] checked: every
    /// source is read before it is overwritten.
    fn move_cap_springs<const CAP: bool>(&mut self, window: &Window<EDGES, CAP>, dir: usize) {
        let Some(map) = window.maps.get(dir) else {
            return;
        };
        let topo = &mut self.topo;
        let count = topo.edges().len();
        let warm = &mut self.warm;
        // The source spring is copied out before the edge is written; each path writes
        // the edge itself, so that a copy does not go through the computed path's memory.
        let mut step = |e: usize| {
            let (source, reversed) = continued(map.get(e).copied().unwrap_or(NONE));
            let value = warm.get(source).copied().unwrap_or(A::REST);
            if let Some(w) = warm.get_mut(e) {
                *w = value;
            }
            if let Some(&Edge { dir, inv_len, .. }) = topo.edges().get(source) {
                let dir = if reversed {
                    dir.map(i32::saturating_neg)
                } else {
                    dir
                };
                topo.set_rest_geometry(e, dir, inv_len);
            } else {
                let (dir, inv_len) =
                    edge_geometry(window, window.ends.get(e).copied().unwrap_or(0));
                topo.set_rest_geometry(e, dir, inv_len);
            }
        };
        if dir % 2 == 0 {
            (0..count).for_each(&mut step);
        } else {
            (0..count).rev().for_each(&mut step);
        }
    }

    /// Where an edge's two ends are on the grid (start-up): the base end of a vertical
    /// spring is the one fixed end straight below its free end (on a cap too, where a
    /// surface node may lie deeper than `s/2`).
    fn keys(&self, e: &Edge, n: usize, s: f64) -> [Key; 2] {
        let c = (n / 2) as f64;
        let key = |p: [f64; 3]| -> [i32; 2] {
            [
                libm::round(p[0] / s + c) as i32,
                libm::round(p[1] / s + c) as i32,
            ]
        };
        let a = self.topo.rest(e.a).unwrap_or([0.0; 3]);
        let b = if e.b == GROUND {
            let l0 = crate::topology::Topology::<NODES, EDGES>::rest_length(e);
            core::array::from_fn(|k| a[k] + to_f64(e.dir[k], DIR_FRAC) * l0)
        } else {
            self.topo.rest(e.b).unwrap_or([0.0; 3])
        };
        let (ka, kb) = (key(a), key(b));
        let base = e.b == GROUND && ka == kb;
        [[ka[0], ka[1], 0], [kb[0], kb[1], base as i32]]
    }

    /// One haptic tick on the tissue with the probe at `probe` (mm, tissue frame)
    /// touching it through `proxy`; the window follows the contact (see [`Window`]).
    /// Returns the force the device must render (N).
    pub fn step_roaming<const CAP: bool>(
        &mut self,
        probe: [Length; 3],
        proxy: &mut Proxy,
        window: &mut Window<EDGES, CAP>,
    ) -> [Force; 3] {
        // The probe in the patch frame whose origin is `o`.
        let in_frame = |o: [i32; 2]| {
            let p = probe.map(Length::to_bits);
            [p[0].saturating_sub(o[0]), p[1].saturating_sub(o[1]), p[2]]
        };
        let o = window.origin();
        let mut p = in_frame(o);
        let probe_vel = tick_velocity(self.probe_prev, p, self.c.tick_hz);
        let frame = cap_frame(window);
        // The contact's goal on a flat tissue: the probe with its `xy` held to the
        // tissue's rectangle (past the tissue's edge, the point above the nearest point of
        // the tissue). On a cap, the radial line through the probe itself (past the edge
        // the cap falls away below the edge's rim, and the contact ends there).
        let tissue = window.tissue_rect(o);
        match &frame {
            None => proxy.update(&self.view(proxy), q::held_to(tissue, p)),
            Some(f) => proxy.update_cap(&self.cap_view(proxy, window), f, p, tissue),
        }
        let g = proxy.grid_position().unwrap_or_else(|| proxy.grid_of(p));
        let d = window.step_for(g);
        // One axis at a time (each index constant: no bounds check on the tick path).
        if d[0] != 0 {
            self.shift(window, [d[0], 0], proxy);
        }
        if d[1] != 0 {
            self.shift(window, [0, d[1]], proxy);
        }
        if d != [0, 0] {
            p = in_frame(window.origin());
        }
        self.probe_prev = p;
        if CAP && window.is_cap() {
            self.proxy_substeps_cap(p, probe_vel, proxy, window);
        } else {
            self.proxy_substeps(p, probe_vel, proxy);
        }
        self.device_force()
    }

    /// Moves the window one node along `d` (one axis): node states, warm-start values,
    /// the proxy's place.
    fn shift<const CAP: bool>(
        &mut self,
        window: &mut Window<EDGES, CAP>,
        d: [i32; 2],
        proxy: &mut Proxy,
    ) {
        // The free nodes are the inner `m × m` of the window's surface, node `(i, j)` at
        // `1 + i m + j` (`surface_node`); node `(i, j)` takes `(i, j) + d`'s state, which
        // is `d₀ m + d₁` slots on, or rest when that is the fixed ring. In the direction
        // of the shift, so that every source is read before it is overwritten.
        let m = window.n - 2;
        let offset = d[0] * m + d[1];
        let order = |s: i32, k: i32| if s > 0 { k } else { m - 1 - k };
        for ki in 0..m {
            let i = order(d[0], ki);
            let row_in = (0..m).contains(&(i + d[0]));
            for kj in 0..m {
                let j = order(d[1], kj);
                let slot = 1 + i * m + j;
                // Each path writes the node itself (a merged value would go through the
                // stack).
                let source = (row_in && (0..m).contains(&(j + d[1])))
                    .then(|| self.nodes.get((slot + offset) as usize))
                    .flatten();
                if let Some(&Node { u, v, .. }) = source {
                    if let Some(x) = self.nodes.get_mut(slot as usize) {
                        x.u = u;
                        x.v = v;
                    }
                } else if let Some(x) = self.nodes.get_mut(slot as usize) {
                    x.u = [0; 3];
                    x.v = [0; 3];
                }
            }
        }
        let dir = match d {
            [1, 0] => 0,
            [-1, 0] => 1,
            [0, 1] => 2,
            _ => 3,
        };
        if CAP && window.cap.is_some() {
            // The warm-start values move with the geometry, in place.
            self.shift_cap(window, d, dir);
        } else {
            let old = self.warm;
            for (e, w) in self.warm.iter_mut().enumerate() {
                let from = window.maps[dir].get(e).copied().unwrap_or(NONE);
                *w = old.get(continued(from).0).copied().unwrap_or(A::REST);
            }
        }
        proxy.shift_grid(d);
        window.corner = [window.corner[0] + d[0], window.corner[1] + d[1]];
        window.shifts = window.shifts.saturating_add(1);
    }

    /// A shift's part on a cap: the rest heights move with the window (the `n` entering
    /// ones computed), then the springs' rest geometry and warm-start values
    /// ([`Self::move_cap_springs`]).
    #[inline(never)]
    fn shift_cap<const CAP: bool>(
        &mut self,
        window: &mut Window<EDGES, CAP>,
        d: [i32; 2],
        dir: usize,
    ) {
        let n = window.n;
        let Some(cap) = window.cap else {
            return;
        };
        // Height `(a, b)` at `a n + b` takes `(a, b) + d`'s: whole rows move along x, each
        // row's heights along y, in the direction of the shift (every source is read
        // before it is overwritten); the entering row or column is the cap's. (Indexed
        // loops: `copy_within` would leave a panic path in the tick.)
        let nu = n.max(0) as usize;
        let nn = nu * nu;
        let h = &mut window.heights;
        let mut take = |to: usize, from: usize| {
            if let Some(&z) = h.get(from) {
                if let Some(slot) = h.get_mut(to) {
                    *slot = z;
                }
            }
        };
        match d {
            [1, 0] => (0..nn.saturating_sub(nu)).for_each(|i| take(i, i + nu)),
            [-1, 0] => (nu..nn).rev().for_each(|i| take(i, i - nu)),
            [0, 1] => (0..nn).step_by(nu.max(1)).for_each(|r| {
                (r..r + nu.saturating_sub(1)).for_each(|i| take(i, i + 1));
            }),
            _ => (0..nn).step_by(nu.max(1)).for_each(|r| {
                (r + 1..r + nu).rev().for_each(|i| take(i, i - 1));
            }),
        }
        for k in 0..n {
            let (a, b) = match d {
                [1, 0] => (n - 1, k),
                [-1, 0] => (0, k),
                [0, 1] => (k, n - 1),
                _ => (k, 0),
            };
            let z = cap.height(window.corner[0] + a + d[0], window.corner[1] + b + d[1]);
            if let Some(h) = window.heights.get_mut((a * n + b) as usize) {
                *h = z;
            }
        }
        self.set_cap_heights(window);
        self.move_cap_springs(window, dir);
    }
}

/// Where [`Solver::window_as`] puts a window, once its configuration is checked.
struct Placement {
    /// The patch's side, the tissue's width and height (nodes).
    n: usize,
    w: usize,
    h: usize,
    /// The spacing, mm and Q24 mm.
    s: f64,
    spacing: i32,
    /// The window's corner on the tissue (nodes).
    corner: [i32; 2],
    /// The shift threshold, Q16 spacings.
    limit: i32,
    /// The cap, if the tissue is one.
    cap: Option<Cap>,
}

/// The window's cap as the proxy sees it this tick (`None`: flat; always for a flat-only
/// window, so that its tick compiles without the cap's code).
pub(super) fn cap_frame<const EDGES: usize, const CAP: bool>(
    window: &Window<EDGES, CAP>,
) -> Option<CapFrame> {
    if !CAP {
        return None;
    }
    let origin = window.origin();
    window.cap.map(|cap| CapFrame { cap, origin })
}

/// A spring's rest geometry `(dir, 1/l0)` (Q23, Q31 per mm) on a cap from its packed
/// ends and the window's rest heights, in spacings so that every square fits `i64`: the
/// horizontal offsets are whole spacings, the vertical one `Δz/s` by a product by `1/s`;
/// `s/l0` by one reciprocal square root (within 2e-8).
fn edge_geometry<const EDGES: usize, const CAP: bool>(
    window: &Window<EDGES, CAP>,
    ends: u32,
) -> (V3, i32) {
    let [a, b] = unpack_ends(ends);
    // (da, db) = (0, 0): a vertical spring, from a surface node to the base node a
    // spacing straight below it (or the other way): its geometry is the flat patch's.
    if a[0] == b[0] && a[1] == b[1] {
        let down = if b[2] > a[2] { -1 } else { 1 };
        return ([0, 0, down << DIR_FRAC], window.inv_s.saturating_mul(2));
    }
    let z = |k: [i32; 3]| {
        let h = window
            .heights
            .get((k[0] * window.n + k[1]) as usize)
            .copied()
            .unwrap_or(0);
        h.saturating_sub(k[2].wrapping_mul(window.spacing))
    };
    // Offsets in spacings, Q28 (|Δz| ≤ 128 mm over s ≥ 1 mm: the squares sum within i64).
    // Every product is rounded to nearest, symmetrically: a spring computed from its
    // other end is its exact negation (a continued spring may run the other way), and
    // a unit direction's length stays within rounding of one (no strain at rest).
    let dz = z(b).saturating_sub(z(a));
    // The horizontal offsets are whole spacings (−1, 0 or 1): their squares are exact.
    let (da, db) = (b[0] - a[0], b[1] - a[1]);
    let ds_z = sat(round_shr(mul_wide(dz, window.inv_s), 26));
    let flat2 = ((da * da + db * db) as i64) << 56;
    let (y, e) = q::rsqrt(flat2 + mul_wide(ds_z, ds_z));
    // s/l0 = y 2^(e/2 − 34) (the sum is Q56), in Q30: y >> (4 − e/2); l0 ≥ s: e ≤ 6.
    let sl = round_shr(y as i64, 4u32.saturating_sub(e >> 1).max(1)) as i32;
    // 1/l0 = (s/l0)(1/s): Q30 · Q30 = Q60, Q31 after >> 29; 1 mm is held at i32::MAX.
    let inv_len = sat(round_shr(mul_wide(sl, window.inv_s), 29));
    // dir = (Δ/s)(s/l0): Q28 · Q30 = Q58, Q23 after >> 35 (a whole spacing: sl >> 7).
    let whole = |d: i32| d.wrapping_mul(round_shr(sl as i64, 7) as i32);
    let dir = [whole(da), whole(db), sat(round_shr(mul_wide(ds_z, sl), 35))];
    (dir, inv_len)
}

/// `x / 2^sh` rounded to nearest, halves away from zero (`sh` ≥ 1): odd in `x`.
fn round_shr(x: i64, sh: u32) -> i64 {
    let m = (x.unsigned_abs() + (1 << (sh - 1))) >> sh;
    if x < 0 {
        -(m as i64)
    } else {
        m as i64
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_patch::patch_and_proxy;
    use super::DIRECTIONS;
    use crate::window::{FLIP, NONE};
    use crate::ProxyError;
    use crate::{Arith, DefaultArith, Topology, WindowConfig};

    /// A cap's window moves its springs' geometry in place, which needs every spring's
    /// source on one side of it per direction (the standard patch's cell-by-cell order):
    /// the same patch with its springs in reverse order is refused on a cap (and still
    /// taken flat, where nothing moves in place).
    #[test]
    fn a_cap_refuses_springs_out_of_the_order_its_shift_needs() {
        let mut topo = Topology::<10, 61>::standard_patch(5, 2.5).unwrap();
        topo.reverse_edges();
        let (mut s, proxy) = patch_and_proxy(topo);
        let tissue = |cap_radius| WindowConfig {
            tissue_w: 16,
            tissue_h: 16,
            hysteresis: 0.1,
            cap_radius,
        };
        assert_eq!(
            s.shaped_window(&tissue(Some(60.0)), &proxy, 0.0, 0.0),
            Err(ProxyError::Grid)
        );
        assert!(s.shaped_window(&tissue(None), &proxy, 0.0, 0.0).is_ok());
    }

    /// A shift gives every spring that continues one the warm-start value of that one
    /// (whichever way it runs), and the others rest: for each direction, on a flat
    /// window and on a cap. Reversed springs exist in every direction. (The warm-start
    /// values are marked with their spring's index.)
    #[test]
    fn a_shift_carries_every_continued_springs_warm_start_value() {
        for cap_radius in [None, Some(60.0)] {
            for (dir, d) in DIRECTIONS.into_iter().enumerate() {
                let topo = Topology::<10, 61>::standard_patch(5, 2.5).unwrap();
                let (mut s, mut proxy) = patch_and_proxy(topo);
                let tissue = WindowConfig {
                    tissue_w: 16,
                    tissue_h: 16,
                    hysteresis: 0.1,
                    cap_radius,
                };
                let mut w = s.shaped_window(&tissue, &proxy, 0.0, 0.0).unwrap();
                for (e, x) in s.warm.iter_mut().enumerate() {
                    *x = 1000 + e as i32;
                }
                s.shift(&mut w, d, &mut proxy);
                let (mut carried, mut reversed) = (0, 0);
                for (e, &m) in w.maps[dir].iter().enumerate() {
                    if m == NONE {
                        assert_eq!(s.warm[e], <DefaultArith as Arith>::REST, "{d:?} {e}");
                    } else {
                        assert_eq!(s.warm[e], 1000 + (m & !FLIP) as i32, "{d:?} {e}");
                        carried += 1;
                        reversed += (m & FLIP != 0) as u32;
                    }
                }
                assert!(carried > 30 && reversed > 0, "{d:?}: {carried} {reversed}");
            }
        }
    }
}
