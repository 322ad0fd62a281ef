//! The device layer against embedded-hal-mock: the AS5047P frames, the motor drive, the
//! 1-DOF device, and the controller's safe state.

use embedded_hal_mock::eh1::digital::{Mock as PinMock, State, Transaction as PinTx};
use embedded_hal_mock::eh1::pwm::{Mock as PwmMock, Transaction as PwmTx};
use embedded_hal_mock::eh1::spi::{Mock as SpiMock, Transaction as SpiTx};
use mccs::{Force, ForceTable64, Length, Params, Solver, SolverConfig, Topology};
use mccs_firmware::drivers::as5047p::{
    self, decode, read_command, As5047p, EncoderConfig, Frame, ANGLECOM, ERRFL,
};
use mccs_firmware::drivers::pwm_motor::{MotorConfig, PwmMotor};
use mccs_firmware::one_dof::OneDofDevice;
use mccs_firmware::{Controller, Fault, HapticDevice};

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
    assert_eq!(read_command(0).count_ones() % 2, 0);
    assert_eq!(decode(frame(1234, false)), Frame::Data(1234));
    assert_eq!(decode(frame(1234, true)), Frame::ErrorFlag);
    assert_eq!(decode(frame(1234, false) ^ 0x0001), Frame::Parity);
    assert_eq!(decode(frame(0x3FFF, false)), Frame::Data(0x3FFF));
}

const MM_PER_COUNT: f64 = 0.002876;

fn config() -> EncoderConfig {
    EncoderConfig {
        zero: 100,
        mm_per_count: MM_PER_COUNT,
    }
}

#[test]
fn angles_become_travel_and_bad_frames_keep_the_last_good() {
    let angle = read_command(ANGLECOM);
    let mut tx = Vec::new();
    tx.extend(xfer(angle, frame(9999, false))); // answers the power-up NOP: ignored
    tx.extend(xfer(angle, frame(100 + 1000, false))); // +1000 counts
    tx.extend(xfer(angle, frame(100 + 1000, false) ^ 0x0100)); // parity error
    tx.extend(xfer(angle, frame(0, true))); // error flag: next command reads ERRFL
    tx.extend(xfer(read_command(ERRFL), frame(0, true))); // flag still set until then
    tx.extend(xfer(angle, frame(0x0004, false))); // ERRFL contents: not an angle
    tx.extend(xfer(angle, frame(16384 + 100 - 500, false))); // −500 counts, wrapped
    tx.extend(xfer(angle, frame(100 + 8191, false))); // half a turn less one
    let spi = SpiMock::new(&tx);
    let mut enc = As5047p::new(spi, config());
    let mm = |c: f64| Length::from_num(c * MM_PER_COUNT);
    // 10 nm: the Q30 scale is exact to 3e-10 mm per count.
    let close = |a: Length, b: Length| (a - b).abs() < Length::from_num(1e-5);
    assert_eq!(enc.read().unwrap(), Length::ZERO);
    assert!(close(enc.read().unwrap(), mm(1000.0)));
    assert!(
        close(enc.read().unwrap(), mm(1000.0)),
        "parity error keeps the last good"
    );
    assert!(
        close(enc.read().unwrap(), mm(1000.0)),
        "error flag keeps the last good"
    );
    assert!(
        close(enc.read().unwrap(), mm(1000.0)),
        "so does the next flagged frame"
    );
    assert!(
        close(enc.read().unwrap(), mm(1000.0)),
        "ERRFL contents are not a position"
    );
    assert!(close(enc.read().unwrap(), mm(-500.0)));
    let last = enc.read().unwrap();
    assert!(close(last, mm(8191.0)), "{last} vs {}", mm(8191.0));
    let e = enc.errors();
    assert_eq!((e.parity, e.flagged, e.consecutive), (1, 2, 0));
    enc.release().done();
}

