//! The arm variant's wiring (`--features arm`; `haptic_f405::arm`) on embedded-hal 1.0
//! parts in memory: start-up is every joint at zero duty and the driver off, then the
//! driver on (`embedded-hal-mock`: a wrong call or order fails the mock); no duty before
//! the home input, whatever the probe presses; a press drives the joints once homed; a
//! failure at every part (each counter, PWM channel and direction pin, the enable and the
//! home input) ends with every duty at zero and the driver off, re-asserted on every tick
//! after; and the start-up errors name the part and the joint.

use embedded_hal::digital::{
    ErrorKind as PinErrorKind, ErrorType as PinErrorType, InputPin, OutputPin,
};
use embedded_hal::pwm::{ErrorKind as PwmErrorKind, ErrorType as PwmErrorType, SetDutyCycle};
use embedded_hal_mock::eh1::digital::{Mock as PinMock, State, Transaction as PinTx};
use embedded_hal_mock::eh1::pwm::{Mock as PwmMock, Transaction as PwmTx};
use haptic_f405::arm::{arm_controller_into, arm_device, arm_start_into, LinkedArm, ARM};
use haptic_f405::device::{BoardController, BoardRoaming, DevicePart, StartError};
use haptic_f405::tissue::TISSUE;
use haptic_f405::BOARD;
use mccs::{Arm, ArmError, Force};
use mccs_firmware::arm::device::{ArmFault, JointParts};
use mccs_firmware::arm::encoder::{JointEncoder, MockEncoder};
use mccs_firmware::Fault;
use std::cell::Cell;
use std::rc::Rc;

/// One part's state, shared with the test: a level or a value, and whether its next
/// calls fail.
#[derive(Clone, Default)]
struct Part {
    value: Rc<Cell<u16>>,
    fail: Rc<Cell<bool>>,
}

/// A counter in memory.
struct Counter(Part);
impl JointEncoder for Counter {
    type Error = ();
    fn read(&mut self) -> Result<u16, ()> {
        if self.0.fail.get() {
            Err(())
        } else {
            Ok(self.0.value.get())
        }
    }
}

/// A PWM channel in memory: 8400 steps, as TIM1 at 20 kHz.
struct Pwm(Part);
impl PwmErrorType for Pwm {
    type Error = PwmErrorKind;
}
impl SetDutyCycle for Pwm {
    fn max_duty_cycle(&self) -> u16 {
        8400
    }
    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), PwmErrorKind> {
        if self.0.fail.get() {
            return Err(PwmErrorKind::Other);
        }
        self.0.value.set(duty);
        Ok(())
    }
}

/// An output pin in memory (1: high).
struct Out(Part);
impl PinErrorType for Out {
    type Error = PinErrorKind;
}
impl OutputPin for Out {
    fn set_low(&mut self) -> Result<(), PinErrorKind> {
        if self.0.fail.get() {
            return Err(PinErrorKind::Other);
        }
        self.0.value.set(0);
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), PinErrorKind> {
        if self.0.fail.get() {
            return Err(PinErrorKind::Other);
        }
        self.0.value.set(1);
        Ok(())
    }
}

/// The home input in memory.
struct In(Part);
impl PinErrorType for In {
    type Error = PinErrorKind;
}
impl InputPin for In {
    fn is_high(&mut self) -> Result<bool, PinErrorKind> {
        if self.0.fail.get() {
            return Err(PinErrorKind::Other);
        }
        Ok(self.0.value.get() != 0)
    }
    fn is_low(&mut self) -> Result<bool, PinErrorKind> {
        self.is_high().map(|h| !h)
    }
}

type J = JointParts<Counter, Pwm, Out>;
type Ctl = BoardController<LinkedArm<J, J, J, Out, In>, BoardRoaming>;

/// The board's arm on parts in memory: each joint's counter, PWM and direction, the
/// enable and the home input.
struct Rig {
    counter: [Part; 3],
    pwm: [Part; 3],
    direction: [Part; 3],
    enable: Part,
    home: Part,
    ctl: Ctl,
}

