//! The f64 reference law against an independent coil-by-coil oracle, its invariants,
//! its two inverses against each other, and random springs (proptest).

use crate::common;

use common::any_spring;
use mccs::{Cone, ParamError, ParamKey, Params};
use mccs_host::reference::Reference;
use proptest::prelude::*;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// Wahl's per-coil deflection, each slice stopped at its gap: sum over `slices` of
/// `min(8 F D³/(G d⁴), H/n) · dn`, `D` linear from D1 to D2 over the `n` coils.
fn coil_sum(c: &Cone, f: f64, slices: usize) -> f64 {
    let dn = c.active_coils / slices as f64;
    let gd4 = c.shear_modulus * c.wire_diameter.powi(4);
    let gap = c.compressible_height / c.active_coils;
    let mut sum = 0.0;
    for i in 0..slices {
        let frac = (i as f64 + 0.5) / slices as f64;
        let d = c.small_diameter + (c.large_diameter - c.small_diameter) * frac;
        sum += (8.0 * f * d.powi(3) / gd4).min(gap) * dn;
    }
    sum
}

/// `F(Δ(F)) = F` to 1e-12 relative, or to what the law's conditioning allows: rounding
/// `Δ` to its last bit moves `F` by `stiffness · ε_machine · |Δ|`, which dominates where a
/// stiff series spring is on (large `k_p`).
fn round_trip_tol(r: &Reference, f: f64, d: f64) -> f64 {
    1e-12 * f.abs().max(r.f_t) + 8.0 * f64::EPSILON * d.abs() * r.stiffness(d)
}

fn springs() -> Vec<Params> {
    let mut v = vec![Params::TABLE2];
    let mut p = Params::TABLE2;
    p.cone.small_diameter = 0.5;
    p.cone.active_coils = 3.0;
    v.push(p);
    let mut p = Params::TABLE2;
    p.cone.large_diameter = 2.0;
    p.cone.wire_diameter = 0.2;
    p.cone.compressible_height = 1.5;
    p.linear.preload = Some(1.0);
    v.push(p);
    let mut p = Params::TABLE2;
    p.cone.shear_modulus = 8.0e4;
    p.linear.active_coils = 4.0;
    v.push(p);
    v
}

#[test]
fn table2_derived_constants() {
    let r = Reference::new(&Params::TABLE2).unwrap();
    let s = r.series.unwrap();
    assert!(rel(r.k, 2.30037) < 1e-5, "k = {}", r.k);
    assert!(rel(r.f_t, 0.541172) < 1e-5, "F_T = {}", r.f_t);
    assert!(rel(r.f_c, 10.2622) < 1e-5, "F_C = {}", r.f_c);
    assert!(rel(s.k_p, 16.4206) < 1e-5, "k_p = {}", s.k_p);
    // The starting spec printed Δ(F_T) = 0.235268; its own formulas (F_T / k, and
    // H (D1+D2)(D1²+D2²)/(4 D2³)) both give 0.2352539 (6e-5 apart: a typo there).
    assert!(rel(r.delta(r.f_t), 0.2352539) < 1e-6);
    assert!(rel(r.delta(r.f_t), r.f_t / r.k) < 1e-15);
    assert_eq!(s.preload, r.f_t);
}

#[test]
fn oracle_coil_sum_matches_eq11() {
    for p in springs() {
        // The cone alone: eq. 11 is the cone's strain in its nonlinear phase.
        let cone = Reference::cone_only(&p.cone);
        for i in 0..=20 {
            let f = cone.f_t + (cone.f_c - cone.f_t) * (0.001 + 0.998 * i as f64 / 20.0);
            let oracle = coil_sum(&p.cone, f, 200_000);
            let model = cone.delta(f);
            assert!(rel(model, oracle) < 1e-9, "F = {f}: {model} vs {oracle}");
        }
        // Below F_T every coil is free: the sum is F/k.
        let f = 0.5 * cone.f_t;
        assert!(rel(cone.delta(f), coil_sum(&p.cone, f, 200_000)) < 1e-9);
    }
}

#[test]
fn transition_strain_is_geometric() {
    for p in springs() {
        let c = &p.cone;
        let (d1, d2) = (c.small_diameter, c.large_diameter);
        let expect = c.compressible_height * (d1 + d2) * (d1 * d1 + d2 * d2) / (4.0 * d2.powi(3));
        for (n, g, d) in [(1.0, 1.0, 1.0), (7.5, 3.0e5, 0.05), (0.3, 10.0, 2.0)] {
            let mut q = p;
            q.cone.active_coils = n;
            q.cone.shear_modulus = g;
            q.cone.wire_diameter = d;
            let r = Reference::cone_only(&q.cone);
            assert!(rel(r.delta(r.f_t), expect) < 1e-13);
            if q.linear.preload.is_none() {
                let r = Reference::new(&q).unwrap();
                assert!(rel(r.delta(r.f_t), expect) < 1e-13);
            }
        }
    }
}

