//! The proxy on a flat tissue: depth, the friction cone and the coupling's damping
//! along `z`, the goal on the vertical line through the probe.

use super::force::{damping, held, scale_to, spring};
use super::{Proxy, Surface};
use crate::coupling::CouplingQ;
use crate::q::{self, mul_wide, V3};

impl Proxy {
    /// One tick's contact and friction on a flat tissue with the probe at `probe` (Q24
    /// mm, patch frame), its `xy` held to the surface (the patch, or the window's
    /// tissue): when it lies beyond the patch, the surface goes on there at rest.
    pub(super) fn update_flat(&mut self, s: &impl Surface, probe: V3) {
        let (goal_g, beyond) = self.locate(s, probe[0], probe[1]);
        let goal = self.centre(s, goal_g);
        if goal[2] <= probe[2] {
            self.release();
            return;
        }
        let Some(mut at) = self.at else {
            self.at = Some(goal_g);
            self.slipping = false;
            return;
        };
        let frictionless = self.mu_s == 0 && self.mu_k == 0;
        if frictionless {
            self.at = Some(goal_g);
            self.slipping = true;
            return;
        }
        // The offset is measured from the goal's line, the vertical through the probe:
        // from the goal, or, when the probe lies beyond the patch (the goal held to its
        // edge), from the probe itself, so that a probe far from a sticking proxy still
        // makes it slip (held, the offset stopped at the patch's edge and the proxy
        // stuck with the force at the device's maximum).
        let from = if beyond { probe } else { goal };
        for pass in 0..3 {
            let proxy = self.centre(s, at);
            let depth = proxy[2].saturating_sub(probe[2]).max(0);
            // The offset across z, and the cones, in Q20 (squares within i64).
            let t = [
                proxy[0].saturating_sub(from[0]) >> 4,
                proxy[1].saturating_sub(from[1]) >> 4,
            ];
            let t2 = mul_wide(t[0], t[0]) + mul_wide(t[1], t[1]);
            let (radius, radius2) = self.cone(pass, t2, depth);
            if t2 <= radius2 {
                break;
            }
            // On the cone: goal + t · radius/|t|, the ratio by a reciprocal square root.
            let lambda = scale_to(radius, t2);
            let next = [0, 1].map(|k| {
                let off = proxy[k].saturating_sub(from[k]);
                from[k].saturating_add(q::mul_weight(off, lambda))
            });
            // Past the cone only when slipping (sticking, the state test above keeps
            // `t2` within the static cone): the next pass re-measures the depth there.
            at = self.locate_from(s, next[0], next[1], at).0;
        }
        self.at = Some(at);
    }

    /// The device's force (Q20 N) in one substep on a flat tissue, with the probe at
    /// `probe` moving at `probe_vel` (Q16 mm/s), and the proxy's triangle with its
    /// weights to put the reaction (minus the force) on; zero out of contact.
    pub(super) fn force_flat(
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
        let p = Self::blend(w, corners.map(|(a, b)| s.position(a, b)));
        // Only the surface's normal (z) velocity enters: the damping acts along z.
        let vz = Self::blend1(w, corners.map(|(a, b)| s.velocity(a, b)[2]));
        let proxy = [p[0], p[1], p[2].saturating_add(self.radius)];
        let mut f = spring(coupling, proxy, probe);
        f[2] = f[2].saturating_add(damping(coupling, vz.saturating_sub(probe_vel[2])));
        if f[2] < 0 {
            return ([0; 3], corners, w);
        }
        (held(f, coupling.max_force), corners, w)
    }
}
