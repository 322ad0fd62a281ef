//! The board's black box ([`mccs_firmware::black_box`]): two boxes outside the SRAM that
//! `memory/stm32f405.x` gives the linker ([`BLACK_BOX_ADDR`]: the chip's CCM; in QEMU
//! past its 128 KiB), so that no section covers them: neither the start-up code (which
//! zeroes `.bss` and copies `.data`) nor a loader writes them, and a reset leaves them as
//! the run before left them.
//!
//! - At boot ([`take_at_boot`]): the live box kept as the last run's with the reset's
//!   cause (RCC_CSR, which the board's `main` reads and clears), the live box started
//!   again.
//! - Each tick: [`tick_record`] into the live box; the first fault stops it with the
//!   cause and the part ([`stop_of`]).
//! - A fault handler or a panic: [`stop_in_handler`], after the motor is cut.
//! - The link answers `BlackBox` from the last box (`mccs link blackbox`).

use crate::device::DevicePart;
use mccs::Force;
use mccs_firmware::black_box::{BlackBox, BLACK_BOX_TICKS};
use mccs_firmware::{DeviceStatus, Fault, Telemetry};
use mccs_link::black_box::{box_flags, BoxTick, StopCause};

/// The board's box.
pub type BoardBox = BlackBox<BLACK_BOX_TICKS>;

/// Where the two boxes lie (the live box, then the last run's): outside the 128 KiB of
/// SRAM that `memory/stm32f405.x` links, so that no section covers them. On the chip
/// they lie in its 64 KiB of core-coupled RAM ([`CCM_BOX_ADDR`], clocked from reset:
/// RCC_AHB1ENR's reset value sets CCMDATARAMEN; only the core writes the boxes, and the
/// CCM needs no more); in QEMU, which models no CCM, past the 128 KiB in the 192 KiB of
/// SRAM its netduinoplus2 has ([`QEMU_BOX_ADDR`]). The statics (some 50 KB at N = 10)
/// and the stack (some 73 KB at its deepest: the start-up's controller, a replay's or a
/// tissue check's start) share the 128 KiB; the test command's `link-qemu` stage holds
/// 4 KiB of them free (docs/safety.md).
#[cfg(not(board_qemu))]
pub const BLACK_BOX_ADDR: usize = CCM_BOX_ADDR;
/// See the chip's.
#[cfg(board_qemu)]
pub const BLACK_BOX_ADDR: usize = QEMU_BOX_ADDR;
/// The STM32F405's core-coupled RAM: 64 KiB at `0x1000_0000` (RM0090, "Memory map").
pub const CCM_BOX_ADDR: usize = 0x1000_0000;
/// In QEMU: the end of the chip's 128 KiB of SRAM, within the 192 KiB QEMU models.
pub const QEMU_BOX_ADDR: usize = 0x2002_0000;
const _: () = assert!(
    CCM_BOX_ADDR + BLACK_BOX_BYTES <= 0x1001_0000,
    "within the CCM"
);
const _: () = assert!(
    QEMU_BOX_ADDR + BLACK_BOX_BYTES <= 0x2003_0000,
    "within QEMU's SRAM"
);
/// Their room.
pub const BLACK_BOX_BYTES: usize = 0x8000;
const _: () = assert!(2 * core::mem::size_of::<BoardBox>() <= BLACK_BOX_BYTES);

/// The cause a controller's fault is kept as.
pub const fn stop_of(fault: Fault) -> StopCause {
    match fault {
        Fault::Read => StopCause::Read,
        Fault::Write => StopCause::Write,
        Fault::Overruns => StopCause::Overruns,
        Fault::Amplifier => StopCause::Amplifier,
    }
}

/// A force in mN, saturated to ±32,767 (integers only: the tick's).
fn millinewtons(f: Force) -> i16 {
    let mn = (f.to_bits() as i64 * 1000) >> Force::FRAC_NBITS;
    mn.clamp(-32_767, 32_767) as i16
}

/// One tick as the box keeps it: the controller's telemetry after it (its tick and
/// force), the device's status (its duties and flags), its `counts` and the link's
/// `gain` (Q15).
pub fn tick_record(run: &Telemetry, status: &DeviceStatus, counts: [i32; 3], gain: u16) -> BoxTick {
    let flags = [
        (status.homed, box_flags::HOMED),
        (status.at_limit, box_flags::AT_LIMIT),
        (status.thermal, box_flags::THERMAL),
        (run.clamped, box_flags::CLAMPED),
        (run.fault.is_some(), box_flags::FAULT),
    ]
    .iter()
    .fold(0, |f, &(on, bit)| if on { f | bit } else { f });
    BoxTick {
        tick: run.ticks.saturating_sub(1),
        counts,
        force_mn: run.force.map(millinewtons),
        duty_q15: status
            .duties
            .map(|d| (d >> 1).clamp(-32_767, 32_767) as i16),
        gain,
        flags,
    }
}

/// Records a tick in `live` and, on the first tick of a fault, stops it with the
/// cause and `part`.
pub fn record(live: &mut BoardBox, tick: BoxTick, fault: Option<Fault>, part: Option<DevicePart>) {
    live.record(tick);
    if let Some(f) = fault {
        live.stop(stop_of(f), part.map_or(0, DevicePart::code), tick.tick, 0);
    }
}

