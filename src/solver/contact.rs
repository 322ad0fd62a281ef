//! The solver driven through a [`Proxy`] on its surface (issue #19): the standard patch's
//! surface nodes as the proxy sees them, and the tick.

use super::step::tick_velocity;
use super::Solver;
use crate::arith::Arith;
use crate::proxy::{Proxy, ProxyConfig, ProxyError, Surface};
use crate::q::{self, V3};
use crate::topology::surface_node;
use crate::units::{from_f64, Force, Length, LEN_FRAC};

/// The standard patch's surface as a proxy reads it: node `(a, b)` of the `n × n` grid,
/// the outer ring at rest.
pub(super) struct View<'a, const NODES: usize, const EDGES: usize, const S: usize, A: Arith> {
    solver: &'a Solver<NODES, EDGES, S, A>,
    n: usize,
    /// Spacing, Q24 mm.
    spacing: i32,
}

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith>
    View<'_, NODES, EDGES, S, A>
{
    /// The node of surface point `(a, b)`, `None` on the ring.
    fn node(&self, a: usize, b: usize) -> Option<usize> {
        surface_node(self.n, a as i32, b as i32)
    }

    /// A ring node's rest `x` and `y` (Q24 mm, patch frame): within the patch's ±100 mm
    /// (`Proxy::new` checks `(n/2) s` ≤ 100 mm), so the products fit `i32` (no
    /// saturating product: on the M0 that is a 64-bit one, six per surface point).
    #[inline(always)]
    fn ring_xy(&self, a: usize, b: usize) -> [i32; 2] {
        let c = (self.n / 2) as i32;
        [
            (a as i32 - c).wrapping_mul(self.spacing),
            (b as i32 - c).wrapping_mul(self.spacing),
        ]
    }
}

