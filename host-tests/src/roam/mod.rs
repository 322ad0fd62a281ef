//! The roaming probe in `f64` (issue #19): a tissue larger than the patch, a window of it
//! that follows the contact, and a god-object proxy with friction on the window's
//! surface. This is the reference the fixed-point core's roaming contact will be held
//! to, written first and held to physics by `host-tests/tests/roam.rs`.
//!
//! - `tissue.rs`: the tissue grid and its rest surface (flat, or a spherical cap);
//! - `surface.rs`: the surface's triangles and points held on them ([`Anchor`]);
//! - `friction.rs`: the friction cone and its stick–slip state ([`Slip`]);
//! - this file: [`RoamTwin`], the window's dynamics (the patch twin's springs and
//!   integrator), the window's shifts and the contact.
//!
//! # Per tick
//! 1. **Contact.** Depth is measured along the rest surface's normal `n` (flat: `z`; a
//!    cap: radial), which is smooth; the deformed triangles' own normals are not (under
//!    a point load they are the crater's walls, and a frictionless point probe would
//!    slide down them onto the nearest node: cogging). The goal is the deformed surface
//!    point on the probe's normal line, plus `r n`; the depth is `n · (goal − probe)`,
//!    and the probe is in contact while it is > 0. The proxy (a surface point held as an
//!    [`Anchor`], plus `r n`) moves toward the goal as friction allows; out of contact it
//!    is the goal.
//! 2. **Window.** The window (`n × n` tissue nodes, outer ring fixed at rest) is centred
//!    on a tissue node. When the contact point (out of contact: the probe's `xy`) is more
//!    than `½ + hysteresis` spacings from the centre along an axis, the window moves one
//!    node that way: the nodes that stay free keep their state, the others start at
//!    rest. It stays within the tissue.
//! 3. **Substeps.** Springs as in the patch twin; the coupling `k_c (proxy − probe)`,
//!    plus its damping along the contact normal, is the device's force, held to the
//!    device maximum in magnitude (so that its direction, and the friction ratio, stay);
//!    its reaction goes onto the contact triangle's corners with the proxy's weights. It
//!    never pulls the surface up (unilateral).

pub mod friction;
pub mod surface;
pub mod tissue;

pub use friction::{Friction, Slip};
pub use surface::{locate, Anchor};
pub use tissue::{Shape, Tissue};

use crate::patch::{Mesh, Twin, TwinConfig, V};
use crate::reference::Reference;

/// Why a roaming configuration is refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RoamError {
    /// A tissue side outside 3 … 64 nodes.
    TissueSize,
    /// A spacing below 1 mm or not finite.
    Spacing,
    /// The tissue reaches beyond ±100 mm of its centre.
    TissueExtent,
    /// A cap radius below 4/3 of the tissue's half-diagonal, above 2000 mm, or not finite.
    CapRadius,
    /// A window side below 3 or larger than the tissue.
    Window,
    /// A friction coefficient outside `[0, 2]`.
    Friction,
    /// A probe radius outside `[0, spacing/2]`.
    ProbeRadius,
    /// A window hysteresis outside `[0.05, 0.45]` spacings.
    Hysteresis,
}

impl core::fmt::Display for RoamError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::TissueSize => "tissue: each side must be 3 to 64 nodes",
            Self::Spacing => "tissue: the spacing must be a finite number of mm >= 1",
            Self::TissueExtent => "tissue: it must lie within ±100 mm of its centre",
            Self::CapRadius => "tissue: the cap radius must be 4/3 of the half-diagonal to 2000 mm",
            Self::Window => "window: its side must be 3 or more and fit in the tissue",
            Self::Friction => "friction: mu_s and mu_k must each be 0 to 2",
            Self::ProbeRadius => "probe radius: must be 0 to half the spacing, mm",
            Self::Hysteresis => "window hysteresis: must be 0.05 to 0.45 spacings",
        })
    }
}

impl std::error::Error for RoamError {}

