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
        }
    }
}

/// The MCU's registers, by volatile access at their addresses.
#[cfg(target_os = "none")]
pub struct Mmio;

#[cfg(target_os = "none")]
impl Registers for Mmio {
    fn read(&mut self, addr: u32) -> u32 {
        // SAFETY: only the addresses of `STOP` and `DBGMCU_APB2_FZ` come here: the
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
        regs.insert(tim1::BDTR, tim1::MOE | (1 << 11) | 0x2A);
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
        assert_eq!(m.log[0], ('r', tim1::BDTR, tim1::MOE | (1 << 11) | 0x2A));
        assert_eq!(m.log[1], ('w', tim1::BDTR, (1 << 11) | 0x2A));
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
    fn the_addresses_are_the_reference_manuals() {
        // RM0090: TIM1 at 0x4001_0000, CCR1 at 0x34, BDTR at 0x44; GPIOB at 0x4002_0400,
        // BSRR at 0x18; DBGMCU_APB2_FZ at 0xE004_200C.
        assert_eq!(tim1::CCR[0], 0x4001_0034);
        assert_eq!(tim1::BDTR, 0x4001_0044);
        assert_eq!(GPIOB_BSRR, 0x4002_0418);
        assert_eq!(DBGMCU_APB2_FZ, 0xE004_200C);
    }
}
