//! Coulomb friction on the proxy: the friction cone of the god-object (Zilles & Salisbury
//! 1995; Ruspini et al. 1997 §4), with CHAI3D's stick–slip state machine
//! (`cAlgorithmFingerProxy::testFrictionAndMoveProxy`).
//!
//! The angle `θ` between the probe→proxy vector and the surface normal is
//! `atan(|proxy − goal| / depth)`, where the goal is the probe projected on the contact
//! plane and the depth is the probe's distance below that plane:
//! - sticking, the proxy stays while `θ ≤ atan μ_s`;
//! - past it, the contact slips: the proxy moves toward the goal until it sits on the
//!   kinetic radius `depth · μ_k`;
//! - it sticks again only when `θ` falls below `hysteresis · atan μ_k`;
//! - with `μ_k > μ_s` it always slips; with `μ_s = μ_k = 0` the proxy is the goal.

use super::RoamError;
use crate::patch::V;

/// Largest friction coefficient accepted (the typical pairs reach 1.0 / 0.7).
pub const MAX_MU: f64 = 2.0;

/// Friction coefficients and the stick hysteresis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Friction {
    /// Static coefficient `μ_s`.
    pub mu_s: f64,
    /// Kinetic coefficient `μ_k`.
    pub mu_k: f64,
    /// A slipping contact sticks again below this fraction of the kinetic angle (CHAI3D:
    /// 0.6).
    pub hysteresis: f64,
}

impl Friction {
    /// No friction.
    pub const NONE: Friction = Friction {
        mu_s: 0.0,
        mu_k: 0.0,
        hysteresis: 0.6,
    };

    /// `μ_s`, `μ_k` in `[0, 2]`, CHAI3D's hysteresis 0.6.
    pub fn new(mu_s: f64, mu_k: f64) -> Result<Friction, RoamError> {
        let ok = |m: f64| m.is_finite() && (0.0..=MAX_MU).contains(&m);
        if !ok(mu_s) || !ok(mu_k) {
            return Err(RoamError::Friction);
        }
        Ok(Friction {
            mu_s,
            mu_k,
            hysteresis: 0.6,
        })
    }
}

/// Whether the contact slips (the state between two ticks).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Slip(pub bool);

impl Slip {
    /// The proxy's next centre, from where it is (`proxy`), the goal (the surface point on
    /// the probe's normal line, plus `r n`), and the proxy's height above the probe along
    /// the normal `n` (`depth` > 0, mm: the force's normal part over the coupling
    /// stiffness). The offset `proxy − goal` across `n`, over `depth`, is `tan θ`.
    pub fn advance(&mut self, f: &Friction, proxy: V, goal: V, depth: f64, n: V) -> V {
        if f.mu_s == 0.0 && f.mu_k == 0.0 {
            self.0 = true;
            return goal;
        }
        let off = [0, 1, 2].map(|k| proxy[k] - goal[k]);
        let along = off[0] * n[0] + off[1] * n[1] + off[2] * n[2];
        let t = [0, 1, 2].map(|k| off[k] - along * n[k]);
        let r = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
        let theta = r.atan2(depth);
        self.0 = if f.mu_k > f.mu_s {
            true
        } else if self.0 {
            theta >= f.hysteresis * f.mu_k.atan()
        } else {
            theta > f.mu_s.atan()
        };
        let radius = depth * if self.0 { f.mu_k } else { f.mu_s };
        if r > radius {
            [0, 1, 2].map(|k| goal[k] + t[k] * radius / r)
        } else {
            proxy
        }
    }
}
