//! The stability bound: how many substeps per tick the improved Euler integrator needs on
//! a given topology, table and configuration (start-up only).
//!
//! For one mass `m` on a spring `K` with damping rate `γ = C/m`, the improved Euler step
//! `h` is stable exactly when `h < 2/γ` and `h < 2 C/K`: unlike symplectic Euler it
//! *amplifies* an undamped oscillation (by `1 + h²ω²/2` per step), so it needs damping.
//! The bound applies that per node, Gershgorin-style, with a safety factor of 2:
//! `K_i = Σ k_max / l0` over the node's springs (+ the coupling), `C_i = Σ C` over its
//! springs + the node damping (+ the coupling damper), and
//! `h ≤ ½ · min(2 m / (2 max C_i), 2 min(C_i / K_i))`, where `k_max` is the table's largest
//! tangent stiffness. The masses are haptic masses (a few grams per node), not the
//! tissue's: they set how many substeps a tick needs, not the settled force.

use super::{ConfigKey, SolverConfig, SolverError};
use crate::arith::{MAX_H_OVER_M, MAX_SUBSTEP};
use crate::table::ForceTable;
use crate::topology::Topology;

/// Checks `config` and returns the substeps per tick the stability bound asks for.
pub fn substeps_for<const NODES: usize, const EDGES: usize, const S: usize>(
    topo: &Topology<NODES, EDGES>,
    table: &ForceTable<S>,
    config: &SolverConfig,
) -> Result<u32, SolverError> {
    config.validate()?;
    let cp = &config.coupling;
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
    // The arithmetics' own limits on h/m and h.
    let h = 1.0 / (config.tick_hz * n as f64);
    if 1000.0 * h / config.node_mass >= MAX_H_OVER_M {
        return Err(SolverError::Config(ConfigKey::NodeMass));
    }
    if h >= MAX_SUBSTEP {
        return Err(SolverError::Config(ConfigKey::TickHz));
    }
    Ok(n)
}
