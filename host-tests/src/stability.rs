//! The exact stability bound of the paper's improved Euler on the `f64` twin's patch,
//! from the eigenvalues of its one-step matrix (independent of the core's estimate):
//!
//! ```text
//! G(h) = | I − h²A/2   h (I − hB/2) |     A = M⁻¹K, B = M⁻¹C
//!        | −hA         I − hB       |
//! ```
//!
//! the map of one step `v' = v + h M⁻¹(−K x − C v)`, `x' = x + h (v + v')/2`. The bound is
//! the largest `h` with `ρ(G(h)) < 1`, by bisection on the eigenvalues (Schur, nalgebra).

use crate::patch::{Mesh, TwinConfig, V};
use crate::reference::Reference;
use nalgebra::DMatrix;

/// The linearised patch: mass (kg), damping (N·s/mm) and stiffness (N/mm) on the free
/// nodes' degrees of freedom (3 per node, in the mesh's order).
#[derive(Clone, Debug)]
pub struct Linear {
    /// Node mass, kg.
    pub mass: f64,
    /// Damping.
    pub c: DMatrix<f64>,
    /// Stiffness.
    pub k: DMatrix<f64>,
}

/// Where each node's degrees of freedom start (`None`: fixed).
fn dofs(mesh: &Mesh) -> (Vec<Option<usize>>, usize) {
    let mut n = 0;
    let idx = mesh
        .fixed
        .iter()
        .map(|&f| {
            (!f).then(|| {
                n += 3;
                n - 3
            })
        })
        .collect();
    (idx, n)
}

/// How each spring is linearised.
pub enum Stiffness<'a> {
    /// Every spring at `k_max` (N per unit strain) along its rest direction: what the
    /// core's bound takes.
    AtRest(f64),
    /// At positions `x` (mm): the law's tangent stiffness along the current direction,
    /// and across it the geometric stiffness of tension `|f| / l` (compression's
    /// softening left out: it can only lengthen the stable step, and where it buckles the
    /// linearisation has no time-step bound to speak of).
    At(&'a Reference, &'a [V]),
}

impl Linear {
    /// The patch of `mesh` with the twin's configuration, linearised as `how` says.
    pub fn new(mesh: &Mesh, cfg: &TwinConfig, how: Stiffness<'_>) -> Linear {
        let (idx, n) = dofs(mesh);
        let mut c = DMatrix::zeros(n, n);
        let mut k = DMatrix::zeros(n, n);
        let cs = cfg.spring_damping / 1000.0;
        for s in &mesh.springs {
            // The 3×3 stiffness block of the spring and its direction.
            let block: [[f64; 3]; 3] = match how {
                Stiffness::AtRest(k_max) => {
                    let d: [f64; 3] =
                        std::array::from_fn(|j| (mesh.rest[s.j][j] - mesh.rest[s.i][j]) / s.l0);
                    std::array::from_fn(|p| std::array::from_fn(|q| k_max / s.l0 * d[p] * d[q]))
                }
                Stiffness::At(law, x) => {
                    let r: [f64; 3] = std::array::from_fn(|j| x[s.j][j] - x[s.i][j]);
                    let l = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
                    let d = r.map(|c| c / l);
                    let eps = (s.l0 - l) / s.l0;
                    let (kt, f) = (law.stiffness(eps) / s.l0, law.force(eps));
                    // Tension (f < 0) stiffens across the direction; compression is left out.
                    let g = (-f / l).max(0.0);
                    std::array::from_fn(|p| {
                        std::array::from_fn(|q| {
                            let dd = d[p] * d[q];
                            kt * dd + g * ((p == q) as u8 as f64 - dd)
                        })
                    })
                }
            };
            for (a, b, sign) in [
                (s.i, s.i, 1.0),
                (s.j, s.j, 1.0),
                (s.i, s.j, -1.0),
                (s.j, s.i, -1.0),
            ] {
                if let (Some(ia), Some(ib)) = (idx[a], idx[b]) {
                    for p in 0..3 {
                        c[(ia + p, ib + p)] += sign * cs;
                        for q in 0..3 {
                            k[(ia + p, ib + q)] += sign * block[p][q];
                        }
                    }
                }
            }
        }
        for (i, di) in idx.iter().enumerate() {
            let Some(d) = di else { continue };
            for p in 0..3 {
                c[(d + p, d + p)] += cfg.node_damping / 1000.0;
                if i == mesh.contact {
                    c[(d + p, d + p)] += cfg.coupling.1 / 1000.0;
                    k[(d + p, d + p)] += cfg.coupling.0;
                }
            }
        }
        Linear {
            mass: cfg.node_mass,
            c,
            k,
        }
    }

    /// `G(h)` (mm, mm/s: `A = K / m · 1000`, `B = C / m · 1000`).
    pub fn step_matrix(&self, h: f64) -> DMatrix<f64> {
        let n = self.k.nrows();
        let a = &self.k * (1000.0 / self.mass);
        let b = &self.c * (1000.0 / self.mass);
        let id = DMatrix::<f64>::identity(n, n);
        let mut g = DMatrix::zeros(2 * n, 2 * n);
        g.view_mut((0, 0), (n, n))
            .copy_from(&(&id - &a * (h * h / 2.0)));
        g.view_mut((0, n), (n, n))
            .copy_from(&((&id - &b * (h / 2.0)) * h));
        g.view_mut((n, 0), (n, n)).copy_from(&(&a * -h));
        g.view_mut((n, n), (n, n)).copy_from(&(&id - &b * h));
        g
    }

    /// `ρ(G(h))`: the largest eigenvalue modulus, from a real Schur decomposition of at
    /// most 10⁴ iterations (nalgebra's own `complex_eigenvalues` iterates without a limit
    /// and never returns on some undamped patches). Where it does not converge,
    /// `‖G^(2¹⁴)‖^(1/2¹⁴)` by repeated squaring (renormalised), which tends to `ρ` from
    /// above (by a factor `κ^(1/16384)` for a non-normal `G`: on the safe side).
    pub fn spectral_radius(&self, h: f64) -> f64 {
        let g = self.step_matrix(h);
        if let Some(schur) = nalgebra::linalg::Schur::try_new(g.clone(), f64::EPSILON, 10_000) {
            return schur
                .complex_eigenvalues()
                .iter()
                .map(|z| z.norm())
                .fold(0.0, f64::max);
        }
        let (mut m, mut log_norm) = (g, 0.0f64);
        for _ in 0..14 {
            m = &m * &m;
            log_norm *= 2.0;
            let n = m.norm();
            if !(n.is_finite() && n > 0.0) {
                return if n == 0.0 { 0.0 } else { f64::INFINITY };
            }
            m /= n;
            log_norm += n.ln();
        }
        (log_norm / 16384.0).exp()
    }

    /// The largest `h` (s) with `ρ(G(h)) ≤ 1`, to 1e-6 relative, searched up to `limit`.
    pub fn exact_bound(&self, limit: f64) -> f64 {
        let stable = |h: f64| self.spectral_radius(h) <= 1.0 + 1e-12;
        let (mut lo, mut hi) = (0.0, limit);
        if stable(hi) {
            return hi;
        }
        for _ in 0..60 {
            if hi - lo <= 1e-6 * hi {
                break;
            }
            let mid = 0.5 * (lo + hi);
            if stable(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }
}
