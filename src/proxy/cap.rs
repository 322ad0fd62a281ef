//! The proxy on a cap ([`crate::shape::Cap`]): the flat contact's model with depth, friction
//! cone and damping along the cap's rest normal instead of `z`, as the `f64` reference
//! (`mccs_host::roam`) has them.
//!
//! - The goal is the deformed surface's point on the cap's radial line through the probe
//!   (from where that line meets the rest cap, three corrections along it by the
//!   deformed surface's offset; the normal `n` of that line), plus `r n'` with `n'` the
//!   rest normal under the goal; the probe is in contact while `n' · (goal − probe) > 0`.
//! - The friction cone is measured across `n'`: the proxy's offset from the goal less its
//!   part along `n'`, against `μ` times the proxy's own depth along `n'`; a slip moves it
//!   within that plane onto the cone, then back onto the surface along the goal's radial
//!   line.
//! - The coupling's damping acts along the rest normal under the proxy, and the force is
//!   unilateral along it.
//!
//! The rest normal is the cap's at the rest point of the proxy's grid position (its
//! height blended from the triangle's corners: a unit vector to within the chord's sag,
//! `s²/(8R²)`).

use super::force::{damping, held, scale_to, spring};
use super::{Proxy, Surface, G_FRAC};
use crate::coupling::CouplingQ;
use crate::q::{self, mul_wide, sat, V3};
use crate::shape::{Cap, N16_SH};

/// The cap as a proxy sees it in one tick: the cap, and the patch frame's origin in the
/// tissue frame (Q24 mm, `x` and `y`; the frames share `z`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct CapFrame {
    /// The tissue's cap.
    pub cap: Cap,
    /// The patch frame's origin.
    pub origin: [i32; 2],
}

/// Corrections of the goal's surface point along its radial line (from where the line
/// meets the rest cap): two leave 1.7e-2 of the force against the reference on the
/// palpations of `host-tests/tests/cap.rs`, three 7.2e-3, four no better.
const LOCATE_STEPS: usize = 3;
/// Corrections of a slip's surface point (from where the proxy was, close by).
const SLIP_STEPS: usize = 2;

/// `a · n` for a Q24 vector and a direction from [`crate::shape::Cap`] (Q29 on a Q15 grid),
/// Q24: one product with a 16-bit operand per axis, floored.
fn dot(a: V3, n: V3) -> i32 {
    let p = |k: usize| q::mul_s::<15>(a[k], n[k] >> N16_SH);
    p(0).saturating_add(p(1)).saturating_add(p(2))
}

/// `x n` for a Q24 length and a direction from [`crate::shape::Cap`], Q24, floored.
fn along(x: i32, n: V3) -> V3 {
    n.map(|c| q::mul_s::<15>(x, c >> N16_SH))
}

fn sub(a: V3, b: V3) -> V3 {
    [
        a[0].saturating_sub(b[0]),
        a[1].saturating_sub(b[1]),
        a[2].saturating_sub(b[2]),
    ]
}

impl Proxy {
    /// The cap's rest normal (Q29) at grid `g`'s rest point.
    fn rest_normal(&self, s: &impl Surface, f: &CapFrame, g: [i32; 2]) -> V3 {
        let (c, w) = self.triangle(g);
        let z = Self::blend1(w, c.map(|(a, b)| s.rest_z(a, b)));
        let top = (self.n - 1) << G_FRAC;
        let centre = (self.n / 2) << G_FRAC;
        // (u − n/2) s, Q16 · Q24 >> 16, plus the origin: the tissue frame.
        let at = |u: i32, o: i32| {
            sat(mul_wide(u.max(0).min(top) - centre, self.spacing) >> G_FRAC).saturating_add(o)
        };
        f.cap
            .normal([at(g[0], f.origin[0]), at(g[1], f.origin[1]), z])
    }

    /// The proxy's centre for grid `g` on a cap (the surface point plus `r` along the
    /// rest normal), and that normal.
    fn centre_cap(&self, s: &impl Surface, f: &CapFrame, g: [i32; 2]) -> (V3, V3) {
        let n = self.rest_normal(s, f, g);
        (q::add(self.point(s, g), along(self.radius, n)), n)
    }

    /// The proxy's centre on the current surface of a cap (Q24 mm), when in contact.
    pub(super) fn centre_cap_at(&self, s: &impl Surface, f: &CapFrame) -> Option<V3> {
        self.at.map(|g| self.centre_cap(s, f, g).0)
    }

    /// The grid position of the deformed surface's point on the cap's radial line
    /// through `p` (patch frame, Q24 mm), whether it was held to the patch (the line
    /// meets the surface beyond it), that line's direction (Q29), and where it meets the
    /// rest cap (patch frame `xy`).
    fn locate_cap(&self, s: &impl Surface, f: &CapFrame, p: V3) -> ([i32; 2], bool, V3, [i32; 2]) {
        let n = f.cap.radial([
            p[0].saturating_add(f.origin[0]),
            p[1].saturating_add(f.origin[1]),
            p[2],
        ]);
        // Where the line meets the rest cap: R n from the cap's centre (R Q20 · n Q29 is
        // Q49: Q24 after >> 25), in the patch frame.
        let r = f.cap.radius_q20();
        let on_cap = |k: usize| sat(mul_wide(r, n[k]) >> 25).saturating_sub(f.origin[k]);
        let start = self.rest_grid(on_cap(0), on_cap(1));
        let (g, held) = self.locate_along(s, p, n, start, LOCATE_STEPS);
        (g, held, n, [on_cap(0), on_cap(1)])
    }

