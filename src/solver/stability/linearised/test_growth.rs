//! The linearised step's tests: its growth against the same step in plain `f64`, and the
//! coefficient and state limits that call a step unstable.

use super::super::closed_form;
use super::*;
use crate::{ForceTable64, Params};

/// The linearised step of [`Linearised::growth`] in plain `f64` from the same start:
/// the energy ratio over the last [`RUN_WINDOW`] of [`RUN_STEPS`] steps, or where the
/// run ends at `steps` before that (its energy fallen away), the energy then over the
/// start's.
fn growth_f64<const NODES: usize, const EDGES: usize>(
    lin: &Linearised<'_, NODES, EDGES>,
    h: f64,
    steps: usize,
) -> f64 {
    let n = lin.topo.node_count();
    let symplectic = lin.integrator == Integrator::SymplecticDamped;
    let d = if symplectic {
        1.0 / (1.0 + h * lin.most_damping as f64)
    } else {
        1.0
    };
    let hm = h * lin.per_mass as f64 * d;
    let mut x = [[0.0f64; 3]; NODES];
    let mut v = [[0.0f64; 3]; NODES];
    let mut seed: u32 = 0x2545_f491;
    for xi in x[1..n].iter_mut() {
        for c in xi.iter_mut() {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            *c = ((((seed >> 8) as i32 - (1 << 23)) >> 4) as f64) / (1 << 20) as f64;
        }
    }
    let dir = |e: &crate::topology::Edge| e.dir.map(|c| c as f64 / (1 << DIR_FRAC) as f64);
    let c = lin.topo.contact() as usize;
    let energy = |x: &[[f64; 3]; NODES], v: &[[f64; 3]; NODES]| -> f64 {
        let mut e = 0.0;
        for edge in lin.topo.edges() {
            let k = spring_of(lin.k_max, edge);
            let dd = dir(edge);
            let s: f64 = (0..3)
                .map(|j| (x[edge.b as usize][j] - x[edge.a as usize][j]) * dd[j])
                .sum();
            e += 0.5 * k as f64 * s * s;
        }
        for j in 0..3 {
            e += 0.5 * lin.k_c as f64 * x[c][j] * x[c][j];
        }
        let mass = 1.0 / lin.per_mass as f64;
        e + v[1..n]
            .iter()
            .flatten()
            .map(|w| 0.5 * mass * w * w)
            .sum::<f64>()
    };
    let (mut at_window, mut scale) = (energy(&x, &v), 0.0);
    for step in 0..steps.min(RUN_STEPS) {
        if step == RUN_STEPS - RUN_WINDOW && steps >= RUN_STEPS {
            at_window = energy(&x, &v);
            scale = 0.0;
        }
        let mut f = [[0.0f64; 3]; NODES];
        for edge in lin.topo.edges() {
            let k = spring_of(lin.k_max, edge);
            let (a, b) = (edge.a as usize, edge.b as usize);
            let dd = dir(edge);
            let s: f64 = (0..3).map(|j| (x[b][j] - x[a][j]) * dd[j]).sum();
            for j in 0..3 {
                let on_a = k as f64 * s * dd[j] + lin.c_spring as f64 * (v[b][j] - v[a][j]);
                f[a][j] += on_a;
                f[b][j] -= on_a;
            }
        }
        for i in 1..n {
            for j in 0..3 {
                let mut fi = f[i][j] - lin.c_node as f64 * v[i][j];
                if i == c {
                    fi -= lin.k_c as f64 * x[i][j] + lin.b_c as f64 * v[i][j];
                }
                let v_new = v[i][j] + hm * fi;
                let from = if symplectic { v_new } else { v[i][j] };
                x[i][j] += 0.5 * h * (from + v_new);
                v[i][j] = v_new;
            }
        }
        // Renormalised by powers of two, counted: only the ratio matters.
        let e = energy(&x, &v);
        if e > 1e100 || (e > 0.0 && e < 1e-100) {
            let s = if e > 1.0 { -100.0 } else { 100.0 };
            let k = libm::exp2(s / 2.0);
            x.iter_mut().flatten().for_each(|c| *c *= k);
            v.iter_mut().flatten().for_each(|c| *c *= k);
            scale -= s;
        }
    }
    energy(&x, &v) / at_window * libm::exp2(scale)
}

