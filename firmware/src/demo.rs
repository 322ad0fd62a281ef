//! The demo run, shared by the firmware (`firmware/src/bin/haptic.rs`) and the host (`mccs demo`)
//! so that both run exactly the same thing: a palpation ([`palpation_path`], 4 s: press,
//! slide 30 mm, press harder, slide back, lift) through a proxy with friction on a flat
//! 64 × 64 Table 2 tissue at 2.5 mm, which the core's standard patch follows as a window
//! ([`Roaming`]); 1.25 s in, mid-slide, a switch to a stiffer tissue
//! ([`STIFFER`]: the cone's shear modulus × 1.25, its table emitted by `mccs table`),
//! prepared by the main loop and handed over through a
//! [`Mailbox`](crate::mailbox::Mailbox). Each core runs the
//! [`DemoSpec`] that fits its instruction budget.

use crate::arm::sim::{samples_for, SimArmError, SimulatedArm};
use crate::controller::{Controller, Roaming};
use crate::device::SimulatedDevice;
use crate::probe_path::{palpation_path, PathError, ProbePath};
use crate::target::Core;
use mccs::{
    Arith, Flat, ForceTable64, Narrow, ParamSet, ProxyConfig, ProxyError, Solver, SolverConfig,
    SolverError, Topology, TopologyError, Wide, WindowConfig,
};

/// A demo configuration: what each core runs within its instruction budget.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DemoSpec {
    /// `m4f`, `m3` or `m0`.
    pub core: &'static str,
    /// Tick rate, Hz.
    pub tick_hz: u32,
    /// Patch: N × N surface nodes at 2.5 mm.
    pub grid: usize,
    /// Haptic node mass, kg.
    pub node_mass: f64,
    /// Spring damping, N·s/m.
    pub spring_damping: f64,
    /// QEMU `-icount` shift: one instruction is 2^shift ns, which makes the emulated
    /// instruction rate no faster than the real core at one instruction per cycle.
    pub icount_shift: u32,
    /// The core clock the budget stands for, Hz.
    pub clock_hz: u32,
}

/// Cortex-M4F (STM32F405, 168 MHz): N = 8 (214 springs) at 1 kHz, the default
/// configuration (3 substeps per tick). Budget: 125,000 instructions per tick
/// (`-icount shift=3`, 8 ns each).
pub const M4F: DemoSpec = DemoSpec {
    core: "m4f",
    tick_hz: 1000,
    grid: 8,
    node_mass: 0.005,
    spring_damping: 1.0,
    icount_shift: 3,
    clock_hz: 168_000_000,
};

/// Cortex-M3 (LM3S6965, 50 MHz): N = 5 at 1 kHz, the default configuration (2 substeps
/// per tick). Budget: 31,250 instructions per tick (`shift=5`, 32 ns).
pub const M3: DemoSpec = DemoSpec {
    core: "m3",
    tick_hz: 1000,
    grid: 5,
    node_mass: 0.005,
    spring_damping: 1.0,
    icount_shift: 5,
    clock_hz: 50_000_000,
};

/// Cortex-M0 (48 MHz class): N = 4 at 1 kHz with heavier haptic masses and more damping
/// (1 substep per tick), in the narrow spring arithmetic ([`mccs::Narrow`]: the M0 has
/// no 32 × 32 → 64 multiply). N = 5 does not fit its 16 KiB of RAM with the start-up's
/// stack. Budget: 31,250 instructions per tick (`shift=5`, 32 ns).
pub const M0: DemoSpec = DemoSpec {
    core: "m0",
    tick_hz: 1000,
    grid: 4,
    node_mass: 0.03,
    spring_damping: 3.0,
    icount_shift: 5,
    clock_hz: 48_000_000,
};

/// The spec for a core name.
pub fn spec(core: &str) -> Option<DemoSpec> {
    [M4F, M3, M0].into_iter().find(|s| s.core == core)
}

/// The spec for a core.
pub const fn spec_for(core: Core) -> DemoSpec {
    match core {
        Core::M4F => M4F,
        Core::M3 => M3,
        Core::M0 => M0,
    }
}

impl DemoSpec {
    /// Ticks in the run (4 s).
    pub const fn ticks(&self) -> u32 {
        4 * self.tick_hz
    }

