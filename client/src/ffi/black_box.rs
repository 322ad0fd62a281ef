//! The black box through the C ABI: what a device kept of its run before its last
//! reset ([`crate::BlackBox`]; docs/safety.md, "The black box").

use super::{argument, fail, guarded, handle, McDevice, MCCS_ERR_BUFFER};
use crate::BlackBox;
use mccs_link::black_box::{BoxTick, StopCause};
use std::ffi::{c_char, c_int, CString};
use std::sync::OnceLock;

/// What a device kept of its last run (all zero but `kept` when it kept none).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct McBlackBox {
    /// 1 when the device kept a record; 0 after a power-on (nothing to read).
    pub kept: c_int,
    /// What first stopped the force, a stop cause's code (`mccs_stop_cause_name`): 0 none,
    /// 1 read, 2 write, 3 overruns, 4 amplifier, 5 panic, 6 hard-fault, 7 mem-manage,
    /// 8 bus-fault, 9 usage-fault.
    pub stopped_by: c_int,
    /// The device's part that failed: the board's code (haptic-f405's `DevicePart`), 0
    /// none.
    pub part: c_int,
    /// The tick it stopped on.
    pub stop_tick: u32,
    /// What ended the run, if a fault handler or a panic did (a stop cause's code; 0: a
    /// reset or a power cut ended it).
    pub ended_by: c_int,
    /// The last tick that ran.
    pub end_tick: u32,
    /// A HardFault's faulting instruction, else 0.
    pub pc: u32,
    /// The reset's cause as the chip reported it (the STM32F4's RCC_CSR: bit 25 BOR, 26
    /// PIN, 27 POR, 28 SFT, 29 IWDG, 30 WWDG, 31 LPWR; 0 where not modelled, as in QEMU).
    pub reset_flags: u32,
    /// The ticks kept (at most 500 on the board).
    pub ticks: u32,
}

/// One tick of the record, in units.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct McBoxTick {
    /// The tick (from the device's start).
    pub tick: u32,
    /// The arm's joint counts (from home once homed); a lever's position in µm along z.
    pub counts: [i32; 3],
    /// The force rendered, N per axis (tissue frame; kept in mN, saturated at ±32.767).
    pub force_n: [f64; 3],
    /// The duties written, −1 … 1.
    pub duties: [f64; 3],
    /// The link's force gain, 0 … 1.
    pub gain: f64,
    /// Bit 0 homed, 1 at a limit, 2 thermal, 3 clamped, 4 faulted.
    pub flags: u32,
}

impl McBoxTick {
    fn of(t: &BoxTick) -> Self {
        Self {
            tick: t.tick,
            counts: t.counts,
            force_n: BlackBox::force_n(t),
            duties: BlackBox::duties(t),
            gain: BlackBox::gain(t),
            flags: t.flags as u32,
        }
    }
}

/// Reads the device's black box whole (a part of 4 ticks a request: some 125 requests
/// for the board's 500 ticks): what stopped and ended the run into `*out`, its ticks,
/// oldest first, into `ticks` (room for `capacity`), their count in `*count` (may be
/// null). `MCCS_ERR_BUFFER` when `capacity` is too small: `*out` and `*count` are still
/// written, so a second call with room for `out->ticks` reads it (again). The device
/// resetting while it is read is `MCCS_ERR_INTERNAL` with the reason.
///
/// # Safety
/// `d` is a live handle or null; `out` writable or null; `ticks` has room for
/// `capacity` ticks (or is null with `capacity` 0); `count` writable or null.
#[no_mangle]
pub unsafe extern "C" fn mccs_black_box(
    d: *const McDevice,
    out: *mut McBlackBox,
    ticks: *mut McBoxTick,
    capacity: usize,
    count: *mut usize,
) -> c_int {
    guarded(|| {
        // SAFETY: the caller's promise.
        let dev = unsafe { handle(d) }?;
        // SAFETY: the caller's promise.
        let out = unsafe { out.as_mut() }.ok_or_else(|| argument("out: null"))?;
        if ticks.is_null() && capacity != 0 {
            return Err(argument("ticks: null with a capacity"));
        }
        let b = dev.black_box(|_, _| {}).map_err(fail)?;
        let h = &b.head;
        *out = McBlackBox {
            kept: h.kept as c_int,
            stopped_by: h.cause.code() as c_int,
            part: h.part as c_int,
            stop_tick: h.tick,
            ended_by: h.end.code() as c_int,
            end_tick: h.end_tick,
            pc: h.pc,
            reset_flags: h.reset_flags,
            ticks: b.ticks.len() as u32,
        };
        // SAFETY: the caller's promise.
        if let Some(c) = unsafe { count.as_mut() } {
            *c = b.ticks.len();
        }
        if b.ticks.len() > capacity {
            return Err((
                MCCS_ERR_BUFFER,
                format!(
                    "the black box kept {} ticks, the buffer room for {capacity}",
                    b.ticks.len()
                ),
            ));
        }
        for (k, t) in b.ticks.iter().enumerate() {
            // SAFETY: `k < len ≤ capacity`, within the caller's buffer.
            unsafe { *ticks.add(k) = McBoxTick::of(t) };
        }
        Ok(())
    })
}

/// A stop cause's name (`"read"`, `"hard-fault"`, as `mccs link blackbox` prints it), or
/// null for a code that names none. Static: never freed.
#[no_mangle]
pub extern "C" fn mccs_stop_cause_name(code: c_int) -> *const c_char {
    static NAMES: OnceLock<Vec<CString>> = OnceLock::new();
    let names = NAMES.get_or_init(|| {
        StopCause::ALL
            .iter()
            .map(|c| CString::new(c.name()).unwrap_or_default())
            .collect()
    });
    u8::try_from(code)
        .ok()
        .and_then(StopCause::from_code)
        .and_then(|c| names.get(c.code() as usize))
        .map_or(std::ptr::null(), |n| n.as_ptr())
}
