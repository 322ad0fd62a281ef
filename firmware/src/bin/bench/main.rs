//! Instruction counts of the per-tick arithmetic, measured in QEMU under `-icount`:
//! SysTick runs free (no interrupt) at the machine's clock, and is calibrated against a
//! loop of known instruction count (`harness`); each case (`cases`) is averaged over
//! repeated calls of an `#[inline(never)]` entry point (`mccs_firmware::entry`) with
//! `black_box`ed inputs, less the cost of an empty call. Prints
//! `BENCH core=<m4f|m3|m0> case=<name> instructions=<n>`, then checks this core's budgets
//! (`report`, `bench/budgets.txt`) and exits with failure on a breach.
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
mod arm_check;
#[cfg(target_os = "none")]
mod cases;
#[cfg(target_os = "none")]
mod harness;
#[cfg(target_os = "none")]
mod hold_check;
#[cfg(target_os = "none")]
mod kernel_check;
#[cfg(target_os = "none")]
mod peer_patch;
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
        budget_test_requested, budgets, check_budgets, fits, largest_patch, substep_case, Figures,
        Steps, SPRING_PATH_SPREAD,
    };
    use super::{
        arm, arm_check, cases, harness, hold_check, kernel_check, peer_patch, report, ticks,
    };
    use cases::TablePath;
    use core::hint::black_box;
    use cortex_m_rt::entry;
    use mccs::{ForceTable64, Integrator, Length, Solver};
    use mccs_firmware::target::{Core, CORE};

    static TABLE2: ForceTable64 = include!("../../../../tables/table2.rs");
    static STIFF_SERIES: ForceTable64 = include!("../../../../tables/stiff_series.rs");
    static STEEP_KINK: ForceTable64 = include!("../../../../tables/steep_kink.rs");

    /// The probe the patch cases press with.
    const PROBE: [Length; 3] = [Length::ZERO, Length::ZERO, Length::from_bits(-(1 << 23))];

    /// What every group of cases is given: the harness, the figures, Table 2's table,
    /// the cost of an empty call.
    struct Bench<'a> {
        h: Harness,
        figs: Figures,
        table: &'a ForceTable64,
        empty: u32,
    }

    #[entry]
    fn main() -> ! {
        let Some(cp) = cortex_m::Peripherals::take() else {
            exit(false)
        };
        let h = harness::start(cp.SYST);
        defmt::info!("calibration: {=u32} counts per 1024 instructions", h.cpk);
        let empty = h.measure(64, || {
            black_box(0u32);
        });
        let table: &ForceTable64 = black_box(&TABLE2);
        // The assembly against the Rust it replaces, before any figure: the M4F's spring
        // loop, integrator and arm pose, the M0's holds.
        kernel_check::check(table);
        arm_check::check();
        hold_check::check();
        budget_breach_if_asked(&h, table);
        let mut b = Bench {
            h,
            figs: Figures::new(),
            table,
            empty,
        };
        b.springs();
        b.substeps();
        b.spring_paths();
        let steps = Steps::new(table, Integrator::ImprovedEuler);
        b.peers(&steps);
        b.ticks();
        b.roaming();
        b.memory();
        fits(&b.figs, &steps);
        largest_patch(&b.figs, &steps);
        // The f32 and f64 peers' largest patches beside it, on the same substeps.
        peer_patch::largest_patches(&b.h, &steps, table, empty);
        largest_patch(&b.figs, &Steps::new(table, Integrator::SymplecticDamped));
        let ok = check_budgets(&b.figs, budgets(false));
        exit(ok)
    }

    /// The breach's test (scripts/test.sh, `budget-breach-fails`), when the command line
    /// asks for it: one case, held to a budget it cannot meet, and the run ends. Apart
    /// from `main`, whose frame the M0's stack has no room to grow.
    #[inline(never)]
    fn budget_breach_if_asked(h: &Harness, table: &ForceTable64) {
        if budget_test_requested() {
            let mut figs = Figures::new();
            figs.report("force_and_stiffness", cases::force_and_stiffness(h, table));
            exit(check_budgets(&figs, budgets(true)))
        }
    }

    impl Bench<'_> {
        /// One spring's force and stiffness (Table 2 and the graded tables' corners), and
        /// the whole spring update.
        fn springs(&mut self) {
            let (h, table) = (&self.h, self.table);
            // These two take off their own harness (the empty call included).
            let f = &mut self.figs;
            f.report("force_and_stiffness", cases::force_and_stiffness(h, table));
            let stiff = black_box(&STIFF_SERIES);
            f.report(
                "force_and_stiffness_corner",
                cases::force_and_stiffness_corner(h, stiff),
            );
            let steep = black_box(&STEEP_KINK);
            f.report(
                "force_and_stiffness_lower_corner",
                cases::force_and_stiffness_corner(h, steep),
            );
            f.report("spring", cases::spring(h, table));
        }

        /// One substep of each patch, each integrator (the symplectic option's names end
        /// in `_symplectic`), and one spring where the solver runs it, per spring. Not
        /// on the M0 above N = 5: its 16 KiB hold neither these patches nor their figures;
        /// N = 9 and 10 (the board's) on the M4F alone, whose flash holds their cases.
        fn substeps(&mut self) {
            let (h, table, empty) = (&self.h, self.table, self.empty);
            let sub = |n, i| match n {
                3 => cases::substep::<2, 9>(h, 3, table, PROBE, i),
                4 => cases::substep::<5, 30>(h, 4, table, PROBE, i),
                5 => cases::substep::<10, 61>(h, 5, table, PROBE, i),
                6 => cases::substep::<17, 102>(h, 6, table, PROBE, i),
                7 => cases::substep::<26, 153>(h, 7, table, PROBE, i),
                // (Guarded by the core, a constant, so that the M3's flash is not given
                // cases it never runs.)
                9 if CORE == Core::M4F => cases::substep::<50, 285>(h, 9, table, PROBE, i),
                10 if CORE == Core::M4F => cases::substep::<65, 366>(h, 10, table, PROBE, i),
                _ => cases::substep::<37, 214>(h, 8, table, PROBE, i),
            };
            let largest = match CORE {
                Core::M0 => 5,
                Core::M3 => 8,
                Core::M4F => 10,
            };
            for integrator in [Integrator::ImprovedEuler, Integrator::SymplecticDamped] {
                for n in 3..=largest {
                    let name = substep_case(n, integrator).unwrap_or("substep");
                    self.figs.report(name, sub(n, integrator) - empty);
                }
            }
            let in_loop = cases::spring_in_loop::<10, 61>(h, 5, table, PROBE, empty);
            self.figs.report("spring_in_loop_n5", in_loop);
            if CORE != Core::M0 {
                let in_loop = cases::spring_in_loop::<37, 214>(h, 8, table, PROBE, empty);
                self.figs.report("spring_in_loop_n8", in_loop);
            }
        }

        /// One spring on each path of its arithmetic, in the loop (`cases::spring_path`):
        /// the most it took over strains across the path (the corner's as fractions of
        /// it); the spread is the most of all less the least of all.
        fn spring_paths(&mut self) {
            let (h, table, empty) = (&self.h, self.table, self.empty);
            let within = |t: &ForceTable64, x: f64| {
                t.corner().map_or(0.5, |(a, b)| {
                    let (a, b) = (a.to_num::<f64>(), b.to_num::<f64>());
                    a + (b - a) * x
                })
            };
            let fractions = [0.1, 0.3, 0.5, 0.7, 0.9];
            let paths: [(&'static str, &ForceTable64, [f64; 5], TablePath); 7] = [
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
                    fractions.map(|x| within(&STIFF_SERIES, x)),
                    TablePath::Corner,
                ),
                (
                    "spring_path_lower_corner",
                    &STEEP_KINK,
                    fractions.map(|x| within(&STEEP_KINK, x)),
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
            ];
            let (mut fastest, mut slowest) = (u32::MAX, 0);
            for (name, t, strains, on) in paths {
                let mut path = 0;
                for strain in strains {
                    let cost = cases::spring_path(h, t, strain, on, empty);
                    (fastest, slowest) = (fastest.min(cost), slowest.max(cost));
                    path = path.max(cost);
                }
                self.figs.report(name, path);
            }
            self.figs
                .report(SPRING_PATH_SPREAD, slowest.saturating_sub(fastest));
        }

        /// The comparators: the same substep in f32 (the M4F's FPU, software elsewhere)
        /// and in f64 (software everywhere).
        fn peers(&mut self, steps: &Steps) {
            let (h, table, empty) = (&self.h, self.table, self.empty);
            let sub5 = steps.substeps(5, 1000).unwrap_or(1);
            let sub8 = steps.substeps(8, 1000).unwrap_or(1);
            let f = &mut self.figs;
            f.report(
                "substep_n5_f32",
                cases::float::<f32, 10, 61>(h, 5, sub5, table) - empty,
            );
            f.report(
                "substep_n5_f64",
                cases::float::<f64, 10, 61>(h, 5, sub5, table) - empty,
            );
            if CORE != Core::M0 {
                f.report(
                    "substep_n8_f32",
                    cases::float::<f32, 37, 214>(h, 8, sub8, table) - empty,
                );
                f.report(
                    "substep_n8_f64",
                    cases::float::<f64, 37, 214>(h, 8, sub8, table) - empty,
                );
            }
        }

        /// Whole ticks: the demo's, through a proxy, the link's share, the arm's chain
        /// and its peer, the passivity observer, the velocity tracker; the start-up and a tissue's check.
        fn ticks(&mut self) {
            let (h, table, empty) = (&self.h, self.table, self.empty);
            let f = &mut self.figs;
            // One whole tick of this core's demo configuration, in contact.
            f.report("tick", ticks::tick(h, table, PROBE) - empty);
            // One tick of the demo's patch through a sliding proxy (issue #19).
            f.report("tick_proxy", ticks::tick_proxy(h, table) - empty);
            // What the host link adds to a tick (the board's TIM2).
            f.report("tick_link", ticks::tick_link(h, table));
            // Its rarer work at the board's patch, N = 10 (the M4F's: the board's core).
            if CORE == Core::M4F {
                let (swap, mesh) = ticks::link_extras(h, table);
                f.report("link_swap_n10", swap.saturating_sub(empty));
                f.report("link_mesh_n10", mesh.saturating_sub(empty));
            }
            // The arm's counts to duties without the solver, fixed point and its f32 peer.
            f.report("arm_kinematics", arm::arm_kinematics(h) - empty);
            f.report("arm_kinematics_f32", arm::arm_kinematics_f32(h) - empty);
            // The passivity observer's tick (the arm board's).
            f.report("passivity_observer", arm::passivity_observer(h) - empty);
            // The probe's velocity from its quantised positions (the tracker, 3 axes).
            f.report("velocity_tracker", arm::velocity_tracker(h) - empty);
            // The solver's start-up for the demo's patch, once (millions of instructions).
            let grid = mccs_firmware::demo::spec_for(CORE).grid as u32;
            report::startup(f, grid, ticks::startup(h, table));
            // A new tissue's check on the device, the host's substeps proposed (the link's).
            report::tissue_check(f, grid, ticks::tissue_check(h, table));
        }

        /// The demo's roaming: the longest tick without and with a window shift, a
        /// shift's own cost (the most a shift tick took over the tick before), and their
        /// sum (a bound on a shift falling on the most expensive tick, which the slide
        /// need not meet); the same over a spherical cap (R = 150 mm), whose contact is
        /// along its normals and whose shift also computes the entering rest heights and
        /// springs; and issue #19's M4F configuration, N = 5, over the cap.
        fn roaming(&mut self) {
            let (h, table, empty) = (&self.h, self.table, self.empty);
            let f = &mut self.figs;
            let roam = ticks::roaming(h, table, empty);
            f.report("tick_roaming", roam.steady);
            f.report("tick_roaming_shift", roam.shift);
            f.report("window_shift", roam.shift_extra);
            f.report(
                "tick_roaming_bound",
                roam.steady.saturating_add(roam.shift_extra),
            );
            let cap = ticks::roaming_cap(h, table, empty);
            f.report("tick_roaming_cap", cap.steady);
            f.report("tick_roaming_cap_shift", cap.shift);
            f.report("window_shift_cap", cap.shift_extra);
            f.report(
                "tick_roaming_cap_bound",
                cap.steady.saturating_add(cap.shift_extra),
            );
            if CORE == Core::M4F {
                let cap5 = ticks::roaming_cap_n5(h, table, empty);
                f.report("tick_roaming_cap_n5", cap5.steady);
                f.report("window_shift_cap_n5", cap5.shift_extra);
                f.report(
                    "tick_roaming_cap_n5_bound",
                    cap5.steady.saturating_add(cap5.shift_extra),
                );
            }
        }

        /// The solvers', the table's and the windows' sizes (a window: its four shift
        /// maps and, used on a cap, its rest heights and the springs' packed ends).
        fn memory(&mut self) {
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
            defmt::println!(
                "MEM core={=str} window_n4={=usize} window_n8={=usize}",
                CORE.name(),
                core::mem::size_of::<mccs::Window<30>>(),
                core::mem::size_of::<mccs::Window<214>>()
            );
            for (case, bytes) in mem {
                self.figs.record(case, bytes as u32);
            }
        }
    }
}
