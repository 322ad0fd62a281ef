//! The board's arm loop closed through the arm's body: the board's own arm device and
//! roaming controller (`haptic_f405::arm`, as the board builds them) read the counts of
//! an [`ArmBody`] and drive its amplifiers, and a [`Hand`] leads the probe home, down to
//! the tissue and along the demo's palpation. Each tick: the counts are read, the tick
//! runs, and its duties reach the motors after the read-to-write delay (the tick's
//! budget, half a tick: the latest they may), through ten steps of the body a tick.

use super::dynamics::{ArmBody, BodySpec, Hand};
pub use super::lead::{HoldAt, Lead, LEAD_TICKS};
use embedded_hal::digital::{ErrorType, InputPin, OutputPin};
use haptic_f405::arm::{arm_controller_into, arm_device, LinkedArm};
use haptic_f405::config::BoardConfig;
use haptic_f405::device::{BoardController, BoardRoaming, DevicePart};
use haptic_f405::tissue::TISSUE;
use mccs::ArmSpec;
use mccs_firmware::arm::device::{Joint, PartFailed};
use mccs_firmware::arm::plant::HOME_TICKS;
use nalgebra::Vector3;
use std::cell::RefCell;
use std::rc::Rc;

/// Body steps per tick.
pub const STEPS_PER_TICK: u32 = 10;
/// Steps of a tick before its duties reach the motors: half a tick, the tick's budget.
pub const DELAY_STEPS: u32 = STEPS_PER_TICK / 2;
/// A PWM channel's full scale (the board's TIM1 at 20 kHz from 168 MHz).
const MAX_DUTY: u16 = 8400;

/// What the board's parts read and were last given.
#[derive(Clone, Copy, Debug, Default)]
struct Wires {
    counts: [i32; 3],
    pwm: [u16; 3],
    forward: [bool; 3],
    enabled: bool,
    home: bool,
}

type Shared = Rc<RefCell<Wires>>;

/// Joint `k`'s counter, PWM channel and direction pin.
pub struct BodyJoint(usize, Shared);
impl Joint for BodyJoint {
    fn read(&mut self) -> Result<u16, PartFailed> {
        Ok(self.1.borrow().counts[self.0] as u16)
    }
    fn duty(&mut self, duty: u16) -> Result<(), PartFailed> {
        self.1.borrow_mut().pwm[self.0] = duty.min(MAX_DUTY);
        Ok(())
    }
    fn direction(&mut self, forward: bool) -> Result<(), PartFailed> {
        self.1.borrow_mut().forward[self.0] = forward;
        Ok(())
    }
    fn max_duty(&self) -> u16 {
        MAX_DUTY
    }
}

/// The driver's enable.
pub struct BodyEnable(Shared);
impl ErrorType for BodyEnable {
    type Error = core::convert::Infallible;
}
impl OutputPin for BodyEnable {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        self.0.borrow_mut().enabled = false;
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), Self::Error> {
        self.0.borrow_mut().enabled = true;
        Ok(())
    }
}

/// The home input.
pub struct BodyHome(Shared);
impl ErrorType for BodyHome {
    type Error = core::convert::Infallible;
}
impl InputPin for BodyHome {
    fn is_high(&mut self) -> Result<bool, Self::Error> {
        Ok(self.0.borrow().home)
    }
    fn is_low(&mut self) -> Result<bool, Self::Error> {
        Ok(!self.0.borrow().home)
    }
}

/// The board's controller on the body's parts.
pub type BodyController =
    BoardController<LinkedArm<BodyJoint, BodyJoint, BodyJoint, BodyEnable, BodyHome>, BoardRoaming>;

/// The loop: the body, the hand, the board's controller, the lead.
pub struct ClosedLoop {
    /// The arm's body.
    pub body: ArmBody,
    /// The hand on the handle (change it to let go).
    pub hand: Hand,
    /// Where the hand leads.
    pub lead: Lead,
    ctl: BodyController,
    wires: Shared,
    /// The lead's clock: it waits at home while the board checks its motors' directions.
    tick: u32,
    /// Ticks the lead waited so.
    checking: u32,
    /// The work the device did on the body over those ticks (the nudges'), J.
    nudged_j: f64,
    tick_hz: f64,
}

