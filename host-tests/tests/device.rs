//! The device layer: the AS5047P frames and their checks, the motor drive, the 1-DOF
//! device, and the controller's safe state — exact call sequences against
//! `embedded-hal-mock`, and a fault injected at every device call site with recording
//! fakes (the mock's SPI cannot fail a transfer).

use embedded_hal::digital::{ErrorType as PinErrorType, OutputPin};
use embedded_hal::pwm::{ErrorType as PwmErrorType, SetDutyCycle};
use embedded_hal::spi::{ErrorType as SpiErrorType, Operation, SpiDevice};
use embedded_hal_mock::eh1::digital::{Mock as PinMock, State, Transaction as PinTx};
use embedded_hal_mock::eh1::pwm::{Mock as PwmMock, Transaction as PwmTx};
use embedded_hal_mock::eh1::spi::{Mock as SpiMock, Transaction as SpiTx};
use embedded_hal_mock::eh1::MockError;
use mccs::{
    Force, ForceTable64, Length, Params, ProxyConfig, Solver, SolverConfig, SolverError, Topology,
    WindowConfig,
};
use mccs_firmware::drivers::as5047p::{
    self, decode, read_command, As5047p, EncoderConfig, Frame, ANGLECOM, DIAAGC, DIAAGC_LF, ERRFL,
};
use mccs_firmware::drivers::pwm_motor::{MotorConfig, MotorConfigError, PwmMotor};
use mccs_firmware::one_dof::OneDofDevice;
use mccs_firmware::{Controller, Fault, HapticDevice, Roaming};
use std::cell::RefCell;
use std::rc::Rc;

/// A response frame with even parity: data, or the error flag.
fn frame(data: u16, error_flag: bool) -> u16 {
    let f = (data & 0x3FFF) | if error_flag { 0x4000 } else { 0 };
    if f.count_ones() % 2 == 1 {
        f | 0x8000
    } else {
        f
    }
}

fn xfer(cmd: u16, response: u16) -> Vec<SpiTx<u8>> {
    vec![
        SpiTx::transaction_start(),
        SpiTx::transfer(cmd.to_be_bytes().to_vec(), response.to_be_bytes().to_vec()),
        SpiTx::transaction_end(),
    ]
}

#[test]
fn commands_and_frames() {
    assert_eq!(read_command(ANGLECOM), 0xFFFF);
    assert_eq!(read_command(ERRFL), 0x4001);
    assert_eq!(read_command(DIAAGC).count_ones() % 2, 0);
    assert_eq!(read_command(0).count_ones() % 2, 0);
    assert_eq!(decode(frame(1234, false)), Frame::Data(1234));
    assert_eq!(decode(frame(1234, true)), Frame::ErrorFlag);
    assert_eq!(decode(frame(1234, false) ^ 0x0001), Frame::Parity);
    assert_eq!(decode(frame(0x3FFF, false)), Frame::Data(0x3FFF));
    // The stuck lines: low reads a valid-looking angle 0, high an error flag.
    assert_eq!(decode(0x0000), Frame::Data(0));
    assert_eq!(decode(0xFFFF), Frame::ErrorFlag);
    assert_eq!(as5047p::NOP, 0);
}

const MM_PER_COUNT: f64 = 0.002876;

/// No plausibility limit, no diagnostics: the frame checks alone.
fn plain() -> EncoderConfig {
    EncoderConfig {
        zero: 100,
        mm_per_count: MM_PER_COUNT,
        max_step: 8191,
        diag_every: 0,
        max_travel_counts: 1 << 24,
    }
}

#[test]
fn angles_become_travel_and_bad_frames_keep_the_last_good() {
    let angle = read_command(ANGLECOM);
    let mut tx = Vec::new();
    tx.extend(xfer(angle, frame(9999, false))); // answers the power-up NOP: ignored
    tx.extend(xfer(angle, frame(100 + 1000, false))); // +1000 counts
    tx.extend(xfer(angle, frame(100 + 1000, false) ^ 0x0100)); // parity error
    tx.extend(xfer(angle, frame(0, true))); // error flag: the next command reads ERRFL
    tx.extend(xfer(read_command(ERRFL), frame(0, true))); // the flag, still set
    tx.extend(xfer(angle, frame(0x0004, false))); // ERRFL contents: not an angle
    tx.extend(xfer(angle, frame(16384 + 100 - 500, false))); // −500 counts, wrapped
    tx.extend(xfer(angle, frame(100 + 7000, false))); // +7,500 counts: under half a turn
    let spi = SpiMock::new(&tx);
    let mut enc = As5047p::new(spi, plain());
    let mm = |c: f64| Length::from_num(c * MM_PER_COUNT);
    // 10 nm: the Q30 scale is exact to 3e-10 mm per count.
    let close = |a: Length, b: Length| (a - b).abs() < Length::from_num(1e-5);
    assert_eq!(enc.read().unwrap(), Length::ZERO);
    assert!(close(enc.read().unwrap(), mm(1000.0)));
    for why in [
        "parity error",
        "error flag",
        "still flagged",
        "ERRFL contents",
    ] {
        assert!(
            close(enc.read().unwrap(), mm(1000.0)),
            "{why} keeps the last good"
        );
    }
    assert!(close(enc.read().unwrap(), mm(-500.0)));
    let last = enc.read().unwrap();
    assert!(close(last, mm(7000.0)), "{last} vs {}", mm(7000.0));
    let e = enc.errors();
    assert_eq!((e.parity, e.flagged, e.consecutive), (1, 2, 0));
    enc.release().done();
}

