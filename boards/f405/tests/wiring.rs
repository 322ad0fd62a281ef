//! The board's device wiring against `embedded-hal-mock`: the constants held to the parts'
//! limits (the HAL's SPI divider, the PWM's resolution, the tick timer), the SPI mode,
//! the encoder's frame sequence from power-up, the duty and direction on a force step,
//! the safe state at start-up and on a fault, and the run QEMU checks (an encoder that
//! reads zeros), tick by tick. A wrong pin level, command or duty fails the mock.

mod common;

use common::{moved_by, Log, Pin, Pwm, Sensor, CHECKED_BY};
use embedded_hal::spi::{Phase, Polarity};
use embedded_hal_mock::eh1::digital::{Mock as PinMock, State, Transaction as PinTx};
use embedded_hal_mock::eh1::pwm::{Mock as PwmMock, Transaction as PwmTx};
use embedded_hal_mock::eh1::spi::{Mock as SpiMock, Transaction as SpiTx};
use haptic_f405::config::{
    pwm_max_duty, spi_clock_hz, tick_timer, BoardConfigError, Clocks, QEMU_TIMER_CLOCK_HZ,
};
use haptic_f405::device::{self, BoardController, SPI_MODE};
use haptic_f405::telemetry::{qemu_verdict, zeros_fault_tick, BoardTelemetry, QemuMismatch};
use haptic_f405::{BoardConfig, BOARD};
use mccs::{Force, ForceTable, ForceTable64, Length, Params};
use mccs_firmware::drivers::as5047p::{read_command, ANGLECOM, DIAAGC, DIAAGC_LF};
use mccs_firmware::{Fault, HapticDevice};

/// A response frame with even parity.
fn frame(data: u16) -> u16 {
    let f = data & 0x3FFF;
    if f.count_ones() % 2 == 1 {
        f | 0x8000
    } else {
        f
    }
}

/// One SPI frame: a command out, a response in, chip select around it.
fn xfer(command: u16, response: u16) -> Vec<SpiTx<u8>> {
    vec![
        SpiTx::transaction_start(),
        SpiTx::transfer(
            read_command(command).to_be_bytes().to_vec(),
            response.to_be_bytes().to_vec(),
        ),
        SpiTx::transaction_end(),
    ]
}

/// The board's tissue, the table its firmware runs.
fn tissue() -> haptic_f405::tissue::TissueTable {
    haptic_f405::tissue::TISSUE
}

#[test]
fn the_board_constants_hold_the_parts_limits() {
    assert_eq!(BOARD.check(), Ok(()));
    let clocks = Clocks::for_sysclk(BOARD.sysclk_hz);
    assert_eq!(
        clocks,
        Clocks {
            sysclk_hz: 168_000_000,
            pclk2_hz: 84_000_000,
            tim1_hz: 168_000_000,
            tim2_hz: 84_000_000,
            pclk1_hz: 42_000_000,
        }
    );
    // The HAL rounds the SPI divider down: 10 MHz asked of 84 MHz is 10.5 MHz, over the
    // AS5047P's limit; the board asks 7 MHz and gets 5.25 MHz.
    assert_eq!(spi_clock_hz(84_000_000, 10_000_000), 10_500_000);
    assert_eq!(spi_clock_hz(84_000_000, BOARD.spi_request_hz), 5_250_000);
    let too_fast = BoardConfig {
        spi_request_hz: 10_000_000,
        ..BOARD
    };
    assert_eq!(too_fast.check(), Err(BoardConfigError::SpiTooFast));
    // 20 kHz PWM from TIM1's 168 MHz: 8400 steps.
    assert_eq!(pwm_max_duty(clocks.tim1_hz, BOARD.pwm_hz), 8400);
    // The tick: a 1 MHz counter, 1000 counts per tick, on the board and in QEMU.
    assert_eq!(tick_timer(clocks.tim2_hz, 1000), Some((83, 999)));
    assert_eq!(tick_timer(QEMU_TIMER_CLOCK_HZ, 1000), Some((999, 999)));
    assert_eq!(
        tick_timer(84_500_000, 1000),
        None,
        "not a whole number of MHz"
    );
    assert_eq!(tick_timer(84_000_000, 3000), None, "does not divide 1 MHz");
    // The reset clock QEMU keeps: everything at HSI's 16 MHz.
    let hsi = Clocks::for_sysclk(16_000_000);
    assert_eq!(
        (hsi.pclk2_hz, hsi.tim1_hz, hsi.tim2_hz),
        (16_000_000, 16_000_000, 16_000_000)
    );
    assert!(spi_clock_hz(hsi.pclk2_hz, BOARD.spi_request_hz) <= 10_000_000);
    // A 100 MHz core: APB1 ÷4 = 25 MHz (TIM2 at 50 MHz), APB2 ÷2 = 50 MHz (TIM1 at 100).
    let c100 = Clocks::for_sysclk(100_000_000);
    assert_eq!(
        (c100.pclk2_hz, c100.tim1_hz, c100.tim2_hz),
        (50_000_000, 100_000_000, 50_000_000)
    );
}

