//! The figures of a run: recorded by case, printed as `BENCH` lines, turned into the
//! largest patch that fits a tick (`FIT`), and held to `bench/budgets.txt`.

use mccs::solver::stability::bounds;
use mccs::topology::standard_capacity;
use mccs::{ForceTable64, Integrator, SolverConfig, Topology};
use mccs_firmware::target::{Core, CORE};

/// Clock (MHz) and cycles per instruction (×100) assumed to turn instruction counts into
/// time ([`Core::clock_estimate`]).
const CLOCK: (u32, u32) = CORE.clock_estimate();

/// The figures measured in this run, by case name (64 at most; a full list only drops
/// the budget check's view of the rest, which then reports them missing).
pub struct Figures(heapless::Vec<(&'static str, u32), 64>);

impl Figures {
    /// None yet.
    pub fn new() -> Self {
        Self(heapless::Vec::new())
    }

    /// Records one figure.
    pub fn record(&mut self, case: &'static str, value: u32) {
        let _ = self.0.push((case, value));
    }

    fn get(&self, case: &str) -> Option<u32> {
        self.0.iter().find(|(c, _)| *c == case).map(|(_, v)| *v)
    }

    /// Records and prints one instruction count.
    pub fn report(&mut self, case: &'static str, instructions: u32) {
        self.record(case, instructions);
        defmt::println!(
            "BENCH core={=str} case={=str} instructions={=u32}",
            CORE.name(),
            case,
            instructions
        );
    }
}

const SUBSTEP: [&str; 8] = [
    "substep_n3",
    "substep_n4",
    "substep_n5",
    "substep_n6",
    "substep_n7",
    "substep_n8",
    "substep_n9",
    "substep_n10",
];

const SUBSTEP_SYMPLECTIC: [&str; 8] = [
    "substep_n3_symplectic",
    "substep_n4_symplectic",
    "substep_n5_symplectic",
    "substep_n6_symplectic",
    "substep_n7_symplectic",
    "substep_n8_symplectic",
    "substep_n9_symplectic",
    "substep_n10_symplectic",
];

/// The case name of one substep of the N × N patch (N = 3 … 10) with `integrator`.
pub fn substep_case(n: u32, integrator: Integrator) -> Option<&'static str> {
    let names = match integrator {
        Integrator::ImprovedEuler => &SUBSTEP,
        Integrator::SymplecticDamped => &SUBSTEP_SYMPLECTIC,
    };
    names.get((n as usize).checked_sub(3)?).copied()
}

/// The case recording how many instructions a spring can cost beyond what it cost in the
/// substep cases: the slowest of the `spring_path_*` cases less the fastest.
pub const SPRING_PATH_SPREAD: &str = "spring_path_spread";

/// A standard patch's tick at `tick_hz`: `(substeps, tick, worst)`, the measured tick
/// (substeps × the measured substep of `steps`' integrator) and its bound over every
/// state: each of the patch's springs at [`SPRING_PATH_SPREAD`] more per substep, as if
/// every one of them had been on its fastest path in the measured substep and were now on
/// its slowest.
fn tick_of(figs: &Figures, steps: &Steps, n: u32, tick_hz: u32) -> Option<(u32, u32, u32)> {
    let substeps = steps.substeps(n, tick_hz)?;
    let substep = figs.get(substep_case(n, steps.integrator)?)?;
    let springs = standard_capacity(n as usize).1 as u32;
    let spread = springs.saturating_mul(figs.get(SPRING_PATH_SPREAD)?);
    Some((
        substeps,
        substeps.saturating_mul(substep),
        substeps.saturating_mul(substep.saturating_add(spread)),
    ))
}

/// The solver's start-up for this core's demo patch, `n` × `n` ([`crate::cases::startup`]):
/// a `BENCH` line, `case=startup n= instructions= ms_at_clock=` (the time at `CLOCK`
/// with its cycles-per-instruction estimate).
pub fn startup(figs: &mut Figures, n: u32, instructions: u64) {
    let ms = CORE.ms_at_clock(instructions);
    figs.record("startup", u32::try_from(instructions).unwrap_or(u32::MAX));
    defmt::println!(
        "BENCH core={=str} case=startup n={=u32} instructions={=u64} ms_at_clock={=u64}",
        CORE.name(),
        n,
        instructions,
        ms
    );
}

/// A device's check of a new tissue, the host's substeps proposed
/// ([`crate::ticks::tissue_check`]): `case=tissue_check n= instructions= ms_at_clock=
/// steps= slice_steps= worst_slice_instructions=` (the steps of the linearised patch it
/// ran; run again in slices of `slice_steps`, the most one took).
pub fn tissue_check(figs: &mut Figures, n: u32, (instructions, steps, slice): (u64, u32, u64)) {
    let ms = CORE.ms_at_clock(instructions);
    figs.record(
        "tissue_check",
        u32::try_from(instructions).unwrap_or(u32::MAX),
    );
    defmt::println!(
        "BENCH core={=str} case=tissue_check n={=u32} instructions={=u64} ms_at_clock={=u64} \
         steps={=u32} slice_steps={=u32} worst_slice_instructions={=u64}",
        CORE.name(),
        n,
        instructions,
        ms,
        steps,
        crate::ticks::CHECK_SLICE_STEPS,
        slice
    );
}

/// The largest standard patch whose tick's bound over every state ([`tick_of`]) fits in
/// `half_tick` instructions: `(n, substeps, tick, worst)`, or `None` where none fits.
fn largest(
    figs: &Figures,
    steps: &Steps,
    tick_hz: u32,
    half_tick: u32,
) -> Option<(u32, u32, u32, u32)> {
    (3..=10u32)
        .filter_map(|n| {
            let (substeps, tick, worst) = tick_of(figs, steps, n, tick_hz)?;
            (worst <= half_tick).then_some((n, substeps, tick, worst))
        })
        .next_back()
}

/// The largest standard patch that fits in half a tick at 1 kHz and at 10 kHz, at
/// `CLOCK` with its cycles-per-instruction estimate: `FIT` lines.
pub fn fits(figs: &Figures, steps: &Steps) {
    let core = CORE.name();
    for tick_hz in [1_000u32, 10_000] {
        let half_tick =
            (CLOCK.0 as u64 * 1_000_000 * 100 / CLOCK.1 as u64 / (2 * tick_hz as u64)) as u32;
        match largest(figs, steps, tick_hz, half_tick) {
            None => defmt::println!(
                "FIT core={=str} tick_hz={=u32} mhz={=u32} cpi={=u32}/100 half_tick_instructions={=u32} largest_n=none",
                core, tick_hz, CLOCK.0, CLOCK.1, half_tick
            ),
            Some((n, substeps, tick, worst)) => defmt::println!(
                "FIT core={=str} tick_hz={=u32} mhz={=u32} cpi={=u32}/100 half_tick_instructions={=u32} largest_n={=u32} substeps={=u32} tick_instructions={=u32} worst_tick_instructions={=u32}",
                core, tick_hz, CLOCK.0, CLOCK.1, half_tick, n, substeps, tick, worst
            ),
        }
    }
}

/// The largest standard patch that fits in half a 1 kHz tick at the core's clock at one
/// instruction per cycle (issue #17's yardstick) in every state ([`tick_of`]), with
/// `steps`' integrator, as a `BENCH` line: `case=largest_patch_1khz n= substeps=
/// instructions= worst_instructions=` (the measured tick and its bound; all 0 where none
/// fits);
/// the symplectic option's case is `largest_patch_1khz_symplectic`.
pub fn largest_patch(figs: &Figures, steps: &Steps) {
    let half_tick = CLOCK.0 * 1_000_000 / 2_000;
    let (n, substeps, tick, worst) = largest(figs, steps, 1_000, half_tick).unwrap_or((0, 0, 0, 0));
    let case = match steps.integrator {
        Integrator::ImprovedEuler => "largest_patch_1khz",
        Integrator::SymplecticDamped => "largest_patch_1khz_symplectic",
    };
    defmt::println!(
        "BENCH core={=str} case={=str} n={=u32} substeps={=u32} instructions={=u32} worst_instructions={=u32} half_tick_instructions={=u32}",
        CORE.name(),
        case,
        n,
        substeps,
        tick,
        worst,
        half_tick
    );
    if steps.integrator == Integrator::ImprovedEuler {
        next_patch(figs, steps, n.max(2) + 1, half_tick);
    }
}

/// The next standard patch, `n` × `n`, one larger than the largest that fits (where this
/// core measures its substep): what it would take, as a `BENCH` line, `case=next_patch_1khz
/// n= substeps= instructions= worst_instructions= half_tick_instructions=
/// substep_to_fit=`, the last the largest measured substep with which its bound would fit
/// half a tick (its substeps unchanged; 0 where the spread alone fills it).
fn next_patch(figs: &Figures, steps: &Steps, n: u32, half_tick: u32) {
    let Some((substeps, tick, worst)) = tick_of(figs, steps, n, 1_000) else {
        return;
    };
    let Some(spread) = figs.get(SPRING_PATH_SPREAD) else {
        return;
    };
    let springs = standard_capacity(n as usize).1 as u32;
    let to_fit = (half_tick / substeps.max(1)).saturating_sub(springs.saturating_mul(spread));
    defmt::println!(
        "BENCH core={=str} case=next_patch_1khz n={=u32} substeps={=u32} instructions={=u32} worst_instructions={=u32} half_tick_instructions={=u32} substep_to_fit={=u32}",
        CORE.name(),
        n,
        substeps,
        tick,
        worst,
        half_tick,
        to_fit
    );
}

/// Patches [`Steps`] holds, N = 3 onward: up to N = 10 on the M4F, 8 elsewhere (the M0's
/// bench has no room on its stack for two more: 32 bytes more in `main`'s frame ran its
/// `f64` substep into a lockup).
const STEP_SLOTS: usize = if matches!(CORE, Core::M4F) { 8 } else { 6 };

/// The substep (s) the default configuration's stability bound takes on the standard
/// N × N patch, for N = 3 … 10 (`None` where the core cannot hold the patch): computed
/// once, since it does not depend on the tick rate (the estimate is the start-up's
/// longest job).
pub struct Steps {
    steps: [Option<f64>; STEP_SLOTS],
    integrator: Integrator,
}

impl Steps {
    /// Computes them with `integrator` (out of line: the M0's `main` must not carry these
    /// frames).
    #[inline(never)]
    pub fn new(table: &ForceTable64, integrator: Integrator) -> Self {
        let cfg = SolverConfig {
            integrator,
            ..SolverConfig::default()
        };
        Self {
            steps: core::array::from_fn(|i| chosen_step(i as u32 + 3, table, &cfg)),
            integrator,
        }
    }

    /// Substeps per tick at `tick_hz` for the N × N patch.
    pub fn substeps(&self, n: u32, tick_hz: u32) -> Option<u32> {
        let h = (*self.steps.get((n as usize).checked_sub(3)?)?)?;
        let s = libm::ceil(1.0 / (tick_hz as f64 * h));
        (1.0..1e6).contains(&s).then_some(s as u32)
    }
}

#[inline(never)]
fn chosen_step(n: u32, table: &ForceTable64, cfg: &SolverConfig) -> Option<f64> {
    #[inline(never)]
    fn of<const N: usize, const E: usize>(
        n: u32,
        table: &ForceTable64,
        cfg: &SolverConfig,
    ) -> Option<f64> {
        let topo = Topology::<N, E>::standard_patch(n as usize, 2.5).ok()?;
        Some(bounds(&topo, table, cfg).ok()?.chosen)
    }
    match n {
        3 => of::<2, 9>(n, table, cfg),
        4 => of::<5, 30>(n, table, cfg),
        5 => of::<10, 61>(n, table, cfg),
        // Not on the M0: its 16 KiB hold neither these patches nor their figures.
        6 if CORE != Core::M0 => of::<17, 102>(n, table, cfg),
        7 if CORE != Core::M0 => of::<26, 153>(n, table, cfg),
        8 if CORE != Core::M0 => of::<37, 214>(n, table, cfg),
        // The M4F's alone: the board's patch (N = 10) and the one between.
        9 if CORE == Core::M4F => of::<50, 285>(n, table, cfg),
        10 if CORE == Core::M4F => of::<65, 366>(n, table, cfg),
        _ => None,
    }
}

const BUDGETS: &str = include_str!("../../../../bench/budgets.txt");

fn field<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    line.split_whitespace()
        .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('='))
}

