//! `Proxy`: a god-object contact that slides on the standard patch's surface with Coulomb
//! friction, in fixed point: the `f64` reference is `mccs_host::roam` (`docs/roaming.md`),
//! whose model this follows. One update per tick and one force per substep
//! (`Proxy::update`, `Proxy::force`) for every [`Shape`] of tissue: on a flat one
//! (`flat.rs`) or on a cap (`cap.rs`); the coupling's force and its ratios in `force.rs`.
//!
//! The surface is the patch's `n × n` surface nodes (outer ring fixed at rest), each
//! cell split along its `(i, j)`–`(i+1, j+1)` diagonal. A surface point is held in grid
//! coordinates `(u, v)` (Q16 spacings from the patch's corner), so it moves with the
//! deformed nodes. Depth is measured along `z` (the rest normal of a flat patch).
//!
//! Per tick on a flat tissue (`Proxy::update`): the goal is the deformed
//! surface's point above or below the probe (found from the rest grid by a product by
//! `1/s`, then two corrections by the deformed surface's offset: no search, no
//! division), plus `r` up; the probe is in
//! contact while it is below the goal. Sticking, the proxy stays while its offset across
//! `z` is within `μ_s` times its height above the probe; past it the contact slips and
//! the proxy moves toward the goal onto `μ_k` times that height (three passes, since the
//! surface's height under the proxy changes it); it sticks again below the hysteresis
//! cone `tan(0.6 atan μ_k)`. Per substep (`Proxy::force`): the coupling
//! `k_c (proxy − probe)` plus its damping along `z`, held to the device maximum in
//! magnitude, never pulling the surface up; its reaction goes onto the proxy's triangle
//! with the proxy's weights.
//!
//! Formats: positions Q24 mm, velocities Q16 mm/s, forces Q20 N, grid coordinates and
//! weights Q16, friction coefficients Q16. The only square roots are reciprocal ones by
//! two Newton steps from a table's guess (`rsqrt`), for a slip and for a force over the
//! device maximum.

mod cap;
mod flat;
mod force;

use crate::coupling::CouplingQ;
use crate::q::{self, mul_wide, sat, V3};
use crate::shape::Shape;
use crate::units::{from_f64, LEN_FRAC};
use cap::CapFrame;
use force::tan_small;

/// Fraction bits of grid coordinates and weights.
const G_FRAC: u32 = 16;
const ONE_G: i32 = 1 << G_FRAC;

/// What a proxy is built from (start-up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProxyConfig {
    /// The patch's side `n` (its `Topology::standard_patch` grid, 3 … 200).
    pub grid: usize,
    /// The patch's spacing, mm (1 … 100, within the topology's ±100 mm).
    pub spacing: f64,
    /// Static friction coefficient (0 … 2).
    pub mu_s: f64,
    /// Kinetic friction coefficient (0 … 2).
    pub mu_k: f64,
    /// Probe radius, mm (0 … spacing/2).
    pub probe_radius: f64,
}

/// A proxy's friction in fixed point: `μ_s`, `μ_k` and the hysteresis cone
/// `tan(0.6 atan μ_k)`, Q16 — built away from the tick (`f64`), taken by a proxy between
/// two ticks ([`Proxy::set_friction`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Friction {
    mu_s: i32,
    mu_k: i32,
    mu_h: i32,
}

impl Friction {
    /// From the coefficients, each within 0 … 2 (`μ_k > μ_s` slides with no hysteresis
    /// cone).
    pub fn new(mu_s: f64, mu_k: f64) -> Result<Friction, ProxyError> {
        let ok = |m: f64| m.is_finite() && (0.0..=2.0).contains(&m);
        if !ok(mu_s) || !ok(mu_k) {
            return Err(ProxyError::Friction);
        }
        let mu_h = if mu_k > mu_s {
            0.0
        } else {
            tan_small(0.6 * libm::atan(mu_k))
        };
        Ok(Friction {
            mu_s: from_f64(mu_s, G_FRAC),
            mu_k: from_f64(mu_k, G_FRAC),
            mu_h: from_f64(mu_h, G_FRAC),
        })
    }

