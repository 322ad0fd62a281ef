//! The patch linearised at rest, stepped in block fixed point (`i32` state under one
//! exponent, exact high-word products): [`Linearised::growth`], the energy growth of a
//! run of the configured integrator's step, which the estimate bisects on
//! ([`super::bounds`]).

use super::most_damping;
use crate::arith::Integrator;
use crate::q;
use crate::solver::SolverConfig;
use crate::topology::{Edge, Topology, GROUND};
use crate::units::DIR_FRAC;
use step::{step_once, NodeSums, StepCoeffs};

/// Steps of each run of the linearised step ([`Linearised::growth`]). At 768, a lightly
/// damped patch's slowly growing mode stayed hidden under its slowly decaying ones, and
/// the estimate reached 1.30 times the exact bound, the substep taken 0.975 of it
/// (`host-tests/tests/stability.rs`, random configurations); at 1536, 1.12 and 0.84 on
/// the same draw.
const RUN_STEPS: usize = 1536;

/// The last steps of a run, over which its growth is measured.
const RUN_WINDOW: usize = RUN_STEPS / 3;

/// A run whose energy has fallen to this fraction of its start's (2⁻⁶⁴), or grown to
/// its inverse times it, ends there, its growth that ratio: the whole run would decide
/// the same (`test_growth` holds every decision to the whole run's).
/// - Fallen: the step is stable and its motion visibly dies out. A mode that does not
///   decay over the run (growth above [`super::TRUSTED_DECAY`] over its last third, or
///   any growth) keeps at least 2⁻³ of its share of the start's energy (its left
///   eigenvector `w` holds `|w·s_k| ≥ |λ|^k |w·s_0|`; `w` vanishes where the energy
///   does, on the springs' mechanisms), so the energy falls this far only where the
///   fixed pseudo-random start held less than 2⁻⁶¹ of such a mode.
/// - Grown: the step is unstable. A stable step's energy grows only by its
///   eigenvectors' conditioning, a Jordan pair's (critical damping) by at most `k²`
///   over `k` steps: 2²² in a run, far below 2⁶⁴.
const DECIDED: f32 = 1.0 / 18_446_744_073_709_551_616.0;

/// Steps between two looks at a run's energy ([`DECIDED`]); and the state's exponent must
/// first have moved [`LOOK_GATE_BITS`] from the start's, so that a run whose energy moves
/// slowly pays nothing for the look (its energy is a loop over the springs in `f32`, and
/// `f64` for each spring's stiffness).
const LOOK_STEPS: usize = 64;
const LOOK_GATE_BITS: i32 = 16;

/// The state's exponent at a run's start (its components in Q20 mm).
const START_EXP: i32 = -20;

/// The fraction bits of the fixed-point step's coefficients ([`Linearised::growth`]).
const COEFF_FRAC: u32 = 24;

/// A coefficient of the fixed-point step at or above this (a spring's, the node
/// damping's or the coupling's velocity change per step, per unit of displacement or of
/// velocity) means the step is unstable: a one-mode step is stable only below 4 (see
/// [`Linearised::growth`]).
const COEFF_LIMIT: f32 = 32.0;

/// A node's springs' coefficients summing to this or more means the step is unstable:
/// a one-mode step is stable only below 12 (see [`Linearised::growth`]).
const ROW_LIMIT: f32 = 64.0;

/// The state's largest component is kept in `[2^(STATE_BITS − 2), 2^STATE_BITS)` after
/// each step: 20 bits of resolution, and headroom for a stable step's growth.
const STATE_BITS: u32 = 21;

/// A state component at or above this after a step: the step grew the state over 2⁹-fold
/// in one step, which no stable step does.
const STATE_LIMIT: u32 = 1 << 30;

