//! What differs between the board and QEMU, in one place (`board_qemu`, from build.rs):
//! the clock tree, the timers' clock, the log's transport, the cycle counter that times
//! the tick, and the ways out — a panic, a hard fault, the end of a QEMU run.
//!
//! - On the board: the HSE and the PLL (`BoardConfig`), the timers at the HAL's
//!   clocks, defmt over RTT, the DWT cycle counter; a way out stops at a breakpoint
//!   (with no debugger, a HardFault that spins until the watchdog resets the chip).
//! - In QEMU (`netduinoplus2`, which models no RCC: an HSE or PLL never reports ready):
//!   the reset clock (HSI, 16 MHz), the timers at QEMU's 1 GHz, defmt over
//!   semihosting, SysTick free-running at the core clock as the cycle counter (QEMU
//!   models no DWT cycle counter: it reads 0; under `-icount` SysTick counts
//!   instructions), and every way out exits QEMU through semihosting.
//!
//! Every way out — a panic, HardFault, MemManage, BusFault, UsageFault — cuts the motor
//! first, on every build (`haptic_f405::safe_stop::cut_motor`: raw register writes),
//! then stops the black box with its cause (`haptic_f405::black_box`), then logs what
//! stopped it, then exits.

use haptic_f405::config::{self, BOARD};
use mccs_link::StopCause;
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::{Clocks, Rcc};

#[cfg(not(board_qemu))]
use defmt_rtt as _;
#[cfg(board_qemu)]
use defmt_semihosting as _;

/// The clock tree: the board's from its crystal; QEMU's reset clock.
pub fn clocks(rcc: Rcc) -> Clocks {
    if cfg!(board_qemu) {
        rcc.cfgr.freeze()
    } else {
        rcc.cfgr
            .use_hse(BOARD.hse_hz.Hz())
            .sysclk(BOARD.sysclk_hz.Hz())
            .freeze()
    }
}

/// The clock of TIM2, the tick's timer.
pub fn timer_clock(clocks: &Clocks) -> u32 {
    if cfg!(board_qemu) {
        config::QEMU_TIMER_CLOCK_HZ
    } else {
        clocks.timclk1().raw()
    }
}

/// Starts the counter [`cycles`] reads.
pub fn start_cycle_counter(cp: &mut cortex_m::Peripherals) {
    cp.DCB.enable_trace();
    cp.DWT.enable_cycle_counter();
    if cfg!(board_qemu) {
        use cortex_m::peripheral::syst::SystClkSource;
        cp.SYST.set_clock_source(SystClkSource::Core);
        cp.SYST.set_reload(0x00FF_FFFF);
        cp.SYST.clear_current();
        cp.SYST.enable_counter();
    }
}

/// The cycle counter now: the DWT's, counting up; in QEMU SysTick's (24 bits, counting
/// down at the core clock).
pub fn cycles() -> u32 {
    if cfg!(board_qemu) {
        cortex_m::peripheral::SYST::get_current()
    } else {
        cortex_m::peripheral::DWT::cycle_count()
    }
}

/// Cycles of [`cycles`] in one tick's period: the core clock's (QEMU's SysTick counts
/// at the 168 MHz the machine models, whatever the clock tree says).
pub fn tick_period_cycles(clocks: &Clocks) -> u32 {
    let hz = if cfg!(board_qemu) {
        168_000_000
    } else {
        clocks.sysclk().raw()
    };
    hz / BOARD.tick_hz
}

/// Cycles from `start` to `end` of [`cycles`].
pub fn elapsed(start: u32, end: u32) -> u32 {
    if cfg!(board_qemu) {
        start.wrapping_sub(end) & 0x00FF_FFFF
    } else {
        end.wrapping_sub(start)
    }
}

#[cfg(board_run_ends)]
/// Cycles of the QEMU cycle counter as instructions: SysTick counts at 168 MHz, an
/// instruction is 2^3 ns under `-icount shift=3`.
pub fn qemu_instructions(cycles: u32) -> u32 {
    (cycles as f32 * 1e9 / (168e6 * 8.0)) as u32
}

/// The reset's cause (RCC_CSR's flags, bits 24–31), read and then cleared (RMVF) so
/// that the next boot reads only its own. QEMU models no RCC: 0.
pub fn reset_flags(rcc: &stm32f4xx_hal::pac::RCC) -> u32 {
    let flags = rcc.csr().read().bits() & 0xFF00_0000;
    rcc.csr().modify(|_, w| w.rmvf().set_bit());
    flags
}

