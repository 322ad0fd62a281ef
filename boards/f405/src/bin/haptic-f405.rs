//! The board firmware: the MCCS patch in a TIM2 interrupt on an STM32F405, driving a
//! 1-DOF device — an AS5047P encoder on SPI1 and a DC motor on TIM1's PWM with direction
//! and enable pins — with an independent watchdog fed by the tick and defmt over RTT.
//! `--features qemu` runs it in QEMU (`netduinoplus2`) instead: see docs/firmware.md,
//! "Bring-up on a board", and `haptic_f405` for the parts tested on the host.
//!
//! - The tick interrupt owns the hardware: `main` builds the device (in its safe state)
//!   and hands it over; the tick's first run builds the controller, enables the driver,
//!   starts the watchdog and the tick timer.
//! - Each tick: clear the update, one controller tick (read, solve, write; a device error
//!   latches the safe state, re-asserted every tick after), feed the watchdog, time it.
//!   A tick that ends with the next update already pending is an overrun.
//! - The main loop logs the tick statistics every second.
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
    use embedded_hal_bus::spi::{ExclusiveDevice, NoDelay};
    use haptic_f405::config::{self, spi_clock_hz, tick_timer, AS5047P_MAX_SPI_HZ, BOARD};
    use haptic_f405::device::{self, BoardController, BoardDevice, StartFault};
    use haptic_f405::pins::{EncoderCs, MotorDirection, MotorEnable, Pins};
    use haptic_f405::telemetry::BoardTelemetry;
    use haptic_f405::tissue::TISSUE;
    use mccs_firmware::{Mailbox, Shared};
    use stm32f4xx_hal::pac::{self, interrupt, Interrupt};
    use stm32f4xx_hal::prelude::*;
    use stm32f4xx_hal::spi::Spi;
    use stm32f4xx_hal::timer::{PwmChannel, Timer};
    use stm32f4xx_hal::watchdog::IndependentWatchdog;

    type Encoder = ExclusiveDevice<Spi<pac::SPI1>, EncoderCs, NoDelay>;
    type Motor = PwmChannel<pac::TIM1, 0>;
    type Device = BoardDevice<Encoder, Motor, MotorDirection, MotorEnable>;
    type Ctl = BoardController<Device>;

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
    static TELEMETRY: Shared<BoardTelemetry> = Shared::new(BoardTelemetry::new());

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

        let pins = Pins::take(dp.GPIOA.split(), dp.GPIOB.split());
        let spi_hz = spi_clock_hz(clocks.pclk2().raw(), BOARD.spi_request_hz);
        if spi_hz == 0 || spi_hz > AS5047P_MAX_SPI_HZ {
            fail_with(StartFault::Config(config::BoardConfigError::SpiTooFast));
        }
        let spi = Spi::new(
            dp.SPI1,
            (pins.sck, pins.miso, pins.mosi),
            device::SPI_MODE,
            BOARD.spi_request_hz.Hz(),
            &clocks,
        );
        // The chip select's error is `Infallible`.
        let Ok(encoder) = ExclusiveDevice::new_no_delay(spi, pins.cs);
        let (_pwm, (ch1, ..)) = dp.TIM1.pwm_hz(BOARD.pwm_hz.Hz(), &clocks);
        let mut motor = ch1.with(pins.pwm);
        motor.set_duty(0);
        motor.enable();
        let max_duty = motor.get_max_duty();
        let device = match device::device(&BOARD, encoder, motor, pins.direction, pins.enable) {
            Ok(d) => d,
            Err(e) => fail_with(e.fault()),
        };

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
        // SAFETY: the handler shares state only through `Mailbox` and `Shared`.
        unsafe { NVIC::unmask(Interrupt::TIM2) };
        cortex_m::asm::isb();
        let (springs, substeps) = match START.get() {
            Start::Running { springs, substeps } => (springs, substeps),
            Start::Failed(fault) => fail_with(fault),
            Start::Pending => fail("the tick's first run did not start"),
        };
        defmt::info!(
            "mccs haptic-f405: sysclk={=u32} Hz, spi={=u32} Hz (mode 1), pwm={=u32} Hz ({=u16} steps), tick={=u32} Hz, watchdog={=u32} ms; N={=usize} patch, {=usize} springs, {=u32} substeps per tick",
            clocks.sysclk().raw(),
            spi_hz,
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
        let mut next_log = BOARD.tick_hz;
        loop {
            cortex_m::asm::wfi();
            let t = TELEMETRY.get();
            if t.run.ticks >= next_log {
                next_log = next_log.saturating_add(BOARD.tick_hz);
                log_second(&t);
            }
            #[cfg(feature = "qemu")]
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
        if let (Some(fault), Some(at)) = (t.run.fault, t.fault_tick) {
            defmt::error!("safe state since tick {=u32}: {}", at, fault);
        }
    }

    #[interrupt]
    fn TIM2() {
        static mut CTL: Option<Ctl> = None;
        static mut HW: Option<(TickTimer, IndependentWatchdog)> = None;
        let (Some(ctl), Some((tick, watchdog))) = (CTL.as_mut(), HW.as_mut()) else {
            init(CTL, HW);
            return;
        };
        let start = cycles();
        tick.clear();
        #[cfg(feature = "qemu")]
        if ctl.telemetry().ticks >= BOARD.qemu_ticks {
            tick.stop();
            return;
        }
        ctl.tick(None);
        watchdog.feed();
        let us = tick.count();
        let cycles = elapsed(start, cycles());
        if tick.pending() {
            ctl.note_overrun();
        }
        let mut t = TELEMETRY.get();
        t.record(ctl.telemetry(), us, cycles, ctl.device().encoder.errors());
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
        match device::controller_into(&BOARD, TISSUE, device, ctl) {
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
            Err((e, _)) => START.set(Start::Failed(e.fault())),
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
        #[cfg(feature = "qemu")]
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
    #[cfg(feature = "qemu")]
    fn qemu_end(t: &BoardTelemetry) -> ! {
        use haptic_f405::telemetry::qemu_verdict;
        let verdict = qemu_verdict(&BOARD, t);
        // SysTick counts at 168 MHz → instructions at 2^shift ns each (-icount shift=3).
        let instructions = t.worst_cycles as f32 * 1e9 / (168e6 * 8.0);
        defmt::println!(
            "SUMMARY board=f405 ticks={=u32} overruns={=u32} fault={=str} fault_tick={=i32} worst_tick_instructions={=u32} safe_state_errors={=u32} verdict={=str}",
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
