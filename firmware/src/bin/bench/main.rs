//! Instruction counts of the per-tick arithmetic, measured in QEMU under `-icount`:
//! SysTick runs free (no interrupt) at the machine's clock, and is calibrated against a
//! loop of known instruction count ([`harness`]); each case ([`cases`]) is averaged over
//! repeated calls of an `#[inline(never)]` entry point (`mccs_firmware::entry`) with
//! `black_box`ed inputs, less the cost of an empty call. Prints
//! `BENCH core=<m4f|m3|m0> case=<name> instructions=<n>`, then checks this core's budgets
//! ([`report`], `bench/budgets.txt`) and exits with failure on a breach.
#![cfg_attr(target_os = "none", no_std)]
#![cfg_attr(target_os = "none", no_main)]

#[cfg(not(target_os = "none"))]
fn main() {
    eprintln!("bench is firmware: run it in QEMU (scripts/bench.sh; see docs/performance.md)");
    std::process::exit(2);
}

#[cfg(target_os = "none")]
#[path = "../fw_common.rs"]
mod fw_common;

#[cfg(target_os = "none")]
mod arm;
#[cfg(target_os = "none")]
mod cases;
#[cfg(target_os = "none")]
mod harness;
#[cfg(target_os = "none")]
mod hold_check;
#[cfg(target_os = "none")]
mod kernel_check;
#[cfg(target_os = "none")]
mod report;
#[cfg(target_os = "none")]
mod rng;
#[cfg(target_os = "none")]
mod ticks;

#[cfg(target_os = "none")]
mod firmware {
    use super::fw_common::exit;
    use super::harness::Harness;
    use super::report::{
        check_budgets, fits, largest_patch, substep_case, Figures, Steps, SPRING_PATH_SPREAD,
    };
    use super::{arm, cases, harness, hold_check, kernel_check, report, ticks};
    use cases::TablePath;
    use core::hint::black_box;
    use cortex_m_rt::entry;
    use mccs::{ForceTable64, Integrator, Length, Solver};
    use mccs_firmware::target::{Core, CORE};

    static TABLE2: ForceTable64 = include!("../../../../tables/table2.rs");