#[test]
fn every_constant_out_of_range_is_named() {
    use BoardConfigError as E;
    let cases: [(BoardConfig, E); 18] = [
        (
            BoardConfig {
                hse_hz: 2_000_000,
                ..BOARD
            },
            E::Hse,
        ),
        (
            BoardConfig {
                sysclk_hz: 180_000_000,
                ..BOARD
            },
            E::Sysclk,
        ),
        (
            BoardConfig {
                tick_hz: 3000,
                ..BOARD
            },
            E::Tick,
        ),
        (
            BoardConfig {
                tick_hz: 50,
                ..BOARD
            },
            E::Tick,
        ),
        (
            BoardConfig {
                spi_request_hz: 0,
                ..BOARD
            },
            E::SpiTooFast,
        ),
        (
            BoardConfig {
                pwm_hz: 200_000,
                ..BOARD
            },
            E::PwmResolution,
        ),
        (
            BoardConfig {
                watchdog_ms: 5,
                ..BOARD
            },
            E::Watchdog,
        ),
        (
            BoardConfig {
                watchdog_ms: 20_000,
                ..BOARD
            },
            E::Watchdog,
        ),
        (
            BoardConfig {
                encoder_zero: 16384,
                ..BOARD
            },
            E::Encoder,
        ),
        (
            BoardConfig {
                mm_per_count: f64::NAN,
                ..BOARD
            },
            E::Encoder,
        ),
        (
            BoardConfig {
                max_speed_mm_s: 0.0,
                ..BOARD
            },
            E::Speed,
        ),
        (
            BoardConfig {
                force_at_full_duty: 0.0,
                ..BOARD
            },
            E::Motor(mccs_firmware::drivers::pwm_motor::MotorConfigError::ForceAtFullDuty),
        ),
        (BoardConfig { grid: 11, ..BOARD }, E::Patch),
        (
            BoardConfig {
                node_mass_g: -1.0,
                ..BOARD
            },
            E::Patch,
        ),
        (
            BoardConfig {
                coupling_stiffness: 0.0,
                ..BOARD
            },
            E::Coupling,
        ),
        (
            BoardConfig {
                coupling_damping: -1.0,
                ..BOARD
            },
            E::Coupling,
        ),
        (
            BoardConfig {
                max_force: f64::NAN,
                ..BOARD
            },
            E::Coupling,
        ),
        // The clamp over what the motor gives at full duty: it would saturate unsaid.
        (
            BoardConfig {
                max_force: 3.5,
                ..BOARD
            },
            E::ForceClamp,
        ),
    ];
    for (config, expected) in cases {
        assert_eq!(config.check(), Err(expected), "{config:?}");
        assert!(!expected.message().is_empty());
    }
    // A bad constant stops the device before it touches a pin.
    let log = Log::default();
    let r = device::device(
        &BoardConfig { grid: 2, ..BOARD },
        Sensor::new(|_| 0),
        Pwm(log.clone()),
        Pin(log.clone(), "dir"),
        Pin(log.clone(), "enable"),
    );
    let Err(device::StartError::Config(E::Patch)) = r else {
        panic!("grid 2 accepted")
    };
    assert!(log.0.borrow().is_empty(), "{:?}", log.0.borrow());
}