/// A lever that turns on past half a turn reads on over whole turns (it once wrapped at
/// ±8192 counts, ±23.6 mm: a lever beyond read suddenly deep, and was driven into its
/// stop), and past its travel the encoder says so, and the device's read fails.
#[test]
fn the_lever_is_followed_over_whole_turns_and_beyond_its_travel_is_a_fault() {
    let angle = read_command(ANGLECOM);
    // 0, then steps of 3000 counts: through half a turn (8192) and a whole one.
    let steps: Vec<i64> = (0..8).map(|k| k * 3000).collect();
    let mut tx = xfer(angle, frame(0, false)); // the power-up NOP's answer
    for &c in &steps {
        tx.extend(xfer(angle, frame(((100 + c) % 16384) as u16, false)));
    }
    let config = EncoderConfig {
        max_travel_counts: 20_000,
        ..plain()
    };
    let mut enc = As5047p::new(SpiMock::new(&tx), config);
    enc.read().unwrap();
    for &c in &steps {
        let z = enc.read().unwrap();
        assert_eq!(enc.counts() as i64, c);
        let want = c as f64 * MM_PER_COUNT;
        assert!((z.to_num::<f64>() - want).abs() < 1e-5, "{z} vs {want}");
        assert_eq!(enc.out_of_travel(), c > 20_000, "at {c} counts");
    }
    enc.release().done();

    // The device: the same lever, through OneDofDevice, fails its read past the travel.
    let mut tx = xfer(angle, frame(0, false));
    for &c in &steps {
        tx.extend(xfer(angle, frame(((100 + c) % 16384) as u16, false)));
    }
    let enc = As5047p::new(SpiMock::new(&tx), config);
    let pwm = PwmMock::new(&[PwmTx::max_duty_cycle(1000)]);
    let config = MotorConfig {
        force_at_full_duty: 3.0,
    };
    let motor = PwmMotor::new(pwm, PinMock::new(&[]), config).unwrap();
    let mut dev = OneDofDevice::new(enc, motor, 3);
    let reads: Vec<bool> = (0..=steps.len())
        .map(|_| dev.read_position().is_ok())
        .collect();
    // NOP, 0 … 18,000 counts read; 21,000 is beyond 20,000.
    assert_eq!(
        reads,
        [true, true, true, true, true, true, true, true, false]
    );
    dev.encoder.release().done();
    let (mut pwm, mut dir, _) = dev.motor.release();
    pwm.done();
    dir.done();
}

/// An SPI device that answers like an AS5047P at a scripted angle per frame (the
/// pipeline included), with the MISO line optionally stuck, and that can fail.
#[derive(Clone)]
struct Sensor(Rc<RefCell<SensorState>>);

struct SensorState {
    angle: Box<dyn FnMut(usize) -> u16>,
    /// MISO forced to this level from this frame on.
    stuck: Option<(usize, bool)>,
    /// Frames whose transfer fails.
    fail: Box<dyn Fn(usize) -> bool>,
    frame: usize,
    last_command: u16,
}

impl Sensor {
    fn new(angle: impl FnMut(usize) -> u16 + 'static) -> Self {
        Self(Rc::new(RefCell::new(SensorState {
            angle: Box::new(angle),
            stuck: None,
            fail: Box::new(|_| false),
            frame: 0,
            last_command: as5047p::NOP,
        })))
    }
}

impl SpiErrorType for Sensor {
    type Error = embedded_hal::spi::ErrorKind;
}