/// The fixed-point step's growth is the `f64` step's, on the standard N = 3 and
/// N = 4 patches with the defaults and a light and a heavy damping, both integrators,
/// from a sixteenth of the closed form to four times it: the same side of 1 wherever
/// the `f64` growth is not within 1 % of it, and the same logarithm within 1e-2 and
/// 1e-3 of its magnitude (measured: 5.1e-3 near 1, 5.6e-4 relative far from it, as
/// its `LINEARISED case=growth_vs_f64` line prints them);
/// infinite (unstable) only where the `f64` step grows.
#[test]
fn the_fixed_point_growth_is_the_f64_steps() {
    let table = ForceTable64::new(&Params::TABLE2).unwrap();
    let k_max = table.max_stiffness().to_num::<f64>();
    let mut compared = 0;
    // The worst difference of the logarithms where the growth is within a factor e of
    // 1, and relative to the logarithm beyond.
    let worst = core::cell::Cell::new((0.0f64, 0.0f64));
    for integrator in [Integrator::ImprovedEuler, Integrator::SymplecticDamped] {
        for (spring_damping, node_damping) in [(1.0, 0.05), (0.05, 0.05), (10.0, 0.5)] {
            let config = SolverConfig {
                integrator,
                spring_damping,
                node_damping,
                ..SolverConfig::default()
            };
            let topo3 = Topology::<2, 9>::standard_patch(3, 2.5).unwrap();
            let topo4 = Topology::<5, 30>::standard_patch(4, 2.5).unwrap();
            let check = |fixed: f32, float: f64, what: &str| {
                if fixed.is_infinite() {
                    assert!(float > 1.0, "{what}: infinite against {float}");
                } else if fixed == 0.0 {
                    // (Below `f32`'s range.)
                    assert!(float < 1e-30, "{what}: 0 against {float}");
                } else {
                    let fixed = fixed as f64;
                    let (lf, lg) = (fixed.ln(), float.ln());
                    if lg.abs() > 0.01 {
                        assert_eq!(fixed <= 1.0, float <= 1.0, "{what}: {fixed} vs {float}");
                    }
                    assert!(
                        (lf - lg).abs() <= 1e-2 + 1e-3 * lg.abs(),
                        "{what}: {fixed} vs {float}"
                    );
                    let (near, far) = worst.get();
                    worst.set(if lg.abs() <= 1.0 {
                        (near.max((lf - lg).abs()), far)
                    } else {
                        (near, far.max((lf - lg).abs() / lg.abs()))
                    });
                }
            };
            let closed3 = closed_form(&topo3, k_max, &config).unwrap();
            let lin3 = Linearised::new(&topo3, k_max, &config);
            let closed4 = closed_form(&topo4, k_max, &config).unwrap();
            let lin4 = Linearised::new(&topo4, k_max, &config);
            for f in [0.0625, 0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0] {
                let what = format!("{integrator:?} C={spring_damping} c={node_damping} {f}×closed");
                let (g3, steps3) = lin3.growth_in(f * closed3);
                let (g4, steps4) = lin4.growth_in(f * closed4);
                check(
                    g3,
                    growth_f64(&lin3, f * closed3, steps3 as usize),
                    &format!("N=3 {what}"),
                );
                check(
                    g4,
                    growth_f64(&lin4, f * closed4, steps4 as usize),
                    &format!("N=4 {what}"),
                );
                compared += 2;
            }
        }
    }
    assert_eq!(compared, 96);
    let (near, far) = worst.get();
    std::println!(
        "LINEARISED case=growth_vs_f64 worst_log_near_1={near:.1e} \
         worst_log_relative_far={far:.1e}"
    );
}

/// Past the limits the step is unstable without running: a coefficient at 32 or
/// more (a substep a thousand times the closed form), and the start's growth is
/// finite and below 1 at a hundredth of it.
#[test]
fn the_limits_call_a_step_unstable() {
    let table = ForceTable64::new(&Params::TABLE2).unwrap();
    let k_max = table.max_stiffness().to_num::<f64>();
    let config = SolverConfig::default();
    let topo = Topology::<5, 30>::standard_patch(4, 2.5).unwrap();
    let closed = closed_form(&topo, k_max, &config).unwrap();
    let lin = Linearised::new(&topo, k_max, &config);
    assert_eq!(lin.growth(1000.0 * closed), f32::INFINITY);
    assert!(coeff(COEFF_LIMIT).is_none() && coeff(f32::NAN).is_none());
    assert_eq!(
        coeff(COEFF_LIMIT * 0.999),
        Some(((COEFF_LIMIT * 0.999) * (1u32 << 24) as f32) as i32)
    );
    let g = lin.growth(0.01 * closed);
    assert!(g.is_finite() && g < 1.0, "{g}");
}