    /// The tick whose `z` force is the steady force: the end of the first hold (t = 0.5 s).
    pub const fn steady_tick(&self) -> u32 {
        self.tick_hz / 2 - 1
    }

    /// The first tick on the swapped parameters (mid-stroke, t = 1.25 s).
    pub const fn swap_tick(&self) -> u32 {
        self.tick_hz * 5 / 4
    }

    /// Instructions one tick may take: `2^-shift` instructions per ns over the tick.
    pub const fn budget(&self) -> u32 {
        ((1_000_000_000u64 / self.tick_hz as u64) >> self.icount_shift) as u32
    }

    /// The solver configuration.
    pub fn config(&self) -> SolverConfig {
        SolverConfig {
            tick_hz: self.tick_hz as f64,
            node_mass: self.node_mass,
            spring_damping: self.spring_damping,
            ..SolverConfig::default()
        }
    }

    /// The demo controller, starting from `table` (Table 2's). Out of line, like the
    /// other start-up builders, so that small-RAM cores do not pay for their stack
    /// frames at once.
    pub fn controller<const N: usize, const E: usize, A: Arith>(
        &self,
        table: &ForceTable64,
    ) -> Result<DemoControllerIn<N, E, A>, DemoError> {
        let mut slot = None;
        self.controller_into(table, &mut slot)?;
        slot.ok_or(DemoError::Path(PathError::Count))
    }

    /// [`Self::controller`], built straight into `slot` (fewer copies on the stack).
    #[inline(never)]
    pub fn controller_into<const N: usize, const E: usize, A: Arith>(
        &self,
        table: &ForceTable64,
        slot: &mut Option<DemoControllerIn<N, E, A>>,
    ) -> Result<(), DemoError> {
        let topo = Topology::standard_patch(self.grid, SPACING).map_err(DemoError::Topology)?;
        let path = palpation_path(self.tick_hz).map_err(DemoError::Path)?;
        let mut solver = Solver::with_arith(topo, *table, &self.config(), A::default())
            .map_err(DemoError::Solver)?;
        let start = path.at(0).map(|c| c.to_num::<f64>());
        let contact = self.roaming(&mut solver, start[0], start[1])?;
        place(slot, solver, contact, path, self.steady_tick());
        Ok(())
    }

    /// [`Self::controller_into`] on the arm ([`ArmDemoControllerIn`]): the same solver,
    /// contact and palpation, the probe read through the WoodenHaptics arm's joint
    /// counts (the path converted once, here) and the force written as its duties.
    #[inline(never)]
    pub fn arm_controller_into<const N: usize, const E: usize, A: Arith>(
        &self,
        table: &ForceTable64,
        slot: &mut Option<ArmDemoControllerIn<N, E, A>>,
    ) -> Result<(), DemoError> {
        let topo = Topology::standard_patch(self.grid, SPACING).map_err(DemoError::Topology)?;
        let path = palpation_path(self.tick_hz).map_err(DemoError::Path)?;
        let arm = SimulatedArm::from_path(&ARM, &path, self.ticks(), self.steady_tick())
            .map_err(DemoError::Arm)?;
        let mut solver = Solver::with_arith(topo, *table, &self.config(), A::default())
            .map_err(DemoError::Solver)?;
        let start = path.at(0).map(|c| c.to_num::<f64>());
        let contact = self.roaming(&mut solver, start[0], start[1])?;
        *slot = Some(Controller::with_contact(
            solver,
            contact,
            arm,
            self.steady_tick(),
        ));
        Ok(())
    }

    /// The demo's contact for `solver`, the window centred at `(x, y)` (mm, tissue frame).
    /// Out of line, like the other start-up builders.
    #[inline(never)]
    pub fn roaming<const N: usize, const E: usize, A: Arith>(
        &self,
        solver: &mut Solver<N, E, 64, A>,
        x: f64,
        y: f64,
    ) -> Result<Roaming<E>, DemoError> {
        let proxy = solver
            .proxy(&self.proxy_config())
            .map_err(DemoError::Contact)?;
        let window = solver
            .window(&WINDOW, &Flat, &proxy, x, y)
            .map_err(DemoError::Contact)?;
        Ok(Roaming::new(proxy, window))
    }

