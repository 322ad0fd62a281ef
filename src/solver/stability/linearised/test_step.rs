//! The linearised step's `i32` kernel against the same step written plainly in `i64`:
//! the same state and the same verdict, on random states, coefficients and shifts up to
//! their limits, and its position step over the whole range of its input.

use super::position::PositionStep;
use super::*;

/// `a b / 2^frac` rounded to nearest, in `i64` (exact for the step's operands).
fn round_product(a: i32, b: i32, frac: u32) -> i64 {
    (a as i64 * b as i64 + (1i64 << (frac - 1))) >> frac
}

/// The linearised step of [`Linearised::start`] written plainly in `i64`: every product
/// `a b / 2^frac` rounded, a spring's damping the difference of its ends' `χ V`, each
/// rounded (as [`step_once`] takes it), the position step
/// `X + (S + half) >> g` with `S = V + V'` or `2 V'`; `None` where a component reaches
/// [`STATE_LIMIT`], else the state renormalised and its exponent's change. The reference
/// [`step_once`] must equal (`kappa` each spring's `κ` in plain Q24, not doubled).
fn step_once_i64(
    edges: &[Edge],
    kappa: &[i32; 61],
    k: &StepCoeffs,
    x: &mut [[i32; 3]; 10],
    v: &mut [[i32; 3]; 10],
) -> Option<i32> {
    let (n, c) = (k.n, k.contact);
    let mut dv = [[0i64; 3]; 10];
    for (e, &kq) in edges.iter().zip(kappa.iter()) {
        let (a, b) = (e.a as usize, e.b as usize);
        let along: i64 = (0..3)
            .map(|j| round_product(x[b][j] - x[a][j], e.dir[j], DIR_FRAC))
            .sum();
        let stretch = round_product(along as i32, kq, COEFF_FRAC);
        for j in 0..3 {
            let on_a = round_product(stretch as i32, e.dir[j], DIR_FRAC)
                + round_product(v[b][j], k.chi, COEFF_FRAC)
                - round_product(v[a][j], k.chi, COEFF_FRAC);
            dv[a][j] += on_a;
            dv[b][j] -= on_a;
        }
    }
    let mut magnitude = 0u64;
    for i in 1..n {
        for j in 0..3 {
            let (xi, vi) = (x[i][j] as i64, v[i][j] as i64);
            let mut dvi = dv[i][j] - round_product(v[i][j], k.chi_node, COEFF_FRAC);
            if i == c {
                dvi -= round_product(x[i][j], k.kappa_c, COEFF_FRAC)
                    + round_product(v[i][j], k.chi_c, COEFF_FRAC);
            }
            let v_new = vi + dvi;
            let s = if k.symplectic { 2 * v_new } else { vi + v_new };
            let x_new = xi + ((s + ((1i64 << k.g) >> 1)) >> k.g);
            let grown = x_new.unsigned_abs() | v_new.unsigned_abs();
            if grown >= STATE_LIMIT as u64 {
                return None;
            }
            (x[i][j], v[i][j]) = (x_new as i32, v_new as i32);
            magnitude |= grown;
        }
    }
    let bits = u64::BITS - magnitude.leading_zeros();
    let up = if bits > STATE_BITS || (magnitude != 0 && bits < STATE_BITS - 1) {
        (STATE_BITS - 1) as i32 - bits as i32
    } else {
        0
    };
    for i in 0..n {
        for j in 0..3 {
            (x[i][j], v[i][j]) = if up >= 0 {
                (x[i][j] << up, v[i][j] << up)
            } else {
                (x[i][j] >> -up, v[i][j] >> -up)
            };
        }
    }
    Some(-up)
}

/// A small deterministic generator (xorshift32).
struct Rng(u32);

impl Rng {
    fn next(&mut self) -> u32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 17;
        self.0 ^= self.0 << 5;
        self.0
    }

    /// Uniform in `±2^bits` (`bits` ≤ 31).
    fn signed(&mut self, bits: u32) -> i32 {
        let m = (1u64 << bits) as i64;
        ((self.next() as i64 % (2 * m)) - m) as i32
    }

    /// Uniform in `0 … 2^bits`.
    fn coeff(&mut self, bits: u32) -> i32 {
        (self.next() as u64 % (1u64 << bits)) as i32
    }
}

/// The `i64` position step (the reference's): `X'`, or `None` past the limit.
fn position_i64(x: i32, v: i32, v_new: i32, g: u32, symplectic: bool) -> Option<i32> {
    let step = if symplectic {
        2 * v_new as i64
    } else {
        v as i64 + v_new as i64
    };
    let x_new = x as i64 + ((step + ((1i64 << g) >> 1)) >> g);
    let grown = x_new.unsigned_abs() | v_new.unsigned_abs() as u64;
    (grown < STATE_LIMIT as u64).then_some(x_new as i32)
}

