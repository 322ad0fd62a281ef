//! The per-tick arithmetic as a strategy ([`Arith`]): how one spring's force is computed
//! from its ends, and how a node's velocity and position are advanced, in one of two
//! arithmetics chosen per core.
//!
//! - [`Wide`] (`wide.rs`): every product a 32 × 32 → 64 multiply, one instruction on the
//!   M3/M4F; lengths to ~1e-7 of `l0`, forces to ~1e-6. The default on cores that have
//!   a long multiply.
//! - [`Narrow`] (`narrow.rs`): every product has one 16-bit operand, two 32-bit
//!   multiplies on the Cortex-M0 (which has no long multiply) instead of four; errors a
//!   few 1e-4 of the force (measured: `docs/accuracy.md`). The default on the M0.
//!
//! Both give the same results on every core ([`crate::q`]); the host tests run both.
//! Everything that differs between the two lives in their files: the spring kernel, the
//! integrator, how velocities are stored, and what each derives from a table and a
//! configuration. The solver is generic over [`Arith`] and has no branch on it.

use crate::q::V3;
use crate::state::{Node, SpringEnds};
use crate::table::ForceTable;
use crate::topology::{Edge, Topology};

pub mod narrow;
pub mod wide;
#[cfg(mccs_dsp)]
mod wide_dsp;

pub use narrow::Narrow;
pub use wide::Wide;

/// Largest force of one spring (law and damping together), N in Q20: 64 N = 2²⁶, so
/// that a node's sum of [`crate::topology::MAX_SPRINGS_PER_NODE`] springs cannot
/// overflow.
pub const SPRING_FORCE_LIMIT: i32 = 1 << SPRING_FORCE_BITS;
/// [`SPRING_FORCE_LIMIT`] as a power of two.
pub const SPRING_FORCE_BITS: u32 = 26;
const _: () = assert!(SPRING_FORCE_LIMIT == 64 << crate::units::FORCE_FRAC);

/// Largest substep `h`, s: `h/2` must fit Q40 in an `i32` ([`Wide`]'s integrator), just
/// under 2⁻⁸ s.
pub const MAX_SUBSTEP: f64 = i32::MAX as f64 / (1u64 << 39) as f64;
/// Largest `h/m`, (mm/s)/N: [`Wide`] holds it in Q20 (< 2048), and [`Narrow`]'s
/// velocity step `C_v h/m` stays below 60 with it.
pub const MAX_H_OVER_M: f64 = 2000.0;

/// Which one-step scheme advances the free nodes. Both cost the same per node (the same
/// products with other coefficients); `docs/experiments/performance.md` ("Integrator variants")
/// has their measured bounds and accuracy.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Integrator {
    /// The paper's improved Euler (eqs. 21–22): `v' = v + h F/m`,
    /// `u' = u + h (v + v')/2`. The default.
    #[default]
    ImprovedEuler,
    /// Symplectic Euler with one implicit damping factor for every node:
    /// `v' = v + h D F/m`, `u' = u + h v'`, with `D = 1/(1 + h γ)` and `γ` the largest
    /// damping on one node (its own, its springs', the coupling's) over its mass
    /// ([`crate::solver::stability::damping_factor`]). A larger stable step on stiff
    /// patches (N = 8 at 1 kHz: 2 substeps instead of 3), and a smaller step-response
    /// error; the same static equilibrium.
    SymplecticDamped,
}

/// What the arithmetic's coefficients are derived from (start-up only): the substep, the
/// configuration's masses and dampings, and the integrator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepSpec {
    /// Substep `h`, s.
    pub h: f64,
    /// Haptic mass of each free node, kg.
    pub node_mass: f64,
    /// Absolute damping of each node, N·s/m.
    pub node_damping: f64,
    /// Relative damping of each spring, N·s/m.
    pub spring_damping: f64,
    /// The scheme.
    pub integrator: Integrator,
    /// The factor `D` (0 < `D` ≤ 1) on the velocity step, `v' = v + h D F/m`: 1 for
    /// [`Integrator::ImprovedEuler`].
    pub damping_factor: f64,
}

impl StepSpec {
    /// The velocity step's substep, `h D` (s).
    pub fn velocity_h(&self) -> f64 {
        self.h * self.damping_factor
    }

    /// Whether the position advances by the new velocity alone (`u' = u + h v'`).
    pub fn symplectic(&self) -> bool {
        self.integrator == Integrator::SymplecticDamped
    }
}