impl Rig {
    fn new() -> Rig {
        let parts = || [Part::default(), Part::default(), Part::default()];
        let (counter, pwm, direction) = (parts(), parts(), parts());
        let joint = |k: usize| JointParts {
            encoder: Counter(counter[k].clone()),
            pwm: Pwm(pwm[k].clone()),
            direction: Out(direction[k].clone()),
        };
        let (enable, home) = (Part::default(), Part::default());
        // The driver "on" before start-up: the safe state must turn it off.
        enable.value.set(1);
        let device = arm_device(
            &BOARD,
            &ARM,
            (joint(0), joint(1), joint(2)),
            Out(enable.clone()),
            In(home.clone()),
        )
        .unwrap_or_else(|_| panic!("the arm's device"));
        assert_eq!(enable.value.get(), 0, "start-up: the driver off");
        let mut slot = None;
        assert!(arm_controller_into(&BOARD, TISSUE, device, &mut slot).is_ok());
        assert_eq!(
            enable.value.get(),
            1,
            "the driver on once the controller is built"
        );
        let mut ctl: Ctl = slot.unwrap_or_else(|| panic!("the controller"));
        // Full force, as the link's guard gives it once its ramp is done.
        ctl.device_mut().set_gain(mccs_link::scale::GAIN_FULL);
        Rig {
            counter,
            pwm,
            direction,
            enable,
            home,
            ctl,
        }
    }

    /// The counters at `counts` (their low 16 bits, as the timers hold them).
    fn set_counts(&self, counts: [i32; 3]) {
        for k in 0..3 {
            self.counter[k].value.set(counts[k] as u16);
        }
    }

    fn duties(&self) -> [u16; 3] {
        [0, 1, 2].map(|k| self.pwm[k].value.get())
    }

    /// Homed at `counts` (the home input held high its 50 ms with the arm still), then
    /// released.
    fn home_at(&mut self, counts: [i32; 3]) {
        self.set_counts(counts);
        self.home.value.set(1);
        for _ in 0..50 {
            self.ctl.tick(None);
        }
        assert!(self.ctl.device().inner().homed());
        self.home.value.set(0);
    }

    /// Ticks the direction check through, each joint turning a count a tick the way its
    /// duty and pin drive it times `wiring` (+1 right, −1 reversed); the ticks it took,
    /// or the fault it ended in.
    fn nudge_through(&mut self, wiring: [i32; 3]) -> Result<u32, Fault> {
        let mut counts = [0i32; 3];
        for tick in 0..2000 {
            self.ctl.tick(None);
            if let Some(fault) = self.ctl.telemetry().fault {
                return Err(fault);
            }
            if self.ctl.device().inner().direction_checked() {
                return Ok(tick);
            }
            let pins = [0, 1, 2].map(|k| self.direction[k].value.get());
            for k in 0..3 {
                if self.duties()[k] > 0 {
                    counts[k] += if pins[k] == 1 { wiring[k] } else { -wiring[k] };
                }
            }
            self.set_counts(counts);
        }
        panic!("no verdict in 2 s");
    }
}

/// Counts that put the probe `depth_mm` into the tissue at its origin (yaw 0, the probe
/// straight above the origin): the elbow's two-link solution in f64, then the count
/// found by the core's own forward kinematics to be pressing.
fn pressing_counts(depth_mm: f64) -> [i32; 3] {
    let (lb, lc) = (ARM.upper_arm_mm, ARM.forearm_mm);
    let [ox, _, oz] = ARM.tissue_origin_mm;
    let (r, h) = (ox, oz - depth_mm - ARM.base_height_mm);
    let d = (r * r + h * h).sqrt();
    let phi = r.atan2(h);
    let alpha = ((lb * lb + d * d - lc * lc) / (2.0 * lb * d)).acos();
    let b = phi - alpha;
    let (vx, vy) = (r - lb * b.sin(), h - lb * b.cos());
    let c = vx.atan2(-vy);
    let count = |angle: f64, j: usize| {
        let s = &ARM.joints[j];
        (angle.to_degrees() * s.counts_per_rev * s.ratio / 360.0).round() as i32
    };
    let counts = [0, count(b, 1), count(c, 2)];
    let arm = Arm::new(&ARM).unwrap_or_else(|e| panic!("{e}"));
    let pose = arm.pose(counts);
    let p = pose.probe.map(|x| x.to_num::<f64>());
    assert_eq!(pose.flags, 0, "within the joints' limits");
    assert!(
        p[0].abs() < 0.1 && p[1].abs() < 0.1,
        "above the origin: {p:?}"
    );
    assert!((p[2] + depth_mm).abs() < 0.1, "{depth_mm} mm deep: {p:?}");
    counts
}

