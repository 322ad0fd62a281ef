//! The board firmware: the MCCS patch in a TIM2 interrupt on an STM32F405, driving the
//! device of its variant (`variant/`: the 1-DOF lever, the WoodenHaptics arm, or either
//! on a simulated plant), with an independent watchdog fed by the tick, defmt logs and
//! the host link on USART2. docs/firmware.md, "Bring-up on a board", and docs/arm.md are
//! the guides; `haptic_f405` holds the parts tested on the host.
//!
//! - `main` builds the device (in its safe state) and hands it to the tick; the tick's
//!   first run builds the controller, enables the driver, starts the watchdog and the
//!   tick timer.
//! - Each tick: clear the update, one tick of the controller with the link
//!   (`LinkState::run_tick`: the guard's gain, the pose, a checked tissue swapped in,
//!   read, solve, write; a device error latches the safe state), feed the watchdog, time
//!   it; a tick that ends with the next update pending is an overrun, and a run of them
//!   ends in the safe state.
//! - The main loop runs the host link (`host_link.rs`) and logs the tick statistics
//!   every second.
//! - What differs in QEMU is in `platform.rs`; which device, in `variant/`. Every
//!   `'static` buffer is a `static mut` local of `main` or of the tick (a `Slot` where it
//!   must lie in `.bss`), which cortex-m-rt hands over once.
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
mod host_link;
#[cfg(target_os = "none")]
mod platform;
#[cfg(target_os = "none")]
mod tick_timer;
#[cfg(target_os = "none")]
mod variant;

#[cfg(target_os = "none")]
mod firmware {
    use crate::host_link::{BoardLink, BoardWork, HostLink, RX_QUEUE};
    use crate::platform;
    use crate::tick_timer::TickTimer;
    use crate::variant::{BoardParts, BoardVariant, CtlOf, Variant};
    use cortex_m::peripheral::NVIC;
    use cortex_m_rt::entry;
    use haptic_f405::black_box::{self, BoardBox};
    use haptic_f405::config::{self, tick_timer, BOARD};
    use haptic_f405::device::{StartFault, SPACING_MM};
    use haptic_f405::telemetry::BoardTelemetry;
    use haptic_f405::tissue::TISSUE;
    use heapless::spsc::Queue;
    use mccs_firmware::link::{Guard, GuardTimes, Live, Session};
    use mccs_firmware::{HapticDevice, Mailbox, Shared, Slot};
    use mccs_link::{ContactKind, Core};
    use stm32f4xx_hal::pac::{self, interrupt, Interrupt};
    use stm32f4xx_hal::prelude::*;
    use stm32f4xx_hal::timer::Timer;
    use stm32f4xx_hal::watchdog::IndependentWatchdog;

    type Ctl = CtlOf<Variant>;
    type Device = <Variant as BoardVariant>::Device;

    /// The link's guard, pose, swap and mesh, shared by the tick and the main loop.
    static LINK: BoardLink = BoardLink::new(Guard::new(GuardTimes::at_rate(
        BOARD.tick_hz,
        BOARD.ramp_ms,
    )));

