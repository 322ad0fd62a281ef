//! The board firmware: the MCCS patch in a TIM2 interrupt on an STM32F405, driving a
//! 1-DOF device — an AS5047P encoder on SPI1 and a DC motor on TIM1's PWM with direction
//! and enable pins — with an independent watchdog fed by the tick and defmt over RTT.
//! `--features qemu` runs it in QEMU (`netduinoplus2`) instead: see docs/firmware.md,
//! "Bring-up on a board", and `haptic_f405` for the parts tested on the host.
//!
//! `--features arm` drives the WoodenHaptics 3-DOF arm instead (`haptic_f405::arm`:
//! three quadrature timers, TIM1's three PWM channels; docs/arm.md).
//!
//! - The tick interrupt owns the hardware: `main` builds the device (in its safe state)
//!   and hands it over; the tick's first run builds the controller, enables the driver,
//!   starts the watchdog and the tick timer.
//! - Each tick: clear the update, one controller tick (read, solve, write; a device error
//!   latches the safe state, re-asserted every tick after), feed the watchdog, time it.
//!   A tick that ends with the next update already pending is an overrun.
//! - The main loop logs the tick statistics every second, and runs the host link
//!   (`host_link.rs`, docs/link.md), which hands the tick what it must see through
//!   shared state and a mailbox. The tick never waits on the link.
//! - The device, one file per variant (`variant/`): its pins, parts and controller.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "haptic-f405 is firmware: build it for the STM32F405 with `cargo f405-build`, flash it \
         with `cargo f405-run`, or run it in QEMU with `bash scripts/f405-qemu.sh` (see docs/firmware.md)"
    );
    std::process::exit(2);
}

// The main loop's end of the host link, and USART2's receive interrupt.
#[cfg(target_os = "none")]
#[path = "haptic-f405/host_link.rs"]
mod host_link;

// The device each variant drives: its pins, its parts, its controller.
#[cfg(all(target_os = "none", feature = "arm"))]
#[path = "variant/arm.rs"]
mod variant;

/// The peripherals `main` hands a variant's `build_device`; it takes the ones its device
/// uses (the 1-DOF: TIM1 and SPI1; the arm: TIM1, TIM3, TIM4, TIM5) and drops the rest,
/// which stay in their reset state (hence `dead_code`: each variant reads only its own).
#[cfg(target_os = "none")]
#[allow(dead_code)]
struct Timers {
    tim1: stm32f4xx_hal::pac::TIM1,
    spi1: stm32f4xx_hal::pac::SPI1,
    tim3: stm32f4xx_hal::pac::TIM3,
    tim4: stm32f4xx_hal::pac::TIM4,
    tim5: stm32f4xx_hal::pac::TIM5,
}
#[cfg(all(target_os = "none", not(feature = "arm")))]
#[path = "variant/one_dof.rs"]
mod variant;

#[cfg(target_os = "none")]
mod firmware {
    #[cfg(not(feature = "qemu"))]
    use defmt_rtt as _;
    #[cfg(feature = "qemu")]
    use defmt_semihosting as _;
    #[cfg(not(feature = "qemu"))]
    use panic_probe as _;

    use cortex_m::peripheral::NVIC;
    use cortex_m_rt::entry;
    use haptic_f405::config::{self, tick_timer, BOARD};
    use haptic_f405::device::StartFault;
    use haptic_f405::device::NODES;
    use haptic_f405::telemetry::BoardTelemetry;
    use haptic_f405::tissue::TISSUE;
    use heapless::spsc::Queue;
    use mccs::{ParamSet, Wide};
    use mccs_firmware::link::{Mesh, TickLink};
    use mccs_firmware::{Mailbox, Shared};
    use stm32f4xx_hal::pac::{self, interrupt, Interrupt};
    use stm32f4xx_hal::prelude::*;
    use stm32f4xx_hal::timer::Timer;
    use stm32f4xx_hal::watchdog::IndependentWatchdog;

