//! The stop every way out of the firmware takes first: the motor's torque to zero by
//! raw register writes, before anything else runs (a log, a semihosting exit, a
//! breakpoint), with no HAL, no allocation and no lock.
//!
//! [`STOP`] is the sequence, as data, so that a host test holds it on a mock register
//! block ([`Registers`]) and the handlers apply it to the real ones ([`cut_motor`]):
//!
//! 1. TIM1's main output enable (BDTR.MOE, bit 15) cleared: the timer's outputs go to
//!    their idle level (low: PWM off) at once, whatever its compare registers hold;
//! 2. TIM1's four compare registers (CCR1–CCR4) zeroed: a MOE set again by the break
//!    logic's automatic output enable (unused here) would still give zero duty;
//! 3. the drivers' enable pin, PB1 (both variants' pin tables), low through GPIOB's BSRR
//!    (an atomic write: no read-modify-write of ODR that an interrupted tick could race).
//!
//! The panic handler, HardFault, MemManage, BusFault and UsageFault (the board bin's
//! `platform` module) call [`cut_motor`] as their first statement, on every build.
//! [`freeze_tim1_on_halt`] sets DBGMCU's `DBG_TIM1_STOP`: while a debugger halts the
//! core, TIM1 stops with its outputs disabled (RM0090 §17.3.20: "as if the MOE bit was
//! reset"), as the independent watchdog stops (`stop_on_debug`).
//!
//! QEMU 7.2's netduinoplus2 models neither TIM1 nor the GPIOs (their writes are
//! dropped), so in QEMU the test command holds that each handler runs (each fault class
//! injected: `--features fault-test`); the writes themselves are held here, on the mock.

/// TIM1's registers (RM0090 §17.4): base address and the offsets a stop writes.
pub mod tim1 {
    /// TIM1's base address (APB2).
    pub const BASE: u32 = 0x4001_0000;
    /// Status register.
    pub const SR: u32 = BASE + 0x10;
    /// SR's break interrupt flag: set by the hardware when the break input went active.
    pub const BIF: u32 = 1 << 7;
    /// BDTR's break enable.
    pub const BKE: u32 = 1 << 12;
    /// BDTR's break polarity (1: active high).
    pub const BKP: u32 = 1 << 13;
    /// BDTR's automatic output enable (the HAL sets it: MOE set again at the next
    /// update event once a break clears).
    pub const AOE: u32 = 1 << 14;
    /// Capture/compare register 1 … 4.
    pub const CCR: [u32; 4] = [BASE + 0x34, BASE + 0x38, BASE + 0x3C, BASE + 0x40];
    /// Break and dead-time register.
    pub const BDTR: u32 = BASE + 0x44;
    /// BDTR's main output enable.
    pub const MOE: u32 = 1 << 15;
}

/// GPIOB's bit set/reset register (RM0090 §8.4.7): a write of `1 << (16 + n)` drives pin
/// `n` low, atomically.
pub const GPIOB_BSRR: u32 = 0x4002_0400 + 0x18;

/// The drivers' enable pin: PB1 on the 1-DOF and the arm board.
pub const ENABLE_PIN: u32 = 1;

/// GPIOB's mode, pull and alternate-function (high) registers, for PB12, TIM1's break
/// input (`TIM1_BKIN`, AF1).
pub mod gpiob {
    /// GPIOB's base address (AHB1).
    pub const BASE: u32 = 0x4002_0400;
    /// Mode register (2 bits a pin; 0b10: alternate function).
    pub const MODER: u32 = BASE; // offset 0x00
    /// Pull-up/pull-down register (2 bits a pin; 0b01 up, 0b10 down).
    pub const PUPDR: u32 = BASE + 0x0C;
    /// Alternate function register for pins 8–15 (4 bits a pin).
    pub const AFRH: u32 = BASE + 0x24;
    /// The break input's pin, PB12.
    pub const BKIN_PIN: u32 = 12;
}