    /// `(μ_s, μ_k)` as numbers.
    pub fn values(&self) -> (f64, f64) {
        let f = |q: i32| q as f64 / ONE_G as f64;
        (f(self.mu_s), f(self.mu_k))
    }
}

/// Why a proxy configuration is refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProxyError {
    /// A grid outside 3 … 200, a spacing outside 1 … 100 mm or beyond ±100 mm, or not
    /// the solver's standard patch.
    Grid,
    /// A friction coefficient outside 0 … 2.
    Friction,
    /// A probe radius outside 0 … spacing/2.
    ProbeRadius,
    /// A tissue smaller than the patch, larger than 64 nodes a side or beyond ±100 mm, or
    /// a window hysteresis outside 0.05 … 0.45 spacings.
    Window,
    /// A cap radius outside 4/3 of the tissue's half-diagonal … 2000 mm, or a cap whose
    /// base reaches below −100 mm or whose longest spring is too long for the arithmetic.
    Cap,
}

impl ProxyError {
    /// The message: one source for `Display` and the `defmt` impl.
    pub const fn message(&self) -> &'static str {
        match self {
            Self::Grid => "proxy: not this solver's standard patch (on a cap: its springs in its order), or a grid outside 3 to 200 nodes a side with a spacing of 1 to 100 mm within ±100 mm",
            Self::Friction => "proxy: mu_s and mu_k must be within [0, 2]",
            Self::ProbeRadius => "proxy: the probe radius must be within [0, spacing/2] mm",
            Self::Window => "window: the tissue must be the window's side to 64 nodes a side within ±100 mm, the hysteresis 0.05 to 0.45",
            Self::Cap => "cap: the radius must be 4/3 of the tissue's half-diagonal … 2000 mm, its base above -100 mm, its springs within the arithmetic's longest",
        }
    }
}

impl core::fmt::Display for ProxyError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.message())
    }
}

impl core::error::Error for ProxyError {}

/// A proxy: its configuration in fixed point and its state (where it is on the surface,
/// and whether it slips).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Proxy {
    n: i32,
    /// Spacing, Q24 mm.
    spacing: i32,
    /// The patch's rectangle in the patch frame, Q24 mm (`[x_lo, x_hi, y_lo, y_hi]`):
    /// its nodes `0 … n − 1`, the centre node `n/2` at the origin.
    patch_rect: [i32; 4],
    /// `1/s`, Q30 per mm.
    inv_s: i32,
    /// `μ_s`, `μ_k` and the hysteresis cone `tan(0.6 atan μ_k)`, Q16.
    mu_s: i32,
    mu_k: i32,
    mu_h: i32,
    /// Probe radius, Q24 mm.
    radius: i32,
    /// The proxy's grid coordinates, when in contact.
    at: Option<[i32; 2]>,
    slipping: bool,
    /// On a cap: the rest normal under the proxy (Q29), set by the tick's update for its
    /// substeps (a window's shift leaves it: it is the tissue's).
    normal: V3,
}

/// Surface node `(a, b)`'s current position (Q24 mm), as the solver gives it.
pub(crate) trait Surface {
    /// Position of surface node `(a, b)`, `a, b < n`.
    fn position(&self, a: usize, b: usize) -> V3;
    /// Velocity of surface node `(a, b)` (Q16 mm/s).
    fn velocity(&self, a: usize, b: usize) -> V3;
    /// Rest height of surface node `(a, b)` (Q24 mm; a flat patch's is 0).
    fn rest_z(&self, _a: usize, _b: usize) -> i32 {
        0
    }
}