    use crate::host_link::{HostLink, LINK_RX, RX_QUEUE};
    use crate::variant::{self, build_device, take_pins, Ctl, Device};
    use crate::Timers;
    pub(crate) type Segments = ParamSet<{ haptic_f405::tissue::SEGMENTS }, Wide>;

    /// The link's guard, pose and swap flag, shared by the tick and the main loop.
    pub(crate) static LINK: TickLink = TickLink::new(BOARD.tick_hz);
    /// A checked tissue for the tick to swap in.
    pub(crate) static SWAP: Mailbox<Segments> = Mailbox::new();
    /// The patch's nodes, when the host watches the mesh.
    pub(crate) static MESH: Mailbox<Mesh<NODES>> = Mailbox::new();

    /// What `main` hands the tick.
    struct Hardware {
        device: Device,
        tick: TickTimer,
        watchdog: IndependentWatchdog,
    }
    static HARDWARE: Mailbox<Hardware> = Mailbox::new();

    /// How the tick's first run went.
    #[derive(Clone, Copy)]
    enum Start {
        Pending,
        Running { springs: usize, substeps: u32 },
        Failed(StartFault),
    }
    static START: Shared<Start> = Shared::new(Start::Pending);
    pub(crate) static TELEMETRY: Shared<BoardTelemetry> = Shared::new(BoardTelemetry::new());

    #[entry]
    fn main() -> ! {
        let (Some(dp), Some(mut cp)) = (pac::Peripherals::take(), cortex_m::Peripherals::take())
        else {
            fail("peripherals taken twice")
        };
        if let Err(e) = BOARD.check() {
            fail_with(StartFault::Config(e));
        }
        let rcc = dp.RCC.constrain();
        // QEMU models no RCC (an HSE or PLL never reports ready): it keeps the reset
        // clock, HSI at 16 MHz.
        #[cfg(not(feature = "qemu"))]
        let clocks = rcc
            .cfgr
            .use_hse(BOARD.hse_hz.Hz())
            .sysclk(BOARD.sysclk_hz.Hz())
            .freeze();
        #[cfg(feature = "qemu")]
        let clocks = rcc.cfgr.freeze();
        cp.DCB.enable_trace();
        cp.DWT.enable_cycle_counter();
        // QEMU models no DWT cycle counter: SysTick, free-running, times the tick there.
        #[cfg(feature = "qemu")]
        {
            use cortex_m::peripheral::syst::SystClkSource;
            cp.SYST.set_clock_source(SystClkSource::Core);
            cp.SYST.set_reload(0x00FF_FFFF);
            cp.SYST.clear_current();
            cp.SYST.enable_counter();
        }

        let pins = take_pins(dp.GPIOA.split(), dp.GPIOB.split(), dp.GPIOC.split());
        // The device first, in its safe state; it hands back the link's pins.
        let (device, max_duty, (link_tx, link_rx)) = match build_device(
            pins,
            &clocks,
            Timers {
                tim1: dp.TIM1,
                spi1: dp.SPI1,
                tim3: dp.TIM3,
                tim4: dp.TIM4,
                tim5: dp.TIM5,
            },
        ) {
            Ok(built) => built,
            Err(fault) => fail_with(fault),
        };
        // The host link: USART2 at 115200 8N1, its receive interrupt feeding a queue.
        let Ok(serial) = dp.USART2.serial(
            (link_tx, link_rx),
            stm32f4xx_hal::serial::Config::default().baudrate(115_200.bps()),
            &clocks,
        ) else {
            fail("USART2: the clock cannot make 115200 baud")
        };
        let (link_tx, mut link_rx) = serial.split();
        link_rx.listen();
        let queue: &'static mut Queue<u8, RX_QUEUE> = {
            static mut QUEUE: Queue<u8, RX_QUEUE> = Queue::new();
            // SAFETY: the one reference to QUEUE, taken once before any interrupt runs.
            unsafe { &mut *core::ptr::addr_of_mut!(QUEUE) }
        };
        let (producer, consumer) = queue.split();
        let _ = LINK_RX.post((link_rx, producer));

