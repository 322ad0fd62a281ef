//! One tick of the solver: the probe's drive, the substeps, and within each substep the
//! springs (the arithmetic's kernel over every edge) and the integration of every free
//! node.

use super::Solver;
use crate::arith::Arith;
use crate::q::{self, V3};
use crate::state::{DISP_LIMIT, VEL_LIMIT};
use crate::units::{Force, Length, VEL_FRAC};

/// How the contact node is driven.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Drive {
    /// By the probe through the coupling.
    Probe { probe: V3, probe_vel: V3 },
    /// Held at a commanded displacement moving at a commanded velocity.
    Hold { disp: V3, vel: V3 },
}

/// The velocity (Q16 mm/s) of a position (Q24 mm) going from `from` to `to` in one tick
/// at `tick_hz`, saturating.
pub(super) fn tick_velocity(from: V3, to: V3, tick_hz: i32) -> V3 {
    const SH: u32 = crate::units::LEN_FRAC - VEL_FRAC;
    core::array::from_fn(|i| {
        // `to − from` in 33 bits: the wrapped difference, and ±2³² when it wrapped; its
        // product by `tick_hz` by one 32 × 32 product (no 64-bit library product on the
        // M0) and the correction in the high word, exact.
        let (d, wrapped) = to[i].overflowing_sub(from[i]);
        let carry = if !wrapped {
            0
        } else if d < 0 {
            tick_hz as i64
        } else {
            -(tick_hz as i64)
        };
        q::sat((q::mul_wide(d, tick_hz) + (carry << 32)) >> SH)
    })
}

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith> Solver<NODES, EDGES, S, A> {
    /// One haptic tick with the probe at `probe` (mm, patch frame). Returns the force the
    /// device must render on the probe (N per axis, clamped to the coupling maximum).
    pub fn step(&mut self, probe: [Length; 3]) -> [Force; 3] {
        let p = probe.map(Length::to_bits);
        let probe_vel = tick_velocity(self.probe_prev, p, self.c.tick_hz);
        self.probe_prev = p;
        let drive = Drive::Probe {
            probe: p,
            probe_vel,
        };
        for _ in 0..self.substeps {
            self.substep(drive);
        }
        self.device_force()
    }

    /// The force the device must render: minus the coupling's force on the tissue (N).
    #[inline(always)]
    pub(super) fn device_force(&self) -> [Force; 3] {
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
        let vel = tick_velocity(prev, target, self.c.tick_hz);
        let n = self.substeps as i64;
        for s in 1..=n {
            let disp = core::array::from_fn(|i| {
                q::sat(prev[i] as i64 + (target[i] as i64 - prev[i] as i64) * s / n)
            });
            self.substep(Drive::Hold { disp, vel });
        }
        self.reaction.map(Force::from_bits)
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
        A::spring_forces(
            &self.table,
            &self.c.arith,
            &self.topo,
            &mut self.warm,
            &mut self.nodes,
        );
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
        if let Some(free) = self.nodes.get_mut(1..count) {
            A::integrate(&self.c.arith, free);
        }
        if let Drive::Hold { disp, vel } = drive {
            let v = vel.map(|x| self.stored_velocity(x.clamp(-VEL_LIMIT, VEL_LIMIT - 1)));
            if let Some(n) = self.nodes.get_mut(c) {
                n.u = disp.map(|x| x.clamp(-DISP_LIMIT, DISP_LIMIT - 1));
                n.v = v;
            }
        }
    }

    pub(super) fn node_disp(&self, i: usize) -> V3 {
        self.nodes.get(i).map_or([0; 3], |n| n.u)
    }

    /// Node `i`'s velocity in mm/s (Q16).
    pub(super) fn node_vel(&self, i: usize) -> V3 {
        let v = self.nodes.get(i).map_or([0; 3], |n| n.v);
        v.map(|x| A::velocity(&self.c.arith, x))
    }

    /// A velocity (Q16 mm/s, within the limit) as the nodes store it.
    pub(super) fn stored_velocity(&self, v: i32) -> i32 {
        A::store_velocity(&self.c.arith, v)
    }
}

#[cfg(test)]
mod tests {
    use super::tick_velocity;

    /// The velocity of a tick against the 64-bit formula, saturated to `i32`, for every
    /// pair of extreme positions (a difference that wraps `i32` either way) and rates
    /// from 1 Hz to 100 kHz.
    #[test]
    fn tick_velocity_matches_the_64_bit_product() {
        let xs = [
            i32::MIN,
            i32::MIN + 1,
            -(1 << 30),
            -123_456_789,
            -1,
            0,
            1,
            987_654_321,
            1 << 30,
            i32::MAX - 1,
            i32::MAX,
        ];
        for hz in [1, 7, 255, 256, 1000, 4096, 100_000] {
            for &a in &xs {
                for &b in &xs {
                    let want = ((b as i64 - a as i64) * hz as i64) >> 8;
                    let want = want.clamp(i32::MIN as i64, i32::MAX as i64) as i32;
                    let got = tick_velocity([a, b, 0], [b, a, a], hz);
                    let back = ((a as i64 - b as i64) * hz as i64) >> 8;
                    let back = back.clamp(i32::MIN as i64, i32::MAX as i64) as i32;
                    assert_eq!(got[0], want, "{a} -> {b} at {hz} Hz");
                    assert_eq!(got[1], back, "{b} -> {a} at {hz} Hz");
                }
            }
        }
    }
}