impl Proxy {
    /// A proxy out of contact.
    pub fn new(c: &ProxyConfig) -> Result<Proxy, ProxyError> {
        let half = (c.grid / 2) as f64 * c.spacing;
        if !(3..=200).contains(&c.grid)
            || !c.spacing.is_finite()
            || !(1.0..=100.0).contains(&c.spacing)
            || half > 100.0
        {
            return Err(ProxyError::Grid);
        }
        let friction = Friction::new(c.mu_s, c.mu_k)?;
        let r = c.probe_radius;
        if !(r.is_finite() && (0.0..=c.spacing / 2.0).contains(&r)) {
            return Err(ProxyError::ProbeRadius);
        }
        // The patch's rectangle: its nodes `0 … n − 1`, the centre node `n/2` at the
        // origin.
        let edge = |k: usize| from_f64(k as f64 * c.spacing, LEN_FRAC);
        let (lo, hi) = (-edge(c.grid / 2), edge(c.grid - 1 - c.grid / 2));
        Ok(Proxy {
            n: c.grid as i32,
            spacing: from_f64(c.spacing, LEN_FRAC),
            patch_rect: [lo, hi, lo, hi],
            inv_s: from_f64(1.0 / c.spacing, 30),
            mu_s: friction.mu_s,
            mu_k: friction.mu_k,
            mu_h: friction.mu_h,
            radius: from_f64(r, LEN_FRAC),
            at: None,
            slipping: false,
            normal: [0, 0, 1 << 29],
        })
    }

    /// The proxy's grid coordinates (Q16 spacings from the patch's corner), when in
    /// contact.
    pub fn grid_position(&self) -> Option<[i32; 2]> {
        self.at
    }

    /// The grid's side `n` and spacing (Q24 mm).
    pub fn grid(&self) -> (usize, i32) {
        (self.n as usize, self.spacing)
    }

    /// The rest normal under the proxy, as this tick's contact used it: along it the
    /// depth is measured, the coupling damps and the force is unilateral (flat: `z`; on
    /// a cap, the cap's normal at the proxy's rest point). Meaningful in contact.
    pub fn normal(&self) -> [f64; 3] {
        self.normal.map(|c| crate::units::to_f64(c, 29))
    }

    /// Takes new friction coefficients (prepared away from the tick: [`Friction::new`]),
    /// from the next update on; the contact and its place are kept.
    pub fn set_friction(&mut self, f: Friction) {
        self.mu_s = f.mu_s;
        self.mu_k = f.mu_k;
        self.mu_h = f.mu_h;
    }

    /// The friction coefficients in use.
    pub fn friction(&self) -> Friction {
        Friction {
            mu_s: self.mu_s,
            mu_k: self.mu_k,
            mu_h: self.mu_h,
        }
    }

    /// Whether the contact slips.
    pub fn slipping(&self) -> bool {
        self.at.is_some() && self.slipping
    }

    /// The rest grid's coordinates of patch-frame point `p` (Q16): where the probe is when
    /// out of contact.
    pub(crate) fn grid_of(&self, p: V3) -> [i32; 2] {
        self.rest_grid(p[0], p[1])
    }

    /// The proxy's place after the patch moved by `d` nodes over the tissue.
    pub(crate) fn shift_grid(&mut self, d: [i32; 2]) {
        if let Some(g) = self.at.as_mut() {
            for k in 0..2 {
                g[k] = g[k].saturating_sub(d[k] << G_FRAC);
            }
        }
    }

    /// Out of contact.
    pub fn release(&mut self) {
        self.at = None;
        self.slipping = false;
    }

    /// The triangle holding grid point `g` (clamped to the patch) and its weights (Q16).
    pub(crate) fn triangle(&self, g: [i32; 2]) -> ([(usize, usize); 3], [i32; 3]) {
        let top = (self.n - 1) << G_FRAC;
        let (u, v) = (g[0].max(0).min(top), g[1].max(0).min(top));
        let (i, j) = ((u >> G_FRAC).min(self.n - 2), (v >> G_FRAC).min(self.n - 2));
        let (fu, fv) = (u - (i << G_FRAC), v - (j << G_FRAC));
        let (i, j) = (i as usize, j as usize);
        if fv > fu {
            (
                [(i, j), (i + 1, j + 1), (i, j + 1)],
                [ONE_G - fv, fu, fv - fu],
            )
        } else {
            (
                [(i, j), (i + 1, j), (i + 1, j + 1)],
                [ONE_G - fu, fu - fv, fv],
            )
        }
    }