/// [`PositionStep::advance`] is the `i64` step for `X`, `V` within ±2²¹, every `g` and
/// both integrators, and `V'` over the whole `i32` range: random, and each value within
/// 4 of 0, ±2³⁰, ±2³¹ and of the limits' edges for `X'`.
#[test]
fn the_position_step_is_the_i64_steps() {
    let mut rng = Rng(0x2545_f491);
    let mut special = std::vec::Vec::new();
    for c in [0i64, 1 << 29, 1 << 30, 1 << 31, (1 << 31) - (1 << 21)] {
        for d in -4..=4 {
            for s in [-1, 1] {
                special.push((s * c + d).clamp(i32::MIN as i64, i32::MAX as i64) as i32);
            }
        }
    }
    let (mut within, mut past) = (0u32, 0u32);
    for g in 0..=12 {
        for symplectic in [false, true] {
            let p = PositionStep::new(symplectic, g);
            for k in 0..40_000 {
                let x = rng.signed(21).clamp(1 - (1 << 21), (1 << 21) - 1);
                let v = rng.signed(21).clamp(1 - (1 << 21), (1 << 21) - 1);
                let v_new = match k % 3 {
                    0 => special[(rng.next() as usize) % special.len()],
                    1 => rng.next() as i32,
                    // Near the limit, where X' crosses it.
                    _ => {
                        let bits = 31 - rng.next() % 4;
                        rng.signed(bits)
                    }
                };
                let got = p.advance(x, v, v_new);
                assert_eq!(
                    got,
                    position_i64(x, v, v_new, g, symplectic),
                    "x={x} v={v} v'={v_new} g={g} {symplectic}"
                );
                if got.is_some() {
                    within += 1;
                } else {
                    past += 1;
                }
            }
        }
    }
    assert!(
        within > 100_000 && past > 100_000,
        "{within} within, {past} past"
    );
}

/// 20,000 random steps of the standard N = 4 and N = 5 patches: coefficients up to the
/// limits (a spring's `κ` and `χ` below 2, so that each node's sum is within its row's;
/// the node's and the coupling's below 32, in Q24), states within ±2²¹ with magnitudes
/// from 2⁸ up and a quarter at ±(2²¹ − 1), every `g` in 0…12 and both integrators:
/// the kernel's state and exponent are the plain `i64` step's on each. (Within the
/// limits a step never reaches the state's limit: that path is
/// [`the_position_step_is_the_i64_steps`]'.)
#[test]
fn the_step_is_the_i64_steps() {
    let t4 = Topology::<10, 61>::standard_patch(4, 2.5).unwrap();
    let t5 = Topology::<10, 61>::standard_patch(5, 2.5).unwrap();
    let mut rng = Rng(0x9e37_79b9);
    for case in 0..20_000 {
        let topo = if case % 2 == 0 { &t4 } else { &t5 };
        let (n, c, edges) = (topo.node_count(), topo.contact() as usize, topo.edges());
        let extreme = case % 4 == 1;
        let reach = 18 + rng.next() % 12;
        let (spring_bits, node_bits) = (reach.min(25), reach.min(29));
        let k = StepCoeffs {
            chi: rng.coeff(spring_bits),
            chi_node: rng.coeff(node_bits),
            kappa_c: rng.coeff(node_bits),
            chi_c: rng.coeff(node_bits),
            g: rng.next() % 13,
            symplectic: rng.next().is_multiple_of(2),
            n,
            contact: c,
        };
        let mut kappa = [0; 61];
        for kq in kappa.iter_mut().take(edges.len()) {
            *kq = if extreme {
                1 << spring_bits
            } else {
                rng.coeff(spring_bits)
            };
        }
        let bits = 8 + rng.next() % 14;
        let mut nodes = [NodeState::default(); 10];
        for node in nodes.iter_mut().take(n).skip(1) {
            for j in 0..3 {
                for w in [&mut node.x[j], &mut node.v[j]] {
                    *w = match (extreme, rng.next() % 2) {
                        (true, 0) => (1 << 21) - 1,
                        (true, _) => 1 - (1 << 21),
                        _ => rng.signed(bits).clamp(1 - (1 << 21), (1 << 21) - 1),
                    };
                }
            }
        }
        let mut x_ref = nodes.map(|node| node.x);
        let mut v_ref = nodes.map(|node| node.v);
        let exp_ref = step_once_i64(edges, &kappa, &k, &mut x_ref, &mut v_ref);
        let twice = kappa.map(|kq| 2 * kq);
        let mut exp = 0;
        let mut sums = [NodeSums::default(); 10];
        let ok = step_once(edges, &twice, &mut nodes, &mut sums, &k, &mut exp);
        assert_eq!(ok, exp_ref.is_some(), "case {case}: the verdict");
        assert_eq!(exp_ref, Some(exp), "case {case}: the exponent");
        let state = (nodes.map(|node| node.x), nodes.map(|node| node.v));
        assert_eq!(state, (x_ref, v_ref), "case {case}: the state");
    }
}