#[test]
fn start_up_is_zero_duty_and_the_driver_off_then_on_in_that_order() {
    let pwm = [0, 1, 2].map(|_| PwmMock::new(&[PwmTx::set_duty_cycle(0)]));
    let enable = PinMock::new(&[PinTx::set(State::Low), PinTx::set(State::High)]);
    let directions = [0, 1, 2].map(|_| PinMock::new(&[]));
    let home = PinMock::new(&[]);
    let joint = |k: usize| JointParts {
        encoder: MockEncoder::default(),
        pwm: pwm[k].clone(),
        direction: directions[k].clone(),
    };
    let device = arm_device(
        &BOARD,
        &ARM,
        (joint(0), joint(1), joint(2)),
        enable.clone(),
        home.clone(),
    )
    .unwrap_or_else(|_| panic!("the arm's device"));
    let mut slot = None;
    assert!(arm_start_into(&BOARD, TISSUE, device, &mut slot).is_ok());
    drop(slot);
    for mut m in pwm {
        m.done();
    }
    for mut m in directions {
        m.done();
    }
    let (mut enable, mut home) = (enable, home);
    enable.done();
    home.done();
}

#[test]
fn no_duty_before_homing_then_a_press_drives_the_joints() {
    let mut rig = Rig::new();
    let counts = pressing_counts(1.0);
    // Not homed: the counters read the pressing pose, the home input low.
    rig.set_counts(counts);
    for _ in 0..50 {
        rig.ctl.tick(None);
        assert_eq!(rig.duties(), [0; 3], "a duty before homing");
    }
    assert!(!rig.ctl.device().inner().homed());
    // Homed at the pose the counters read as home (all zero): then pressed.
    rig.set_counts([0; 3]);
    rig.home.value.set(1);
    // The home input must stay high 50 ms (50 ticks) with the arm still.
    for _ in 0..49 {
        rig.ctl.tick(None);
    }
    assert!(!rig.ctl.device().inner().homed(), "homed before 50 ms");
    rig.ctl.tick(None);
    assert!(rig.ctl.device().inner().homed());
    rig.home.value.set(0);
    // Each joint nudged both ways, and turning the way it is driven.
    assert!(rig.nudge_through([1; 3]).is_ok());
    rig.set_counts([0; 3]);
    // Down onto the tissue from above it (a contact starts only so).
    rig.set_counts(pressing_counts(-2.0));
    rig.ctl.tick(None);
    rig.set_counts(counts);
    let mut force = [Force::ZERO; 3];
    for _ in 0..200 {
        force = rig.ctl.tick(None);
    }
    let fz = force[2].to_num::<f64>();
    assert!(fz > 0.05, "the tissue pushes back: {fz} N");
    assert!(rig.duties().iter().any(|&d| d > 0), "{:?}", rig.duties());
    // The joints pushed the way the duties' signs say, written through their pins.
    let q16 = rig.ctl.device().inner().duties();
    for k in 0..3 {
        if q16[k] != 0 {
            assert_eq!(
                rig.direction[k].value.get(),
                (q16[k] > 0) as u16,
                "joint {k}'s pin"
            );
        }
    }
    assert_eq!(rig.ctl.telemetry().fault, None);
}

