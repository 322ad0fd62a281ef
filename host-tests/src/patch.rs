//! The f64 twin of the core's patch solver: the standard patch of `docs/model.md`, the
//! reference law, the paper's improved Euler (eqs. 21–22) or the symplectic option
//! (`mccs::Integrator`), and the same virtual coupling, written without the core's code
//! so that tests can hold one against the other.
//!
//! Nodes are stored as they are (fixed ones included); positions are absolute, in mm, in
//! the patch frame (origin at the contact node's rest position, `z` up).

use crate::reference::Reference;

/// A 3-vector of f64.
pub type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm(a: V) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// One spring: node indices and rest length (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spring {
    /// First node.
    pub i: usize,
    /// Second node.
    pub j: usize,
    /// Rest length, mm.
    pub l0: f64,
}

/// Nodes and springs of a patch.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Rest positions, mm.
    pub rest: Vec<V>,
    /// Whether each node is fixed.
    pub fixed: Vec<bool>,
    /// The springs.
    pub springs: Vec<Spring>,
    /// The contact node.
    pub contact: usize,
}

impl Mesh {
    /// the standard patch of `docs/model.md`: `n × n` surface nodes (index `i·n + j`), then the base
    /// layer (index `n² + i·n + j`); springs with both ends fixed are left out.
    pub fn standard(n: usize, spacing: f64) -> Mesh {
        let c = (n / 2) as f64;
        Mesh::grid(n, spacing, |i, j| {
            [(i as f64 - c) * spacing, (j as f64 - c) * spacing, 0.0]
        })
    }

    /// The standard patch's nodes and springs over any rest surface: surface node `(i, j)`
    /// at `surface(i, j)` (mm), its base node `spacing` below it; the outer ring and the
    /// base fixed; the contact node `(n/2, n/2)`.
    pub fn grid(n: usize, spacing: f64, surface: impl Fn(usize, usize) -> V) -> Mesh {
        let mut rest = Vec::new();
        let mut fixed = Vec::new();
        for layer in [0.0, -spacing] {
            for i in 0..n {
                for j in 0..n {
                    let p = surface(i, j);
                    rest.push([p[0], p[1], p[2] + layer]);
                    let ring = i == 0 || j == 0 || i == n - 1 || j == n - 1;
                    fixed.push(layer < 0.0 || ring);
                }
            }
        }
        let id = |i: usize, j: usize| i * n + j;
        let mut pairs = Vec::new();
        for i in 0..n {
            for j in 0..n {
                if i + 1 < n {
                    pairs.push((id(i, j), id(i + 1, j)));
                }
                if j + 1 < n {
                    pairs.push((id(i, j), id(i, j + 1)));
                }
                if i + 1 < n && j + 1 < n {
                    pairs.push((id(i, j), id(i + 1, j + 1)));
                    pairs.push((id(i + 1, j), id(i, j + 1)));
                }
                pairs.push((id(i, j), n * n + id(i, j)));
            }
        }
        let springs = pairs
            .into_iter()
            .filter(|&(a, b)| !(fixed[a] && fixed[b]))
            .map(|(a, b)| Spring {
                i: a,
                j: b,
                l0: norm(sub(rest[b], rest[a])),
            })
            .collect();
        Mesh {
            rest,
            fixed,
            springs,
            contact: id(n / 2, n / 2),
        }
    }
}

/// Configuration of the twin (same meaning and units as the core's `SolverConfig`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwinConfig {
    /// Tick rate, Hz.
    pub tick_hz: f64,
    /// Substeps per tick.
    pub substeps: u32,
    /// Node mass, kg.
    pub node_mass: f64,
    /// Spring (relative) damping, N·s/m.
    pub spring_damping: f64,
    /// Node (absolute) damping, N·s/m.
    pub node_damping: f64,
    /// Coupling stiffness N/mm, damping N·s/m, max force per axis N.
    pub coupling: (f64, f64, f64),
    /// The integrator (the twin's own implementation of each, [`Twin`]).
    pub integrator: mccs::Integrator,
}

impl TwinConfig {
    /// The twin of a core `SolverConfig`, at `substeps` per tick.
    pub fn from_solver(cfg: &mccs::SolverConfig, substeps: u32) -> TwinConfig {
        TwinConfig {
            tick_hz: cfg.tick_hz,
            substeps,
            node_mass: cfg.node_mass,
            spring_damping: cfg.spring_damping,
            node_damping: cfg.node_damping,
            coupling: (
                cfg.coupling.stiffness,
                cfg.coupling.damping,
                cfg.coupling.max_force,
            ),
            integrator: cfg.integrator,
        }
    }
}

