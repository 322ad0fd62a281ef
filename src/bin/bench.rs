//! Instruction counts of the per-tick arithmetic, measured in QEMU under `-icount`:
//! SysTick runs free (no interrupt) at the machine's clock, and is calibrated against a
//! loop of known instruction count; each case is averaged over repeated calls of an
//! `#[inline(never)]` entry point (`mccs::entry`) with `black_box`ed inputs, less the cost
//! of an empty call. Prints `BENCH core=<m4f|m3|m0> case=<name> instructions=<n>`.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("bench is firmware: run it in QEMU (see README)");
    std::process::exit(2);
}

#[cfg(target_os = "none")]
mod fw_common;

#[cfg(target_os = "none")]
mod firmware {
    use super::fw_common;
    use core::hint::black_box;
    use cortex_m::peripheral::{syst::SystClkSource, SYST};
    use cortex_m_rt::entry;
    use fw_common::exit;
    use mccs::float_patch::{FloatPatch, Real};
    use mccs::spring::{Arith, Damping, DefaultArith};
    use mccs::{entry as e, Edge, ForceTable64, Length, Solver, SolverConfig, Strain, Topology};

    #[cfg(core = "m4f")]
    const CORE: &str = "m4f";
    #[cfg(core = "m3")]
    const CORE: &str = "m3";
    #[cfg(core = "m0")]
    const CORE: &str = "m0";

    static TABLE2: ForceTable64 = include!("../../tables/table2.rs");

    /// `n` iterations of a two-instruction loop.
    #[inline(never)]
    fn known_loop(n: u32) {
        unsafe {
            core::arch::asm!("2:", "subs {0}, #1", "bne 2b", inout(reg) n => _, options(nomem, nostack));
        }
    }

    fn now() -> u32 {
        SYST::get_current()
    }

    /// SysTick counts per 1024 instructions.
    fn calibrate() -> u32 {
        let t0 = now();
        known_loop(black_box(1000));
        let t1 = now();
        known_loop(black_box(11000));
        let t2 = now();
        let small = t0.wrapping_sub(t1) & 0xFF_FFFF;
        let large = t1.wrapping_sub(t2) & 0xFF_FFFF;
        // 20000 more instructions in the large run.
        ((large - small) as u64 * 1024 / 20000) as u32
    }

    /// Instructions of `reps` runs of `f`, per run.
    fn measure(cpk: u32, reps: u32, mut f: impl FnMut()) -> u32 {
        let t0 = now();
        for _ in 0..reps {
            f();
        }
        let t1 = now();
        let counts = t0.wrapping_sub(t1) & 0xFF_FFFF;
        ((counts as u64 * 1024 / cpk as u64) / reps as u64) as u32
    }