#[test]
fn a_failure_at_every_part_ends_at_zero_duty_and_the_driver_off() {
    // (part, the fault the controller latches)
    type Pick = Box<dyn Fn(&Rig) -> &Part>;
    let cases: Vec<(&str, Pick, Fault)> = vec![
        ("counter A", Box::new(|r| &r.counter[0]), Fault::Read),
        ("counter B", Box::new(|r| &r.counter[1]), Fault::Read),
        ("counter C", Box::new(|r| &r.counter[2]), Fault::Read),
        ("home", Box::new(|r| &r.home), Fault::Read),
        ("PWM A", Box::new(|r| &r.pwm[0]), Fault::Write),
        ("PWM B", Box::new(|r| &r.pwm[1]), Fault::Write),
        ("PWM C", Box::new(|r| &r.pwm[2]), Fault::Write),
        ("direction A", Box::new(|r| &r.direction[0]), Fault::Write),
        ("direction B", Box::new(|r| &r.direction[1]), Fault::Write),
        ("direction C", Box::new(|r| &r.direction[2]), Fault::Write),
    ];
    // Pressing at the origin, then joint A turned 30 counts: the proxy sticks (friction),
    // so the force has a lateral part and every joint is driven.
    let pressed = pressing_counts(1.0);
    let above = pressing_counts(-2.0);
    let mut counts = pressed;
    counts[0] = 30;
    for (name, part, fault) in cases {
        let mut rig = Rig::new();
        if name == "home" {
            // The home input is read only until the arm is homed.
            part(&rig).fail.set(true);
        } else if name.starts_with("direction") {
            // A direction pin is written only when its joint's direction changes (the
            // first one after homing included): failing from the start, it fails there.
            part(&rig).fail.set(true);
            rig.home.value.set(1);
            for _ in 0..50 {
                rig.ctl.tick(None);
            }
            rig.home.value.set(0);
            rig.set_counts(above);
            rig.ctl.tick(None);
            rig.set_counts(pressed);
            for _ in 0..100 {
                rig.ctl.tick(None);
            }
            rig.set_counts(counts);
        } else {
            rig.home.value.set(1);
            for _ in 0..50 {
                rig.ctl.tick(None);
            }
            rig.home.value.set(0);
            rig.set_counts(above);
            rig.ctl.tick(None);
            rig.set_counts(pressed);
            for _ in 0..100 {
                rig.ctl.tick(None);
            }
            rig.set_counts(counts);
            for _ in 0..100 {
                rig.ctl.tick(None);
            }
            assert!(
                rig.duties().iter().all(|&d| d > 0),
                "{name}: every joint driven before the fault: {:?}",
                rig.duties()
            );
            part(&rig).fail.set(true);
        }
        let mut latched = false;
        for _ in 0..300 {
            rig.ctl.tick(None);
            if rig.ctl.telemetry().fault.is_some() {
                latched = true;
                break;
            }
        }
        assert!(latched, "{name}: the fault was not seen");
        assert_eq!(rig.ctl.telemetry().fault, Some(fault), "{name}");
        // Every channel that takes a write is at zero; a failed channel keeps what it
        // last took, and the driver's enable is what stops it.
        let mut zero = [0; 3];
        if let Some(k) = name
            .strip_prefix("PWM ")
            .map(|j| (j.as_bytes()[0] - b'A') as usize)
        {
            zero[k] = rig.duties()[k];
        }
        assert_eq!(rig.duties(), zero, "{name}: a duty after the fault");
        assert_eq!(rig.enable.value.get(), 0, "{name}: the driver still on");
        // The safe state on every tick after, even with the part mended and pressing.
        part(&rig).fail.set(false);
        rig.set_counts(counts);
        rig.enable.value.set(1);
        rig.ctl.tick(None);
        assert_eq!(
            rig.enable.value.get(),
            0,
            "{name}: the safe state re-asserted"
        );
        assert_eq!(rig.duties(), [0; 3], "{name}");
    }
}