/// The law's largest tangent stiffness over the default strain domain (N per unit
/// strain), at 1,001 evenly spaced strains: the `k_max` of [`substeps`] for a twin of
/// `law`.
pub fn max_stiffness(law: &Reference) -> f64 {
    let (lo, hi) = mccs::table::DEFAULT_DOMAIN;
    (0..=1000)
        .map(|i| law.stiffness(lo + (hi - lo) * i as f64 / 1000.0))
        .fold(0.0, f64::max)
}

/// The most substeps per tick the twin runs (the CLI's reference backend): more than the
/// core's 64, since its rule ([`substeps`]) is the conservative one, which asks for more
/// than the core's exact bound (spring damping 30 N·s/m at the defaults: over 64, which
/// the core runs; `tests/cli/replay.rs`), and the `f64` twin has no tick to fit.
pub const TWIN_MAX_SUBSTEPS: u32 = 1024;

/// Substeps per tick for `mesh` with the law's largest tangent stiffness `k_max` (N per
/// unit strain), from the conservative bound of the core's docs (`solver::stability`),
/// computed independently: every spring at most `k_max / l0` stiff in every direction
/// against its damping `C` in every direction, `θ = k_max / (l0_min C)` or the coupling's
/// `k_c / (c + b_c)`; `γ` the damping's largest Gershgorin row sum over the mass; `h` half
/// of `min(2/θ, 2/γ)`. `None` without damping; `u32::MAX` where no step is stable in
/// `f64` (a spring so short, or a node so light, that `h` is zero).
pub fn substeps(mesh: &Mesh, k_max: f64, cfg: &TwinConfig) -> Option<u32> {
    let n = mesh.rest.len();
    let (cs, cn) = (cfg.spring_damping, cfg.node_damping);
    let (kc, bc) = (cfg.coupling.0 * 1000.0, cfg.coupling.1);
    let mut row = vec![cn; n];
    let mut k_row = vec![0.0; n];
    let mut shortest = f64::INFINITY;
    for s in &mesh.springs {
        shortest = shortest.min(s.l0);
        let both = !mesh.fixed[s.i] && !mesh.fixed[s.j];
        for e in [s.i, s.j] {
            row[e] += if both { 2.0 * cs } else { cs };
            k_row[e] += k_max / s.l0 * 1000.0 * if both { 2.0 } else { 1.0 };
        }
    }
    row[mesh.contact] += bc;
    k_row[mesh.contact] += kc;
    let free = (0..n).filter(|&i| !mesh.fixed[i]);
    let gamma = free.clone().map(|i| row[i]).fold(0.0, f64::max) / cfg.node_mass;
    let theta = if cs > 0.0 {
        let springs = k_max / shortest * 1000.0 / cs;
        let coupling = if cn + bc > 0.0 {
            kc / (cn + bc)
        } else {
            springs + kc / cs
        };
        springs.max(coupling)
    } else if cn > 0.0 {
        free.map(|i| k_row[i]).fold(0.0, f64::max) / cn
    } else {
        return None;
    };
    let h = 0.5 * (2.0 / theta).min(2.0 / gamma);
    // (The cast saturates: an `h` of zero or below f64's range is u32::MAX substeps.)
    let h = if h.is_nan() { 0.0 } else { h };
    Some((1.0 / (cfg.tick_hz * h)).ceil().max(1.0) as u32)
}

/// The f64 patch.
#[derive(Clone, Debug)]
pub struct Twin {
    /// The mesh.
    pub mesh: Mesh,
    /// The law.
    pub law: Reference,
    /// Configuration.
    pub cfg: TwinConfig,
    /// Positions, mm.
    pub x: Vec<V>,
    /// Velocities, mm/s.
    pub v: Vec<V>,
    probe_prev: V,
    coupling_force: V,
    reaction: V,
    /// When set, every spring is linear with this stiffness (N per unit strain) instead
    /// of the law: the linearisation the stability bound is computed on.
    pub linear_stiffness: Option<f64>,
}

impl Twin {
    /// At rest.
    pub fn new(mesh: Mesh, law: Reference, cfg: TwinConfig) -> Twin {
        let x = mesh.rest.clone();
        let v = vec![[0.0; 3]; x.len()];
        Twin {
            mesh,
            law,
            cfg,
            x,
            v,
            probe_prev: [0.0; 3],
            coupling_force: [0.0; 3],
            reaction: [0.0; 3],
            linear_stiffness: None,
        }
    }

    fn h(&self) -> f64 {
        1.0 / (self.cfg.tick_hz * self.cfg.substeps as f64)
    }

