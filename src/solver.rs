//! `Solver`: the MCCS patch in fixed point, one call per haptic tick.
//!
//! Each spring applies the tabulated law ([`ForceTable`]) to its compressive strain
//! `ε = (l0 − l)/l0` along the edge, plus the paper's relative-velocity damping (eq. 17);
//! each free node integrates `m a = f_ext − Σ F_spring − Σ C (v_i − v_j) − c v_i` with the
//! paper's improved Euler: velocity by an explicit Euler step (eq. 21), position by the
//! trapezoid of old and new velocity (eq. 22). The probe drives the contact node through a
//! virtual [`Coupling`]; the device renders the coupling force.
//!
//! # Per tick
//! [`Solver::step`] runs a fixed number of substeps (chosen at construction), each a loop
//! over the springs and one over the nodes: constant time, no division, no square root
//! (the length comes from a warm-started Newton step for `1/l`), no floating point, no
//! heap, no panic; every step saturates or works within ranges the clamps bound (see
//! [`crate::spring`]).
//!
//! # Units and formats
//! Displacements from rest in mm, Q24, kept within ±64 mm; velocities in mm/s, Q16, kept
//! within ±16384 mm/s (the [`crate::spring::Narrow`] arithmetic stores them as `C v`, N,
//! see [`crate::spring::Damping`]); forces in N, Q20 (±2048 N; one spring's force, law and damping,
//! within ±64 N). Positions are in the patch frame (origin at the contact node's rest
//! position, `z` up). The spring's own formats are in [`crate::spring`].
//!
//! # Stability (the substep count)
//! For one mass `m` on a spring `K` with damping rate `γ = C/m`, the improved Euler step
//! `h` is stable exactly when `h < 2/γ` and `h < 2 C/K`: unlike symplectic Euler it
//! *amplifies* an undamped oscillation (by `1 + h²ω²/2` per step), so it needs damping.
//! The solver applies that per node, Gershgorin-style, with a safety factor of 2:
//! `K_i = Σ k_max / l0` over the node's springs (+ the coupling), `C_i = Σ C` over its
//! springs + the node damping (+ the coupling damper), and
//! `h ≤ ½ · min(2 m / (2 max C_i), 2 min(C_i / K_i))`, where `k_max` is the table's largest
//! tangent stiffness. The masses are haptic masses (a few grams per node), not the
//! tissue's: they set how many substeps a tick needs, not the settled force.

use crate::coupling::{Coupling, CouplingQ};
use crate::q::{self, V3};
use crate::spring::{Arith, Damping, DefaultArith};
use crate::table::ForceTable;
use crate::topology::{Topology, GROUND};
use crate::Force;
use core::marker::PhantomData;
use fixed::types::I8F24;

/// Length in mm, Q24 (±128 mm).
pub type Length = I8F24;
/// Velocity in mm/s, Q16 (±32768 mm/s).
pub type Velocity = fixed::types::I16F16;

/// Fraction bits of velocities (mm/s).
const VEL_FRAC: u32 = 16;
/// Fraction bits of forces (N).
const FORCE_FRAC: u32 = 20;
/// Fraction bits of `h/m` ((mm/s)/N) and of `1 − h c/m` (the velocity kept through the
/// node damping): Q20 N · Q20 and Q16 mm/s · Q24 are both Q40, shifted by 24 to Q16 mm/s.
const HM_FRAC: u32 = 20;
const KEEP_FRAC: u32 = 24;
const _: () = assert!(VEL_FRAC + KEEP_FRAC == FORCE_FRAC + HM_FRAC);
/// Fraction bits of `h/2` (s): Q16 mm/s · Q40 s → high word Q24 mm.
const HALF_H_FRAC: u32 = 40;
/// Most springs at one node: their summed forces cannot overflow the Q20 accumulator.
pub const MAX_SPRINGS_PER_NODE: usize = 20;
/// Largest displacement from rest, mm in Q24: just under 64 mm.
const DISP_LIMIT: i32 = 1 << 30;
/// Largest speed, mm/s in Q16: just under 16384 mm/s.
const VEL_LIMIT: i32 = 1 << 30;
/// Runtime configuration of a [`Solver`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverConfig {
    /// Haptic tick rate, Hz (1 … 100,000).
    pub tick_hz: f64,
    /// Haptic (scaled) mass of each free node, kg.
    pub node_mass: f64,
    /// Relative-velocity damping of each spring (eq. 17), N·s/m (0 … 30).
    pub spring_damping: f64,
    /// Absolute damping of each node (eq. 21), N·s/m (0 … 10,000).
    pub node_damping: f64,
    /// Largest number of substeps per tick the stability bound may ask for.
    pub max_substeps: u32,
    /// The probe coupling.
    pub coupling: Coupling,
}