        // QEMU's timers run at 1 GHz whatever the clock tree says.
        let timer_clock = if cfg!(feature = "qemu") {
            config::QEMU_TIMER_CLOCK_HZ
        } else {
            clocks.timclk1().raw()
        };
        let Some((psc, arr)) = tick_timer(timer_clock, BOARD.tick_hz) else {
            fail_with(StartFault::Config(config::BoardConfigError::Tick))
        };
        let tick = TickTimer::new(Timer::new(dp.TIM2, &clocks).release(), psc, arr);
        let watchdog = IndependentWatchdog::new(dp.IWDG);
        watchdog.stop_on_debug(&dp.DBGMCU, true);
        if HARDWARE
            .post(Hardware {
                device,
                tick,
                watchdog,
            })
            .is_some()
        {
            fail("hardware posted twice");
        }
        // The tick's first run builds the controller and starts the timer.
        NVIC::pend(Interrupt::TIM2);
        // SAFETY: the handlers share state only through `Mailbox`, `Shared` and the
        // queue's two ends.
        unsafe {
            NVIC::unmask(Interrupt::TIM2);
            NVIC::unmask(Interrupt::USART2);
        }
        cortex_m::asm::isb();
        let (springs, substeps) = match START.get() {
            Start::Running { springs, substeps } => (springs, substeps),
            Start::Failed(fault) => fail_with(fault),
            Start::Pending => fail("the tick's first run did not start"),
        };
        defmt::info!(
            "mccs haptic-f405: sysclk={=u32} Hz, device={=str}, pwm={=u32} Hz ({=u16} steps), tick={=u32} Hz, watchdog={=u32} ms; N={=usize} patch, {=usize} springs, {=u32} substeps per tick",
            clocks.sysclk().raw(),
            variant::DEVICE,
            BOARD.pwm_hz,
            max_duty,
            BOARD.tick_hz,
            BOARD.watchdog_ms,
            BOARD.grid,
            springs,
            substeps
        );

