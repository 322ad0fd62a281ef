//! The stability bound against the exact one: the eigenvalues of the improved Euler's
//! one-step matrix on the linearised patch (`mccs_host::stability`), at rest and at
//! deformed states; and in the `f64` twin, the energy decays at the chosen substep and
//! grows at 1.5 times the exact bound.

use mccs::solver::stability::{bounds, CONSERVATIVE_FACTOR, ESTIMATE_MARGIN};
use mccs::{Bound, Coupling, ForceTable64, Integrator, Params, SolverConfig, Topology};
use mccs_host::patch::{Mesh, Twin, TwinConfig};
use mccs_host::reference::Reference;
use mccs_host::stability::{Linear, Stiffness};

use crate::common::{cases, run_cases, seed};

/// Room for the N = 10 patch, the board's.
type Topo = Topology<65, 366>;

fn table() -> ForceTable64 {
    ForceTable64::new(&Params::TABLE2).unwrap()
}

/// The core's bounds and the exact one (s) for the standard patch.
fn compare(n: usize, spacing: f64, cfg: &SolverConfig) -> (mccs::solver::Bounds, f64) {
    let t = table();
    let topo = Topo::standard_patch(n, spacing).unwrap();
    let b = bounds(&topo, &t, cfg).unwrap();
    let k_max = t.max_stiffness().to_num::<f64>();
    let lin = Linear::new(
        &Mesh::standard(n, spacing),
        &TwinConfig::from_solver(cfg, 1),
        Stiffness::AtRest(k_max),
    );
    (b, lin.exact_bound(0.02))
}

/// The old rule (a per-node Gershgorin sum of every spring's stiffness and damping, and
/// a factor ½), for the report.
fn old_rule(n: usize, spacing: f64, cfg: &SolverConfig, k_max: f64) -> f64 {
    let mesh = Mesh::standard(n, spacing);
    let nodes = mesh.rest.len();
    let (mut stiff, mut damp) = (vec![0.0; nodes], vec![cfg.node_damping; nodes]);
    for s in &mesh.springs {
        for e in [s.i, s.j] {
            stiff[e] += k_max / s.l0 * 1000.0;
            damp[e] += cfg.spring_damping;
        }
    }
    stiff[mesh.contact] += cfg.coupling.stiffness * 1000.0;
    damp[mesh.contact] += cfg.coupling.damping;
    let free: Vec<usize> = (0..nodes).filter(|&i| !mesh.fixed[i]).collect();
    let c_max = free.iter().map(|&i| damp[i]).fold(0.0, f64::max);
    let tau = free
        .iter()
        .map(|&i| damp[i] / stiff[i])
        .fold(f64::INFINITY, f64::min);
    0.5 * (cfg.node_mass / c_max).min(2.0 * tau)
}

/// The configuration's integrator as the report lines name it: nothing for the paper's
/// (its lines keep their keys), `integrator=symplectic_damped ` for the option.
fn tag(cfg: &SolverConfig) -> &'static str {
    match cfg.integrator {
        Integrator::ImprovedEuler => "",
        Integrator::SymplecticDamped => "integrator=symplectic_damped ",
    }
}

/// The default configuration with each integrator.
fn with_each_integrator() -> [SolverConfig; 2] {
    [Integrator::ImprovedEuler, Integrator::SymplecticDamped].map(|integrator| SolverConfig {
        integrator,
        ..SolverConfig::default()
    })
}

