//! The arm as a device (`mccs_firmware::arm::device`): the encoders' 16-bit counts carried
//! to 32 bits at any speed the arm reaches, no force before homing, and a fault injected
//! at every device call ending with every duty at zero and the driver disabled.

use mccs::{Arm, Force, Length, PassivityLimits};
use mccs_firmware::arm::device::{
    ArmDevice, ArmFault, Joint, PartFailed, SpeedLimits, Thermal, Trims, Walls,
};
use mccs_firmware::arm::encoder::Extended;
use mccs_firmware::HapticDevice;
use proptest::prelude::*;
use std::cell::Cell;
use std::rc::Rc;

proptest! {
    /// Steps of up to ±32,767 counts a tick (beyond any arm's speed), the counter
    /// wrapping at 16 bits: the carried count is the true one.
    #[test]
    fn the_count_is_carried_past_16_bits(start in any::<i32>(), steps in proptest::collection::vec(-32_767i32..=32_767, 1..500)) {
        let mut truth = start as i64;
        let mut e = Extended::new(start as u16, start);
        for s in steps {
            truth += s as i64;
            let raw = truth as u16;
            let got = e.update(raw);
            prop_assert_eq!(got, truth as i32);
        }
    }
}

/// The shipped WoodenHaptics device file.
fn wooden() -> mccs::ArmSpec {
    mccs_host::arm::device_file::read(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../devices/woodenhaptics.toml"
    )))
    .unwrap()
}

/// Every call the device makes, numbered; the one numbered `fail_at` fails.
#[derive(Default)]
struct Calls {
    n: Cell<usize>,
    fail_at: Cell<Option<usize>>,
}

impl Calls {
    fn call(&self) -> Result<(), PartFailed> {
        let n = self.n.get();
        self.n.set(n + 1);
        if self.fail_at.get() == Some(n) {
            Err(PartFailed)
        } else {
            Ok(())
        }
    }
}

/// A joint in memory: its counter, its last duty and direction.
struct MockJoint {
    calls: Rc<Calls>,
    raw: Rc<Cell<u16>>,
    duty: Rc<Cell<u16>>,
    forward: Rc<Cell<Option<bool>>>,
}

impl Joint for MockJoint {
    fn read(&mut self) -> Result<u16, PartFailed> {
        self.calls.call().map(|()| self.raw.get())
    }
    fn duty(&mut self, d: u16) -> Result<(), PartFailed> {
        self.calls.call()?;
        self.duty.set(d);
        Ok(())
    }
    fn direction(&mut self, f: bool) -> Result<(), PartFailed> {
        self.calls.call()?;
        self.forward.set(Some(f));
        Ok(())
    }
    fn max_duty(&self) -> u16 {
        4200
    }
}

/// A pin in memory.
struct Pin {
    calls: Rc<Calls>,
    level: Rc<Cell<bool>>,
}

impl embedded_hal::digital::ErrorType for Pin {
    type Error = core::convert::Infallible;
}

impl embedded_hal::digital::OutputPin for Pin {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        self.level.set(false);
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), Self::Error> {
        self.level.set(true);
        Ok(())
    }
}

/// A failing pin: the home input or the enable pin, through the shared calls.
struct CountedPin(Pin);

#[derive(Debug)]
struct PinError;
impl embedded_hal::digital::Error for PinError {
    fn kind(&self) -> embedded_hal::digital::ErrorKind {
        embedded_hal::digital::ErrorKind::Other
    }
}
impl embedded_hal::digital::ErrorType for CountedPin {
    type Error = PinError;
}
impl embedded_hal::digital::OutputPin for CountedPin {
    fn set_low(&mut self) -> Result<(), PinError> {
        self.0.calls.call().map_err(|_| PinError)?;
        self.0.level.set(false);
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), PinError> {
        self.0.calls.call().map_err(|_| PinError)?;
        self.0.level.set(true);
        Ok(())
    }
}
impl embedded_hal::digital::InputPin for CountedPin {
    fn is_high(&mut self) -> Result<bool, PinError> {
        self.0.calls.call().map_err(|_| PinError)?;
        Ok(self.0.level.get())
    }
    fn is_low(&mut self) -> Result<bool, PinError> {
        self.is_high().map(|h| !h)
    }
}

