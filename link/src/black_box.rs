//! The black box as the link carries it: [`BoxTick`], one tick as the device keeps it
//! (the same layout in the device's memory and in a message), [`StopCause`], what
//! stopped the device, and [`BlackBoxPart`], the answer to
//! [`crate::ToDevice::BlackBox`]: the record the device kept from its last run, before
//! its last reset, a few ticks at a time (docs/protocol.md, "BlackBox").

use postcard_schema::Schema;
use serde::{Deserialize, Serialize};

/// Ticks one [`BlackBoxPart`] carries (its frame stays within [`crate::MAX_FRAME`]).
pub const BOX_PART: usize = 4;

/// One tick as the black box keeps it: 32 bytes, every field an integer (the device
/// keeps it in memory a reset does not clear, where any bits are a record).
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq, Default)]
#[repr(C)]
pub struct BoxTick {
    /// The tick (0-based, from the device's start).
    pub tick: u32,
    /// The device's counts: an arm's three joints (from home once homed); a 1-DOF
    /// lever's position in µm along `z`, the others 0.
    pub counts: [i32; 3],
    /// The force rendered, mN per axis (tissue frame), saturated to ±32,767.
    pub force_mn: [i16; 3],
    /// The duties written, Q15 (±32,767: ±100 %).
    pub duty_q15: [i16; 3],
    /// The link's force gain, Q15 ([`crate::scale::GAIN_FULL`], 32,768: full).
    pub gain: u16,
    /// [`box_flags`].
    pub flags: u16,
}

/// [`BoxTick::flags`]' bits.
pub mod box_flags {
    /// The device knows its position (an arm homed; a lever always).
    pub const HOMED: u16 = 1;
    /// A joint at its limit.
    pub const AT_LIMIT: u16 = 2;
    /// A motor folded back by its I²t model.
    pub const THERMAL: u16 = 4;
    /// The force was held to the clamp.
    pub const CLAMPED: u16 = 8;
    /// The device in its safe state.
    pub const FAULT: u16 = 16;
}

/// What stopped the device, as its black box keeps it (a code in memory: 0 … 9).
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum StopCause {
    /// Nothing: the run ended by a reset or a power cut with no fault.
    #[default]
    None,
    /// The device could not read the probe (its part in [`BoxStop::part`]).
    Read,
    /// The device could not render the force (its part in [`BoxStop::part`]).
    Write,
    /// Ticks overran their period too many times in a row.
    Overruns,
    /// The emergency stop or an amplifier's fault output cut the drive.
    Amplifier,
    /// The firmware panicked.
    Panic,
    /// A HardFault (its PC in [`BoxStop::pc`]).
    HardFault,
    /// A MemManage fault.
    MemManage,
    /// A BusFault.
    BusFault,
    /// A UsageFault.
    UsageFault,
}

impl StopCause {
    /// Every cause, by its code.
    pub const ALL: [StopCause; 10] = [
        Self::None,
        Self::Read,
        Self::Write,
        Self::Overruns,
        Self::Amplifier,
        Self::Panic,
        Self::HardFault,
        Self::MemManage,
        Self::BusFault,
        Self::UsageFault,
    ];

    /// Its code in memory.
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// The cause of `code` (an unknown code: `None`, as memory of no known run).
    pub const fn from_code(code: u8) -> Option<StopCause> {
        if (code as usize) < Self::ALL.len() {
            Some(Self::ALL[code as usize])
        } else {
            None
        }
    }

    /// Its name in lines.
    pub const fn name(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::Read => "read",
            Self::Write => "write",
            Self::Overruns => "overruns",
            Self::Amplifier => "amplifier",
            Self::Panic => "panic",
            Self::HardFault => "hard-fault",
            Self::MemManage => "mem-manage",
            Self::BusFault => "bus-fault",
            Self::UsageFault => "usage-fault",
        }
    }
}

/// What stopped the run, where and when, as the device keeps it (integers only).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[repr(C)]
pub struct BoxStop {
    /// [`StopCause::code`].
    pub cause: u8,
    /// The device's part that failed (a board's own code: haptic-f405's `DevicePart`),
    /// 0 when none is known.
    pub part: u8,
    /// Unused (0).
    pub reserved: u16,
    /// The tick it stopped on.
    pub tick: u32,
    /// For a HardFault, the faulting instruction's address; 0 otherwise.
    pub pc: u32,
}

/// A part of the black box the device kept from its last run: what stopped it (the first
/// fault, which froze the ring), what ended it, the reset that followed, and ticks `first .. first + BOX_PART` (oldest first) of the
/// `ticks` it kept.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct BlackBoxPart {
    /// Whether the device holds a record of its last run (false after a power-on: the
    /// rest is zero).
    pub kept: bool,
    /// The reset's cause as the chip reports it (the STM32F4's RCC_CSR, bits 24–31:
    /// BOR, PIN, POR, SFT, IWDG, WWDG, LPWR; 0 where it is not modelled, as in QEMU).
    pub reset_flags: u32,
    /// What stopped the run.
    pub cause: StopCause,
    /// The part that failed (see [`BoxStop::part`]).
    pub part: u8,
    /// The tick it stopped on (the ring's last).
    pub tick: u32,
    /// How the run ended, if a fault handler or a panic ended it (after the stop, or
    /// as it); `None` otherwise (a watchdog's reset of a hung core, a reset, a power
    /// cut).
    pub end: StopCause,
    /// The last tick that ran before it ended.
    pub end_tick: u32,
    /// For a HardFault's end, the faulting PC; 0 otherwise.
    pub pc: u32,
    /// Ticks kept (at most the device's ring).
    pub ticks: u16,
    /// The first tick's index in this part (0: the oldest kept).
    pub first: u16,
    /// The ticks; past `ticks − first`, zero.
    pub part_ticks: [BoxTick; BOX_PART],
}