#[test]
fn a_failed_enable_at_start_up_leaves_every_duty_at_zero() {
    let pwm = [Part::default(), Part::default(), Part::default()];
    let joint = |k: usize| JointParts {
        encoder: Counter(Part::default()),
        pwm: Pwm(pwm[k].clone()),
        direction: Out(Part::default()),
    };
    for k in 0..3 {
        pwm[k].value.set(1234);
    }
    let enable = Part::default();
    enable.fail.set(true);
    let got = arm_device(
        &BOARD,
        &ARM,
        (joint(0), joint(1), joint(2)),
        Out(enable.clone()),
        In(Part::default()),
    );
    let Err(e) = got else {
        panic!("a failed enable pin started")
    };
    assert_eq!(e, StartError::SafeState(ArmFault::Enable));
    assert_eq!(
        pwm.each_ref().map(|p| p.value.get()),
        [0; 3],
        "duties zeroed first"
    );
    assert_eq!(
        e.fault().to_string(),
        "safe state: the motor driver's enable pin failed"
    );
}

#[test]
fn start_up_errors_name_the_part_and_the_joint() {
    let said = |e: StartError<ArmFault>| e.fault().to_string();
    assert_eq!(
        said(StartError::SafeState(ArmFault::Pwm(1))),
        "safe state: joint B's PWM channel failed"
    );
    assert_eq!(
        said(StartError::SafeState(ArmFault::Encoder(2))),
        "safe state: joint C's counter failed"
    );
    assert_eq!(
        said(StartError::SafeState(ArmFault::Direction(0))),
        "safe state: joint A's direction pin failed"
    );
    assert_eq!(
        said(StartError::SafeState(ArmFault::Home)),
        "safe state: the arm's home input failed"
    );
    // A device constant out of range is refused before any part is touched.
    let mut bad = ARM;
    bad.joints[2].ratio = 0.0;
    let (pwm, enable) = (Part::default(), Part::default());
    pwm.value.set(1234);
    enable.value.set(1);
    let joint = || JointParts {
        encoder: Counter(Part::default()),
        pwm: Pwm(pwm.clone()),
        direction: Out(Part::default()),
    };
    let got = arm_device(
        &BOARD,
        &bad,
        (joint(), joint(), joint()),
        Out(enable.clone()),
        In(Part::default()),
    );
    let Err(e) = got else {
        panic!("a zero ratio started")
    };
    assert_eq!(e, StartError::Arm(ArmError::Transmission(2)));
    assert_eq!(
        (pwm.value.get(), enable.value.get()),
        (1234, 1),
        "a part was touched"
    );
    assert_eq!(
        e.fault().to_string(),
        "joint: counts_per_rev and ratio must be finite and > 0, a joint turn 16 to 2^30 counts (joint C)"
    );
}

/// A coupling over half the arm's stable region at its damping (what `mccs check
/// --device arm` refuses) is refused at start-up with its figures, the driver never
/// enabled; a damping outside the measured region too. The board's own passes.
#[test]
fn a_coupling_beyond_half_the_stable_region_is_refused_at_start_up() {
    use haptic_f405::arm::check_coupling;
    use haptic_f405::BoardConfig;
    assert_eq!(check_coupling(&BOARD), Ok(()));
    let at = |k: f64, b: f64| BoardConfig {
        coupling_stiffness: k,
        coupling_damping: b,
        ..BOARD
    };
    // Half of 90.51 N/mm at 0.5 N·s/m: 45.25 passes, 45.26 does not; between 0 and 0.5
    // N·s/m, half the lower, 64 N/mm.
    assert_eq!(check_coupling(&at(45.25, 0.5)), Ok(()));
    for (config, said) in [
        (
            at(45.26, 0.5),
            "coupling: 45.260 N/mm at 0.500 N·s/m is over half the arm's stable region there, 45.255 N/mm (docs/safety.md)",
        ),
        (
            at(33.0, 0.25),
            "coupling: 33.000 N/mm at 0.250 N·s/m is over half the arm's stable region there, 32.000 N/mm (docs/safety.md)",
        ),
        (
            at(1.0, 7.0),
            "coupling: its damping, 7.000 N·s/m, is outside the arm's measured stable region (docs/safety.md)",
        ),
    ] {
        let enable = Part::default();
        let joint = || JointParts {
            encoder: Counter(Part::default()),
            pwm: Pwm(Part::default()),
            direction: Out(Part::default()),
        };
        let device = arm_device(
            &config,
            &ARM,
            (joint(), joint(), joint()),
            Out(enable.clone()),
            In(Part::default()),
        )
        .unwrap_or_else(|_| panic!("the arm's device"));
        let mut slot = None;
        let Err((e, _device)) = arm_start_into(&config, TISSUE, device, &mut slot) else {
            panic!("{said}: started")
        };
        assert_eq!(e.fault().to_string(), said);
        assert!(slot.is_none());
        assert_eq!(enable.value.get(), 0, "the driver enabled");
    }
}