/// Why the loop could not be built: the board refused its configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct Refused(pub String);

impl ClosedLoop {
    /// The board of `config` on the arm of `spec` with the body `body`, held by `hand`,
    /// at home.
    pub fn new(
        config: &BoardConfig,
        spec: &ArmSpec,
        body: BodySpec,
        hand: Hand,
    ) -> Result<Self, Refused> {
        let wires: Shared = Rc::default();
        let joint = |k| BodyJoint(k, wires.clone());
        let device = arm_device(
            config,
            spec,
            (joint(0), joint(1), joint(2)),
            BodyEnable(wires.clone()),
            BodyHome(wires.clone()),
        )
        .map_err(|e| Refused(e.fault().to_string()))?;
        let mut slot = None;
        arm_controller_into(config, TISSUE, device, &mut slot)
            .map_err(|(e, _)| Refused(e.fault().to_string()))?;
        let mut ctl: BodyController = slot.ok_or_else(|| Refused("no controller".into()))?;
        // Full force at once (the link's guard ramps it on the board).
        ctl.device_mut().set_gain(u16::MAX);
        Ok(Self {
            body: ArmBody::new(*spec, body),
            hand,
            lead: Lead::palpation(config, spec),
            ctl,
            wires,
            tick: 0,
            checking: 0,
            nudged_j: 0.0,
            tick_hz: config.tick_hz as f64,
        })
    }

    /// The lead's ticks: those run, less the ticks it waited at home for the board's
    /// direction check ([`ClosedLoop::checking_ticks`]).
    pub fn ticks(&self) -> u32 {
        self.tick
    }

    /// Ticks the lead waited at home, its home input released, while the board nudged
    /// each joint ([`mccs_firmware::arm::device::DirectionCheck`]).
    pub fn checking_ticks(&self) -> u32 {
        self.checking
    }

    /// The energy the device rendered into the body and hand over the run, less its
    /// direction check's nudges (work it means to do), mJ (positive: put out).
    pub fn rendered_mj(&self) -> f64 {
        (self.body.rendered_j - self.nudged_j) * 1e3
    }

    /// The nudges' work, mJ.
    pub fn nudged_mj(&self) -> f64 {
        self.nudged_j * 1e3
    }

    /// The joint the board's direction check drives now, if any.
    pub fn nudging(&self) -> Option<u8> {
        self.ctl.device().inner().direction_nudging()
    }

    /// Whether the board is checking its motors' directions (homed, its home input
    /// released, no verdict yet): the hand waits at home, still.
    fn checking(&self) -> bool {
        let arm = self.ctl.device().inner();
        self.tick >= HOME_TICKS && !arm.direction_checked() && self.fault().is_none()
    }

    /// The board's fault, if it has one.
    /// (With the part that failed, as the board's log names it.)
    pub fn fault(&self) -> Option<String> {
        let fault = self.ctl.telemetry().fault?;
        Some(match self.ctl.device_error() {
            Some(e) => format!("{fault}: {}", DevicePart::from(e).name()),
            None => fault.to_string(),
        })
    }

    /// The driver is off and every duty is zero: the safe state.
    pub fn safe(&self) -> bool {
        let w = self.wires.borrow();
        !w.enabled && w.pwm == [0; 3]
    }

    /// The motors' commanded currents, A, from the parts' state.
    fn command(&self) -> [f64; 3] {
        let w = *self.wires.borrow();
        std::array::from_fn(|k| {
            if !w.enabled {
                return 0.0;
            }
            let sign = if w.forward[k] { 1.0 } else { -1.0 };
            sign * w.pwm[k] as f64 / MAX_DUTY as f64 * self.lead.spec().joints[k].max_current_a
        })
    }