#[test]
fn motor_duty_saturates_and_direction_changes_once() {
    let pwm = PwmMock::new(&[
        PwmTx::max_duty_cycle(1000),
        PwmTx::set_duty_cycle(250),  // +2.5 N of 10 N
        PwmTx::set_duty_cycle(500),  // +5 N: same direction, pin untouched
        PwmTx::set_duty_cycle(1000), // −30 N: saturates
        PwmTx::set_duty_cycle(0),    // 0 N
    ]);
    let pin = PinMock::new(&[PinTx::set(State::High), PinTx::set(State::Low)]);
    let mut motor = PwmMotor::new(
        pwm,
        pin,
        MotorConfig {
            force_at_full_duty: 10.0,
        },
    );
    motor.write(Force::from_num(2.5)).unwrap();
    motor.write(Force::from_num(5.0)).unwrap();
    motor.write(Force::from_num(-30.0)).unwrap();
    motor.write(Force::ZERO).unwrap();
    let (mut pwm, mut pin) = motor.release();
    pwm.done();
    pin.done();
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

#[test]
fn one_dof_device_faults_after_bad_frames_and_the_controller_goes_safe() {
    let angle = read_command(ANGLECOM);
    let bad = frame(1000, false) ^ 1;
    let mut tx = Vec::new();
    tx.extend(xfer(angle, frame(100, false))); // power-up answer
    tx.extend(xfer(angle, frame(100 - 100, false))); // −100 counts: pressing in
    for _ in 0..4 {
        tx.extend(xfer(angle, bad));
    }
    let spi = SpiMock::new(&tx);
    // Tick 1, 2 render; ticks 3, 4, 5 keep the last good position (3 bad frames
    // tolerated); tick 6 fails: safe state, zero force from then on.
    let mut duties = vec![PwmTx::max_duty_cycle(1000)];
    duties.extend((0..5).map(|_| PwmTx::set_duty_cycle(0)));
    duties.extend([PwmTx::set_duty_cycle(0), PwmTx::set_duty_cycle(0)]);
    let pwm = PwmMock::new(&duties);
    // Tick 1: no contact yet, zero force (pin low); tick 2 on: pressed in, pushing back up
    // (pin high); the safe state: zero (pin low).
    let pin = PinMock::new(&[
        PinTx::set(State::Low),
        PinTx::set(State::High),
        PinTx::set(State::Low),
    ]);
    let device = OneDofDevice {
        encoder: As5047p::new(spi, config()),
        motor: PwmMotor::new(
            pwm,
            pin,
            MotorConfig {
                force_at_full_duty: 1000.0,
            },
        ),
        max_bad_frames: 3,
    };
    let mut ctl = Controller::new(solver(), device, 0);
    for _ in 0..5 {
        ctl.tick(None);
        assert_eq!(ctl.telemetry().fault, None);
    }
    ctl.tick(None);
    assert_eq!(ctl.telemetry().fault, Some(Fault::Read));
    assert_eq!(ctl.telemetry().force, [Force::ZERO; 3]);
    // Latched: no more reads, zero force written.
    ctl.tick(None);
    assert_eq!(ctl.telemetry().force, [Force::ZERO; 3]);
    let (_, device) = ctl.into_parts();
    assert_eq!(device.encoder.errors().parity, 4);
    device.encoder.release().done();
    let (mut pwm, mut pin) = device.motor.release();
    pwm.done();
    pin.done();
}

/// A device that fails on demand.
struct Flaky {
    fail_read_at: u32,
    fail_write_at: u32,
    n: u32,
    writes: Vec<[Force; 3]>,
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
}

#[test]
fn any_device_error_latches_zero_force() {
    for (read, write, fault) in [(5, 0, Fault::Read), (0, 5, Fault::Write)] {
        let dev = Flaky {
            fail_read_at: read,
            fail_write_at: write,
            n: 0,
            writes: vec![],
        };
        let mut ctl = Controller::new(solver(), dev, 0);
        for _ in 0..20 {
            ctl.tick(None);
        }
        assert_eq!(ctl.telemetry().fault, Some(fault));
        let writes = &ctl.device().writes;
        assert!(
            writes[..4].iter().any(|f| f[2] != Force::ZERO),
            "it was rendering"
        );
        assert!(
            writes[5..].iter().all(|f| *f == [Force::ZERO; 3]),
            "then zero, for good"
        );
        assert_eq!(ctl.telemetry().force, [Force::ZERO; 3]);
    }
}

#[test]
fn as5047p_constants() {
    assert_eq!(as5047p::NOP, 0);
}