/// One budget line's figure, limit and whether it is met (`None`: the figure is
/// missing). `None` for a malformed line.
fn evaluate<'a>(
    kind: &str,
    line: &'a str,
    figs: &Figures,
) -> Option<(&'a str, Option<u32>, u32, Option<bool>)> {
    if kind == "RATIO" {
        let (num, den) = (field(line, "num")?, field(line, "den")?);
        let min = field(line, "min")
            .and_then(|m| m.parse::<u32>().ok())
            .unwrap_or(u32::MAX);
        // Tenths of the ratio.
        let tenths = match (figs.get(num), figs.get(den)) {
            (Some(a), Some(b)) if b > 0 => Some((a as u64 * 10 / b as u64) as u32),
            _ => None,
        };
        let limit = min.saturating_mul(10);
        Some((num, tenths, limit, tenths.map(|t| t >= limit)))
    } else {
        let case = field(line, "case")?;
        let max = field(line, "max")
            .and_then(|m| m.parse::<u32>().ok())
            .unwrap_or(0);
        let value = figs.get(case);
        Some((case, value, max, value.map(|v| v <= max)))
    }
}

/// Whether the word `budget-test` is on the run's semihosting command line (QEMU's
/// `-semihosting-config …,arg=bench,arg=budget-test`, as the test command's
/// `budget-breach-fails` stage runs the bench it built). False where the line cannot be
/// read (too long for the buffer, or RTT logging without a semihosting host).
pub fn budget_test_requested() -> bool {
    #[cfg(not(feature = "rtt"))]
    {
        let mut line = [0u8; 256];
        let asked = mccs_firmware::command_line::words(&mut line).any(|w| w == b"budget-test");
        asked
    }
    #[cfg(feature = "rtt")]
    false
}