    /// One tick: counts read, the board's tick, the body driven through it. The force
    /// the tick rendered, N (tissue frame).
    pub fn step(&mut self) -> [f64; 3] {
        {
            let mut w = self.wires.borrow_mut();
            w.counts = self.body.counts();
            w.home = self.tick < HOME_TICKS;
        }
        let before = self.command();
        let force = self.ctl.tick(None).map(|f| f.to_num::<f64>());
        let after = self.command();
        let led = |t: u32| Vector3::from(self.lead.at(t)) / 1000.0;
        let waiting = self.checking();
        let next = if waiting { self.tick } else { self.tick + 1 };
        let (from, to) = (led(self.tick), led(next));
        let velocity = (to - from) * self.tick_hz;
        let dt = 1.0 / (self.tick_hz * STEPS_PER_TICK as f64);
        let rendered = self.body.rendered_j;
        for i in 0..STEPS_PER_TICK {
            let command = if i < DELAY_STEPS { before } else { after };
            let at = from + (to - from) * (i as f64 / STEPS_PER_TICK as f64);
            self.body.step(dt, command, &self.hand, at, velocity);
        }
        if waiting {
            self.checking += 1;
            self.nudged_j += self.body.rendered_j - rendered;
        } else {
            self.tick += 1;
        }
        force
    }

    /// The probe in the tissue's frame, mm.
    pub fn probe_mm(&self) -> [f64; 3] {
        let p = self.body.probe().0;
        std::array::from_fn(|k| p[k] * 1000.0 - self.lead.origin[k])
    }
}

/// A held press waits this long above the tissue (the hand catching up with its lead),
/// then goes down over as long, ticks.
pub const PRESS_TICKS: u32 = 500;

/// A press held: what [`hold`] measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Held {
    /// Each joint's cycle over the window, counts: the range (largest less smallest) of
    /// its counts about their moving mean ([`CYCLE_MEAN_TICKS`]; a press that still
    /// creeps as the tissue relaxes is not a cycle).
    pub cycle_counts: [f64; 3],
    /// The energy the device rendered over the window, mJ (positive: put into the hand).
    pub window_mj: f64,
    /// Over the whole run.
    pub run_mj: f64,
    /// The energy of one count ([`COUNT_AT_PROBE_MM`]) in the coupling's spring, mJ:
    /// `½ k c²`, what where the run ends within a count leaves `run_mj` unknown by.
    pub count_mj: f64,
    /// The largest force over the window, N.
    pub most_n: f64,
    /// The board's fault, and its tick.
    pub fault: Option<(u32, String)>,
}

/// The hand leads the probe down to just above the tissue at the palpation's start,
/// waits there, goes `depth_mm` into it (each [`PRESS_TICKS`]) and holds; `settle`
/// ticks later, a window of `window` ticks.
pub fn hold(
    config: &BoardConfig,
    spec: &ArmSpec,
    body: BodySpec,
    hand: Hand,
    depth_mm: f64,
    settle: u32,
    window: u32,
) -> Result<Held, Refused> {
    let count_mj = 0.5 * config.coupling_stiffness * COUNT_AT_PROBE_MM * COUNT_AT_PROBE_MM;
    let mut lp = ClosedLoop::new(config, spec, body, hand)?;
    let start = lp.lead.at(LEAD_TICKS);
    lp.lead.hold = Some(HoldAt {
        from: LEAD_TICKS,
        wait: PRESS_TICKS,
        ramp: PRESS_TICKS,
        to: [start[0], start[1], lp.lead.device([0.0; 3])[2] - depth_mm],
    });
    let settle = settle + 2 * PRESS_TICKS;
    let end = LEAD_TICKS + settle + window;
    let mut seen: Vec<[i32; 3]> = Vec::with_capacity(window as usize);
    let mut before = 0.0;
    let mut most = 0.0f64;
    while lp.ticks() < end {
        let t = lp.ticks();
        if t == LEAD_TICKS + settle {
            before = lp.body.rendered_j;
        }
        let f = lp.step();
        if let Some(fault) = lp.fault() {
            return Ok(Held {
                cycle_counts: [f64::INFINITY; 3],
                window_mj: f64::NAN,
                run_mj: lp.rendered_mj(),
                count_mj,
                most_n: most,
                fault: Some((t, fault)),
            });
        }
        if t >= LEAD_TICKS + settle {
            seen.push(lp.body.counts());
            most = most.max(f.iter().map(|x| x * x).sum::<f64>().sqrt());
        }
    }
    Ok(Held {
        cycle_counts: std::array::from_fn(|k| cycle_range(seen.iter().map(|c| c[k] as f64))),
        window_mj: (lp.body.rendered_j - before) * 1e3,
        run_mj: lp.rendered_mj(),
        count_mj,
        most_n: most,
        fault: None,
    })
}