        // The table's own measured error against the f64 law (`mccs table` measured it).
        if let Some(e) = TISSUE.max_error() {
            defmt::info!(
                "force table: {=usize} knots, error {=f32} of F(to) in force, {=f32} in stiffness (measured when emitted)",
                haptic_f405::tissue::SEGMENTS + 1,
                e.force as f32,
                e.stiffness as f32
            );
        }
        let mut link = HostLink::new(link_tx, consumer);
        let mut next_log = BOARD.tick_hz;
        loop {
            let busy = link.poll();
            if !busy {
                cortex_m::asm::wfi();
            }
            let t = TELEMETRY.get();
            if t.run.ticks >= next_log {
                next_log = next_log.saturating_add(BOARD.tick_hz);
                log_second(&t);
            }
            // A QEMU run ends after its ticks, unless it serves a host link.
            #[cfg(all(feature = "qemu", not(feature = "qemu-link")))]
            if t.run.ticks >= BOARD.qemu_ticks {
                qemu_end(&t);
            }
        }
    }

    /// The tick statistics, every second.
    fn log_second(t: &BoardTelemetry) {
        let e = t.encoder;
        defmt::info!(
            "tick={=u32} worst_tick_us={=u32} worst_tick_cycles={=u32} overruns={=u32} force_n={=f32} encoder parity={=u32} flagged={=u32} implausible={=u32} diagnostic={=u32}",
            t.run.ticks,
            t.worst_us,
            t.worst_cycles,
            t.run.overruns,
            t.run.force[2].to_num::<f32>(),
            e.parity,
            e.flagged,
            e.implausible,
            e.diagnostic
        );
        variant::log_second(t);
        if let (Some(fault), Some(at)) = (t.run.fault, t.fault_tick) {
            defmt::error!("safe state since tick {=u32}: {}", at, fault);
        }
    }

    #[interrupt]
    fn TIM2() {
        // The controller in `.bss`: an `Option<Ctl>` static is initialised data (its
        // `None` is a niche value), 8 KB of flash for its image. Written `None` once.
        static mut CTL: core::mem::MaybeUninit<Option<Ctl>> = core::mem::MaybeUninit::uninit();
        static mut CTL_WRITTEN: bool = false;
        static mut HW: Option<(TickTimer, IndependentWatchdog)> = None;
        if !*CTL_WRITTEN {
            CTL.write(None);
            *CTL_WRITTEN = true;
        }
        // SAFETY: written above before its first read.
        let slot = unsafe { CTL.assume_init_mut() };
        let (Some(ctl), Some((tick, watchdog))) = (slot.as_mut(), HW.as_mut()) else {
            init(slot, HW);
            return;
        };
        let start = cycles();
        tick.clear();
        #[cfg(all(feature = "qemu", not(feature = "qemu-link")))]
        if ctl.telemetry().ticks >= BOARD.qemu_ticks {
            tick.stop();
            return;
        }
        let (_, gain) = LINK.tick(ctl, &SWAP, &MESH);
        watchdog.feed();
        let us = tick.count();
        let cycles = elapsed(start, cycles());
        if tick.pending() {
            ctl.note_overrun();
        }
        let mut t = TELEMETRY.get();
        t.record(ctl.telemetry(), us, cycles, variant::encoder_errors(ctl));
        variant::record(ctl, &mut t);
        t.probe = ctl.device().probe().map(|c| c.to_bits());
        t.gain = gain;
        TELEMETRY.set(t);
    }

    /// The core's cycle counter (DWT), counting up.
    #[cfg(not(feature = "qemu"))]
    fn cycles() -> u32 {
        cortex_m::peripheral::DWT::cycle_count()
    }
    #[cfg(not(feature = "qemu"))]
    fn elapsed(start: u32, end: u32) -> u32 {
        end.wrapping_sub(start)
    }
    /// In QEMU: SysTick (24 bits, counting down at QEMU's 168 MHz core clock).
    #[cfg(feature = "qemu")]
    fn cycles() -> u32 {
        cortex_m::peripheral::SYST::get_current()
    }
    #[cfg(feature = "qemu")]
    fn elapsed(start: u32, end: u32) -> u32 {
        start.wrapping_sub(end) & 0x00FF_FFFF
    }

    /// The tick's first run: builds the controller on the hardware `main` handed over,
    /// enables the driver, starts the watchdog and the timer. Out of line, so that its
    /// stack frames are free before the ticks.
    #[inline(never)]
    fn init(ctl: &mut Option<Ctl>, hw: &mut Option<(TickTimer, IndependentWatchdog)>) {
        let Some(Hardware {
            device,
            mut tick,
            mut watchdog,
        }) = HARDWARE.take()
        else {
            return;
        };
        match variant::controller_into(&BOARD, TISSUE, device, ctl) {
            Ok(()) => {
                if let Some(c) = ctl {
                    START.set(Start::Running {
                        springs: c.solver().topology().edges().len(),
                        substeps: c.solver().substeps(),
                    });
                }
                watchdog.start(BOARD.watchdog_ms.millis());
                tick.start();
                *hw = Some((tick, watchdog));
            }
            // The device is in its safe state; the timer never starts.
            Err((fault, _)) => START.set(Start::Failed(fault)),
        }
    }

    /// TIM2 as the tick: the counter at 1 MHz, an update every tick.
    struct TickTimer(pac::TIM2);

    impl TickTimer {
        /// Sets the prescaler and the period; neither counting nor interrupting yet.
        fn new(tim: pac::TIM2, psc: u16, arr: u32) -> Self {
            tim.psc().write(|w| w.psc().set(psc));
            tim.arr().write(|w| w.arr().set(arr));
            // Load the prescaler now (an update event), then clear its flag.
            tim.egr().write(|w| w.ug().set_bit());
            tim.sr().write(|w| w.uif().clear());
            Self(tim)
        }
        /// Counts from zero, an update interrupt every tick. (Writing the counter also
        /// arms QEMU's timer model, whose alarm lapses if it expires while disabled.)
        fn start(&mut self) {
            self.0.sr().write(|w| w.uif().clear());
            self.0.dier().modify(|_, w| w.uie().set_bit());
            self.0.cr1().modify(|_, w| w.cen().set_bit());
            self.0.cnt().write(|w| w.cnt().set(0));
        }
        #[cfg(all(feature = "qemu", not(feature = "qemu-link")))]
        fn stop(&mut self) {
            self.0.dier().modify(|_, w| w.uie().clear_bit());
        }
        fn clear(&mut self) {
            self.0.sr().write(|w| w.uif().clear());
        }
        /// Whether the next update fell due.
        fn pending(&self) -> bool {
            self.0.sr().read().uif().bit_is_set()
        }
        /// µs since the last update. (QEMU's model does not restart its counter at an
        /// update: 0 there.)
        fn count(&self) -> u32 {
            if cfg!(feature = "qemu") {
                0
            } else {
                self.0.cnt().read().cnt().bits()
            }
        }
    }

    /// The end of a QEMU run: the SUMMARY, held to the fault rules (the encoder reads
    /// zeros in QEMU), and the exit through semihosting.
    #[cfg(all(feature = "qemu", not(feature = "qemu-link")))]
    fn qemu_end(t: &BoardTelemetry) -> ! {
        use haptic_f405::telemetry::qemu_verdict;
        let verdict = qemu_verdict(&BOARD, t, variant::QEMU_FAULT_TICK);
        // SysTick counts at 168 MHz → instructions at 2^shift ns each (-icount shift=3).
        let instructions = t.worst_cycles as f32 * 1e9 / (168e6 * 8.0);
        defmt::println!(
            "SUMMARY board={=str} ticks={=u32} overruns={=u32} fault={=str} fault_tick={=i32} worst_tick_instructions={=u32} safe_state_errors={=u32} verdict={=str}",
            variant::NAME,
            t.run.ticks,
            t.run.overruns,
            match t.run.fault {
                None => "none",
                Some(mccs_firmware::Fault::Read) => "read",
                Some(mccs_firmware::Fault::Write) => "write",
            },
            t.fault_tick.map_or(-1, |x| x as i32),
            instructions as u32,
            t.run.safe_state_errors,
            match verdict {
                Ok(()) => "ok",
                Err(m) => m.message(),
            }
        );
        exit(verdict.is_ok())
    }

    #[cfg(feature = "qemu")]
    #[panic_handler]
    fn panic(info: &core::panic::PanicInfo) -> ! {
        defmt::error!("panic: {}", defmt::Display2Format(info));
        exit(false)
    }

    #[cfg(feature = "qemu")]
    #[cortex_m_rt::exception]
    unsafe fn HardFault(_frame: &cortex_m_rt::ExceptionFrame) -> ! {
        exit(false)
    }

    /// QEMU exits through semihosting (0 on success).
    #[cfg(feature = "qemu")]
    fn exit(success: bool) -> ! {
        use cortex_m_semihosting::debug;
        debug::exit(if success {
            debug::EXIT_SUCCESS
        } else {
            debug::EXIT_FAILURE
        });
        loop {
            cortex_m::asm::bkpt();
        }
    }

    /// A start-up failure, logged with its type and values (`StartFault`): as [`fail`].
    fn fail_with(fault: StartFault) -> ! {
        defmt::error!("start-up failed: {}", fault);
        stop()
    }

    /// A start-up failure: logged; the motor pins stay at their safe levels, the
    /// watchdog and the tick never start. In QEMU: exit with failure.
    fn fail(what: &str) -> ! {
        defmt::error!("start-up failed: {=str}", what);
        stop()
    }

    /// Stops after a start-up failure.
    fn stop() -> ! {
        #[cfg(feature = "qemu")]
        exit(false);
        #[cfg(not(feature = "qemu"))]
        loop {
            cortex_m::asm::wfi();
        }
    }
}
