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
//!
//! The same for the variants issue #17 names as candidates ([`Scheme`]), and their
//! accuracy: a step response of the linearised patch against a fine Runge–Kutta
//! solution ([`Linear::step_response`], [`response_error`]).

use crate::patch::{Mesh, TwinConfig, V};
use crate::reference::Reference;
use nalgebra::{DMatrix, DVector};

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
    /// The nodes' own damping (each free degree of freedom's, N·s/mm), also in `c`.
    pub node_damping: f64,
    /// The contact node's vertical degree of freedom (`None`: the contact node is fixed).
    pub contact_z: Option<usize>,
    /// The scheme of the configuration's integrator ([`Linear::exact_bound`]).
    pub scheme: Scheme,
}

/// A one-step scheme for the linearised patch, `a(x, v) = M⁻¹(−K x − C v)`: the paper's
/// improved Euler, which the core runs, and the candidates issue #17 names. Each costs
/// what the paper's does per node (a per-node factor at most); none changes the static
/// equilibrium (`K x = f`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scheme {
    /// The paper's improved Euler (eqs. 21–22): `v' = v + h a`, `x' = x + h (v + v')/2`.
    Paper,
    /// The paper's with the nodes' own damping `c_n` integrated exactly:
    /// `v' = e^(−h c_n/m) v + h (a + c_n v/m)`.
    ExactNodeDamping,
    /// The paper's with each node's own share of the damping (the diagonal of `C`: its
    /// springs' and its own) implicit: `v' = v + h D a`, `D = (I + h diag(C)/m)⁻¹`.
    ImplicitOwnDamping,
    /// Symplectic Euler: `v' = v + h a`, `x' = x + h v'`.
    Symplectic,
    /// Symplectic Euler with each node's own share of the damping implicit.
    SymplecticImplicitOwnDamping,
    /// Symplectic Euler with one factor for every node: `D = (1 + h max diag(C)/m)⁻¹`.
    SymplecticImplicitUniformDamping,
}

impl Scheme {
    /// The scheme the core runs for `integrator`.
    pub fn of(integrator: mccs::Integrator) -> Scheme {
        match integrator {
            mccs::Integrator::ImprovedEuler => Scheme::Paper,
            mccs::Integrator::SymplecticDamped => Scheme::SymplecticImplicitUniformDamping,
        }
    }

    /// Every scheme, the paper's first.
    pub const ALL: [Scheme; 6] = [
        Scheme::Paper,
        Scheme::ExactNodeDamping,
        Scheme::ImplicitOwnDamping,
        Scheme::Symplectic,
        Scheme::SymplecticImplicitOwnDamping,
        Scheme::SymplecticImplicitUniformDamping,
    ];

    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Scheme::Paper => "paper",
            Scheme::ExactNodeDamping => "exact_node_damping",
            Scheme::ImplicitOwnDamping => "implicit_own_damping",
            Scheme::Symplectic => "symplectic",
            Scheme::SymplecticImplicitOwnDamping => "symplectic_implicit_own_damping",
            Scheme::SymplecticImplicitUniformDamping => "symplectic_implicit_uniform_damping",
        }
    }

    /// `x' = x + h (α v + β v')`: `(α, β)`.
    fn position_weights(self) -> (f64, f64) {
        match self {
            Scheme::Symplectic
            | Scheme::SymplecticImplicitOwnDamping
            | Scheme::SymplecticImplicitUniformDamping => (0.0, 1.0),
            _ => (0.5, 0.5),
        }
    }
}