/// The hands the stable region is measured with: the corners of the range a hand on a
/// surgical trainer's handle spans (0.1–0.5 kg, 2–10 N·s/m, 100–1000 N/m).
pub const HANDS: [Hand; 8] = {
    let mut hands = [Hand::OFF; 8];
    let mut i = 0;
    while i < 8 {
        hands[i] = Hand {
            mass_kg: if i & 1 == 0 { 0.1 } else { 0.5 },
            damping_n_s_m: if i & 2 == 0 { 2.0 } else { 10.0 },
            stiffness_n_m: if i & 4 == 0 { 100.0 } else { 1000.0 },
        };
        i += 1;
    }
    hands
};

/// How deep the hand leads a held press, mm.
pub const HOLD_DEPTH_MM: f64 = 3.0;
/// Ticks a held press settles, then the ticks it is watched.
pub const HOLD_SETTLE: u32 = 2000;
/// See [`HOLD_SETTLE`].
pub const HOLD_WINDOW: u32 = 1000;
/// The largest cycle a joint may show over a held press's window, counts (no limit
/// cycle above it).
pub const STILL_COUNTS: f64 = 2.0;

/// Ticks of the moving mean a joint's cycle is measured about (0.1 s at 1 kHz).
pub const CYCLE_MEAN_TICKS: usize = 101;

/// The range of `xs` less their centred moving mean over [`CYCLE_MEAN_TICKS`] (where the
/// mean has its whole span): a cycle, not a creep.
fn cycle_range(xs: impl Iterator<Item = f64>) -> f64 {
    let xs: Vec<f64> = xs.collect();
    let w = CYCLE_MEAN_TICKS;
    if xs.len() < w {
        return 0.0;
    }
    let mut sum: f64 = xs[..w].iter().sum();
    let (mut lo, mut hi) = (f64::MAX, f64::MIN);
    for i in 0..=xs.len() - w {
        if i > 0 {
            sum += xs[i + w - 1] - xs[i - 1];
        }
        let r = xs[i + w / 2] - sum / w as f64;
        lo = lo.min(r);
        hi = hi.max(r);
    }
    hi - lo
}

/// Whether a held press is stable: no fault, no joint's counts spread over
/// [`STILL_COUNTS`], no net energy out of the device over the run beyond one count's in
/// the coupling ([`Held::count_mj`]: the force is a whole count's, so the energy a run
/// ends with is known to no better; a loop that pumps energy gains more with every
/// cycle); or why not.
pub fn verdict(h: &Held) -> Result<(), String> {
    if let Some((t, f)) = &h.fault {
        return Err(format!("the board faulted at tick {t}: {f}"));
    }
    if let Some(k) = (0..3).find(|&k| h.cycle_counts[k] > STILL_COUNTS) {
        return Err(format!(
            "joint {} cycles over {:.1} counts",
            ["A", "B", "C"][k],
            h.cycle_counts[k]
        ));
    }
    if h.run_mj > h.count_mj {
        return Err(format!(
            "the device put out {:.3} mJ net, over a count's {:.3} mJ in the coupling",
            h.run_mj, h.count_mj
        ));
    }
    Ok(())
}

/// [`hold`] as the stable region measures it: [`HOLD_DEPTH_MM`] deep, after
/// [`HOLD_SETTLE`], over [`HOLD_WINDOW`].
pub fn held_press(
    config: &BoardConfig,
    spec: &ArmSpec,
    body: BodySpec,
    hand: Hand,
) -> Result<Held, Refused> {
    held_press_at(config, spec, body, hand, 0)
}

/// One encoder count at the probe, mm: joint C's, the forearm's 245 mm over its 24,000
/// counts a turn (`arm_dynamics::the_count_at_the_probe_is_the_forearm_s` holds it to the
/// device file; docs/safety.md, "The probe's velocity").
pub const COUNT_AT_PROBE_MM: f64 = 0.064;