    #[entry]
    fn main() -> ! {
        let Some(mut cp) = cortex_m::Peripherals::take() else {
            exit(false)
        };
        cp.SYST.set_clock_source(SystClkSource::Core);
        cp.SYST.set_reload(0x00FF_FFFF);
        cp.SYST.clear_current();
        cp.SYST.enable_counter();
        while now() == 0 {}
        let cpk = calibrate();
        let mut figs = Figures(heapless::Vec::new());
        defmt::info!("calibration: {=u32} counts per 1024 instructions", cpk);
        let empty = measure(cpk, 64, || {
            black_box(0u32);
        });
        let table = black_box(TABLE2);
        // Strains sweeping [−0.25, 0.75): both straight lines and the cubic part. The
        // harness (the next strain, the black boxes) is measured alone and taken off.
        let mut k = 0i32;
        let harness = measure(cpk, 256, || {
            k = k.wrapping_add(65_713);
            let eps = Strain::from_bits((k & 0x00FF_FFFF) - 0x0040_0000);
            black_box((black_box(&table), eps));
        });
        let mut k = 0i32;
        let fs = measure(cpk, 256, || {
            k = k.wrapping_add(65_713);
            let eps = Strain::from_bits((k & 0x00FF_FFFF) - 0x0040_0000);
            black_box(e::force_and_stiffness(black_box(&table), eps));
        }) - (harness - empty);
        figs.report("force_and_stiffness", fs - empty);
        // One spring (`spring_case`) through `e::spring`, less the same call to
        // `no_spring` (the call, the arguments and the harness's black boxes).
        let mut r = DefaultArith::REST;
        let case = spring_case();
        let harness = measure(cpk, 256, || {
            let c = black_box(&case);
            black_box(no_spring(
                black_box(&table),
                &c.edge,
                &c.ends,
                &mut r,
                &c.damping,
            ));
        });
        let spring = measure(cpk, 256, || {
            let c = black_box(&case);
            black_box(e::spring(
                black_box(&table),
                &c.edge,
                &c.ends,
                &mut r,
                &c.damping,
            ));
        }) - (harness - empty);
        figs.report("spring", spring - empty);
        let probe = [Length::ZERO, Length::ZERO, Length::from_num(-0.5)];
        let sub3 = substep_case::<2, 9>(cpk, 3, &table, probe);
        figs.report("substep_n3", sub3 - empty);
        let sub4 = substep_case::<5, 30>(cpk, 4, &table, probe);
        figs.report("substep_n4", sub4 - empty);
        let sub5 = substep_case::<10, 61>(cpk, 5, &table, probe);
        figs.report("substep_n5", sub5 - empty);
        #[cfg(not(core = "m0"))]
        {
            let sub6 = substep_case::<17, 102>(cpk, 6, &table, probe);
            figs.report("substep_n6", sub6 - empty);
            let sub7 = substep_case::<26, 153>(cpk, 7, &table, probe);
            figs.report("substep_n7", sub7 - empty);
            let sub8 = substep_case::<37, 214>(cpk, 8, &table, probe);
            figs.report("substep_n8", sub8 - empty);
        }
        // The comparators: the same substep in f32 (the M4F's FPU, software elsewhere) and
        // in f64 (software everywhere).
        let f32_5 = float_case::<f32, 10, 61>(cpk, 5, &table);
        figs.report("substep_n5_f32", f32_5 - empty);
        let f64_5 = float_case::<f64, 10, 61>(cpk, 5, &table);
        figs.report("substep_n5_f64", f64_5 - empty);
        #[cfg(not(core = "m0"))]
        {
            let f32_8 = float_case::<f32, 37, 214>(cpk, 8, &table);
            figs.report("substep_n8_f32", f32_8 - empty);
            let f64_8 = float_case::<f64, 37, 214>(cpk, 8, &table);
            figs.report("substep_n8_f64", f64_8 - empty);
        }
        // One whole tick of this core's demo configuration, in contact.
        let tick = tick_case(cpk, &table, probe);
        figs.report("tick", tick - empty);
        let mem = [
            ("solver_n4", core::mem::size_of::<Solver<5, 30, 64>>()),
            ("solver_n5", core::mem::size_of::<Solver<10, 61, 64>>()),
            ("solver_n8", core::mem::size_of::<Solver<37, 214, 64>>()),
            ("table", core::mem::size_of::<ForceTable64>()),
        ];
        defmt::println!(
            "MEM core={=str} solver_n4={=usize} solver_n5={=usize} solver_n8={=usize} table={=usize}",
            CORE,
            mem[0].1,
            mem[1].1,
            mem[2].1,
            mem[3].1
        );
        for (case, bytes) in mem {
            figs.record(case, bytes as u32);
        }
        fits(&figs, &table);
        let ok = check_budgets(&figs);
        exit(ok)
    }

    /// Clock (MHz) and cycles per instruction assumed to turn instruction counts into time:
    /// an STM32F405 at 168 MHz (flash behind the ART accelerator), an LM3S6965 at 50 MHz,
    /// an STM32F0-class M0 at 48 MHz (one flash wait state). Estimates, not measurements.
    #[cfg(core = "m4f")]
    const CLOCK: (u32, u32) = (168, 125);
    #[cfg(core = "m3")]
    const CLOCK: (u32, u32) = (50, 125);
    #[cfg(core = "m0")]
    const CLOCK: (u32, u32) = (48, 150);

    /// The spring case's inputs (raw formats of `mccs::spring`).
    struct SpringCase {
        edge: Edge,
        ends: e::SpringEnds,
        damping: Damping,
    }

    /// A 4 mm spring along −z compressed by 2 mm (strain 0.5: the table's cubic part, the
    /// longest path), its ends moving, 1 N·s/m of damping.
    fn spring_case() -> SpringCase {
        SpringCase {
            edge: Edge {
                a: 1,
                b: 2,
                dir: [0, 0, -(1 << 29)],
                inv_len: 1 << 29,
            },
            ends: e::SpringEnds {
                ua: [0; 3],
                ub: [1 << 20, -(1 << 20), 2 << 24],
                va: [10, -20, 30],
                vb: [0; 3],
            },
            damping: Damping::new(1.0),
        }
    }

    /// [`e::spring`]'s signature, and nothing but taking its arguments into registers
    /// (empty `asm!`) and returning zeros: the spring case's harness.
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    fn no_spring(
        table: &ForceTable64,
        edge: &Edge,
        ends: &e::SpringEnds,
        warm: &mut i32,
        damping: &Damping,
    ) -> [i32; 3] {
        // SAFETY: the template is a comment: nothing is read or written.
        unsafe {
            core::arch::asm!(
                "/* {0} {1} {2} {3} {4} */",
                in(reg) table,
                in(reg) edge,
                in(reg) ends,
                in(reg) warm,
                in(reg) damping,
                options(nostack, preserves_flags)
            );
        }
        [0; 3]
    }