impl SpiDevice<u8> for Sensor {
    fn transaction(&mut self, ops: &mut [Operation<'_, u8>]) -> Result<(), Self::Error> {
        let mut s = self.0.borrow_mut();
        let n = s.frame;
        s.frame += 1;
        if (s.fail)(n) {
            return Err(embedded_hal::spi::ErrorKind::Other);
        }
        for op in ops.iter_mut() {
            if let Operation::Transfer(rx, tx) = op {
                let cmd = u16::from_be_bytes([tx[0], tx[1]]) & 0x3FFF;
                let answer = match s.last_command {
                    ANGLECOM => frame((s.angle)(n), false),
                    DIAAGC => frame(DIAAGC_LF | 0x80, false),
                    _ => frame(0, false),
                };
                let answer = match s.stuck {
                    Some((from, high)) if n >= from => {
                        if high {
                            0xFFFF
                        } else {
                            0x0000
                        }
                    }
                    _ => answer,
                };
                rx.copy_from_slice(&answer.to_be_bytes());
                s.last_command = cmd;
            }
        }
        Ok(())
    }
}

/// The probe's real plausibility limit: 500 mm/s at a 1 kHz frame rate.
fn checked() -> EncoderConfig {
    EncoderConfig {
        zero: 100,
        mm_per_count: MM_PER_COUNT,
        max_step: EncoderConfig::max_step_for(MM_PER_COUNT, 500.0, 1000.0),
        diag_every: 100,
        max_travel_counts: 1 << 24,
    }
}

/// Frames until a read of the 1-DOF device fails, for a sensor, with 3 bad frames
/// tolerated (`None`: it never does within 1000 frames).
fn frames_to_fault(sensor: Sensor) -> Option<usize> {
    let mut enc = As5047p::new(sensor, checked());
    (0..1000).find(|_| {
        enc.read().unwrap();
        enc.errors().consecutive > 3
    })
}

#[test]
fn a_moving_probe_reads_cleanly_with_the_checks_on() {
    // 20 mm/s of travel for 1 s (the sensor's range is ±23.5 mm), within the limit.
    let sensor = Sensor::new(|n| (100.0 + n as f64 * 0.02 / MM_PER_COUNT) as u16 % 16384);
    let mut enc = As5047p::new(sensor.clone(), checked());
    let mut prev = Length::ZERO;
    for n in 0..1000 {
        let z = enc.read().unwrap();
        assert!(z >= prev, "frame {n}: travel went back");
        prev = z;
    }
    let e = enc.errors();
    assert_eq!(
        (e.implausible, e.diagnostic, e.parity, e.flagged),
        (0, 0, 0, 0)
    );
    assert!(
        (prev - Length::from_num(19.98)).abs() < Length::from_num(0.01),
        "{prev}"
    );
}

#[test]
fn stuck_lines_are_detected() {
    // MISO stuck low from power-up: the first diagnostic fails, no angle is ever taken.
    let s = Sensor::new(|_| 5000);
    s.0.borrow_mut().stuck = Some((0, false));
    assert!(frames_to_fault(s).is_some_and(|n| n <= 5));
    // Stuck high: every frame flagged.
    let s = Sensor::new(|_| 5000);
    s.0.borrow_mut().stuck = Some((0, true));
    assert!(frames_to_fault(s).is_some_and(|n| n <= 5));
    // Stuck low mid-run far from angle 0: the jump is implausible at once.
    let s = Sensor::new(|_| 5000);
    s.0.borrow_mut().stuck = Some((300, false));
    assert!(frames_to_fault(s).is_some_and(|n| (300..=305).contains(&n)));
    // Stuck low mid-run with the probe resting at angle 0: caught by the next
    // diagnostic read, at most 100 frames later.
    let s = Sensor::new(|_| 0);
    s.0.borrow_mut().stuck = Some((300, false));
    let n = frames_to_fault(s).expect("caught");
    assert!((300..=406).contains(&n), "{n}");
    // Without the checks, that line is taken as "probe at zero" forever (the defect).
    let s = Sensor::new(|_| 5000);
    s.0.borrow_mut().stuck = Some((300, false));
    let mut enc = As5047p::new(s, plain());
    for _ in 0..1000 {
        enc.read().unwrap();
    }
    assert_eq!(enc.errors().consecutive, 0);
}

#[test]
fn an_implausible_jump_is_a_bad_frame_and_the_allowance_grows_with_time() {
    let step = checked().max_step;
    // One frame jumps far and comes back: one bad frame, then fine.
    let s = Sensor::new(|n| if n == 50 { 9000 } else { 200 });
    let mut enc = As5047p::new(s, checked());
    for _ in 0..100 {
        enc.read().unwrap();
    }
    assert_eq!(enc.errors().implausible, 1);
    assert_eq!(enc.errors().consecutive, 0);
    // One real step of 2.5 times the limit: two bad frames, then the allowance (the
    // limit times the frames since the last good angle) has caught up.
    let s = Sensor::new(move |n| if n < 50 { 200 } else { 200 + step * 5 / 2 });
    let mut enc = As5047p::new(s, checked());
    for _ in 0..100 {
        enc.read().unwrap();
    }
    assert_eq!(enc.errors().implausible, 2);
    assert_eq!(enc.errors().consecutive, 0);
    // Moving steadily faster than the limit is a fault: the allowance never catches up.
    let s = Sensor::new(move |n| 200 + (n as u16) * (step * 3 / 2));
    assert!(frames_to_fault(s).is_some());
}

#[test]
fn motor_duty_saturates_and_goes_through_zero_to_turn() {
    let pwm = PwmMock::new(&[
        PwmTx::max_duty_cycle(1000),
        PwmTx::set_duty_cycle(0),    // +2.5 N: zero before the pin
        PwmTx::set_duty_cycle(250),  // +2.5 N of 10 N
        PwmTx::set_duty_cycle(500),  // +5 N: same direction, pin untouched
        PwmTx::set_duty_cycle(0),    // −30 N: zero before the pin
        PwmTx::set_duty_cycle(1000), // −30 N: saturates
        PwmTx::set_duty_cycle(0),    // 0 N: the pin stays
        PwmTx::set_duty_cycle(0),    // the safe state
    ]);
    let pin = PinMock::new(&[PinTx::set(State::High), PinTx::set(State::Low)]);
    let mut motor = PwmMotor::new(
        pwm,
        pin,
        MotorConfig {
            force_at_full_duty: 10.0,
        },
    )
    .unwrap();
    motor.write(Force::from_num(2.5)).unwrap();
    motor.write(Force::from_num(5.0)).unwrap();
    motor.write(Force::from_num(-30.0)).unwrap();
    motor.write(Force::ZERO).unwrap();
    motor.safe().unwrap();
    let (mut pwm, mut pin, _) = motor.release();
    pwm.done();
    pin.done();
}

/// The defect: with a small full-scale force the duty per newton overflowed and
/// a large force gave zero duty. Every force of the format now maps into [0, max].
#[test]
fn the_duty_never_overflows() {
    for full in [0.001, 0.01, 0.1, 1.0, 10.0, 1024.0] {
        for max in [1u16, 1000, 8400, u16::MAX] {
            let pwm = PwmMock::new(&[PwmTx::max_duty_cycle(max)]);
            let motor = PwmMotor::new(
                pwm,
                PinMock::new(&[]),
                MotorConfig {
                    force_at_full_duty: full,
                },
            )
            .unwrap();
            let mut prev = 0;
            for bits in (0..=i32::MAX).step_by(1 << 16).chain([i32::MAX]) {
                let d = motor.duty_for(Force::from_bits(bits));
                assert!(
                    d >= prev && d <= max,
                    "full {full} N, max {max}: {d} at {bits}"
                );
                prev = d;
                assert_eq!(motor.duty_for(Force::from_bits(-bits)), d);
            }
            assert_eq!(motor.duty_for(Force::MAX), max, "full {full}, max {max}");
            assert_eq!(motor.duty_for(Force::MIN), max);
            assert_eq!(motor.duty_for(Force::ZERO), 0);
            // Proportional below full scale, to one count of the forces the format
            // resolves (9.5e-7 N: a thousandth of the smallest full scale).
            let (half, full_q20) = (Force::from_num(full / 2.0), Force::from_num(full));
            let want = (half.to_bits() as f64 / full_q20.to_bits() as f64 * max as f64).floor();
            let got = motor.duty_for(half);
            assert!((got as f64 - want).abs() <= 1.0, "{got} vs {want}");
            let (mut pwm, mut pin, _) = motor.release();
            pwm.done();
            pin.done();
        }
    }
    for bad in [0.0, -1.0, 1e-4, 2048.0, f64::NAN, f64::INFINITY] {
        let log = Rc::new(RefCell::new(Log::default()));
        let r = PwmMotor::new(
            FakePwm(log.clone(), Fail::Never, 0),
            FakePin(log, Fail::Never, 0, false),
            MotorConfig {
                force_at_full_duty: bad,
            },
        );
        assert_eq!(r.err(), Some(MotorConfigError::ForceAtFullDuty), "{bad}");
    }
}

/// The defect: a failed direction-pin write returned before the duty was set,
/// and the PWM kept its last duty. Now the duty is zero before the pin is written.
#[test]
fn a_failed_direction_write_leaves_zero_duty() {
    let pwm = PwmMock::new(&[
        PwmTx::max_duty_cycle(1000),
        PwmTx::set_duty_cycle(0),
        PwmTx::set_duty_cycle(50), // pushing up at 50/1000
        PwmTx::set_duty_cycle(0),  // turning: zero first
        PwmTx::set_duty_cycle(0),  // the safe state
    ]);
    let err = MockError::Io(std::io::ErrorKind::NotConnected);
    let pin = PinMock::new(&[
        PinTx::set(State::High),
        PinTx::set(State::Low).with_error(err),
    ]);
    let mut motor = PwmMotor::new(
        pwm,
        pin,
        MotorConfig {
            force_at_full_duty: 10.0,
        },
    )
    .unwrap();
    motor.write(Force::from_num(0.5)).unwrap();
    assert!(motor.write(Force::from_num(-0.5)).is_err());
    motor.safe().unwrap();
    let (mut pwm, mut pin, _) = motor.release();
    pwm.done();
    pin.done();
}

/// What a fake PWM channel and pin saw: the duty now, every duty written, every
/// failure.
#[derive(Clone, Debug, Default)]
struct Log {
    duty: u16,
    duties: Vec<u16>,
    pin_high: Option<bool>,
    enabled: bool,
}

/// A call schedule: which calls (0-based, per part) fail.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Fail {
    Never,
    Once(usize),
    From(usize),
}

