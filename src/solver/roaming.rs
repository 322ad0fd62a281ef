//! The solver's tick on a window onto a larger tissue ([`Window`]), flat or of another
//! [`Shape`], driven through a [`Proxy`]: the contact, the window's shift, the substeps.
//! The window's start-up is `solver/window.rs`; its own shift rules `crate::window`.

use super::step::tick_velocity;
use super::Solver;
use crate::arith::Arith;
use crate::proxy::{Frame, Proxy};
use crate::shape::Shape;
use crate::state::Node;
use crate::topology::Edge;
use crate::units::{Force, Length, Velocity};
use crate::window::{continued, Window, NONE};

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith> Solver<NODES, EDGES, S, A> {
    /// One haptic tick on the tissue with the probe at `probe` (mm, tissue frame)
    /// touching it through `proxy`; the window follows the contact (see [`Window`]).
    /// The probe's velocity is the one-tick difference of its positions. Returns the
    /// force the device must render (N).
    pub fn step_roaming<Sh: Shape>(
        &mut self,
        probe: [Length; 3],
        proxy: &mut Proxy,
        window: &mut Window<EDGES, Sh>,
    ) -> [Force; 3] {
        self.step_roaming_at(probe, None, proxy, window)
    }

    /// [`Solver::step_roaming`] with the probe's velocity given (mm/s, e.g. a
    /// [`crate::velocity::TrackedVelocity`]'s from quantised counts); `None`: the
    /// one-tick difference.
    #[inline(always)]
    pub fn step_roaming_at<Sh: Shape>(
        &mut self,
        probe: [Length; 3],
        velocity: Option<[Velocity; 3]>,
        proxy: &mut Proxy,
        window: &mut Window<EDGES, Sh>,
    ) -> [Force; 3] {
        // The probe in the patch frame whose origin is `o`.
        let in_frame = |o: [i32; 2]| {
            let p = probe.map(Length::to_bits);
            [p[0].saturating_sub(o[0]), p[1].saturating_sub(o[1]), p[2]]
        };
        let o = window.origin();
        let mut p = in_frame(o);
        let probe_vel = match velocity {
            Some(v) => v.map(Velocity::to_bits),
            None => tick_velocity(self.probe_prev, p, self.c.tick_hz),
        };
        let frame = Frame {
            shape: window.shape(),
            origin: o,
        };
        let tissue = window.tissue_rect(o);
        proxy.update(&self.view_in(proxy, window), &frame, p, tissue);
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
        let shape = window.shape();
        self.proxy_substeps(p, probe_vel, proxy, shape, shape.rest(window.heights()));
        self.device_force()
    }

    /// Moves the window one node along `d` (one axis) and the patch's state with it:
    /// node states, warm-start values (on a cap with the springs' rest geometry), the
    /// proxy's place.
    fn shift<Sh: Shape>(&mut self, window: &mut Window<EDGES, Sh>, d: [i32; 2], proxy: &mut Proxy) {
        // The free nodes are the inner `m × m` of the window's surface, node `(i, j)` at
        // `1 + i m + j` (`surface_node`); node `(i, j)` takes `(i, j) + d`'s state, which
        // is `d₀ m + d₁` slots on, or rest when that is the fixed ring. In the direction
        // of the shift, so that every source is read before it is overwritten.
        let m = window.side() - 2;
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
        window.advance(d);
        if window.shape().cap().is_some() {
            // The warm-start values move with the geometry, in place.
            self.follow_cap(window, dir);
        } else {
            let old = self.warm;
            let map = window.map(dir);
            for (e, w) in self.warm.iter_mut().enumerate() {
                let from = map.and_then(|m| m.get(e)).copied().unwrap_or(NONE);
                *w = old.get(continued(from).0).copied().unwrap_or(A::REST);
            }
        }
        proxy.shift_grid(d);
    }

    /// A shift's part on a cap, after the window moved along direction `dir` with its
    /// rest heights: the free nodes' rest heights, then each spring's rest geometry and
    /// warm-start value taken from the spring it continues (its direction negated if that
    /// one runs the other way), else the geometry computed from the window's rest heights
    /// and the value at rest. In place, in the order the window's start-up checked: every
    /// source is read before it is overwritten.
    #[inline(never)]
    fn follow_cap<Sh: Shape>(&mut self, window: &Window<EDGES, Sh>, dir: usize) {
        self.set_rest_heights(window);
        let Some(map) = window.map(dir) else {
            return;
        };
        let mut geometry = self.topo.rest_geometry();
        let count = geometry.edges().len();
        let warm = &mut self.warm;
        // The source spring is copied out before the edge is written; each path writes
        // the edge itself, so that a copy does not go through the computed path's memory.
        let mut step = |e: usize| {
            let (source, reversed) = continued(map.get(e).copied().unwrap_or(NONE));
            let value = warm.get(source).copied().unwrap_or(A::REST);
            if let Some(w) = warm.get_mut(e) {
                *w = value;
            }
            if let Some(&Edge { dir, inv_len, .. }) = geometry.edges().get(source) {
                let dir = if reversed {
                    dir.map(i32::saturating_neg)
                } else {
                    dir
                };
                geometry.set(e, dir, inv_len);
            } else {
                let (dir, inv_len) = window.spring_geometry(e);
                geometry.set(e, dir, inv_len);
            }
        };
        if dir.is_multiple_of(2) {
            (0..count).for_each(&mut step);
        } else {
            (0..count).rev().for_each(&mut step);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_patch::patch_and_proxy;
    use crate::shape::{Flat, Sphere};
    use crate::window::{DIRECTIONS, FLIP, NONE};
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
        let tissue = WindowConfig {
            tissue_w: 16,
            tissue_h: 16,
            hysteresis: 0.1,
        };
        let cap = Sphere { radius_mm: 60.0 };
        assert_eq!(
            s.window(&tissue, &cap, &proxy, 0.0, 0.0),
            Err(ProxyError::Grid)
        );
        assert!(s.window(&tissue, &Flat, &proxy, 0.0, 0.0).is_ok());
    }

    /// A shift gives every spring that continues one the warm-start value of that one
    /// (whichever way it runs), and the others rest: for each direction, on a flat
    /// window and on a cap. Reversed springs exist in every direction. (The warm-start
    /// values are marked with their spring's index.)
    #[test]
    fn a_shift_carries_every_continued_springs_warm_start_value() {
        fn check<Sh: crate::shape::ShapeSpec>(shape: Sh) {
            for (dir, d) in DIRECTIONS.into_iter().enumerate() {
                let topo = Topology::<10, 61>::standard_patch(5, 2.5).unwrap();
                let (mut s, mut proxy) = patch_and_proxy(topo);
                let tissue = WindowConfig {
                    tissue_w: 16,
                    tissue_h: 16,
                    hysteresis: 0.1,
                };
                let mut w = s.window(&tissue, &shape, &proxy, 0.0, 0.0).unwrap();
                for (e, x) in s.warm.iter_mut().enumerate() {
                    *x = 1000 + e as i32;
                }
                s.shift(&mut w, d, &mut proxy);
                let (mut carried, mut reversed) = (0, 0);
                for (e, &m) in w.map(dir).unwrap().iter().enumerate() {
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
        check(Flat);
        check(Sphere { radius_mm: 60.0 });
    }
}