    /// The grid position of the deformed surface's point on the line through `p` along
    /// `n` (Q29), from grid position `start` near it: `steps` corrections, each by the
    /// offset between that line and the surface point there; held to the patch, and
    /// whether it was.
    fn locate_along(
        &self,
        s: &impl Surface,
        p: V3,
        n: V3,
        start: [i32; 2],
        steps: usize,
    ) -> ([i32; 2], bool) {
        let mut g = start;
        for _ in 0..steps {
            let sp = self.point(s, g);
            let t = dot(sub(sp, p), n);
            let target = q::add(p, along(t, n));
            g = [
                g[0].saturating_add(self.spacings(target[0].saturating_sub(sp[0]))),
                g[1].saturating_add(self.spacings(target[1].saturating_sub(sp[1]))),
            ];
        }
        self.held_to_patch(g)
    }

    /// [`Proxy::update`] on a cap; `tissue`: the tissue's rectangle in the patch frame
    /// (`[x_lo, x_hi, y_lo, y_hi]`, Q24 mm).
    pub(super) fn update_cap(
        &mut self,
        s: &impl Surface,
        f: &CapFrame,
        probe: V3,
        tissue: [i32; 4],
    ) {
        let (goal_g, held, line, meets) = self.locate_cap(s, f, probe);
        // The line meets the tissue beyond the window: the window has yet to follow.
        let over_tissue = (tissue[0]..=tissue[1]).contains(&meets[0])
            && (tissue[2]..=tissue[3]).contains(&meets[1]);
        let beyond = held && over_tissue;
        let (goal, n) = self.centre_cap(s, f, goal_g);
        if dot(sub(goal, probe), n) <= 0 {
            self.release();
            return;
        }
        let Some(mut at) = self.at else {
            self.at = Some(goal_g);
            self.normal = n;
            self.slipping = false;
            return;
        };
        if self.mu_s == 0 && self.mu_k == 0 {
            self.at = Some(goal_g);
            self.normal = n;
            self.slipping = true;
            return;
        }
        // The offset is measured from the goal's line: from the goal across its normal,
        // or, when the line meets the tissue beyond the patch (the goal held to its
        // edge), from the probe across the line itself (as `Proxy::update`). Past the
        // tissue's edge, from the goal held to it, as the reference.
        let (from, n) = if beyond { (probe, line) } else { (goal, n) };
        // The rest normal under `at`, once known (`None` after a move).
        let mut n_at = None;
        for pass in 0..3 {
            let (proxy, under) = self.centre_cap(s, f, at);
            n_at = Some(under);
            let depth = dot(sub(proxy, probe), n).max(0);
            // The offset across n, and the cones, in Q20 (squares within i64).
            let off = sub(proxy, from);
            let t = sub(off, along(dot(off, n), n));
            let t20 = t.map(|x| x >> 4);
            let t2 = t20.iter().map(|&x| mul_wide(x, x)).sum();
            let (radius, radius2) = self.cone(pass, t2, depth);
            if t2 <= radius2 {
                break;
            }
            let lambda = scale_to(radius, t2);
            let next: V3 =
                core::array::from_fn(|k| from[k].saturating_add(q::mul_weight(t[k], lambda)));
            // The surface point under the slid proxy, along the goal's line, from where
            // the proxy was.
            at = self
                .locate_along(s, sub(next, along(self.radius, n)), line, at, SLIP_STEPS)
                .0;
            n_at = None;
        }
        self.at = Some(at);
        self.normal = n_at.unwrap_or_else(|| self.rest_normal(s, f, at));
    }

    /// [`Proxy::force`] on a cap: the damping along the rest normal under the proxy (the
    /// tick's update found it), the force unilateral along it.
    pub(super) fn force_cap(
        &self,
        s: &impl Surface,
        coupling: &CouplingQ,
        probe: V3,
        probe_vel: V3,
    ) -> (V3, [(usize, usize); 3], [i32; 3]) {
        let Some(g) = self.at else {
            return ([0; 3], [(0, 0); 3], [0; 3]);
        };
        let (corners, w) = self.triangle(g);
        // The rest normal under the proxy, from the tick's update.
        let n = self.normal;
        let proxy = q::add(self.point(s, g), along(self.radius, n));
        let v = Self::blend(w, corners.map(|(a, b)| s.velocity(a, b)));
        // The closing speed along n (Q16 mm/s: a Q16 vector dotted with Q29 is Q16).
        let closing = dot(sub(v, probe_vel), n);
        let force = q::add(
            spring(coupling, proxy, probe),
            along(damping(coupling, closing), n),
        );
        if dot(force, n) < 0 {
            return ([0; 3], corners, w);
        }
        (held(force, coupling.max_force), corners, w)
    }
}