/// A window's surface over a cap as the proxy reads it: the ring's rest heights from the
/// window's (the free nodes' rest positions are the topology's, moved with the window).
pub(super) struct CapView<'a, const NODES: usize, const EDGES: usize, const S: usize, A: Arith> {
    view: View<'a, NODES, EDGES, S, A>,
    heights: &'a [i32; EDGES],
}

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith> Surface
    for CapView<'_, NODES, EDGES, S, A>
{
    fn position(&self, a: usize, b: usize) -> V3 {
        match self.view.node(a, b) {
            Some(_) => self.view.position(a, b),
            None => {
                let [x, y] = self.view.ring_xy(a, b);
                [x, y, self.rest_z(a, b)]
            }
        }
    }

    fn velocity(&self, a: usize, b: usize) -> V3 {
        self.view.velocity(a, b)
    }

    fn rest_z(&self, a: usize, b: usize) -> i32 {
        self.heights.get(a * self.view.n + b).copied().unwrap_or(0)
    }
}

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith> Surface
    for View<'_, NODES, EDGES, S, A>
{
    fn position(&self, a: usize, b: usize) -> V3 {
        let ring = || {
            let [x, y] = self.ring_xy(a, b);
            [x, y, 0]
        };
        match self.node(a, b) {
            Some(i) => {
                let rest = self.solver.topo.rest_q24(i).unwrap_or_else(ring);
                let u = self.solver.node_disp(i);
                core::array::from_fn(|k| rest[k].saturating_add(u[k]))
            }
            None => ring(),
        }
    }

    fn velocity(&self, a: usize, b: usize) -> V3 {
        self.node(a, b).map_or([0; 3], |i| self.solver.node_vel(i))
    }
}

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith> Solver<NODES, EDGES, S, A> {
    /// A proxy for this solver's patch, which must be the standard patch of `config`'s grid
    /// and spacing (its node count and its first free node's rest position are checked).
    pub fn proxy(&self, config: &ProxyConfig) -> Result<Proxy, ProxyError> {
        let proxy = Proxy::new(config)?;
        let n = config.grid;
        let c = (n / 2) as f64;
        let first = [(1.0 - c) * config.spacing, (1.0 - c) * config.spacing, 0.0];
        let matches = self.topo.node_count() == (n - 2) * (n - 2) + 1
            && self.topo.rest_q24(1) == Some(first.map(|x| from_f64(x, LEN_FRAC)));
        if matches {
            Ok(proxy)
        } else {
            Err(ProxyError::Grid)
        }
    }

    pub(super) fn view(&self, proxy: &Proxy) -> View<'_, NODES, EDGES, S, A> {
        let (n, spacing) = proxy.grid();
        View {
            solver: self,
            n,
            spacing,
        }
    }

    /// A window's surface over a cap.
    pub(super) fn cap_view<'a, const CAP: bool>(
        &'a self,
        proxy: &Proxy,
        window: &'a crate::window::Window<EDGES, CAP>,
    ) -> CapView<'a, NODES, EDGES, S, A> {
        CapView {
            view: self.view(proxy),
            heights: &window.heights,
        }
    }

    /// The proxy's centre (mm, patch frame) on the current surface, when in contact.
    pub fn proxy_point(&self, proxy: &Proxy) -> Option<[Length; 3]> {
        proxy
            .centre_at(&self.view(proxy))
            .map(|p| p.map(Length::from_bits))
    }

    /// The proxy's centre (mm, patch frame) on a window's current surface (flat or a
    /// cap), when in contact.
    pub fn proxy_point_in<const CAP: bool>(
        &self,
        proxy: &Proxy,
        window: &crate::window::Window<EDGES, CAP>,
    ) -> Option<[Length; 3]> {
        match super::roaming::cap_frame(window) {
            None => self.proxy_point(proxy),
            Some(f) => proxy
                .centre_cap_at(&self.cap_view(proxy, window), &f)
                .map(|p| p.map(Length::from_bits)),
        }
    }

    /// One haptic tick with the probe at `probe` (mm, patch frame) touching the surface
    /// through `proxy` (from [`Solver::proxy`]): the proxy's contact and friction once,
    /// then the substeps with the coupling between probe and proxy. Returns the force the
    /// device must render (N, held to the coupling's maximum in magnitude).
    pub fn step_proxy(&mut self, probe: [Length; 3], proxy: &mut Proxy) -> [Force; 3] {
        let p = probe.map(Length::to_bits);
        let probe_vel = tick_velocity(self.probe_prev, p, self.c.tick_hz);
        self.probe_prev = p;
        proxy.update(&self.view(proxy), p);
        self.proxy_substeps(p, probe_vel, proxy);
        self.device_force()
    }

    /// The tick's substeps with the probe at `p` (Q24 mm, patch frame) moving at
    /// `probe_vel` (Q16 mm/s), coupled to `proxy`.
    pub(super) fn proxy_substeps(&mut self, p: V3, probe_vel: V3, proxy: &Proxy) {
        self.coupled_substeps(proxy, |s| {
            proxy.force(&s.view(proxy), &s.c.coupling, p, probe_vel)
        });
    }

    /// [`Self::proxy_substeps`] on a cap.
    pub(super) fn proxy_substeps_cap<const CAP: bool>(
        &mut self,
        p: V3,
        probe_vel: V3,
        proxy: &Proxy,
        window: &crate::window::Window<EDGES, CAP>,
    ) {
        self.coupled_substeps(proxy, |s| {
            proxy.force_cap(&s.cap_view(proxy, window), &s.c.coupling, p, probe_vel)
        });
    }

    /// The tick's substeps, the proxy's coupling force (Q20 N, its triangle and weights)
    /// from `force` in each.
    #[inline(always)]
    fn coupled_substeps(
        &mut self,
        proxy: &Proxy,
        force: impl Fn(&Self) -> (V3, [(usize, usize); 3], [i32; 3]),
    ) {
        // The glued substep's two calls, written out again: shared through helpers they
        // changed the glued path's compiled code (the M3's N = 7 substep by 4 %).
        let count = self.topo.node_count().min(NODES);
        for _ in 0..self.substeps {
            A::spring_forces(
                &self.table,
                &self.c.arith,
                &self.topo,
                &mut self.warm,
                &mut self.nodes,
            );
            let (f, corners, w) = force(self);
            self.react(proxy, f, corners, w);
            if let Some(free) = self.nodes.get_mut(1..count) {
                A::integrate(&self.c.arith, free);
            }
        }
    }

    /// The force `f` (Q20 N) of the proxy on the tissue through its triangle `corners`
    /// with weights `w`: minus it onto the free corners, kept as the coupling force.
    #[inline(always)]
    fn react(&mut self, proxy: &Proxy, f: V3, corners: [(usize, usize); 3], w: [i32; 3]) {
        let view = self.view(proxy);
        let nodes = corners.map(|(a, b)| view.node(a, b));
        for (node, w) in nodes.into_iter().zip(w) {
            if let Some(n) = node.and_then(|i| self.nodes.get_mut(i)) {
                for k in 0..3 {
                    n.f[k] = n.f[k].saturating_sub(q::mul_weight(f[k], w));
                }
            }
        }
        self.coupling_force = f.map(i32::saturating_neg);
    }
}