#[test]
fn delta_depends_on_force_times_coils() {
    for p in springs() {
        let r1 = Reference::cone_only(&p.cone);
        let mut q = p.cone;
        q.active_coils *= 2.5;
        let r2 = Reference::cone_only(&q);
        for i in 0..50 {
            let f = r1.f_c * 1.2 * i as f64 / 49.0;
            assert!(rel(r1.delta(f), r2.delta(f / 2.5)) < 1e-12 || r1.delta(f) == 0.0);
        }
    }
}

#[test]
fn continuous_at_kink_and_solid_point() {
    for p in springs() {
        let r = Reference::new(&p).unwrap();
        for f in [r.f_t, r.f_c] {
            let h = f * 1e-10;
            let jump = (r.delta(f + h) - r.delta(f - h)).abs();
            assert!(jump < 1e-8 * r.delta(f), "jump {jump} at F = {f}");
        }
    }
}

#[test]
fn strictly_increasing_and_round_trips() {
    for p in springs() {
        let r = Reference::new(&p).unwrap();
        let mut prev = f64::NEG_INFINITY;
        for i in 0..20_000 {
            let f = -r.f_t + (1.5 * r.f_c + r.f_t) * i as f64 / 19_999.0;
            let d = r.delta(f);
            assert!(d > prev, "not increasing at F = {f}");
            prev = d;
            let back = r.force(d);
            assert!(
                (back - f).abs() <= round_trip_tol(&r, f, d),
                "F(Δ({f})) = {back}"
            );
        }
    }
}

#[test]
fn stiffness_is_k_below_and_kp_above() {
    for p in springs() {
        let r = Reference::new(&p).unwrap();
        let k_p = r.series.unwrap().k_p;
        for d in [-0.3, 0.0, 0.5 * r.strain_t(), r.strain_t()] {
            assert!(rel(r.stiffness(d), r.k) < 1e-14);
        }
        for d in [r.strain_c() + 1e-9, r.strain_c() + 0.5, r.strain_c() + 5.0] {
            assert!(
                rel(r.stiffness(d), k_p) < 1e-14,
                "{d}: {} vs {k_p}",
                r.stiffness(d)
            );
        }
        // Just past the kink: the series of k and k_p; just before solid: k_p.
        let after = r.stiffness(r.strain_t() * (1.0 + 1e-12));
        assert!(rel(after, 1.0 / (1.0 / r.k + 1.0 / k_p)) < 1e-6);
        let before = r.stiffness(r.strain_c() * (1.0 - 1e-12));
        assert!(rel(before, k_p) < 1e-3);
    }
}

#[test]
fn stiffness_matches_central_difference() {
    let r = Reference::new(&Params::TABLE2).unwrap();
    for i in 1..100 {
        let d = r.strain_t() + (r.strain_c() - r.strain_t()) * i as f64 / 100.0;
        let h = 1e-6;
        let numeric = (r.force(d + h) - r.force(d - h)) / (2.0 * h);
        assert!(rel(r.stiffness(d), numeric) < 1e-6);
    }
}

#[test]
fn closed_form_and_bracketed_inverse_agree() {
    for p in springs() {
        for r in [Reference::new(&p).unwrap(), Reference::cone_only(&p.cone)] {
            for i in 1..1000 {
                let d = r.strain_t() + (r.strain_c() - r.strain_t()) * i as f64 / 1000.0;
                let a = r.force_closed_form(d);
                let b = r.force_bracketed(d);
                assert!(rel(a, b) < 1e-9, "Δ = {d}: Ferrari {a}, bracketed {b}");
                assert!(rel(r.delta(b), d) < 1e-13);
                assert!(rel(r.force(d), b) < 1e-12);
            }
        }
    }
}

#[test]
fn cone_alone_is_solid_at_h() {
    let r = Reference::cone_only(&Params::TABLE2.cone);
    assert!(rel(r.strain_c(), 0.6) < 1e-15);
    assert_eq!(r.force(0.61), f64::INFINITY);
    assert!(rel(r.delta(r.f_c), 0.6) < 1e-12);
}