    /// What `main` hands the tick.
    struct Hardware {
        device: Device,
        tick: TickTimer,
        watchdog: IndependentWatchdog,
        /// Cycles in a tick's period.
        period: u32,
        /// The live black box.
        black_box: &'static mut BoardBox,
    }
    /// What the tick keeps of it once its controller runs.
    type TickHardware = (TickTimer, IndependentWatchdog, u32, &'static mut BoardBox);
    static HARDWARE: Mailbox<Hardware> = Mailbox::new();

    /// How the tick's first run went.
    #[derive(Clone, Copy)]
    enum Start {
        Pending,
        Running { springs: usize, substeps: u32 },
        Failed(StartFault),
    }
    static START: Shared<Start> = Shared::new(Start::Pending);
    /// The tick's statistics for the log.
    static TELEMETRY: Shared<BoardTelemetry> = Shared::new(BoardTelemetry::new());

    #[entry]
    fn main() -> ! {
        static mut RX: Queue<u8, RX_QUEUE> = Queue::new();
        static mut WORK: Slot<BoardWork> = Slot::new();
        static mut STORE: Slot<<Variant as BoardVariant>::Store> = Slot::new();
        let (Some(dp), Some(mut cp)) = (pac::Peripherals::take(), cortex_m::Peripherals::take())
        else {
            fail("peripherals taken twice")
        };
        // The last run's black box kept before anything else (the reset's cause with it).
        let Some((live_box, last_box)) = black_box::take_at_boot(platform::reset_flags(&dp.RCC))
        else {
            fail("the black box taken twice")
        };
        log_last_run(last_box);
        // Every fault to its own handler, each of which cuts the motor first.
        platform::enable_fault_handlers(&mut cp.SCB);
        if let Err(e) = BOARD.check() {
            fail_with(StartFault::Config(e));
        }
        let clocks = platform::clocks(dp.RCC.constrain());
        platform::start_cycle_counter(&mut cp);
        let parts = BoardParts {
            gpio: (dp.GPIOA.split(), dp.GPIOB.split(), dp.GPIOC.split()),
            tim1: dp.TIM1,
            spi1: dp.SPI1,
            tim3: dp.TIM3,
            tim4: dp.TIM4,
            tim5: dp.TIM5,
        };
        // The device first, in its safe state; it hands back the link's pins.
        let (device, max_duty, link_pins) = match Variant::build(parts, &clocks, STORE) {
            Ok(built) => built,
            Err(fault) => fail_with(fault),
        };
        // TIM1's PWM is set up, every duty zero: the stop chain's break input armed.
        haptic_f405::safe_stop::arm_break_input(BOARD.break_input);
        post_hardware(device, dp.TIM2, dp.IWDG, &dp.DBGMCU, &clocks, live_box);
        let work: &'static mut BoardWork = WORK.insert(BoardWork::new());
        let session = Session::new(live(), TISSUE, friction()).with_black_box(last_box);
        let mut link =
            match HostLink::start(dp.USART2, link_pins, &clocks, RX, &LINK, work, session) {
                Ok(l) => l,
                Err(_) => fail_with(StartFault::Config(config::BoardConfigError::Baud)),
            };
        // The tick's first run builds the controller and starts the timer.
        NVIC::pend(Interrupt::TIM2);
        // SAFETY: the handlers share state only through `Mailbox`, `Shared`, the link's
        // state and the queue's two ends.
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
        log_start(&clocks, max_duty, springs, substeps);
        let mut next_log = BOARD.tick_hz;
        loop {
            if !link.poll() {
                cortex_m::asm::wfi();
            }
            let t = TELEMETRY.get();
            if t.run.ticks >= next_log {
                next_log = next_log.saturating_add(BOARD.tick_hz);
                log_second(&t);
            }
            #[cfg(board_fault_test)]
            if t.run.ticks >= 100 {
                platform::inject_fault(&mut cp.SCB);
            }
            #[cfg(board_run_ends)]
            if t.run.ticks >= Variant::QEMU_TICKS {
                qemu_end(&t, substeps);
            }
        }
    }

    /// The tick's hardware, handed to the tick through its mailbox: the device (in its
    /// safe state), TIM2 at the tick rate, and the independent watchdog (frozen while a
    /// debugger halts the core, as TIM1's outputs are cut: `safe_stop`).
    fn post_hardware(
        device: Device,
        tim2: pac::TIM2,
        iwdg: pac::IWDG,
        dbgmcu: &pac::DBGMCU,
        clocks: &stm32f4xx_hal::rcc::Clocks,
        black_box: &'static mut BoardBox,
    ) {
        let Some((psc, arr)) = tick_timer(platform::timer_clock(clocks), BOARD.tick_hz) else {
            fail_with(StartFault::Config(config::BoardConfigError::Tick))
        };
        let tick = TickTimer::new(Timer::new(tim2, clocks).release(), psc, arr);
        let watchdog = IndependentWatchdog::new(iwdg);
        watchdog.stop_on_debug(dbgmcu, true);
        if HARDWARE
            .post(Hardware {
                device,
                tick,
                watchdog,
                period: platform::tick_period_cycles(clocks),
                black_box,
            })
            .is_some()
        {
            fail("hardware posted twice");
        }
    }

    /// The start-up lines: the board, its rates and its patch, and the table's error.
    fn log_start(
        clocks: &stm32f4xx_hal::rcc::Clocks,
        max_duty: u16,
        springs: usize,
        substeps: u32,
    ) {
        defmt::info!(
            "mccs haptic-f405 ({=str}): sysclk={=u32} Hz, device={=str}, pwm={=u32} Hz ({=u16} steps), tick={=u32} Hz, watchdog={=u32} ms, link={=u32} baud; N={=usize} patch, {=usize} springs, {=u32} substeps per tick",
            Variant::NAME,
            clocks.sysclk().raw(),
            Variant::DESCRIPTION,
            BOARD.pwm_hz,
            max_duty,
            BOARD.tick_hz,
            BOARD.watchdog_ms,
            BOARD.baud,
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
    }

    /// The device as the link describes it.
    fn live() -> Live {
        let roaming = Variant::CONTACT == ContactKind::Roaming;
        let tissue = if roaming {
            BOARD.tissue_nodes.map(|n| n as u8)
        } else {
            [BOARD.grid as u8; 2]
        };
        Live {
            device: Variant::KIND,
            simulated: Variant::SIMULATED,
            core: Core::M4f,
            contact: Variant::CONTACT,
            grid: BOARD.grid,
            spacing: SPACING_MM,
            tissue,
            config: BOARD.solver(),
            workspace: BOARD.workspace_q24(),
            pose_speed_mm_s: BOARD.pose_speed_mm_s,
            pose_turn_deg_s: BOARD.pose_turn_deg_s,
            baud: BOARD.baud,
            budget: BOARD.budget(),
            narrow: false,
        }
    }

    /// The start-up tissue's friction, on a contact with friction.
    fn friction() -> Option<mccs::Friction> {
        if Variant::CONTACT == ContactKind::Roaming {
            mccs::Friction::new(BOARD.mu_s, BOARD.mu_k).ok()
        } else {
            None
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
        Variant::log_second(t);
        if let (Some(fault), Some(at)) = (t.run.fault, t.fault_tick) {
            match t.part {
                Some(p) => defmt::error!(
                    "safe state since tick {=u32}: {}: {=str}",
                    at,
                    fault,
                    p.name()
                ),
                None => defmt::error!("safe state since tick {=u32}: {}", at, fault),
            }
        }
    }

    #[interrupt]
    fn TIM2() {
        static mut CTL: Slot<Ctl> = Slot::new();
        static mut HW: Option<TickHardware> = None;
        let slot = CTL.option();
        if slot.is_none() || HW.is_none() {
            init(slot, HW);
            return;
        }
        let (Some(ctl), Some((tick, watchdog, period, live_box))) = (slot.as_mut(), HW.as_mut())
        else {
            return;
        };
        let start = platform::cycles();
        tick.clear();
        #[cfg(board_run_ends)]
        if ctl.telemetry().ticks >= Variant::QEMU_TICKS {
            tick.stop();
            return;
        }
        // The stop chain cut the drive in hardware: latch the safe state (and say why).
        if haptic_f405::safe_stop::break_tripped_now() {
            ctl.stop(mccs_firmware::Fault::Amplifier);
        }
        LINK.run_tick(ctl);
        watchdog.feed();
        let us = tick.count();
        let cycles = platform::elapsed(start, platform::cycles());
        // Overrun: the next update fell due, or (QEMU's timer model does not say so)
        // the tick took longer than its period.
        if tick.pending() || cycles > *period {
            ctl.note_overrun();
        } else {
            ctl.note_on_time();
        }
        let encoder = Variant::encoder_errors(ctl);
        let device = ctl.device().status();
        let part = Variant::device_part(ctl);
        let run = ctl.telemetry();
        let gain = ctl.device().gain();
        let kept = black_box::tick_record(&run, &device, Variant::box_counts(ctl), gain);
        black_box::record(live_box, kept, run.fault, part);
        TELEMETRY.update(|t| t.record(run, us, cycles, (encoder, device, part)));
    }

    /// The tick's first run: builds the controller on the hardware `main` handed over,
    /// enables the driver, starts the watchdog and the timer. Out of line, so that its
    /// stack frames are free before the ticks.
    #[inline(never)]
    fn init(ctl: &mut Option<Ctl>, hw: &mut Option<TickHardware>) {
        let Some(Hardware {
            device,
            mut tick,
            mut watchdog,
            period,
            black_box,
        }) = HARDWARE.take()
        else {
            return;
        };
        match Variant::controller_into(&BOARD, TISSUE, device, ctl) {
            Ok(()) => {
                if let Some(c) = ctl {
                    START.set(Start::Running {
                        springs: c.solver().topology().edges().len(),
                        substeps: c.solver().substeps(),
                    });
                }
                watchdog.start(BOARD.watchdog_ms.millis());
                tick.start();
                *hw = Some((tick, watchdog, period, black_box));
            }
            // The device is in its safe state; the timer never starts.
            Err((fault, _)) => START.set(Start::Failed(fault)),
        }
    }

    /// The end of a QEMU run: the SUMMARY, held to the fault rules, and the exit through
    /// semihosting.
    #[cfg(board_run_ends)]
    fn qemu_end(t: &BoardTelemetry, substeps: u32) -> ! {
        use haptic_f405::telemetry::qemu_verdict;
        let verdict = qemu_verdict(Variant::QEMU_TICKS, t, Variant::QEMU_FAULT_TICK);
        let worst = platform::qemu_instructions(t.worst_cycles);
        // The simulated arm's run is the trainer's whole tick (issue 60): the counts, the
        // arm's chain, the roaming patch with friction, Jᵀ F and gravity, the duties and
        // the link's share, at its worst over a palpation; held to half a tick at 168 MHz
        // by the test command (bench/budgets.txt), and to what the board's budget model
        // says it costs (`tick_base_cost + substeps × substep_cost`, which a tissue's
        // check is held to).
        if Variant::SIMULATED && matches!(Variant::KIND, mccs_link::DeviceKind::Arm) {
            defmt::println!(
                "BENCH core=m4f case=trainer_tick n={=usize} substeps={=u32} ticks={=u32} worst_instructions={=u32} model_instructions={=u32} half_tick_instructions={=u32}",
                BOARD.grid,
                substeps,
                t.run.ticks,
                worst,
                BOARD.budget().cost(substeps),
                BOARD.tick_budget
            );
        }
        defmt::println!(
            "SUMMARY board={=str} ticks={=u32} overruns={=u32} fault={=str} fault_tick={=i32} worst_tick_instructions={=u32} safe_state_errors={=u32} verdict={=str}",
            Variant::NAME,
            t.run.ticks,
            t.run.overruns,
            mccs_firmware::link::state::fault_reason(t.run.fault).name(),
            t.fault_tick.map_or(-1, |x| x as i32),
            worst,
            t.run.safe_state_errors,
            match verdict {
                Ok(()) => "ok",
                Err(m) => m.message(),
            }
        );
        platform::exit(verdict.is_ok())
    }

    /// What the black box kept of the run before the last reset, in one line (none after
    /// a power-on). With `fault-test`, a run that finds one stopped by its injected
    /// fault ends here (with failure, as the fault's run would have).
    fn log_last_run(last: &BoardBox) {
        if !last.kept() {
            defmt::info!("black box: no record of a last run");
            return;
        }
        let (stop, (end, ended)) = (last.stop_record(), last.ended());
        let part = haptic_f405::device::DevicePart::from_code(stop.part).map_or("", |p| p.name());
        defmt::info!(
            "black box: the last run stopped by {=str} ({=str}) at tick {=u32}, ended by {=str} at tick {=u32} pc={=u32:#x}; reset flags {=u32:#x}; {=usize} ticks kept",
            last.cause().name(),
            part,
            stop.tick,
            end.name(),
            ended.tick,
            ended.pc,
            last.reset_flags(),
            last.len()
        );
        // (The injected fault's run, read back after its reset: the test's end.)
        #[cfg(board_fault_test)]
        if end != mccs_link::StopCause::None {
            platform::exit(false);
        }
    }

    /// A start-up failure, logged with its type and values (`StartFault`): as [`fail`].
    fn fail_with(fault: StartFault) -> ! {
        defmt::error!("start-up failed: {}", fault);
        platform::stop()
    }

    /// A start-up failure: logged; the motor pins stay at their safe levels, the
    /// watchdog and the tick never start. In QEMU: exit with failure.
    fn fail(what: &str) -> ! {
        defmt::error!("start-up failed: {=str}", what);
        platform::stop()
    }
}