/// The rig: the device and handles on its parts.
struct Rig {
    calls: Rc<Calls>,
    raw: [Rc<Cell<u16>>; 3],
    duty: [Rc<Cell<u16>>; 3],
    enable: Rc<Cell<bool>>,
    home: Rc<Cell<bool>>,
}

type Device = ArmDevice<MockJoint, MockJoint, MockJoint, CountedPin, CountedPin>;

fn rig() -> (Rig, Device) {
    let spec = wooden();
    let calls = Rc::new(Calls::default());
    let cell = || Rc::new(Cell::new(0u16));
    let raw = [cell(), cell(), cell()];
    let duty = [cell(), cell(), cell()];
    let joint = |k: usize| MockJoint {
        calls: calls.clone(),
        raw: raw[k].clone(),
        duty: duty[k].clone(),
        forward: Rc::new(Cell::new(None)),
    };
    let enable = Rc::new(Cell::new(false));
    let home = Rc::new(Cell::new(false));
    let dev = ArmDevice::new(
        Arm::new(&spec).unwrap(),
        (joint(0), joint(1), joint(2)),
        CountedPin(Pin {
            calls: calls.clone(),
            level: enable.clone(),
        }),
        CountedPin(Pin {
            calls: calls.clone(),
            level: home.clone(),
        }),
    );
    (
        Rig {
            calls,
            raw,
            duty,
            enable,
            home,
        },
        dev,
    )
}

/// The driver enabled and the arm homed (the home input high for one read, a device
/// without debounce) at the rig's counts.
fn enable_and_home(r: &Rig, dev: &mut Device) {
    dev.enable().unwrap();
    r.home.set(true);
    dev.read_position().unwrap();
    r.home.set(false);
}

/// Counts at a pose in the workspace, the probe just above the tissue's surface (a
/// probe that appears below it is held out of contact: `ArmDevice::below_entry`).
fn at_work(r: &Rig) {
    // B 20°, C 38.5°: the probe 0.8 mm above the tissue's origin, on the working branch
    // (docs/arm.md).
    let counts = [
        0i32,
        (20.0 / 360.0 * 24_000.0) as i32,
        (38.5 / 360.0 * 24_000.0) as i32,
    ];
    for k in 0..3 {
        r.raw[k].set(counts[k] as u16);
    }
}

#[test]
fn no_force_before_the_arm_is_homed() {
    let (r, mut dev) = rig();
    dev.enable().unwrap();
    at_work(&r);
    let force = [
        Force::from_num(1.0),
        Force::from_num(-0.5),
        Force::from_num(2.0),
    ];
    for _ in 0..5 {
        dev.read_position().unwrap();
        dev.write_force(force).unwrap();
        assert!(r.duty.iter().all(|d| d.get() == 0), "a duty before homing");
        assert!(!dev.homed());
    }
    // The home input: the counts are the home counts (0); the arm then moves to work.
    for k in 0..3 {
        r.raw[k].set(0);
    }
    r.home.set(true);
    dev.read_position().unwrap();
    assert!(dev.homed());
    r.home.set(false);
    at_work(&r);
    let p = dev.read_position().unwrap();
    assert!(p.iter().all(|c| c.abs() < Length::from_num(127)), "{p:?}");
    dev.write_force(force).unwrap();
    assert!(r.duty.iter().any(|d| d.get() > 0), "no duty after homing");
}