/// The patch linearised at rest, as the estimate runs it.
pub(super) struct Linearised<'a, const NODES: usize, const EDGES: usize> {
    topo: &'a Topology<NODES, EDGES>,
    /// The table's largest tangent stiffness, N (each spring's `k_max / l0`:
    /// [`spring_of`], computed where it is needed rather than held, for the M0's start-up
    /// stack).
    k_max: f32,
    /// The stiffest spring's `k_max / l0` and the largest sum of them on one free node,
    /// N/mm; the most springs on one free node.
    k_spring: f32,
    k_row: f32,
    degree: u32,
    /// N·s/mm.
    c_spring: f32,
    c_node: f32,
    /// Coupling N/mm and N·s/mm, at the contact.
    k_c: f32,
    b_c: f32,
    /// 1000 / m: (mm/s²) per N.
    per_mass: f32,
    integrator: Integrator,
    /// [`most_damping`], 1/s.
    most_damping: f32,
    /// Whether a run ends where its energy has moved past [`DECIDED`] (always, but in
    /// the tests that hold the decisions to the whole runs').
    decided_early: bool,
}

/// A run of the linearised step in progress ([`Linearised::start`],
/// [`Linearised::advance`]): its state, its coefficients and how far it is.
#[derive(Clone, Debug)]
pub(super) struct Run<const NODES: usize, const EDGES: usize> {
    nodes: [NodeState; NODES],
    /// Per spring `2 κ` (Q24): what its product takes.
    kappa: [i32; EDGES],
    chi: i32,
    chi_node: i32,
    kappa_c: i32,
    chi_c: i32,
    g: u32,
    h: f32,
    symplectic: bool,
    /// Steps run.
    step: usize,
    exp: i32,
    at_window: (f32, i32),
    /// The energy at the start (exponent [`START_EXP`]).
    at_start: f32,
}

impl<const NODES: usize, const EDGES: usize> Run<NODES, EDGES> {
    /// Steps run so far.
    pub(super) fn steps(&self) -> u32 {
        self.step as u32
    }
}

/// Steps of one run at most ([`RUN_STEPS`]).
pub const STEPS_PER_RUN: u32 = RUN_STEPS as u32;

/// A step coefficient in Q24, `None` at or above [`COEFF_LIMIT`] (or not a number).
fn coeff(x: f32) -> Option<i32> {
    if (0.0..COEFF_LIMIT).contains(&x) {
        Some(libm::roundf(x * (1u32 << COEFF_FRAC) as f32) as i32)
    } else {
        None
    }
}

/// One spring's extension along its rest direction, `Σ (x_b − x_a) d` (Q23 direction),
/// in the state's units: within ±3 · 2^(STATE_BITS + 1) for components within
/// ±2^STATE_BITS (each term `⌊(x_b − x_a) 2⁹ d / 2³²⌋`: one `smmul` on the M4F, the
/// difference within 2³¹ after its shift).
#[inline(always)]
fn along(xa: &[i32; 3], xb: &[i32; 3], d: &[i32; 3]) -> i32 {
    const _: () = assert!(STATE_BITS + 1 + (32 - DIR_FRAC) < 32);
    (0..3)
        .map(|j| q::mulhi_round((xb[j] - xa[j]) << (32 - DIR_FRAC), d[j]))
        .sum()
}

impl<'a, const NODES: usize, const EDGES: usize> Linearised<'a, NODES, EDGES> {
    pub(super) fn new(topo: &'a Topology<NODES, EDGES>, k_max: f64, config: &SolverConfig) -> Self {
        let mut row = [(0.0f32, 0u32); NODES];
        let (k_spring, k_row, degree) = spring_rows(
            topo.edges(),
            topo.node_count().min(NODES),
            k_max as f32,
            &mut row,
        );
        Self {
            topo,
            k_max: k_max as f32,
            k_spring,
            k_row,
            degree,
            c_spring: (config.spring_damping / 1000.0) as f32,
            c_node: (config.node_damping / 1000.0) as f32,
            k_c: config.coupling.stiffness as f32,
            b_c: (config.coupling.damping / 1000.0) as f32,
            per_mass: (1000.0 / config.node_mass) as f32,
            integrator: config.integrator,
            most_damping: most_damping(topo, config) as f32,
            decided_early: true,
        }
    }