#[test]
fn the_spi_mode_is_the_as5047p_s() {
    // Datasheet: SPI mode 1, CPOL = 0 (clock idles low), CPHA = 1 (data captured on
    // the falling, second edge).
    assert_eq!(SPI_MODE.polarity, Polarity::IdleLow);
    assert_eq!(SPI_MODE.phase, Phase::CaptureOnSecondTransition);
}

#[test]
fn start_up_is_the_safe_state_then_the_driver_is_enabled() {
    let mut pwm = PwmMock::new(&[PwmTx::max_duty_cycle(8400), PwmTx::set_duty_cycle(0)]);
    let mut dir = PinMock::new(&[]);
    let mut en = PinMock::new(&[PinTx::set(State::Low), PinTx::set(State::High)]);
    let mut spi = SpiMock::new(&[]);
    let dev = device::device(&BOARD, spi.clone(), pwm.clone(), dir.clone(), en.clone()).unwrap();
    let mut slot: Option<BoardController<_>> = None;
    if device::controller_into(&BOARD, tissue(), dev, &mut slot).is_err() {
        panic!("the board's controller did not build");
    }
    let ctl = slot.unwrap();
    assert_eq!(
        ctl.solver().topology().edges().len(),
        366,
        "the N = 10 patch"
    );
    drop(ctl);
    spi.done();
    pwm.done();
    dir.done();
    en.done();
}

#[test]
fn the_encoder_frames_from_power_up() {
    // Power-up: DIAAGC until a diagnostic passes (the first frame answers nothing),
    // then ANGLECOM; each response answers the previous frame's command.
    let angle = 1000u16;
    let mut tx = Vec::new();
    tx.extend(xfer(DIAAGC, frame(0))); // answers the power-up NOP
    tx.extend(xfer(DIAAGC, frame(DIAAGC_LF))); // DIAAGC: running
    tx.extend(xfer(ANGLECOM, frame(DIAAGC_LF))); // DIAAGC again: running
    tx.extend(xfer(ANGLECOM, frame(angle))); // the first angle
    let mut spi = SpiMock::new(&tx);
    let mut pwm = PwmMock::new(&[PwmTx::max_duty_cycle(8400), PwmTx::set_duty_cycle(0)]);
    let mut en = PinMock::new(&[PinTx::set(State::Low)]);
    let mut dir = PinMock::new(&[]);
    let mut dev =
        device::device(&BOARD, spi.clone(), pwm.clone(), dir.clone(), en.clone()).unwrap();
    for _ in 0..3 {
        assert_eq!(
            dev.read_position().unwrap(),
            [Length::ZERO; 3],
            "no angle yet"
        );
    }
    let z = dev.read_position().unwrap()[2].to_num::<f64>();
    let expected = (angle - BOARD.encoder_zero) as f64 * BOARD.mm_per_count;
    assert!((z - expected).abs() < 1e-5, "{z} mm vs {expected} mm");
    drop(dev);
    spi.done();
    pwm.done();
    en.done();
    dir.done();
}