/// A spring-and-integrator arithmetic. Implementations: [`Wide`], [`Narrow`].
pub trait Arith: Copy + core::fmt::Debug + Default + PartialEq + Eq + 'static {
    /// What the arithmetic derives from a force table (start-up only).
    type TableAux: Copy + core::fmt::Debug + PartialEq + Eq;
    /// What it derives from a configuration and the substep (start-up only): the spring
    /// damping and the integrator's coefficients in its formats.
    type Coeffs: Copy + core::fmt::Debug + PartialEq + Eq;
    /// A spring's warm-start value at rest.
    const REST: i32;
    /// The hold on a spring's `l0/l` (exclusive): a spring crushed below `l0 / MAX_RATIO`
    /// keeps `MAX_RATIO`, so that its force fades to zero at zero length.
    const MAX_RATIO: f64;
    /// The longest rest length, mm, for which the arithmetic holds its documented
    /// precision (`docs/accuracy.md`); a solver refuses longer springs.
    const MAX_REST_LENGTH_MM: f64;

    /// The table's extra data for this arithmetic.
    fn table_aux<const S: usize>(table: &ForceTable<S>) -> Self::TableAux;

    /// The warm-start value of a spring at `l0/l = r` (`0 < r <` [`Arith::MAX_RATIO`];
    /// start-up and tests).
    fn warm_of_ratio(r: f64) -> i32;

    /// The coefficients for `spec`.
    fn coeffs(spec: &StepSpec) -> Self::Coeffs;

    /// A velocity (Q16 mm/s, within ±[`crate::state::VEL_LIMIT`]) as the nodes store it.
    fn store_velocity(c: &Self::Coeffs, v: i32) -> i32;

    /// A stored velocity in mm/s (Q16).
    fn velocity(c: &Self::Coeffs, stored: i32) -> i32;

    /// The force on end `a` of one spring (Q20 N): the law along the edge plus the
    /// relative damping (eq. 17), from its ends; advances the spring's warm-start value.
    fn spring<const S: usize>(
        table: &ArithTable<S, Self>,
        c: &Self::Coeffs,
        edge: &Edge,
        ends: &SpringEnds,
        warm: &mut i32,
    ) -> V3;

    /// Every spring's force, accumulated on its two nodes.
    fn spring_forces<const S: usize, const NODES: usize, const EDGES: usize>(
        table: &ArithTable<S, Self>,
        c: &Self::Coeffs,
        topo: &Topology<NODES, EDGES>,
        warm: &mut [i32; EDGES],
        nodes: &mut [Node; NODES],
    );

    /// The configured [`Integrator`] on every node of `free`, with its force
    /// accumulator, which is then cleared for the next substep.
    fn integrate(c: &Self::Coeffs, free: &mut [Node]);
}

/// A force table with what arithmetic `A` derives from it: what the spring kernels read.
/// The derived part comes first and the table's header right after it, so that the
/// Cortex-M0 reaches every field the kernel reads with an immediate offset from one
/// address (Thumb-1 loads reach 124 bytes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct ArithTable<const S: usize, A: Arith> {
    /// What `A` derives from the table.
    pub aux: A::TableAux,
    /// The table.
    pub table: ForceTable<S>,
}

impl<const S: usize, A: Arith> ArithTable<S, A> {
    /// `table` with what `A` derives from it (start-up).
    pub fn new(table: ForceTable<S>) -> Self {
        Self {
            aux: A::table_aux(&table),
            table,
        }
    }
}

/// The arithmetic of this build's core: [`Narrow`] without a long multiply (the
/// Cortex-M0, see [`crate::q::HAS_LONG_MULTIPLY`]), else [`Wide`].
#[cfg(all(target_arch = "arm", not(target_has_atomic = "32")))]
pub type DefaultArith = Narrow;
/// The arithmetic of this build's core: [`Narrow`] without a long multiply (the
/// Cortex-M0, see [`crate::q::HAS_LONG_MULTIPLY`]), else [`Wide`].
#[cfg(not(all(target_arch = "arm", not(target_has_atomic = "32"))))]
pub type DefaultArith = Wide;

const _: () = assert!(
    crate::q::HAS_LONG_MULTIPLY
        == cfg!(not(all(target_arch = "arm", not(target_has_atomic = "32"))))
);
