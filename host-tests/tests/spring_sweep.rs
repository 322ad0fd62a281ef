//! One spring over its whole documented state range, idsp style: 10⁶ states per
//! arithmetic (displacements of each end ±64 mm on every axis, every direction, rest
//! lengths 1 … 300 mm for `Wide`, 1 … 16 mm for `Narrow`), the fixed-point kernel against an `f64` model of the same spring
//! with the same documented limits (`docs/accuracy.md`, "One spring"). Every force is
//! within the measured bound of the model's, and never points the wrong way: a
//! stretched spring pulls its ends together, a compressed one pushes them apart.

use crate::common;
use mccs::arith::ArithTable;
use mccs::state::SpringEnds;
use mccs::units::{from_f64, DIR_FRAC, FORCE_FRAC, INV_LEN_FRAC, LEN_FRAC};
use mccs::{Arith, Edge, ForceTable64, Narrow, Params, Wide};
use mccs_host::reference::Reference;
use rand::{Rng, SeedableRng};

/// The documented limits of one arithmetic's spring.
struct Limits {
    /// Whether, where `l0/l` is held, the strain comes from the Newton step's unheld
    /// `l0/l` (`Wide`: `1 − a R (3 − a R²)/2`) or from the held one (`Narrow`: `1 − a R`).
    strain_from_step: bool,
    /// The edge over its rest length, per axis.
    w_cap: f64,
    /// `l0/l`.
    r_max: f64,
    /// Longest rest length, mm.
    l0_max: f64,
    /// The error bound the sweep asserts: `rel` of the larger of the two forces'
    /// magnitudes, plus the law's tangent stiffness times a strain error of
    /// `strain · (1 + l0/l)`, plus `abs` N. The measured figures are printed.
    rel: f64,
    strain: f64,
    abs: f64,
}

const WIDE: Limits = Limits {
    strain_from_step: true,
    w_cap: 2.0,
    r_max: Wide::MAX_RATIO,
    l0_max: 300.0,
    rel: 2e-5,
    strain: 0.0,
    abs: 2e-5,
};
const NARROW: Limits = Limits {
    strain_from_step: false,
    w_cap: 2.0,
    r_max: Narrow::MAX_RATIO,
    l0_max: 16.0,
    rel: 2e-3,
    strain: 1e-3,
    abs: 1e-5,
};

/// The spring's force on end `a` (N) in the `f64` model, the documented limits applied:
/// the edge over its rest length held per axis, `l0/l` held (so that a crushed spring's
/// force fades to zero), the law force within ±64 N, each axis within
/// ±64 N. Also the strain (`1 − a r`, as the kernel forms it) and the law's tangent
/// stiffness there times `1 + l0/l`.
fn model(law: &Reference, lim: &Limits, x: [f64; 3], l0: f64) -> ([f64; 3], f64, f64) {
    let (f, strain, k, _) = model_r(law, lim, x, l0);
    (f, strain, k * (1.0 + r_of(lim, x, l0)))
}

/// `l0/l` as the kernel holds it.
fn r_of(lim: &Limits, x: [f64; 3], l0: f64) -> f64 {
    let a = x
        .map(|c| (c / l0).clamp(-lim.w_cap, lim.w_cap))
        .iter()
        .map(|c| c * c)
        .sum::<f64>();
    if a * lim.r_max * lim.r_max < 1.0 {
        lim.r_max
    } else {
        1.0 / a.sqrt()
    }
}

/// [`model`] with `l0/l`.
fn model_r(law: &Reference, lim: &Limits, x: [f64; 3], l0: f64) -> ([f64; 3], f64, f64, f64) {
    let w = x.map(|c| (c / l0).clamp(-lim.w_cap, lim.w_cap));
    let a = w.iter().map(|c| c * c).sum::<f64>();
    let held = a * lim.r_max * lim.r_max < 1.0;
    let r = if held { lim.r_max } else { 1.0 / a.sqrt() };
    let stretch = if held && lim.strain_from_step {
        a * r * (3.0 - a * r * r) / 2.0
    } else {
        a * r
    };
    let strain = 1.0 - stretch;
    // Beyond the table's domain edge the table's line is the law's tangent there.
    let (_, edge) = mccs::table::DEFAULT_DOMAIN;
    let (f, k) = if strain > edge {
        let k = law.stiffness(edge);
        (law.force(edge) + k * (strain - edge), k)
    } else {
        (law.force(strain), law.stiffness(strain))
    };
    let f = f.clamp(-64.0, 64.0);
    let fr = f * r;
    (w.map(|c| (-fr * c).clamp(-64.0, 64.0)), strain, k, r)
}