/// The budgets a run holds its figures to: bench/budgets.txt, or with `budget-test` a
/// budget no code can meet (one instruction for one spring's force and stiffness), to
/// show that a breach fails the run. The budget test measures that case alone and holds
/// it to that budget alone, so that the run fails by the breach and nothing else.
pub fn budgets(budget_test: bool) -> &'static str {
    if budget_test {
        "BUDGET core=m4f case=force_and_stiffness max=1 status=enforced\nBUDGET core=m3 case=force_and_stiffness max=1 status=enforced\nBUDGET core=m0 case=force_and_stiffness max=1 status=enforced"
    } else {
        BUDGETS
    }
}

/// Checks this core's lines of `budgets` ([`budgets`]) against the figures; prints one
/// line each. False when a budget is breached or its figure is missing, or a line is
/// malformed: every budget is enforced (`status=enforced`; any other status is
/// malformed: a target the product does not promise is not listed).
pub fn check_budgets(figs: &Figures, budgets: &str) -> bool {
    let core = CORE.name();
    let mut ok = true;
    for line in budgets.lines() {
        let kind = line.split_whitespace().next().unwrap_or("");
        if !matches!(kind, "BUDGET" | "RATIO" | "MEMORY") || field(line, "core") != Some(core) {
            continue;
        }
        let evaluated =
            evaluate(kind, line, figs).filter(|_| field(line, "status") == Some("enforced"));
        let Some((case, value, limit, within)) = evaluated else {
            defmt::println!("BUDGET core={=str} malformed line: {=str}", core, line);
            ok = false;
            continue;
        };
        let result = match within {
            Some(true) => "ok",
            Some(false) => "OVER",
            None => "missing",
        };
        if within != Some(true) {
            ok = false;
        }
        defmt::println!(
            "{=str} core={=str} case={=str} value={=u32} limit={=u32} result={=str}",
            kind,
            core,
            case,
            value.unwrap_or(0),
            limit,
            result
        );
    }
    ok
}
