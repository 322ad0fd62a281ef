//! `mccs check`: will a tissue run on a core before any firmware is built? The substeps
//! the core's own stability bound asks for this tissue and configuration (computed here,
//! in the core's arithmetic), and the tick's instructions estimated from the bench's
//! measured costs on that core (`bench/baseline.txt`, compiled in), against half a tick
//! at the core's clock.

use super::patch_args::{config_error, topology_error, TuningArgs};
use super::table::{build, with_knots, Domain, TableArgs};
use super::{arg_error, io_error, CliError, IntegratorArg};
use crate::paramfile;
use crate::replay::{FIXED_EDGES, FIXED_NODES};
use mccs::{Arith, ForceTable, Solver, SolverConfig, Topology};
use mccs_client::shown::ShownPath;
use std::io::Write;
use std::path::PathBuf;

/// The bench's measured figures, as committed (`scripts/bench.sh --update` rewrites
/// them): what the estimate is made of.
const BASELINE: &str = include_str!("../../../bench/baseline.txt");

/// A core the bench measures.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum CoreArg {
    /// Cortex-M4F (STM32F405, 168 MHz; the board's).
    M4f,
    /// Cortex-M3 (LM3S6965, 50 MHz).
    M3,
    /// Cortex-M0 (48 MHz).
    M0,
}

impl CoreArg {
    fn name(self) -> &'static str {
        match self {
            Self::M4f => "m4f",
            Self::M3 => "m3",
            Self::M0 => "m0",
        }
    }

    /// Its clock, MHz (the bench's yardstick: one instruction per cycle).
    fn mhz(self) -> u64 {
        match self {
            Self::M4f => 168,
            Self::M3 => 50,
            Self::M0 => 48,
        }
    }

    /// The patch its demo firmware (and the M4F's board) runs.
    fn demo_grid(self) -> usize {
        match self {
            Self::M4f => 8,
            Self::M3 => 5,
            Self::M0 => 4,
        }
    }
}

/// What the tick runs besides the patch.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum DeviceArg {
    /// The bare patch's substeps, as the bench's largest-patch figure counts them.
    Patch,
    /// The arm board's whole tick (the trainer tick): the patch, its roaming contact with
    /// friction and window shifts, the arm's chain (counts to duties) and the link's share.
    Arm,
}

#[derive(clap::Args, Debug)]
pub(super) struct Args {
    /// Parameter file (the TOML schema of docs/model.md).
    #[arg(long)]
    params: PathBuf,
    /// The core it is to run on.
    #[arg(long, value_enum, default_value_t = CoreArg::M4f)]
    core: CoreArg,
    /// The tick it is to fit: the bare patch, or the arm board's whole tick (which also
    /// holds the coupling to half the arm's stable region).
    #[arg(long, value_enum, default_value_t = DeviceArg::Patch)]
    device: DeviceArg,
    /// With --device arm: the device file whose [stability] the coupling is held to
    /// (default: the board's, devices/woodenhaptics.toml).
    #[arg(long)]
    arm_file: Option<PathBuf>,
    /// Surface nodes per side, N (default: the core's demo patch, m4f 8, m3 5, m0 4).
    #[arg(long)]
    grid: Option<usize>,
    /// Grid spacing, mm (the board's: 2.5).
    #[arg(long, default_value_t = 2.5, allow_negative_numbers = true)]
    spacing: f64,
    /// Tick rate, Hz (a whole number, 1 … 100000).
    #[arg(long, default_value_t = 1000.0, allow_negative_numbers = true)]
    rate: f64,
    /// Integrator (docs/performance.md, "The symplectic option").
    #[arg(long, value_enum, default_value_t = IntegratorArg::ImprovedEuler)]
    integrator: IntegratorArg,
    #[command(flatten)]
    tuning: TuningArgs,
    #[command(flatten)]
    table: TableArgs,
}

/// Which of a spring's costlier paths a table has (the bench's `spring_path_*` cases):
/// every table has its segments, its two lines and the held edge vector and `l0/l`; some
/// have a graded corner (a stiff series spring's), some a lower corner (a steep kink's).
struct TablePaths {
    corner: bool,
    lower_corner: bool,
}