/// The virtual walls 3° inside each joint's limits: nothing inside; past a wall a duty
/// back toward the range, proportional, full at the limit (the stop); through the device
/// added to the tissue's duty, on the joint past its wall only.
#[test]
fn a_joint_past_its_wall_is_pushed_back_full_at_the_stop() {
    let spec = wooden();
    let walls = Walls::of(&spec, 3.0);
    // B: 24,000 counts a turn, limits −30° … 90°: walls at −27° and 87° (−1,800 and 5,800
    // counts), 200 counts of margin.
    assert_eq!(walls.at[1], (-1800, 5800));
    assert_eq!(
        walls.duty(walls.at.map(|(_, hi)| hi)),
        [0; 3],
        "at the wall: nothing"
    );
    assert_eq!(walls.duty([0, 3000, 3000]), [0; 3], "inside: nothing");
    let past = walls.duty([0, 5900, 0]);
    assert_eq!(
        past[1],
        -100 * walls.duty_per_count[1],
        "half way to the stop, pushed back"
    );
    assert!(
        (past[1] + 32_768).abs() < 200,
        "about half duty: {}",
        past[1]
    );
    assert_eq!(walls.duty([0, 6000, 0])[1], -65_536, "full at the stop");
    assert_eq!(walls.duty([0, 9000, 0])[1], -65_536, "held to full beyond");
    assert!(walls.duty([0, -1900, 0])[1] > 0, "the low wall pushes up");
    assert_eq!(
        walls.duty([0, 5900, 0])[0],
        0,
        "only the joint past its wall"
    );

    // Through the device: the same counts with and without walls differ by the wall.
    let duties = |with: bool| {
        let (r, dev) = rig();
        let mut dev = if with { dev.with_walls(walls) } else { dev };
        enable_and_home(&r, &mut dev);
        r.raw[1].set(5900);
        dev.read_position().unwrap();
        dev.write_force([Force::ZERO; 3]).unwrap();
        dev.duties()
    };
    let (plain, walled) = (duties(false), duties(true));
    assert_eq!(walled[0], plain[0]);
    assert_eq!(walled[2], plain[2]);
    assert_eq!(walled[1], (plain[1] + past[1]).clamp(-65_536, 65_536));
}

/// The amplifiers' trims: none before homing (zero duty), each duty through its joint's
/// offset and dead band after, and a failed write still ends at zero duty, not the offset.
#[test]
fn the_trims_shift_each_duty_once_homed_and_never_before() {
    let mut spec = wooden();
    spec.joints[0].duty_offset = 0.02;
    spec.joints[1].dead_band = 0.05;
    spec.joints[2].duty_offset = -0.01;
    spec.joints[2].dead_band = 0.03;
    let trims = Trims::of(&spec);
    let push = [
        Force::from_num(0.5),
        Force::from_num(-0.5),
        Force::from_num(0.3),
    ];
    let duties = |with: bool, home: bool| {
        let (r, dev) = rig();
        let mut dev = if with { dev.with_trims(trims) } else { dev };
        if home {
            enable_and_home(&r, &mut dev);
            at_work(&r);
        }
        dev.read_position().unwrap();
        dev.write_force(push).unwrap();
        dev.duties()
    };
    assert_eq!(
        duties(true, false),
        [0; 3],
        "not homed: zero duty, trims or not"
    );
    let (plain, trimmed) = (duties(false, true), duties(true, true));
    assert_eq!(trimmed, trims.apply(plain), "{plain:?} → {trimmed:?}");
    assert_ne!(trimmed, plain);
    let (r, dev) = rig();
    let mut dev = dev.with_trims(trims);
    enable_and_home(&r, &mut dev);
    dev.safe_state().unwrap();
    assert_eq!(
        dev.duties(),
        [0; 3],
        "the safe state is zero duty, not the offset"
    );
}

