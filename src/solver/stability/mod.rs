//! The stability bound: the largest substep `h` at which the configured integrator (the
//! paper's improved Euler by default) is stable on a patch, and so the substeps per tick
//! (start-up only; never per tick).
//!
//! # The integrator's one-step matrix
//! Linearised around a state, the patch is `M ẍ + C ẋ + K x = 0` (`M` the node masses,
//! `C` the spring dampings on the full relative velocity plus the node and coupling
//! dampings, `K` every spring at the table's largest tangent stiffness `k_max / l0` along
//! its rest direction, plus the coupling's stiffness). With `A = M⁻¹K`, `B = M⁻¹C`, one
//! step of eqs. 21–22 (`v' = v + h M⁻¹ F`, `x' = x + h (v + v')/2`) maps `(x, v)` by
//!
//! ```text
//! G(h) = | I − h²A/2   h (I − hB/2) |
//!        | −hA         I − hB       |
//! ```
//!
//! (not two-stage Runge–Kutta: the position uses the new velocity). The step is stable
//! while the spectral radius `ρ(G(h)) < 1`. For one mode (`ω²`, `γ`) that is
//! `h < 2γ/ω²` and `h < 2/γ`: unlike symplectic Euler the scheme amplifies an undamped
//! oscillation, so a stiff, lightly damped mode sets the bound.
//!
//! # Two bounds
//! Both start from a closed form, the one-mode bound applied spring by spring: each
//! spring's stiffness is at most `k_max / l0` in every direction while its damping is `C`
//! in every direction, so `K ⪯ θ C` with `θ = k_max / (l0_min C)` (the coupling's
//! `k_c / (c + b_c)` where that is larger), tension's geometric stiffness included
//! (`|f|/l ≤ k_max / l0`); and `λ_max(M⁻¹C)` is at most the largest Gershgorin row sum
//! `γ`. Were `K` and `C` to share their eigenvectors, `h < min(2/θ, 2/γ)` would hold for
//! every mode. They do not, so the closed form is a per-mode argument, **not** a proof
//! for the coupled patch; over the 120 configurations of `host-tests/tests/stability.rs`
//! it never exceeded the exact bound (`STABILITY sweep`, `max_closed_of_exact`: equal
//! where `2/γ` binds, which is exact for node damping alone).
//! - [`Bound::Estimated`], the default: the largest `h` with `ρ(G(h)) < 1`, estimated
//!   matrix-free by running the linearised step (in block fixed point: `i32` state
//!   under one exponent, exact high-word products, so that a core without an FPU runs
//!   it at integer speed; `Linearised::growth`) from a fixed start and measuring its
//!   growth, bisected (geometrically, 7 steps) between a quarter of the
//!   closed form and four times it; then [`ESTIMATE_MARGIN`] of it, where the motion at
//!   that step visibly dies out (energy growth at most [`TRUSTED_DECAY`] over the last
//!   third of the run); where it does not (a lightly damped patch: near the edge its
//!   growth is too slow for the run to see), the conservative bound. The margin covers
//!   the estimate's error and the states away from rest (a deep indentation stiffens the
//!   springs across their direction); the tests hold it to the exact bound (the
//!   eigenvalues of `G(h)`) on rest and deformed states.
//! - [`Bound::Conservative`]: [`CONSERVATIVE_FACTOR`] of the closed form, no simulation.
//!   About a quarter of the exact bound on the standard patch (it cannot use the
//!   springs' being stiff along one direction only): twice the substeps or more.
//!
//! # The symplectic integrator
//! [`Integrator::SymplecticDamped`] steps `v' = v + h D M⁻¹F`, `x' = x + h v'`, with
//! `D = 1/(1 + h γ)` and `γ` the largest diagonal entry of `M⁻¹C` ([`most_damping`]):
//!
//! ```text
//! G(h) = | I − h²DA   h (I − hDB) |
//!        | −hDA       I − hDB     |
//! ```
//!
//! The estimate runs this step instead (`Linearised::growth`), bisected up to 16 times
//! the closed form. The closed form, and so [`Bound::Conservative`] and the fallback, is
//! the paper's, and stays on the safe side per mode: for one mode (`ω²`, damping rate
//! `β ≤ γ`) the step is stable while `h D β < 2` (always: `h D β < 1`) and
//! `h² ω² + 2 h β < 4 (1 + h γ)`, which `h < 2β/ω²` (the paper's condition) implies. The
//! host tests hold both bounds to the eigenvalues of this `G(h)` as for the paper's.
//!
//! The masses are haptic masses (a few grams per node), not the tissue's: they set how
//! many substeps a tick needs, not the settled force.

