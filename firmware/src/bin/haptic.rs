//! The haptic firmware: the MCCS patch solver in a 1 kHz SysTick interrupt, roaming a
//! tissue under a simulated device that replays the demo's palpation (see
//! `mccs_firmware::demo`), logging with defmt. Runs in QEMU on `netduinoplus2` (Cortex-M4F, the default), `lm3s6965evb`
//! (Cortex-M3) and `microbit` (Cortex-M0); see docs/firmware.md.
//!
//! - The tick interrupt owns the controller (solver + device). The main loop reads the
//!   telemetry and hands over a new parameter set through a `Mailbox` (double buffer):
//!   the tick switches between two ticks, never inside one.
//! - A tick during which the next tick fell due (SysTick pending again when it ends) is
//!   counted as an overrun. In QEMU under `-icount shift=N` time is instructions, so that
//!   is a tick over its instruction budget (`DemoSpec::budget`).
//! - A device error puts the controller in its safe state (zero force, latched).
//! - A panic or a hard fault exits QEMU with failure through semihosting.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!(
        "haptic is firmware: build it for a Cortex-M target, e.g. \
         `cargo run -p mccs-firmware --release --target thumbv7em-none-eabihf --bin haptic` (see docs/firmware.md)"
    );
    std::process::exit(2);
}

#[cfg(target_os = "none")]
mod fw_common;

#[cfg(target_os = "none")]
mod stack_paint;

#[cfg(target_os = "none")]
mod firmware {
    use super::{fw_common, stack_paint};
    use cortex_m::peripheral::{syst::SystClkSource, SCB, SYST};
    use cortex_m_rt::{entry, exception};
    use fw_common::exit;
    use mccs::{DefaultArith, ParamSet};
    use mccs_firmware::demo::{self, DemoSpec};
    use mccs_firmware::target::{Core, CORE};
    use mccs_firmware::{Mailbox, Shared, Slot, Telemetry};

    /// SysTick clock (the core clock as each QEMU machine models it).
    const SYSTICK_HZ: u32 = match CORE {
        Core::M4F => 168_000_000,
        Core::M3 => 12_500_000,
        Core::M0 => 16_000_000,
    };
    /// What this core runs (see `mccs_firmware::demo`).
    const SPEC: DemoSpec = demo::spec_for(CORE);
    /// The controller's capacities: exactly the core's patch (N = 8 on the M4F, N = 5 on
    /// the M3, N = 4 on the M0, whose 16 KiB of RAM must also hold the start-up's stack).
    const NODES: usize = mccs::topology::standard_capacity(SPEC.grid).0;
    const EDGES: usize = mccs::topology::standard_capacity(SPEC.grid).1;
    /// The controller type: the palpation on a simulated probe, or (`--features arm`)
    /// through the simulated arm's joints.
    #[cfg(not(feature = "arm"))]
    type Ctl = demo::DemoControllerOf<NODES, EDGES>;
    #[cfg(feature = "arm")]
    type Ctl = demo::ArmDemoControllerOf<NODES, EDGES>;
    // The M0's 16 KiB of RAM do not hold the arm demo's samples of counts (3 KB) beside
    // its controller and its start-up's stack.
    const _: () = assert!(
        !(cfg!(feature = "arm") && matches!(CORE, Core::M0)),
        "the arm demo runs on the M4F and the M3, not the M0"
    );
    /// The start line's device.
    const DEVICE: &str = if cfg!(feature = "arm") {
        " on the arm (WoodenHaptics)"
    } else {
        ""
    };

    /// Log every this many ticks (every 0.1 s).
    const TRACE_EVERY: u32 = SPEC.tick_hz / 10;

    /// What the tick's first run built.
    #[derive(Clone, Copy)]
    struct Info {
        springs: usize,
        substeps: u32,
    }
    /// How the tick's first run went: not yet, the controller built, or why not.
    #[derive(Clone, Copy)]
    enum Start {
        Pending,
        Built(Info),
        Failed(demo::DemoError),
    }
    static START: Shared<Start> = Shared::new(Start::Pending);
    static SWAP: Mailbox<ParamSet<64>> = Mailbox::new();
    static TELEMETRY: Shared<Telemetry> = Shared::new(Telemetry::new());
    /// The arm's duties (`--features arm`): the last, the steady tick's, the largest.
    #[cfg(feature = "arm")]
    static DUTIES: Shared<([i32; 3], [i32; 3], i32)> = Shared::new(([0; 3], [0; 3], 0));
    /// The longest tick so far, SysTick counts.
    static WORST_TICK: Shared<u32> = Shared::new(0);
    /// SysTick counts per tick.
    const PERIOD: u32 = SYSTICK_HZ / SPEC.tick_hz;

