//! [`LinkedDevice`]: a device as the link sees it — the probe read into the tissue's
//! frame through the host's pose ([`mccs::TissuePose`], moved toward its target at the
//! device's slew limits every tick) and the force rendered back in the device's frame,
//! scaled by the link's gain ([`super::Guard`]) and held on each axis to the device's
//! clamp before it reaches the actuator.
//!
//! The clamp again after the rotation: the glued contact clamps each axis in the
//! tissue's frame (docs/solver.md), and a rotated tissue mixes its axes, so that one
//! axis of the device's frame took up to √3 times the clamp (on the 1-DOF board, a
//! tissue turned 78° about `x` rendered 3.01 N against a 3 N clamp on the tick it began
//! to turn, and 4.24 N at 45°: `tests/link/any_run.rs`). The roaming contact clamps
//! the force's size, which a rotation keeps, so that there it changes nothing.

use crate::device::{DeviceStatus, HapticDevice};
use mccs::{Force, Length, TissuePose};
use mccs_link::scale::GAIN_FULL;

/// A device with the link's pose and gain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LinkedDevice<D> {
    device: D,
    pose: TissuePose,
    gain: u16,
    probe: [Length; 3],
    rendered: [Force; 3],
    /// The device's clamp on each axis of its frame, Q20 N (positive).
    max_force: i32,
}

impl<D> LinkedDevice<D> {
    /// `device` with the tissue at its origin, unrotated, at zero gain until the guard
    /// raises it; the pose moves at most `pose` allows; each axis of the force it
    /// renders held within `±max_force` (its size taken: a negative clamp is its size).
    pub fn new(device: D, pose: TissuePose, max_force: Force) -> Self {
        Self {
            device,
            pose,
            gain: 0,
            probe: [Length::ZERO; 3],
            rendered: [Force::ZERO; 3],
            max_force: max_force.to_bits().saturating_abs(),
        }
    }

    /// Where the tissue should lie: an origin (Q24 mm) and a unit quaternion (Q30).
    pub fn set_target(&mut self, origin: [i32; 3], rotation: [i32; 4]) {
        self.pose.set_target(origin, rotation);
    }

    /// The pose now.
    pub fn pose(&self) -> &TissuePose {
        &self.pose
    }

    /// The force gain for the ticks to come, Q15.
    pub fn set_gain(&mut self, gain: u16) {
        self.gain = gain.min(GAIN_FULL);
    }

    /// The force gain now, Q15.
    pub fn gain(&self) -> u16 {
        self.gain
    }

    /// The last probe read, in the tissue's frame.
    pub fn probe(&self) -> [Length; 3] {
        self.probe
    }

    /// The force last sent to the device, in its frame, the gain and the clamp applied.
    pub fn rendered(&self) -> [Force; 3] {
        self.rendered
    }

    /// The device.
    pub fn inner(&self) -> &D {
        &self.device
    }

    /// The device, to change what it holds between ticks.
    pub fn inner_mut(&mut self) -> &mut D {
        &mut self.device
    }
}

impl<D: HapticDevice> HapticDevice for LinkedDevice<D> {
    type Error = D::Error;

    fn read_position(&mut self) -> Result<[Length; 3], Self::Error> {
        self.pose.step();
        let p = self.device.read_position()?;
        self.probe = self.pose.to_tissue(p);
        Ok(self.probe)
    }

    fn write_force(&mut self, force: [Force; 3]) -> Result<(), Self::Error> {
        let g = self.gain as i64;
        let m = self.max_force;
        let f = self.pose.to_device(force);
        // (`max` and `min`, not `clamp`, which asserts its bounds: a panic path.)
        let scaled = f.map(|c| {
            let s = ((c.to_bits() as i64 * g) >> 15) as i32;
            Force::from_bits(s.max(-m).min(m))
        });
        self.rendered = scaled;
        self.device.write_force(scaled)
    }

    fn safe_state(&mut self) -> Result<(), Self::Error> {
        self.rendered = [Force::ZERO; 3];
        self.device.safe_state()
    }

    fn status(&self) -> DeviceStatus {
        self.device.status()
    }
}