    /// How much the configured integrator's step `h` grows a perturbation: the ratio of its
    /// energy (kinetic and elastic, which an oscillation trades without changing their
    /// sum, so that the ratio does not depend on the phase it stops at) over the last
    /// [`RUN_WINDOW`] of [`RUN_STEPS`] steps (the first let the decaying modes fall behind
    /// the growing one, as in a power iteration); infinite where it overflows. The run
    /// in one call: [`Self::start`] and [`Self::advance`] run it in pieces.
    #[cfg(test)]
    pub(super) fn growth(&self, h: f64) -> f32 {
        self.growth_in(h).0
    }

    /// [`Self::growth`] and the steps the run took.
    #[cfg(test)]
    pub(super) fn growth_in(&self, h: f64) -> (f32, u32) {
        match self.start(h) {
            Ok(mut run) => loop {
                if let Some(g) = self.advance(&mut run, RUN_STEPS as u32) {
                    return (g, run.steps());
                }
            },
            Err(g) => (g, 0),
        }
    }

    /// A run of the step `h` from its fixed start, or its growth at once where a
    /// coefficient says the step is unstable (infinite).
    ///
    /// In block fixed point, so that a core without an FPU runs it at integer speed (in
    /// software floating point it takes tens of seconds at their clocks): the
    /// displacements `X` (in half units) and the velocities as displacements per step
    /// `V = 2^g v h` share one exponent, `i32` components renormalised after each step to
    /// below 2^[`STATE_BITS`], every product the rounded high word of a long multiply.
    /// With `q = h² D / m`, a spring adds `κ ((X_b − X_a)·d) d` and `χ (V_b − V_a)` to its
    /// end's velocity change per step (`κ = 2^g q k / 2`, `χ = q C / h`; the node damping
    /// and the coupling likewise), so that `V' = V + ΔV` and `X' = X + (V + V') / 2^g`
    /// (`X + 2 V' / 2^g` symplectic, rounded) need no other product. Infinite (unstable)
    /// where a coefficient reaches [`COEFF_LIMIT`] or a node's sum of them [`ROW_LIMIT`]
    /// (a one-mode step is stable only while `h²ω²D < 4` and `h γ D < 2`, and each
    /// coefficient is at most one of those), or where a step grows a component past
    /// [`STATE_LIMIT`].
    pub(super) fn start(&self, h: f64) -> Result<Run<NODES, EDGES>, f32> {
        let n = self.topo.node_count().min(NODES);
        let symplectic = self.integrator == Integrator::SymplecticDamped;
        let d = if symplectic {
            1.0 / (1.0 + h as f32 * self.most_damping)
        } else {
            1.0
        };
        let hf = h as f32;
        let q = hf * hf * self.per_mass * d;
        // `V` carries `g` more bits than `X`, `2^g ≤ 1/(h ω)` for the stiffest node
        // (`(h ω)²` at most its springs' `q k` summed): a slow mode's velocity per step
        // is far below its displacement, and 20 bits of both would leave it a few (its
        // growth was off by up to 0.25 in the logarithm without).
        // (From the exponent of `s` ∈ [2^e, 2^(e+1)): `g = ⌊(−e − 1)/2⌋` within 0…12.)
        let s = q * self.k_row.max(self.k_c);
        let e = ((s.to_bits() >> 23) & 0xFF) as i32 - 127;
        let g = ((-e - 1) / 2).clamp(0, 12) as u32;
        let up = 0.5 * q * (1u32 << g) as f32;
        // Every coefficient below [`COEFF_LIMIT`] (the springs' at most the stiffest's),
        // and every node's springs' coefficients summed below [`ROW_LIMIT`] (at most the
        // stiffest node's `κ` and the most springs' `χ`: a one-mode step is stable only
        // while the sum is below 12, a node's springs' `κ` summing to at most 3 h²ω²D
        // and their `χ` to `h γ D`), so that a node's velocity change from its springs
        // stays within 2^29.6 and sums in an `i32` (see `advance`).
        let chi_f = q * self.c_spring / hf;
        let row = up * self.k_row + self.degree as f32 * chi_f;
        let (Some(_), Some(chi), Some(chi_node), Some(kappa_c), Some(chi_c), true) = (
            coeff(up * self.k_spring),
            coeff(chi_f),
            coeff(q * self.c_node / hf),
            coeff(up * self.k_c),
            coeff(q * self.b_c / hf),
            row < ROW_LIMIT,
        ) else {
            return Err(f32::INFINITY);
        };
        let mut kappa = [0i32; EDGES];
        for (kq, e) in kappa.iter_mut().zip(self.topo.edges()) {
            let k = spring_of(self.k_max, e);
            // (Below 2³⁰: each spring's coefficient is below 32, in Q24.)
            *kq = 2 * libm::roundf(up * k * (1u32 << COEFF_FRAC) as f32) as i32;
        }
        let mut nodes = [NodeState::default(); NODES];
        // A fixed pseudo-random start in every degree of freedom, ±0.5 mm in Q20.
        let mut seed: u32 = 0x2545_f491;
        for node in nodes[..n].iter_mut().skip(1) {
            for c in node.x.iter_mut() {
                seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                *c = ((seed >> 8) as i32 - (1 << 23)) >> 4;
            }
        }
        let at_start = self.energy(&nodes, hf, g);
        Ok(Run {
            nodes,
            kappa,
            chi,
            chi_node,
            kappa_c,
            chi_c,
            g,
            h: hf,
            symplectic,
            step: 0,
            exp: START_EXP,
            at_window: (0.0, 0),
            at_start,
        })
    }

