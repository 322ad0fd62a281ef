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
    /// Takes new friction coefficients; false for a contact without friction.
    fn set_friction(&mut self, _friction: mccs::Friction) -> bool {
        false
    }
    /// The friction in use, for a contact with friction.
    fn friction(&self) -> Option<mccs::Friction> {
        None
    }
    /// Where the contact is after a tick (`None`: a contact that does not know, the
    /// glued one: the force says it).
    fn state(&self, _solver: &Solver<NODES, EDGES, S, A>) -> Option<ContactState> {
        None
    }
}

/// Where a roaming contact is: touching or not, slipping or not, the proxy's point and
/// the window's origin in the tissue's frame (Q24 mm).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ContactState {
    /// The proxy is on the surface.
    pub touching: bool,
    /// It slides (kinetic friction).
    pub slipping: bool,
    /// The proxy's point, tissue frame (zero out of contact).
    pub proxy: [i32; 3],
    /// The window's origin (the patch's centre), tissue frame.
    pub window: [i32; 2],
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
/// ([`Solver::step_roaming_at`]); the probe in the tissue frame.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Roaming<const EDGES: usize, Sh: Shape = Flat> {
    /// The proxy (from `Solver::proxy`).
    pub proxy: Proxy,
    /// The window (from `Solver::window`).
    pub window: Window<EDGES, Sh>,
    /// The probe's velocity for the coupling's damping: a tracker on the probe's
    /// quantised positions (the arm's: `mccs::velocity`); `None`, the solver's one-tick
    /// difference.
    pub velocity: Option<mccs::TrackedVelocity>,
}

impl<const EDGES: usize, Sh: Shape> Roaming<EDGES, Sh> {
    /// The contact on `proxy` and `window`, its velocity the one-tick difference.
    pub fn new(proxy: Proxy, window: Window<EDGES, Sh>) -> Self {
        Self {
            proxy,
            window,
            velocity: None,
        }
    }

    /// Its velocity from a tracker with `gains`.
    pub fn with_velocity_tracker(mut self, gains: mccs::TrackerGains) -> Self {
        self.velocity = Some(mccs::TrackedVelocity::new(gains));
        self
    }
}

impl<const NODES: usize, const EDGES: usize, const S: usize, A: Arith, Sh: Shape>
    Contact<NODES, EDGES, S, A> for Roaming<EDGES, Sh>
{
    fn step(&mut self, solver: &mut Solver<NODES, EDGES, S, A>, probe: [Length; 3]) -> [Force; 3] {
        let velocity = self.velocity.as_mut().map(|v| v.update(probe));
        solver.step_roaming_at(probe, velocity, &mut self.proxy, &mut self.window)
    }

    fn window_shifts(&self) -> u32 {
        self.window.shifts()
    }

    fn set_friction(&mut self, friction: mccs::Friction) -> bool {
        self.proxy.set_friction(friction);
        true
    }

    fn friction(&self) -> Option<mccs::Friction> {
        Some(self.proxy.friction())
    }

    fn state(&self, solver: &Solver<NODES, EDGES, S, A>) -> Option<ContactState> {
        let origin = self.window.origin_mm().map(Length::to_bits);
        let touching = self.proxy.grid_position().is_some();
        let proxy = solver
            .proxy_point_in(&self.proxy, &self.window)
            .map_or([0; 3], |p| {
                let b = p.map(Length::to_bits);
                [
                    b[0].saturating_add(origin[0]),
                    b[1].saturating_add(origin[1]),
                    b[2],
                ]
            });
        Some(ContactState {
            touching,
            slipping: self.proxy.slipping(),
            proxy,
            window: origin,
        })
    }
}

/// Why the controller is in its safe state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// The device could not read the probe.
    Read,
    /// The device could not render the force.
    Write,
    /// Ticks overran their period too many times in a row
    /// ([`Controller::set_overrun_limit`]).
    Overruns,
    /// The drive was cut outside the MCU (the board's break input: the emergency stop or
    /// an amplifier's fault output), [`Controller::stop`].
    Amplifier,
}