#[test]
fn a_force_step_sets_the_direction_at_zero_duty_then_the_duty() {
    // The lever at rest passes its start-up nudges first (the tissue's force after).
    let log = Log::default();
    let mut dev = device::device(
        &BOARD,
        Sensor::new(moved_by(&log, 1, |_| BOARD.encoder_zero)),
        Pwm(log.clone()),
        Pin(log.clone(), "dir"),
        Pin(log.clone(), "enable"),
    )
    .unwrap();
    let z = |f: f64| [Force::ZERO, Force::ZERO, Force::from_num(f)];
    for _ in 0..CHECKED_BY {
        dev.read_position().unwrap();
        dev.write_force(z(0.0)).unwrap();
    }
    assert!(dev.direction_checked());
    log.0.borrow_mut().clear();
    for f in [1.5, 1.5, -1.5, -6.0, 0.0] {
        dev.write_force(z(f)).unwrap();
    }
    // 1.5 N of the 3 N at full duty: half of 8400 steps; the nudges ended going down.
    assert_eq!(
        *log.0.borrow(),
        [
            "duty 0",
            "dir high",
            "duty 4200", // +z: zero first, the direction, the duty
            "duty 4200", // +z again: no direction change
            "duty 0",
            "dir low",
            "duty 4200", // −z
            "duty 8400", // −6 N: saturates at full duty
            "duty 0",    // no force
        ]
    );
}

/// The run QEMU makes: its SPI has no device behind it, so every frame reads zeros.
/// Tick by tick: the solver runs (no force: the probe sits at the surface) until the
/// encoder's rules fault the read, then the safe state — zero duty, enable low — every
/// tick, and the SPI is never touched again.
#[test]
fn an_encoder_reading_zeros_ends_in_the_safe_state_on_the_expected_tick() {
    let fault_tick = zeros_fault_tick(&BOARD).unwrap();
    assert_eq!(fault_tick, BOARD.max_bad_frames + 1);
    let ticks = BOARD.qemu_ticks;
    let mut spi_tx = Vec::new();
    let mut pwm_tx = vec![PwmTx::max_duty_cycle(8400), PwmTx::set_duty_cycle(0)];
    let mut en_tx = vec![PinTx::set(State::Low), PinTx::set(State::High)];
    for t in 0..ticks {
        if t <= fault_tick {
            spi_tx.extend(xfer(DIAAGC, 0));
        }
        pwm_tx.push(PwmTx::set_duty_cycle(0));
        if t >= fault_tick {
            en_tx.push(PinTx::set(State::Low));
        }
    }
    let mut spi = SpiMock::new(&spi_tx);
    let mut pwm = PwmMock::new(&pwm_tx);
    let mut en = PinMock::new(&en_tx);
    let mut dir = PinMock::new(&[]);
    let dev = device::device(&BOARD, spi.clone(), pwm.clone(), dir.clone(), en.clone()).unwrap();
    let mut slot: Option<BoardController<_>> = None;
    if device::controller_into(&BOARD, tissue(), dev, &mut slot).is_err() {
        panic!("the board's controller did not build");
    }
    let mut ctl = slot.unwrap();
    let mut t = BoardTelemetry::new();
    for _ in 0..ticks {
        ctl.tick(None);
        let status = ctl.device().status();
        let part = ctl.device_error().map(device::DevicePart::from);
        t.record(
            ctl.telemetry(),
            0,
            0,
            (ctl.device().inner().encoder.errors(), status, part),
        );
    }
    assert_eq!(t.run.fault, Some(Fault::Read));
    assert_eq!(t.part, Some(device::DevicePart::Encoder));
    assert_eq!(t.fault_tick, Some(fault_tick));
    assert_eq!(t.encoder.diagnostic, fault_tick);
    assert_eq!(
        qemu_verdict(BOARD.qemu_ticks, &t, zeros_fault_tick(&BOARD)),
        Ok(())
    );
    // The verdict fails a run that is anything else.
    let mut late = t;
    late.fault_tick = Some(fault_tick + 1);
    assert_eq!(
        qemu_verdict(BOARD.qemu_ticks, &late, zeros_fault_tick(&BOARD)),
        Err(QemuMismatch::Fault)
    );
    let mut short = t;
    short.run.ticks -= 1;
    assert_eq!(
        qemu_verdict(BOARD.qemu_ticks, &short, zeros_fault_tick(&BOARD)),
        Err(QemuMismatch::Ticks)
    );
    let mut overrun = t;
    overrun.run.overruns = 1;
    assert_eq!(
        qemu_verdict(BOARD.qemu_ticks, &overrun, zeros_fault_tick(&BOARD)),
        Err(QemuMismatch::Overrun)
    );
    drop(ctl);
    spi.done();
    pwm.done();
    en.done();
    dir.done();
}