/// The simulated arm board's own loop (its plant palpating, the board's arm device and
/// roaming controller) never trips the passivity observer: a passive tissue under a hand
/// that follows its path.
#[test]
fn the_simulated_arm_s_palpation_never_trips_the_passivity_observer() {
    use mccs_firmware::arm::plant::{Plant, PALPATION_TICKS};
    let path = mccs_firmware::palpation_path(BOARD.tick_hz).unwrap();
    let plant: &'static Plant = Box::leak(Box::new(Plant::new(&ARM, &path).unwrap()));
    let (joints, enable, home) = plant.joints();
    let device =
        arm_device(&BOARD, &ARM, joints, enable, home).unwrap_or_else(|_| panic!("device"));
    let mut slot = None;
    assert!(arm_controller_into(&BOARD, TISSUE, device, &mut slot).is_ok());
    let mut ctl = slot.unwrap();
    // Full gain (the link's guard sets it each tick on the board).
    ctl.device_mut().set_gain(u16::MAX);
    let mut lowest = 0.0f64;
    let mut most = 0.0f64;
    for t in 0..(2000 + 3 * PALPATION_TICKS) {
        let f = ctl.tick(None);
        most = most.max(f[2].to_num::<f64>());
        let e = ctl.device().inner().passivity_mj().unwrap();
        lowest = lowest.min(e);
        let fault = ctl.telemetry().fault;
        assert!(fault.is_none(), "tick {t}: {fault:?}, energy {e} mJ");
    }
    assert!(most > 0.5, "the palpation pressed: {most} N");
    println!("PASSIVITY case=simulated_arm lowest_mj={lowest:.3}");
}

/// A joint wired the wrong way round: the direction check after homing finds it, the
/// arm goes to its safe state (every duty zero, the driver off) and the board's log
/// names the joint; before the check no force reaches the tissue, however deep the
/// counts read.
#[test]
fn a_reversed_joint_fails_the_direction_check_into_the_safe_state() {
    for k in 0..3 {
        let mut rig = Rig::new();
        rig.home_at([0; 3]);
        let mut wiring = [1; 3];
        wiring[k] = -1;
        assert_eq!(rig.nudge_through(wiring), Err(Fault::Read));
        assert_eq!(rig.duties(), [0; 3]);
        assert_eq!(rig.enable.value.get(), 0, "the driver off");
        let part = rig.ctl.device_error().map(DevicePart::from);
        assert_eq!(part, Some(DevicePart::JointReversed(k as u8)));
        assert!(part.is_some_and(|p| p.name().contains("turning against its drive")));
        // The fault holds: a press reads nothing and drives nothing.
        rig.set_counts(pressing_counts(2.0));
        for _ in 0..10 {
            assert_eq!(rig.ctl.tick(None), [Force::ZERO; 3]);
        }
        assert_eq!(rig.duties(), [0; 3]);
    }
    // Wired right: no tissue force while the check runs, even pressed.
    let mut rig = Rig::new();
    rig.home_at([0; 3]);
    rig.ctl.tick(None);
    assert!(!rig.ctl.device().inner().direction_checked());
    rig.set_counts(pressing_counts(2.0));
    for _ in 0..20 {
        assert_eq!(
            rig.ctl.tick(None),
            [Force::ZERO; 3],
            "force before the check"
        );
    }
}