    #[entry]
    fn main() -> ! {
        let Some(mut cp) = cortex_m::Peripherals::take() else {
            fail("peripherals taken twice")
        };
        // The free stack painted before the start-up's build and swap, read at the end
        // (`finish`).
        stack_paint::paint();
        // The tick owns the controller: its first run builds it (the counter is still
        // stopped, so nothing is timed yet), on the interrupt's stack.
        SCB::set_pendst();
        cortex_m::asm::isb();
        let info = match START.get() {
            Start::Built(info) => info,
            Start::Failed(e) => {
                defmt::error!("start-up failed: demo controller: {}", e);
                exit(false)
            }
            Start::Pending => fail("demo controller: the tick's first run did not start"),
        };
        let swap_substeps = post_swap();
        defmt::info!(
            "mccs haptic demo: core={=str}{=str} tick={=u32} Hz, N={=usize} window on a {=usize} x {=usize} tissue, {=usize} springs, {=u32} substeps per tick ({=u32} after the swap), budget {=u32} instructions per tick",
            SPEC.core,
            DEVICE,
            SPEC.tick_hz,
            SPEC.grid,
            demo::WINDOW.tissue_w,
            demo::WINDOW.tissue_h,
            info.springs,
            info.substeps,
            swap_substeps,
            SPEC.budget()
        );

        let syst = &mut cp.SYST;
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(PERIOD - 1);
        syst.clear_current();
        syst.enable_counter();
        syst.enable_interrupt();

        let mut next_trace = 0;
        loop {
            cortex_m::asm::wfi();
            let t = TELEMETRY.get();
            if t.ticks >= next_trace && t.ticks > 0 {
                next_trace = t.ticks + TRACE_EVERY;
                trace(&t);
            }
            if let Some(fault) = t.fault {
                defmt::error!("safe state: {}", defmt::Debug2Format(&fault));
            }
            if t.ticks >= SPEC.ticks() {
                syst.disable_interrupt();
                finish(&t);
            }
        }
    }

    /// The trace line of telemetry `t` (and, with the arm, its duties).
    fn trace(t: &Telemetry) {
        defmt::info!(
            "tick={=u32} force_n=({=f32}, {=f32}, {=f32}) window_shifts={=u32}",
            t.ticks,
            t.force[0].to_num::<f32>(),
            t.force[1].to_num::<f32>(),
            t.force[2].to_num::<f32>(),
            t.window_shifts
        );
        #[cfg(feature = "arm")]
        {
            let (d, ..) = DUTIES.get();
            defmt::info!(
                "tick={=u32} duty=({=f32}, {=f32}, {=f32})",
                t.ticks,
                q16(d[0]),
                q16(d[1]),
                q16(d[2])
            );
        }
    }

    /// The least stack the run may leave unused, bytes: below it the next frame to grow
    /// writes over the statics under the stack (without a fault: defmt's state is the
    /// first it reaches), so the run fails here instead.
    const MIN_FREE_STACK: u32 = 64;

    /// The run's last lines (the longest tick, the stack, the `SUMMARY`), then the exit:
    /// success unless telemetry `t` holds a fault or the stack came within
    /// [`MIN_FREE_STACK`] of the statics.
    fn finish(t: &Telemetry) -> ! {
        let (used, free) = stack_paint::used_and_free();
        defmt::info!(
            "STACK core={=str} used_bytes={=u32} free_bytes={=u32} min_free_bytes={=u32}",
            SPEC.core,
            used,
            free,
            MIN_FREE_STACK
        );
        if free < MIN_FREE_STACK {
            defmt::error!(
                "the stack came within {=u32} bytes of the statics (at least {=u32} must stay free)",
                free,
                MIN_FREE_STACK
            );
            exit(false)
        }
        // Counts → instructions under -icount: SYSTICK_HZ · 2^shift / 1e9 per one.
        let per_instruction = SYSTICK_HZ as f32 * (1u32 << SPEC.icount_shift) as f32 / 1e9;
        defmt::info!(
            "longest tick: {=u32} SysTick counts = {=f32} instructions under -icount shift={=u32} (budget {=u32})",
            WORST_TICK.get(),
            WORST_TICK.get() as f32 / per_instruction,
            SPEC.icount_shift,
            SPEC.budget()
        );
        #[cfg(not(feature = "arm"))]
        defmt::println!(
            "SUMMARY ticks={=u32} overruns={=u32} max_force_n={=f32} steady_force_n={=f32} window_shifts={=u32}",
            t.ticks,
            t.overruns,
            t.max_force.to_num::<f32>(),
            t.steady_force.to_num::<f32>(),
            t.window_shifts
        );
        #[cfg(feature = "arm")]
        {
            let (_, steady, max) = DUTIES.get();
            defmt::println!(
                "SUMMARY ticks={=u32} overruns={=u32} max_force_n={=f32} steady_force_n={=f32} window_shifts={=u32} steady_duty_a={=f32} steady_duty_b={=f32} steady_duty_c={=f32} max_duty={=f32}",
                t.ticks,
                t.overruns,
                t.max_force.to_num::<f32>(),
                t.steady_force.to_num::<f32>(),
                t.window_shifts,
                q16(steady[0]),
                q16(steady[1]),
                q16(steady[2]),
                q16(max)
            );
        }
        exit(t.fault.is_none());
    }