/// One step of a [`Scheme`] as matrices: `v' = P v + h D (−A x − B' v + a_f)`.
struct StepParts {
    a: DMatrix<f64>,
    p: DMatrix<f64>,
    d: DMatrix<f64>,
    b: DMatrix<f64>,
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
            node_damping: cfg.node_damping / 1000.0,
            contact_z: idx[mesh.contact].map(|d| d + 2),
            scheme: Scheme::of(cfg.integrator),
        }
    }

    /// `A = K / m · 1000` and `B = C / m · 1000` (mm, mm/s, s).
    fn rates(&self) -> (DMatrix<f64>, DMatrix<f64>) {
        (
            &self.k * (1000.0 / self.mass),
            &self.c * (1000.0 / self.mass),
        )
    }

    /// The matrices of one step of `scheme` at `h` (s).
    fn parts(&self, scheme: Scheme, h: f64) -> StepParts {
        let n = self.k.nrows();
        let (a, b) = self.rates();
        let id = DMatrix::<f64>::identity(n, n);
        let own =
            |b: &DMatrix<f64>| DMatrix::from_diagonal(&b.diagonal().map(|x| 1.0 / (1.0 + h * x)));
        match scheme {
            Scheme::Paper | Scheme::Symplectic => StepParts {
                a,
                p: id.clone(),
                d: id,
                b,
            },
            Scheme::ExactNodeDamping => {
                let bn = self.node_damping * 1000.0 / self.mass;
                StepParts {
                    a,
                    p: &id * (-h * bn).exp(),
                    b: &b - &id * bn,
                    d: id,
                }
            }
            Scheme::SymplecticImplicitUniformDamping => {
                let most = b.diagonal().max();
                StepParts {
                    a,
                    d: &id / (1.0 + h * most),
                    p: id,
                    b,
                }
            }
            Scheme::ImplicitOwnDamping | Scheme::SymplecticImplicitOwnDamping => StepParts {
                a,
                p: id,
                d: own(&b),
                b,
            },
        }
    }

    /// `G(h)` of `scheme` (mm, mm/s): `v' = V_x x + V_v v` and `x' = x + h (α v + β v')`.
    pub fn step_matrix_of(&self, scheme: Scheme, h: f64) -> DMatrix<f64> {
        let n = self.k.nrows();
        let StepParts { a, p, d, b } = self.parts(scheme, h);
        let (alpha, beta) = scheme.position_weights();
        let id = DMatrix::<f64>::identity(n, n);
        let vx = &d * &a * -h;
        let vv = &p - &d * &b * h;
        let mut g = DMatrix::zeros(2 * n, 2 * n);
        g.view_mut((0, 0), (n, n))
            .copy_from(&(&id + &vx * (h * beta)));
        g.view_mut((0, n), (n, n))
            .copy_from(&((&id * alpha + &vv * beta) * h));
        g.view_mut((n, 0), (n, n)).copy_from(&vx);
        g.view_mut((n, n), (n, n)).copy_from(&vv);
        g
    }

    /// `ρ(G(h))` of `scheme`: the largest eigenvalue modulus, from the eigenvalues of
    /// [`crate::eigenvalues::spectral_radius`] (at most `30 · 2n` QR iterations: nalgebra's
    /// own `complex_eigenvalues` iterates without a limit and never returns on some
    /// undamped patches, and its `Schur::try_new` took 2.3 times as long). Where it does
    /// not converge, `‖G^(2¹⁴)‖^(1/2¹⁴)` by repeated squaring (renormalised), which
    /// tends to `ρ` from above (by a factor `κ^(1/16384)` for a non-normal `G`: on the
    /// safe side).
    pub fn spectral_radius_of(&self, scheme: Scheme, h: f64) -> f64 {
        let g = self.step_matrix_of(scheme, h);
        if let Some(rho) = crate::eigenvalues::spectral_radius(&g) {
            return rho;
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

    /// The largest `h` (s) with `ρ(G(h)) ≤ 1` for the configuration's scheme
    /// ([`Linear::scheme`]), to 1e-6 relative, searched up to `limit`.
    pub fn exact_bound(&self, limit: f64) -> f64 {
        self.exact_bound_within(self.scheme, limit, 1e-6)
    }

    /// [`Linear::exact_bound`] for `scheme`, to `rel` relative. (Bisection assumes one
    /// stable interval below the bound: `the_integrator_variants_report` samples below
    /// it on the report's patches.)
    pub fn exact_bound_within(&self, scheme: Scheme, limit: f64, rel: f64) -> f64 {
        let stable = |h: f64| self.spectral_radius_of(scheme, h) <= 1.0 + 1e-12;
        let (mut lo, mut hi) = (0.0, limit);
        if stable(hi) {
            return hi;
        }
        for _ in 0..60 {
            if hi - lo <= rel * hi {
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

    /// A step response's contact degree of freedom and its forcing `a_f`: a constant unit
    /// vertical acceleration on the contact node (any size: the patch is linear). `None`
    /// when it is fixed.
    fn forced(&self) -> Option<(usize, DVector<f64>)> {
        let c = self.contact_z?;
        let mut force = DVector::<f64>::zeros(self.k.nrows());
        force[c] = 1.0;
        Some((c, force))
    }

    /// The contact node's vertical displacement at every 1 ms tick up to `ticks`, from
    /// rest under a constant vertical force on it, by a fourth-order Runge–Kutta at 5 µs
    /// steps (the same errors to two digits as at 1 µs on the report's patches): the
    /// reference for [`Linear::step_response`]. `None` when the contact node is fixed.
    pub fn reference_step_response(&self, ticks: u32) -> Option<Vec<f64>> {
        let (c, force) = self.forced()?;
        let (a, b) = self.rates();
        let accel = |x: &DVector<f64>, v: &DVector<f64>| -(&a * x) - (&b * v) + &force;
        const FINE: u32 = 200;
        let h = 1e-3 / FINE as f64;
        let n = self.k.nrows();
        let (mut x, mut v) = (DVector::zeros(n), DVector::zeros(n));
        let mut out = Vec::new();
        for _ in 0..ticks {
            for _ in 0..FINE {
                let (k1x, k1v) = (v.clone(), accel(&x, &v));
                let (x2, v2) = (&x + &k1x * (h / 2.0), &v + &k1v * (h / 2.0));
                let (k2x, k2v) = (v2.clone(), accel(&x2, &v2));
                let (x3, v3) = (&x + &k2x * (h / 2.0), &v + &k2v * (h / 2.0));
                let (k3x, k3v) = (v3.clone(), accel(&x3, &v3));
                let (x4, v4) = (&x + &k3x * h, &v + &k3v * h);
                let (k4x, k4v) = (v4.clone(), accel(&x4, &v4));
                x += (k1x + k2x * 2.0 + k3x * 2.0 + k4x) * (h / 6.0);
                v += (k1v + k2v * 2.0 + k3v * 2.0 + k4v) * (h / 6.0);
            }
            out.push(x[c]);
        }
        Some(out)
    }

    /// The same by `scheme` at `substeps` steps per tick.
    pub fn step_response(&self, scheme: Scheme, substeps: u32, ticks: u32) -> Option<Vec<f64>> {
        let (c, force) = self.forced()?;
        let n = self.k.nrows();
        let h = 1e-3 / substeps as f64;
        let StepParts { a, p, d, b } = self.parts(scheme, h);
        let (alpha, beta) = scheme.position_weights();
        let (mut x, mut v) = (DVector::zeros(n), DVector::zeros(n));
        let mut out = Vec::new();
        for _ in 0..ticks {
            for _ in 0..substeps {
                let acc = &d * (-(&a * &x) - (&b * &v) + &force);
                let vn = &p * &v + acc * h;
                x += (&v * alpha + &vn * beta) * h;
                v = vn;
            }
            out.push(x[c]);
        }
        Some(out)
    }
}

/// The largest difference between a response and its reference, relative to the
/// reference's largest value.
pub fn response_error(response: &[f64], reference: &[f64]) -> f64 {
    let peak = reference.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let worst = response
        .iter()
        .zip(reference)
        .fold(0.0f64, |m, (x, r)| m.max((x - r).abs()));
    worst / peak
}