    /// The proxy: the demo's friction and a point probe on this spec's patch.
    pub fn proxy_config(&self) -> ProxyConfig {
        ProxyConfig {
            grid: self.grid,
            spacing: SPACING,
            mu_s: FRICTION.0,
            mu_k: FRICTION.1,
            probe_radius: 0.0,
        }
    }

    /// The swapped parameter set for this spec's patch: [`STIFFER`]'s table with the
    /// substeps and coefficients it needs (software floating point: for the main loop,
    /// not the tick).
    #[inline(never)]
    pub fn swapped_set<const N: usize, const E: usize, A: Arith>(
        &self,
    ) -> Result<ParamSet<64, A>, DemoError> {
        let topo =
            Topology::<N, E>::standard_patch(self.grid, SPACING).map_err(DemoError::Topology)?;
        Solver::<N, E, 64, A>::prepare_for(&topo, STIFFER, &self.config())
            .map_err(DemoError::Solver)
    }
}

/// Builds the controller into `slot`. Out of line: the parts arrive by reference, and
/// the controller's temporary is on this frame alone (the M0's start-up stack).
#[inline(never)]
fn place<const N: usize, const E: usize, A: Arith>(
    slot: &mut Option<DemoControllerIn<N, E, A>>,
    solver: Solver<N, E, 64, A>,
    contact: Roaming<E>,
    path: ProbePath<9>,
    steady_tick: u32,
) {
    let device = SimulatedDevice::new(path);
    *slot = Some(Controller::with_contact(
        solver,
        contact,
        device,
        steady_tick,
    ));
}

/// Grid spacing of the demo patch and tissue, mm.
pub const SPACING: f64 = 2.5;

/// The demo's tissue (64 × 64 nodes, 157.5 mm a side) and window hysteresis (0.1
/// spacing past the half).
pub const WINDOW: WindowConfig = WindowConfig {
    tissue_w: 64,
    tissue_h: 64,
    hysteresis: 0.1,
};

/// The demo's friction `(μ_s, μ_k)`.
pub const FRICTION: (f64, f64) = (0.6, 0.4);

/// The demo's device.
pub type DemoDevice = SimulatedDevice<9>;
/// The arm the arm demo drives: WoodenHaptics (`devices/woodenhaptics.toml`).
pub const ARM: mccs::ArmSpec = crate::arm::device::WOODENHAPTICS;
/// Samples of joint counts the arm demo's 4 s at 1 kHz take.
pub const ARM_SAMPLES: usize = samples_for(4000);
/// The arm demo's device: the palpation through the arm's joints.
pub type ArmDemoDevice = SimulatedArm<ARM_SAMPLES>;
/// An arm demo controller ([`DemoSpec::arm_controller_into`]).
pub type ArmDemoControllerIn<const NODES: usize, const EDGES: usize, A> =
    Controller<ArmDemoDevice, NODES, EDGES, 64, A, Roaming<EDGES>>;
/// An arm demo controller in this core's arithmetic.
pub type ArmDemoControllerOf<const NODES: usize, const EDGES: usize> =
    ArmDemoControllerIn<NODES, EDGES, mccs::DefaultArith>;
/// A demo controller in arithmetic `A` with capacity for `NODES` node slots (the ground
/// included) and `EDGES` springs.
pub type DemoControllerIn<const NODES: usize, const EDGES: usize, A> =
    Controller<DemoDevice, NODES, EDGES, 64, A, Roaming<EDGES>>;
/// A demo controller in this core's arithmetic.
pub type DemoControllerOf<const NODES: usize, const EDGES: usize> =
    DemoControllerIn<NODES, EDGES, mccs::DefaultArith>;
/// A demo controller with capacity for N = 8 (36 free nodes + ground, 214 springs): the
/// M4F demo.
pub type DemoController = DemoControllerOf<37, 214>;
/// A demo controller with capacity for N = 5 (9 free nodes + ground, 61 springs): the
/// M3 and M0 demos, which must fit 16 KiB of RAM on the M0.
pub type SmallDemoController = DemoControllerOf<10, 61>;

/// The demo's first tissue: the paper's Table 2 spring (`params/table2.toml`), its
/// table as `mccs table` emits it.
pub static TABLE2: ForceTable64 = include!("../../tables/table2.rs");

/// The tissue switched to mid-run: Table 2 with the cone's shear modulus × 1.25
/// (`params/table2-stiffer.toml`), its table as `mccs table` emits it.
pub static STIFFER: ForceTable64 = include!("../../tables/table2_stiffer.rs");