/// The break input's active level (`BoardConfig::break_input`): the hardware clears
/// TIM1's MOE, and so every PWM output, within a few timer clocks of the level, without
/// the MCU's code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BreakInput {
    /// Not used (PB12 left as it is). Only for a bench without a stop chain.
    Off,
    /// Active low, the fail-safe choice: a chain of normally-closed contacts (the
    /// emergency stop, the amplifiers' fault outputs) from 3.3 V holds PB12 high; a
    /// pressed stop, a tripped amplifier or a wire off lets the internal pull-down take
    /// it low: the break. With nothing wired the drive never comes on (a bench without a
    /// stop chain ties PB12 to 3.3 V, knowingly).
    ActiveLow,
    /// Active high (an amplifier's push-pull fault output), PB12 pulled down.
    ActiveHigh,
}

/// The writes that arm TIM1's break input on PB12 at `level` (none for `Off`): the pin
/// to AF1, pulled down; then in BDTR, AOE cleared (the HAL sets it: a break that clears
/// would set MOE again by itself at the next update; now only software sets MOE, and the
/// firmware never does after a break), then BKE, the polarity and MOE (the HAL's AOE
/// would have set it at the first update; every duty is zero here).
pub fn break_writes(level: BreakInput) -> [Write; 8] {
    let pin = gpiob::BKIN_PIN;
    let pull = 0b10;
    let bkp = match level {
        BreakInput::ActiveHigh => tim1::BKP,
        BreakInput::Off | BreakInput::ActiveLow => 0,
    };
    let nop = Write::Clear {
        addr: tim1::BDTR,
        mask: 0,
    };
    if level == BreakInput::Off {
        return [nop; 8];
    }
    [
        Write::Clear {
            addr: gpiob::AFRH,
            mask: 0xF << ((pin - 8) * 4),
        },
        Write::Or {
            addr: gpiob::AFRH,
            bits: 1 << ((pin - 8) * 4),
        },
        Write::Clear {
            addr: gpiob::PUPDR,
            mask: 0b11 << (pin * 2),
        },
        Write::Or {
            addr: gpiob::PUPDR,
            bits: pull << (pin * 2),
        },
        Write::Clear {
            addr: gpiob::MODER,
            mask: 0b11 << (pin * 2),
        },
        Write::Or {
            addr: gpiob::MODER,
            bits: 0b10 << (pin * 2),
        },
        Write::Clear {
            addr: tim1::BDTR,
            mask: tim1::AOE,
        },
        Write::Or {
            addr: tim1::BDTR,
            bits: tim1::BKE | bkp | tim1::MOE,
        },
    ]
}

/// Whether TIM1's break has tripped (SR.BIF, latched by the hardware until cleared; the
/// firmware never clears it): read every tick, which then latches the safe state.
pub fn break_tripped(regs: &mut impl Registers) -> bool {
    regs.read(tim1::SR) & tim1::BIF != 0
}

/// DBGMCU's APB2 freeze register, and its TIM1 bit (RM0090 §38.16.4; offset 0x0C).
pub const DBGMCU_APB2_FZ: u32 = 0xE004_200C;
/// `DBG_TIM1_STOP`.
pub const DBG_TIM1_STOP: u32 = 1 << 0;

/// One register write of the stop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Write {
    /// Write `value` at `addr`.
    Set {
        /// The register's address.
        addr: u32,
        /// The value written.
        value: u32,
    },
    /// Clear the bits of `mask` at `addr` (read, modify, write).
    Clear {
        /// The register's address.
        addr: u32,
        /// The bits cleared.
        mask: u32,
    },
    /// Set the bits of `bits` at `addr` (read, modify, write).
    Or {
        /// The register's address.
        addr: u32,
        /// The bits set.
        bits: u32,
    },
}

/// The stop, in order (the module's docs say why this order).
pub const STOP: [Write; 6] = [
    Write::Clear {
        addr: tim1::BDTR,
        mask: tim1::MOE,
    },
    Write::Set {
        addr: tim1::CCR[0],
        value: 0,
    },
    Write::Set {
        addr: tim1::CCR[1],
        value: 0,
    },
    Write::Set {
        addr: tim1::CCR[2],
        value: 0,
    },
    Write::Set {
        addr: tim1::CCR[3],
        value: 0,
    },
    Write::Set {
        addr: GPIOB_BSRR,
        value: 1 << (16 + ENABLE_PIN),
    },
];

/// A block of 32-bit registers: the MCU's ([`Mmio`]) or a test's mock.
pub trait Registers {
    /// The register at `addr`.
    fn read(&mut self, addr: u32) -> u32;
    /// Writes `value` to the register at `addr`.
    fn write(&mut self, addr: u32, value: u32);
}

