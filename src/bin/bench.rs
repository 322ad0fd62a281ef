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
    use mccs::{entry as e, ForceTable64, Length, Solver, SolverConfig, Strain, Topology};

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
        defmt::println!(
            "BENCH core={=str} case=force_and_stiffness instructions={=u32}",
            CORE,
            fs - empty
        );
        // A 4 mm spring along −z compressed by 2 mm (strain 0.5: the table's cubic part,
        // the longest path), its ends moving, 1 N·s/m of damping.
        let mut r = 1 << 24;
        let harness = measure(cpk, 256, || {
            black_box((
                black_box(&table),
                black_box([0, 0, -(1 << 29)]),
                black_box(1 << 29),
                black_box([0; 3]),
                black_box([1 << 20, -(1 << 20), 2 << 24]),
                black_box([10, -20, 30]),
                black_box([0; 3]),
                &mut r,
                black_box(68_719_477),
            ));
        });
        let spring = measure(cpk, 256, || {
            black_box(e::spring(
                black_box(&table),
                black_box([0, 0, -(1 << 29)]),
                black_box(1 << 29),
                black_box([0; 3]),
                black_box([1 << 20, -(1 << 20), 2 << 24]),
                black_box([10, -20, 30]),
                black_box([0; 3]),
                &mut r,
                black_box(68_719_477),
            ));
        }) - (harness - empty);
        defmt::println!(
            "BENCH core={=str} case=spring instructions={=u32}",
            CORE,
            spring - empty
        );
        let probe = [Length::ZERO, Length::ZERO, Length::from_num(-0.5)];
        let sub3 = substep_case::<2, 9>(cpk, 3, &table, probe);
        report("substep_n3", sub3 - empty);
        let sub4 = substep_case::<5, 30>(cpk, 4, &table, probe);
        report("substep_n4", sub4 - empty);
        let sub5 = substep_case::<10, 61>(cpk, 5, &table, probe);
        report("substep_n5", sub5 - empty);
        #[cfg(not(core = "m0"))]
        {
            let sub8 = substep_case::<37, 214>(cpk, 8, &table, probe);
            report("substep_n8", sub8 - empty);
        }
        // The comparators: the same substep in f32 (the M4F's FPU, software elsewhere) and
        // in f64 (software everywhere).
        let f32_5 = float_case::<f32, 10, 61>(cpk, 5, &table);
        report("substep_n5_f32", f32_5 - empty);
        let f64_5 = float_case::<f64, 10, 61>(cpk, 5, &table);
        report("substep_n5_f64", f64_5 - empty);
        #[cfg(not(core = "m0"))]
        {
            let f32_8 = float_case::<f32, 37, 214>(cpk, 8, &table);
            report("substep_n8_f32", f32_8 - empty);
            let f64_8 = float_case::<f64, 37, 214>(cpk, 8, &table);
            report("substep_n8_f64", f64_8 - empty);
        }
        // One whole tick of this core's demo configuration, in contact.
        let tick = tick_case(cpk, &table, probe);
        report("tick", tick - empty);
        defmt::println!(
            "MEM core={=str} solver_n4={=usize} solver_n5={=usize} solver_n8={=usize} table={=usize}",
            CORE,
            core::mem::size_of::<Solver<5, 30, 64>>(),
            core::mem::size_of::<Solver<10, 61, 64>>(),
            core::mem::size_of::<Solver<37, 214, 64>>(),
            core::mem::size_of::<ForceTable64>()
        );
        exit(true)
    }

    fn report(case: &str, instructions: u32) {
        defmt::println!(
            "BENCH core={=str} case={=str} instructions={=u32}",
            CORE,
            case,
            instructions
        );
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
