//! The lever's start-up direction check on the board's device and controller
//! (`device::lever_check`): a lever wired right passes its two nudges before any tissue
//! force, even pressed; one whose motor or encoder is reversed, or that does not move,
//! ends in the safe state with the part named, within the check's time and a few
//! counts of travel.

mod common;

use common::{moved_by, Log, Pin, Pwm, Sensor, CHECKED_BY};
use haptic_f405::device::{self, BoardController, DevicePart};
use haptic_f405::BOARD;
use mccs_firmware::{Fault, HapticDevice};

/// The board's controller on a lever at rest `depth_counts` into the tissue (0: at its
/// surface), wired `wiring` (1 right, −1 reversed, 0 held); its motor's log.
fn lever(
    wiring: i32,
    depth_counts: i32,
) -> (BoardController<device::Linked<Sensor, Pwm, Pin, Pin>>, Log) {
    let log = Log::default();
    let rest = (BOARD.encoder_zero as i32 - depth_counts).rem_euclid(16384) as u16;
    let dev = device::device(
        &BOARD,
        Sensor::new(moved_by(&log, wiring, move |_| rest)),
        Pwm(log.clone()),
        Pin(log.clone(), "dir"),
        Pin(log.clone(), "enable"),
    )
    .unwrap();
    let mut slot = None;
    if device::controller_into(&BOARD, haptic_f405::tissue::TISSUE, dev, &mut slot).is_err() {
        panic!("the board's controller did not build");
    }
    let mut ctl = slot.unwrap();
    ctl.device_mut().set_gain(mccs_link::scale::GAIN_FULL);
    (ctl, log)
}

/// The duties written, in order (the last of the log's `duty N`).
fn duties(log: &Log) -> Vec<u16> {
    log.0
        .borrow()
        .iter()
        .filter_map(|e| e.strip_prefix("duty ")?.parse().ok())
        .collect()
}

#[test]
fn a_lever_wired_right_passes_its_nudges_before_any_tissue_force_even_pressed() {
    let check = device::lever_check(&BOARD);
    // 0.2 N of 3 N at full duty; 20 of 2⁻¹⁰ mm (7 counts); 200 ms; 30 ms.
    assert_eq!(check.duty_q16, [4369]);
    assert_eq!(
        (check.counts, check.timeout_ticks, check.settle_ticks),
        (20, 200, 30)
    );
    // Pressed 1 mm into the tissue: the tissue pushes back, but not before the check.
    let press = (1.0 / BOARD.mm_per_count) as i32;
    let (mut ctl, log) = lever(1, press);
    let nudge = (4369u32 * 8400 / 65536) as u16; // duty steps
    let mut passed_at = None;
    for tick in 0..CHECKED_BY as u32 {
        ctl.tick(None);
        let homed = ctl.device().status().homed;
        if homed && passed_at.is_none() {
            passed_at = Some(tick);
        }
        if passed_at.is_none() {
            // Every duty so far is zero or the nudge's.
            assert!(
                duties(&log)
                    .iter()
                    .all(|&d| d == 0 || d.abs_diff(nudge) <= 1),
                "tick {tick}: {:?}",
                duties(&log)
            );
        }
    }
    let passed_at = passed_at.expect("the check passed");
    assert_eq!(ctl.telemetry().fault, None);
    // Two nudges of 7 counts, each after 30 ms: 74 ticks.
    let ms = |ticks: u32| ticks as u64 * 1000 / BOARD.tick_hz as u64;
    println!("LEVER case=wired_right check_ms={}", ms(passed_at));
    assert!((60..=90).contains(&passed_at), "{passed_at}");
    // Then the tissue's force (it pushes the pressed lever back up).
    for _ in 0..50 {
        ctl.tick(None);
    }
    let last = *duties(&log).last().unwrap();
    assert!(
        last > 100,
        "the tissue's force after the check: duty {last}"
    );
}

#[test]
fn a_reversed_or_held_lever_fails_its_check_into_the_safe_state_naming_the_part() {
    for (wiring, part, within, name) in [
        (-1, DevicePart::LeverReversed, 30 + 8 + 1, "reversed"),
        (0, DevicePart::LeverUnmoved, 30 + 200 + 1, "unmoved"),
    ] {
        let (mut ctl, log) = lever(wiring, 0);
        let mut fault_at = None;
        for tick in 0..400 {
            ctl.tick(None);
            if ctl.telemetry().fault.is_some() {
                fault_at = Some(tick);
                break;
            }
        }
        let fault_at = fault_at.unwrap_or_else(|| panic!("{part:?}: no fault"));
        assert_eq!(ctl.telemetry().fault, Some(Fault::Read), "{part:?}");
        assert_eq!(ctl.device_error().map(DevicePart::from), Some(part));
        assert!(fault_at <= within, "{part:?} at tick {fault_at}");
        // How far the lever went the wrong way (from its rest at the surface, 0).
        let moved_um = ctl.device().probe()[2].to_num::<f64>().abs() * 1000.0;
        assert!(moved_um < 30.0, "{part:?}: {moved_um} µm");
        // The motor safe: zero duty, the driver disabled, and no force since.
        let l = log.0.borrow();
        assert_eq!(&l[l.len() - 2..], ["duty 0", "enable low"], "{part:?}");
        drop(l);
        for _ in 0..20 {
            ctl.tick(None);
        }
        assert_eq!(*duties(&log).last().unwrap(), 0);
        assert!(!ctl.device().status().homed);
        let ms = fault_at as u64 * 1000 / BOARD.tick_hz as u64;
        println!("LEVER case={name} found_ms={ms} moved_um={moved_um:.1}");
    }
}