impl TablePaths {
    /// The most a spring of this table takes on any of its paths less the least, on
    /// `core`: the bench's `spring_path_spread` where a path's figure is missing.
    fn spread(&self, core: &str) -> u64 {
        let mut paths = vec!["uniform", "below", "above", "stretched", "crushed"];
        if self.corner {
            paths.push("corner");
        }
        if self.lower_corner {
            paths.push("lower_corner");
        }
        let costs: Option<Vec<u64>> = paths
            .iter()
            .map(|p| bench_figure(core, &format!("spring_path_{p}"), "instructions"))
            .collect();
        match costs {
            Some(c) => c.iter().max().unwrap_or(&0) - c.iter().min().unwrap_or(&0),
            None => bench_figure(core, "spring_path_spread", "instructions").unwrap_or(0),
        }
    }

    /// What the message names: the corners it counts.
    fn named(&self) -> &'static str {
        match (self.corner, self.lower_corner) {
            (false, false) => ", no corner",
            (true, false) => ", its graded corner among them",
            (false, true) => ", its lower corner among them",
            (true, true) => ", both its corners among them",
        }
    }
}

/// One core's figure from the bench's baseline (`bench/baseline.txt`, compiled in): the
/// `field` of its `case` line, `None` where there is none.
pub fn bench_figure(core: &str, case: &str, field: &str) -> Option<u64> {
    BASELINE.lines().find_map(|l| {
        let mut f = l.split_whitespace();
        if f.next() != Some("BENCH") {
            return None;
        }
        let kv: Vec<(&str, &str)> = f.filter_map(|x| x.split_once('=')).collect();
        let get = |k: &str| kv.iter().find(|(a, _)| *a == k).map(|(_, v)| *v);
        (get("core") == Some(core) && get("case") == Some(case))
            .then(|| get(field)?.parse().ok())
            .flatten()
    })
}

pub(super) fn run(a: Args, out: &mut dyn Write) -> Result<(), CliError> {
    let core = a.core;
    let n = a.grid.unwrap_or(core.demo_grid());
    let rate = a.rate;
    if !(rate.is_finite() && (1.0..=100_000.0).contains(&rate) && rate.fract() == 0.0) {
        return Err(arg_error(
            "--rate",
            "must be a whole number of Hz, 1 … 100000",
        ));
    }
    if a.device == DeviceArg::Arm {
        coupling_within_region(a.arm_file.as_deref(), &a.tuning)?;
    }
    let substep = substep_figure(core, n, a.integrator)?;
    let cfg = SolverConfig {
        integrator: a.integrator.into(),
        ..a.tuning.config(rate)?
    };
    let p = paramfile::read(&a.params)?;
    let ((substeps, conservative), paths) = with_knots!(a.table.knots(), |S| {
        let t = build::<S>(&p, &a.params, Domain::Default, a.table.accept_error, true)?;
        let paths = TablePaths {
            corner: t.corner().is_some(),
            lower_corner: t.lower_corner(),
        };
        let substeps = match core {
            CoreArg::M0 => substeps_of(t, n, a.spacing, &cfg, mccs::Narrow)?,
            _ => substeps_of(t, n, a.spacing, &cfg, mccs::Wide)?,
        };
        (substeps, paths)
    });
    // The bench's bound over every state of the patch's substeps, as its
    // `largest_patch_1khz` takes it: each spring at the spread of its paths more, over
    // the paths this table has (a graded or a lower corner only where it has one).
    let springs = mccs::topology::standard_capacity(n).1 as u64;
    let spread = paths.spread(core.name());
    let patch_tick = substeps as u64 * (substep + springs * spread);
    let budget = core.mhz() * 1_000_000 / (2 * rate as u64);
    let (tick, how) = device_share(core, a.device, patch_tick);
    let fits = tick <= budget;

    eprintln!(
        "mccs check: tick_instructions estimated from the bench's measured costs on the {} (bench/baseline.txt): {substeps} substeps × ({substep} per substep + {springs} springs × {spread}, their spread over every state of this table's paths{}); {how}; budget: half a {} Hz tick at {} MHz, one instruction per cycle",
        core.name(),
        paths.named(),
        rate as u64,
        core.mhz()
    );
    writeln!(
        out,
        "substeps={substeps} tick_instructions={tick} budget={budget} fits={}",
        if fits { "yes" } else { "no" }
    )
    .map_err(io_error)?;
    out.flush().map_err(io_error)?;
    if fits {
        Ok(())
    } else {
        // What lowers the substeps: a heavier node where the estimated bound sets them;
        // where the patch is too lightly damped for the estimate to see its edge, the
        // conservative bound (about `2 C / k`, whatever the mass) sets them, and more
        // damping or a lighter node (back within the estimate's reach) lowers them.
        // At one substep, only a smaller patch or a slower tick.
        let remedy = if substeps == 1 {
            "a smaller --grid or a lower --rate (one substep a tick already)"
        } else if conservative {
            "more --spring-damping or a lighter --node-mass (the patch is too lightly damped for the stability estimate, and takes the conservative bound), a smaller --grid or a lower --rate"
        } else {
            "a smaller --grid, a lower --rate or a heavier --node-mass"
        };
        Err(CliError::check_failed(format!(
            "the tick would take {tick} instructions, over its budget of {budget}: {remedy}"
        )))
    }
}