impl Fail {
    fn at(self, n: usize) -> bool {
        match self {
            Fail::Never => false,
            Fail::Once(k) => n == k,
            Fail::From(k) => n >= k,
        }
    }
}

struct FakePwm(Rc<RefCell<Log>>, Fail, usize);
struct FakePin(Rc<RefCell<Log>>, Fail, usize, bool);

impl PwmErrorType for FakePwm {
    type Error = embedded_hal::pwm::ErrorKind;
}
impl SetDutyCycle for FakePwm {
    fn max_duty_cycle(&self) -> u16 {
        1000
    }
    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
        let n = self.2;
        self.2 += 1;
        if self.1.at(n) {
            return Err(embedded_hal::pwm::ErrorKind::Other);
        }
        let mut log = self.0.borrow_mut();
        log.duty = duty;
        log.duties.push(duty);
        Ok(())
    }
}
impl PinErrorType for FakePin {
    type Error = embedded_hal::digital::ErrorKind;
}
impl OutputPin for FakePin {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        self.set(false)
    }
    fn set_high(&mut self) -> Result<(), Self::Error> {
        self.set(true)
    }
}
impl FakePin {
    fn set(&mut self, high: bool) -> Result<(), embedded_hal::digital::ErrorKind> {
        let n = self.2;
        self.2 += 1;
        if self.1.at(n) {
            return Err(embedded_hal::digital::ErrorKind::Other);
        }
        let mut log = self.0.borrow_mut();
        if self.3 {
            log.enabled = high;
        } else {
            log.pin_high = Some(high);
        }
        Ok(())
    }
}