#[test]
fn the_default_patch_report() {
    let cfg = SolverConfig::default();
    let k_max = table().max_stiffness().to_num::<f64>();
    // The symplectic option's exact bound and the core's estimate of it (N = 10: the
    // board's patch, docs/arm.md).
    for n in [5, 8, 10] {
        let cfg = with_each_integrator()[1];
        let (b, exact) = compare(n, 2.5, &cfg);
        let subs = |h: f64| (1.0 / (1000.0 * h)).ceil() as u32;
        let estimated = b.estimated.unwrap();
        println!(
            "STABILITY {}patch=n{n} exact_us={:.0} estimated_us={:.0} chosen_us={:.0} substeps_chosen={} substeps_exact={}",
            tag(&cfg),
            exact * 1e6,
            estimated * 1e6,
            b.chosen * 1e6,
            subs(b.chosen),
            subs(exact),
        );
        assert_eq!(
            b.chosen,
            ESTIMATE_MARGIN * estimated,
            "the estimate is taken"
        );
        assert!(b.chosen <= exact, "{b:?} vs {exact}");
        assert!(
            (estimated - exact).abs() <= 0.1 * exact,
            "estimate {estimated} vs exact {exact}"
        );
    }
    for n in [5, 8] {
        let (b, exact) = compare(n, 2.5, &cfg);
        let old = old_rule(n, 2.5, &cfg, k_max);
        let subs = |h: f64| (1.0 / (1000.0 * h)).ceil() as u32;
        println!(
            "STABILITY patch=n{n} exact_us={:.0} estimated_us={:.0} chosen_us={:.0} conservative_us={:.0} old_rule_us={:.0} substeps_old={} substeps_conservative={} substeps_chosen={} substeps_exact={}",
            exact * 1e6,
            b.estimated.unwrap() * 1e6,
            b.chosen * 1e6,
            CONSERVATIVE_FACTOR * b.closed * 1e6,
            old * 1e6,
            subs(old),
            subs(CONSERVATIVE_FACTOR * b.closed),
            subs(b.chosen),
            subs(exact),
        );
        assert!(
            CONSERVATIVE_FACTOR * b.closed <= exact && b.chosen <= exact,
            "{b:?} vs {exact}"
        );
        let estimated = b.estimated.unwrap();
        assert!(
            (estimated - exact).abs() <= 0.1 * exact,
            "estimate {estimated} vs exact {exact}"
        );
        assert!(b.chosen > 1.5 * old, "the new bound is tighter");
    }
}

/// Over masses, dampings, couplings, spacings and patch sizes: the chosen substep
/// (estimated, with its margin) and the conservative one are never above the exact
/// bound, and where the estimate is taken it is at most 1.2 times it. The closed form
/// itself can be above it: the report says by how much.
#[test]
fn the_chosen_bound_is_never_optimistic() {
    the_chosen_bound_is_never_optimistic_with(Integrator::ImprovedEuler);
}

#[test]
fn the_chosen_bound_is_never_optimistic_symplectic() {
    the_chosen_bound_is_never_optimistic_with(Integrator::SymplecticDamped);
}

fn the_chosen_bound_is_never_optimistic_with(integrator: Integrator) {
    let (mut worst_est, mut least_est) = (0.0f64, f64::INFINITY);
    let (mut tight, mut closed_over, mut cons_over) = (0.0f64, 0.0f64, 0.0f64);
    let (mut count, mut fallbacks) = (0, 0);
    for n in [3, 4, 5] {
        for spacing in [1.5, 5.0] {
            for mass in [0.002, 0.03] {
                for (cs, cn) in [
                    (0.05, 0.05),
                    (1.0, 0.0),
                    (10.0, 0.5),
                    (0.0, 2.0),
                    (30.0, 0.0),
                ] {
                    for (kc, bc) in [(1.0, 0.5), (8.0, 0.0)] {
                        count += 1;
                        let cfg = SolverConfig {
                            node_mass: mass,
                            spring_damping: cs,
                            node_damping: cn,
                            coupling: Coupling {
                                stiffness: kc,
                                damping: bc,
                                max_force: 10.0,
                            },
                            integrator,
                            ..SolverConfig::default()
                        };
                        let (b, exact) = compare(n, spacing, &cfg);
                        let what =
                            format!("N={n} s={spacing} m={mass} C={cs} c={cn} kc={kc} bc={bc}");
                        let conservative = CONSERVATIVE_FACTOR * b.closed;
                        assert!(
                            conservative <= exact,
                            "{what}: conservative {conservative} > exact {exact}"
                        );
                        assert!(
                            b.chosen <= exact,
                            "{what}: chosen {} > exact {exact}",
                            b.chosen
                        );
                        let estimated = b.estimated.unwrap();
                        if b.chosen == ESTIMATE_MARGIN * estimated {
                            worst_est = worst_est.max(estimated / exact);
                            least_est = least_est.min(estimated / exact);
                        } else {
                            fallbacks += 1;
                        }
                        tight = tight.max(b.chosen / exact);
                        closed_over = closed_over.max(b.closed / exact);
                        cons_over = cons_over.max(conservative / exact);
                    }
                }
            }
        }
    }
    let cfg = SolverConfig {
        integrator,
        ..SolverConfig::default()
    };
    println!("STABILITY {}case=sweep configurations={count} conservative_fallbacks={fallbacks} estimate_of_exact_min={least_est:.3} estimate_of_exact_max={worst_est:.3} max_chosen_of_exact={tight:.3} max_conservative_of_exact={cons_over:.3} max_closed_of_exact={closed_over:.4}", tag(&cfg));
    // The margin (0.75) covers an estimate up to 1.33 times the exact bound.
    assert!(
        worst_est <= 1.2,
        "the estimate {worst_est} times the exact bound"
    );
}