/// Runs, runs ended early, their steps and the whole runs' ([`compare_with_whole`]).
#[derive(Default)]
struct Ended {
    runs: u32,
    early: u32,
    steps: u64,
    whole_steps: u64,
}

/// Each run of `lin` from a sixteenth of `closed` to four times it (geometric steps of
/// 2^¼) decides as the whole run does (see below).
fn compare_with_whole<const N: usize, const E: usize>(
    topo: &Topology<N, E>,
    k_max: f64,
    config: &SolverConfig,
    tally: &mut Ended,
) {
    let closed = closed_form(topo, k_max, config).unwrap();
    let mut lin = Linearised::new(topo, k_max, config);
    let trusted = super::super::TRUSTED_DECAY;
    let what = format!("N={N} {config:?}");
    for k in -16..=8 {
        let h = closed * libm::exp2(k as f64 / 4.0);
        lin.decided_early = true;
        let (g, ran) = lin.growth_in(h);
        lin.decided_early = false;
        let (whole, whole_ran) = lin.growth_in(h);
        assert_eq!(
            g <= 1.0,
            whole <= 1.0,
            "{what} h={h:e}: {g} against {whole}"
        );
        assert_eq!(
            g <= trusted,
            whole <= trusted,
            "{what} h={h:e}: {g} against {whole}"
        );
        if ran < whole_ran {
            assert!(
                !(DECIDED..1.0 / DECIDED).contains(&g),
                "{what} h={h:e}: ended at {ran} with {g}"
            );
            tally.early += 1;
        }
        tally.runs += 1;
        tally.steps += ran as u64;
        tally.whole_steps += whole_ran as u64;
    }
}

/// A run that ends where its energy has fallen to [`DECIDED`] of its start's, or grown to
/// its inverse times it, decides as the whole run does: stable (growth at most 1) and trusted (at most [`super::super::TRUSTED_DECAY`])
/// alike, on the standard N = 3, 4, 5 and 8 patches, both integrators, a light, the
/// default and a heavy damping, from a sixteenth of the closed form to four times it.
/// How many runs end early and the steps they take is printed (`LINEARISED
/// case=decided_early`).
#[test]
fn a_run_ended_by_its_energy_decides_as_the_whole_run() {
    let table = ForceTable64::new(&Params::TABLE2).unwrap();
    let k_max = table.max_stiffness().to_num::<f64>();
    let mut tally = Ended::default();
    for integrator in [Integrator::ImprovedEuler, Integrator::SymplecticDamped] {
        for (spring_damping, node_damping) in [(0.05, 0.05), (1.0, 0.05), (10.0, 0.5)] {
            let config = SolverConfig {
                integrator,
                spring_damping,
                node_damping,
                ..SolverConfig::default()
            };
            let t = &mut tally;
            compare_with_whole(
                &Topology::<2, 9>::standard_patch(3, 2.5).unwrap(),
                k_max,
                &config,
                t,
            );
            compare_with_whole(
                &Topology::<5, 30>::standard_patch(4, 2.5).unwrap(),
                k_max,
                &config,
                t,
            );
            compare_with_whole(
                &Topology::<10, 61>::standard_patch(5, 2.5).unwrap(),
                k_max,
                &config,
                t,
            );
            compare_with_whole(
                &Topology::<37, 214>::standard_patch(8, 2.5).unwrap(),
                k_max,
                &config,
                t,
            );
        }
    }
    let Ended {
        runs,
        early,
        steps,
        whole_steps,
    } = tally;
    assert!(early > runs / 4, "{early} of {runs} runs ended early");
    std::println!(
        "LINEARISED case=decided_early runs={runs} ended_early={early} steps_of_whole_pct={}",
        100 * steps / whole_steps
    );
}
