//! `Controller`: one haptic tick end to end — device in, solver, device out — with the
//! safe state and the run statistics the firmware reports.
//!
//! Contact, a type parameter (only the one used is compiled in): [`Glued`] (the probe
//! holds the patch's contact node through a spring on all three axes, the indentation
//! test's contact; probe in the patch frame) or [`Roaming`] (a proxy with friction on a
//! tissue the patch follows as a window; probe in the tissue frame).
//!
//! Safe state: any device error (failing to read or to write) latches a [`Fault`] and
//! puts the device in its safe state at once ([`HapticDevice::safe_state`]: zero duty
//! first, then the drive cut); from then on every tick re-asserts the safe state and
//! does nothing else, until reset by building a new controller. A parameter set prepared
//! for another topology or tick rate is refused and counted; the solver keeps its set.

use crate::device::HapticDevice;
use mccs::{Arith, DefaultArith, Flat, Force, Length, ParamSet, Proxy, Shape, Solver, Window};

/// How the probe touches the tissue: one tick of the solver with the probe read.
pub trait Contact<const NODES: usize, const EDGES: usize, const S: usize, A: Arith> {
    /// One tick of `solver` with the probe at `probe` (mm); the force to render (N).
    fn step(&mut self, solver: &mut Solver<NODES, EDGES, S, A>, probe: [Length; 3]) -> [Force; 3];
    /// Window shifts so far (0 for a contact without a window).
    fn window_shifts(&self) -> u32 {
        0
    }
}

/// The probe glued to the patch's contact node through a spring on all three axes
/// ([`Solver::step`], the indentation test's contact); the probe in the patch frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Glued;

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith> Contact<NODES, EDGES, S, A>
    for Glued
{
    fn step(&mut self, solver: &mut Solver<NODES, EDGES, S, A>, probe: [Length; 3]) -> [Force; 3] {
        solver.step(probe)
    }
}

/// The probe touching a tissue of shape `Sh` (flat by default, or a cap) through a proxy
/// with friction, the patch following the contact as a window
/// ([`Solver::step_roaming`]); the probe in the tissue frame.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Roaming<const EDGES: usize, Sh: Shape = Flat> {
    /// The proxy (from `Solver::proxy`).
    pub proxy: Proxy,
    /// The window (from `Solver::window`).
    pub window: Window<EDGES, Sh>,
}

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith, Sh: Shape>
    Contact<NODES, EDGES, S, A> for Roaming<EDGES, Sh>
{
    fn step(&mut self, solver: &mut Solver<NODES, EDGES, S, A>, probe: [Length; 3]) -> [Force; 3] {
        solver.step_roaming(probe, &mut self.proxy, &mut self.window)
    }

    fn window_shifts(&self) -> u32 {
        self.window.shifts()
    }
}

/// Why the controller is in its safe state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// The device could not read the probe.
    Read,
    /// The device could not render the force.
    Write,
}

impl Fault {
    /// The message: one source for `Display` and the `defmt` impl.
    pub const fn message(&self) -> &'static str {
        match self {
            Self::Read => "device read failed",
            Self::Write => "device write failed",
        }
    }
}

impl core::fmt::Display for Fault {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.message())
    }
}

/// What the tick publishes for the main loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Telemetry {
    /// Ticks run.
    pub ticks: u32,
    /// The force rendered in the last tick, N.
    pub force: [Force; 3],
    /// The largest force on any axis so far, N (absolute value).
    pub max_force: Force,
    /// The force along `z` at the steady tick (see [`Controller::new`]), N.
    pub steady_force: Force,
    /// Ticks that overran their budget (counted by the firmware).
    pub overruns: u32,
    /// The safe state, if entered.
    pub fault: Option<Fault>,
    /// Window shifts so far (roaming contact; 0 when glued).
    pub window_shifts: u32,
    /// Parameter sets applied so far.
    pub swaps: u32,
    /// Parameter sets refused (prepared for another topology or tick rate).
    pub rejected_swaps: u32,
    /// Ticks on which putting the device in its safe state itself reported an error.
    pub safe_state_errors: u32,
}

impl Telemetry {
    /// Before the first tick.
    pub const fn new() -> Self {
        Self {
            ticks: 0,
            force: [Force::ZERO; 3],
            max_force: Force::ZERO,
            steady_force: Force::ZERO,
            overruns: 0,
            fault: None,
            window_shifts: 0,
            swaps: 0,
            rejected_swaps: 0,
            safe_state_errors: 0,
        }
    }
}