/// The error bound of `lim` for a model force of magnitude `scale` (the larger of the
/// two) at tangent stiffness `k` (times `1 + l0/l`, see [`model`]).
fn bound(lim: &Limits, scale: f64, k: f64) -> f64 {
    lim.rel * scale + lim.strain * k + lim.abs
}

/// The arithmetic's warm-start value at `l0/l = r`.
fn warm_of<A: Arith>(r: f64) -> i32 {
    A::warm_of_ratio(r)
}

struct Sweep {
    states: usize,
    worst_rel: f64,
    worst_abs: f64,
    /// The largest error where both forces are below 0.01 N.
    worst_small: f64,
    /// The largest error as a fraction of its bound.
    worst_of_bound: f64,
    held: usize,
}

fn sweep<A: Arith>(name: &str, lim: &Limits, states: usize, seed: u64) -> Sweep {
    let law = Reference::new(&Params::TABLE2).unwrap();
    let table = ArithTable::<64, A>::new(ForceTable64::new(&Params::TABLE2).unwrap());
    let coeffs = common::spring_coeffs::<A>();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut out = Sweep {
        states,
        worst_rel: 0.0,
        worst_abs: 0.0,
        worst_small: 0.0,
        worst_of_bound: 0.0,
        held: 0,
    };
    let q24 = |x: f64| from_f64(x, LEN_FRAC);
    for i in 0..states {
        // Every direction (a quarter of them along an axis), rest lengths from 1 mm to
        // the arithmetic's longest (log-uniform), each end displaced up to ±64 mm per axis (a fifth of the states
        // within ±l0, where the law is curved).
        let dir = if i % 4 == 0 {
            let mut d = [0.0; 3];
            d[rng.random_range(0..3)] = if rng.random() { 1.0 } else { -1.0 };
            d
        } else {
            let v: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
            let n = v.iter().map(|c| c * c).sum::<f64>().sqrt().max(1e-9);
            v.map(|c| c / n)
        };
        let l0 = (rng.random_range(0.0f64..lim.l0_max.ln())).exp().max(1.0);
        let span = if i % 5 == 0 { l0.min(64.0) } else { 64.0 };
        let ua: [f64; 3] = std::array::from_fn(|_| rng.random_range(-span..span));
        let ub: [f64; 3] = std::array::from_fn(|_| rng.random_range(-span..span));
        let edge = Edge {
            a: 1,
            b: 2,
            dir: dir.map(|c| from_f64(c, DIR_FRAC)),
            inv_len: from_f64(1.0 / l0, INV_LEN_FRAC),
        };
        // The model on the geometry as the kernel stores it (rounded direction, 1/l0).
        let l0q = (1u64 << INV_LEN_FRAC) as f64 / edge.inv_len as f64;
        let dq = edge.dir.map(|c| c as f64 / (1u64 << DIR_FRAC) as f64);
        let uaq = ua.map(|c| q24(c) as f64 / (1u64 << LEN_FRAC) as f64);
        let ubq = ub.map(|c| q24(c) as f64 / (1u64 << LEN_FRAC) as f64);
        let x: [f64; 3] = std::array::from_fn(|k| dq[k] * l0q + ubq[k] - uaq[k]);
        let (want, strain, k) = model(&law, lim, x, l0q);
        let ends = SpringEnds {
            ua: ua.map(q24),
            ub: ub.map(q24),
            va: [0; 3],
            vb: [0; 3],
        };
        // Warm-started at the converged l0/l (as in steady operation), then two steps.
        let a = x
            .map(|c| (c / l0q).clamp(-lim.w_cap, lim.w_cap))
            .iter()
            .map(|c| c * c)
            .sum::<f64>();
        let mut warm = warm_of::<A>((1.0 / a.sqrt()).min(lim.r_max * 0.999));
        let mut got = [0; 3];
        for _ in 0..3 {
            got = A::spring(&table, &coeffs, &edge, &ends, &mut warm);
        }
        let got = got.map(|c| c as f64 / (1u64 << FORCE_FRAC) as f64);
        let mag = |v: [f64; 3]| v.iter().map(|c| c * c).sum::<f64>().sqrt();
        let scale = mag(want).max(mag(got));
        let err = mag(std::array::from_fn(|k| got[k] - want[k]));
        assert!(
            err <= bound(lim, scale, k),
            "{name}: state {i}: l0 {l0:.4} mm, dir {dir:?}, ua {ua:?}, ub {ub:?}: force {got:?}, model {want:?} (strain {strain:.6})"
        );
        // The direction: along the edge, a stretched spring pulls a towards b, a
        // compressed one pushes it away (where the force is above the resolution).
        let along: f64 = (0..3).map(|k| got[k] * x[k]).sum();
        if mag(want) > 2.0 * bound(lim, scale, k) {
            if strain < 0.0 {
                assert!(
                    along > 0.0,
                    "{name}: state {i}: stretched (strain {strain}) but pushes: {got:?}"
                );
            } else if strain > 0.0 {
                assert!(
                    along < 0.0,
                    "{name}: state {i}: compressed (strain {strain}) but pulls: {got:?}"
                );
            }
        }
        if x.iter().any(|c| (c / l0q).abs() > lim.w_cap) || want.iter().any(|c| c.abs() >= 64.0) {
            out.held += 1;
        }
        out.worst_of_bound = out.worst_of_bound.max(err / bound(lim, scale, k));
        if scale > 0.01 {
            out.worst_rel = out.worst_rel.max(err / scale);
        } else {
            out.worst_small = out.worst_small.max(err);
        }
        out.worst_abs = out.worst_abs.max(err);
    }
    out
}