    /// The figures measured in this run, by case name (20 at most; a full list only
    /// drops the budget check's view of the rest, which then reports them missing).
    struct Figures(heapless::Vec<(&'static str, u32), 32>);

    impl Figures {
        fn record(&mut self, case: &'static str, value: u32) {
            let _ = self.0.push((case, value));
        }

        fn get(&self, case: &str) -> Option<u32> {
            self.0.iter().find(|(c, _)| *c == case).map(|(_, v)| *v)
        }

        /// Records and prints one instruction count.
        fn report(&mut self, case: &'static str, instructions: u32) {
            self.record(case, instructions);
            defmt::println!(
                "BENCH core={=str} case={=str} instructions={=u32}",
                CORE,
                case,
                instructions
            );
        }
    }

    /// The largest standard patch whose ticks (substeps × one substep, default
    /// configuration) fit in half a tick at 1 kHz and at 10 kHz, at `CLOCK`.
    fn fits(figs: &Figures, table: &ForceTable64) {
        for tick_hz in [1_000u32, 10_000] {
            let half_tick =
                (CLOCK.0 as u64 * 1_000_000 * 100 / CLOCK.1 as u64 / (2 * tick_hz as u64)) as u32;
            let cfg = SolverConfig {
                tick_hz: tick_hz as f64,
                ..SolverConfig::default()
            };
            let mut best = (0u32, 0u32, 0u32);
            for n in 3..=8u32 {
                let (Some(substeps), Some(sub)) = (
                    substeps_for(n, table, &cfg),
                    figs.get(SUBSTEP[n as usize - 3]),
                ) else {
                    continue;
                };
                let tick = substeps.saturating_mul(sub);
                if tick <= half_tick {
                    best = (n, substeps, tick);
                }
            }
            if best.0 == 0 {
                defmt::println!(
                    "FIT core={=str} tick_hz={=u32} mhz={=u32} cpi={=u32}/100 half_tick_instructions={=u32} largest_n=none",
                    CORE, tick_hz, CLOCK.0, CLOCK.1, half_tick
                );
            } else {
                defmt::println!(
                    "FIT core={=str} tick_hz={=u32} mhz={=u32} cpi={=u32}/100 half_tick_instructions={=u32} largest_n={=u32} substeps={=u32} tick_instructions={=u32}",
                    CORE, tick_hz, CLOCK.0, CLOCK.1, half_tick, best.0, best.1, best.2
                );
            }
        }
    }

    const SUBSTEP: [&str; 6] = [
        "substep_n3",
        "substep_n4",
        "substep_n5",
        "substep_n6",
        "substep_n7",
        "substep_n8",
    ];

    /// Substeps per tick the stability bound asks for on the standard N × N patch.
    fn substeps_for(n: u32, table: &ForceTable64, cfg: &SolverConfig) -> Option<u32> {
        fn of<const N: usize, const E: usize>(
            n: u32,
            table: &ForceTable64,
            cfg: &SolverConfig,
        ) -> Option<u32> {
            let topo = Topology::<N, E>::standard_patch(n as usize, 2.5).ok()?;
            Solver::<N, E, 64>::substeps_for(&topo, table, cfg).ok()
        }
        match n {
            3 => of::<2, 9>(n, table, cfg),
            4 => of::<5, 30>(n, table, cfg),
            5 => of::<10, 61>(n, table, cfg),
            // Not on the M0: its 16 KiB hold neither these patches nor their figures.
            #[cfg(not(core = "m0"))]
            6 => of::<17, 102>(n, table, cfg),
            #[cfg(not(core = "m0"))]
            7 => of::<26, 153>(n, table, cfg),
            #[cfg(not(core = "m0"))]
            8 => of::<37, 214>(n, table, cfg),
            _ => None,
        }
    }

    const BUDGETS: &str = include_str!("../../bench/budgets.txt");

    fn field<'a>(line: &'a str, key: &str) -> Option<&'a str> {
        line.split_whitespace()
            .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('='))
    }

    /// Checks this core's lines of bench/budgets.txt against the figures; prints one line
    /// each. False when an enforced budget is breached or its figure is missing.
    fn check_budgets(figs: &Figures) -> bool {
        let mut ok = true;
        // The `budget-test` feature adds a budget no code can meet, to show that a breach
        // fails the run.
        #[cfg(feature = "budget-test")]
        let extra = "BUDGET core=m4f case=force_and_stiffness max=1 status=enforced\nBUDGET core=m3 case=force_and_stiffness max=1 status=enforced\nBUDGET core=m0 case=force_and_stiffness max=1 status=enforced";
        #[cfg(not(feature = "budget-test"))]
        let extra = "";
        for line in BUDGETS.lines().chain(extra.lines()) {
            let kind = line.split_whitespace().next().unwrap_or("");
            if !matches!(kind, "BUDGET" | "RATIO" | "MEMORY") || field(line, "core") != Some(CORE) {
                continue;
            }
            let enforced = field(line, "status") == Some("enforced");
            let (case, value, limit, within) = if kind == "RATIO" {
                let (Some(num), Some(den)) = (field(line, "num"), field(line, "den")) else {
                    defmt::println!("BUDGET core={=str} malformed line: {=str}", CORE, line);
                    ok = false;
                    continue;
                };
                let min = field(line, "min")
                    .and_then(|m| m.parse::<u32>().ok())
                    .unwrap_or(u32::MAX);
                // Tenths of the ratio.
                let tenths = match (figs.get(num), figs.get(den)) {
                    (Some(a), Some(b)) if b > 0 => Some((a as u64 * 10 / b as u64) as u32),
                    _ => None,
                };
                (
                    num,
                    tenths,
                    min.saturating_mul(10),
                    tenths.map(|t| t >= min.saturating_mul(10)),
                )
            } else {
                let Some(case) = field(line, "case") else {
                    defmt::println!("BUDGET core={=str} malformed line: {=str}", CORE, line);
                    ok = false;
                    continue;
                };
                let max = field(line, "max")
                    .and_then(|m| m.parse::<u32>().ok())
                    .unwrap_or(0);
                let value = figs.get(case);
                (case, value, max, value.map(|v| v <= max))
            };
            let result = match (within, enforced) {
                (Some(true), true) => "ok",
                (Some(false), true) => "OVER",
                (Some(true), false) => "open-met",
                (Some(false), false) => "open",
                (None, _) => "missing",
            };
            if enforced && within != Some(true) {
                ok = false;
            }
            defmt::println!(
                "{=str} core={=str} case={=str} value={=u32} limit={=u32} result={=str}",
                kind,
                CORE,
                case,
                value.unwrap_or(0),
                limit,
                result
            );
        }
        ok
    }

    /// One substep of the standard N × N patch (2.5 mm, default configuration), after
    /// 200 ticks pressed in, averaged over 16.
    #[inline(never)]
    fn substep_case<const N: usize, const E: usize>(
        cpk: u32,
        n: usize,
        table: &ForceTable64,
        probe: [Length; 3],
    ) -> u32 {
        let Ok(topo) = Topology::<N, E>::standard_patch(n, 2.5) else {
            exit(false)
        };
        let Ok(mut s) = Solver::new(topo, *table, &SolverConfig::default()) else {
            exit(false)
        };
        for _ in 0..200 {
            e::tick(&mut s, probe);
        }
        measure(cpk, 16, || e::substep(&mut s, black_box(probe)))
    }

    /// One floating-point substep of the standard N × N patch, after 200 substeps pressed
    /// in, averaged over 4.
    #[inline(never)]
    fn float_case<T: Real, const N: usize, const E: usize>(
        cpk: u32,
        n: usize,
        table: &ForceTable64,
    ) -> u32 {
        let Ok(topo) = Topology::<N, E>::standard_patch(n, 2.5) else {
            exit(false)
        };
        let cfg = SolverConfig::default();
        let Ok(substeps) = Solver::<N, E, 64>::substeps_for(&topo, table, &cfg) else {
            exit(false)
        };
        let mut p = FloatPatch::<T, N, E, 64>::new(&topo, table, &cfg, substeps);
        let probe = [T::ZERO, T::ZERO, T::of(-0.5)];
        for _ in 0..200 {
            float_substep(&mut p, probe);
        }
        measure(cpk, 4, || float_substep(&mut p, black_box(probe)))
    }

    #[inline(never)]
    fn float_substep<T: Real, const N: usize, const E: usize>(
        p: &mut FloatPatch<T, N, E, 64>,
        probe: [T; 3],
    ) {
        p.substep(probe)
    }

    /// One tick of this core's demo configuration, pressed in, averaged over 4.
    #[inline(never)]
    fn tick_case(cpk: u32, table: &ForceTable64, probe: [Length; 3]) -> u32 {
        #[cfg(core = "m4f")]
        let (spec, topo) = (mccs::demo::M4F, Topology::<10, 61>::standard_patch(5, 2.5));
        #[cfg(core = "m3")]
        let (spec, topo) = (mccs::demo::M3, Topology::<10, 61>::standard_patch(4, 2.5));
        #[cfg(core = "m0")]
        let (spec, topo) = (mccs::demo::M0, Topology::<10, 61>::standard_patch(4, 2.5));
        let Ok(topo) = topo else { exit(false) };
        let Ok(mut s) = Solver::new(topo, *table, &spec.config()) else {
            exit(false)
        };
        for _ in 0..200 {
            e::tick(&mut s, probe);
        }
        measure(cpk, 4, || {
            black_box(e::tick(&mut s, black_box(probe)));
        })
    }
}
