//! [`TelemetrySample`]: a live tick of the device, in units.

use mccs_link::{scale, FaultReason, Flags, Telemetry};
use std::time::Duration;

/// A live tick, in units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TelemetrySample {
    /// Counts telemetry messages: a gap is a drop.
    pub seq: u32,
    /// The device's tick.
    pub tick: u32,
    /// When it arrived, since the session opened.
    pub received: Duration,
    /// The probe in the tissue's frame, mm.
    pub probe_mm: [f64; 3],
    /// The force rendered in the device's frame, N.
    pub force_n: [f64; 3],
    /// The link's gain, 0 … 1.
    pub gain: f64,
    /// The tick's flags.
    pub flags: Flags,
    /// Why the device is in its safe state (`None` when not).
    pub fault: FaultReason,
    /// The joints' duties, −1 … 1 of full scale.
    pub duties: [f64; 3],
    /// The proxy in the tissue's frame, mm (with [`Flags::CONTACT`] on a roaming device).
    pub proxy_mm: [f64; 3],
    /// The window's origin in the tissue's frame, mm.
    pub window_mm: [f64; 2],
    /// Telemetry the device dropped so far.
    pub dropped: u32,
}

impl TelemetrySample {
    /// From the message, received at `received`.
    pub fn from_raw(t: &Telemetry, received: Duration) -> Self {
        Self {
            seq: t.seq,
            tick: t.tick,
            received,
            probe_mm: t.probe.map(scale::mm),
            force_n: t.force.map(scale::newtons),
            gain: scale::gain(t.gain),
            flags: t.flags,
            fault: t.fault,
            duties: t.duties.map(scale::duty),
            proxy_mm: t.proxy.map(scale::mm),
            window_mm: t.window.map(scale::mm),
            dropped: t.dropped,
        }
    }
}
