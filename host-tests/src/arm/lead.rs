//! [`Lead`]: where a hand on the arm's handle leads the probe at each tick of the closed
//! loop ([`super::closed_loop`]) — home, a rise in joint space, straight down, the demo's
//! palpation — or a press held from a tick on ([`HoldAt`]).

use super::twin::ArmTwin;
use haptic_f405::config::BoardConfig;
use mccs::ArmSpec;
use mccs_firmware::arm::plant::{
    APPROACH_HEIGHT_MM, APPROACH_TICKS, DESCENT_TICKS, HOME_TICKS, PALPATION_TICKS,
};
use mccs_firmware::probe_path::ProbePath;

/// The ticks before the palpation: the home pose, the rise and the descent.
pub const LEAD_TICKS: u32 = HOME_TICKS + APPROACH_TICKS;

/// Where the hand leads the probe (device frame, mm) at each tick: home, a rise in joint
/// space to above the palpation's start, straight down to it, then the palpation over
/// and over; or held at one point from a tick on.
pub struct Lead {
    home: [f64; 3],
    above: [f64; 3],
    start: [f64; 3],
    palpation: ProbePath<9>,
    pub(super) origin: [f64; 3],
    twin: ArmTwin,
    /// From a tick on, the hand goes to a point and holds it there.
    pub hold: Option<HoldAt>,
}

/// A hold: from tick `from`, the hand waits `wait` ticks where it is led then, moves to
/// `to` (device frame, mm) over `ramp` ticks (smoothly), and holds it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoldAt {
    /// See [`HoldAt`].
    pub from: u32,
    /// See [`HoldAt`].
    pub wait: u32,
    /// See [`HoldAt`].
    pub ramp: u32,
    /// See [`HoldAt`].
    pub to: [f64; 3],
}

fn smooth(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl Lead {
    /// The arm it leads.
    pub fn spec(&self) -> &ArmSpec {
        &self.twin.spec
    }

    /// The demo's palpation at the board's tick rate, on the arm of `spec`.
    pub fn palpation(config: &BoardConfig, spec: &ArmSpec) -> Lead {
        let twin = ArmTwin { spec: *spec };
        let palpation = mccs_firmware::palpation_path(config.tick_hz)
            .unwrap_or_else(|e| panic!("the demo's palpation: {e:?}"));
        let origin = spec.tissue_origin_mm;
        let start: [f64; 3] =
            std::array::from_fn(|k| palpation.at(0)[k].to_num::<f64>() + origin[k]);
        let above = [start[0], start[1], start[2] + APPROACH_HEIGHT_MM];
        let home_angles = spec.joints.map(|j| j.home_angle_deg.to_radians());
        Lead {
            home: twin.fk(home_angles),
            above,
            start,
            palpation,
            origin,
            twin,
            hold: None,
        }
    }

    /// A point of the tissue's frame (mm) in the device frame.
    pub fn device(&self, tissue: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|k| tissue[k] + self.origin[k])
    }

    /// Where the probe is led at `tick`, device frame, mm.
    pub fn at(&self, tick: u32) -> [f64; 3] {
        match self.hold {
            Some(h) if tick >= h.from => {
                let p = self.path(h.from);
                let t =
                    smooth((tick - h.from).saturating_sub(h.wait) as f64 / h.ramp.max(1) as f64);
                std::array::from_fn(|k| p[k] + (h.to[k] - p[k]) * t)
            }
            _ => self.path(tick),
        }
    }

    /// Where the path leads at `tick` (no hold), device frame, mm.
    fn path(&self, tick: u32) -> [f64; 3] {
        let rise_end = LEAD_TICKS - DESCENT_TICKS;
        if tick < HOME_TICKS {
            self.home
        } else if tick < rise_end {
            let t = smooth((tick - HOME_TICKS) as f64 / (rise_end - HOME_TICKS) as f64);
            let from = self.twin.spec.joints.map(|j| j.home_angle_deg.to_radians());
            let to = self.twin.ik(self.above).unwrap_or(from);
            self.twin
                .fk(std::array::from_fn(|k| from[k] + (to[k] - from[k]) * t))
        } else if tick < LEAD_TICKS {
            let t = smooth((tick - rise_end) as f64 / DESCENT_TICKS as f64);
            let mut p = self.above;
            p[2] = self.start[2] + APPROACH_HEIGHT_MM * (1.0 - t);
            p
        } else {
            let t = (tick - LEAD_TICKS) % PALPATION_TICKS;
            self.device(self.palpation.at(t).map(|c| c.to_num::<f64>()))
        }
    }
}