    /// Force of every spring on every node (N): the law along the edge + eq. 17 damping.
    pub fn spring_forces(&self, x: &[V], v: &[V]) -> Vec<V> {
        let mut f = vec![[0.0; 3]; x.len()];
        for s in &self.mesh.springs {
            let d = sub(x[s.j], x[s.i]);
            let l = norm(d);
            let strain = (s.l0 - l) / s.l0;
            let force = match self.linear_stiffness {
                Some(k) => k * strain,
                None => self.law.force(strain),
            };
            let dv = sub(v[s.j], v[s.i]);
            for k in 0..3 {
                let along = if l > 0.0 { force * d[k] / l } else { 0.0 };
                let on_i = -along + self.cfg.spring_damping / 1000.0 * dv[k];
                f[s.i][k] += on_i;
                f[s.j][k] -= on_i;
            }
        }
        f
    }

    /// The symplectic integrator's `γ` (1/s), computed here from the mesh: the largest
    /// damping on one free node (its own, each of its springs', the coupling's at the
    /// contact) over the node mass.
    pub fn most_damping(&self) -> f64 {
        let n = self.mesh.rest.len();
        let mut diag = vec![self.cfg.node_damping; n];
        for s in &self.mesh.springs {
            diag[s.i] += self.cfg.spring_damping;
            diag[s.j] += self.cfg.spring_damping;
        }
        diag[self.mesh.contact] += self.cfg.coupling.1;
        (0..n)
            .filter(|&i| !self.mesh.fixed[i])
            .map(|i| diag[i])
            .fold(0.0, f64::max)
            / self.cfg.node_mass
    }

    /// Advances every free node by one substep under the forces `f` (N; the nodes' own
    /// damping is added here): the paper's improved Euler, `v' = v + h F/m`,
    /// `x' = x + h (v + v')/2`; or symplectic Euler with one implicit damping factor,
    /// `v' = v + h F/(m (1 + h γ))`, `x' = x + h v'`.
    pub fn integrate(&mut self, f: &[V]) {
        let h = self.h();
        let symplectic = self.cfg.integrator == mccs::Integrator::SymplecticDamped;
        let d = if symplectic {
            1.0 / (1.0 + h * self.most_damping())
        } else {
            1.0
        };
        for i in 0..self.x.len() {
            if self.mesh.fixed[i] {
                continue;
            }
            for k in 0..3 {
                let net = f[i][k] - self.cfg.node_damping / 1000.0 * self.v[i][k];
                let v_new = self.v[i][k] + h * d * 1000.0 * net / self.cfg.node_mass;
                self.x[i][k] += if symplectic {
                    h * v_new
                } else {
                    0.5 * h * (self.v[i][k] + v_new)
                };
                self.v[i][k] = v_new;
            }
        }
    }

    fn substep(&mut self, probe: Option<(V, V)>, held: Option<(V, V)>) {
        let mut f = self.spring_forces(&self.x, &self.v);
        let c = self.mesh.contact;
        self.reaction = f[c];
        self.coupling_force = [0.0; 3];
        if let Some((p, pv)) = probe {
            let (kc, bc, fmax) = self.cfg.coupling;
            if p[2] < self.x[c][2] {
                for k in 0..3 {
                    let fk = kc * (p[k] - self.x[c][k]) + bc / 1000.0 * (pv[k] - self.v[c][k]);
                    self.coupling_force[k] = fk.clamp(-fmax, fmax);
                    f[c][k] += self.coupling_force[k];
                }
            }
        }
        self.integrate(&f);
        if let Some((pos, vel)) = held {
            self.x[c] = pos;
            self.v[c] = vel;
        }
    }

    /// One tick with the probe at `probe` (mm); the device force (N).
    pub fn step(&mut self, probe: V) -> V {
        let pv = sub(probe, self.probe_prev).map(|d| d * self.cfg.tick_hz);
        self.probe_prev = probe;
        for _ in 0..self.cfg.substeps {
            self.substep(Some((probe, pv)), None);
        }
        self.coupling_force.map(|f| -f)
    }

    /// One tick with the contact node held at `position` (absolute, mm), moved there
    /// linearly over the tick; the spring force on it (N).
    pub fn step_held(&mut self, position: V) -> V {
        let c = self.mesh.contact;
        let start = self.x[c];
        let vel = sub(position, start).map(|d| d * self.cfg.tick_hz);
        let n = self.cfg.substeps;
        for s in 1..=n {
            let t = s as f64 / n as f64;
            let pos = [0, 1, 2].map(|k| start[k] + (position[k] - start[k]) * t);
            self.substep(None, Some((pos, vel)));
        }
        self.reaction
    }

    /// Kinetic energy (J): Σ ½ m |v|², v in m/s.
    pub fn kinetic_energy(&self) -> f64 {
        self.v
            .iter()
            .zip(&self.mesh.fixed)
            .filter(|(_, f)| !**f)
            .map(|(v, _)| {
                0.5 * self.cfg.node_mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) * 1e-6
            })
            .sum()
    }
}