/// Stops after a start-up failure: on the board the motor pins stay at their safe
/// levels, the watchdog and the tick never start; in QEMU, exit with failure.
pub fn stop() -> ! {
    if cfg!(board_qemu) {
        exit(false)
    }
    loop {
        cortex_m::asm::wfi();
    }
}

/// QEMU exits through semihosting (0 on success); on the board, a breakpoint.
pub fn exit(success: bool) -> ! {
    #[cfg(board_qemu)]
    {
        use cortex_m_semihosting::debug;
        debug::exit(if success {
            debug::EXIT_SUCCESS
        } else {
            debug::EXIT_FAILURE
        });
    }
    let _ = success;
    loop {
        cortex_m::asm::bkpt();
    }
}

/// The end of every way out, the motor cut and the black box stopped: on the board a
/// breakpoint (with no debugger, a HardFault that spins until the watchdog resets the
/// chip, the black box kept); in QEMU an exit with failure; with `fault-test`, the reset
/// the watchdog would make (QEMU models no watchdog), so that the next boot reads the
/// black box back.
fn stopped() -> ! {
    #[cfg(board_fault_test)]
    cortex_m::peripheral::SCB::sys_reset();
    #[allow(unreachable_code)]
    exit(false)
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    haptic_f405::safe_stop::cut_motor();
    haptic_f405::black_box::stop_in_handler(StopCause::Panic, 0);
    defmt::error!(
        "stop: panic, the motor cut: {}",
        defmt::Display2Format(info)
    );
    stopped()
}

/// Enables the configurable faults (MemManage, BusFault, UsageFault), so that each comes
/// to its own handler rather than escalating to HardFault; each cuts the motor as
/// HardFault does. And DBGMCU: a debugger's halt stops TIM1 with its outputs off.
pub fn enable_fault_handlers(scb: &mut cortex_m::peripheral::SCB) {
    use cortex_m::peripheral::scb::Exception;
    scb.enable(Exception::MemoryManagement);
    scb.enable(Exception::BusFault);
    scb.enable(Exception::UsageFault);
    haptic_f405::safe_stop::freeze_tim1_on_halt();
}

#[cortex_m_rt::exception]
unsafe fn HardFault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
    haptic_f405::safe_stop::cut_motor();
    haptic_f405::black_box::stop_in_handler(StopCause::HardFault, frame.pc());
    defmt::error!("stop: HardFault at pc={=u32:#x}, the motor cut", frame.pc());
    stopped()
}

#[cortex_m_rt::exception]
fn MemoryManagement() -> ! {
    haptic_f405::safe_stop::cut_motor();
    haptic_f405::black_box::stop_in_handler(StopCause::MemManage, 0);
    defmt::error!("stop: MemManage, the motor cut");
    stopped()
}

#[cortex_m_rt::exception]
fn BusFault() -> ! {
    haptic_f405::safe_stop::cut_motor();
    haptic_f405::black_box::stop_in_handler(StopCause::BusFault, 0);
    defmt::error!("stop: BusFault, the motor cut");
    stopped()
}

#[cortex_m_rt::exception]
fn UsageFault() -> ! {
    haptic_f405::safe_stop::cut_motor();
    haptic_f405::black_box::stop_in_handler(StopCause::UsageFault, 0);
    defmt::error!("stop: UsageFault, the motor cut");
    stopped()
}

/// A fault injected after start-up (`--features fault-test`, for the test command's
/// `board-faults` stage): the class named on the run's semihosting command line
/// (`panic`, `hard`, `mem`, `bus` or `usage`); none when it names none.
#[cfg(board_fault_test)]
pub fn inject_fault(scb: &mut cortex_m::peripheral::SCB) {
    let mut line = [0u8; 128];
    let class = mccs_firmware::command_line::words(&mut line)
        .nth(1)
        .unwrap_or(b"");
    defmt::info!("fault-test: injecting {=[u8]:a}", class);
    match class {
        b"panic" => panic!("injected"),
        b"usage" => cortex_m::asm::udf(),
        // UsageFault disabled, an undefined instruction escalates to HardFault.
        b"hard" => {
            scb.disable(cortex_m::peripheral::scb::Exception::UsageFault);
            cortex_m::asm::udf()
        }
        // A read of the reserved space above the peripherals (no device answers).
        // SAFETY: the read faults; it is the point.
        b"bus" => unsafe {
            core::ptr::read_volatile(0x6800_0000 as *const u32);
        },
        // A jump into the system region, which is never executable (XN).
        // SAFETY: the call faults before any instruction there runs.
        b"mem" => unsafe {
            let f: extern "C" fn() = core::mem::transmute(0xE000_0001usize);
            f();
        },
        _ => {}
    }
}