/// Random configurations (the solver properties' range: N = 3…5, spacing 1.5–5 mm, 2–30 g
/// nodes, spring damping 0.05–30 N·s/m log-uniform, node damping 0–1 N·s/m, coupling
/// 0.4–8 N/mm and 0–5 N·s/m, either integrator), on a fixed seed unless
/// `PROPTEST_RNG_SEED` is set: the estimated bound's substep is never above the exact
/// bound. Reported: how close it comes, and the estimate itself (before its margin)
/// where it is taken (measured up to 1.23 times the exact bound, on 25,000 cases of seed
/// 777, a lightly damped patch; the margin, 0.75, covers up to 1.33).
#[test]
fn the_chosen_bound_is_never_optimistic_on_random_configurations() {
    use proptest::prelude::*;
    let cases = cases(200, 1);
    let strategy = (
        (3usize..=5, 1.5f64..5.0, 2.0f64..30.0),
        (
            (0.05f64.ln()..30f64.ln()).prop_map(f64::exp),
            0.0f64..1.0,
            0.4f64..8.0,
            0.0f64..5.0,
            any::<bool>(),
        ),
    );
    let worst = std::cell::Cell::new((0.0f64, 0.0f64, 0u32));
    let closest = std::cell::Cell::new(String::new());
    run_cases(
        cases,
        strategy,
        |((n, spacing, mass_g), (c, node_c, kc, bc, symplectic))| {
            let cfg = SolverConfig {
                node_mass: mass_g / 1000.0,
                spring_damping: c,
                node_damping: node_c,
                max_substeps: 100_000,
                coupling: Coupling {
                    stiffness: kc,
                    damping: bc,
                    max_force: 5.0,
                },
                integrator: if symplectic {
                    Integrator::SymplecticDamped
                } else {
                    Integrator::ImprovedEuler
                },
                ..SolverConfig::default()
            };
            let (b, exact) = compare(n, spacing, &cfg);
            prop_assert!(b.chosen <= exact, "chosen {} > exact {exact}", b.chosen);
            // (Where the estimate is taken: a lightly damped patch falls back.)
            let estimated = b.estimated.unwrap();
            let taken = b.chosen == ESTIMATE_MARGIN * estimated;
            let (w, e, f) = worst.get();
            if b.chosen / exact > w {
                closest.set(format!(
                        "n={n} spacing_mm={spacing:.3} mass_g={mass_g:.3} spring_damping={c:.4} node_damping={node_c:.4} coupling_n_mm={kc:.3} coupling_damping={bc:.3} symplectic={symplectic} chosen_of_exact={:.3}",
                        b.chosen / exact
                    ));
            }
            let e = if taken { e.max(estimated / exact) } else { e };
            worst.set((w.max(b.chosen / exact), e, f + !taken as u32));
            Ok(())
        },
    );
    let (w, e, f) = worst.get();
    let seed = seed();
    println!(
        "STABILITY case=random configurations={cases} seed={seed} conservative_fallbacks={f} max_chosen_of_exact={w:.3} max_estimate_of_exact={e:.3}"
    );
    println!("STABILITY case=random_closest {}", closest.take());
}