impl Default for SolverConfig {
    /// 1 kHz; 5 g nodes; 1 N·s/m per spring, 0.05 N·s/m per node; at most 64 substeps;
    /// the default coupling.
    fn default() -> Self {
        Self {
            tick_hz: 1000.0,
            node_mass: 0.005,
            spring_damping: 1.0,
            node_damping: 0.05,
            max_substeps: 64,
            coupling: Coupling::default(),
        }
    }
}

/// A configuration value the solver cannot use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum ConfigKey {
    TickHz,
    NodeMass,
    SpringDamping,
    NodeDamping,
    MaxSubsteps,
    CouplingStiffness,
    CouplingDamping,
    CouplingMaxForce,
}

impl ConfigKey {
    /// The field's name.
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::TickHz => "tick_hz",
            Self::NodeMass => "node_mass",
            Self::SpringDamping => "spring_damping",
            Self::NodeDamping => "node_damping",
            Self::MaxSubsteps => "max_substeps",
            Self::CouplingStiffness => "coupling.stiffness",
            Self::CouplingDamping => "coupling.damping",
            Self::CouplingMaxForce => "coupling.max_force",
        }
    }
}

/// Why a solver could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SolverError {
    /// A configuration value is out of its range (see [`SolverConfig`]).
    Config(ConfigKey),
    /// No damping at all: the improved Euler step is unstable at any step size.
    NoDamping,
    /// The stability bound needs more substeps per tick than `max_substeps`.
    TooManySubsteps {
        /// Substeps the bound asks for (saturated at `u32::MAX`).
        needed: u32,
    },
    /// The topology has no contact node.
    NoContact,
}

impl core::fmt::Display for SolverError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Config(k) => write!(f, "{}: out of range", k.as_str()),
            Self::NoDamping => f.write_str(
                "spring_damping/node_damping: the improved Euler integrator needs damping",
            ),
            Self::TooManySubsteps { needed } => write!(
                f,
                "max_substeps: stability needs {needed} substeps per tick (raise max_substeps, the node mass or the damping, or lower the tick rate)"
            ),
            Self::NoContact => f.write_str("topology: no contact node"),
        }
    }
}

impl core::error::Error for SolverError {}

/// How the contact node is driven.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Drive {
    /// By the probe through the coupling.
    Probe { probe: V3, probe_vel: V3 },
    /// Held at a commanded displacement moving at a commanded velocity.
    Hold { disp: V3, vel: V3 },
}

/// The integrator's coefficients as 16-bit operands with run-time shifts, for
/// [`crate::spring::Narrow`] (each to 2⁻¹⁵ relative). Its nodes store the velocity as
/// `V = C_v v` in N, Q(20 + g) (`C_v` and `g` from [`Damping`]), so that a spring's
/// damping force is a difference of stored values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct NarrowStep {
    /// `h c_node / m` (≤ ½), Q(16 + `damp_sh`).
    damp: i32,
    damp_sh: u8,
    /// `C_v h / m` (dimensionless) as a 16-bit operand: `f · step` (f Q20 N) is a stored
    /// velocity after the shifts.
    step: i32,
    step_sh1: u8,
    step_sh2: u8,
    /// Largest force (Q20 N) whose velocity step fits: `|f step| / 2^step_sh1 ≤ 2³⁰`.
    f_hold: i32,
    /// Whether the fast path applies (no hold: `f_hold` is `i32::MAX`; `h/(2 C_v)` in
    /// stored units to mm < 2; stored velocities within ±2²⁸): the step as
    /// `⌊f · fast / 2¹⁶⌋ >> fast_sh` and the position change as
    /// `⌊(V + V') · fast_hh / 2¹⁴⌋ >> fast_hh_sh`.
    fast_path: bool,
    fast: i32,
    fast_sh: u8,
    fast_hh: i32,
    fast_hh_sh: u8,
    /// `h / (2 C_v)`, mm/N, as a 16-bit operand: `V · hh` is Q24 mm after the shifts.
    hh: i32,
    hh_sh1: u8,
    hh_sh2: u8,
    /// `C_v` as a 16-bit operand: mm/s (Q16) to a stored velocity (`cv_sh` ≥ 8).
    cv: i32,
    cv_sh: u8,
    /// `1 / C_v` as a 16-bit operand: a stored velocity to mm/s (Q16).
    inv_cv: i32,
    inv_cv_sh: u8,
    /// The velocity limit (16384 mm/s) as a stored velocity.
    v_limit: i32,
}

/// `(sh1, sh2)` with `sh1 = min(sh, 16)`: a [`q::mul_s_by`] shift and the rest.
fn split_shift(sh: u32) -> (u32, u32) {
    (sh.min(16), sh.saturating_sub(16))
}

