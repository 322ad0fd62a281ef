//! One step of the linearised patch ([`step_once`]), in block fixed point: its fixed
//! coefficients, its per-node scratch and its products.

use super::position::PositionStep;
use super::{along, NodeState, COEFF_FRAC, STATE_BITS};
use crate::q;
use crate::topology::Edge;
use crate::units::DIR_FRAC;

/// [`q::mulhi_round`] (`a b / 2³²` rounded to nearest, exact: a floor's bias acts as
/// a damping over the run, measured up to 0.4 in the logarithm of a lightly damped
/// patch's growth) for the step's products per node: one instruction where the core has
/// a long multiply, else out of line (the M0 builds it from 16-bit pieces). The springs'
/// loop takes [`q::mulhi_round`] itself, inlined on every core: its seven products a
/// spring are most of the M0's step (inlined there, 1.5 % faster for 1.2 KB of flash).
#[inline(always)]
fn mulhi(a: i32, b: i32) -> i32 {
    if q::HAS_LONG_MULTIPLY {
        q::mulhi_round(a, b)
    } else {
        mulhi_out_of_line(a, b)
    }
}

#[inline(never)]
fn mulhi_out_of_line(a: i32, b: i32) -> i32 {
    q::mulhi_round_split(a, b)
}

/// What a step sums on one node, side by side so that a spring reaches each end's
/// through one address (a step's scratch, on the stack of [`super::Linearised::advance`]: not
/// in the [`super::Run`], which the M0's start-up holds more than once on its 16 KiB).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct NodeSums {
    /// Its velocity as the springs' damping takes it, `χ V` (one product per node, not
    /// per spring).
    pub(super) damped: [i32; 3],
    /// The springs' change to its velocity.
    pub(super) dv: [i32; 3],
}

/// A run's fixed coefficients and its patch's shape, for [`step_once`].
#[derive(Clone, Copy)]
pub(super) struct StepCoeffs {
    pub(super) chi: i32,
    pub(super) chi_node: i32,
    pub(super) kappa_c: i32,
    pub(super) chi_c: i32,
    pub(super) g: u32,
    pub(super) symplectic: bool,
    /// Node slots in use (the ground's included).
    pub(super) n: usize,
    pub(super) contact: usize,
}

/// One step of the linearised patch (see [`super::Linearised::start`]), on slices: one copy of
/// the loop for every patch's capacity (monomorphised per capacity, it was five copies
/// of 10 KB in the bench firmware). False where a component grew past [`super::STATE_LIMIT`]
/// (the step is unstable). Every sum is an `i32` (the bounds are argued where each is
/// formed; [`PositionStep`] for the positions').
// Whole on purpose (over 80 lines): the kernel mirrors the solver's substep line by line
// (springs, then nodes, then the coupling), which is what the stability proof relies on;
// split, it would no longer read against the substep in `solver/step.rs`.
#[inline(never)]
pub(super) fn step_once(
    edges: &[Edge],
    kappa: &[i32],
    nodes: &mut [NodeState],
    sums: &mut [NodeSums],
    k: &StepCoeffs,
    exp: &mut i32,
) -> bool {
    let StepCoeffs {
        chi,
        chi_node,
        kappa_c,
        chi_c,
        g,
        symplectic,
        n,
        contact: c,
    } = *k;
    // One length for both (so that an index checked once is in bounds of each).
    let len = nodes.len().min(sums.len());
    let (nodes, sums) = (&mut nodes[..len], &mut sums[..len]);
    for (node, sum) in nodes.iter().zip(sums.iter_mut()) {
        sum.dv = [0; 3];
        sum.damped = node.v.map(|vj| mulhi(vj << 8, chi));
    }
    // (Slot 0 is the ground: its state stays zero, and what its springs add to its
    // velocity change is never read.) With components within ±2^STATE_BITS (2²¹) the
    // extension is within 2^23.6, so a spring's stretch and push are within `κ` · 2^23.6
    // < 2^28.6 and its damping `χ V_b − χ V_a` within 2 · 2²¹ · 32 = 2²⁷; a node's
    // sum, within its row's 64 · 2^23.6, fits an `i32`. Each product is a rounded high
    // word (`a b / 2³²`, exact) with its operands shifted up within 2³¹:
    // `along · κ / 2²⁴`, `stretch · d / 2²³`, and once per node `V χ / 2²⁴`.
    const _: () = assert!(COEFF_FRAC == 24 && DIR_FRAC == 23 && STATE_BITS == 21);
    for (e, &kq) in edges.iter().zip(kappa.iter()) {
        let (a, b) = (e.a as usize, e.b as usize);
        if a >= len || b >= len {
            continue;
        }
        let stretch = q::mulhi_round(along(&nodes[a].x, &nodes[b].x, &e.dir) << 7, kq);
        for j in 0..3 {
            let on_a = q::mulhi_round(stretch << 2, e.dir[j] << 7)
                + (sums[b].damped[j] - sums[a].damped[j]);
            sums[a].dv[j] = sums[a].dv[j].wrapping_add(on_a);
            sums[b].dv[j] = sums[b].dv[j].wrapping_sub(on_a);
        }
    }
    let position = PositionStep::new(symplectic, g);
    let mut magnitude = 0u32;
    // (An iterator, not indices: 1.5 % fewer instructions in the M4F's check.)
    for (i, (node, sum)) in nodes
        .iter_mut()
        .zip(sums.iter())
        .enumerate()
        .take(n)
        .skip(1)
    {
        for j in 0..3 {
            let (xi, vi) = (node.x[j], node.v[j]);
            // The springs' change within 2^29.6 (their row), each node term within 2²⁶
            // (`χ`, `κ` < 32 on components within 2²¹): all within `i32`.
            let mut dvi = sum.dv[j] - mulhi(vi << 8, chi_node);
            if i == c {
                dvi -= mulhi(xi << 8, kappa_c) + mulhi(vi << 8, chi_c);
            }
            let v_new = vi + dvi;
            let Some(x_new) = position.advance(xi, vi, v_new) else {
                return false;
            };
            node.x[j] = x_new;
            node.v[j] = v_new;
            magnitude |= x_new.unsigned_abs() | v_new.unsigned_abs();
        }
    }
    // Renormalise: the largest component back into [2^(STATE_BITS − 2), 2^STATE_BITS)
    // (only the growth matters). (Slot 0, the ground, stays zero either way.)
    let bits = u32::BITS - magnitude.leading_zeros();
    let up = if bits > STATE_BITS || (magnitude != 0 && bits < STATE_BITS - 1) {
        (STATE_BITS - 1) as i32 - bits as i32
    } else {
        0
    };
    if up != 0 {
        for node in nodes.iter_mut().take(n) {
            for j in 0..3 {
                (node.x[j], node.v[j]) = if up > 0 {
                    (node.x[j] << up, node.v[j] << up)
                } else {
                    (node.x[j] >> -up, node.v[j] >> -up)
                };
            }
        }
        *exp -= up;
    }
    true
}