mod check;
mod linearised;

pub use check::{StabilityCheck, MAX_CHECK_STEPS};

use super::{ConfigKey, SolverConfig, SolverError};
use crate::arith::{Integrator, MAX_H_OVER_M, MAX_SUBSTEP};
use crate::table::ForceTable;
use crate::topology::{Topology, GROUND};

/// Which stability bound a solver takes its substeps from (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Bound {
    /// The estimated exact bound with its margin: the fewest substeps.
    #[default]
    Estimated,
    /// A fraction of the closed form: about twice the substeps, computed in one loop
    /// over the springs.
    Conservative,
}

/// The fraction of the estimated exact bound a solver takes.
pub const ESTIMATE_MARGIN: f64 = 0.75;

/// The largest growth (energy at the end of the estimate's run over that two thirds in)
/// at the estimated step with its margin for which the estimate is taken; above it, the
/// patch is too lightly damped for the estimate to see the edge, and the solver takes
/// the conservative bound.
pub const TRUSTED_DECAY: f32 = 0.5;

/// The fraction of the closed form that [`Bound::Conservative`] takes.
pub const CONSERVATIVE_FACTOR: f64 = 0.5;

/// The bounds of one patch and configuration (the tests report them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// The closed form (see the module docs: not a proof), s.
    pub closed: f64,
    /// The estimated exact bound (before the margin), s; `None` with
    /// [`Bound::Conservative`], which does not estimate.
    pub estimated: Option<f64>,
    /// The substep the solver takes with its configuration's [`Bound`], s.
    pub chosen: f64,
}

/// Checks `config` and returns the substeps per tick the stability bound asks for.
pub fn substeps_for<const NODES: usize, const EDGES: usize, const S: usize>(
    topo: &Topology<NODES, EDGES>,
    table: &ForceTable<S>,
    config: &SolverConfig,
) -> Result<u32, SolverError> {
    let b = bounds(topo, table, config)?;
    substeps_of(b.chosen, config)
}

/// The substeps per tick for a substep of at most `h_max`, checked against the
/// configuration's limit and the arithmetics'.
pub(crate) fn substeps_of(h_max: f64, config: &SolverConfig) -> Result<u32, SolverError> {
    let needed = libm::ceil(1.0 / (config.tick_hz * h_max));
    if needed.is_nan() || needed > config.max_substeps as f64 {
        let needed = if needed < u32::MAX as f64 {
            needed as u32
        } else {
            u32::MAX
        };
        return Err(SolverError::TooManySubsteps { needed });
    }
    let n = (needed as u32).max(1);
    // The arithmetics' own limits on h/m and h.
    let h = 1.0 / (config.tick_hz * n as f64);
    if 1000.0 * h / config.node_mass >= MAX_H_OVER_M {
        return Err(SolverError::Config(ConfigKey::NodeMass));
    }
    if h >= MAX_SUBSTEP {
        return Err(SolverError::Config(ConfigKey::TickHz));
    }
    Ok(n)
}

/// The largest damping on one free node — its own, its springs' (each spring's `C` on
/// both of its nodes), and at the contact the coupling's — over the node mass: `γ` of
/// [`Integrator::SymplecticDamped`], 1/s (the largest diagonal entry of `M⁻¹C`).
pub fn most_damping<const NODES: usize, const EDGES: usize>(
    topo: &Topology<NODES, EDGES>,
    config: &SolverConfig,
) -> f64 {
    let mut diag = [config.node_damping; NODES];
    for e in topo.edges() {
        for n in [e.a, e.b] {
            if let Some(d) = diag.get_mut(n as usize).filter(|_| n != GROUND) {
                *d += config.spring_damping;
            }
        }
    }
    if let Some(d) = diag.get_mut(topo.contact() as usize) {
        *d += config.coupling.damping;
    }
    (1..topo.node_count().min(NODES))
        .map(|i| diag[i])
        .fold(0.0, f64::max)
        / config.node_mass
}