/// The holds a hand's verdict takes: [`HOLD_DEPTH_MM`] and deeper by fifths of
/// [`COUNT_AT_PROBE_MM`], so that where the press rests within a count, which decides a
/// count's limit cycle, is sampled, not fixed.
pub const HOLDS_PER_HAND: usize = 5;

/// The `i`th of a hand's holds ([`HOLDS_PER_HAND`]).
fn held_press_at(
    config: &BoardConfig,
    spec: &ArmSpec,
    body: BodySpec,
    hand: Hand,
    i: usize,
) -> Result<Held, Refused> {
    let depth = HOLD_DEPTH_MM + COUNT_AT_PROBE_MM * i as f64 / HOLDS_PER_HAND as f64;
    hold(config, spec, body, hand, depth, HOLD_SETTLE, HOLD_WINDOW)
}

/// Whether a hand's press is stable, as the stable region judges it: held at each of
/// [`HOLDS_PER_HAND`] depths across one count, it is not stable when most of them are not
/// ([`verdict`]); the first such hold's reason, and how many were not stable. A count's
/// limit cycle can put a press out a fraction of a mJ at one depth in a count and not
/// at the next (docs/safety.md, "The stable region"); a loop past its edge does so at
/// most depths. It stops once most holds agree.
pub fn hand_verdict(
    config: &BoardConfig,
    spec: &ArmSpec,
    body: BodySpec,
    hand: Hand,
) -> Result<Result<(), String>, Refused> {
    let most = HOLDS_PER_HAND / 2 + 1;
    let (mut stable, mut not, mut first_why) = (0, 0, String::new());
    for i in 0..HOLDS_PER_HAND {
        if stable >= most || not >= most {
            break;
        }
        if let Err(why) = verdict(&held_press_at(config, spec, body, hand, i)?) {
            if not == 0 {
                first_why = why;
            }
            not += 1;
        } else {
            stable += 1;
        }
    }
    Ok(if not >= most {
        Err(format!("{first_why} ({not} of {} holds)", stable + not))
    } else {
        Ok(())
    })
}

/// [`hand_verdict`] for each of `hands`, in their order, judged side by side (one thread
/// each).
pub fn hand_verdicts(
    config: &BoardConfig,
    spec: &ArmSpec,
    body: BodySpec,
    hands: &[Hand],
) -> Vec<Result<Result<(), String>, Refused>> {
    std::thread::scope(|s| {
        let runs: Vec<_> = hands
            .iter()
            .map(|hand| s.spawn(|| hand_verdict(config, spec, body, *hand)))
            .collect();
        runs.into_iter()
            .map(|r| {
                r.join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
            })
            .collect()
    })
}

/// The coupling stiffnesses tried, N/mm: 0.25 to 1024 by factors of √2.
pub fn stiffness_grid() -> impl Iterator<Item = f64> {
    (0..=24).map(|i| 0.25 * 2f64.powf(i as f64 / 2.0))
}

/// The stable region's edge at one damping: the largest coupling stiffness on
/// [`stiffness_grid`] below the first that is not stable with every hand of `hands`
/// ([`hand_verdict`]), and why that one is not (the first such hand's reason; the board
/// refusing it; or the grid's end). `progress` is called with each stiffness tried. The
/// hands are judged side by side ([`hand_verdicts`]).
pub fn largest_stable(
    config: &BoardConfig,
    spec: &ArmSpec,
    body: BodySpec,
    hands: &[Hand],
    damping: f64,
    mut progress: impl FnMut(f64),
) -> (f64, String) {
    let mut best = 0.0;
    for k in stiffness_grid() {
        progress(k);
        let cfg = BoardConfig {
            coupling_stiffness: k,
            coupling_damping: damping,
            ..*config
        };
        for (hand, v) in hands.iter().zip(hand_verdicts(&cfg, spec, body, hands)) {
            let why = match v {
                Err(Refused(e)) => format!("the board refuses it: {e}"),
                Ok(Ok(())) => continue,
                Ok(Err(e)) => format!(
                    "{e} (hand {} kg, {} N·s/m, {} N/m)",
                    hand.mass_kg, hand.damping_n_s_m, hand.stiffness_n_m
                ),
            };
            return (best, format!("{k:.3} N/mm: {why}"));
        }
        best = k;
    }
    (best, "the grid's end".into())
}