impl NarrowStep {
    #[inline(never)]
    fn new(h: f64, config: &SolverConfig) -> Self {
        let cv = Damping::velocity_scale(config.spring_damping);
        // Stored velocities: Q(20 + g) N.
        let vq = FORCE_FRAC + Damping::velocity_frac(config.spring_damping, h / config.node_mass);
        let (damp, damp_sh) = q::norm16(h * config.node_damping / config.node_mass, 16, 30);
        // C_v h/m ≤ 0.03 · 2000 (checked), as Q(x): f · step / 2^(x + 20 − vq).
        let (step, x) = q::norm16(cv * 1000.0 * h / config.node_mass, 0, 60);
        let (step_sh1, step_sh2) = split_shift((x + FORCE_FRAC).saturating_sub(vq));
        let f_hold = if step > 0 {
            ((1i64 << (30 + step_sh1)) / step as i64).min(i32::MAX as i64) as i32
        } else {
            i32::MAX
        };
        let v_limit = q::from_f64(16384.0 * cv, vq);
        // Without the hold the step per unit force is ≤ ½ in stored units: one operand
        // and one right shift after a 16-bit product.
        let factor =
            cv * 1000.0 * h / config.node_mass * libm::ldexp(1.0, vq as i32 - FORCE_FRAC as i32);
        let factor_hh =
            0.5 * h / cv * libm::ldexp(1.0, crate::topology::LEN_FRAC as i32 - vq as i32);
        let fast_path = f_hold == i32::MAX && factor_hh < 2.0 - 1.0 / 16384.0 && v_limit <= 1 << 28;
        let ((fast, fast_sh), (fast_hh, fast_hh_sh)) = if fast_path {
            (q::norm16(factor, 16, 40), q::norm16(factor_hh, 14, 40))
        } else {
            ((0, 0), (0, 0))
        };
        // h/(2 C_v) ≤ 2⁻⁹ s / 10⁻⁴ N·s/mm < 20 mm/N, as Q(y): V · hh / 2^(vq + y − 24).
        let (hh, y) = q::norm16(0.5 * h / cv, 0, 60);
        let (hh_sh1, hh_sh2) = split_shift((vq + y).saturating_sub(crate::topology::LEN_FRAC));
        // mm/s Q16 · C_v Q(e) / 2^(16 + e − vq) = Q(vq).
        let (cvq, e) = q::norm16(cv, 0, 60);
        let cv_sh = (VEL_FRAC + e).saturating_sub(vq);
        // Q(vq) · 1/C_v Q(z) / 2^(vq + z − 16) = Q16 (1/C_v ≤ 10⁴: z ≥ 1).
        let (inv_cv, z) = q::norm16(1.0 / cv, 0, 30);
        Self {
            damp,
            damp_sh: damp_sh as u8,
            step,
            step_sh1: step_sh1 as u8,
            step_sh2: step_sh2 as u8,
            f_hold,
            fast_path,
            fast,
            fast_sh: fast_sh as u8,
            fast_hh,
            fast_hh_sh: fast_hh_sh as u8,
            hh,
            hh_sh1: hh_sh1 as u8,
            hh_sh2: hh_sh2 as u8,
            cv: cvq,
            cv_sh: cv_sh as u8,
            inv_cv,
            inv_cv_sh: (vq + z - VEL_FRAC) as u8,
            v_limit,
        }
    }

    /// A velocity (Q16 mm/s, within ±2³⁰) as the node stores it.
    fn store(&self, v: i32) -> i32 {
        let (sh1, sh2) = split_shift(self.cv_sh as u32);
        (q::mul_s_by(v, self.cv, sh1) >> sh2)
            .max(-self.v_limit)
            .min(self.v_limit)
    }

    /// A stored velocity in mm/s (Q16).
    fn velocity(&self, stored: i32) -> i32 {
        let (sh1, sh2) = split_shift(self.inv_cv_sh as u32);
        q::mul_s_by(stored, self.inv_cv, sh1) >> sh2
    }
}

/// The fixed-point coefficients derived from a [`SolverConfig`] and the step size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Coeffs {
    /// `h/m`, (mm/s)/N, Q20.
    h_over_m: i32,
    /// `1 − h c_node / m`, dimensionless, Q24 (in [½, 1] by the stability bound).
    keep: i32,
    /// `h/2`, s, Q40.
    half_h: i32,
    /// The same step in 16-bit coefficients ([`crate::spring::Narrow`]).
    narrow: NarrowStep,
    /// Spring damping in both arithmetics' formats.
    spring_damping: Damping,
    /// Tick rate, Hz (for the probe velocity).
    tick_hz: i32,
    coupling: CouplingQ,
}

/// A force table with the substeps and coefficients it needs on a given topology and
/// configuration: built by [`Solver::prepare`] (start-up or main loop, `f64`), switched in
/// by [`Solver::apply`] between two ticks (a few moves). `A`: the spring arithmetic of
/// the solver it is for (its coefficients differ).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParamSet<const S: usize, A = DefaultArith> {
    table: ForceTable<S>,
    substeps: u32,
    c: Coeffs,
    arith: PhantomData<A>,
}

impl<const S: usize, A> ParamSet<S, A> {
    /// The table.
    pub fn table(&self) -> &ForceTable<S> {
        &self.table
    }

