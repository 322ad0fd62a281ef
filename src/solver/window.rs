//! A window of the solver's patch onto a larger tissue (start-up): the configuration
//! checked, the window placed, its shape's rest geometry given to the patch.

use super::Solver;
use crate::arith::Arith;
use crate::proxy::{Proxy, ProxyError};
use crate::shape::{Shape, ShapeSpec};
use crate::topology::{surface_node, Edge, GROUND};
use crate::units::{from_f64, to_f64, DIR_FRAC, LEN_FRAC};
use crate::window::{Key, Placement, Window, WindowConfig};

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith> Solver<NODES, EDGES, S, A> {
    /// A window of this solver's patch onto a tissue of `config`'s size and `shape`
    /// ([`crate::shape::Flat`], or a [`crate::shape::Sphere`]), centred on the tissue
    /// node nearest `(x, y)` (mm, tissue frame: origin at its centre), for a proxy from
    /// [`Solver::proxy`] (start-up: the maps take `4 E²` comparisons). On a cap the patch
    /// takes the window's rest geometry (its substeps and [`crate::ParamSet`] fingerprint
    /// stay the flat patch's: the cap's springs are no shorter, so no stiffer). The
    /// window's type names its shape: a flat window's tick carries no cap code.
    #[inline(never)]
    pub fn window<Spec: ShapeSpec>(
        &mut self,
        config: &WindowConfig,
        shape: &Spec,
        proxy: &Proxy,
        x: f64,
        y: f64,
    ) -> Result<Window<EDGES, Spec::Shape>, ProxyError> {
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
        let shape = shape
            .shape(w, h, s, A::MAX_REST_LENGTH_MM)
            .ok_or(ProxyError::Cap)?;
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
        };
        self.build_window(&place, shape)
    }

    /// The window [`Solver::window`] checked and placed, and on a cap the patch's rest
    /// heights and springs' geometry from it (start-up).
    ///
    /// Apart from the checks, so that this function's large frame (where every spring's
    /// ends are: some 36 KiB on a host's N = 9 patch) is set up on entry, before a value
    /// of theirs is live: an x86-64 release build's stack probe of that frame clobbered
    /// one otherwise (`docs/experiments/roaming.md`; `scripts/long.sh` checks a release build).
    #[inline(never)]
    fn build_window<Sh: Shape>(
        &mut self,
        place: &Placement,
        shape: Sh,
    ) -> Result<Window<EDGES, Sh>, ProxyError> {
        let count = self.topo.edges().len().min(EDGES);
        let mut keys: [[Key; 2]; EDGES] = [[[-9; 3]; 2]; EDGES];
        for (key, edge) in keys.iter_mut().zip(self.topo.edges()) {
            *key = self.keys(edge, place.n, place.s).ok_or(ProxyError::Grid)?;
        }
        let window = Window::at(place, shape, &keys, count)?;
        if window.shape().cap().is_some() {
            self.set_rest_heights(&window);
            let mut geometry = self.topo.rest_geometry();
            for e in 0..count {
                let (dir, inv_len) = window.spring_geometry(e);
                geometry.set(e, dir, inv_len);
            }
        }
        Ok(window)
    }

    /// The free nodes' rest heights from the window's (on a cap).
    pub(super) fn set_rest_heights<Sh: Shape>(&mut self, window: &Window<EDGES, Sh>) {
        let n = window.side();
        for a in 1..n - 1 {
            for b in 1..n - 1 {
                if let Some(i) = surface_node(n as usize, a, b) {
                    self.topo.set_rest_z(i, window.rest_height(a, b));
                }
            }
        }
    }

    /// Where an edge's two ends are on the grid (start-up; `None`: an end the topology
    /// does not hold, a logic error): the base end of a vertical spring is the one fixed
    /// end straight below its free end (on a cap too, where a surface node may lie deeper
    /// than `s/2`).
    fn keys(&self, e: &Edge, n: usize, s: f64) -> Option<[Key; 2]> {
        let c = (n / 2) as f64;
        let key = |p: [f64; 3]| -> [i32; 2] {
            [
                libm::round(p[0] / s + c) as i32,
                libm::round(p[1] / s + c) as i32,
            ]
        };
        let a = self.topo.rest(e.a)?;
        let b = if e.b == GROUND {
            let l0 = crate::topology::Topology::<NODES, EDGES>::rest_length(e);
            core::array::from_fn(|k| a[k] + to_f64(e.dir[k], DIR_FRAC) * l0)
        } else {
            self.topo.rest(e.b)?
        };
        let (ka, kb) = (key(a), key(b));
        let base = e.b == GROUND && ka == kb;
        Some([[ka[0], ka[1], 0], [kb[0], kb[1], base as i32]])
    }
}
