//! The spectral radius of a real square matrix (the largest eigenvalue modulus), from its
//! eigenvalues alone: a Householder reduction to upper Hessenberg form, then the
//! Francis double-shift QR iteration on the active block only (EISPACK's `orthes` and
//! `hqr`, in the public domain; no Schur vectors, no Schur form outside the block).
//!
//! [`crate::stability`]'s bisection asks for `ρ(G(h))` twenty-odd times a bound, and
//! nalgebra's `Schur::try_new`, the only one of its eigenvalue routines with an iteration
//! limit, also builds the orthogonal factor and updates the whole matrix at each step:
//! about two and a half times this work. `host-tests/tests/eigenvalues.rs` holds this to
//! nalgebra's eigenvalues on random matrices and on the step matrices of the patch.

use nalgebra::DMatrix;

/// `max |λ|` over the eigenvalues of `m` (square), or `None` where the QR iteration has
/// not converged after `30 · n` iterations in all (EISPACK's limit) or `m` holds a value
/// that is not finite. 0 for an empty matrix.
pub fn spectral_radius(m: &DMatrix<f64>) -> Option<f64> {
    let n = m.nrows();
    assert_eq!(n, m.ncols(), "a square matrix");
    if m.iter().any(|x| !x.is_finite()) {
        return None;
    }
    // Row-major: `h[i * n + j]`.
    let mut h: Vec<f64> = (0..n * n).map(|k| m[(k / n, k % n)]).collect();
    hessenberg(&mut h, n);
    let mut largest = 0.0f64;
    hessenberg_eigenvalues(&mut h, n, &mut |re, im| largest = largest.max(re.hypot(im)))?;
    Some(largest)
}

/// `h` (`n × n`, row-major) to upper Hessenberg form by Householder similarities
/// (EISPACK's `orthes`); zeros below the subdiagonal.
fn hessenberg(h: &mut [f64], n: usize) {
    let mut ort = vec![0.0f64; n];
    let mut f = vec![0.0f64; n];
    for m in 1..n.saturating_sub(1) {
        let scale: f64 = (m..n).map(|i| h[i * n + m - 1].abs()).sum();
        if scale == 0.0 {
            continue;
        }
        let mut sum = 0.0;
        for i in (m..n).rev() {
            ort[i] = h[i * n + m - 1] / scale;
            sum += ort[i] * ort[i];
        }
        let g = if ort[m] >= 0.0 {
            -sum.sqrt()
        } else {
            sum.sqrt()
        };
        let hh = sum - ort[m] * g;
        ort[m] -= g;
        // H ← (I − u uᵀ/hh) H (I − u uᵀ/hh), u in rows m.., row by row (contiguous).
        let u = &ort[m..n];
        f[m..n].fill(0.0);
        for (i, &ui) in (m..n).zip(u) {
            for (fj, hij) in f[m..n].iter_mut().zip(&h[i * n + m..i * n + n]) {
                *fj += ui * hij;
            }
        }
        for (i, &ui) in (m..n).zip(u) {
            let w = ui / hh;
            for (hij, fj) in h[i * n + m..i * n + n].iter_mut().zip(&f[m..n]) {
                *hij -= fj * w;
            }
        }
        for i in 0..n {
            let row = &mut h[i * n + m..i * n + n];
            let w = row.iter().zip(u).map(|(a, b)| a * b).sum::<f64>() / hh;
            for (hij, uj) in row.iter_mut().zip(u) {
                *hij -= w * uj;
            }
        }
        h[m * n + m - 1] = scale * g;
    }
    for i in 2..n {
        for j in 0..i - 1 {
            h[i * n + j] = 0.0;
        }
    }
}

/// The eigenvalues of the upper Hessenberg `h` (`n × n`, row-major; destroyed), each
/// given to `found` as `(re, im)`, by the Francis double-shift QR iteration with
/// deflation (EISPACK's `hqr`). `None` where it has not converged after `30 · n`
/// iterations in all.
fn hessenberg_eigenvalues(h: &mut [f64], n: usize, found: &mut impl FnMut(f64, f64)) -> Option<()> {
    let at = |i: usize, j: usize| i * n + j;
    let eps = f64::EPSILON;
    let norm: f64 = (0..n)
        .flat_map(|i| (i.saturating_sub(1)..n).map(move |j| (i, j)))
        .map(|(i, j)| h[at(i, j)].abs())
        .sum();
    let mut budget = 30 * n;
    let mut shift = 0.0f64;
    let mut iterations = 0;
    // `en`: the last row of the active block, counted from 1 (0: every eigenvalue found).
    let mut en = n;
    while en > 0 {
        let e = en - 1;
        // The block's first row: below the last negligible subdiagonal element.
        let mut l = e;
        while l > 0 {
            let mut s = h[at(l - 1, l - 1)].abs() + h[at(l, l)].abs();
            if s == 0.0 {
                s = norm;
            }
            if h[at(l, l - 1)].abs() <= eps * s {
                break;
            }
            l -= 1;
        }
        if l == e {
            // One real root.
            found(h[at(e, e)] + shift, 0.0);
            en -= 1;
            iterations = 0;
            continue;
        }
        let (x, y, w) = (
            h[at(e, e)],
            h[at(e - 1, e - 1)],
            h[at(e, e - 1)] * h[at(e - 1, e)],
        );
        if l == e - 1 {
            // Two roots, of the trailing 2 × 2 block.
            let p = (y - x) / 2.0;
            let q = p * p + w;
            let z = q.abs().sqrt();
            let x = x + shift;
            if q >= 0.0 {
                let z = if p >= 0.0 { p + z } else { p - z };
                found(x + z, 0.0);
                found(if z != 0.0 { x - w / z } else { x + z }, 0.0);
            } else {
                found(x + p, z);
                found(x + p, -z);
            }
            en -= 2;
            iterations = 0;
            continue;
        }
        if budget == 0 {
            return None;
        }
        budget -= 1;
        let (mut x, mut y, mut w) = (x, y, w);
        if iterations == 10 || iterations == 20 {
            // Wilkinson's exceptional shift.
            shift += x;
            for i in 0..=e {
                h[at(i, i)] -= x;
            }
            let s = h[at(e, e - 1)].abs() + h[at(e - 1, e - 2)].abs();
            x = 0.75 * s;
            y = x;
            w = -0.4375 * s * s;
        }
        iterations += 1;
        double_shift_step(h, n, l, e, x, y, w);
    }
    Some(())
}