/// A one-axis device on fakes that log to `log`: the PWM and the direction pin fail as
/// `pwm` and `pin` say, the enable pin never; enabled, 10 N at full duty.
fn rig(
    log: &Rc<RefCell<Log>>,
    sensor: Sensor,
    pwm: Fail,
    pin: Fail,
) -> OneDofDevice<Sensor, FakePwm, FakePin, FakePin> {
    let motor = PwmMotor::with_enable(
        FakePwm(log.clone(), pwm, 0),
        FakePin(log.clone(), pin, 0, false),
        FakePin(log.clone(), Fail::Never, 0, true),
        MotorConfig {
            force_at_full_duty: 10.0,
        },
    )
    .unwrap();
    let mut device = OneDofDevice::new(As5047p::new(sensor, plain()), motor, 3);
    device.motor.enable().unwrap();
    device
}

fn solver() -> Solver<10, 61, 64> {
    let topo = Topology::standard_patch(5, 2.5).unwrap();
    Solver::new(
        topo,
        ForceTable64::new(&Params::TABLE2).unwrap(),
        &SolverConfig::default(),
    )
    .unwrap()
}

/// The controller's contact in [`run_as`].
#[derive(Clone, Copy, Debug, PartialEq)]
enum Mode {
    /// The probe glued to the patch's centre node.
    Glued,
    /// Roaming a flat tissue.
    Roaming,
    /// Roaming a spherical cap of radius 150 mm.
    Cap,
}

/// The roaming contact (issue #19) for [`solver`]: friction 0.6 / 0.4, the window on a
/// 64 × 64 tissue centred under the 1-DOF probe.
fn roaming(s: &mut Solver<10, 61, 64>) -> Roaming<61> {
    let (proxy, wc) = roaming_parts(s);
    let window = s.window(&wc, &mccs::Flat, &proxy, 0.0, 0.0).unwrap();
    Roaming::new(proxy, window)
}

/// [`roaming`] over a cap of radius 150 mm (its top under the probe).
fn roaming_cap(s: &mut Solver<10, 61, 64>) -> Roaming<61, mccs::Cap> {
    let (proxy, wc) = roaming_parts(s);
    let cap = mccs::Sphere { radius_mm: 150.0 };
    let window = s.window(&wc, &cap, &proxy, 0.0, 0.0).unwrap();
    Roaming::new(proxy, window)
}

