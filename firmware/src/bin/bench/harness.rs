//! The measuring harness: SysTick running free at the core clock, calibrated against a
//! loop of known instruction count, so that its counts become instructions under QEMU's
//! `-icount`.

use core::cell::RefCell;
use core::hint::black_box;
use core::sync::atomic::{AtomicU32, Ordering};
use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::exception;

/// SysTick's wraps while [`Harness::measure_long`] runs (its exception is enabled only
/// then; this handler is the only writer: a load and a store, which every core has).
static WRAPS: AtomicU32 = AtomicU32::new(0);

#[exception]
fn SysTick() {
    WRAPS.store(
        WRAPS.load(Ordering::Relaxed).wrapping_add(1),
        Ordering::Relaxed,
    );
}

/// A running, calibrated counter.
pub struct Harness {
    /// SysTick counts per 1024 instructions.
    pub cpk: u32,
    /// SysTick, owned: [`Harness::measure_long`] turns its exception on and off.
    syst: RefCell<SYST>,
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
        syst: RefCell::new(syst),
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

    /// Instructions of one run of `f`, which may take longer than SysTick's 2²⁴ counts
    /// (start-up work: millions of instructions): its wraps counted by its exception,
    /// enabled for the run. Within a few instructions of [`Harness::measure`]'s figure.
    pub fn measure_long(&self, f: impl FnOnce()) -> u64 {
        WRAPS.store(0, Ordering::Relaxed);
        let t0 = now();
        self.syst.borrow_mut().enable_interrupt();
        f();
        // The counter and its wraps, read so that a wrap between the two reads is seen.
        let (mut wraps, mut t1);
        loop {
            wraps = WRAPS.load(Ordering::Relaxed);
            t1 = now();
            if WRAPS.load(Ordering::Relaxed) == wraps {
                break;
            }
        }
        self.syst.borrow_mut().disable_interrupt();
        // (A wrap after `t1` and before the exception was disabled is not in the count:
        // it happened after the run.)
        let counts = (wraps as u64) * 0x100_0000 + t0 as u64 - t1 as u64;
        counts * 1024 / self.cpk as u64
    }
}