/// Where a Francis double-shift step on rows and columns `l..=e` of `h` starts, the
/// shifts the roots of `λ² − (x + y) λ + (x y − w)`: the last row `m` from which two
/// consecutive subdiagonal elements are negligible, and the first column of the shifted
/// product there, `(p, q, r)`, normalised.
fn double_shift_start(
    h: &[f64],
    n: usize,
    l: usize,
    e: usize,
    x: f64,
    y: f64,
    w: f64,
) -> (usize, f64, f64, f64) {
    let at = |i: usize, j: usize| i * n + j;
    let mut m = e - 2;
    loop {
        let z = h[at(m, m)];
        let (rr, ss) = (x - z, y - z);
        let p = (rr * ss - w) / h[at(m + 1, m)] + h[at(m, m + 1)];
        let q = h[at(m + 1, m + 1)] - z - rr - ss;
        let r = h[at(m + 2, m + 1)];
        let s = p.abs() + q.abs() + r.abs();
        let (p, q, r) = (p / s, q / s, r / s);
        if m == l {
            return (m, p, q, r);
        }
        let lhs = h[at(m, m - 1)].abs() * (q.abs() + r.abs());
        let rhs = f64::EPSILON
            * p.abs()
            * (h[at(m - 1, m - 1)].abs() + z.abs() + h[at(m + 1, m + 1)].abs());
        if lhs <= rhs {
            return (m, p, q, r);
        }
        m -= 1;
    }
}

/// One Francis double-shift QR step on rows and columns `l..=e` of `h`, the shifts the
/// roots of `λ² − (x + y) λ + (x y − w)`: from its start ([`double_shift_start`]), the
/// bulge chased down.
fn double_shift_step(h: &mut [f64], n: usize, l: usize, e: usize, x: f64, y: f64, w: f64) {
    let at = |i: usize, j: usize| i * n + j;
    let (m, mut p, mut q, mut r) = double_shift_start(h, n, l, e, x, y, w);
    for i in m + 2..=e {
        h[at(i, i - 2)] = 0.0;
        if i > m + 2 {
            h[at(i, i - 3)] = 0.0;
        }
    }
    for k in m..e {
        let not_last = k != e - 1;
        let mut xk = 0.0;
        if k != m {
            p = h[at(k, k - 1)];
            q = h[at(k + 1, k - 1)];
            r = if not_last { h[at(k + 2, k - 1)] } else { 0.0 };
            xk = p.abs() + q.abs() + r.abs();
            if xk == 0.0 {
                continue;
            }
            p /= xk;
            q /= xk;
            r /= xk;
        }
        let s = (p * p + q * q + r * r).sqrt().copysign(p);
        if s == 0.0 {
            continue;
        }
        if k != m {
            h[at(k, k - 1)] = -s * xk;
        } else if l != m {
            h[at(k, k - 1)] = -h[at(k, k - 1)];
        }
        p += s;
        let (xr, yr, zr) = (p / s, q / s, r / s);
        q /= p;
        r /= p;
        // Rows k, k+1 (and k+2), columns k..=e (as slices: no bounds checks in the loop).
        let (row_k, rest) = h[at(k, 0)..].split_at_mut(n);
        let (row_k1, rest) = rest.split_at_mut(n);
        let (row_k, row_k1) = (&mut row_k[k..=e], &mut row_k1[k..=e]);
        if not_last {
            let row_k2 = &mut rest[k..=e];
            for ((a, b), c) in row_k
                .iter_mut()
                .zip(row_k1.iter_mut())
                .zip(row_k2.iter_mut())
            {
                let t = *a + q * *b + r * *c;
                *a -= t * xr;
                *b -= t * yr;
                *c -= t * zr;
            }
        } else {
            for (a, b) in row_k.iter_mut().zip(row_k1.iter_mut()) {
                let t = *a + q * *b;
                *a -= t * xr;
                *b -= t * yr;
            }
        }
        // Columns k, k+1 (and k+2), rows l..=min(e, k+3).
        for i in l..=e.min(k + 3) {
            let mut t = xr * h[at(i, k)] + yr * h[at(i, k + 1)];
            if not_last {
                t += zr * h[at(i, k + 2)];
                h[at(i, k + 2)] -= t * r;
            }
            h[at(i, k)] -= t;
            h[at(i, k + 1)] -= t * q;
        }
    }
}