fn roaming_parts(s: &Solver<10, 61, 64>) -> (mccs::Proxy, WindowConfig) {
    let proxy = s
        .proxy(&ProxyConfig {
            grid: 5,
            spacing: 2.5,
            mu_s: 0.6,
            mu_k: 0.4,
            probe_radius: 0.0,
        })
        .unwrap();
    let wc = WindowConfig {
        tissue_w: 64,
        tissue_h: 64,
        hysteresis: 0.1,
    };
    (proxy, wc)
}

/// A 1-DOF device on fakes, the probe pressing in and out (so that the direction
/// turns), with faults at `spi`, `pin` and `pwm` calls; 400 ticks of a controller, its
/// probe glued or roaming (`mode`). Returns the tick of the first failure, the tick the
/// fault latched, and whether the actuator was driven (duty above zero with the driver
/// enabled) at the end of every tick.
fn run_as(spi: Fail, pin: Fail, pwm: Fail, mode: Mode) -> (Option<usize>, Option<usize>, Vec<u16>) {
    let log = Rc::new(RefCell::new(Log::default()));
    // 0.3 mm of travel per 100 counts; down to −3 mm and back, every 100 ticks.
    let sensor = Sensor::new(|n| {
        let phase = (n % 200) as f64 / 100.0;
        let mm = if phase < 1.0 {
            -3.0 * phase
        } else {
            -3.0 * (2.0 - phase)
        } + 0.5;
        (100.0 + mm / MM_PER_COUNT).rem_euclid(16384.0) as u16
    });
    sensor.0.borrow_mut().fail = Box::new(move |n| spi.at(n));
    let device = rig(&log, sensor, pwm, pin);
    // One tick, returning the telemetry after it: the controller glued or roaming.
    let mut tick: Box<dyn FnMut() -> mccs_firmware::Telemetry> = match mode {
        Mode::Roaming => {
            let mut s = solver();
            let c = roaming(&mut s);
            let mut ctl = Controller::with_contact(s, c, device, 0);
            Box::new(move || {
                ctl.tick(None);
                ctl.telemetry()
            })
        }
        Mode::Cap => {
            let mut s = solver();
            let c = roaming_cap(&mut s);
            let mut ctl = Controller::with_contact(s, c, device, 0);
            Box::new(move || {
                ctl.tick(None);
                ctl.telemetry()
            })
        }
        Mode::Glued => {
            let mut ctl = Controller::new(solver(), device, 0);
            Box::new(move || {
                ctl.tick(None);
                ctl.telemetry()
            })
        }
    };
    let mut duties = Vec::new();
    let (mut first_failure, mut latched) = (None, None);
    let mut before = mccs_firmware::Telemetry::new();
    for t in 0..400 {
        let seen = log.borrow().duties.len();
        let now = tick();
        let failed_now = spi.at(t)
            || log.borrow().duties.len() < seen + 1
            || now.fault != before.fault
            || now.safe_state_errors != before.safe_state_errors;
        before = now;
        if failed_now && first_failure.is_none() {
            first_failure = Some(t);
        }
        if now.fault.is_some() && latched.is_none() {
            latched = Some(t);
            assert!(!log.borrow().enabled || pin != Fail::Never || pwm != Fail::Never);
        }
        let l = log.borrow();
        duties.push(if l.enabled { l.duty } else { 0 });
    }
    (first_failure, latched, duties)
}

/// Every device call site — the encoder read, the direction pin, the PWM — failing
/// once and failing forever: the actuator is off (zero duty, or the driver disabled
/// where the PWM refuses every write) at the end of the tick the fault is found in, and
/// at the end of every tick after (the safe state re-asserted every tick).
/// The same with the probe glued and roaming, flat and over a cap (issue #19's contact:
/// the fault path does not depend on it).
#[test]
fn a_fault_at_any_call_site_ends_at_the_actuator() {
    for roam in [Mode::Glued, Mode::Roaming, Mode::Cap] {
        let (_, latched, duties) = run_as(Fail::Never, Fail::Never, Fail::Never, roam);
        assert_eq!(latched, None);
        assert!(
            duties.iter().filter(|&&d| d > 0).count() > 100,
            "{roam:?}: it renders"
        );
        for schedule in [Fail::Once(150), Fail::From(150)] {
            for site in ["spi", "direction", "pwm"] {
                let (spi, pin, pwm) = match site {
                    "spi" => (schedule, Fail::Never, Fail::Never),
                    // The pin is written when the direction changes: the force on this
                    // 1-DOF probe always pushes up, so its one call is the first contact.
                    "direction" => (Fail::Never, shift(schedule, 0), Fail::Never),
                    _ => (Fail::Never, Fail::Never, shift(schedule, 150)),
                };
                let (_, latched, duties) = run_as(spi, pin, pwm, roam);
                let t = latched
                    .unwrap_or_else(|| panic!("{roam:?}: {site} {schedule:?}: no fault latched"));
                assert!(
                    duties[t..].iter().all(|&d| d == 0),
                    "{roam:?}: {site} {schedule:?}: duty after the fault at tick {t}: {:?}",
                    &duties[t..(t + 10).min(duties.len())]
                );
            }
        }
    }
}

