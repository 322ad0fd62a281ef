//! `mccs_host::eigenvalues::spectral_radius` (the stability reference's `ρ`), held to
//! nalgebra's real Schur decomposition: on random matrices of 1 to 40 rows (proptest), on
//! the patch's own step matrices (N = 3 and 4, both integrators) from a tenth of their
//! bound to four times it, on spectra known in closed form, and at its edges (empty,
//! zero, not finite).

use mccs::{Integrator, SolverConfig};
use mccs_host::eigenvalues::spectral_radius;
use mccs_host::patch::{Mesh, TwinConfig};
use mccs_host::stability::{Linear, Scheme, Stiffness};
use nalgebra::DMatrix;
use proptest::prelude::*;

use crate::common::{cases, run_cases};

/// nalgebra's `max |λ|` (its Schur decomposition with the orthogonal factor).
fn nalgebra_radius(m: &DMatrix<f64>) -> f64 {
    nalgebra::linalg::Schur::try_new(m.clone(), f64::EPSILON, 100_000)
        .expect("nalgebra converges")
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

/// Square matrices of 1 to 40 rows, entries spread over six decades, some zero.
fn any_matrix() -> impl Strategy<Value = DMatrix<f64>> {
    (1usize..=40, any::<u64>()).prop_map(|(n, seed)| {
        let mut s = seed | 1;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        DMatrix::from_fn(n, n, |_, _| {
            let r = next();
            if r % 7 == 0 {
                return 0.0;
            }
            let unit = (r >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
            unit * 10f64.powi((r % 6) as i32 - 3)
        })
    })
}

#[test]
fn random_matrices_agree_with_nalgebra() {
    let worst = std::sync::Mutex::new(0.0f64);
    run_cases(cases(400, 1), any_matrix(), |m| {
        let ours = spectral_radius(&m).expect("converges");
        let theirs = nalgebra_radius(&m);
        // Relative to the matrix's size: an eigenvalue is as exact as the backward error
        // of either decomposition allows (ε ‖M‖), times its condition.
        let scale = theirs.max(1e-6 * m.norm());
        let err = if ours == theirs {
            0.0
        } else {
            (ours - theirs).abs() / scale
        };
        let mut w = worst.lock().unwrap();
        *w = w.max(err);
        prop_assert!(
            err < 1e-9,
            "ρ {ours} against nalgebra's {theirs} (n = {})",
            m.nrows()
        );
        Ok(())
    });
    println!(
        "EIGEN case=random worst_relative={:.1e}",
        worst.into_inner().unwrap()
    );
}

#[test]
fn the_patch_s_step_matrices_agree_with_nalgebra() {
    let k_max = 10.0;
    let mut worst = 0.0f64;
    let mut compared = 0;
    for integrator in [Integrator::ImprovedEuler, Integrator::SymplecticDamped] {
        let cfg = SolverConfig {
            integrator,
            ..SolverConfig::default()
        };
        for n in [3, 4] {
            let lin = Linear::new(
                &Mesh::standard(n, 2.5),
                &TwinConfig::from_solver(&cfg, 1),
                Stiffness::AtRest(k_max),
            );
            for scheme in Scheme::ALL {
                let edge = lin.exact_bound_within(scheme, 0.02, 1e-3);
                for f in [0.1, 0.5, 0.9, 0.999, 1.001, 1.5, 4.0] {
                    let g = lin.step_matrix_of(scheme, f * edge);
                    let (ours, theirs) = (spectral_radius(&g).unwrap(), nalgebra_radius(&g));
                    let err = (ours - theirs).abs() / theirs;
                    assert!(
                        err < 1e-9,
                        "{scheme:?} N={n} at {f} of the bound: ρ {ours}, nalgebra {theirs}"
                    );
                    // On which side of 1 it is, as the bisection asks, where it is not a
                    // hair from 1.
                    if (theirs - 1.0).abs() > 1e-9 {
                        assert_eq!(ours <= 1.0, theirs <= 1.0);
                    }
                    worst = worst.max(err);
                    compared += 1;
                }
            }
        }
    }
    println!("EIGEN case=step_matrices compared={compared} worst_relative={worst:.1e}");
}

#[test]
fn known_spectra() {
    // A rotation by 0.3 rad scaled by 0.9: a complex pair of modulus 0.9.
    let (c, s) = (0.9 * 0.3f64.cos(), 0.9 * 0.3f64.sin());
    let rot = DMatrix::from_row_slice(2, 2, &[c, -s, s, c]);
    assert!((spectral_radius(&rot).unwrap() - 0.9).abs() < 1e-15);
    // Upper triangular: its diagonal, whatever lies above it.
    let tri = DMatrix::from_fn(6, 6, |i, j| match i.cmp(&j) {
        std::cmp::Ordering::Equal => [0.5, -3.0, 2.0, 1.0, 0.0, -0.25][i],
        std::cmp::Ordering::Less => (i + 2 * j) as f64,
        std::cmp::Ordering::Greater => 0.0,
    });
    assert!((spectral_radius(&tri).unwrap() - 3.0).abs() < 1e-12);
    // A similarity of a known diagonal: the same radius.
    let d = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![0.2, -0.7, 0.95, 0.1]));
    let p = DMatrix::from_fn(4, 4, |i, j| if i == j { 2.0 } else { 0.1 * (i + j) as f64 });
    let m = &p * d * p.clone().try_inverse().unwrap();
    assert!((spectral_radius(&m).unwrap() - 0.95).abs() < 1e-12);
    // A cyclic shift of 12 (a nilpotent-free permutation): every root of unity, modulus 1.
    let shift = DMatrix::from_fn(12, 12, |i, j| f64::from(j == (i + 1) % 12));
    assert!((spectral_radius(&shift).unwrap() - 1.0).abs() < 1e-12);
}

#[test]
fn edges_empty_zero_and_not_finite() {
    assert_eq!(spectral_radius(&DMatrix::zeros(0, 0)), Some(0.0));
    assert_eq!(spectral_radius(&DMatrix::zeros(5, 5)), Some(0.0));
    let mut m = DMatrix::<f64>::identity(4, 4);
    m[(2, 1)] = f64::NAN;
    assert_eq!(spectral_radius(&m), None);
    m[(2, 1)] = f64::INFINITY;
    assert_eq!(spectral_radius(&m), None);
}
