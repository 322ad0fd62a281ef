//! Which Cortex-M core this build is for, told by standard target cfgs (no build-script
//! cfg): a hard-float ABI (`thumbv7em-none-eabihf`) is the Cortex-M4F; a target without
//! a 32 × 32 → 64 multiply ([`mccs::q::HAS_LONG_MULTIPLY`]: `thumbv6m-none-eabi`) the
//! Cortex-M0; any other (`thumbv7m-none-eabi`) the Cortex-M3. On a host the answer is
//! [`Core::M3`] and means nothing.

/// A core the demo and the bench know.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Core {
    /// Cortex-M4F (`thumbv7em-none-eabihf`), the default controller.
    M4F,
    /// Cortex-M3 (`thumbv7m-none-eabi`).
    M3,
    /// Cortex-M0 (`thumbv6m-none-eabi`).
    M0,
}

impl Core {
    /// The clock (MHz) and cycles per instruction (×100) that turn an instruction count
    /// into time on a real part: an STM32F405 at 168 MHz (flash behind the ART
    /// accelerator), an LM3S6965 at 50 MHz, an STM32F0-class M0 at 48 MHz (one flash
    /// wait state). Estimates, not measurements (QEMU models no cycles).
    pub const fn clock_estimate(self) -> (u32, u32) {
        match self {
            Self::M4F => (168, 125),
            Self::M3 => (50, 125),
            Self::M0 => (48, 150),
        }
    }

    /// `instructions` as milliseconds at [`Core::clock_estimate`].
    pub const fn ms_at_clock(self, instructions: u64) -> u64 {
        let (mhz, cpi) = self.clock_estimate();
        instructions * cpi as u64 / 100 / (mhz as u64 * 1000)
    }

    /// `m4f`, `m3` or `m0`.
    pub const fn name(self) -> &'static str {
        match self {
            Self::M4F => "m4f",
            Self::M3 => "m3",
            Self::M0 => "m0",
        }
    }
}

/// The core of this build.
pub const CORE: Core = if cfg!(target_abi = "eabihf") {
    Core::M4F
} else if !mccs::q::HAS_LONG_MULTIPLY {
    Core::M0
} else {
    Core::M3
};
