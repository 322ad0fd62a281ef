//! What the board's tick publishes for the main loop: the controller's telemetry, the
//! tick's length (µs on the tick timer, core cycles on the DWT), the encoder's error
//! counters and the tick on which the safe state was entered; and the verdict of a QEMU
//! run, whose encoder reads zeros.

use crate::config::BoardConfig;
use crate::device::DevicePart;
use mccs_firmware::drivers::as5047p::EncoderErrors;
use mccs_firmware::{DeviceStatus, Fault, Telemetry};

/// The board's run statistics.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoardTelemetry {
    /// The controller's.
    pub run: Telemetry,
    /// The longest tick so far, µs from the timer's update to the tick's end (the
    /// interrupt's latency included).
    pub worst_us: u32,
    /// The longest tick so far, core cycles from the interrupt's entry (DWT; 0 where
    /// there is no cycle counter, as in QEMU).
    pub worst_cycles: u32,
    /// The encoder's error counters.
    pub encoder: EncoderErrors,
    /// The tick (0-based) on which the safe state was entered.
    pub fault_tick: Option<u32>,
    /// What the device knows of itself: homed, at a limit, its duties.
    pub device: DeviceStatus,
    /// The device's part that failed (or what it did) when a failed read or write put
    /// it in the safe state.
    pub part: Option<DevicePart>,
}

impl BoardTelemetry {
    /// Before the first tick.
    pub const fn new() -> Self {
        Self {
            run: Telemetry::new(),
            worst_us: 0,
            worst_cycles: 0,
            encoder: EncoderErrors {
                parity: 0,
                flagged: 0,
                implausible: 0,
                diagnostic: 0,
                consecutive: 0,
            },
            fault_tick: None,
            device: DeviceStatus {
                homed: false,
                at_limit: false,
                thermal: false,
                duties: [0; 3],
            },
            part: None,
        }
    }

    /// Records one tick: the controller's telemetry after it, its length, the encoder's
    /// counters, the device's status and the part whose failure put it in the safe
    /// state.
    pub fn record(
        &mut self,
        run: Telemetry,
        us: u32,
        cycles: u32,
        (encoder, device, part): (EncoderErrors, DeviceStatus, Option<DevicePart>),
    ) {
        self.device = device;
        self.part = part;
        if self.fault_tick.is_none() && run.fault.is_some() {
            self.fault_tick = Some(run.ticks.saturating_sub(1));
        }
        self.run = run;
        self.worst_us = self.worst_us.max(us);
        self.worst_cycles = self.worst_cycles.max(cycles);
        self.encoder = encoder;
    }
}

impl Default for BoardTelemetry {
    fn default() -> Self {
        Self::new()
    }
}

/// The tick on which an encoder that reads all zeros (MISO low, or QEMU's SPI, which has
/// no device behind it) puts the board in its safe state, by the encoder's rules: the
/// first frame answers no command; every later one answers a DIAAGC read with `LF` = 0,
/// a failed diagnostic; the read fails on the `max_bad_frames + 1`-th in a row. `None`
/// when diagnostics are off (`diag_every` = 0): zeros then read as angle 0, which
/// only the plausibility check can catch, and only once the probe has moved.
pub const fn zeros_fault_tick(config: &BoardConfig) -> Option<u32> {
    if config.diag_every == 0 {
        None
    } else {
        Some(config.max_bad_frames.saturating_add(1))
    }
}

/// Why a QEMU run is not what the board's fault rules say it must be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum QemuMismatch {
    /// It did not run `qemu_ticks` ticks.
    Ticks,
    /// A tick overran its period.
    Overrun,
    /// The safe state was not entered through a failed read on the tick
    /// [`zeros_fault_tick`] says.
    Fault,
    /// Putting the device in its safe state reported an error.
    SafeState,
    /// An arm that was never homed drove a joint.
    Unhomed,
}

impl QemuMismatch {
    /// The message.
    pub const fn message(&self) -> &'static str {
        match self {
            Self::Ticks => "the run did not last its ticks",
            Self::Overrun => "a tick overran its period",
            Self::Fault => "the encoder's zeros did not fault the read on the expected tick",
            Self::SafeState => "the safe state reported an error",
            Self::Unhomed => "a joint was driven before the arm was homed",
        }
    }
}

/// Holds a QEMU run to its length, `ticks` (the variant's: `BoardConfig::qemu_ticks`, or
/// the simulated arm's palpation), and to the fault rules: the safe state entered through
/// a failed read on `fault_tick` (the 1-DOF board: its SPI reads zeros,
/// [`zeros_fault_tick`]) or never (`None`: the arm, whose counters read and whose home
/// input stays low), and no duty on an arm that was never homed.
pub fn qemu_verdict(
    ticks: u32,
    t: &BoardTelemetry,
    fault_tick: Option<u32>,
) -> Result<(), QemuMismatch> {
    if t.run.ticks != ticks {
        return Err(QemuMismatch::Ticks);
    }
    if t.run.overruns != 0 {
        return Err(QemuMismatch::Overrun);
    }
    let fault = fault_tick.map(|_| Fault::Read);
    if t.run.fault != fault || t.fault_tick != fault_tick {
        return Err(QemuMismatch::Fault);
    }
    if t.run.safe_state_errors != 0 {
        return Err(QemuMismatch::SafeState);
    }
    if !t.device.homed && t.device.duties != [0; 3] {
        return Err(QemuMismatch::Unhomed);
    }
    Ok(())
}