/// The board's device file, as committed: its [stability] is the default region.
const BOARD_ARM: &str = include_str!("../../../devices/woodenhaptics.toml");

/// With `--device arm`: the coupling at most half the arm's stable region at its
/// damping (`arm_file`'s [stability], or the board's), or the failed check naming both.
fn coupling_within_region(
    arm_file: Option<&std::path::Path>,
    tuning: &TuningArgs,
) -> Result<(), CliError> {
    use crate::arm::device_file;
    let (path, region) = match arm_file {
        Some(p) => (p.to_path_buf(), device_file::read_stability(p)),
        None => {
            let p = PathBuf::from("devices/woodenhaptics.toml");
            let r = device_file::parse_stability(BOARD_ARM, &p);
            (p, r)
        }
    };
    let file = ShownPath(&path);
    let Some(region) = region.map_err(CliError::new)? else {
        eprintln!(
            "mccs check: warning: {file} has no [stability] (`mccs arm stability` measures it): the coupling is not held to the arm's stable region"
        );
        return Ok(());
    };
    let (k, b) = (tuning.coupling_stiffness, tuning.coupling_damping);
    let Some(edge) = region.max_coupling(b) else {
        let (lo, hi) = (region.points[0].0, region.points[region.points.len() - 1].0);
        return Err(CliError::check_failed(format!(
            "--coupling-damping {b} N·s/m is outside the arm's measured stable region ({lo} … {hi} N·s/m, {file} [stability])"
        )));
    };
    if k > edge / 2.0 {
        return Err(CliError::check_failed(format!(
            "--coupling-stiffness {k} N/mm is over half the arm's stable region at {b} N·s/m ({edge:.3} N/mm measured, {file} [stability]): at most {:.3}",
            edge / 2.0
        )));
    }
    eprintln!(
        "mccs check: the coupling, {k} N/mm at {b} N·s/m, is within half the arm's stable region there ({edge:.3} N/mm, {file} [stability])"
    );
    Ok(())
}

/// The bench's measured substep cost for the `n × n` patch on `core` with `integrator`,
/// or the `--grid` error naming the sizes it measures.
fn substep_figure(core: CoreArg, n: usize, integrator: IntegratorArg) -> Result<u64, CliError> {
    let symplectic = integrator == IntegratorArg::SymplecticDamped;
    let suffix = if symplectic { "_symplectic" } else { "" };
    if let Some(substep) = bench_figure(
        core.name(),
        &format!("substep_n{n}{suffix}"),
        "instructions",
    ) {
        return Ok(substep);
    }
    let measured: Vec<String> = (3..=12)
        .filter(|k| {
            bench_figure(
                core.name(),
                &format!("substep_n{k}{suffix}"),
                "instructions",
            )
            .is_some()
        })
        .map(|k| k.to_string())
        .collect();
    Err(arg_error(
        "--grid",
        &format!(
            "the bench measures the {} substep{} for N = {} only, not {n}",
            core.name(),
            if symplectic {
                " of --integrator symplectic-damped"
            } else {
                ""
            },
            measured.join(", ")
        ),
    ))
}