    #[exception]
    fn SysTick() {
        // The controller in `.bss` (a `Slot`: an `Option<Ctl>` static would be
        // initialised data, its image in flash as large as the controller).
        static mut CTL: Slot<Ctl> = Slot::new();
        let slot = CTL.option();
        let Some(ctl) = slot.as_mut() else {
            init(slot);
            return;
        };
        run_tick(ctl);
    }

    /// One tick, timed. Out of line: its frame (the swapped set's copy among it) is not
    /// under `init`'s on the first run (the M0's 16 KiB of RAM).
    #[inline(never)]
    fn run_tick(ctl: &mut Ctl) {
        let ticks = ctl.telemetry().ticks;
        if ticks >= SPEC.ticks() {
            return;
        }
        #[cfg(feature = "panic-test")]
        if ticks == 10 {
            panic!("injected by the panic-test feature");
        }
        let start = SYST::get_current();
        let pending_at_start = SCB::is_pendst_pending();
        let swap = if ticks >= SPEC.swap_tick() {
            SWAP.take()
        } else {
            None
        };
        ctl.tick(swap);
        // The tick's own length in SysTick counts. The counter runs down from PERIOD − 1
        // and reloads; it wrapped during the tick if it now reads higher, or if the next
        // tick became pending meanwhile. (A tick that started late — the main loop held
        // interrupts off — is not charged for that.) Longer than a period: an overrun. In
        // QEMU under -icount, counts are instructions (SPEC.budget() per period).
        let end = SYST::get_current();
        let wrapped = end > start || (SCB::is_pendst_pending() && !pending_at_start);
        let elapsed = start
            .wrapping_sub(end)
            .wrapping_add(if wrapped { PERIOD } else { 0 });
        if elapsed > PERIOD {
            ctl.note_overrun();
        }
        WORST_TICK.set(WORST_TICK.get().max(elapsed));
        TELEMETRY.set(ctl.telemetry());
        #[cfg(feature = "arm")]
        {
            let arm = ctl.device();
            DUTIES.set((arm.duties(), arm.steady_duties(), arm.max_duty()));
        }
    }

    /// A Q16 duty as a fraction of full scale (the host's `demo::ArmSummary` the same).
    #[cfg(feature = "arm")]
    fn q16(d: i32) -> f32 {
        d as f32 / 65_536.0
    }

    /// Builds the controller into the tick's slot. Out of line: its construction's stack
    /// space is free again before the ticks start (the M0 has 16 KiB of RAM).
    #[inline(never)]
    fn init(slot: &mut Option<Ctl>) {
        #[cfg(not(feature = "arm"))]
        let built = SPEC.controller_into(&demo::TABLE2, slot);
        #[cfg(feature = "arm")]
        let built = SPEC.arm_controller_into(&demo::TABLE2, slot);
        match built {
            Ok(()) => {
                if let Some(ctl) = slot {
                    START.set(Start::Built(Info {
                        springs: ctl.solver().topology().edges().len(),
                        substeps: ctl.solver().substeps(),
                    }));
                }
            }
            Err(e) => {
                *slot = None;
                START.set(Start::Failed(e));
            }
        }
    }

    /// Builds the second parameter set in the main loop's context (software floating
    /// point) and posts it for the tick, which switches to it between two ticks at
    /// `SPEC.swap_tick()`. Returns its substeps. Out of line, like `init`.
    #[inline(never)]
    fn post_swap() -> u32 {
        match SPEC.swapped_set::<NODES, EDGES, DefaultArith>() {
            Ok(set) => {
                let substeps = set.substeps();
                let _ = SWAP.post(set);
                substeps
            }
            Err(e) => {
                defmt::error!("start-up failed: swapped parameter set: {}", e);
                exit(false)
            }
        }
    }

    fn fail(what: &str) -> ! {
        defmt::error!("start-up failed: {=str}", what);
        exit(false)
    }
}