/// The factor `D` on the velocity step at substep `h` (s): `1/(1 + h γ)` with `γ` from
/// [`most_damping`] for [`Integrator::SymplecticDamped`], 1 for the paper's integrator.
pub fn damping_factor<const NODES: usize, const EDGES: usize>(
    topo: &Topology<NODES, EDGES>,
    config: &SolverConfig,
    h: f64,
) -> f64 {
    match config.integrator {
        Integrator::ImprovedEuler => 1.0,
        Integrator::SymplecticDamped => 1.0 / (1.0 + h * most_damping(topo, config)),
    }
}

/// The closed-form and estimated bounds, and the substep the configuration chooses.
pub fn bounds<const NODES: usize, const EDGES: usize, const S: usize>(
    topo: &Topology<NODES, EDGES>,
    table: &ForceTable<S>,
    config: &SolverConfig,
) -> Result<Bounds, SolverError> {
    let mut check = StabilityCheck::new(topo, table, config, None)?;
    while check.advance(topo, MAX_CHECK_STEPS).is_none() {}
    Ok(check.bounds())
}

/// The closed form `min(2/θ, 2/γ)` of the module docs, s.
fn closed_form<const NODES: usize, const EDGES: usize>(
    topo: &Topology<NODES, EDGES>,
    k_max: f64,
    config: &SolverConfig,
) -> Result<f64, SolverError> {
    let mut row = [0.0f64; NODES];
    let mut k_row = [0.0f64; NODES];
    let n = topo.node_count().min(NODES);
    closed_form_in(
        topo.edges(),
        n,
        topo.contact() as usize,
        k_max,
        config,
        &mut row,
        &mut k_row,
    )
}

/// [`closed_form`] on slices (one copy for every capacity): `row` and `k_row` are
/// scratch, one slot a node.
#[inline(never)]
fn closed_form_in(
    edges: &[crate::topology::Edge],
    nodes: usize,
    contact: usize,
    k_max: f64,
    config: &SolverConfig,
    row: &mut [f64],
    k_row: &mut [f64],
) -> Result<f64, SolverError> {
    let (c_s, c_n) = (config.spring_damping, config.node_damping);
    let cp = &config.coupling;
    // γ: the largest Gershgorin row sum of C (a spring between two free nodes puts C on
    // the diagonal and C off it; to the ground, on the diagonal only), over the mass.
    // θ for the springs: the stiffest spring per unit length over its damping (N/m over
    // N·s/m); without spring damping, every spring's stiffness over the node damping,
    // through K's Gershgorin row sums.
    for (r, kr) in row.iter_mut().zip(k_row.iter_mut()) {
        (*r, *kr) = (c_n, 0.0);
    }
    let mut shortest = f64::INFINITY;
    for e in edges {
        let l0 = crate::topology::rest_length(e);
        shortest = shortest.min(l0);
        let k = k_max / l0 * 1000.0;
        let two_ends = e.b != GROUND;
        for n in [e.a, e.b] {
            if n == GROUND {
                continue;
            }
            if let (Some(r), Some(kr)) = (row.get_mut(n as usize), k_row.get_mut(n as usize)) {
                *r += if two_ends { 2.0 * c_s } else { c_s };
                *kr += if two_ends { 2.0 * k } else { k };
            }
        }
    }
    if let Some(r) = row.get_mut(contact) {
        *r += cp.damping;
    }
    let nodes = nodes.min(row.len()).min(k_row.len());
    let gamma = (1..nodes).map(|i| row[i]).fold(0.0, f64::max) / config.node_mass;
    let k_c = cp.stiffness * 1000.0;
    let theta = if c_s > 0.0 {
        let springs = k_max / shortest * 1000.0 / c_s;
        let coupling = if c_n + cp.damping > 0.0 {
            k_c / (c_n + cp.damping)
        } else {
            // The coupling against the contact's springs' damping, on top.
            springs + k_c / c_s
        };
        springs.max(coupling)
    } else if c_n > 0.0 {
        let k_rows = (1..nodes)
            .map(|i| k_row[i] + if i == contact { k_c } else { 0.0 })
            .fold(0.0, f64::max);
        k_rows / c_n
    } else {
        f64::INFINITY
    };
    let h = libm::fmin(2.0 / theta, 2.0 / gamma);
    if h.is_nan() || h <= 0.0 || theta.is_infinite() || gamma <= 0.0 {
        return Err(SolverError::NoDamping);
    }
    Ok(h)
}