    /// `Σ w_k x_k` for the triangle's corners' values `x` (Q24 or Q16 per the values), per
    /// axis by [`Self::blend1`].
    fn blend(w: [i32; 3], x: [V3; 3]) -> V3 {
        core::array::from_fn(|d| Self::blend1(w, [x[0][d], x[1][d], x[2][d]]))
    }

    /// `Σ w_k x_k` for one value per corner, as `x₀ + w₁ (x₁ − x₀) + w₂ (x₂ − x₀)` (the
    /// weights sum to one), each term by [`q::mul_weight`]: no 64-bit product (on the M0
    /// a pass of the friction loop blends three surface points). Within two units of the
    /// last place of the exact sum.
    fn blend1(w: [i32; 3], x: [i32; 3]) -> i32 {
        let t1 = q::mul_weight(x[1].saturating_sub(x[0]), w[1]);
        let t2 = q::mul_weight(x[2].saturating_sub(x[0]), w[2]);
        x[0].saturating_add(t1).saturating_add(t2)
    }

    /// The deformed surface's point at grid `g`.
    fn point(&self, s: &impl Surface, g: [i32; 2]) -> V3 {
        let (c, w) = self.triangle(g);
        Self::blend(w, c.map(|(a, b)| s.position(a, b)))
    }

    /// A length (Q24 mm) in spacings (Q16): Q24 mm · Q30 /mm = Q54, its high word `>> 6`
    /// (the same floor as `>> 38`; within `i32`: `|x| · 1/s` ≤ 2³¹ · 2³⁰).
    fn spacings(&self, x: i32) -> i32 {
        q::mulhi(x, self.inv_s) >> 6
    }

    /// Grid coordinates of patch-frame `(x, y)` on the rest grid (Q16): the patch's
    /// corner is `n/2` spacings away.
    fn rest_grid(&self, x: i32, y: i32) -> [i32; 2] {
        let c = (self.n / 2) << G_FRAC;
        [x, y].map(|p| self.spacings(p).saturating_add(c))
    }

    /// The deformed surface's point above or below patch-frame `(x, y)`: from the rest
    /// grid, two corrections by the surface's offset there (nodes move sideways far less
    /// than a spacing); held to the patch, and whether it was (the point lies beyond it).
    fn locate(&self, s: &impl Surface, x: i32, y: i32) -> ([i32; 2], bool) {
        self.locate_from(s, x, y, self.rest_grid(x, y))
    }

    /// [`Proxy::locate`] from grid position `start` near the point (a slid proxy: from
    /// where it was, whose offset from the point is the slide, not the surface's
    /// sideways deformation there: the corrections converge from much closer).
    fn locate_from(&self, s: &impl Surface, x: i32, y: i32, start: [i32; 2]) -> ([i32; 2], bool) {
        let mut g = start;
        for _ in 0..2 {
            let p = self.point(s, g);
            g = [
                g[0].saturating_add(self.spacings(x.saturating_sub(p[0]))),
                g[1].saturating_add(self.spacings(y.saturating_sub(p[1]))),
            ];
        }
        self.held_to_patch(g)
    }

    /// The patch's rectangle in the patch frame (Q24 mm, `[x_lo, x_hi, y_lo, y_hi]`).
    pub(crate) fn patch_rect(&self) -> [i32; 4] {
        self.patch_rect
    }

    /// Grid position `g` held to the patch, and whether it was outside.
    fn held_to_patch(&self, g: [i32; 2]) -> ([i32; 2], bool) {
        let top = (self.n - 1) << G_FRAC;
        let held = g.map(|x| x.max(0).min(top));
        (held, held != g)
    }

    /// The proxy's centre for grid `g`: the surface point plus `r` up.
    fn centre(&self, s: &impl Surface, g: [i32; 2]) -> V3 {
        let p = self.point(s, g);
        [p[0], p[1], p[2].saturating_add(self.radius)]
    }

