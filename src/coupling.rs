//! `Coupling`: the virtual coupling (Adams & Hannaford) between the haptic device's probe
//! and the contact node — a spring–damper whose force is what the device renders.
//!
//! It is unilateral: it acts only while the probe is below the contact node (pressing
//! into the tissue); then it acts on all three axes, so a stroke drags the tissue under
//! the probe (no slip). The force is clamped per axis to the device maximum, on the
//! device and on the node alike, so the coupling stays passive.

use crate::q::{mul_wide, sat};
use crate::units::{from_f64, FORCE_FRAC, LEN_FRAC, VEL_FRAC};

/// Coupling parameters (runtime values; see [`crate::SolverConfig`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coupling {
    /// Spring stiffness, N/mm (> 0).
    pub stiffness: f64,
    /// Damper, N·s/m (≥ 0).
    pub damping: f64,
    /// Largest force per axis the device renders, N (> 0, < 2048).
    pub max_force: f64,
}

impl Default for Coupling {
    /// 1 N/mm, 0.5 N·s/m, 10 N per axis.
    fn default() -> Self {
        Self {
            stiffness: 1.0,
            damping: 0.5,
            max_force: 10.0,
        }
    }
}

/// The coupling in the solver's fixed-point units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct CouplingQ {
    /// N/mm, Q16.
    pub stiffness: i32,
    /// N·s/mm, Q24.
    pub damping: i32,
    /// N, Q20.
    pub max_force: i32,
}

impl CouplingQ {
    /// Fraction bits of `stiffness`.
    const STIFF_FRAC: u32 = 16;
    /// Fraction bits of `damping`.
    const DAMP_FRAC: u32 = 24;

    /// From the coupling's parameters (start-up).
    pub fn new(c: &Coupling) -> Self {
        Self {
            stiffness: from_f64(c.stiffness, Self::STIFF_FRAC),
            damping: from_f64(c.damping / 1000.0, Self::DAMP_FRAC),
            max_force: from_f64(c.max_force, FORCE_FRAC),
        }
    }

    /// Force on the contact node (Q20 N) from the probe at `probe` (Q24 mm) moving at
    /// `probe_vel` (Q16 mm/s), the node at `node` moving at `node_vel`. Zero when the
    /// probe is not below the node.
    #[inline(always)]
    pub fn force(
        &self,
        probe: [i32; 3],
        probe_vel: [i32; 3],
        node: [i32; 3],
        node_vel: [i32; 3],
    ) -> [i32; 3] {
        // Q24 mm · Q16 N/mm and Q16 mm/s · Q24 N·s/mm are both Q40: Q20 N after the shift.
        const SH: u32 = LEN_FRAC + CouplingQ::STIFF_FRAC - FORCE_FRAC;
        const _: () = assert!(VEL_FRAC + CouplingQ::DAMP_FRAC - FORCE_FRAC == SH);
        if probe[2] >= node[2] {
            return [0; 3];
        }
        let mut out = [0; 3];
        for i in 0..3 {
            // The stretch and the relative speed held within their formats (±128 mm,
            // ±32768 mm/s): beyond, the force is at the device maximum anyway for any
            // stiffness above 0.08 N/mm.
            let dx = probe[i].saturating_sub(node[i]);
            let dv = probe_vel[i].saturating_sub(node_vel[i]);
            // Q24 mm · Q16 N/mm → Q20 N; Q16 mm/s · Q24 N·s/mm → Q20 N (long products: the
            // M0 builds them from 16-bit pieces).
            let spring = mul_wide(dx, self.stiffness) >> SH;
            let damper = mul_wide(dv, self.damping) >> SH;
            let f = sat(spring + damper);
            // max/min, not clamp: clamp keeps a panic path for min > max.
            out[i] = f.max(-self.max_force).min(self.max_force);
        }
        out
    }
}
