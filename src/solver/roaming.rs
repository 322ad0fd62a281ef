//! The solver as a window onto a larger flat tissue ([`Window`]), driven through a
//! [`Proxy`]: the window's start-up maps, its shifts, and the tick.

use super::step::tick_velocity;
use super::Solver;
use crate::arith::Arith;
use crate::proxy::{Proxy, ProxyError};
use crate::q::V3;
use crate::topology::{surface_node, Edge, GROUND};
use crate::units::{from_f64, to_f64, Force, Length, DIR_FRAC, LEN_FRAC};
use crate::window::{Window, WindowConfig, NONE};

/// Where a spring's end is on the patch's grid: `(a, b, layer)` (layer 1: the base).
type Key = [i32; 3];

/// The shift directions, in the order of [`Window`]'s maps.
const DIRECTIONS: [[i32; 2]; 4] = [[1, 0], [-1, 0], [0, 1], [0, -1]];

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith> Solver<NODES, EDGES, S, A> {
    /// A window of this solver's patch onto a flat tissue of `config`'s size, centred on
    /// the tissue node nearest `(x, y)` (mm, tissue frame: origin at its centre), for a
    /// proxy from [`Solver::proxy`] (start-up: the maps take `4 E²` comparisons).
    pub fn window(
        &self,
        config: &WindowConfig,
        proxy: &Proxy,
        x: f64,
        y: f64,
    ) -> Result<Window<EDGES>, ProxyError> {
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
        let corner = |p: f64, side: usize| {
            let u = libm::round(p / s + (side - 1) as f64 / 2.0) - (n / 2) as f64;
            u.clamp(0.0, (side - n) as f64) as i32
        };
        let keys: [[Key; 2]; EDGES] = core::array::from_fn(|e| {
            self.topo
                .edges()
                .get(e)
                .map_or([[-9; 3]; 2], |edge| self.keys(edge, n, s))
        });
        let count = self.topo.edges().len().min(EDGES);
        let maps = DIRECTIONS.map(|d| {
            core::array::from_fn(|e| {
                if e >= count {
                    return NONE;
                }
                let moved = keys[e].map(|k| [k[0] + d[0], k[1] + d[1], k[2]]);
                (0..count)
                    .find(|&o| {
                        let k = keys[o];
                        (k[0] == moved[0] && k[1] == moved[1])
                            || (k[0] == moved[1] && k[1] == moved[0])
                    })
                    .map_or(NONE, |o| o as u16)
            })
        });
        Ok(Window {
            n: n as i32,
            w: w as i32,
            h: h as i32,
            corner: [corner(x, w), corner(y, h)],
            limit: from_f64(0.5 + config.hysteresis, 16),
            spacing,
            maps,
            shifts: 0,
        })
    }

    /// Where an edge's two ends are on the grid (start-up).
    fn keys(&self, e: &Edge, n: usize, s: f64) -> [Key; 2] {
        let c = (n / 2) as f64;
        let key = |p: [f64; 3]| -> Key {
            [
                libm::round(p[0] / s + c) as i32,
                libm::round(p[1] / s + c) as i32,
                (p[2] < -s / 2.0) as i32,
            ]
        };
        let a = self.topo.rest(e.a).unwrap_or([0.0; 3]);
        let b = if e.b == GROUND {
            let l0 = crate::topology::Topology::<NODES, EDGES>::rest_length(e);
            core::array::from_fn(|k| a[k] + to_f64(e.dir[k], DIR_FRAC) * l0)
        } else {
            self.topo.rest(e.b).unwrap_or([0.0; 3])
        };
        [key(a), key(b)]
    }

    /// One haptic tick on the tissue with the probe at `probe` (mm, tissue frame)
    /// touching it through `proxy`; the window follows the contact (see [`Window`]).
    /// Returns the force the device must render (N).
    pub fn step_roaming(
        &mut self,
        probe: [Length; 3],
        proxy: &mut Proxy,
        window: &mut Window<EDGES>,
    ) -> [Force; 3] {
        let in_window = |w: &Window<EDGES>| {
            let o = w.origin();
            let p = probe.map(Length::to_bits);
            [p[0].saturating_sub(o[0]), p[1].saturating_sub(o[1]), p[2]]
        };
        let mut p = in_window(window);
        let probe_vel = tick_velocity(self.probe_prev, p, self.c.tick_hz);
        proxy.update(&self.view(proxy), p);
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
            p = in_window(window);
        }
        self.probe_prev = p;
        self.proxy_substeps(p, probe_vel, proxy);
        self.device_force()
    }

    /// Moves the window one node along `d` (one axis): node states, warm-start values,
    /// the proxy's place.
    fn shift(&mut self, window: &mut Window<EDGES>, d: [i32; 2], proxy: &mut Proxy) {
        let n = window.n;
        let node = |a: i32, b: i32| surface_node(n as usize, a, b);
        // In the direction of the shift, so that every source is read before it is
        // overwritten.
        let order = |s: i32, k: i32| if s > 0 { k } else { n - 1 - k };
        for ka in 0..n {
            for kb in 0..n {
                let (a, b) = (order(d[0], ka), order(d[1], kb));
                let Some(i) = node(a, b) else {
                    continue;
                };
                let (u, v): (V3, V3) = node(a + d[0], b + d[1])
                    .and_then(|j| self.nodes.get(j))
                    .map_or(([0; 3], [0; 3]), |x| (x.u, x.v));
                if let Some(x) = self.nodes.get_mut(i) {
                    x.u = u;
                    x.v = v;
                }
            }
        }
        let dir = match d {
            [1, 0] => 0,
            [-1, 0] => 1,
            [0, 1] => 2,
            _ => 3,
        };
        let old = self.warm;
        for (e, w) in self.warm.iter_mut().enumerate() {
            let from = window.maps[dir].get(e).copied().unwrap_or(NONE);
            *w = old.get(from as usize).copied().unwrap_or(A::REST);
        }
        proxy.shift_grid(d);
        window.corner = [window.corner[0] + d[0], window.corner[1] + d[1]];
        window.shifts = window.shifts.saturating_add(1);
    }
}
