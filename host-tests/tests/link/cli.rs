//! `mccs link` against the device in software (the firmware's own session and
//! replayer): each subcommand's line, a load acknowledged by its hash and a refusal in
//! one line, a replay that prints `mccs replay --backend fixed`'s CSV byte for byte, a
//! replay beyond the device named by its option.

use crate::cli::{mccs, mccs_ok};
use mccs::{ForceTable64, Params};
use std::path::PathBuf;

/// A soft device with Table 2 live, on a fresh socket.
fn device(name: &str) -> String {
    let dir = std::env::temp_dir().join(format!("mccs-link-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let socket: PathBuf = dir.join(format!("{name}.sock"));
    mccs_host::link::soft::serve(&socket, ForceTable64::new(&Params::TABLE2).unwrap()).unwrap();
    format!("unix:{}", socket.display())
}

fn line(out: &std::process::Output) -> String {
    String::from_utf8(out.stdout.clone())
        .unwrap()
        .trim_end()
        .to_string()
}

#[test]
fn hello_status_arm_pose_and_load() {
    let addr = device("basics");
    let hello = line(&mccs_ok(&["link", "--connect", &addr, "hello"]));
    let t2 = mccs_link::table_bytes::hash(&ForceTable64::new(&Params::TABLE2).unwrap());
    assert_eq!(
        hello,
        format!(
            "protocol={} schema={:08x} core=m4f tick_hz=1000 grid=5 tissue=5x5 knots=65 tissue_hash={t2:08x}",
            mccs_link::PROTOCOL,
            mccs_link::SCHEMA
        )
    );
    let status = line(&mccs_ok(&["link", "--connect", &addr, "status"]));
    assert!(
        status.starts_with("ticks=") && status.ends_with("armed=0 fault=0 pose=0,0,0"),
        "{status}"
    );
    assert!(line(&mccs_ok(&["link", "--connect", &addr, "arm"])).contains("armed=1"));
    assert!(line(&mccs_ok(&["link", "--connect", &addr, "disarm"])).contains("armed=0"));
    assert_eq!(
        line(&mccs_ok(&[
            "link",
            "--connect",
            &addr,
            "pose",
            "--origin",
            "1,-2.5,0"
        ])),
        "pose origin=1,-2.5,0"
    );
    assert!(line(&mccs_ok(&["link", "--connect", &addr, "status"])).ends_with("pose=1,-2.5,0"));
    // A load: the device acknowledges the tissue by its hash, and says it after.
    let ack = line(&mccs_ok(&[
        "link",
        "--connect",
        &addr,
        "load",
        "--params",
        "params/table2-stiffer.toml",
    ]));
    let stiffer = mccs_host::paramfile::read(std::path::Path::new("../params/table2-stiffer.toml"))
        .or_else(|_| mccs_host::paramfile::read(std::path::Path::new("params/table2-stiffer.toml")))
        .unwrap();
    let hash = mccs_link::table_bytes::hash(&ForceTable64::new(&stiffer).unwrap());
    assert_eq!(ack, format!("ack tissue={hash:08x}"));
    assert!(line(&mccs_ok(&["link", "--connect", &addr, "hello"]))
        .ends_with(&format!("tissue_hash={hash:08x}")));
    // A tissue the device's patch cannot run at its tick: refused in one line, kept.
    let out = mccs(&[
        "link",
        "--connect",
        &addr,
        "load",
        "--params",
        "params/steep-kink.toml",
    ]);
    crate::cli::assert_one_line_error(
        &out,
        &["the device refused: the device's solver refused the tissue on its patch"],
    );
    assert!(line(&mccs_ok(&["link", "--connect", &addr, "hello"]))
        .ends_with(&format!("tissue_hash={hash:08x}")));
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
                "--knots",
                "129",
            ][..],
            "--knots: the device takes 65 knots (got 129)",
        ),
    ] {
        crate::cli::assert_one_line_error(&mccs(args), &[needle]);
    }
}

#[test]
fn a_link_replay_prints_the_hosts_fixed_replay() {
    let addr = device("replay");
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
        let mut dev = vec![
            "link",
            "--connect",
            &addr,
            "replay",
            "--probe",
            "params/palpation.csv",
        ];
        dev.extend_from_slice(extra);
        let h = mccs_ok(&host).stdout;
        let d = mccs_ok(&dev).stdout;
        assert!(h.len() > 100_000);
        assert!(
            h == d,
            "{extra:?}: the device's replay differs from the host's"
        );
    }
    for (extra, needle) in [
        (
            &["--grid", "9"][..],
            "--grid: the device holds a patch of at most 8 nodes a side",
        ),
        (
            &["--arith", "narrow", "--backend", "fixed"][..],
            "--backend: a link replay runs the device's core",
        ),
        (
            &["--tissue", "64,64", "--cap-radius", "300"][..],
            "--cap-radius: the device roams flat tissues only",
        ),
    ] {
        let mut dev = vec![
            "link",
            "--connect",
            &addr,
            "replay",
            "--probe",
            "params/palpation.csv",
        ];
        dev.extend_from_slice(extra);
        crate::cli::assert_one_line_error(&mccs(&dev), &[needle]);
    }
}

/// A device of another schema is refused by the host, in one line naming both.
#[test]
fn a_device_of_another_schema_is_refused() {
    use mccs_link::message::{Core, HelloInfo, ToHost};
    use std::io::{Read, Write};
    let dir = std::env::temp_dir().join(format!("mccs-link-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let socket = dir.join("foreign.sock");
    let _ = std::fs::remove_file(&socket);
    let listener = std::os::unix::net::UnixListener::bind(&socket).unwrap();
    std::thread::spawn(move || {
        let (mut s, _) = listener.accept().unwrap();
        let mut b = [0u8; 64];
        let _ = s.read(&mut b);
        let hello = ToHost::Hello(HelloInfo {
            protocol: 1,
            schema: 0x1234_5678,
            core: Core::M4f,
            tick_hz: 1000,
            grid: 5,
            max_grid: 8,
            tissue_w: 5,
            tissue_h: 5,
            knots: 65,
            tissue: 0,
            path_capacity: 64,
        });
        let mut f = [0u8; mccs_link::MAX_FRAME];
        let frame = mccs_link::encode(&hello, &mut f).unwrap();
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
            "the device speaks protocol 1 schema 12345678, this mccs protocol {} schema {:08x}",
            mccs_link::PROTOCOL,
            mccs_link::SCHEMA
        )],
    );
}

/// `mccs link mesh`: every free node of the device's patch once per mesh, at its rest
/// position on the soft device (its patch at rest), meshes at least 17 ticks apart (60 a
/// second at most), numbered without gaps on an idle link; arguments out of range refused.
#[test]
fn mesh_streams_every_free_node_of_the_patch() {
    let addr = device("mesh");
    let (meshes, worst, _) = super::mesh_run(&addr, "0.4", 5);
    assert!(
        worst < 1e-6,
        "the soft device's patch at rest: {worst} mm off"
    );
    assert!(meshes.len() >= 5, "{} meshes in 0.4 s", meshes.len());
    let seqs: Vec<u32> = meshes.keys().copied().collect();
    for w in seqs.windows(2) {
        assert_eq!(w[1], w[0] + 1, "a gap on an idle link");
    }
    let bad = mccs(&["link", "--connect", &addr, "mesh", "--every", "0"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).starts_with("mccs: --every: "));
}
