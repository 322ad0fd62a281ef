//! The measuring harness: SysTick running free at the core clock, calibrated against a
//! loop of known instruction count, so that its counts become instructions under QEMU's
//! `-icount`.

use core::hint::black_box;
use cortex_m::peripheral::{syst::SystClkSource, SYST};

/// A running, calibrated counter.
pub struct Harness {
    /// SysTick counts per 1024 instructions.
    pub cpk: u32,
}

/// `n` iterations of a two-instruction loop.
#[inline(never)]
fn known_loop(n: u32) {
    // SAFETY: a register-only countdown loop: no memory, no stack, no other register.
    unsafe {
        core::arch::asm!("2:", "subs {0}, #1", "bne 2b", inout(reg) n => _, options(nomem, nostack));
    }
}

fn now() -> u32 {
    SYST::get_current()
}

/// Starts SysTick free-running at the core clock and calibrates it.
pub fn start(mut syst: SYST) -> Harness {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(0x00FF_FFFF);
    syst.clear_current();
    syst.enable_counter();
    while now() == 0 {}
    let t0 = now();
    known_loop(black_box(1000));
    let t1 = now();
    known_loop(black_box(11000));
    let t2 = now();
    let small = t0.wrapping_sub(t1) & 0xFF_FFFF;
    let large = t1.wrapping_sub(t2) & 0xFF_FFFF;
    // 20000 more instructions in the large run.
    Harness {
        cpk: ((large - small) as u64 * 1024 / 20000) as u32,
    }
}

impl Harness {
    /// Instructions of `reps` runs of `f`, per run.
    pub fn measure(&self, reps: u32, mut f: impl FnMut()) -> u32 {
        let t0 = now();
        for _ in 0..reps {
            f();
        }
        let t1 = now();
        let counts = t0.wrapping_sub(t1) & 0xFF_FFFF;
        ((counts as u64 * 1024 / self.cpk as u64) / reps as u64) as u32
    }
}