fn report(name: &str, s: &Sweep) {
    println!(
        "SWEEP arith={name} states={} held_at_a_limit={} max_error_rel={:.2e} max_error_abs_n={:.2e} max_error_below_10mn={:.2e} max_error_of_bound={:.2}",
        s.states, s.held, s.worst_rel, s.worst_abs, s.worst_small, s.worst_of_bound
    );
}

#[test]
fn wide_spring_over_its_whole_state_range() {
    let s = sweep::<Wide>("wide", &WIDE, 1_000_000, 1);
    report("wide", &s);
}

#[test]
fn narrow_spring_over_its_whole_state_range() {
    let s = sweep::<Narrow>("narrow", &NARROW, 1_000_000, 2);
    report("narrow", &s);
}

/// From rest (`A::REST`), after a jump to any state, the warm-started Newton converges:
/// 60 steps reach the converged force (the solver takes one per substep).
#[test]
fn both_springs_recover_from_rest_after_any_jump() {
    fn from_rest<A: Arith>(lim: &Limits) {
        let law = Reference::new(&Params::TABLE2).unwrap();
        let table = ArithTable::<64, A>::new(ForceTable64::new(&Params::TABLE2).unwrap());
        let coeffs = common::spring_coeffs::<A>();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..10_000 {
            let l0: f64 = rng.random_range(1.0..20.0);
            let ub: [f64; 3] = std::array::from_fn(|_| rng.random_range(-3.0 * l0..3.0 * l0));
            let edge = Edge {
                a: 1,
                b: 2,
                dir: [0, 0, -(1 << DIR_FRAC)],
                inv_len: from_f64(1.0 / l0, INV_LEN_FRAC),
            };
            let l0q = (1u64 << INV_LEN_FRAC) as f64 / edge.inv_len as f64;
            let ubq = ub.map(|c| from_f64(c, LEN_FRAC) as f64 / (1u64 << LEN_FRAC) as f64);
            let x = [ubq[0], ubq[1], ubq[2] - l0q];
            let (want, _, k) = model(&law, lim, x, l0q);
            let ends = SpringEnds {
                ub: ub.map(|c| from_f64(c, LEN_FRAC)),
                ..SpringEnds::default()
            };
            let mut warm = A::REST;
            let mut got = [0; 3];
            for _ in 0..60 {
                got = A::spring(&table, &coeffs, &edge, &ends, &mut warm);
            }
            let got = got.map(|c| c as f64 / (1u64 << FORCE_FRAC) as f64);
            let scale = want
                .iter()
                .chain(got.iter())
                .fold(0.0f64, |m, c| m.max(c.abs()));
            for i in 0..3 {
                assert!(
                    (got[i] - want[i]).abs() <= 2.0 * bound(lim, scale, k),
                    "{}: l0 {l0}, ub {ub:?}: {got:?} vs {want:?}",
                    std::any::type_name::<A>()
                );
            }
        }
    }
    from_rest::<Wide>(&WIDE);
    from_rest::<Narrow>(&NARROW);
}