/// Why the demo could not start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DemoError {
    /// The patch.
    Topology(TopologyError),
    /// The solver or a parameter set.
    Solver(SolverError),
    /// The probe path.
    Path(PathError),
    /// The proxy or the window.
    Contact(ProxyError),
    /// The arm demo's arm.
    Arm(SimArmError),
}

impl core::fmt::Display for DemoError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Topology(e) => e.fmt(f),
            Self::Solver(e) => e.fmt(f),
            Self::Path(e) => e.fmt(f),
            Self::Contact(e) => e.fmt(f),
            Self::Arm(e) => e.fmt(f),
        }
    }
}

/// What a demo run ends with (the firmware's SUMMARY line).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    /// Ticks run.
    pub ticks: u32,
    /// Ticks over budget.
    pub overruns: u32,
    /// Largest force on any axis, N.
    pub max_force: f32,
    /// Force along z at the steady tick, N.
    pub steady_force: f32,
    /// Window shifts.
    pub window_shifts: u32,
}

/// Runs the whole demo on the host (no overruns: nothing is timed), with the swap handed
/// over at [`DemoSpec::swap_tick`] exactly as the firmware does, in the arithmetic of the
/// spec's core ([`mccs::Narrow`] for the M0).
pub fn run_on_host(spec: &DemoSpec) -> Result<Summary, DemoError> {
    if spec.core == "m0" {
        run_on_host_in::<Narrow>(spec)
    } else {
        run_on_host_in::<Wide>(spec)
    }
}

fn run_on_host_in<A: Arith>(spec: &DemoSpec) -> Result<Summary, DemoError> {
    let mut ctl: DemoControllerIn<37, 214, A> = spec.controller(&TABLE2)?;
    run_ticks(spec, &mut ctl)
}

/// The demo's ticks on `ctl`, the swap handed over as the firmware does; its summary.
fn run_ticks<D: crate::device::HapticDevice, A: Arith>(
    spec: &DemoSpec,
    ctl: &mut Controller<D, 37, 214, 64, A, Roaming<214>>,
) -> Result<Summary, DemoError> {
    let mut swap = Some(spec.swapped_set::<37, 214, A>()?);
    for tick in 0..spec.ticks() {
        let s = if tick >= spec.swap_tick() {
            swap.take()
        } else {
            None
        };
        ctl.tick(s);
    }
    let t = ctl.telemetry();
    Ok(Summary {
        ticks: t.ticks,
        overruns: t.overruns,
        max_force: t.max_force.to_num(),
        steady_force: t.steady_force.to_num(),
        window_shifts: t.window_shifts,
    })
}

/// What the arm demo ends with besides [`Summary`]: the duties (Q16 → fractions of full
/// scale) at the steady tick, and the largest |duty| of any joint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArmSummary {
    /// Joints A, B, C at the steady tick.
    pub steady_duty: [f32; 3],
    /// The largest |duty| over the run.
    pub max_duty: f32,
}

impl ArmSummary {
    /// Of the demo's arm after its run.
    pub fn of(arm: &ArmDemoDevice) -> Self {
        let q16 = |d: i32| d as f32 / 65_536.0;
        Self {
            steady_duty: arm.steady_duties().map(q16),
            max_duty: q16(arm.max_duty()),
        }
    }
}

/// [`run_on_host`] on the arm ([`DemoSpec::arm_controller_into`]).
pub fn run_arm_on_host(spec: &DemoSpec) -> Result<(Summary, ArmSummary), DemoError> {
    if spec.core == "m0" {
        run_arm_on_host_in::<Narrow>(spec)
    } else {
        run_arm_on_host_in::<Wide>(spec)
    }
}

fn run_arm_on_host_in<A: Arith>(spec: &DemoSpec) -> Result<(Summary, ArmSummary), DemoError> {
    let mut slot: Option<ArmDemoControllerIn<37, 214, A>> = None;
    spec.arm_controller_into(&TABLE2, &mut slot)?;
    let mut ctl = slot.ok_or(DemoError::Path(PathError::Count))?;
    let summary = run_ticks(spec, &mut ctl)?;
    Ok((summary, ArmSummary::of(ctl.device())))
}