/// The passivity observer on the device: a force along the probe's motion (energy put
/// into the hand) is a fault once 2 mJ beyond the credit, zero duty first; the same
/// force against the motion (a passive tissue) never is.
#[test]
fn a_force_along_the_probe_s_motion_trips_the_passivity_observer_zero_duty_first() {
    let limits = PassivityLimits::new(2.0, 10.0);
    for (along, trips) in [(-1.0, false), (1.0, true)] {
        let (r, dev) = rig();
        let mut dev = dev.with_passivity(limits);
        enable_and_home(&r, &mut dev);
        at_work(&r);
        let mm = |p: [Length; 3]| p.map(|x| x.to_num::<f64>());
        let mut last = mm(dev.read_position().unwrap());
        dev.write_force([Force::ZERO; 3]).unwrap();
        let mut ended = None;
        for t in 0..2000 {
            // Joint B creeping a count a tick (64 µm at the probe, about).
            r.raw[1].set(r.raw[1].get().wrapping_add(1));
            let p = mm(dev.read_position().unwrap());
            let d: Vec<f64> = (0..3).map(|i| p[i] - last[i]).collect();
            let len = d.iter().map(|x| x * x).sum::<f64>().sqrt();
            let f = [0, 1, 2].map(|i| Force::from_num(along * 2.0 * d[i] / len));
            if let Err(e) = dev.write_force(f) {
                ended = Some((t, e));
                break;
            }
            last = p;
        }
        if trips {
            let (t, e) = ended.expect("tripped");
            assert_eq!(e, ArmFault::EnergyOut);
            assert!(t < 30, "tripped at tick {t}");
            assert_eq!(dev.duties(), [0; 3]);
            assert!(r.duty.iter().all(|d| d.get() == 0), "zero duty written");
        } else {
            assert_eq!(ended, None);
            // In contact all the hand put in is held (a release may give it back),
            // past the 10 mJ credit that holds out of contact.
            let e = dev.passivity_mj().unwrap();
            assert!(e > 10.0, "the hand's input held: {e} mJ");
        }
    }
}

/// The I²t model: a joint held at 100 % duty folds back to its continuous current within
/// 1.2 of its winding's time constant (the model's: at 0.118 τ, where the heat reaches
/// (1 A / 3 A)²), stays within it while the demand lasts, with the `thermal` status, and
/// comes back once the heat has fallen to 81 % of the limit's.
#[test]
fn a_joint_held_at_full_current_folds_back_to_its_continuous_current() {
    let spec = wooden();
    let model = Thermal::of(&spec, 1000);
    let limit = model.limit_q16[0];
    assert_eq!(limit, 21_845, "1 A of 3 A");
    let (r, dev) = rig();
    let mut dev = dev.with_thermal(model);
    enable_and_home(&r, &mut dev);
    at_work(&r);
    // Far more force than the motors give: some joint at 100 %.
    let push = [
        Force::from_num(0.0),
        Force::from_num(300.0),
        Force::from_num(-300.0),
    ];
    let tau_ticks = (41.6 * 1000.0) as usize;
    let mut folded_at = None;
    let mut full = None;
    for t in 0..60_000 {
        dev.read_position().unwrap();
        dev.write_force(push).unwrap();
        let d = dev.duties();
        if t == 0 {
            full = d.iter().position(|x| x.abs() == 65_536);
            assert!(full.is_some(), "a joint at 100 %: {d:?}");
        }
        let k = full.unwrap();
        if folded_at.is_none() && d[k].abs() <= limit {
            folded_at = Some(t);
            assert!(dev.status().thermal, "the thermal status");
        }
        if folded_at.is_some() {
            assert!(
                d[k].abs() <= limit,
                "held to the continuous current at tick {t}: {d:?}"
            );
        }
    }
    let at = folded_at.expect("folded back within 60 s");
    println!(
        "ARM case=i2t folded_after_tau={:.3}",
        at as f64 / tau_ticks as f64
    );
    assert!(
        at as f64 <= 1.2 * tau_ticks as f64,
        "folded after {at} ticks"
    );
    assert!(
        (at as f64 / tau_ticks as f64 - 0.118).abs() < 0.01,
        "the model's 0.118 τ: {at}"
    );
    // The demand gone: it cools, and the full current comes back.
    let mut back = None;
    for t in 0..200_000 {
        dev.read_position().unwrap();
        dev.write_force([Force::ZERO; 3]).unwrap();
        if !dev.status().thermal {
            back = Some(t);
            break;
        }
    }
    assert!(back.is_some(), "it never cooled");
    dev.read_position().unwrap();
    dev.write_force(push).unwrap();
    assert_eq!(
        dev.duties()[full.unwrap()].abs(),
        65_536,
        "full current again"
    );
}