    /// The proxy's centre on the current surface (Q24 mm), when in contact.
    pub(crate) fn centre_at(&self, s: &impl Surface) -> Option<V3> {
        self.at.map(|g| self.centre(s, g))
    }

    /// The friction cone's radius at `depth` (Q24 mm; the radius Q20 and its square) for
    /// the stick–slip state, which the first `pass` of a tick sets from the square `t2`
    /// (Q20²) of the proxy's offset across the normal.
    #[inline(always)]
    fn cone(&mut self, pass: u32, t2: i64, depth: i32) -> (i32, i64) {
        let cone = |mu: i32| {
            let r = sat(mul_wide(depth >> 4, mu) >> G_FRAC);
            (r, mul_wide(r, r))
        };
        if pass == 0 {
            self.slipping = if self.mu_k > self.mu_s {
                true
            } else if self.slipping {
                t2 >= cone(self.mu_h).1
            } else {
                t2 > cone(self.mu_s).1
            };
        }
        cone(if self.slipping { self.mu_k } else { self.mu_s })
    }

    /// One tick's contact and friction with the probe at `probe` (Q24 mm, patch frame)
    /// on the tissue of `frame`'s shape, whose rectangle in the patch frame is `tissue`
    /// (`[x_lo, x_hi, y_lo, y_hi]`, Q24 mm; the patch's own for a patch alone). On a
    /// flat tissue the goal is on the vertical line through the probe with its `xy` held
    /// to that rectangle (past the tissue's edge, the point above the nearest point of
    /// it); on a cap, on the radial line through the probe itself (past the edge the cap
    /// falls away below the edge's rim, and the contact ends there).
    #[inline(always)]
    pub(crate) fn update<Sh: Shape>(
        &mut self,
        s: &impl Surface,
        frame: &Frame<'_, Sh>,
        probe: V3,
        tissue: [i32; 4],
    ) {
        match frame.shape.cap() {
            None => self.update_flat(s, q::held_to(tissue, probe)),
            Some(&cap) => {
                let f = CapFrame {
                    cap,
                    origin: frame.origin,
                };
                self.update_cap(s, &f, probe, tissue)
            }
        }
    }

    /// The device's force (Q20 N) in one substep on a tissue of `shape`, with the probe
    /// at `probe` moving at `probe_vel` (Q16 mm/s), and the proxy's triangle with its
    /// weights to put the reaction (minus the force) on; zero out of contact. The
    /// coupling's damping acts along the rest normal under the proxy (a flat tissue's:
    /// `z`), and the force is unilateral along it.
    #[inline(always)]
    pub(crate) fn force<Sh: Shape>(
        &self,
        s: &impl Surface,
        shape: &Sh,
        coupling: &CouplingQ,
        probe: V3,
        probe_vel: V3,
    ) -> (V3, [(usize, usize); 3], [i32; 3]) {
        if shape.cap().is_some() {
            self.force_cap(s, coupling, probe, probe_vel)
        } else {
            self.force_flat(s, coupling, probe, probe_vel)
        }
    }

    /// The proxy's centre on the current surface of a tissue of `frame`'s shape (Q24 mm,
    /// patch frame), when in contact.
    pub(crate) fn centre_in<Sh: Shape>(
        &self,
        s: &impl Surface,
        frame: &Frame<'_, Sh>,
    ) -> Option<V3> {
        match frame.shape.cap() {
            None => self.centre_at(s),
            Some(&cap) => self.centre_cap_at(
                s,
                &CapFrame {
                    cap,
                    origin: frame.origin,
                },
            ),
        }
    }
}

/// The tissue's shape as a proxy sees it in one tick: the shape, and the patch frame's
/// origin in the tissue frame (Q24 mm, `x` and `y`; the frames share `z`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frame<'a, Sh: Shape> {
    /// The tissue's shape.
    pub shape: &'a Sh,
    /// The patch frame's origin.
    pub origin: [i32; 2],
}
