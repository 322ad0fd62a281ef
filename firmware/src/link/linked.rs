//! [`LinkedDevice`]: a device as the link sees it — the probe in the tissue's frame (the
//! host's pose, reached by a bounded step per tick) and the force scaled by the link's
//! gain ([`super::Guard`]) before it reaches the actuator.

use crate::device::HapticDevice;
use mccs::{Force, Length};

/// A device with the link's pose and gain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LinkedDevice<D> {
    device: D,
    origin: [i32; 3],
    target: [i32; 3],
    max_step: i32,
    gain: u16,
    probe: [Length; 3],
}

impl<D> LinkedDevice<D> {
    /// `device` at the origin, full gain; the pose moves at most `max_step_mm` per tick.
    pub fn new(device: D, max_step_mm: f64) -> Self {
        Self {
            device,
            origin: [0; 3],
            target: [0; 3],
            max_step: Length::saturating_from_num(max_step_mm).to_bits().max(1),
            gain: super::guard::FULL,
            probe: [Length::ZERO; 3],
        }
    }

    /// The tissue's origin in the device frame the pose moves toward, Q24 mm.
    pub fn set_target(&mut self, origin: [i32; 3]) {
        self.target = origin;
    }

    /// The origin now, Q24 mm.
    pub fn origin(&self) -> [i32; 3] {
        self.origin
    }

    /// The force gain for the ticks to come, Q15.
    pub fn set_gain(&mut self, gain: u16) {
        self.gain = gain.min(super::guard::FULL);
    }

    /// The last probe read, in the tissue's frame.
    pub fn probe(&self) -> [Length; 3] {
        self.probe
    }

    /// The device.
    pub fn inner(&self) -> &D {
        &self.device
    }
}

impl<D: HapticDevice> HapticDevice for LinkedDevice<D> {
    type Error = D::Error;

    fn read_position(&mut self) -> Result<[Length; 3], Self::Error> {
        for k in 0..3 {
            let d = self.target[k].saturating_sub(self.origin[k]);
            // (Not `clamp`, which asserts its bounds: a panic path in the tick.)
            self.origin[k] =
                self.origin[k].saturating_add(d.max(-self.max_step).min(self.max_step));
        }
        let p = self.device.read_position()?;
        self.probe =
            core::array::from_fn(|k| p[k].saturating_sub(Length::from_bits(self.origin[k])));
        Ok(self.probe)
    }

    fn write_force(&mut self, force: [Force; 3]) -> Result<(), Self::Error> {
        let g = self.gain as i64;
        let scaled = force.map(|f| Force::from_bits(((f.to_bits() as i64 * g) >> 15) as i32));
        self.device.write_force(scaled)
    }

    fn safe_state(&mut self) -> Result<(), Self::Error> {
        self.device.safe_state()
    }
}
