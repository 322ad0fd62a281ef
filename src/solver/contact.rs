//! The solver driven through a [`Proxy`] on its surface: the standard patch's surface
//! nodes as the proxy sees them (its ring at the rest heights of the tissue's shape), and
//! the tick.

use super::step::tick_velocity;
use super::Solver;
use crate::arith::Arith;
use crate::proxy::{Frame, Proxy, ProxyConfig, ProxyError, Surface};
use crate::q::{self, V3};
use crate::shape::{Flat, Level, RestHeights, Shape};
use crate::topology::surface_node;
use crate::units::{from_f64, Force, Length, LEN_FRAC};
use crate::window::Window;

/// The standard patch's surface as a proxy reads it: node `(a, b)` of the `n × n` grid,
/// the outer ring at rest at the rest heights `H` of the tissue's shape (a flat tissue's:
/// zero, a constant; the free nodes' rest positions are the topology's, moved with a
/// window over a cap).
pub(super) struct View<
    'a,
    const NODES: usize,
    const EDGES: usize,
    const S: usize,
    A: Arith,
    H: RestHeights = Level,
> {
    solver: &'a Solver<NODES, EDGES, S, A>,
    n: usize,
    /// Spacing, Q24 mm.
    spacing: i32,
    heights: H,
}

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith, H: RestHeights>
    View<'_, NODES, EDGES, S, A, H>
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

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith, H: RestHeights> Surface
    for View<'_, NODES, EDGES, S, A, H>
{
    fn position(&self, a: usize, b: usize) -> V3 {
        let ring = || {
            let [x, y] = self.ring_xy(a, b);
            [x, y, self.rest_z(a, b)]
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

    #[inline(always)]
    fn rest_z(&self, a: usize, b: usize) -> i32 {
        self.heights.z(a * self.n + b)
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

    /// The patch's surface, its ring flat.
    #[inline(always)]
    pub(super) fn view(&self, proxy: &Proxy) -> View<'_, NODES, EDGES, S, A> {
        let (n, spacing) = proxy.grid();
        View {
            solver: self,
            n,
            spacing,
            heights: Level,
        }
    }

    /// A window's surface: its ring at the rest heights of the window's shape.
    #[inline(always)]
    pub(super) fn view_in<'a, Sh: Shape>(
        &'a self,
        proxy: &Proxy,
        window: &'a Window<EDGES, Sh>,
    ) -> View<'a, NODES, EDGES, S, A, Sh::Rest<'a>> {
        let (n, spacing) = proxy.grid();
        View {
            solver: self,
            n,
            spacing,
            heights: window.shape().rest(window.heights()),
        }
    }

    /// The proxy's centre (mm, patch frame) on the current surface, when in contact.
    pub fn proxy_point(&self, proxy: &Proxy) -> Option<[Length; 3]> {
        proxy
            .centre_at(&self.view(proxy))
            .map(|p| p.map(Length::from_bits))
    }

    /// The proxy's centre (mm, patch frame) on a window's current surface, when in
    /// contact.
    pub fn proxy_point_in<Sh: Shape>(
        &self,
        proxy: &Proxy,
        window: &Window<EDGES, Sh>,
    ) -> Option<[Length; 3]> {
        let frame = Frame {
            shape: window.shape(),
            origin: window.origin(),
        };
        proxy
            .centre_in(&self.view_in(proxy, window), &frame)
            .map(|p| p.map(Length::from_bits))
    }

    /// One haptic tick with the probe at `probe` (mm, patch frame) touching the surface
    /// through `proxy` (from [`Solver::proxy`]): the proxy's contact and friction once,
    /// then the substeps with the coupling between probe and proxy. Returns the force the
    /// device must render (N, held to the coupling's maximum in magnitude).
    pub fn step_proxy(&mut self, probe: [Length; 3], proxy: &mut Proxy) -> [Force; 3] {
        let p = probe.map(Length::to_bits);
        let probe_vel = tick_velocity(self.probe_prev, p, self.c.tick_hz);
        self.probe_prev = p;
        // Past the patch's edge, the goal is the point above the nearest point of it.
        let flat = Frame {
            shape: &Flat,
            origin: [0; 2],
        };
        proxy.update(&self.view(proxy), &flat, p, proxy.patch_rect());
        self.proxy_substeps(p, probe_vel, proxy, &Flat, Level);
        self.device_force()
    }

    /// The tick's substeps on a tissue of `shape` with the rest heights `heights`, the
    /// probe at `p` (Q24 mm, patch frame) moving at `probe_vel` (Q16 mm/s), coupled to
    /// `proxy` (one function for a patch alone and a flat window).
    pub(super) fn proxy_substeps<Sh: Shape, H: RestHeights + Copy>(
        &mut self,
        p: V3,
        probe_vel: V3,
        proxy: &Proxy,
        shape: &Sh,
        heights: H,
    ) {
        let (n, spacing) = proxy.grid();
        self.coupled_substeps(proxy, |s| {
            let view = View {
                solver: s,
                n,
                spacing,
                heights,
            };
            proxy.force(&view, shape, &s.c.coupling, p, probe_vel)
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
        // The glued substep's two calls, written out again: shared through helpers, they
        // change the glued path's compiled code (its registers).
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
        let shares = reaction_shares(f, w);
        for (node, share) in nodes.into_iter().zip(shares) {
            if let Some(n) = node.and_then(|i| self.nodes.get_mut(i)) {
                for k in 0..3 {
                    n.f[k] = n.f[k].saturating_sub(share[k]);
                }
            }
        }
        self.coupling_force = f.map(i32::saturating_neg);
    }
}

/// The corners' shares of a contact force `f` (Q20 N, within the device maximum) by
/// weights `w` (Q16, summing to one): the last two by product ([`q::mul_weight`]), the
/// first the rest, so that the three sum to `f` exactly (three rounded products could
/// miss it by two units of the last place).
#[inline(always)]
pub(crate) fn reaction_shares(f: V3, w: [i32; 3]) -> [V3; 3] {
    let s1 = f.map(|x| q::mul_weight(x, w[1]));
    let s2 = f.map(|x| q::mul_weight(x, w[2]));
    let s0 = core::array::from_fn(|k| f[k].saturating_sub(s1[k]).saturating_sub(s2[k]));
    [s0, s1, s2]
}

#[cfg(test)]
mod tests {
    use super::super::test_patch::patch_and_proxy;
    use super::reaction_shares;
    use crate::{SolverConfig, Topology};

    /// A small linear congruential generator: the tests' forces.
    fn lcg(state: &mut u64) -> i32 {
        *state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (*state >> 32) as i32
    }

    /// The three shares of any force (the whole `i32` range) by any weights summing to
    /// one sum to the force exactly.
    #[test]
    fn the_shares_sum_to_the_force_exactly() {
        let mut state = 7;
        let edges = [i32::MIN, i32::MIN + 1, -1, 0, 1, i32::MAX - 1, i32::MAX];
        for t in 0..200_000 {
            let f = if t < 49 {
                [edges[t % 7], edges[t / 7], 12345]
            } else {
                [lcg(&mut state), lcg(&mut state) >> 8, lcg(&mut state) >> 20]
            };
            let a = (lcg(&mut state) as u32 >> 15) as i32; // 0 … 2¹⁷
            let (w1, w2) = (a.min(1 << 16), (lcg(&mut state) as u32 >> 16) as i32);
            let w2 = w2.min((1 << 16) - w1);
            let w = [(1 << 16) - w1 - w2, w1, w2];
            let s = reaction_shares(f, w);
            for k in 0..3 {
                let sum = s[0][k] as i64 + s[1][k] as i64 + s[2][k] as i64;
                assert_eq!(sum, f[k] as i64, "f {f:?} w {w:?}: shares {s:?}");
            }
        }
    }

    /// Through the solver: a contact force on an inner triangle (every corner free), at
    /// grid points across a cell, its edges and its corners, leaves minus itself on the
    /// nodes, to the bit.
    #[test]
    fn the_node_forces_of_a_contact_sum_to_minus_its_force() {
        let topo = Topology::<10, 61>::standard_patch(5, 2.5).unwrap();
        let (mut s, proxy) = patch_and_proxy(topo);
        let mut state = 11;
        let limit = (SolverConfig::default().coupling.max_force * (1 << 20) as f64) as i32;
        // Grid points (Q16) over the inner cells, every 1/64 spacing (on their edges and
        // corners too) plus a random fraction.
        for a in 64..192 {
            for b in 64..192 {
                let jitter =
                    |s: &mut u64| (lcg(s) as u32 >> 22) as i32 & if a % 7 == 0 { 0 } else { 1023 };
                let g = [
                    (a << 10) + jitter(&mut state),
                    (b << 10) + jitter(&mut state),
                ];
                let (corners, w) = proxy.triangle(g);
                let f = [0; 3].map(|_| lcg(&mut state) % limit);
                s.nodes.iter_mut().for_each(|n| n.f = [0; 3]);
                s.react(&proxy, f, corners, w);
                let free = corners
                    .iter()
                    .filter(|&&(i, j)| (1..4).contains(&i) && (1..4).contains(&j));
                assert_eq!(free.count(), 3, "{g:?}: {corners:?}");
                for k in 0..3 {
                    let sum: i64 = s.nodes.iter().map(|n| n.f[k] as i64).sum();
                    assert_eq!(sum, -(f[k] as i64), "{g:?} {w:?}: axis {k}");
                }
            }
        }
    }
}
