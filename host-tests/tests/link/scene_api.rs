//! The black box through the scene's C ABI (`mccs_black_box`, called as a C caller
//! would) and through the Python module (`client/python`, ctypes over the same library,
//! run by `python3`), against the soft device's fixture run (`soft::last_run`): each
//! field and tick the same as the Rust client reads, a short buffer refused with the
//! count a second call needs, bad arguments refused without a crash.

use mccs::{ForceTable64, Params};
use mccs_client::ffi::{
    mccs_black_box, mccs_close, mccs_last_error, mccs_open, mccs_stop_cause_name, McBlackBox,
    McBoxTick, McDevice, MCCS_ERR_ARGUMENT, MCCS_ERR_BUFFER, MCCS_OK,
};
use mccs_host::link::soft::{serve, SoftDevice};
use mccs_link::black_box::StopCause;
use std::ffi::{CStr, CString};

fn device(name: &str) -> SoftDevice {
    let dir = std::env::temp_dir().join(format!("mccs-scene-api-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    serve(
        &dir.join(format!("{name}.sock")),
        ForceTable64::new(&Params::TABLE2).unwrap(),
    )
    .unwrap()
}

fn last_error() -> String {
    // SAFETY: the library's static or thread-local string, valid until the next call.
    unsafe { CStr::from_ptr(mccs_last_error()) }
        .to_string_lossy()
        .into_owned()
}

/// What the Rust client reads of the same device: the reference.
fn reference(addr: &str) -> mccs_client::BlackBox {
    mccs_client::Device::open(addr)
        .unwrap()
        .black_box(|_, _| {})
        .unwrap()
}

#[test]
fn the_c_abi_reads_the_black_box_as_the_rust_client_does() {
    let dev = device("c");
    let want = reference(dev.addr());
    assert!(want.kept() && !want.ticks.is_empty());
    let addr = CString::new(dev.addr()).unwrap();
    let mut d: *mut McDevice = std::ptr::null_mut();
    // SAFETY: a NUL-terminated address and a writable handle slot.
    assert_eq!(
        unsafe { mccs_open(addr.as_ptr(), &mut d) },
        MCCS_OK,
        "{}",
        last_error()
    );

    // No room: refused, with the head and the count a second call needs.
    let mut head = McBlackBox::default();
    let mut count = 0usize;
    // SAFETY: a live handle, writable outputs, no tick buffer with capacity 0.
    let r = unsafe { mccs_black_box(d, &mut head, std::ptr::null_mut(), 0, &mut count) };
    assert_eq!(r, MCCS_ERR_BUFFER);
    assert!(last_error().contains("room for 0"), "{}", last_error());
    assert_eq!(count, want.ticks.len());
    assert_eq!(head.ticks as usize, want.ticks.len());

    let mut ticks = vec![McBoxTick::default(); count];
    // SAFETY: as above, `ticks` with room for `count`.
    let r = unsafe { mccs_black_box(d, &mut head, ticks.as_mut_ptr(), count, &mut count) };
    assert_eq!(r, MCCS_OK, "{}", last_error());
    let h = &want.head;
    assert_eq!(head.kept, 1);
    assert_eq!(head.stopped_by, h.cause.code() as i32);
    assert_eq!(head.part, h.part as i32);
    assert_eq!(head.stop_tick, h.tick);
    assert_eq!(head.ended_by, h.end.code() as i32);
    assert_eq!(head.end_tick, h.end_tick);
    assert_eq!(head.pc, h.pc);
    assert_eq!(head.reset_flags, h.reset_flags);
    for (i, (c, r)) in ticks.iter().zip(&want.ticks).enumerate() {
        // The C tick in units, as the CSV prints it.
        let row = format!(
            "{},{},{},{},{},{},{},{:.5},{:.5},{:.5},{:.5},{}",
            c.tick,
            c.counts[0],
            c.counts[1],
            c.counts[2],
            c.force_n[0],
            c.force_n[1],
            c.force_n[2],
            c.duties[0],
            c.duties[1],
            c.duties[2],
            c.gain,
            c.flags
        );
        assert_eq!(row, mccs_client::BlackBox::csv_row(r), "tick {i}");
    }

    // Bad arguments: refused, no crash.
    // SAFETY: null handle and null outputs are what is tested.
    unsafe {
        let n = std::ptr::null_mut();
        assert_eq!(
            mccs_black_box(std::ptr::null(), &mut head, n, 0, n.cast()),
            MCCS_ERR_ARGUMENT
        );
        assert_eq!(
            mccs_black_box(d, std::ptr::null_mut(), n, 0, n.cast()),
            MCCS_ERR_ARGUMENT
        );
        assert_eq!(
            mccs_black_box(d, &mut head, n, 4, n.cast()),
            MCCS_ERR_ARGUMENT
        );
        mccs_close(d);
    }
}

#[test]
fn every_stop_cause_has_its_name_through_the_c_abi_and_none_other_does() {
    for c in StopCause::ALL {
        let p = mccs_stop_cause_name(c.code() as i32);
        assert!(!p.is_null(), "{c:?}");
        // SAFETY: a static NUL-terminated name.
        assert_eq!(unsafe { CStr::from_ptr(p) }.to_str().unwrap(), c.name());
    }
    for code in [-1, StopCause::ALL.len() as i32, 255, 256, i32::MAX] {
        assert!(mccs_stop_cause_name(code).is_null(), "{code}");
    }
}

/// The Python module's `Device.black_box()` on the same device: its line and its ticks
/// as the Rust client's CSV rows, through ctypes over this build's library.
#[test]
fn the_python_module_reads_the_black_box_as_the_rust_client_does() {
    let dev = device("python");
    let want = reference(dev.addr());
    // The library this test binary's build made (target/…/deps), beside it.
    let exe = std::env::current_exe().unwrap();
    let lib = exe.parent().unwrap().join("libmccs_client.so");
    assert!(lib.exists(), "{} (built with the workspace)", lib.display());
    let root = crate::cli::root();
    let script = r#"
import sys
from mccs_client import Device
with Device(sys.argv[1]) as d:
    b = d.black_box()
    print(b.line())
    for t in b.ticks:
        print(t.csv_row())
"#;
    let out = std::process::Command::new("python3")
        .args(["-c", script, dev.addr()])
        .env("PYTHONPATH", root.join("client/python"))
        .env("MCCS_CLIENT_LIB", &lib)
        .output()
        .expect("python3");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "python3: {stderr}");
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some(want.line(&want.head.part.to_string()).as_str())
    );
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), want.ticks.len());
    for (i, (row, t)) in rows.iter().zip(&want.ticks).enumerate() {
        assert_eq!(*row, mccs_client::BlackBox::csv_row(t), "tick {i}");
    }
}