/// The tick's cost beyond the patch's for `device`, and how it was reckoned.
fn device_share(core: CoreArg, device: DeviceArg, patch_tick: u64) -> (u64, String) {
    let roaming = bench_figure(core.name(), "tick_roaming_bound", "instructions").unwrap_or(0);
    match device {
        DeviceArg::Patch => (
            patch_tick,
            format!(
                "the contact's own cost is not in it (a roaming tick's, window shift included, measured {roaming} on the demo's N = {} patch; --device arm adds it)",
                core.demo_grid()
            ),
        ),
        DeviceArg::Arm => {
            // The roaming contact's own cost: the demo's roaming tick (window shift
            // included) less its glued tick, on the same patch and substeps.
            let glued = bench_figure(core.name(), "tick", "instructions").unwrap_or(0);
            let contact = roaming.saturating_sub(glued);
            let chain = bench_figure(core.name(), "arm_kinematics", "instructions").unwrap_or(0);
            let link = bench_figure(core.name(), "tick_link", "instructions").unwrap_or(0);
            let observer = bench_figure(core.name(), "passivity_observer", "instructions").unwrap_or(0);
            let tracker = bench_figure(core.name(), "velocity_tracker", "instructions").unwrap_or(0);
            // The link's rarer work, which may fall on one tick (the board's model,
            // `LINK_WORK_COST`): measured at the board's N = 10, the largest the check
            // takes, where it costs the most.
            let swap = bench_figure(core.name(), "link_swap_n10", "instructions");
            let mesh = bench_figure(core.name(), "link_mesh_n10", "instructions");
            let rare = match (swap, mesh) {
                (Some(swap), Some(mesh)) => (
                    swap + mesh,
                    format!(", a tissue's swap {swap} and a mesh's capture {mesh} (at N = 10: at most)"),
                ),
                _ => (
                    0,
                    format!(
                        "; not in it: a tissue's swap and a mesh's capture (the bench measures them on the m4f only, {} and {} there)",
                        bench_figure("m4f", "link_swap_n10", "instructions").unwrap_or(0),
                        bench_figure("m4f", "link_mesh_n10", "instructions").unwrap_or(0)
                    ),
                ),
            };
            (
                patch_tick + contact + chain + link + rare.0 + observer + tracker,
                format!(
                    "plus the arm board's: the roaming contact with friction {contact} (the demo's roaming tick less its glued tick, measured at N = {}), the arm's chain {chain}, the link's share {link}, the passivity observer {observer}, the velocity tracker {tracker}{}",
                    core.demo_grid(),
                    rare.1
                ),
            )
        }
    }
}

/// The substeps per tick the core's stability bound asks for on the standard `n × n`
/// patch at `spacing` mm with `table` and `cfg`, in arithmetic `A`, and whether they
/// are the conservative bound's where the estimate was asked for (the patch too lightly
/// damped for the estimate to see its edge: `mccs::solver::stability`).
fn substeps_of<const S: usize, A: Arith>(
    table: ForceTable<S>,
    n: usize,
    spacing: f64,
    cfg: &SolverConfig,
    arith: A,
) -> Result<(u32, bool), CliError> {
    if !(3..=crate::replay::MAX_GRID_FIXED).contains(&n) {
        return Err(arg_error("--grid", "must be 3 … 12"));
    }
    if !(spacing.is_finite() && spacing > 0.0 && spacing * n as f64 <= 100.0) {
        return Err(arg_error(
            "--spacing",
            "must be > 0 mm, with grid × spacing ≤ 100 mm",
        ));
    }
    let topo = Topology::<FIXED_NODES, FIXED_EDGES>::standard_patch(n, spacing).map_err(|e| {
        if e == mccs::TopologyError::TooShort {
            arg_error(
                "--spacing",
                "must be ≥ 1 mm (the fixed-point core's springs are 1 mm long at least)",
            )
        } else {
            topology_error(e)
        }
    })?;
    let bounds = mccs::solver::stability::bounds(&topo, &table, cfg);
    let s = Solver::with_arith(topo, table, cfg, arith).map_err(|e| config_error(e, cfg))?;
    let conservative = bounds.is_ok_and(|b| {
        b.estimated.is_some() && b.chosen == mccs::solver::stability::CONSERVATIVE_FACTOR * b.closed
    });
    Ok((s.substeps(), conservative))
}