fn shift(f: Fail, k: usize) -> Fail {
    match f {
        Fail::Once(_) => Fail::Once(k),
        Fail::From(_) => Fail::From(k),
        Fail::Never => Fail::Never,
    }
}

/// The PWM failing forever, the safe state itself cannot write zero: it keeps trying
/// every tick, and counts the failures; the enable pin drops.
#[test]
fn a_failing_safe_state_keeps_trying_and_drops_the_enable_pin() {
    let log = Rc::new(RefCell::new(Log::default()));
    let sensor = Sensor::new(|_| 16384 + 100 - 300);
    let device = rig(&log, sensor, Fail::From(3), Fail::Never);
    assert!(log.borrow().enabled);
    let mut ctl = Controller::new(solver(), device, 0);
    for _ in 0..20 {
        ctl.tick(None);
    }
    let t = ctl.telemetry();
    assert_eq!(t.fault, Some(Fault::Write));
    assert!(t.safe_state_errors >= 15, "{}", t.safe_state_errors);
    assert!(!log.borrow().enabled, "the driver is disabled");
    assert_eq!(t.force, [Force::ZERO; 3]);
}

/// A device that fails on demand, for the controller alone.
struct Flaky {
    fail_read_at: u32,
    fail_write_at: u32,
    n: u32,
    writes: Vec<[Force; 3]>,
    safe_calls: u32,
}

impl HapticDevice for Flaky {
    type Error = ();
    fn read_position(&mut self) -> Result<[Length; 3], ()> {
        self.n += 1;
        if self.n == self.fail_read_at {
            Err(())
        } else {
            Ok([Length::ZERO, Length::ZERO, Length::from_num(-1)])
        }
    }
    fn write_force(&mut self, force: [Force; 3]) -> Result<(), ()> {
        self.writes.push(force);
        if self.writes.len() as u32 == self.fail_write_at {
            Err(())
        } else {
            Ok(())
        }
    }
    fn safe_state(&mut self) -> Result<(), ()> {
        self.safe_calls += 1;
        Ok(())
    }
}

#[test]
fn any_device_error_latches_the_safe_state_and_reasserts_it() {
    for (read, write, fault) in [(5, 0, Fault::Read), (0, 5, Fault::Write)] {
        let dev = Flaky {
            fail_read_at: read,
            fail_write_at: write,
            n: 0,
            writes: vec![],
            safe_calls: 0,
        };
        let mut ctl = Controller::new(solver(), dev, 0);
        for _ in 0..20 {
            ctl.tick(None);
        }
        assert_eq!(ctl.telemetry().fault, Some(fault));
        let dev = ctl.device();
        assert!(
            dev.writes[..4].iter().any(|f| f[2] != Force::ZERO),
            "it was rendering"
        );
        assert_eq!(
            dev.writes.len(),
            if write > 0 { 5 } else { 4 },
            "no writes after"
        );
        assert_eq!(
            dev.safe_calls, 16,
            "the safe state on the fault and every tick after"
        );
        assert_eq!(ctl.telemetry().force, [Force::ZERO; 3]);
    }
}

/// A stop from outside the tick's own checks (the board's break input: the emergency
/// stop or an amplifier fault) latches the safe state at once and on every tick after,
/// with its reason; a later stop or device error does not replace the first reason.
#[test]
fn an_external_stop_latches_the_safe_state_with_its_reason() {
    let dev = Flaky {
        fail_read_at: 12,
        fail_write_at: 0,
        n: 0,
        writes: vec![],
        safe_calls: 0,
    };
    let mut ctl = Controller::new(solver(), dev, 0);
    for _ in 0..5 {
        ctl.tick(None);
    }
    assert!(
        ctl.device().writes.iter().any(|f| f[2] != Force::ZERO),
        "it was rendering"
    );
    ctl.stop(Fault::Amplifier);
    assert_eq!(ctl.device().safe_calls, 1, "the safe state at once");
    for _ in 0..10 {
        ctl.tick(None);
    }
    ctl.stop(Fault::Overruns);
    assert_eq!(ctl.telemetry().fault, Some(Fault::Amplifier));
    assert_eq!(ctl.device().writes.len(), 5, "no writes after the stop");
    assert_eq!(ctl.device().safe_calls, 11, "reasserted every tick");
    assert_eq!(ctl.telemetry().force, [Force::ZERO; 3]);
}

