//! The black box through the scene's C ABI (`mccs_black_box`, called as a C caller
//! would) and through the Python module (`client/python`, ctypes over the same library,
//! run by `python3`), against the soft device's fixture run (`soft::last_run`): each
//! field and tick the same as the Rust client reads, a short buffer refused with the
//! count a second call needs, bad arguments refused without a crash; and the Python
//! module's own argument checks, for what ctypes would pass on changed.

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

/// `python3 -c script args…` with the module and this build's library (target/…/deps,
/// beside this test binary): its stdout, once it exits with success.
fn python(script: &str, args: &[&std::ffi::OsStr]) -> String {
    let exe = std::env::current_exe().unwrap();
    let lib = exe.parent().unwrap().join("libmccs_client.so");
    assert!(lib.exists(), "{} (built with the workspace)", lib.display());
    let out = std::process::Command::new("python3")
        .arg("-c")
        .arg(script)
        .args(args)
        .env("PYTHONPATH", crate::cli::root().join("client/python"))
        .env("MCCS_CLIENT_LIB", &lib)
        .output()
        .expect("python3");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "python3: {stderr}");
    String::from_utf8(out.stdout).unwrap()
}

/// The Python module's `Device.black_box()` on the same device: its line and its ticks
/// as the Rust client's CSV rows, through ctypes over this build's library.
#[test]
fn the_python_module_reads_the_black_box_as_the_rust_client_does() {
    let dev = device("python");
    let want = reference(dev.addr());
    let script = r#"
import sys
from mccs_client import Device
with Device(sys.argv[1]) as d:
    b = d.black_box()
    print(b.line())
    for t in b.ticks:
        print(t.csv_row())
"#;
    let text = python(script, &[dev.addr().as_ref()]);
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

/// What ctypes would pass on changed, the Python module refuses as an argument error
/// (`MccsError`, `code == ERR_ARGUMENT`) naming the argument: a NUL byte in an address
/// or a path (ctypes cut the string there: `"unix:PATH\0junk"` opened `unix:PATH`), a
/// period outside `u16` (ctypes wrapped -1 to 65535 and 70000 to 4464), and a pose of
/// other than three and three numbers (four and two made another pose). A `pathlib.Path`
/// loads as its `str` does.
#[test]
fn the_python_module_refuses_what_ctypes_would_change() {
    let dev = device("python-arguments");
    let script = r#"
import pathlib, sys
import mccs_client as m
addr, params = sys.argv[1], sys.argv[2]
def refused(what, call):
    try:
        call()
    except m.MccsError as e:
        print(f"{what}: {e.code == m.ERR_ARGUMENT} {e}")
    else:
        print(f"{what}: accepted")
refused("addr", lambda: m.Device(addr + "\0junk"))
refused("addr type", lambda: m.Device(7))
with m.Device(addr) as d:
    refused("path", lambda: d.load_tissue(params + "\0.bin"))
    refused("friction", lambda: d.load_tissue(params, friction=(0.5,)))
    refused("watch -1", lambda: d.watch(-1))
    refused("watch 70000", lambda: d.watch(70000))
    refused("watch 2.5", lambda: d.watch(2.5))
    refused("mesh 65536", lambda: d.watch_mesh(65536))
    refused("pose 4+2", lambda: d.set_pose((1, 2, 3, 4), (5, 6)))
    refused("pose text", lambda: d.set_pose(("a", 0, 0)))
    print("hashes", d.load_tissue(pathlib.Path(params)) == d.load_tissue(params))
    d.watch(65535)
    d.watch_mesh(0)
"#;
    let params = crate::cli::root().join("params/table2.toml");
    let text = python(script, &[dev.addr().as_ref(), params.as_os_str()]);
    let want = [
        "addr: True addr: holds a NUL byte",
        "addr type: True addr: must be a str, not int",
        "path: True path: holds a NUL byte",
        "friction: True friction: must be 2 numbers, not 1",
        "watch -1: True every: must be a whole number of ticks, 0 … 65535 (got -1)",
        "watch 70000: True every: must be a whole number of ticks, 0 … 65535 (got 70000)",
        "watch 2.5: True every: must be a whole number of ticks, 0 … 65535 (got 2.5)",
        "mesh 65536: True every: must be a whole number of ticks, 0 … 65535 (got 65536)",
        "pose 4+2: True origin_mm: must be 3 numbers, not 4",
        "pose text: True origin_mm: must be 3 numbers",
        "hashes True",
    ];
    assert_eq!(text.lines().collect::<Vec<_>>(), want);
}