    /// Substeps per tick.
    pub fn substeps(&self) -> u32 {
        self.substeps
    }
}

/// The patch solver: topology, force table and state. `NODES` counts the ground slot;
/// `A` is the spring arithmetic ([`crate::spring`]: [`crate::spring::Wide`] by default,
/// [`crate::spring::Narrow`] on the Cortex-M0).
#[derive(Clone, Debug)]
pub struct Solver<const NODES: usize, const EDGES: usize, const S: usize, A = DefaultArith> {
    topo: Topology<NODES, EDGES>,
    table: ForceTable<S>,
    c: Coeffs,
    substeps: u32,
    contact: usize,
    /// Per node: displacement, velocity, force accumulator.
    nodes: [Node; NODES],
    /// Each spring's warm-started `l0 / l` in the arithmetic's format.
    warm: [i32; EDGES],
    /// Last probe position, Q24 mm.
    probe_prev: V3,
    /// Spring force on the contact node in the last substep, Q20 N.
    reaction: V3,
    /// Coupling force on the contact node in the last substep, Q20 N.
    coupling_force: V3,
    arith: PhantomData<A>,
}

impl<const NODES: usize, const EDGES: usize, const S: usize> Solver<NODES, EDGES, S> {
    /// Builds a solver at rest in this core's spring arithmetic
    /// ([`crate::spring::DefaultArith`]); computes the substeps per tick from the
    /// stability bound.
    #[inline(never)]
    pub fn new(
        topo: Topology<NODES, EDGES>,
        table: ForceTable<S>,
        config: &SolverConfig,
    ) -> Result<Self, SolverError> {
        Self::with_arith(topo, table, config, DefaultArith::default())
    }
}

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith> Solver<NODES, EDGES, S, A> {
    /// [`Solver::new`] in a chosen spring arithmetic (e.g. [`crate::spring::Narrow`] on a
    /// host, to see what the M0 computes).
    #[inline(never)]
    pub fn with_arith(
        topo: Topology<NODES, EDGES>,
        table: ForceTable<S>,
        config: &SolverConfig,
        _arith: A,
    ) -> Result<Self, SolverError> {
        let contact = topo.contact() as usize;
        if contact == GROUND as usize {
            return Err(SolverError::NoContact);
        }
        let set = Self::prepare_for(&topo, table, config)?;
        Ok(Self {
            topo,
            table: set.table,
            c: set.c,
            substeps: set.substeps,
            contact,
            nodes: [Node::ZERO; NODES],
            warm: [A::REST; EDGES],
            probe_prev: [0; 3],
            reaction: [0; 3],
            coupling_force: [0; 3],
            arith: PhantomData,
        })
    }

    /// Prepares a parameter set for this solver's topology: the table, the substeps the
    /// stability bound asks for with it, and the fixed-point coefficients.
    pub fn prepare(
        &self,
        table: ForceTable<S>,
        config: &SolverConfig,
    ) -> Result<ParamSet<S, A>, SolverError> {
        Self::prepare_for(&self.topo, table, config)
    }

    /// Switches to a prepared parameter set; the state (positions, velocities) is kept.
    pub fn apply(&mut self, set: ParamSet<S, A>) {
        self.table = set.table;
        self.substeps = set.substeps;
        self.c = set.c;
    }

    /// [`Solver::prepare`] for a topology without a solver (e.g. in another context than
    /// the one owning the solver).
    #[inline(never)]
    pub fn prepare_for(
        topo: &Topology<NODES, EDGES>,
        table: ForceTable<S>,
        config: &SolverConfig,
    ) -> Result<ParamSet<S, A>, SolverError> {
        let substeps = Self::substeps_for(topo, &table, config)?;
        let h = 1.0 / (config.tick_hz * substeps as f64);
        let cp = &config.coupling;
        // N·s/m → N·s/mm: / 1000. h/m: (s/kg = m/(s·N)) · 1000 → (mm/s)/N.
        let c = Coeffs {
            h_over_m: q::from_f64(1000.0 * h / config.node_mass, HM_FRAC),
            keep: q::from_f64(1.0 - h * config.node_damping / config.node_mass, KEEP_FRAC),
            half_h: q::from_f64(0.5 * h, HALF_H_FRAC),
            // Only the narrow arithmetic's (software f64 at start-up: kept out of the
            // other builds' flash).
            narrow: if A::NARROW {
                NarrowStep::new(h, config)
            } else {
                NarrowStep::default()
            },
            spring_damping: if A::NARROW {
                Damping::with_frac(
                    config.spring_damping,
                    Damping::velocity_frac(config.spring_damping, h / config.node_mass),
                )
            } else {
                Damping::wide_only(config.spring_damping)
            },
            tick_hz: config.tick_hz as i32,
            coupling: CouplingQ {
                stiffness: q::from_f64(cp.stiffness, 16),
                damping: q::from_f64(cp.damping / 1000.0, CouplingQ::DAMP_FRAC),
                max_force: q::from_f64(cp.max_force, FORCE_FRAC),
            },
        };
        Ok(ParamSet {
            table,
            substeps,
            c,
            arith: PhantomData,
        })
    }

    /// Checks `config` and returns the substeps per tick the stability bound asks for
    /// (see the module docs).
    pub fn substeps_for(
        topo: &Topology<NODES, EDGES>,
        table: &ForceTable<S>,
        config: &SolverConfig,
    ) -> Result<u32, SolverError> {
        use ConfigKey as K;
        let check = |ok: bool, k: ConfigKey| {
            if ok {
                Ok(())
            } else {
                Err(SolverError::Config(k))
            }
        };
        let cp = &config.coupling;
        check((1.0..=100_000.0).contains(&config.tick_hz), K::TickHz)?;
        check(
            config.node_mass.is_finite() && config.node_mass > 0.0,
            K::NodeMass,
        )?;
        check(
            (0.0..=30.0).contains(&config.spring_damping),
            K::SpringDamping,
        )?;
        check((0.0..=1e4).contains(&config.node_damping), K::NodeDamping)?;
        check(config.max_substeps >= 1, K::MaxSubsteps)?;
        check(
            cp.stiffness > 0.0 && cp.stiffness <= 1000.0,
            K::CouplingStiffness,
        )?;
        check((0.0..=1000.0).contains(&cp.damping), K::CouplingDamping)?;
        check(
            cp.max_force > 0.0 && cp.max_force < 2000.0,
            K::CouplingMaxForce,
        )?;
        // Per node: stiffness K_i (N/m) and damping C_i (N·s/m).
        let k_max = table.max_stiffness().to_num::<f64>();
        let mut stiff = [0.0f64; NODES];
        let mut damp = [config.node_damping; NODES];
        for e in topo.edges() {
            let k = k_max * 1000.0 / Topology::<NODES, EDGES>::rest_length(e);
            for n in [e.a, e.b] {
                if let (Some(s), Some(d)) = (stiff.get_mut(n as usize), damp.get_mut(n as usize)) {
                    *s += k;
                    *d += config.spring_damping;
                }
            }
        }
        let contact = topo.contact() as usize;
        if let (Some(s), Some(d)) = (stiff.get_mut(contact), damp.get_mut(contact)) {
            *s += cp.stiffness * 1000.0;
            *d += cp.damping;
        }
        let (mut c_max, mut tau_min) = (0.0f64, f64::INFINITY);
        for i in 1..topo.node_count().min(NODES) {
            c_max = c_max.max(damp[i]);
            if stiff[i] > 0.0 {
                tau_min = tau_min.min(damp[i] / stiff[i]);
            }
        }
        if tau_min.is_nan() || tau_min <= 0.0 || c_max <= 0.0 {
            return Err(SolverError::NoDamping);
        }
        let h_max = 0.5 * (2.0 * config.node_mass / (2.0 * c_max)).min(2.0 * tau_min);
        let needed = libm::ceil(1.0 / (config.tick_hz * h_max));
        if needed.is_nan() || needed > config.max_substeps as f64 {
            let needed = if needed < u32::MAX as f64 {
                needed as u32
            } else {
                u32::MAX
            };
            return Err(SolverError::TooManySubsteps { needed });
        }
        let n = (needed as u32).max(1);
        // h/m must fit Q20 ((mm/s)/N < 2048) and h/2 must fit Q32 comfortably.
        let h = 1.0 / (config.tick_hz * n as f64);
        check(1000.0 * h / config.node_mass < 2000.0, K::NodeMass)?;
        check(
            0.5 * h * ((1u64 << HALF_H_FRAC) as f64) < (i32::MAX as f64),
            K::TickHz,
        )?;
        Ok(n)
    }

    /// Substeps per tick.
    pub fn substeps(&self) -> u32 {
        self.substeps
    }

    /// The topology.
    pub fn topology(&self) -> &Topology<NODES, EDGES> {
        &self.topo
    }

    /// The force table.
    pub fn table(&self) -> &ForceTable<S> {
        &self.table
    }

    /// One haptic tick with the probe at `probe` (mm, patch frame). Returns the force the
    /// device must render on the probe (N per axis, clamped to the coupling maximum).
    pub fn step(&mut self, probe: [Length; 3]) -> [Force; 3] {
        let p = probe.map(Length::to_bits);
        // Probe velocity over the tick: Q24 mm · Hz → Q16 mm/s.
        let probe_vel = core::array::from_fn(|i| {
            q::sat(((p[i] as i64 - self.probe_prev[i] as i64) * self.c.tick_hz as i64) >> 8)
        });
        self.probe_prev = p;
        let drive = Drive::Probe {
            probe: p,
            probe_vel,
        };
        for _ in 0..self.substeps {
            self.substep(drive);
        }
        self.coupling_force
            .map(|f| Force::from_bits(f.saturating_neg()))
    }

    /// One tick with the contact node held at `position` (mm, patch frame) — the
    /// indentation test. Returns the reaction: the force the springs exert on the contact
    /// node (N), `z` positive when it resists a downward indentation.
    pub fn step_held(&mut self, position: [Length; 3]) -> [Force; 3] {
        let target = position.map(Length::to_bits);
        let prev = self.node_disp(self.contact);
        // The held node moves linearly from where it was to the target over the tick.
        let vel = core::array::from_fn(|i| {
            q::sat(((target[i] as i64 - prev[i] as i64) * self.c.tick_hz as i64) >> 8)
        });
        let n = self.substeps as i64;
        for s in 1..=n {
            let disp = core::array::from_fn(|i| {
                q::sat(prev[i] as i64 + (target[i] as i64 - prev[i] as i64) * s / n)
            });
            self.substep(Drive::Hold { disp, vel });
        }
        self.reaction.map(Force::from_bits)
    }

    /// Displacement of node `i` from rest (mm), `None` if it does not exist.
    pub fn displacement(&self, i: u16) -> Option<[Length; 3]> {
        self.nodes
            .get(i as usize)
            .map(|n| n.u.map(Length::from_bits))
    }

    /// Velocity of node `i` (mm/s, as `I16F16`).
    pub fn velocity(&self, i: u16) -> Option<[Velocity; 3]> {
        self.nodes
            .get(i as usize)
            .map(|_| self.node_vel(i as usize).map(Velocity::from_bits))
    }

    /// A velocity (Q16 mm/s, within the limit) as the nodes store it.
    fn stored_velocity(&self, v: i32) -> i32 {
        if A::NARROW {
            self.c.narrow.store(v)
        } else {
            v
        }
    }

    /// Puts node `i` at displacement `disp` (mm) with velocity `vel` (mm/s), clamped to
    /// the solver's limits (±64 mm, ±16384 mm/s); the ground and missing nodes are ignored. For tests and for starting from a known state.
    pub fn set_state(&mut self, i: u16, disp: [Length; 3], vel: [Velocity; 3]) {
        if i == GROUND {
            return;
        }
        if let Some(n) = self.nodes.get_mut(i as usize) {
            // Within the integrator's limits, which the spring's ranges rely on.
            n.u = disp.map(|x| x.to_bits().clamp(-DISP_LIMIT, DISP_LIMIT - 1));
        }
        let v = vel.map(|x| self.stored_velocity(x.to_bits().clamp(-VEL_LIMIT, VEL_LIMIT - 1)));
        if let Some(n) = self.nodes.get_mut(i as usize) {
            n.v = v;
        }
    }

    /// Back to rest.
    pub fn reset(&mut self) {
        self.nodes = [Node::ZERO; NODES];
        self.warm = [A::REST; EDGES];
        self.probe_prev = [0; 3];
        self.reaction = [0; 3];
        self.coupling_force = [0; 3];
    }

    /// One substep with the probe at `probe` (Q24 mm, not moving): for benchmarks.
    pub fn substep_probe(&mut self, probe: [Length; 3]) {
        self.substep(Drive::Probe {
            probe: probe.map(Length::to_bits),
            probe_vel: [0; 3],
        });
    }

    /// One substep: spring forces, then the improved Euler update of every free node.
    fn substep(&mut self, drive: Drive) {
        self.spring_forces();
        let c = self.contact;
        self.reaction = self.nodes.get(c).map_or([0; 3], |n| n.f);
        match drive {
            Drive::Probe { probe, probe_vel } => {
                let (node, node_vel) = (self.node_disp(c), self.node_vel(c));
                self.coupling_force = self.c.coupling.force(probe, probe_vel, node, node_vel);
                if let Some(n) = self.nodes.get_mut(c) {
                    n.f = q::add(n.f, self.coupling_force);
                }
            }
            Drive::Hold { .. } => self.coupling_force = [0; 3],
        }
        let count = self.topo.node_count().min(NODES);
        let coeffs = self.c;
        if let Some(free) = self.nodes.get_mut(1..count) {
            let c = &coeffs.narrow;
            if !A::NARROW {
                free.iter_mut().for_each(|n| Self::integrate(&coeffs, n));
            } else if c.fast_path {
                free.iter_mut()
                    .for_each(|n| Self::integrate_narrow::<false>(c, n));
            } else {
                free.iter_mut()
                    .for_each(|n| Self::integrate_narrow::<true>(c, n));
            }
        }
        if let Drive::Hold { disp, vel } = drive {
            let v = vel.map(|x| self.stored_velocity(x.clamp(-VEL_LIMIT, VEL_LIMIT - 1)));
            if let Some(n) = self.nodes.get_mut(c) {
                n.u = disp.map(|x| x.clamp(-DISP_LIMIT, DISP_LIMIT - 1));
                n.v = v;
            }
        }
    }

    fn node_disp(&self, i: usize) -> V3 {
        self.nodes.get(i).map_or([0; 3], |n| n.u)
    }

    /// Node `i`'s velocity in mm/s (Q16).
    fn node_vel(&self, i: usize) -> V3 {
        let v = self.nodes.get(i).map_or([0; 3], |n| n.v);
        if A::NARROW {
            v.map(|x| self.c.narrow.velocity(x))
        } else {
            v
        }
    }

    /// Accumulates every spring's force (law + damping) on its two nodes. A spring to a
    /// fixed point has the ground as `b` (the topology sees to it): its branch reads no
    /// second node and writes only the first (the ground's displacement and velocity are
    /// zero, its accumulator is never read).
    #[inline(always)]
    fn spring_forces(&mut self) {
        if A::NARROW && self.c.spring_damping.unit {
            self.spring_loop::<true>();
        } else {
            self.spring_loop::<false>();
        }
    }

    /// [`Self::spring_forces`], with `UNIT` as in [`Arith::force`].
    #[inline(always)]
    fn spring_loop<const UNIT: bool>(&mut self) {
        let damping = self.c.spring_damping;
        let nodes = self.nodes.as_mut_ptr();
        for (e, r) in self.topo.edges().iter().zip(self.warm.iter_mut()) {
            // SAFETY: `Topology::add_edge` only stores node indices below its node count,
            // which is at most NODES, and `a` is never the ground, so `a ≠ b`; the edges
            // cannot change afterwards. The shared reads end before the writes.
            let na = unsafe { &*nodes.add(e.a as usize) };
            let mut force = |ub: V3, vb: &V3| {
                A::force::<S, UNIT>(&self.table, e, na.u, ub, &na.v, vb, r, &damping)
            };
            let f_on_a = if e.b == GROUND {
                force([0; 3], &[0; 3])
            } else {
                // SAFETY: as above.
                let nb = unsafe { &*nodes.add(e.b as usize) };
                let f = force(nb.u, &nb.v);
                // At most MAX_SPRINGS_PER_NODE springs of ≤ 64 N each: the sums fit.
                // SAFETY: as above.
                let fb = unsafe { &mut (*nodes.add(e.b as usize)).f };
                *fb = core::array::from_fn(|k| fb[k].wrapping_sub(f[k]));
                f
            };
            // SAFETY: as above.
            let fa = unsafe { &mut (*nodes.add(e.a as usize)).f };
            *fa = core::array::from_fn(|k| fa[k].wrapping_add(f_on_a[k]));
        }
    }

    /// Improved Euler for one node (eqs. 21, 22), and the node's force accumulator
    /// cleared for the next substep.
    #[inline(always)]
    fn integrate(c: &Coeffs, n: &mut Node) {
        for j in 0..3 {
            let (u, v, f) = (n.u[j], n.v[j], n.f[j]);
            // v' = (1 − h c/m) v + (h/m) f: Q16 · Q24 and Q20 · Q20, both Q40. Held within
            // ±2³⁰ (±16384 mm/s) through the high word; the low bits of a held value are
            // the product's own (below 0.004 mm/s).
            let p = q::mul_wide(v, c.keep) + q::mul_wide(f, c.h_over_m);
            let v_new = q::shr_held::<{ FORCE_FRAC + HM_FRAC - VEL_FRAC }, 30>(p);
            // u' = u + (v + v') h/2: |v + v'| < 2³¹ and h/2 < 2³¹ in Q40, so |du| < 2³⁰ and
            // the sum cannot overflow before the clamp.
            let du = q::mulhi(v.wrapping_add(v_new), c.half_h);
            n.u[j] = u.wrapping_add(du).clamp(-DISP_LIMIT, DISP_LIMIT - 1);
            n.v[j] = v_new;
        }
        n.f = [0; 3];
    }

    /// [`Self::integrate`] with 16-bit coefficients on the stored velocity `V = C_v v`
    /// ([`NarrowStep`]): two 32-bit multiplies per product on the M0. With `HOLD` (the
    /// general path) the force is held at `f_hold` so that the velocity step fits (16384
    /// mm/s in one substep: never reached by a stable patch), and the shifts are run-time;
    /// without (`fast_path`: every force fits, the stored velocities' fraction bits being
    /// chosen for it where they can be, see [`Damping::velocity_frac`]), two fixed-shift
    /// products with one run-time shift each.
    #[inline(always)]
    fn integrate_narrow<const HOLD: bool>(c: &NarrowStep, n: &mut Node) {
        for j in 0..3 {
            let (u, v, f) = (n.u[j], n.v[j], n.f[j]);
            // V' = V − (h c/m) V + (C_v h/m) f: |V (1 − h c/m)| < 2³⁰ and the step ≤ 2³⁰,
            // so the sum fits before the clamp (max/min: no panic path).
            let drag = q::mul_s::<16>(v, c.damp) >> c.damp_sh;
            let step = if HOLD {
                let f = f.max(-c.f_hold).min(c.f_hold);
                q::mul_s_by(f, c.step, c.step_sh1 as u32) >> c.step_sh2
            } else {
                q::mul_s::<16>(f, c.fast) >> c.fast_sh
            };
            let v_new = v
                .wrapping_sub(drag)
                .wrapping_add(step)
                .max(-c.v_limit)
                .min(c.v_limit);
            // u' = u + (V + V') h/(2 C_v): to Q24 mm by the shifts, |du| < 2³⁰ (the fast
            // path: |V + V'| ≤ 2²⁹ and the factor < 2, so its 16-bit pieces and its
            // result stay within 2³⁰).
            let vv = v.wrapping_add(v_new);
            let du = if HOLD {
                q::mul_s_by(vv, c.hh, c.hh_sh1 as u32) >> c.hh_sh2
            } else {
                q::mul_s::<14>(vv, c.fast_hh) >> c.fast_hh_sh
            };
            n.u[j] = u.wrapping_add(du).clamp(-DISP_LIMIT, DISP_LIMIT - 1);
            n.v[j] = v_new;
        }
        n.f = [0; 3];
    }
}