/// Homing waits for the home input to stay high for the debounce's reads in a row with
/// the arm still (within 2 counts): a bounce or a joint moving 3 counts starts the wait
/// again; no duty until it homes. (It once homed on one sample of the input.)
#[test]
fn home_is_taken_only_after_the_input_stays_high_with_the_arm_still() {
    let (r, dev) = rig();
    let mut dev = dev.with_home_debounce(50);
    dev.enable().unwrap();
    let force = [Force::ZERO, Force::ZERO, Force::from_num(1.0)];
    let read = |dev: &mut Device, n: usize| {
        for _ in 0..n {
            dev.read_position().unwrap();
            dev.write_force(force).unwrap();
            if !dev.homed() {
                assert!(r.duty.iter().all(|d| d.get() == 0), "a duty before homing");
            }
        }
    };
    r.home.set(true);
    read(&mut dev, 49);
    assert!(!dev.homed(), "49 reads are not 50");
    // A bounce: low for one read, then high again: 49 more are not enough.
    r.home.set(false);
    read(&mut dev, 1);
    r.home.set(true);
    read(&mut dev, 49);
    assert!(!dev.homed(), "the bounce restarted the wait");
    // Within 2 counts the arm is still; 3 counts is motion, and restarts it.
    r.raw[1].set(2);
    read(&mut dev, 1);
    assert!(dev.homed(), "50 reads high, 2 counts of motion");
    assert!(
        r.duty.iter().all(|d| d.get() == 0),
        "the homing tick's own write is zero duty"
    );
    at_work(&r);
    dev.read_position().unwrap();
    dev.write_force(force).unwrap();
    assert!(
        r.duty.iter().any(|d| d.get() > 0),
        "then the force is rendered"
    );
    let (r, dev) = rig();
    let mut dev = dev.with_home_debounce(50);
    r.home.set(true);
    for _ in 0..49 {
        dev.read_position().unwrap();
    }
    r.raw[2].set(3);
    for _ in 0..49 {
        dev.read_position().unwrap();
    }
    assert!(!dev.homed(), "3 counts of motion restarted the wait");
    dev.read_position().unwrap();
    assert!(dev.homed());
}

/// The rig with the board's runaway limits (2 rev/s a joint, 1 m/s the probe, 5 ticks
/// in a row at 1 kHz), homed and at work; the joints' counts at work.
fn limited() -> (Rig, Device, [i32; 3]) {
    let (r, dev) = rig();
    let spec = wooden();
    let limits = SpeedLimits::of(&spec, 1000, 2.0, 1000.0, 5);
    // 32,000 counts a turn of A, 24,000 of B and C: 64 and 48 a tick at 2 rev/s; 1 mm
    // a tick at 1 m/s.
    assert_eq!(limits.joint_counts, [64, 48, 48]);
    assert_eq!(limits.probe, Length::from_num(1));
    let mut dev = dev.with_speed_limits(limits);
    enable_and_home(&r, &mut dev);
    at_work(&r);
    // One tick's jump (a tick over the limits), then a tick at rest (the run broken).
    dev.read_position().unwrap();
    dev.read_position().unwrap();
    let work = [0, r.raw[1].get() as i32, r.raw[2].get() as i32];
    (r, dev, work)
}