/// What a roaming twin is built from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoamConfig {
    /// The tissue.
    pub tissue: Tissue,
    /// The window's side, nodes (the standard patch's `n`).
    pub n: usize,
    /// Dynamics and coupling (the patch twin's).
    pub dynamics: TwinConfig,
    /// Friction.
    pub friction: Friction,
    /// Probe radius `r`, mm (0: a point).
    pub probe_radius: f64,
    /// How far past half a spacing the contact must go before the window moves,
    /// spacings.
    pub window_hysteresis: f64,
}

impl RoamConfig {
    /// Checks the ranges.
    pub fn validate(&self) -> Result<(), RoamError> {
        let t = &self.tissue;
        if self.n < 3 || self.n > t.w || self.n > t.h {
            return Err(RoamError::Window);
        }
        let r = self.probe_radius;
        if !r.is_finite() || r < 0.0 || r > t.spacing / 2.0 {
            return Err(RoamError::ProbeRadius);
        }
        let h = self.window_hysteresis;
        if !(0.05..=0.45).contains(&h) {
            return Err(RoamError::Hysteresis);
        }
        Friction::new(self.friction.mu_s, self.friction.mu_k).map(|_| ())
    }
}

/// The contact: where the proxy is on the surface, and whether it slips.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// The proxy's surface point.
    pub anchor: Anchor,
    /// The friction state.
    pub slip: Slip,
}

/// What one tick leaves for a caller to read.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TickOut {
    /// Force on the device, N.
    pub force: V,
    /// The proxy's centre (surface point + `r` along the normal), mm; the probe when out
    /// of contact.
    pub proxy: V,
    /// The contact triangle's upward normal (zero out of contact).
    pub normal: V,
    /// Whether the window moved this tick.
    pub shifted: bool,
}

/// The roaming `f64` twin.
#[derive(Clone, Debug)]
pub struct RoamTwin {
    cfg: RoamConfig,
    /// The window's patch (mesh, state, law); its mesh is rebuilt at each shift.
    twin: Twin,
    /// The window's first corner, tissue grid coordinates.
    corner: (usize, usize),
    contact: Option<Contact>,
    /// The last tick's probe (`None` before the first: its velocity is then zero).
    probe_prev: Option<V>,
    out: TickOut,
    /// Window shifts so far.
    pub shifts: u32,
}

/// Most fixed-point steps of [`RoamTwin`]'s surface point on a cap.
const SURFACE_STEPS: usize = 50;

fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl RoamTwin {
    /// At rest, the window centred on the tissue node nearest `(x, y)` (mm).
    pub fn new(cfg: RoamConfig, law: Reference, x: f64, y: f64) -> Result<RoamTwin, RoamError> {
        cfg.validate()?;
        let (u, v) = cfg.tissue.grid(x, y);
        let corner = Self::corner_for(&cfg, u.round(), v.round());
        let mesh = cfg.tissue.window_mesh(cfg.n, corner.0, corner.1);
        Ok(RoamTwin {
            cfg,
            twin: Twin::new(mesh, law, cfg.dynamics),
            corner,
            contact: None,
            probe_prev: None,
            out: TickOut::default(),
            shifts: 0,
        })
    }

    /// The window corner for a centre at grid `(u, v)`, kept inside the tissue.
    fn corner_for(cfg: &RoamConfig, u: f64, v: f64) -> (usize, usize) {
        let half = (cfg.n / 2) as f64;
        let i = (u - half).clamp(0.0, (cfg.tissue.w - cfg.n) as f64);
        let j = (v - half).clamp(0.0, (cfg.tissue.h - cfg.n) as f64);
        (i as usize, j as usize)
    }

    /// The window's centre node, tissue grid coordinates.
    pub fn centre(&self) -> (usize, usize) {
        (
            self.corner.0 + self.cfg.n / 2,
            self.corner.1 + self.cfg.n / 2,
        )
    }

    /// The contact, if any.
    pub fn contact(&self) -> Option<Contact> {
        self.contact
    }

    /// The window's patch twin (its mesh and state).
    pub fn window(&self) -> &Twin {
        &self.twin
    }

    /// The window's node index of tissue node `(i, j)` on the surface, if inside.
    fn local(&self, (i, j): (usize, usize)) -> Option<usize> {
        let n = self.cfg.n;
        let (a, b) = (i.checked_sub(self.corner.0)?, j.checked_sub(self.corner.1)?);
        (a < n && b < n).then_some(a * n + b)
    }

    /// Current position of tissue surface node `(i, j)`, mm.
    pub fn position(&self, node: (usize, usize)) -> V {
        match self.local(node) {
            Some(k) => self.twin.x[k],
            None => self.cfg.tissue.rest(node.0, node.1),
        }
    }

    fn velocity(&self, node: (usize, usize)) -> V {
        self.local(node).map_or([0.0; 3], |k| self.twin.v[k])
    }

    /// One tick with the probe's centre at `probe` (mm, tissue frame).
    pub fn step(&mut self, probe: V) -> TickOut {
        let hz = self.cfg.dynamics.tick_hz;
        let prev = self.probe_prev.unwrap_or(probe);
        let pv = [0, 1, 2].map(|k| (probe[k] - prev[k]) * hz);
        self.probe_prev = Some(probe);
        self.update_contact(probe);
        self.out.shifted = self.follow(probe);
        for _ in 0..self.cfg.dynamics.substeps {
            self.substep(probe, pv);
        }
        self.out
    }

    /// The proxy's centre for a surface point `anchor` on the current surface, and the
    /// rest normal there.
    fn proxy_of(&self, anchor: &Anchor) -> (V, V) {
        let s = anchor.point(|c| self.position(c));
        let rest = anchor.point(|c| self.cfg.tissue.rest(c.0, c.1));
        let n = self.cfg.tissue.normal(rest[0], rest[1]);
        let r = self.cfg.probe_radius;
        ([0, 1, 2].map(|k| s[k] + r * n[k]), n)
    }

    /// The deformed surface's point on the rest normal line through `p` (for a cap, see
    /// [`Self::surface_along`]; flat, exact at once).
    fn surface_at(&self, p: V) -> Anchor {
        let tissue = &self.cfg.tissue;
        let (x, y) = tissue.project(p);
        let a = locate(tissue, |c| self.position(c), x, y);
        if tissue.shape == Shape::Flat {
            return a;
        }
        self.surface_along(p, tissue.normal(x, y), a)
    }

    /// The deformed surface's point on the line through `p` along `n`, from `a` near it:
    /// fixed-point steps along the line until the distance along it settles within 1e-12
    /// mm, at most [`SURFACE_STEPS`] (three left 2 % of the force unsettled under a 1 mm
    /// sphere pressed 1.5 mm into the cap's slope).
    fn surface_along(&self, p: V, n: V, mut a: Anchor) -> Anchor {
        let tissue = &self.cfg.tissue;
        let mut last = f64::INFINITY;
        for _ in 0..SURFACE_STEPS {
            let s = a.point(|c| self.position(c));
            let t = dot(n, [0, 1, 2].map(|k| s[k] - p[k]));
            a = locate(
                tissue,
                |c| self.position(c),
                p[0] + t * n[0],
                p[1] + t * n[1],
            );
            if (t - last).abs() < 1e-12 {
                break;
            }
            last = t;
        }
        a
    }

    fn update_contact(&mut self, p: V) {
        let goal_anchor = self.surface_at(p);
        let line = {
            let (x, y) = self.cfg.tissue.project(p);
            self.cfg.tissue.normal(x, y)
        };
        let (goal, n) = self.proxy_of(&goal_anchor);
        let depth = dot(n, [0, 1, 2].map(|k| goal[k] - p[k]));
        if depth <= 0.0 {
            self.contact = None;
            return;
        }
        let Some(Contact {
            mut anchor,
            mut slip,
        }) = self.contact
        else {
            self.contact = Some(Contact {
                anchor: goal_anchor,
                slip: Slip(false),
            });
            return;
        };
        // The proxy's own depth sets the cone (the force's angle); a slip moves it onto
        // the cone, where the surface's height changes that depth a little: three
        // passes settle it.
        let start = slip;
        for pass in 0..3 {
            let (proxy, _) = self.proxy_of(&anchor);
            let own = dot(n, [0, 1, 2].map(|k| proxy[k] - p[k])).max(0.0);
            let mut s = if pass == 0 { start } else { slip };
            let next = s.advance(&self.cfg.friction, proxy, goal, own, n);
            if pass == 0 {
                slip = s;
            }
            if next == proxy {
                break;
            }
            let surface = [0, 1, 2].map(|k| next[k] - self.cfg.probe_radius * n[k]);
            // On a cap, along the goal's line (as the core does, which then needs no
            // new square root): from the proxy's place.
            anchor = if next == goal {
                goal_anchor
            } else if self.cfg.tissue.shape == Shape::Flat {
                self.surface_at(surface)
            } else {
                self.surface_along(surface, line, anchor)
            };
            if !slip.0 {
                break;
            }
        }
        self.contact = Some(Contact { anchor, slip });
    }

    /// Moves the window one node per axis toward the contact point (or the probe) when it
    /// is past the hysteresis; whether it moved.
    fn follow(&mut self, p: V) -> bool {
        let (u, v) = match self.contact {
            Some(c) => c.anchor.grid(),
            None => self.cfg.tissue.grid(p[0], p[1]),
        };
        let (ci, cj) = self.centre();
        let limit = 0.5 + self.cfg.window_hysteresis;
        let step = |g: f64, c: usize| {
            let d = g - c as f64;
            if d > limit {
                c as f64 + 1.0
            } else if d < -limit {
                c as f64 - 1.0
            } else {
                c as f64
            }
        };
        let corner = Self::corner_for(&self.cfg, step(u, ci), step(v, cj));
        if corner == self.corner {
            return false;
        }
        self.shift_to(corner);
        true
    }

    /// Moves the window to `corner`: free nodes that stay free keep their state.
    fn shift_to(&mut self, corner: (usize, usize)) {
        let n = self.cfg.n;
        let old = self.corner;
        let mesh: Mesh = self.cfg.tissue.window_mesh(n, corner.0, corner.1);
        let mut x = mesh.rest.clone();
        let mut v = vec![[0.0; 3]; x.len()];
        let inner = |a: usize, b: usize| a >= 1 && b >= 1 && a + 1 < n && b + 1 < n;
        for a in 1..n - 1 {
            for b in 1..n - 1 {
                let (ti, tj) = (corner.0 + a, corner.1 + b);
                let (Some(oa), Some(ob)) = (ti.checked_sub(old.0), tj.checked_sub(old.1)) else {
                    continue;
                };
                if oa < n && ob < n && inner(oa, ob) {
                    x[a * n + b] = self.twin.x[oa * n + ob];
                    v[a * n + b] = self.twin.v[oa * n + ob];
                }
            }
        }
        self.twin.mesh = mesh;
        self.twin.x = x;
        self.twin.v = v;
        self.corner = corner;
        // One shift per axis moved, as the core counts them (`docs/roaming.md`: a
        // diagonal move is two shifts).
        self.shifts += u32::from(corner.0 != old.0) + u32::from(corner.1 != old.1);
    }

    fn substep(&mut self, p: V, pv: V) {
        let cfg = self.cfg.dynamics;
        let mut f = self.twin.spring_forces(&self.twin.x, &self.twin.v);
        self.out.force = [0.0; 3];
        self.out.proxy = p;
        self.out.normal = [0.0; 3];
        if let Some(c) = self.contact {
            let (proxy, n) = self.proxy_of(&c.anchor);
            let vs = c.anchor.point(|k| self.velocity(k));
            let (kc, bc, fmax) = cfg.coupling;
            let closing = dot(n, [0, 1, 2].map(|k| vs[k] - pv[k]));
            let mut force =
                [0, 1, 2].map(|k| kc * (proxy[k] - p[k]) + bc / 1000.0 * closing * n[k]);
            if dot(force, n) < 0.0 {
                force = [0.0; 3];
            }
            let mag = dot(force, force).sqrt();
            if mag > fmax {
                force = force.map(|x| x * fmax / mag);
            }
            for (m, corner) in c.anchor.corners().into_iter().enumerate() {
                if let Some(k) = self.local(corner) {
                    for d in 0..3 {
                        f[k][d] -= c.anchor.bary[m] * force[d];
                    }
                }
            }
            self.out = TickOut {
                force,
                proxy,
                normal: n,
                shifted: self.out.shifted,
            };
        }
        // The twin's integrator, on the window's mesh.
        self.twin.integrate(&f);
    }
}