/// One node's state: displacement from rest (Q24 mm), velocity (Q16 mm/s) and the force
/// accumulator of the current substep (Q20 N), together so that a spring reaches all of
/// an end through one address.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Node {
    u: V3,
    v: V3,
    f: V3,
}

impl Node {
    const ZERO: Self = Self {
        u: [0; 3],
        v: [0; 3],
        f: [0; 3],
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The narrow integrator's velocity step fits 2³⁰ for every force it may see: any
    /// `i32` when `f_hold` is `i32::MAX` (no hold), else the held force; and the
    /// configurations that allow it (the default among them) need no hold.
    #[test]
    fn narrow_velocity_step_fits() {
        let mut no_hold = 0;
        for c in [0.0, 0.05, 0.1, 1.0, 3.0, 30.0] {
            for m in [0.001, 0.005, 0.03, 0.2] {
                for hz in [250.0, 1000.0, 10_000.0] {
                    for n in [1.0, 6.0] {
                        let cfg = SolverConfig {
                            spring_damping: c,
                            node_mass: m,
                            tick_hz: hz,
                            ..SolverConfig::default()
                        };
                        let h = 1.0 / (hz * n);
                        if 1000.0 * h / m >= 2000.0 {
                            continue;
                        }
                        let s = NarrowStep::new(h, &cfg);
                        let limit = if s.f_hold == i32::MAX {
                            no_hold += 1;
                            i32::MAX
                        } else {
                            s.f_hold
                        };
                        let lowest = if limit == i32::MAX { i32::MIN } else { -limit };
                        for f in [lowest, limit, limit / 3] {
                            let exact = (f as i64 * s.step as i64) >> s.step_sh1;
                            assert!(exact.abs() <= 1 << 30, "C={c} m={m} {hz} Hz n={n}");
                            assert_eq!(q::mul_s_by(f, s.step, s.step_sh1 as u32) as i64, exact);
                            if s.fast_path {
                                // The fast path: the same step to 2⁻¹⁴, within 2³⁰.
                                let fast = (f as i64 * s.fast as i64) >> (16 + s.fast_sh);
                                let general = exact >> s.step_sh2;
                                assert!(fast.abs() <= 1 << 30);
                                assert!((fast - general).abs() <= 2 + general.abs() / 16384);
                                assert_eq!(q::mul_s::<16>(f, s.fast) as i64 >> s.fast_sh, fast);
                            }
                        }
                        if s.fast_path {
                            assert_eq!(s.f_hold, i32::MAX);
                            // |V + V'| ≤ 2 v_limit ≤ 2²⁹: the fast position step, within
                            // 2³⁰ and equal to the general one to 2⁻¹³.
                            assert!(s.v_limit <= 1 << 28);
                            let vm = 2 * s.v_limit;
                            for vv in [-vm, vm, 12345] {
                                let fast = q::mul_s::<14>(vv, s.fast_hh) as i64 >> s.fast_hh_sh;
                                let exact = ((vv as i64 * s.fast_hh as i64) >> 14) >> s.fast_hh_sh;
                                assert_eq!(fast, exact);
                                let general = ((vv as i64 * s.hh as i64) >> s.hh_sh1) >> s.hh_sh2;
                                assert!((fast - general).abs() <= 2 + general.abs() / 8192);
                                assert!(fast.abs() <= 1 << 30);
                            }
                        }
                    }
                }
            }
        }
        assert!(no_hold > 0);
        let d = SolverConfig::default();
        assert_eq!(NarrowStep::new(1.0 / 6000.0, &d).f_hold, i32::MAX);
        assert!(NarrowStep::new(1.0 / 6000.0, &d).fast_path);
    }
}
