//! [`SolverConfig`]: the solver's runtime configuration, its ranges, and the key that
//! names a value out of range.

use super::stability::Bound;
use super::SolverError;
use crate::arith::Integrator;
use crate::coupling::Coupling;

/// Runtime configuration of a [`crate::Solver`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverConfig {
    /// Haptic tick rate, Hz (1 … 100,000).
    pub tick_hz: f64,
    /// Haptic (scaled) mass of each free node, kg (> 0).
    pub node_mass: f64,
    /// Relative-velocity damping of each spring (eq. 17), N·s/m (0 … 30).
    pub spring_damping: f64,
    /// Absolute damping of each node (eq. 21), N·s/m (0 … 10,000).
    pub node_damping: f64,
    /// Largest number of substeps per tick the stability bound may ask for (≥ 1).
    pub max_substeps: u32,
    /// The probe coupling.
    pub coupling: Coupling,
    /// Which stability bound sets the substeps ([`Bound::Estimated`] by default).
    pub bound: Bound,
    /// The integrator ([`Integrator::ImprovedEuler`], the paper's, by default).
    pub integrator: Integrator,
}

impl Default for SolverConfig {
    /// 1 kHz; 5 g nodes; 1 N·s/m per spring, 0.05 N·s/m per node; at most 64 substeps;
    /// the default coupling; the estimated bound; the paper's integrator.
    fn default() -> Self {
        Self {
            tick_hz: 1000.0,
            node_mass: 0.005,
            spring_damping: 1.0,
            node_damping: 0.05,
            max_substeps: 64,
            coupling: Coupling::default(),
            bound: Bound::Estimated,
            integrator: Integrator::ImprovedEuler,
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

impl core::fmt::Display for ConfigKey {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl SolverConfig {
    /// Checks every value against its range (see the fields).
    pub fn validate(&self) -> Result<(), SolverError> {
        use ConfigKey as K;
        let check = |ok: bool, k: ConfigKey| {
            if ok {
                Ok(())
            } else {
                Err(SolverError::Config(k))
            }
        };
        let cp = &self.coupling;
        check((1.0..=100_000.0).contains(&self.tick_hz), K::TickHz)?;
        check(
            self.node_mass.is_finite() && self.node_mass > 0.0,
            K::NodeMass,
        )?;
        check(
            (0.0..=30.0).contains(&self.spring_damping),
            K::SpringDamping,
        )?;
        check((0.0..=1e4).contains(&self.node_damping), K::NodeDamping)?;
        check(self.max_substeps >= 1, K::MaxSubsteps)?;
        check(
            cp.stiffness > 0.0 && cp.stiffness <= 1000.0,
            K::CouplingStiffness,
        )?;
        check((0.0..=1000.0).contains(&cp.damping), K::CouplingDamping)?;
        check(
            cp.max_force > 0.0 && cp.max_force < 2000.0,
            K::CouplingMaxForce,
        )
    }
}