    /// Runs up to `steps` more steps of `run`; its growth once it has run all
    /// [`RUN_STEPS`] (infinite where a step overflowed; its energy over the start's
    /// where that passed [`DECIDED`] first), `None` before. A run that has given its
    /// growth is over ([`Run::steps`] says how many steps it took).
    pub(super) fn advance(&self, run: &mut Run<NODES, EDGES>, steps: u32) -> Option<f32> {
        let k = StepCoeffs {
            chi: run.chi,
            chi_node: run.chi_node,
            kappa_c: run.kappa_c,
            chi_c: run.chi_c,
            g: run.g,
            symplectic: run.symplectic,
            n: self.topo.node_count().min(NODES),
            contact: self.topo.contact() as usize,
        };
        let last = run.step.saturating_add(steps as usize).min(RUN_STEPS);
        let mut sums = [NodeSums::default(); NODES];
        while run.step < last {
            if run.step == RUN_STEPS - RUN_WINDOW {
                run.at_window = (self.energy(&run.nodes, run.h, run.g), run.exp);
            }
            if self.decided_early
                && run.step.is_multiple_of(LOOK_STEPS)
                && (run.exp - START_EXP).abs() >= LOOK_GATE_BITS
            {
                // (Not on an energy of 0, which the springs' mechanisms alone hold: the
                // whole run calls that unstable.)
                let ratio = self.since_start(run);
                if (ratio > 0.0 && ratio < DECIDED) || ratio >= 1.0 / DECIDED {
                    return Some(ratio);
                }
            }
            run.step += 1;
            let edges = self.topo.edges();
            if !step_once(
                edges,
                &run.kappa,
                &mut run.nodes,
                &mut sums,
                &k,
                &mut run.exp,
            ) {
                return Some(f32::INFINITY);
            }
        }
        if run.step < RUN_STEPS {
            return None;
        }
        let e = self.energy(&run.nodes, run.h, run.g);
        let (e0, exp0) = run.at_window;
        Some(if e0 > 0.0 {
            libm::ldexpf(e / e0, 2 * (run.exp - exp0))
        } else {
            f32::INFINITY
        })
    }

    /// The run's energy now over its start's.
    fn since_start(&self, run: &Run<NODES, EDGES>) -> f32 {
        let e = self.energy(&run.nodes, run.h, run.g);
        if run.at_start > 0.0 {
            libm::ldexpf(e / run.at_start, 2 * (run.exp - START_EXP))
        } else {
            f32::INFINITY
        }
    }