impl Default for Telemetry {
    fn default() -> Self {
        Self::new()
    }
}

/// A solver driving a device.
#[derive(Debug)]
pub struct Controller<
    D,
    const NODES: usize,
    const EDGES: usize,
    const S: usize,
    A: Arith = DefaultArith,
    C = Glued,
> {
    solver: Solver<NODES, EDGES, S, A>,
    contact: C,
    device: D,
    steady_tick: u32,
    telemetry: Telemetry,
}

impl<D: HapticDevice, const NODES: usize, const EDGES: usize, const S: usize, A: Arith>
    Controller<D, NODES, EDGES, S, A, Glued>
{
    /// A controller with the probe glued to the patch ([`Glued`]); the force along `z` at
    /// tick `steady_tick` (0-based) is recorded as the steady force.
    pub fn new(solver: Solver<NODES, EDGES, S, A>, device: D, steady_tick: u32) -> Self {
        Self::with_contact(solver, Glued, device, steady_tick)
    }
}

impl<
        D: HapticDevice,
        const NODES: usize,
        const EDGES: usize,
        const S: usize,
        A: Arith,
        C: Contact<NODES, EDGES, S, A>,
    > Controller<D, NODES, EDGES, S, A, C>
{
    /// A controller with the probe touching the tissue through `contact`; the force along
    /// `z` at tick `steady_tick` (0-based) is recorded as the steady force.
    pub fn with_contact(
        solver: Solver<NODES, EDGES, S, A>,
        contact: C,
        device: D,
        steady_tick: u32,
    ) -> Self {
        Self {
            solver,
            contact,
            device,
            steady_tick,
            telemetry: Telemetry::new(),
        }
    }

    /// One tick. `swap`, if given, is applied first, between this tick and the last.
    /// Returns the force rendered.
    pub fn tick(&mut self, swap: Option<ParamSet<S, A>>) -> [Force; 3] {
        if let Some(set) = swap {
            let t = &mut self.telemetry;
            match self.solver.apply(set) {
                Ok(()) => t.swaps = t.swaps.saturating_add(1),
                Err(_) => t.rejected_swaps = t.rejected_swaps.saturating_add(1),
            }
        }
        let force = if self.telemetry.fault.is_some() {
            self.safe_state();
            [Force::ZERO; 3]
        } else {
            match self.device.read_position() {
                Ok(probe) => {
                    let force = self.contact.step(&mut self.solver, probe);
                    self.telemetry.window_shifts = self.contact.window_shifts();
                    if self.device.write_force(force).is_ok() {
                        force
                    } else {
                        self.enter_safe_state(Fault::Write)
                    }
                }
                Err(_) => self.enter_safe_state(Fault::Read),
            }
        };
        let t = &mut self.telemetry;
        if t.ticks == self.steady_tick {
            t.steady_force = force[2];
        }
        for f in force {
            t.max_force = t.max_force.max(f.saturating_abs());
        }
        t.force = force;
        t.ticks = t.ticks.saturating_add(1);
        force
    }

    /// Latches `fault` and puts the device in its safe state; the force is zero.
    fn enter_safe_state(&mut self, fault: Fault) -> [Force; 3] {
        self.telemetry.fault = Some(fault);
        self.safe_state();
        [Force::ZERO; 3]
    }

    /// The device's safe state, its errors counted.
    fn safe_state(&mut self) {
        if self.device.safe_state().is_err() {
            let t = &mut self.telemetry;
            t.safe_state_errors = t.safe_state_errors.saturating_add(1);
        }
    }

    /// Counts a tick that overran its budget.
    pub fn note_overrun(&mut self) {
        self.telemetry.overruns = self.telemetry.overruns.saturating_add(1);
    }

    /// The statistics so far.
    pub fn telemetry(&self) -> Telemetry {
        self.telemetry
    }

    /// The solver.
    pub fn solver(&self) -> &Solver<NODES, EDGES, S, A> {
        &self.solver
    }

    /// The contact.
    pub fn contact(&self) -> &C {
        &self.contact
    }

    /// The device.
    pub fn device(&self) -> &D {
        &self.device
    }

    /// The device, to set what it holds between ticks (a link's pose and gain).
    pub fn device_mut(&mut self) -> &mut D {
        &mut self.device
    }

    /// The solver and the device back.
    pub fn into_parts(self) -> (Solver<NODES, EDGES, S, A>, D) {
        (self.solver, self.device)
    }
}