/// A press into the tissue: the probe goes 1 mm down at the fastest plausible speed
/// and stays; the tissue pushes back along +z: the direction pin goes high at zero duty,
/// then a duty in proportion to the force the controller returns.
#[test]
fn a_press_renders_an_upward_force() {
    let press = (1.0 / BOARD.mm_per_count) as i32; // counts, 1 mm down: +z is up
    let step = BOARD.encoder().max_step as i32 - 1;
    // After the start-up nudges.
    let angle = move |frame: usize| {
        let down = (frame.saturating_sub(CHECKED_BY) as i32 * step).min(press);
        (BOARD.encoder_zero as i32 - down).rem_euclid(16384) as u16
    };
    let log = Log::default();
    let dev = device::device(
        &BOARD,
        Sensor::new(moved_by(&log, 1, angle)),
        Pwm(log.clone()),
        Pin(log.clone(), "dir"),
        Pin(log.clone(), "enable"),
    )
    .unwrap();
    let mut slot: Option<BoardController<_>> = None;
    if device::controller_into(&BOARD, tissue(), dev, &mut slot).is_err() {
        panic!("the board's controller did not build");
    }
    let mut ctl = slot.unwrap();
    // Full force, as the link's guard gives it once its ramp is done.
    ctl.device_mut().set_gain(mccs_link::scale::GAIN_FULL);
    let mut last = [Force::ZERO; 3];
    for _ in 0..500 {
        last = ctl.tick(None);
    }
    assert_eq!(ctl.telemetry().fault, None);
    assert_eq!(ctl.device().inner().encoder.errors().implausible, 0);
    let f = last[2].to_num::<f64>();
    assert!(
        f > 0.05 && f < BOARD.force_at_full_duty,
        "the tissue pushes back: {f} N"
    );
    let log = log.0.borrow();
    assert_eq!(
        &log[..3],
        ["duty 0", "enable low", "enable high"],
        "safe, then enabled"
    );
    let first_up = log
        .iter()
        .position(|l| l == "dir high")
        .expect("the direction set up");
    assert_eq!(
        log[first_up - 1],
        "duty 0",
        "the direction changes at zero duty"
    );
    let duty: f64 = log
        .last()
        .unwrap()
        .strip_prefix("duty ")
        .unwrap()
        .parse()
        .unwrap();
    let expected = f / BOARD.force_at_full_duty * 8400.0;
    assert!(
        (duty - expected).abs() <= 1.0,
        "duty {duty} for {f} N (expected {expected})"
    );
}