#[test]
fn every_invalid_parameter_is_named() {
    let set = |p: &mut Params, key: ParamKey, v: f64| {
        let (c, l) = (&mut p.cone, &mut p.linear);
        match key {
            ParamKey::ConeWireDiameter => c.wire_diameter = v,
            ParamKey::ConeSmallDiameter => c.small_diameter = v,
            ParamKey::ConeLargeDiameter => c.large_diameter = v,
            ParamKey::ConeActiveCoils => c.active_coils = v,
            ParamKey::ConeCompressibleHeight => c.compressible_height = v,
            ParamKey::ConeShearModulus => c.shear_modulus = v,
            ParamKey::LinearWireDiameter => l.wire_diameter = v,
            ParamKey::LinearMeanDiameter => l.mean_diameter = v,
            ParamKey::LinearActiveCoils => l.active_coils = v,
            ParamKey::LinearShearModulus => l.shear_modulus = v,
            ParamKey::LinearPreload => l.preload = Some(v),
        }
    };
    for key in ParamKey::ALL {
        for (v, expect) in [
            (0.0, ParamError::NotPositive(key)),
            (-1.0, ParamError::NotPositive(key)),
            (f64::NAN, ParamError::NotFinite(key)),
            (f64::INFINITY, ParamError::NotFinite(key)),
            (f64::NEG_INFINITY, ParamError::NotFinite(key)),
        ] {
            let mut p = Params::TABLE2;
            set(&mut p, key, v);
            let err = Reference::new(&p).unwrap_err();
            assert_eq!(err, expect, "{key} = {v}");
            assert!(err.to_string().starts_with(key.as_str()));
            assert_eq!(mccs::Law::new(&p).unwrap_err(), expect);
        }
    }
    for d2 in [0.3, 0.2] {
        let mut p = Params::TABLE2;
        p.cone.large_diameter = d2;
        assert_eq!(
            Reference::new(&p).unwrap_err(),
            ParamError::LargeNotAboveSmall
        );
        assert_eq!(
            ParamError::LargeNotAboveSmall.key(),
            ParamKey::ConeLargeDiameter
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn prop_round_trip_and_monotone(p in any_spring(), u in 0.0f64..1.0, v in 0.0f64..1.0) {
        let r = Reference::new(&p).unwrap();
        let f1 = -r.f_t + 1.5 * (r.f_c + r.f_t) * u.min(v);
        let f2 = -r.f_t + 1.5 * (r.f_c + r.f_t) * u.max(v);
        if f1 < f2 {
            prop_assert!(r.delta(f1) < r.delta(f2));
        }
        let d2 = r.delta(f2);
        let back = r.force(d2);
        prop_assert!((back - f2).abs() <= round_trip_tol(&r, f2, d2), "{} vs {}", back, f2);
    }

    #[test]
    fn prop_inverses_agree(p in any_spring(), u in 0.0f64..1.0) {
        let r = Reference::new(&p).unwrap();
        let d = r.strain_t() + (r.strain_c() - r.strain_t()) * u;
        let a = r.force_closed_form(d);
        let b = r.force_bracketed(d);
        prop_assert!(rel(a, b) < 1e-9, "{} vs {}", a, b);
    }

    #[test]
    fn prop_oracle(p in any_spring(), u in 0.001f64..0.999) {
        let cone = Reference::cone_only(&p.cone);
        let f = cone.f_t + (cone.f_c - cone.f_t) * u;
        prop_assert!(rel(cone.delta(f), coil_sum(&p.cone, f, 100_000)) < 1e-9);
    }

    #[test]
    fn prop_continuous_and_kinked(p in any_spring()) {
        let r = Reference::new(&p).unwrap();
        // No jump at the kinks F_T, P and F_C: the change across ±h is what the
        // one-sided slopes allow, and nothing more.
        for f in [r.f_t, r.series.unwrap().preload, r.f_c] {
            let h = f * 1e-9;
            let jump = (r.delta(f + h) - r.delta(f - h)).abs();
            let slopes = h * (r.compliance(f - h) + r.compliance(f + h));
            prop_assert!(jump <= 1.001 * slopes + 1e-14 * r.delta(f), "F = {}", f);
        }
        // Core law agrees with the reference (independent code paths).
        let law = mccs::Law::new(&p).unwrap();
        for u in [0.1, 0.5, 0.9] {
            let d = r.strain_t() + (r.strain_c() - r.strain_t()) * u;
            prop_assert!(rel(law.force(d), r.force(d)) < 1e-12);
        }
    }
}

/// Values that are finite and > 0 one by one, but whose derived quantities leave the
/// fixed-point formats (the G = 1e308 and G = 1e-300 among them), are refused
/// with the key that pushed them out the most.
#[test]
fn derived_quantities_out_of_the_formats_name_their_key() {
    use mccs::{Derived, ParamError};
    let cases: [(ParamKey, f64, Derived, bool); 8] = [
        (ParamKey::ConeShearModulus, 1e308, Derived::K, true),
        (ParamKey::ConeShearModulus, 1e-300, Derived::K, false),
        (ParamKey::ConeWireDiameter, 1e100, Derived::K, true),
        (ParamKey::ConeSmallDiameter, 1e-200, Derived::Fc, true),
        (ParamKey::LinearShearModulus, 1e300, Derived::Kp, true),
        (ParamKey::LinearMeanDiameter, 1e-100, Derived::Kp, true),
        (ParamKey::ConeCompressibleHeight, 1e-9, Derived::Ft, false),
        (ParamKey::ConeCompressibleHeight, 1e6, Derived::Ft, true),
    ];
    for (key, value, quantity, high) in cases {
        let mut p = Params::TABLE2;
        key.set(&mut p, value);
        let want = ParamError::OutOfFormat {
            key,
            quantity,
            high,
        };
        assert_eq!(p.validate(), Err(want), "{key} = {value}");
        assert_eq!(Reference::new(&p).err(), Some(want));
        assert_eq!(mccs::Law::new(&p).err(), Some(want));
        assert!(want.to_string().starts_with(key.as_str()));
    }
    // Table 2 itself sits well inside every range.
    for q in Derived::ALL {
        let (lo, hi) = q.range();
        let v = q.of(&Params::TABLE2);
        assert!(v > 10.0 * lo && v < hi / 10.0, "{q:?} = {v}");
    }
}
