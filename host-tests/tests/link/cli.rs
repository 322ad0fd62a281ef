//! `mccs link` against the device in software (the arm board's own link server and tick
//! on a simulated palpating probe): each subcommand's line, a load acknowledged by its
//! hash and a refusal in one line, a replay that prints `mccs replay --backend fixed`'s
//! CSV byte for byte, the mesh and telemetry streams, and `mccs link script` holding the
//! device armed across its steps.

use crate::cli::{mccs, mccs_ok};
use mccs::{ForceTable64, Params};
use mccs_host::link::soft::SoftDevice;
use std::path::PathBuf;

/// A soft device with Table 2 live, on a fresh socket.
fn device(name: &str) -> SoftDevice {
    let dir = std::env::temp_dir().join(format!("mccs-link-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let socket: PathBuf = dir.join(format!("{name}.sock"));
    mccs_host::link::soft::serve(&socket, ForceTable64::new(&Params::TABLE2).unwrap()).unwrap()
}

fn line(out: &std::process::Output) -> String {
    String::from_utf8(out.stdout.clone())
        .unwrap()
        .trim_end()
        .to_string()
}

fn hash_of(file: &str) -> u32 {
    let p = mccs_host::paramfile::read(&crate::cli::root().join(file)).unwrap();
    mccs_link::table_bytes::hash(&ForceTable64::new(&p).unwrap())
}

#[test]
fn hello_status_arm_pose_and_load() {
    let dev = device("basics");
    let addr = dev.addr().to_string();
    let hello = line(&mccs_ok(&["link", "--connect", &addr, "hello"]));
    let t2 = hash_of("params/table2.toml");
    for field in [
        format!("protocol={} schema={:08x}", mccs_link::PROTOCOL, mccs_link::SCHEMA),
        format!(
            "device=arm simulated=1 core=m4f tick_hz=1000 contact=roaming grid={} tissue=64x64",
            haptic_f405::BOARD.grid
        ),
        format!("knots=65 tissue_hash={t2:08x} friction=0.6,0.4"),
        "force_clamp_n=3 workspace_mm=-50,-50,-40..50,50,40 pose_limits=200mm/s,180deg/s baud=1000000".into(),
    ] {
        assert!(hello.contains(&field), "{field} not in {hello}");
    }
    let status = line(&mccs_ok(&["link", "--connect", &addr, "status"]));
    assert!(
        status.starts_with("ticks=") && status.contains("armed=0 fault=none"),
        "{status}"
    );
    assert!(line(&mccs_ok(&["link", "--connect", &addr, "arm"])).contains("armed=1"));
    assert!(line(&mccs_ok(&["link", "--connect", &addr, "disarm"])).contains("armed=0"));
    let pose = line(&mccs_ok(&[
        "link",
        "--connect",
        &addr,
        "pose",
        "--origin",
        "1,-2.5,0",
        "--rotation",
        "0,15,0",
    ]));
    assert_eq!(pose, "pose origin=1,-2.5,0 rotation=0.000,15.000,0.000");
    assert!(line(&mccs_ok(&["link", "--connect", &addr, "status"]))
        .contains("pose=1,-2.5,0 rotation_deg=0.000,15.000,0.000"));
    // A load: acknowledged by the tissue's hash, which hello says after; with friction.
    let ack = line(&mccs_ok(&[
        "link",
        "--connect",
        &addr,
        "load",
        "--params",
        "params/table2-stiffer.toml",
        "--friction",
        "0.5,0.3",
    ]));
    let hash = hash_of("params/table2-stiffer.toml");
    assert_eq!(ack, format!("ack tissue={hash:08x}"));
    let hello = line(&mccs_ok(&["link", "--connect", &addr, "hello"]));
    assert!(
        hello.contains(&format!("tissue_hash={hash:08x} friction=0.5,0.3")),
        "{hello}"
    );
    // The same table as a .bin (`mccs table --format bin`) loads the same.
    let bin = std::env::temp_dir().join(format!("mccs-link-{}-t2.bin", std::process::id()));
    mccs_ok(&[
        "table",
        "--params",
        "params/table2.toml",
        "--format",
        "bin",
        "--out",
        bin.to_str().unwrap(),
    ]);
    let ack = line(&mccs_ok(&[
        "link",
        "--connect",
        &addr,
        "load",
        "--params",
        bin.to_str().unwrap(),
    ]));
    assert_eq!(ack, format!("ack tissue={t2:08x}"));
    // A tissue ten times stiffer: its tick passes the device's budget, one line.
    let stiff = std::env::temp_dir().join(format!("mccs-link-{}-stiff.toml", std::process::id()));
    let text = std::fs::read_to_string(crate::cli::root().join("params/table2.toml")).unwrap();
    std::fs::write(
        &stiff,
        text.replace("shear_modulus = 1.8472e5", "shear_modulus = 1.8472e6")
            .replace("shear_modulus = 4.9151e5", "shear_modulus = 4.9151e6"),
    )
    .unwrap();
    let out = mccs(&[
        "link",
        "--connect",
        &addr,
        "load",
        "--params",
        stiff.to_str().unwrap(),
    ]);
    crate::cli::assert_one_line_error(
        &out,
        &["the device refused: the tissue's tick would pass the device's instruction budget: it needs"],
    );
    // A pose outside the workspace.
    let out = mccs(&["link", "--connect", &addr, "pose", "--origin", "0,0,60"]);
    crate::cli::assert_one_line_error(&out, &["the device refused: the pose's origin is outside the device's workspace: z passes 40 mm"]);
    // Bad arguments, before the device is reached.
    for (args, needle) in [
        (
            &["link", "--connect", "nowhere:x", "hello"][..],
            "--connect: must be unix:PATH",
        ),
        (
            &["link", "--connect", &addr, "pose", "--origin", "1,2"][..],
            "--origin: must be X,Y,Z",
        ),
        (
            &[
                "link",
                "--connect",
                &addr,
                "load",
                "--params",
                "params/table2.toml",
                "--friction",
                "0.2,0.5",
            ][..],
            "--friction: mu_s and mu_k must be within",
        ),
        (
            &["link", "--connect", "unix:/nonexistent/mccs.sock", "hello"][..],
            "--connect: unix:/nonexistent/mccs.sock: ",
        ),
    ] {
        crate::cli::assert_one_line_error(&mccs(args), &[needle]);
    }
}

#[test]
fn a_link_replay_prints_the_hosts_fixed_replay() {
    let dev = device("replay");
    let addr = dev.addr().to_string();
    for extra in [
        &[][..],
        &["--tissue", "64,64", "--friction", "0.6,0.4"][..],
        &[
            "--grid",
            "7",
            "--tissue",
            "40,40",
            "--coupling-stiffness",
            "2",
            "--node-mass",
            "8",
        ][..],
        &["--arith", "wide"][..],
    ] {
        let mut host = vec![
            "replay",
            "--params",
            "params/table2.toml",
            "--probe",
            "params/palpation.csv",
            "--backend",
            "fixed",
        ];
        host.extend_from_slice(extra);
        let mut link = vec![
            "link",
            "--connect",
            &addr,
            "replay",
            "--probe",
            "params/palpation.csv",
        ];
        link.extend_from_slice(extra);
        let h = mccs_ok(&host).stdout;
        let d = mccs_ok(&link).stdout;
        assert!(h.len() > 100_000);
        assert!(
            h == d,
            "{extra:?}: the device's replay differs from the host's"
        );
    }
    for (extra, needle) in [
        (
            &["--grid", "11"][..],
            "--grid: the device holds a patch of at most 10 nodes a side",
        ),
        (
            &["--arith", "narrow", "--backend", "fixed"][..],
            "--backend: a link replay runs the device's core",
        ),
        // (Checked by the device, where `--arith` was refused before it was sent.)
        (
            &["--arith", "narrow"][..],
            "the device runs one arithmetic (wide)",
        ),
        (
            &["--tissue", "64,64", "--cap-radius", "300"][..],
            "--cap-radius: ",
        ),
    ] {
        let mut link = vec![
            "link",
            "--connect",
            &addr,
            "replay",
            "--probe",
            "params/palpation.csv",
        ];
        link.extend_from_slice(extra);
        crate::cli::assert_one_line_error(&mccs(&link), &[needle]);
    }
}

/// A device of another schema is refused by the host, in one line naming both.
#[test]
fn a_device_of_another_schema_is_refused() {
    use std::io::{Read, Write};
    let dir = std::env::temp_dir().join(format!("mccs-link-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let socket = dir.join("foreign.sock");
    let _ = std::fs::remove_file(&socket);
    let listener = std::os::unix::net::UnixListener::bind(&socket).unwrap();
    // A hello of protocol 2 (its bytes as that protocol framed them): a variant index,
    // protocol, schema, and more this client will not parse past the first two fields.
    let real = dev_hello();
    std::thread::spawn(move || {
        let (mut s, _) = listener.accept().unwrap();
        let mut b = [0u8; 64];
        let _ = s.read(&mut b);
        let mut hello = real;
        hello.protocol = 2;
        hello.schema = 0x1234_5678;
        let mut f = [0u8; mccs_link::MAX_FRAME];
        let frame = mccs_link::encode(&mccs_link::ToHost::Hello(hello), &mut f).unwrap();
        s.write_all(frame).unwrap();
        std::thread::sleep(std::time::Duration::from_millis(500));
    });
    let out = mccs(&[
        "link",
        "--connect",
        &format!("unix:{}", socket.display()),
        "status",
    ]);
    crate::cli::assert_one_line_error(
        &out,
        &[&format!(
            "the device speaks protocol 2 schema 12345678, this client protocol {} schema {:08x}",
            mccs_link::PROTOCOL,
            mccs_link::SCHEMA
        )],
    );
}

/// A hello as the soft device sends it.
fn dev_hello() -> mccs_link::HelloInfo {
    let dev = device("hello");
    mccs_client::Device::open(dev.addr()).unwrap().info().hello
}

/// `mccs link mesh`: every free node once per mesh in its grid place, meshes at least the
/// byte budget's period apart, numbered without gaps on an idle link; arguments out of
/// range refused.
#[test]
fn mesh_streams_every_free_node_of_the_patch() {
    let dev = device("mesh");
    let grid = haptic_f405::BOARD.grid;
    let free = (grid - 2).pow(2);
    let least = mccs_link::rates::mesh_least_every(1000, 1_000_000, free) as u32;
    let (meshes, _, _) = super::mesh_run(dev.addr(), "0.5", grid, least);
    assert!(meshes.len() >= 10, "{} meshes in 0.5 s", meshes.len());
    let bad = mccs(&["link", "--connect", dev.addr(), "mesh", "--every", "0"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).starts_with("mccs: --every: "));
}

/// `mccs link script`: one session through a scene — hello, a load, armed across steps
/// (the gain full throughout, no fade), the pose moved, the telemetry as one CSV with its
/// header once, rows during a load — and a bad line or a refusal as exit 2 with its line.
#[test]
fn a_script_holds_the_device_armed_as_long_as_it_says() {
    let dev = device("script");
    let dir = std::env::temp_dir().join(format!("mccs-link-{}", std::process::id()));
    let script = dir.join("scene.txt");
    std::fs::write(
        &script,
        format!(
            "# a scene\nhello\ntelemetry on every=10\narm\nwait 1.5\nload {}/params/table2-stiffer.toml friction=0.5,0.4\npose 5,0,0,0,10,0   # tilted\nmesh on\nwait 1\nstatus\ndisarm\n",
            crate::cli::root().display()
        ),
    )
    .unwrap();
    let out = mccs_ok(&[
        "link",
        "--connect",
        dev.addr(),
        "script",
        script.to_str().unwrap(),
    ]);
    let text = String::from_utf8(out.stdout).unwrap();
    let steps: Vec<&str> = text.lines().filter(|l| l.starts_with("# ")).collect();
    assert!(steps[0].starts_with("# protocol=3 "), "{steps:?}");
    assert_eq!(steps[1], "# telemetry every=10");
    assert!(steps[2].contains("armed=1"), "{steps:?}");
    assert_eq!(steps[3], "# waited 1.5");
    assert_eq!(
        steps[4],
        format!("# ack tissue={:08x}", hash_of("params/table2-stiffer.toml"))
    );
    assert_eq!(steps[5], "# pose origin=5,0,0 rotation=0.000,10.000,0.000");
    assert!(
        steps.iter().any(|l| l.starts_with("# mesh seq=")),
        "{steps:?}"
    );
    assert!(steps
        .iter()
        .any(|l| l.contains("armed=1") && l.starts_with("# ticks=")));
    assert!(steps.last().unwrap().contains("armed=0"));
    let rows: Vec<&str> = text.lines().filter(|l| !l.starts_with("# ")).collect();
    assert!(rows[0].starts_with("t_s,seq,tick,"), "{}", rows[0]);
    assert_eq!(
        rows.iter().filter(|l| l.starts_with("t_s,")).count(),
        1,
        "one header"
    );
    let col = |name: &str| rows[0].split(',').position(|c| c == name).unwrap();
    let (armed_col, seq_col, tick_col, dropped_col) =
        (col("armed"), col("seq"), col("tick"), col("dropped"));
    // The stream whole, in the device's own counts (not the host's clock, which a loaded
    // machine stalls): each sample follows the last by one `seq`, or the device counted
    // what it dropped between, at a later tick; armed in every row until the disarm.
    let mut last: Option<(u64, u64, u64)> = None;
    let mut armed_rows = 0;
    for r in &rows[1..] {
        let v: Vec<&str> = r.split(',').collect();
        if v[armed_col] == "1" {
            armed_rows += 1;
        }
        let n = |k: usize| v[k].parse::<u64>().unwrap();
        let (seq, tick, dropped) = (n(seq_col), n(tick_col), n(dropped_col));
        if let Some((s, t, d)) = last {
            assert_eq!(seq - s, 1 + dropped - d, "a sample lost at seq {seq}: {r}");
            assert!(tick > t, "ticks going back at seq {seq}: {t} then {tick}");
        }
        last = Some((seq, tick, dropped));
    }
    assert!(armed_rows > 150, "{armed_rows} armed rows");
    // The script `text` run on the device.
    let run = |text: &str| {
        std::fs::write(&script, text).unwrap();
        mccs(&[
            "link",
            "--connect",
            dev.addr(),
            "script",
            script.to_str().unwrap(),
        ])
    };
    // A bad line: exit 2 naming it, before the device is reached; a word with a
    // terminal's escape in it shown escaped.
    for (text, what) in [
        ("hello\narm\nwiat 1\n", "3: unknown step 'wiat'"),
        (
            "hello\n\u{1b}[2Jwait 1\n",
            r"2: unknown step '\u{1b}[2Jwait'",
        ),
        (
            "telemetry on every=\u{1b}]0;t\u{7}\n",
            r"1: 'every=\u{1b}]0;t\u{7}': expected every=N",
        ),
    ] {
        crate::cli::assert_one_line_error(&run(text), &[&format!("{}:{what}", script.display())]);
    }
    // A refusal: exit 2 naming its line, after a disarm.
    let out = run("arm\npose 0,0,90\nwait 1\n");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains(&format!("{}:2: ", script.display()))
            && err.contains("outside the device's workspace"),
        "{err}"
    );
    assert!(line(&mccs_ok(&["link", "--connect", dev.addr(), "status"])).contains("armed=0"));
}

/// `mccs link blackbox`: the record the device kept of its last run (the soft device's
/// fixture, `soft::last_run`: 600 ticks of its palpation, stopped by a read fault of the
/// encoder's frames, ended by a HardFault, kept through a watchdog's reset), read part
/// by part: its line with the part named as the board's log names it, then the ring's
/// last 500 ticks as CSV, each row the tick the board's recording made of it.
#[test]
fn blackbox_reads_the_last_run_back_part_by_part() {
    use mccs_firmware::black_box::BLACK_BOX_TICKS;
    use mccs_host::link::soft::{last_run, LAST_RUN_TICKS};
    let dev = device("blackbox");
    let out = mccs_ok(&["link", "--connect", dev.addr(), "blackbox"]);
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    let head = lines.next().unwrap_or("");
    let last = LAST_RUN_TICKS - 1;
    assert_eq!(
        head,
        format!(
            "blackbox kept=true stopped_by=read part=\"the encoder's frames\" stop_tick={last} ended_by=hard-fault end_tick={} pc=0x08001234 reset=IWDG reset_flags=0x20000000 ticks={BLACK_BOX_TICKS}",
            LAST_RUN_TICKS + 99
        )
    );
    assert_eq!(lines.next(), Some(mccs_client::BlackBox::CSV_HEADER));
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), BLACK_BOX_TICKS);
    // The rows are the box's ticks, oldest first: the last 500 of the 600.
    let kept = last_run(ForceTable64::new(&Params::TABLE2).unwrap());
    for (i, row) in rows.iter().enumerate() {
        let t = kept.tick(i).unwrap();
        assert_eq!(*row, mccs_client::BlackBox::csv_row(&t), "row {i}");
        assert_eq!(
            t.tick as usize,
            LAST_RUN_TICKS as usize - BLACK_BOX_TICKS + i
        );
    }
    // The palpation pressed: some rows carry a force, all the full gain.
    assert!(
        rows.iter().any(|r| r.split(',').nth(6) != Some("0")),
        "no force"
    );
    assert!(rows.iter().all(|r| r.split(',').nth(10) == Some("1.00000")));
}

/// A device that does not answer its hello (another host holds it, or it is not one):
/// `mccs link` says that it waits, and for how long at most, before the error at the
/// end of its wait; it was silent for the whole 10 s. (The run is ended once the line
/// has come.)
#[test]
fn a_silent_device_is_waited_for_out_loud() {
    use std::io::BufRead;
    let dir = std::env::temp_dir().join(format!("mccs-link-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let socket = dir.join("silent.sock");
    let _ = std::fs::remove_file(&socket);
    let _listener = std::os::unix::net::UnixListener::bind(&socket).unwrap();
    let addr = format!("unix:{}", socket.display());
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_mccs"))
        .args(["link", "--connect", &addr, "hello"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    std::io::BufReader::new(child.stderr.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    let _ = child.kill();
    let _ = child.wait();
    assert_eq!(
        first,
        format!("mccs: waiting for {addr} to answer hello (10 s at most; a view or a scene may hold it)\n")
    );
}
