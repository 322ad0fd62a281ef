//! `HapticDevice`: what the tick needs of the hardware — read the probe, write the force —
//! and `SimulatedDevice`, which replays a [`ProbePath`] for QEMU and the host tests.

use crate::probe_path::ProbePath;
use mccs::{Force, Length};

/// A haptic device: probe position in, force out (patch frame, mm and N).
pub trait HapticDevice {
    /// A device failure (the controller then goes to its safe state).
    type Error;
    /// The probe position now.
    fn read_position(&mut self) -> Result<[Length; 3], Self::Error>;
    /// Renders `force` on the probe until the next call.
    fn write_force(&mut self, force: [Force; 3]) -> Result<(), Self::Error>;
    /// The safe state: no force, the drive cut, whatever else fails (every part
    /// attempted; the first error returned). Called on a fault and on every tick after.
    fn safe_state(&mut self) -> Result<(), Self::Error>;
    /// What the device knows of itself beyond the probe, for telemetry: homed (a device
    /// without homing always is), at a joint limit, the duties last written.
    fn status(&self) -> DeviceStatus {
        DeviceStatus::default()
    }
}

/// What a device knows of itself beyond the probe ([`HapticDevice::status`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DeviceStatus {
    /// Its position is known (an arm after homing; always, without homing).
    pub homed: bool,
    /// A joint is at or past its limit.
    pub at_limit: bool,
    /// A joint's current is folded back to its continuous current (the I²t model).
    pub thermal: bool,
    /// The joints' duties last written, Q16 (zero where there are no joints).
    pub duties: [i32; 3],
}

impl Default for DeviceStatus {
    fn default() -> Self {
        Self {
            homed: true,
            at_limit: false,
            thermal: false,
            duties: [0; 3],
        }
    }
}

/// A device that replays a probe path, one waypoint tick per read, and keeps the last
/// force written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SimulatedDevice<const K: usize> {
    path: ProbePath<K>,
    tick: u32,
    last_force: [Force; 3],
}

impl<const K: usize> SimulatedDevice<K> {
    /// Replays `path` from its first waypoint.
    pub fn new(path: ProbePath<K>) -> Self {
        Self {
            path,
            tick: 0,
            last_force: [Force::ZERO; 3],
        }
    }

    /// The last force written.
    pub fn last_force(&self) -> [Force; 3] {
        self.last_force
    }

    /// Ticks read so far.
    pub fn ticks(&self) -> u32 {
        self.tick
    }
}

impl<const K: usize> HapticDevice for SimulatedDevice<K> {
    type Error = core::convert::Infallible;

    fn read_position(&mut self) -> Result<[Length; 3], Self::Error> {
        let p = self.path.at(self.tick);
        self.tick = self.tick.saturating_add(1);
        Ok(p)
    }

    fn write_force(&mut self, force: [Force; 3]) -> Result<(), Self::Error> {
        self.last_force = force;
        Ok(())
    }

    fn safe_state(&mut self) -> Result<(), Self::Error> {
        self.last_force = [Force::ZERO; 3];
        Ok(())
    }
}