/// Deformed states — a deep indentation, a stroke, a pull — linearised with the law's
/// tangent stiffness and the geometric stiffness: the chosen substep stays within their
/// exact bounds.
#[test]
fn the_chosen_bound_holds_on_deformed_states() {
    for cfg in with_each_integrator() {
        the_chosen_bound_holds_on_deformed_states_with(&cfg);
    }
}

fn the_chosen_bound_holds_on_deformed_states_with(cfg: &SolverConfig) {
    let cfg = *cfg;
    let law = Reference::new(&Params::TABLE2).unwrap();
    let mut closest = 0.0f64;
    for n in [5, 8] {
        let (b, _) = compare(n, 2.5, &cfg);
        let mesh = Mesh::standard(n, 2.5);
        for probe in [
            [0.0, 0.0, -2.0],
            [0.0, 0.0, -2.45],
            [2.0, 1.0, -1.2],
            [0.0, 0.0, 1.5],
        ] {
            let mut tw = Twin::new(mesh.clone(), law, TwinConfig::from_solver(&cfg, 8));
            for _ in 0..1500 {
                tw.step_held(probe);
            }
            let lin = Linear::new(
                &mesh,
                &TwinConfig::from_solver(&cfg, 1),
                Stiffness::At(&law, &tw.x),
            );
            let exact = lin.exact_bound(0.02);
            closest = closest.max(b.chosen / exact);
            assert!(
                b.chosen <= exact,
                "N={n} held at {probe:?}: chosen {} > exact {exact}",
                b.chosen
            );
        }
    }
    println!(
        "STABILITY {}case=deformed max_chosen_of_exact={closest:.3} margin={ESTIMATE_MARGIN}",
        tag(&cfg)
    );
}

/// The twin with every spring at the table's largest stiffness (the linearisation the
/// bound is computed on), from a small perturbation: at the chosen substep the motion
/// dies out; at 1.5 times the exact bound it grows.
#[test]
fn the_twin_decays_at_the_chosen_step_and_grows_beyond_the_exact_one() {
    for cfg in with_each_integrator() {
        the_twin_decays_and_grows_with(&cfg);
    }
}

fn the_twin_decays_and_grows_with(cfg: &SolverConfig) {
    let cfg = *cfg;
    let k_max = table().max_stiffness().to_num::<f64>();
    let (b, _) = compare(5, 2.5, &cfg);
    // The probe stays away: the exact bound of the patch without the coupling.
    let mut free = TwinConfig::from_solver(&cfg, 1);
    free.coupling = (0.0, 0.0, 10.0);
    let exact =
        Linear::new(&Mesh::standard(5, 2.5), &free, Stiffness::AtRest(k_max)).exact_bound(0.02);
    let run = |h: f64| -> f64 {
        let mesh = Mesh::standard(5, 2.5);
        let mut tc = TwinConfig::from_solver(&cfg, 1);
        tc.tick_hz = 1.0 / h;
        let mut tw = Twin::new(mesh, Reference::new(&Params::TABLE2).unwrap(), tc);
        tw.linear_stiffness = Some(k_max);
        for (i, x) in tw.x.iter_mut().enumerate() {
            if !tw.mesh.fixed[i] {
                x[0] += 1e-4 * ((i * 7 % 5) as f64 - 2.0);
                x[1] += 1e-4 * ((i * 3 % 7) as f64 - 3.0);
            }
        }
        let far = [0.0, 0.0, 50.0];
        let spread = |tw: &Twin| {
            (0..tw.x.len())
                .flat_map(|i| (0..3).map(move |k| (i, k)))
                .map(|(i, k)| (tw.x[i][k] - tw.mesh.rest[i][k]).abs())
                .map(|d| if d.is_nan() { f64::INFINITY } else { d })
                .fold(0.0, f64::max)
        };
        let start = spread(&tw);
        for _ in 0..3000 {
            tw.step(far);
        }
        spread(&tw) / start
    };
    let (at_chosen, beyond) = (run(b.chosen), run(1.5 * exact));
    // An overflow prints as f64::MAX, so that the line stays all numbers.
    let shown = if beyond.is_finite() { beyond } else { f64::MAX };
    println!(
        "STABILITY {}case=twin growth_at_chosen={at_chosen:.2e} growth_at_1.5x_exact={shown:.2e}",
        tag(&cfg)
    );
    assert!(at_chosen < 1e-3, "{at_chosen}");
    assert!(beyond > 1e3, "{beyond}");
}