/// The two boxes where they lie: the live one and the last run's.
#[cfg(target_os = "none")]
fn boxes() -> (&'static mut BoardBox, &'static mut BoardBox) {
    // Two callers: `take_at_boot`, once (`TAKEN`), whose references the tick and the
    // session then hold; and a fault handler, which writes the live box's end and never
    // returns, so that the tick's is not used again (at worst it interrupts a record half
    // written: one tick's fields mixed). Every field is an integer: whatever bits a
    // power-on leaves are a box, which `kept` rejects unless marked.
    // SAFETY: the boxes lie in RAM no section covers (memory/stm32f405.x), aligned and
    // apart (the assertion above); their callers are the two above.
    unsafe {
        (
            &mut *(BLACK_BOX_ADDR as *mut BoardBox),
            &mut *((BLACK_BOX_ADDR + core::mem::size_of::<BoardBox>()) as *mut BoardBox),
        )
    }
}

/// The boxes, once, at boot: the live one kept as the last run's (with the reset's
/// cause, `reset_flags`: RCC_CSR's, read by the board's `main`), then started again.
/// `None` the second time.
#[cfg(target_os = "none")]
pub fn take_at_boot(reset_flags: u32) -> Option<(&'static mut BoardBox, &'static BoardBox)> {
    use core::sync::atomic::{AtomicBool, Ordering};
    static TAKEN: AtomicBool = AtomicBool::new(false);
    if TAKEN.swap(true, Ordering::AcqRel) {
        return None;
    }
    let (live, last) = boxes();
    last.keep(live, reset_flags);
    Some((live, &*last))
}

/// From a fault handler or the panic handler, after the motor is cut: the run ended
/// with `cause` (and a HardFault's `pc`), after the last tick that ran
/// ([`BlackBox::end`]; its stop too, unless a fault stopped it first).
#[cfg(target_os = "none")]
pub fn stop_in_handler(cause: StopCause, pc: u32) {
    boxes().0.end(cause, pc);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The memory map links the chip's 128 KiB of SRAM and no further, and the boxes lie
    /// outside it: in the CCM's 64 KiB on the chip, in QEMU's SRAM past the 128 KiB and
    /// within its 192. A map that covered them would let the start-up code zero the last
    /// run's record.
    #[test]
    fn the_memory_map_leaves_the_boxes_out_of_the_linked_ram() {
        let map = include_str!("../../../memory/stm32f405.x");
        let ram = map
            .lines()
            .find(|l| l.trim_start().starts_with("RAM"))
            .expect("a RAM line");
        let field = |key: &str| {
            let rest = &ram[ram.find(key).expect(key) + key.len()..];
            let v = rest
                .trim_start_matches([' ', '='])
                .split([',', ' '])
                .next()
                .unwrap();
            match v.strip_suffix('K') {
                Some(k) => k.parse::<usize>().unwrap() * 1024,
                None => usize::from_str_radix(v.trim_start_matches("0x"), 16).unwrap(),
            }
        };
        let (start, end) = (field("ORIGIN"), field("ORIGIN") + field("LENGTH"));
        assert_eq!((start, end), (0x2000_0000, 0x2002_0000), "{ram}");
        assert_eq!(
            QEMU_BOX_ADDR, end,
            "QEMU's boxes start where the linked RAM ends"
        );
        assert!(
            CCM_BOX_ADDR + BLACK_BOX_BYTES <= start,
            "the CCM lies below the SRAM"
        );
    }

    #[test]
    fn every_device_part_has_its_own_code_and_back() {
        for (i, p) in DevicePart::ALL.iter().enumerate() {
            assert_eq!(p.code() as usize, i + 1, "{p:?}");
            assert_eq!(DevicePart::from_code(p.code()), Some(*p));
        }
        assert_eq!(DevicePart::from_code(0), None);
        assert_eq!(DevicePart::from_code(30), None);
        assert_eq!(
            DevicePart::JointReversed(7).code(),
            DevicePart::JointReversed(2).code()
        );
    }

    #[test]
    fn a_tick_is_kept_in_mn_and_q15_with_its_flags_and_the_first_fault_stops_the_box() {
        let run = Telemetry {
            ticks: 42,
            force: [
                Force::from_num(1.5),
                Force::from_num(-40.0),
                Force::from_num(0.0004),
            ],
            clamped: true,
            ..Telemetry::new()
        };
        let status = DeviceStatus {
            homed: true,
            at_limit: false,
            thermal: true,
            duties: [65_536, -65_536, 1001],
        };
        let t = tick_record(&run, &status, [1, -2, 3], 16_384);
        assert_eq!(t.tick, 41);
        assert_eq!(t.force_mn, [1500, -32_767, 0]);
        assert_eq!(t.duty_q15, [32_767, -32_767, 500]);
        assert_eq!(
            t.flags,
            box_flags::HOMED | box_flags::THERMAL | box_flags::CLAMPED
        );
        let mut live = BoardBox::EMPTY;
        live.start();
        record(&mut live, t, None, None);
        let mut t2 = t;
        t2.tick = 42;
        record(
            &mut live,
            t2,
            Some(Fault::Read),
            Some(DevicePart::JointReversed(1)),
        );
        record(&mut live, t2, Some(Fault::Write), None);
        let p = live.part(0);
        assert_eq!(
            (p.cause, p.part, p.tick, p.ticks),
            (StopCause::Read, 23, 42, 2)
        );
        assert_eq!(
            DevicePart::from_code(p.part),
            Some(DevicePart::JointReversed(1))
        );
    }
}