impl Fault {
    /// The message: one source for `Display` and the `defmt` impl.
    pub const fn message(&self) -> &'static str {
        match self {
            Self::Read => "device read failed",
            Self::Write => "device write failed",
            Self::Overruns => "ticks overran their period too many times in a row",
            Self::Amplifier => "the emergency stop or an amplifier fault cut the drive",
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
    /// Overruns in a row, up to the last tick.
    pub overruns_in_row: u32,
    /// The force was held to the coupling's clamp on the last tick.
    pub clamped: bool,
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
            overruns_in_row: 0,
            clamped: false,
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
    D: HapticDevice,
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
    /// Overruns in a row that end in the safe state (0: never).
    overrun_limit: u32,
    /// The device's error that put it in the safe state, if one did.
    device_error: Option<D::Error>,
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
            overrun_limit: 0,
            device_error: None,
        }
    }

    /// A run of `limit` overruns in a row ends in the safe state ([`Fault::Overruns`]);
    /// 0: overruns are only counted.
    pub fn set_overrun_limit(&mut self, limit: u32) {
        self.overrun_limit = limit;
    }

    /// Swaps in a new tissue between two ticks: its parameter set and, for a contact
    /// with friction, its friction (`None`: kept). Counted in the telemetry; a set
    /// prepared for another topology or tick rate is refused, and nothing changes.
    pub fn swap_tissue(&mut self, set: ParamSet<S, A>, friction: Option<mccs::Friction>) -> bool {
        let t = &mut self.telemetry;
        match self.solver.apply(set) {
            Ok(()) => {
                t.swaps = t.swaps.saturating_add(1);
                if let Some(f) = friction {
                    self.contact.set_friction(f);
                }
                true
            }
            Err(_) => {
                t.rejected_swaps = t.rejected_swaps.saturating_add(1);
                false
            }
        }
    }

    /// One tick. `swap`, if given, is applied first, between this tick and the last.
    /// Returns the force rendered.
    pub fn tick(&mut self, swap: Option<ParamSet<S, A>>) -> [Force; 3] {
        if let Some(set) = swap {
            self.swap_tissue(set, None);
        }
        let force = if self.telemetry.fault.is_some() {
            self.safe_state();
            [Force::ZERO; 3]
        } else {
            match self.device.read_position() {
                Ok(probe) => {
                    let force = self.contact.step(&mut self.solver, probe);
                    self.telemetry.window_shifts = self.contact.window_shifts();
                    match self.device.write_force(force) {
                        Ok(()) => force,
                        Err(e) => {
                            self.device_error = Some(e);
                            self.enter_safe_state(Fault::Write)
                        }
                    }
                }
                Err(e) => {
                    self.device_error = Some(e);
                    self.enter_safe_state(Fault::Read)
                }
            }
        };
        let clamped = is_clamped(force, self.solver.max_force());
        let t = &mut self.telemetry;
        t.clamped = clamped;
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

    /// Counts a tick that overran its budget; the limit's run of them in a row puts
    /// the device in its safe state.
    pub fn note_overrun(&mut self) {
        let t = &mut self.telemetry;
        t.overruns = t.overruns.saturating_add(1);
        t.overruns_in_row = t.overruns_in_row.saturating_add(1);
        if self.overrun_limit != 0 && t.overruns_in_row >= self.overrun_limit && t.fault.is_none() {
            self.enter_safe_state(Fault::Overruns);
        }
    }

    /// Latches `fault` from outside the tick's own checks (the board's break input): the
    /// device's safe state at once, and every tick after. The first fault stays the one
    /// reported.
    pub fn stop(&mut self, fault: Fault) {
        if self.telemetry.fault.is_none() {
            self.enter_safe_state(fault);
        }
    }

    /// A tick that ended within its budget: the run of overruns is over.
    pub fn note_on_time(&mut self) {
        self.telemetry.overruns_in_row = 0;
    }

    /// The device's error that put it in the safe state (the first fault's, if it was
    /// a failed read or write; `None` otherwise).
    pub fn device_error(&self) -> Option<&D::Error> {
        self.device_error.as_ref()
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

    /// Where the contact is, on a contact that knows.
    pub fn contact_state(&self) -> Option<ContactState> {
        self.contact.state(&self.solver)
    }

    /// The solver and the device back.
    pub fn into_parts(self) -> (Solver<NODES, EDGES, S, A>, D) {
        (self.solver, self.device)
    }
}

/// Whether `f` was held to the clamp `max`: an axis at it (glued, per axis), or its
/// magnitude within 1/256 of it (through a proxy, in magnitude).
fn is_clamped(f: [Force; 3], max: Force) -> bool {
    let m = max.to_bits();
    let near = m - (m >> 8);
    let b = f.map(|c| c.to_bits());
    if b.iter().any(|&c| c.saturating_abs() >= near) {
        return true;
    }
    // (In `u64`: three squares of up to 2⁶² each; in `i64` they overflowed for a clamp
    // past 1,672 N, with every axis just under it.)
    let f2: u64 = b.iter().map(|&c| (c as i64 * c as i64) as u64).sum();
    f2 >= (near as i64 * near as i64) as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A clamp near the largest the solver takes (1,999.99 N): a force just under it on
    /// every axis is clamped by its magnitude; its three squares passed an `i64` and
    /// overflowed (a panic with overflow checks, a wrapped verdict without), for any clamp
    /// past 1,672 N.
    #[test]
    fn a_force_near_a_large_clamp_on_every_axis_is_clamped() {
        let max = Force::from_num(1999.99);
        assert!(is_clamped([Force::from_num(1990.0); 3], max));
        assert!(is_clamped([Force::from_num(-1990.0); 3], max));
        assert!(is_clamped([Force::from_num(1200.0); 3], max));
        assert!(!is_clamped(
            [Force::from_num(1100.0), Force::ZERO, Force::ZERO],
            max
        ));
        assert!(is_clamped([Force::MIN, Force::ZERO, Force::ZERO], max));
    }
}