/// Moves joint `k` by `step` counts a tick from `counts`, `ticks` times; the first error.
fn spin(
    r: &Rig,
    dev: &mut Device,
    counts: &mut [i32; 3],
    k: usize,
    step: i32,
    ticks: usize,
) -> Result<usize, ArmFault> {
    for t in 0..ticks {
        counts[k] += step;
        r.raw[k].set(counts[k] as u16);
        dev.read_position().inspect_err(|e| {
            assert_eq!(
                t, 4,
                "the fault on the 5th tick over, not tick {t} (joint {k}, {step} a tick, at {counts:?}: {e:?})"
            );
        })?;
    }
    Ok(ticks)
}

#[test]
fn a_runaway_joint_or_probe_is_a_fault_on_its_fifth_tick_in_a_row() {
    // The elbow at 2.5 rev/s (60 counts a tick).
    let (r, mut dev, mut c) = limited();
    assert_eq!(
        spin(&r, &mut dev, &mut c, 2, 60, 10),
        Err(ArmFault::Overspeed(2))
    );

    // At 0.4 rev/s (10 counts a tick, the probe about 0.5 mm a tick) the elbow turns
    // 15° and back without a fault. (The probe's speed is seen where the probe is within
    // the tissue frame's ±128 mm; far from the tissue only the joints' limits hold.)
    let (r, mut dev, mut c) = limited();
    assert_eq!(spin(&r, &mut dev, &mut c, 2, 10, 100), Ok(100));
    assert_eq!(spin(&r, &mut dev, &mut c, 2, -10, 100), Ok(100));

    // The base at 1.9 rev/s (60 counts a tick): within its limit, but the probe, about
    // 200 mm out, moves over 1 m/s: the probe's fault.
    let (r, mut dev, mut c) = limited();
    assert_eq!(
        spin(&r, &mut dev, &mut c, 0, 60, 10),
        Err(ArmFault::ProbeSpeed)
    );

    // Fast for 4 ticks, then one within: never a fault (the ticks must be in a row).
    let (r, mut dev, mut c) = limited();
    for _ in 0..20 {
        assert_eq!(spin(&r, &mut dev, &mut c, 2, 60, 4), Ok(4));
        assert_eq!(spin(&r, &mut dev, &mut c, 2, 0, 1), Ok(1));
        assert_eq!(spin(&r, &mut dev, &mut c, 2, -60, 4), Ok(4));
        assert_eq!(spin(&r, &mut dev, &mut c, 2, 0, 1), Ok(1));
    }
}

#[test]
fn a_fault_at_every_device_call_ends_at_zero_duty() {
    // How many calls a homed tick takes.
    let (r, mut dev) = rig();
    let force = [
        Force::from_num(1.5),
        Force::from_num(1.0),
        Force::from_num(-2.0),
    ];
    enable_and_home(&r, &mut dev);
    at_work(&r);
    dev.read_position().unwrap();
    dev.write_force(force).unwrap();
    // A steady tick (the directions known).
    let before = r.calls.n.get();
    dev.read_position().unwrap();
    dev.write_force(force).unwrap();
    let per_tick = r.calls.n.get() - before;
    assert!(per_tick >= 6, "{per_tick} calls a tick");
    let mut faults = Vec::new();
    for fail in 0..per_tick {
        let (r, mut dev) = rig();
        enable_and_home(&r, &mut dev);
        at_work(&r);
        // A tick at full force first (duties up), then one with the fault.
        dev.read_position().unwrap();
        dev.write_force(force).unwrap();
        assert!(r.duty.iter().any(|d| d.get() > 0));
        r.calls.fail_at.set(Some(r.calls.n.get() + fail));
        let result = dev.read_position().and_then(|_| dev.write_force(force));
        let e = result.expect_err("the injected fault was not seen");
        faults.push(e);
        // What the controller does next: the safe state.
        r.calls.fail_at.set(None);
        dev.safe_state().unwrap();
        assert!(
            r.duty.iter().all(|d| d.get() == 0),
            "call {fail} ({e:?}): a duty left on"
        );
        assert!(!r.enable.get(), "call {fail}: the driver left enabled");
    }
    assert!(
        faults.contains(&ArmFault::Encoder(0))
            && faults.iter().any(|f| matches!(f, ArmFault::Pwm(_)))
    );
}