/// The defect: a parameter set prepared for another topology was applied, and
/// the force chattered. It is refused; the solver keeps its set, and the force is what
/// it would have been without the swap.
#[test]
fn a_parameter_set_for_another_topology_is_refused() {
    let table = ForceTable64::new(&Params::TABLE2).unwrap();
    let cfg = SolverConfig::default();
    let other = Topology::<10, 61>::standard_patch(4, 2.5).unwrap();
    let foreign = Solver::<10, 61, 64>::prepare_for(&other, table, &cfg).unwrap();
    let mut s = solver();
    assert_eq!(s.apply(foreign), Err(SolverError::ForeignParamSet));
    // Another tick rate, on the right topology: refused too.
    let fast = SolverConfig {
        tick_hz: 2000.0,
        ..cfg
    };
    let topo = Topology::<10, 61>::standard_patch(5, 2.5).unwrap();
    let wrong_rate = Solver::<10, 61, 64>::prepare_for(&topo, table, &fast).unwrap();
    assert_eq!(s.apply(wrong_rate), Err(SolverError::ForeignParamSet));
    // Its own topology and rate: applied.
    let own = s.prepare(table, &cfg).unwrap();
    assert_eq!(s.apply(own), Ok(()));
    // Through the controller: counted, and the force is unchanged.
    let dev = || Flaky {
        fail_read_at: 0,
        fail_write_at: 0,
        n: 0,
        writes: vec![],
        safe_calls: 0,
    };
    let mut with = Controller::new(solver(), dev(), 0);
    let mut without = Controller::new(solver(), dev(), 0);
    for t in 0..200 {
        let swap = (t == 100).then_some(foreign);
        assert_eq!(with.tick(swap), without.tick(None), "tick {t}");
    }
    assert_eq!(with.telemetry().rejected_swaps, 1);
    assert_eq!(with.telemetry().swaps, 0);
}

/// The lever moving `counts_per_tick` a tick under a force of `push_n` along its
/// motion (negative: against it), its passivity observer at 2 mJ beyond a 10 mJ credit:
/// the tick it trips at (`None`: not within 2,000), and the log then.
fn pushed_lever(counts_per_tick: i64, push_n: f64) -> (Option<usize>, Log) {
    let log = Rc::new(RefCell::new(Log::default()));
    let sensor = Sensor::new(move |n| (100 + counts_per_tick * n as i64).rem_euclid(16384) as u16);
    let mut device = rig(&log, sensor, Fail::Never, Fail::Never)
        .with_passivity(mccs::PassivityLimits::new(2.0, 10.0));
    // At rest, no force: it watches from here.
    let z0 = device.read_position().unwrap()[2];
    device.write_force([Force::ZERO; 3]).unwrap();
    let z1 = device.read_position().unwrap()[2];
    let along = if z1 >= z0 { push_n } else { -push_n };
    let force = [Force::ZERO, Force::ZERO, Force::from_num(along)];
    for k in 0..2000 {
        match device.write_force(force) {
            Ok(()) => {}
            Err(mccs_firmware::one_dof::OneDofError::EnergyOut) => {
                let log = log.borrow().clone();
                return (Some(k), log);
            }
            Err(e) => panic!("tick {k}: {e:?}"),
        }
        device.read_position().unwrap();
    }
    let log = log.borrow().clone();
    (None, log)
}

#[test]
fn a_force_along_the_lever_s_motion_trips_the_passivity_observer_motor_safe_first() {
    // 2 N pushing the lever along its own motion, 0.0288 mm a tick (29 mm/s): the credit
    // fills only from the hand's input, none here, so the trip comes at 2 mJ of output:
    // 1 mm, about 35 ticks.
    let (tick, log) = pushed_lever(10, 2.0);
    let tick = tick.expect("the observer trips");
    assert!((30..=40).contains(&tick), "tripped at tick {tick}");
    assert_eq!(log.duty, 0, "zero duty at the trip");
    assert!(!log.enabled, "the driver disabled at the trip");
    // Against the motion (the hand pressing into a resisting tissue): never.
    assert_eq!(pushed_lever(10, -2.0).0, None);
    // And no observer, no trip.
    let log = Rc::new(RefCell::new(Log::default()));
    let mut plain_device = rig(
        &log,
        Sensor::new(|n| (100 + 10 * n) as u16),
        Fail::Never,
        Fail::Never,
    );
    for _ in 0..200 {
        plain_device.read_position().unwrap();
        plain_device
            .write_force([Force::ZERO, Force::ZERO, Force::from_num(2.0)])
            .unwrap();
    }
    assert_eq!(plain_device.passivity_mj(), None);
}
