//! The lever's parts for the board's wiring tests: a motor that logs what it is told
//! ([`Log`], [`Pwm`], [`Pin`]), an AS5047P answering with an angle a frame
//! ([`Sensor`]), and a lever its motor moves ([`moved_by`]).

use embedded_hal::digital::{ErrorType as PinErrorType, OutputPin};
use embedded_hal::pwm::{ErrorType as PwmErrorType, SetDutyCycle};
use mccs_firmware::drivers::as5047p::{ANGLECOM, DIAAGC, DIAAGC_LF};
use std::cell::RefCell;
use std::rc::Rc;

/// A response frame with even parity.
pub fn frame(data: u16) -> u16 {
    let f = data & 0x3FFF;
    if f.count_ones() % 2 == 1 {
        f | 0x8000
    } else {
        f
    }
}

/// What the motor saw, in order.
#[derive(Clone, Default)]
pub struct Log(pub Rc<RefCell<Vec<String>>>);

/// A PWM channel that logs each duty (`duty N`).
pub struct Pwm(pub Log);
impl PwmErrorType for Pwm {
    type Error = core::convert::Infallible;
}
impl SetDutyCycle for Pwm {
    fn max_duty_cycle(&self) -> u16 {
        8400
    }
    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Self::Error> {
        self.0 .0.borrow_mut().push(format!("duty {duty}"));
        Ok(())
    }
}
/// A pin that logs each level under its name (`dir high`).
pub struct Pin(pub Log, pub &'static str);
impl PinErrorType for Pin {
    type Error = core::convert::Infallible;
}
impl OutputPin for Pin {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        self.0 .0.borrow_mut().push(format!("{} low", self.1));
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), Self::Error> {
        self.0 .0.borrow_mut().push(format!("{} high", self.1));
        Ok(())
    }
}

/// An AS5047P on the SPI: answers the previous frame's command — DIAAGC running, the
/// angle `angle(frame)` for ANGLECOM — with even parity.
#[derive(Clone)]
pub struct Sensor(Rc<RefCell<SensorState>>);

/// The angle per frame, frames so far, the last command.
pub type SensorState = (Box<dyn FnMut(usize) -> u16>, usize, u16);

impl Sensor {
    /// The sensor answering `angle(frame)`.
    pub fn new(angle: impl FnMut(usize) -> u16 + 'static) -> Self {
        Self(Rc::new(RefCell::new((Box::new(angle), 0, 0))))
    }
}

impl embedded_hal::spi::ErrorType for Sensor {
    type Error = core::convert::Infallible;
}

impl embedded_hal::spi::SpiDevice<u8> for Sensor {
    fn transaction(
        &mut self,
        ops: &mut [embedded_hal::spi::Operation<'_, u8>],
    ) -> Result<(), Self::Error> {
        let mut s = self.0.borrow_mut();
        for op in ops {
            if let embedded_hal::spi::Operation::Transfer(rx, tx) = op {
                let command = u16::from_be_bytes([tx[0], tx[1]]) & 0x3FFF;
                let response = match s.2 {
                    ANGLECOM => {
                        let n = s.1;
                        frame((s.0)(n))
                    }
                    DIAAGC => frame(DIAAGC_LF),
                    _ => frame(0),
                };
                rx.copy_from_slice(&response.to_be_bytes());
                s.2 = command;
                s.1 += 1;
            }
        }
        Ok(())
    }
}

/// Ticks the board's lever check takes at most on [`moved_by`]'s lever (two nudges of
/// 7 counts, each after a 30 ms settle): a press starts after them.
pub const CHECKED_BY: usize = 150;

/// The angle `angle(frame)` on a lever its motor moves over the first [`CHECKED_BY`]
/// frames (then held by a hand: the press's path alone): a count a frame the way the
/// last direction drives it (times `wiring`: 1 right, −1 reversed, 0 held), while the
/// last duty is over 1 % (the board's start-up nudges, 0.2 N of 3 N: 6.7 %).
pub fn moved_by(
    log: &Log,
    wiring: i32,
    mut angle: impl FnMut(usize) -> u16 + 'static,
) -> impl FnMut(usize) -> u16 + 'static {
    let log = log.clone();
    let mut moved = 0i32;
    move |frame| {
        let l = log.0.borrow();
        let duty = l
            .iter()
            .rev()
            .find_map(|e| e.strip_prefix("duty "))
            .and_then(|d| d.parse::<u16>().ok())
            .unwrap_or(0);
        // +z is up and the counts grow with it (the board's `mm_per_count` > 0).
        let up = l
            .iter()
            .rev()
            .find(|e| e.starts_with("dir "))
            .map(|e| e == "dir high");
        if duty > 84 && frame < CHECKED_BY {
            moved += wiring * if up == Some(true) { 1 } else { -1 };
        }
        (angle(frame) as i32 + moved).rem_euclid(16384) as u16
    }
}