/// The conservative bound, as a configuration may ask: more substeps than the default.
#[test]
fn the_conservative_bound_is_the_more_cautious() {
    let cfg = SolverConfig {
        bound: Bound::Conservative,
        ..SolverConfig::default()
    };
    let (b, exact) = compare(5, 2.5, &cfg);
    assert_eq!(b.chosen, CONSERVATIVE_FACTOR * b.closed);
    let (default, _) = compare(5, 2.5, &SolverConfig::default());
    assert!(b.chosen < default.chosen && b.chosen < exact);
}

/// The candidates issue #17 names for a larger stable step at the paper's cost
/// ([`Scheme`]), on the default patches linearised at the table's largest stiffness
/// (and at ten times it, near solid): each one's exact bound, the substeps per 1 kHz
/// tick it would take with the core's margin, and its accuracy on a step response (the
/// contact node under a constant force, 20 ticks) at those substeps and at a common 4.
/// Each scheme converges (8 substeps closer than 4), and is stable below its bound. And
/// what docs/performance.md concludes from it holds: no scheme reaches one substep at
/// N = 5; the nodes' own damping integrated exactly moves no bound by 1 %; symplectic
/// Euler with the own damping implicit (per node or uniform) is more accurate than the
/// paper's at its own substeps and at 4, and takes fewer at N = 8.
#[test]
fn the_integrator_variants_report() {
    use mccs_host::stability::{response_error, Scheme};
    let cfg = SolverConfig::default();
    let k_max = table().max_stiffness().to_num::<f64>();
    for n in [5, 8] {
        let mesh = Mesh::standard(n, 2.5);
        let tc = TwinConfig::from_solver(&cfg, 1);
        let lin = Linear::new(&mesh, &tc, Stiffness::AtRest(k_max));
        let solid = Linear::new(&mesh, &tc, Stiffness::AtRest(10.0 * k_max));
        let reference = lin.reference_step_response(20).unwrap();
        let mut rows = Vec::new();
        for scheme in Scheme::ALL {
            let exact = lin.exact_bound_within(scheme, 0.02, 1e-4);
            for f in [0.3, 0.6, 0.9] {
                let r = lin.spectral_radius_of(scheme, f * exact);
                assert!(
                    r <= 1.0 + 1e-9,
                    "{scheme:?} N={n}: ρ {r} at {f} of its bound"
                );
            }
            let substeps = (1e-3 / (ESTIMATE_MARGIN * exact)).ceil() as u32;
            let err =
                |s: u32| response_error(&lin.step_response(scheme, s, 20).unwrap(), &reference);
            let (own, at4, at8) = (err(substeps), err(4), err(8));
            assert!(
                at8 < 0.75 * at4,
                "{scheme:?} N={n}: {at8} at 8 substeps, {at4} at 4"
            );
            if n == 5 {
                assert!(substeps > 1, "{scheme:?} reaches one substep at N = 5");
            }
            rows.push((scheme, exact, substeps, own, at4));
            println!(
                "INTEGRATOR scheme={} patch=n{n} exact_us={:.0} solid_exact_us={:.0} substeps={substeps} error_own={own:.1e} error_at_4={at4:.1e}",
                scheme.name(),
                exact * 1e6,
                solid.exact_bound_within(scheme, 0.02, 1e-3) * 1e6,
            );
        }
        let row = |s: Scheme| *rows.iter().find(|r| r.0 == s).unwrap();
        let paper = row(Scheme::Paper);
        let exact_damping = row(Scheme::ExactNodeDamping);
        assert!((exact_damping.1 / paper.1 - 1.0).abs() < 0.01);
        for best in [
            row(Scheme::SymplecticImplicitOwnDamping),
            row(Scheme::SymplecticImplicitUniformDamping),
        ] {
            assert!(
                best.3 < paper.3 && best.4 < paper.4,
                "{best:?} vs {paper:?}"
            );
            if n == 8 {
                assert!(best.2 < paper.2, "{best:?} vs {paper:?}");
            }
        }
    }
}