/// Applies `writes` to `regs`, in order.
pub fn apply(regs: &mut impl Registers, writes: &[Write]) {
    for w in writes {
        match *w {
            Write::Set { addr, value } => regs.write(addr, value),
            Write::Clear { addr, mask } => {
                let v = regs.read(addr);
                regs.write(addr, v & !mask);
            }
            Write::Or { addr, bits } => {
                let v = regs.read(addr);
                regs.write(addr, v | bits);
            }
        }
    }
}

/// The MCU's registers, by volatile access at their addresses.
#[cfg(target_os = "none")]
pub struct Mmio;

#[cfg(target_os = "none")]
impl Registers for Mmio {
    fn read(&mut self, addr: u32) -> u32 {
        // SAFETY: only the addresses of this module's constants come here: the
        // STM32F405's TIM1, GPIOB and DBGMCU registers, 4-byte aligned, always mapped.
        unsafe { core::ptr::read_volatile(addr as *const u32) }
    }
    fn write(&mut self, addr: u32, value: u32) {
        // SAFETY: as `read`.
        unsafe { core::ptr::write_volatile(addr as *mut u32, value) }
    }
}

/// The motor's torque to zero ([`STOP`] on the MCU's registers): the first statement of
/// every way out. Safe from any context, at any time: each write leaves the motor
/// stopped or as it was, and a stop that a second fault interrupts is begun again by
/// that fault's handler.
#[cfg(target_os = "none")]
pub fn cut_motor() {
    apply(&mut Mmio, &STOP);
}

/// Arms TIM1's break input on PB12 at `level` ([`break_writes`]). Start-up only, once
/// TIM1's PWM is set up and before the first duty (GPIOB's clock on: the pins' split
/// turned it on).
#[cfg(target_os = "none")]
pub fn arm_break_input(level: BreakInput) {
    apply(&mut Mmio, &break_writes(level));
}

/// Whether TIM1's break has tripped, on the MCU ([`break_tripped`]).
#[cfg(target_os = "none")]
pub fn break_tripped_now() -> bool {
    break_tripped(&mut Mmio)
}