    /// The energy at displacements `x` and velocities per step `v` (substep `h`), over
    /// `2^(2 exp)` of the state's exponent: elastic `½ Σ k ((x_b − x_a)·d)²` and the
    /// coupling's (N/mm · units²), kinetic `½ m (v/h)²` in the same unit.
    fn energy(&self, nodes: &[NodeState; NODES], h: f32, g: u32) -> f32 {
        energy_of(
            self.topo.edges(),
            self.k_max,
            nodes,
            self.topo.node_count().min(NODES),
            self.topo.contact() as usize,
            self.k_c,
            self.per_mass,
            h,
            g,
        )
    }
}

/// A spring's `k_max / l0` (N/mm) for the table's largest tangent stiffness `k_max` (N).
fn spring_of(k_max: f32, e: &Edge) -> f32 {
    // `k_max / l0` as `k_max · (1/l0)` in `f32`: two products, where the rest length's
    // quotient and this one took two divisions in software `f64` (each run's start and
    // each look at its energy take one a spring, and a slice of a check on the link may
    // hold both: `case=tissue_check`'s `worst_slice_instructions`).
    k_max * e.inv_len as f32 * (1.0 / (1u64 << crate::units::INV_LEN_FRAC) as f32)
}

/// Each node's sum of its springs' `k_max / l0` and their count into `row`; the
/// stiffest spring, the largest node's sum and the most springs on a node (on slices:
/// one copy for every capacity).
#[inline(never)]
fn spring_rows(
    edges: &[Edge],
    nodes: usize,
    k_max: f32,
    row: &mut [(f32, u32)],
) -> (f32, f32, u32) {
    // (Compares, not `f32::max`: a library call on the M4F.)
    let (mut k_spring, mut k_row, mut degree) = (0.0f32, 0.0f32, 0);
    for e in edges {
        let s = spring_of(k_max, e);
        if s > k_spring {
            k_spring = s;
        }
        for end in [e.a, e.b] {
            if let Some(r) = row.get_mut(end as usize).filter(|_| end != GROUND) {
                *r = (r.0 + s, r.1 + 1);
            }
        }
    }
    for r in row.iter().take(nodes) {
        if r.0 > k_row {
            k_row = r.0;
        }
        degree = degree.max(r.1);
    }
    (k_spring, k_row, degree)
}

/// One node of a run: its displacement and velocity per step.
#[derive(Clone, Copy, Debug, Default)]
struct NodeState {
    x: [i32; 3],
    v: [i32; 3],
}

/// [`Linearised::energy`] on slices (one copy for every capacity).
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn energy_of(
    edges: &[Edge],
    k_max: f32,
    nodes: &[NodeState],
    n: usize,
    c: usize,
    k_c: f32,
    per_mass: f32,
    h: f32,
    g: u32,
) -> f32 {
    let at = |i: u16| nodes.get(i as usize).map_or([0; 3], |node| node.x);
    let mut elastic = 0.0f32;
    for e in edges {
        let s = along(&at(e.a), &at(e.b), &e.dir) as f32;
        elastic += 0.125 * spring_of(k_max, e) * s * s;
    }
    // ½ m v² with m = 1000/per_mass kg and v = V/h: in N·mm per unit² (as the elastic
    // part), 0.5e-3 m / h².
    let w_v = 0.5 / (per_mass * h * h * (1u32 << (2 * g)) as f32);
    let mut kinetic = 0.0f32;
    for node in nodes.iter().take(n).skip(1) {
        for c in &node.v {
            kinetic += (*c as f32) * (*c as f32);
        }
    }
    if let Some(node) = nodes.get(c).filter(|_| c != 0 && c < n) {
        for c in &node.x {
            elastic += 0.125 * k_c * (*c as f32) * (*c as f32);
        }
    }
    elastic + w_v * kinetic
}

mod position;
mod step;
#[cfg(test)]
mod test_growth;
#[cfg(test)]
mod test_step;