/// A start-up failure keeps its type and values to the log (`StartFault`): a tissue too
/// stiff for the tick says how many substeps it needs; a failed part of the device, which
/// part; a bad constant, which one.
#[test]
fn a_start_up_failure_says_what_failed_with_its_values() {
    let mut stiff = Params::TABLE2;
    stiff.cone.shear_modulus *= 40.0;
    stiff.linear.shear_modulus *= 40.0;
    let table = ForceTable64::new(&stiff).unwrap();
    let log = Log::default();
    let new_device = || {
        device::device(
            &BOARD,
            Sensor::new(|_| 0),
            Pwm(log.clone()),
            Pin(log.clone(), "dir"),
            Pin(log.clone(), "enable"),
        )
        .unwrap()
    };
    let dev = new_device();
    let mut slot: Option<BoardController<_>> = None;
    // The paper's integrator, whose bound this tissue puts past `max_substeps` (64).
    let config = BoardConfig {
        integrator: mccs::Integrator::ImprovedEuler,
        ..BOARD
    };
    let Err((e, _)) = device::controller_into(&config, table, dev, &mut slot) else {
        panic!("a tissue 40 times Table 2's started")
    };
    let fault = e.fault();
    let device::StartFault::Solver(mccs::SolverError::TooManySubsteps { needed }) = fault else {
        panic!("{fault:?}")
    };
    let line = fault.to_string();
    assert!(
        line.starts_with(&format!(
            "solver: max_substeps: stability needs {needed} substeps per tick"
        )),
        "{line}"
    );
    assert!(slot.is_none());
    // With the board's own integrator it stays within `max_substeps` but not within the
    // tick's budget: refused with its figures, as a tissue over the link is.
    let Err((e, _)) = device::controller_into(&BOARD, table, new_device(), &mut slot) else {
        panic!("a tissue 40 times Table 2's started within the budget")
    };
    let device::StartFault::Budget(b) = e.fault() else {
        panic!("{:?}", e.fault())
    };
    assert!(b.substeps > BOARD.budget().most_substeps(), "{b:?}");
    assert_eq!(b.instructions, BOARD.budget().cost(b.substeps));
    assert_eq!(b.budget, BOARD.tick_budget);
    assert!(
        e.fault().to_string().starts_with(&format!(
            "budget: the tissue needs {} substeps per tick, {} instructions, over the board's 84000",
            b.substeps, b.instructions
        )),
        "{}",
        e.fault()
    );
    assert!(slot.is_none());
    use mccs_firmware::drivers::pwm_motor::MotorError;
    use mccs_firmware::one_dof::OneDofError;
    let enable: device::StartError<OneDofError<(), (), (), ()>> =
        device::StartError::SafeState(OneDofError::Motor(MotorError::Enable(())));
    assert_eq!(
        enable.fault().to_string(),
        "safe state: the motor driver's enable pin failed"
    );
    let spi: device::StartError<OneDofError<(), (), (), ()>> =
        device::StartError::SafeState(OneDofError::Spi(()));
    assert_eq!(
        spi.fault(),
        device::StartFault::SafeState(device::DevicePart::Spi)
    );
    let config: device::StartError<OneDofError<(), (), (), ()>> =
        device::StartError::Config(BoardConfigError::Tick);
    assert_eq!(
        config.fault().to_string(),
        format!("config: {}", BoardConfigError::Tick.message())
    );
}

/// The board takes a table of any knot count `mccs table` emits: its controller is
/// generic over the table's segments, and a 129-knot tissue builds and pushes back as the
/// 65-knot one does.
#[test]
fn the_board_runs_a_table_of_any_knot_count() {
    fn press<const S: usize>(table: ForceTable<S>) -> f64 {
        let press = (1.0 / BOARD.mm_per_count) as i32;
        let step = BOARD.encoder().max_step as i32 - 1;
        let angle = move |f: usize| {
            let down = (f.saturating_sub(CHECKED_BY) as i32 * step).min(press);
            (BOARD.encoder_zero as i32 - down).rem_euclid(16384) as u16
        };
        let log = Log::default();
        let dev = device::device(
            &BOARD,
            Sensor::new(moved_by(&log, 1, angle)),
            Pwm(log.clone()),
            Pin(log.clone(), "dir"),
            Pin(log.clone(), "enable"),
        )
        .unwrap();
        let mut slot: Option<BoardController<_, mccs_firmware::Glued, S>> = None;
        if device::controller_into(&BOARD, table, dev, &mut slot).is_err() {
            panic!("the board's controller did not build with {} knots", S + 1);
        }
        let mut ctl = slot.unwrap();
        let mut last = [Force::ZERO; 3];
        for _ in 0..500 {
            last = ctl.tick(None);
        }
        last[2].to_num::<f64>()
    }
    let f65 = press(ForceTable::<64>::new(&Params::TABLE2).unwrap());
    let f129 = press(ForceTable::<128>::new(&Params::TABLE2).unwrap());
    let f17 = press(ForceTable::<16>::new(&Params::TABLE2).unwrap());
    assert!(f65 > 0.05, "{f65}");
    assert!((f129 - f65).abs() < 1e-3 * f65, "{f129} against {f65}");
    assert!((f17 - f65).abs() < 1e-2 * f65, "{f17} against {f65}");
    // (Which tissue the board holds is the user's: `table_source.rs` holds it to the
    // command in its header, whatever the tissue.)
}