/// Sets `DBG_TIM1_STOP`: a debugger's halt stops TIM1 with its outputs off.
#[cfg(target_os = "none")]
pub fn freeze_tim1_on_halt() {
    let mut regs = Mmio;
    let v = regs.read(DBGMCU_APB2_FZ);
    regs.write(DBGMCU_APB2_FZ, v | DBG_TIM1_STOP);
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    /// A mock register block: every register starts at the value `init` gives it; each
    /// access is recorded.
    struct Mock {
        regs: BTreeMap<u32, u32>,
        log: Vec<(char, u32, u32)>,
    }

    impl Registers for Mock {
        fn read(&mut self, addr: u32) -> u32 {
            let v = *self.regs.get(&addr).unwrap_or(&0);
            self.log.push(('r', addr, v));
            v
        }
        fn write(&mut self, addr: u32, value: u32) {
            self.regs.insert(addr, value);
            self.log.push(('w', addr, value));
        }
    }

    /// A motor running: MOE set with other BDTR bits (dead time, OSSR), duties on every
    /// channel.
    fn running() -> Mock {
        let mut regs = BTreeMap::new();
        regs.insert(tim1::BDTR, tim1::AOE | tim1::MOE | (1 << 11) | 0x2A);
        for (k, &ccr) in tim1::CCR.iter().enumerate() {
            regs.insert(ccr, 1000 + k as u32);
        }
        Mock {
            regs,
            log: Vec::new(),
        }
    }

    #[test]
    fn the_stop_clears_moe_first_zeroes_every_compare_and_drops_the_enable() {
        let mut m = running();
        apply(&mut m, &STOP);
        // MOE is the first write, and keeps BDTR's other bits.
        assert_eq!(
            m.log[0],
            ('r', tim1::BDTR, tim1::AOE | tim1::MOE | (1 << 11) | 0x2A)
        );
        assert_eq!(m.log[1], ('w', tim1::BDTR, tim1::AOE | (1 << 11) | 0x2A));
        for ccr in tim1::CCR {
            assert_eq!(m.regs[&ccr], 0, "CCR at {ccr:#x}");
        }
        // PB1 reset through BSRR (bit 17), nothing set.
        assert_eq!(m.regs[&GPIOB_BSRR], 1 << 17);
        // Only TIM1's and GPIOB's registers are touched.
        assert!(m
            .log
            .iter()
            .all(|&(_, a, _)| (tim1::BASE..tim1::BASE + 0x400).contains(&a) || a == GPIOB_BSRR));
    }

    #[test]
    fn a_stop_applied_twice_or_on_a_stopped_timer_leaves_it_stopped() {
        let mut m = running();
        apply(&mut m, &STOP);
        let once = m.regs.clone();
        apply(&mut m, &STOP);
        assert_eq!(m.regs, once);
        let mut idle = Mock {
            regs: BTreeMap::new(),
            log: Vec::new(),
        };
        apply(&mut idle, &STOP);
        assert_eq!(idle.regs[&tim1::BDTR], 0);
    }

    #[test]
    fn the_break_input_is_pb12_in_af1_pulled_to_its_inactive_level_then_enabled() {
        for (level, pull, bkp) in [
            (BreakInput::ActiveLow, 0b10, 0),
            (BreakInput::ActiveHigh, 0b10, tim1::BKP),
        ] {
            let mut m = running();
            // PB12 as an output with a pull-up, AFRH with another pin's AF beside it.
            m.regs.insert(gpiob::MODER, 0b01 << 24 | 0b10 << 4);
            m.regs.insert(gpiob::PUPDR, 0b11 << 24 | 0b01 << 2);
            m.regs.insert(gpiob::AFRH, 0x7 << 16 | 0x5);
            apply(&mut m, &break_writes(level));
            assert_eq!(m.regs[&gpiob::MODER], 0b10 << 24 | 0b10 << 4, "{level:?}");
            assert_eq!(m.regs[&gpiob::PUPDR], pull << 24 | 0b01 << 2, "{level:?}");
            assert_eq!(m.regs[&gpiob::AFRH], 0x1 << 16 | 0x5, "{level:?}");
            let bdtr = m.regs[&tim1::BDTR];
            assert_eq!(bdtr & (tim1::BKE | tim1::BKP), tim1::BKE | bkp, "{level:?}");
            assert_eq!(bdtr & tim1::AOE, 0, "only software sets MOE again");
            // MOE and the dead time untouched: the break does the cutting.
            assert_eq!(bdtr & (tim1::MOE | 0xFF), tim1::MOE | 0x2A);
            // The enable's write comes last: the pin is an input before the break is on.
            assert_eq!(m.log.last().unwrap().1, tim1::BDTR);
        }
        let mut m = running();
        let before = m.regs.clone();
        apply(&mut m, &break_writes(BreakInput::Off));
        assert_eq!(m.regs, before, "Off writes nothing new");
    }

    #[test]
    fn a_tripped_break_is_its_status_flag() {
        let mut m = running();
        assert!(!break_tripped(&mut m));
        m.regs.insert(tim1::SR, tim1::BIF | 1);
        assert!(break_tripped(&mut m));
        m.regs.insert(tim1::SR, 1 | 1 << 6);
        assert!(!break_tripped(&mut m));
    }

    #[test]
    fn the_addresses_are_the_reference_manuals() {
        // RM0090: TIM1 at 0x4001_0000, CCR1 at 0x34, BDTR at 0x44; GPIOB at 0x4002_0400,
        // BSRR at 0x18; DBGMCU_APB2_FZ at 0xE004_200C.
        assert_eq!(tim1::CCR[0], 0x4001_0034);
        assert_eq!(tim1::BDTR, 0x4001_0044);
        assert_eq!(GPIOB_BSRR, 0x4002_0418);
        assert_eq!(DBGMCU_APB2_FZ, 0xE004_200C);
        // TIM1_SR at 0x10 (BIF bit 7), BDTR's BKE bit 12 and BKP bit 13; GPIOB's MODER
        // at 0x00, PUPDR at 0x0C, AFRH at 0x24.
        assert_eq!(
            (tim1::SR, tim1::BIF, tim1::BKE, tim1::BKP),
            (0x4001_0010, 0x80, 0x1000, 0x2000)
        );
        assert_eq!(
            (gpiob::MODER, gpiob::PUPDR, gpiob::AFRH),
            (0x4002_0400, 0x4002_040C, 0x4002_0424)
        );
    }
}