/// A failed duty write zeroes every duty before it returns, and the safe state does
/// even when a duty write fails (each attempted, the driver disabled).
#[test]
fn a_failed_write_and_a_failing_safe_state_still_end_at_zero() {
    let (r, mut dev) = rig();
    enable_and_home(&r, &mut dev);
    at_work(&r);
    let force = [
        Force::from_num(1.5),
        Force::from_num(1.0),
        Force::from_num(-2.0),
    ];
    dev.read_position().unwrap();
    dev.write_force(force).unwrap();
    // The safe state with joint A's duty failing: B and C still zero, the driver off.
    r.calls.fail_at.set(Some(r.calls.n.get()));
    assert_eq!(dev.safe_state(), Err(ArmFault::Pwm(0)));
    assert_eq!((r.duty[1].get(), r.duty[2].get()), (0, 0));
    assert!(!r.enable.get());
}

/// A contact starts only by coming down onto the surface: a probe that comes into the
/// tissue's frame from beside it below the surface's height (where the simulated arm's
/// approach came in, 21 mm deep at x = −128 mm) reads as far above the tissue, no
/// contact, until it rises to the surface inside the frame; then a press is a contact
/// again. Without the rule the contact met it with the whole depth's force (a
/// pop-through of 2.9 N along the approach, which the arm's closed loop measured as
/// 0.15 J put into the hand).
#[test]
fn a_probe_that_comes_in_below_the_surface_is_out_of_contact_until_it_rises_to_it() {
    let spec = wooden();
    let (r, mut dev) = rig();
    enable_and_home(&r, &mut dev);
    let origin = spec.tissue_origin_mm;
    let at = |r: &Rig, tissue: [f64; 3]| {
        let p = std::array::from_fn(|k| tissue[k] + origin[k]);
        let counts = mccs::arm::inverse::counts(&spec, p).unwrap();
        for k in 0..3 {
            r.raw[k].set(counts[k] as u16);
        }
    };
    let far = [Length::ZERO, Length::ZERO, Length::MAX];
    // Beside the frame, 21 mm below the surface's height; then in it, still below.
    for (x, z, expect_far) in [
        (-140.0, -21.0, true),
        (-120.0, -21.0, true),
        (-60.0, -10.0, true),
        (-60.0, -0.2, true),
        // At the surface inside the frame: the rule is done; a press is a contact.
        (-60.0, 0.1, false),
        (-60.0, -1.0, false),
    ] {
        at(&r, [x, 0.0, z]);
        let p = dev.read_position().unwrap();
        dev.write_force([Force::ZERO; 3]).unwrap();
        assert_eq!(p == far, expect_far, "at x {x}, z {z}: {p:?}");
        assert_eq!(dev.below_entry(), expect_far, "at x {x}, z {z}");
        if !expect_far {
            assert!((p[2].to_num::<f64>() - z).abs() < 0.1, "at z {z}: {p:?}");
        }
    }
    // Out of the frame beneath it and back: held out of contact again.
    at(&r, [-60.0, 0.0, -130.0]);
    assert_eq!(dev.read_position().unwrap(), far);
    at(&r, [-60.0, 0.0, -1.0]);
    assert_eq!(dev.read_position().unwrap(), far, "came back in below");
    // Homed (the home pose: beside the frame, 40 mm below the surface's height).
    let (r, mut dev) = rig();
    enable_and_home(&r, &mut dev);
    assert!(dev.below_entry());
    assert_eq!(dev.read_position().unwrap(), far);
}
