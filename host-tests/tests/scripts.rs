//! The scripts a person runs by hand refuse a bad argument before they build or run
//! anything: exit 2, nothing on stdout, and one line on stderr that says what they take.

use std::path::Path;
use std::process::Command;

#[test]
fn scripts_refuse_a_bad_argument_in_one_line() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let cases: [(&str, &[&str], &str); 10] = [
        (
            "bash",
            &["scripts/bench.sh", "--frob"],
            "usage: scripts/bench.sh",
        ),
        (
            "bash",
            &["scripts/long.sh", "abc"],
            "usage: scripts/long.sh",
        ),
        ("bash", &["scripts/fuzz.sh", "0"], "usage: scripts/fuzz.sh"),
        (
            "bash",
            &["scripts/qemu-link.sh"],
            "usage: scripts/qemu-link.sh",
        ),
        (
            "bash",
            &["scripts/firmware.sh", "m7"],
            "core must be m4f, m3 or m0",
        ),
        (
            "python3",
            &["scripts/profile.py", "m4f", "--top", "x"],
            "usage: scripts/profile.py",
        ),
        (
            "python3",
            &["scripts/figures.py", "frob"],
            "usage: scripts/figures.py",
        ),
        ("python3", &["scripts/size.py", "elf"], "usage: size.py"),
        (
            "python3",
            &["scripts/check_tick_path.py"],
            "usage: check_tick_path.py",
        ),
        (
            "python3",
            &["scripts/check_stack_probes.py"],
            "usage: scripts/check_stack_probes.py",
        ),
    ];
    for (program, args, needle) in cases {
        let out = Command::new(program)
            .args(args)
            .current_dir(&root)
            .output()
            .expect("run the script");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}: stdout not empty");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err:?} lacks {needle:?}");
    }
}