    #[entry]
    fn main() -> ! {
        let Some(cp) = cortex_m::Peripherals::take() else {
            exit(false)
        };
        let h = harness::start(cp.SYST);
        let mut figs = Figures::new();
        defmt::info!("calibration: {=u32} counts per 1024 instructions", h.cpk);
        let empty = h.measure(64, || {
            black_box(0u32);
        });
        let table: &ForceTable64 = black_box(&TABLE2);
        // The assembly against the Rust it replaces, before any figure: the M4F's spring
        // loop and integrator, the M0's holds.
        kernel_check::check(table);
        hold_check::check();
        // These two take off their own harness (the empty call included).
        figs.report("force_and_stiffness", cases::force_and_stiffness(&h, table));
        static STIFF_SERIES: ForceTable64 = include!("../../../../tables/stiff_series.rs");
        figs.report(
            "force_and_stiffness_corner",
            cases::force_and_stiffness_corner(&h, black_box(&STIFF_SERIES)),
        );
        static STEEP_KINK: ForceTable64 = include!("../../../../tables/steep_kink.rs");
        figs.report(
            "force_and_stiffness_lower_corner",
            cases::force_and_stiffness_corner(&h, black_box(&STEEP_KINK)),
        );
        figs.report("spring", cases::spring(&h, table));
        let probe = [Length::ZERO, Length::ZERO, Length::from_num(-0.5)];
        let sub = |h: &Harness, n, i| match n {
            3 => cases::substep::<2, 9>(h, 3, table, probe, i),
            4 => cases::substep::<5, 30>(h, 4, table, probe, i),
            5 => cases::substep::<10, 61>(h, 5, table, probe, i),
            6 => cases::substep::<17, 102>(h, 6, table, probe, i),
            7 => cases::substep::<26, 153>(h, 7, table, probe, i),
            _ => cases::substep::<37, 214>(h, 8, table, probe, i),
        };
        // Not on the M0 above N = 5: its 16 KiB hold neither these patches nor their
        // figures. Each integrator's substep (the symplectic option's names end in
        // `_symplectic`).
        let largest = if CORE == Core::M0 { 5 } else { 8 };
        for integrator in [Integrator::ImprovedEuler, Integrator::SymplecticDamped] {
            for n in 3..=largest {
                let name = substep_case(n, integrator).unwrap_or("substep");
                figs.report(name, sub(&h, n, integrator) - empty);
            }
        }
        // One spring where the solver runs it: the spring loop over a pressed patch, per
        // spring.
        figs.report(
            "spring_in_loop_n5",
            cases::spring_in_loop::<10, 61>(&h, 5, table, probe, empty),
        );
        // One spring on each path of its arithmetic, in the loop (`cases::spring_path`):
        // the most it took over strains across the path (the corner's as fractions of it);
        // the spread is the most of all less the least of all.
        let within = |t: &ForceTable64, x: f64| {
            t.corner().map_or(0.5, |(a, b)| {
                let (a, b) = (a.to_num::<f64>(), b.to_num::<f64>());
                a + (b - a) * x
            })
        };
        let corner = |x: f64| within(&STIFF_SERIES, x);
        let lower_corner = |x: f64| within(&STEEP_KINK, x);
        let (mut fastest, mut slowest) = (u32::MAX, 0);
        for (name, t, strains, on) in [
            (
                "spring_path_uniform",
                table,
                [0.25, 0.4, 0.55, 0.7, 0.85],
                TablePath::Uniform,
            ),
            (
                "spring_path_below",
                table,
                [-0.7, -0.3, 0.0, 0.1, 0.2],
                TablePath::Below,
            ),
            (
                "spring_path_above",
                table,
                [0.96, 0.965, 0.97, 0.975, 0.98],
                TablePath::Above,
            ),
            (
                "spring_path_corner",
                &STIFF_SERIES,
                [0.1, 0.3, 0.5, 0.7, 0.9].map(corner),
                TablePath::Corner,
            ),
            (
                "spring_path_lower_corner",
                &STEEP_KINK,
                [0.1, 0.3, 0.5, 0.7, 0.9].map(lower_corner),
                TablePath::Corner,
            ),
            (
                "spring_path_stretched",
                table,
                [-1.1, -1.5, -2.0, -3.0, -5.0],
                TablePath::Below,
            ),
            (
                "spring_path_crushed",
                table,
                [0.985, 0.99, 0.993, 0.995, 0.998],
                TablePath::Above,
            ),
        ] {
            let mut path = 0;
            for strain in strains {
                let cost = cases::spring_path(&h, t, strain, on, empty);
                (fastest, slowest) = (fastest.min(cost), slowest.max(cost));
                path = path.max(cost);
            }
            figs.report(name, path);
        }
        figs.report(SPRING_PATH_SPREAD, slowest.saturating_sub(fastest));
        if CORE != Core::M0 {
            figs.report(
                "spring_in_loop_n8",
                cases::spring_in_loop::<37, 214>(&h, 8, table, probe, empty),
            );
        }
        let steps = Steps::new(table, Integrator::ImprovedEuler);
        let steps_symplectic = Steps::new(table, Integrator::SymplecticDamped);
        let sub5 = steps.substeps(5, 1000).unwrap_or(1);
        let sub8 = steps.substeps(8, 1000).unwrap_or(1);
        // The comparators: the same substep in f32 (the M4F's FPU, software elsewhere) and
        // in f64 (software everywhere).
        figs.report(
            "substep_n5_f32",
            cases::float::<f32, 10, 61>(&h, 5, sub5, table) - empty,
        );
        figs.report(
            "substep_n5_f64",
            cases::float::<f64, 10, 61>(&h, 5, sub5, table) - empty,
        );
        if CORE != Core::M0 {
            figs.report(
                "substep_n8_f32",
                cases::float::<f32, 37, 214>(&h, 8, sub8, table) - empty,
            );
            figs.report(
                "substep_n8_f64",
                cases::float::<f64, 37, 214>(&h, 8, sub8, table) - empty,
            );
        }
        // One whole tick of this core's demo configuration, in contact.
        figs.report("tick", ticks::tick(&h, table, probe) - empty);
        // One tick of the demo's patch through a sliding proxy (issue #19).
        figs.report("tick_proxy", ticks::tick_proxy(&h, table) - empty);
        // What the host link adds to a tick (the board's TIM2).
        figs.report("tick_link", ticks::tick_link(&h, table));
        // The arm's counts to duties without the solver, fixed point and its f32 peer.
        figs.report("arm_kinematics", arm::arm_kinematics(&h) - empty);
        figs.report("arm_kinematics_f32", arm::arm_kinematics_f32(&h) - empty);
        // The passivity observer's tick (the arm board's).
        figs.report("passivity_observer", arm::passivity_observer(&h) - empty);
        // The solver's start-up for the demo's patch, once (millions of instructions).
        let grid = mccs_firmware::demo::spec_for(CORE).grid as u32;
        report::startup(&mut figs, grid, ticks::startup(&h, table));
        // A new tissue's check on the device, the host's substeps proposed (the link's).
        report::tissue_check(&mut figs, grid, ticks::tissue_check(&h, table));
        // The demo's roaming: the longest tick without and with a window shift, and a
        // shift's own cost (the most a shift tick took over the tick before).
        let roam = ticks::roaming(&h, table, empty);
        figs.report("tick_roaming", roam.steady);
        figs.report("tick_roaming_shift", roam.shift);
        figs.report("window_shift", roam.shift_extra);
        // The longest shift-free tick plus the largest shift: a bound on a shift falling on
        // the most expensive tick, which the slide need not meet.
        figs.report(
            "tick_roaming_bound",
            roam.steady.saturating_add(roam.shift_extra),
        );
        // The same over a spherical cap (R = 150 mm): the contact along its normals, and
        // a shift that also computes the entering rest heights and springs.
        let cap = ticks::roaming_cap(&h, table, empty);
        figs.report("tick_roaming_cap", cap.steady);
        figs.report("tick_roaming_cap_shift", cap.shift);
        figs.report("window_shift_cap", cap.shift_extra);
        figs.report(
            "tick_roaming_cap_bound",
            cap.steady.saturating_add(cap.shift_extra),
        );
        // Issue #19's M4F configuration, N = 5, over the cap (the M4F's demo runs N = 8).
        if CORE == Core::M4F {
            let cap5 = ticks::roaming_cap_n5(&h, table, empty);
            figs.report("tick_roaming_cap_n5", cap5.steady);
            figs.report("window_shift_cap_n5", cap5.shift_extra);
            figs.report(
                "tick_roaming_cap_n5_bound",
                cap5.steady.saturating_add(cap5.shift_extra),
            );
        }
        let mem = [
            ("solver_n4", core::mem::size_of::<Solver<5, 30, 64>>()),
            ("solver_n5", core::mem::size_of::<Solver<10, 61, 64>>()),
            ("solver_n8", core::mem::size_of::<Solver<37, 214, 64>>()),
            ("table", core::mem::size_of::<ForceTable64>()),
        ];
        defmt::println!(
            "MEM core={=str} solver_n4={=usize} solver_n5={=usize} solver_n8={=usize} table={=usize}",
            CORE.name(),
            mem[0].1,
            mem[1].1,
            mem[2].1,
            mem[3].1
        );
        // A window: its four shift maps, and (used on a cap) its rest heights and the
        // springs' packed ends.
        defmt::println!(
            "MEM core={=str} window_n4={=usize} window_n8={=usize}",
            CORE.name(),
            core::mem::size_of::<mccs::Window<30>>(),
            core::mem::size_of::<mccs::Window<214>>()
        );
        for (case, bytes) in mem {
            figs.record(case, bytes as u32);
        }
        fits(&figs, &steps);
        largest_patch(&figs, &steps);
        largest_patch(&figs, &steps_symplectic);
        let ok = check_budgets(&figs);
        exit(ok)
    }
}
