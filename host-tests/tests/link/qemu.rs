//! The board firmware in QEMU behind the scene's library (`scripts/qemu-link.sh`): the
//! trainer's loop on the simulated arm board — hello within 50 ticks, armed 10 s on
//! keepalives at full gain, a tissue swapped mid-press without a telemetry gap over 50
//! ticks, a tissue over the tick budget refused, a pose moved and tilted with the force
//! along the tilted surface, friction reaching the hand, a replay equal to the host's,
//! corrupted frames counted, silence faded, the mesh, the stack's room above the statics
//! (the board's RAM read through QMP) — then the 1-DOF board's live path
//! on its simulated lever, and a board whose ticks overrun ending in its safe state.
//! Each scenario runs its steps by name (a failure names its step); figures go out as
//! `LINK` lines (docs/link.md).
//!
//! QEMU takes a while to start and run: the test command runs these in their own stage
//! (`MCCS_LINK_QEMU=1`); `cargo test` alone skips them, saying so.

use crate::cli::{mccs_ok, root};
use mccs_client::{Device, Options, TelemetrySample, Tissue};
use mccs_link::{
    encode, parse, scale, Decoder, FaultReason, Flags, NakReason, Pose, ToDevice, ToHost, MAX_FRAME,
};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

/// QEMU, stopped with the test.
struct Qemu(Child);

impl Drop for Qemu {
    fn drop(&mut self) {
        // The script's process group: the script, QEMU and the decoder.
        let _ = Command::new("kill")
            .args(["--", &format!("-{}", self.0.id())])
            .status();
        let _ = self.0.wait();
    }
}

/// Whether this run holds the QEMU tests (else: skipped, said).
fn wanted() -> bool {
    let on = std::env::var("MCCS_LINK_QEMU").as_deref() == Ok("1");
    if !on {
        eprintln!("skipped: the board firmware in QEMU runs in the test command's link-qemu stage (MCCS_LINK_QEMU=1)");
    }
    on
}

/// `scripts/qemu-link.sh ARGS SOCKET`, its log in target/qemu/link-NAME.log; its address
/// once the socket is there.
fn start(name: &str, args: &[&str]) -> (Qemu, String) {
    use std::os::unix::process::CommandExt;
    let socket = std::env::temp_dir().join(format!("mccs-qemu-{name}-{}.sock", std::process::id()));
    let _ = std::fs::remove_file(&socket);
    std::fs::create_dir_all(root().join("target/qemu")).unwrap();
    let log = std::fs::File::create(root().join(format!("target/qemu/link-{name}.log"))).unwrap();
    let qmp = qmp_socket(name);
    let _ = std::fs::remove_file(&qmp);
    let child = Command::new("bash")
        .env(
            "QEMU_EXTRA",
            format!("-qmp unix:{},server=on,wait=off", qmp.display()),
        )
        .arg(root().join("scripts/qemu-link.sh"))
        .args(args)
        .arg(&socket)
        .current_dir(root())
        .stdin(Stdio::null())
        .stdout(log)
        .stderr(Stdio::inherit())
        .process_group(0)
        .spawn()
        .expect("scripts/qemu-link.sh");
    let qemu = Qemu(child);
    let deadline = Instant::now() + Duration::from_secs(300);
    while !socket.exists() {
        assert!(
            Instant::now() < deadline,
            "{name}: QEMU's socket never appeared"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    (qemu, format!("unix:{}", socket.display()))
}

/// A session, with time for QEMU to boot (bytes before the USART is on are lost: hello
/// again every 200 ms).
fn open(addr: &str) -> Device {
    Device::open_with(
        addr,
        Options {
            hello_timeout: Duration::from_secs(120),
            ..Options::default()
        },
    )
    .unwrap()
}

/// Runs step `name`; its failure names it.
fn step<T>(scenario: &str, name: &str, f: impl FnOnce() -> T) -> T {
    eprintln!("LINK step={scenario}/{name} …");
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
        Ok(v) => {
            println!("LINK step={scenario}/{name} ok");
            v
        }
        Err(e) => {
            let why = e
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            panic!("{scenario}: step '{name}' failed: {why}");
        }
    }
}

/// The telemetry samples of `rx` until `until` says stop (or `limit` passes).
fn collect(
    rx: &Receiver<TelemetrySample>,
    limit: Duration,
    mut until: impl FnMut(&[TelemetrySample]) -> bool,
) -> Vec<TelemetrySample> {
    let end = Instant::now() + limit;
    let mut got = Vec::new();
    while Instant::now() < end {
        if let Ok(t) = rx.recv_timeout(Duration::from_millis(50)) {
            got.push(t);
            if until(&got) {
                break;
            }
        }
    }
    got
}

fn params(name: &str) -> PathBuf {
    root().join("params").join(name)
}

#[test]
fn the_simulated_arm_board_in_qemu_runs_the_trainers_loop() {
    if !wanted() {
        return;
    }
    let s = "arm";
    let (_qemu, addr) = start("arm-sim", &["--sim"]);
    let device = open(&addr);
    let telemetry = device.telemetry_stream();
    step(s, "hello within 50 ticks", || {
        let before = device.status().unwrap().raw.ticks;
        let h = device.hello().unwrap().hello;
        let after = device.status().unwrap().raw.ticks;
        assert!(after - before <= 50, "hello took {} ticks", after - before);
        assert_eq!(
            (h.device, h.contact, h.simulated),
            (
                mccs_link::DeviceKind::Arm,
                mccs_link::ContactKind::Roaming,
                true
            )
        );
        assert_eq!(
            (h.protocol, h.schema, h.knots),
            (mccs_link::PROTOCOL, mccs_link::SCHEMA, 65)
        );
        println!("LINK case=hello round_trip_ticks={}", after - before);
    });
    step(s, "armed 10 s on keepalives at full gain", || {
        device.watch(10).unwrap();
        let armed = device.arm_held().unwrap();
        assert!(armed.raw.armed);
        // The ramp: full gain once the probe has left the tissue and 500 ticks passed.
        // (Limits on the host's clock are generous where the wait ends on the device's
        // state: QEMU runs slower with other work beside it.)
        let up = collect(&telemetry, Duration::from_secs(60), |g| {
            g.last().unwrap().gain >= 1.0
        });
        assert!(
            up.last().unwrap().gain >= 1.0,
            "the gain never reached full"
        );
        let start = Instant::now();
        let held = collect(&telemetry, Duration::from_secs(10), |_| false);
        assert!(start.elapsed() >= Duration::from_secs(9));
        let low = held
            .iter()
            .filter(|t| t.gain < 1.0 || !t.flags.contains(Flags::ARMED))
            .count();
        assert_eq!(low, 0, "{low} samples below full gain or disarmed in 10 s");
        let ticks = held.last().unwrap().tick - held[0].tick;
        println!(
            "LINK case=armed seconds=10 samples={} ticks={ticks} below_full_gain=0",
            held.len()
        );
    });
    step(
        s,
        "a tissue loaded mid-press without a telemetry gap over 50 ticks",
        || {
            // Wait for a press (contact), then load the stiffer tissue while the stream runs.
            collect(&telemetry, Duration::from_secs(30), |g| {
                g.last().unwrap().flags.contains(Flags::CONTACT)
            });
            let stiffer = Tissue::from_param_file(&params("table2-stiffer.toml")).unwrap();
            let t0 = Instant::now();
            let hash = std::thread::scope(|sc| {
                let load = sc.spawn(|| device.load_tissue(&stiffer));
                let during = collect(&telemetry, Duration::from_secs(30), |_| load.is_finished());
                let hash = load.join().unwrap().unwrap();
                let gap = during
                    .windows(2)
                    .map(|w| w[1].tick - w[0].tick)
                    .max()
                    .unwrap_or(0);
                let checking = during
                    .iter()
                    .filter(|t| t.flags.contains(Flags::CHECKING))
                    .count();
                let contact = during
                    .iter()
                    .filter(|t| t.flags.contains(Flags::CONTACT))
                    .count();
                assert!(gap <= 50, "a telemetry gap of {gap} ticks during the load");
                assert!(
                    during.iter().all(|t| t.gain >= 1.0),
                    "the force faded during the load"
                );
                println!(
                "LINK case=load_mid_press seconds={:.2} samples={} largest_gap_ticks={gap} checking_samples={checking} contact_samples={contact}",
                t0.elapsed().as_secs_f64(),
                during.len()
            );
                hash
            });
            assert_eq!(hash, stiffer.hash());
            assert_eq!(device.hello().unwrap().hello.tissue, hash);
        },
    );
    step(
        s,
        "hello and status answered within 50 ticks while the device searches",
        || {
            // No proposal: the device's own search (ten runs), a slice at a time.
            let t2 = Tissue::from_param_file(&params("table2.toml")).unwrap();
            std::thread::scope(|sc| {
                let load =
                    sc.spawn(|| device.load_tissue_proposing(&t2, mccs_client::Proposal::None));
                let (mut worst, mut asked, mut checking) = (0, 0, 0);
                while !load.is_finished() {
                    let a = device.status().unwrap().raw;
                    let h = device.hello().unwrap();
                    let b = device.status().unwrap().raw;
                    if a.checking && b.checking {
                        worst = worst.max(b.ticks - a.ticks);
                        checking += 1;
                    }
                    asked += 1;
                    let _ = h;
                }
                assert_eq!(load.join().unwrap().unwrap(), t2.hash());
                assert!(checking >= 3, "{checking} rounds during the check");
                assert!(
                    worst <= 50,
                    "status, hello, status took {worst} ticks during the check"
                );
                println!("LINK case=answers_during_search rounds={asked} during_check={checking} worst_ticks={worst}");
            });
        },
    );
    step(s, "a tissue over the tick budget refused", || {
        let mut stiff = mccs::Params::TABLE2;
        stiff.cone.shear_modulus *= 10.0;
        stiff.linear.shear_modulus *= 10.0;
        let e = device
            .load_tissue(&Tissue::from_params(&stiff).unwrap())
            .unwrap_err();
        match e.refusal() {
            Some(NakReason::Budget {
                substeps,
                instructions,
                budget,
            }) => {
                println!("LINK case=over_budget substeps={substeps} instructions={instructions} budget={budget}");
                assert!(instructions > budget);
            }
            other => panic!("{other:?}: {e}"),
        }
        let over = device
            .load_tissue(&Tissue::from_param_file(&params("table2.toml")).unwrap())
            .unwrap();
        assert_eq!(device.hello().unwrap().hello.tissue, over);
    });
    step(s, "friction reaches the hand", || {
        // Over the palpation's slides (at depth), slipping: lateral over normal is mu_k.
        // 2,000 of the device's ticks (a sample every 10), however fast QEMU runs.
        let round = collect(&telemetry, Duration::from_secs(40), |g| g.len() >= 200);
        let (mu_s, mu_k) = device.info().friction();
        let slipping: Vec<&TelemetrySample> = round
            .iter()
            .filter(|t| t.flags.contains(Flags::SLIPPING) && t.force_n[2] > 0.2)
            .collect();
        assert!(slipping.len() > 20, "{} slipping samples", slipping.len());
        let ratio: f64 = slipping
            .iter()
            .map(|t| t.force_n[0].hypot(t.force_n[1]) / t.force_n[2])
            .sum::<f64>()
            / slipping.len() as f64;
        assert!(
            (ratio - mu_k).abs() <= 0.1 * mu_k,
            "lateral/normal {ratio:.3} against mu_k {mu_k}"
        );
        println!("LINK case=friction slipping_samples={} lateral_over_normal={ratio:.4} mu_k={mu_k} mu_s={mu_s}", slipping.len());
    });
    step(
        s,
        "the pose moved and tilted, the force along the tilted surface",
        || {
            let tilt = 20.0f64;
            device
                .set_pose(Pose::from_mm_deg([5.0, 0.0, 0.0], [tilt, 0.0, 0.0]))
                .unwrap();
            // 20° at 180°/s: settled within 200 ticks; then a round of the palpation.
            let round = collect(&telemetry, Duration::from_secs(40), |g| g.len() >= 200);
            let n = [0.0, -tilt.to_radians().sin(), tilt.to_radians().cos()];
            let (mu_s, _) = device.info().friction();
            let pressed: Vec<&TelemetrySample> = round[60..]
                .iter()
                .filter(|t| {
                    t.flags.contains(Flags::CONTACT)
                        && t.force_n.iter().map(|f| f * f).sum::<f64>().sqrt() > 0.2
                })
                .collect();
            assert!(pressed.len() > 20, "{} pressed samples", pressed.len());
            let mut worst = 0.0f64;
            let mut off_vertical = 0.0f64;
            for t in &pressed {
                let f = t.force_n;
                let along: f64 = (0..3).map(|k| f[k] * n[k]).sum();
                assert!(along > 0.0, "a force into the surface: {f:?}");
                let across = (0..3)
                    .map(|k| (f[k] - along * n[k]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                worst = worst.max(across / along);
                off_vertical += (f[2] / f.iter().map(|x| x * x).sum::<f64>().sqrt())
                    .acos()
                    .to_degrees();
            }
            // Within the tilted surface's friction cone (the proxy sticks within mu_s).
            assert!(
                worst <= mu_s * 1.05,
                "across/along {worst:.3} past mu_s {mu_s}"
            );
            let off = off_vertical / pressed.len() as f64;
            println!("LINK case=tilt degrees={tilt} pressed_samples={} worst_across_over_along={worst:.3} mean_off_vertical_deg={off:.1}", pressed.len());
            assert!(
                off > 5.0,
                "the force stayed vertical ({off:.1}°): it does not follow the tilt"
            );
            device.set_pose(Pose::IDENTITY).unwrap();
        },
    );
    step(s, "corrupted frames counted, nothing changed", || {
        let before = device.status().unwrap().raw;
        let good = {
            let mut f = [0u8; MAX_FRAME];
            encode(
                &ToDevice::Pose(Pose::from_mm_deg([30.0, 30.0, 30.0], [0.0; 3])),
                &mut f,
            )
            .unwrap()
            .to_vec()
        };
        let mut sent = 0;
        for i in 0..good.len() - 1 {
            let mut bad = good.clone();
            bad[i] ^= 0x10;
            if bad[i] == 0 {
                bad[i] = 0x55;
            }
            device.send_raw(&bad).unwrap();
            sent += 1;
        }
        device.send_raw(&[7u8; 400]).unwrap();
        device.send_raw(&[0]).unwrap();
        sent += 1;
        let after = device.status().unwrap().raw;
        assert!(
            after.bad_frames - before.bad_frames >= sent,
            "{} counted of {sent}",
            after.bad_frames - before.bad_frames
        );
        assert_eq!(
            after.pose, before.pose,
            "a corrupted frame moved the tissue"
        );
        println!(
            "LINK case=corruption frames={sent} counted={}",
            after.bad_frames - before.bad_frames
        );
    });
    step(s, "the mesh in its grid, within the byte budget", || {
        device.watch_mesh(1).unwrap();
        let mut seqs = Vec::new();
        // Ten meshes, or 20 s of the host's clock (at full speed QEMU sends 16 in 2 s).
        let end = Instant::now() + Duration::from_secs(20);
        while Instant::now() < end && seqs.len() < 10 {
            if let Some(m) = device.mesh().filter(|m| seqs.last() != Some(&m.seq)) {
                // The board's N × N patch: (N − 2)² free nodes, 2 (N − 3)² triangles.
                let inner = haptic_f405::BOARD.grid - 2;
                assert_eq!(m.nodes.len(), inner * inner);
                assert_eq!(m.triangles().len(), 2 * (inner - 1) * (inner - 1));
                seqs.push(m.seq);
            }
            std::thread::sleep(Duration::from_millis(2));
        }
        device.watch_mesh(0).unwrap();
        assert_eq!(seqs.len(), 10, "{} meshes in 20 s", seqs.len());
        println!(
            "LINK case=mesh meshes={} least_every={}",
            seqs.len(),
            device.info().hello.mesh_least_every
        );
    });
    // The board's budget model of its tick with the live tissue's substeps: what it
    // holds a tissue's check to.
    let h = device.hello().unwrap().hello;
    assert!(h.substeps >= 1, "{h:?}");
    let model = (
        h.tick_base_cost + u32::from(h.substeps) * h.substep_cost,
        h.tick_budget,
    );
    drop(device);
    step(s, "a replay equals the host's fixed replay", || {
        let args = [
            "--probe",
            "params/stroke.csv",
            "--tissue",
            "64,64",
            "--friction",
            "0.6,0.4",
        ];
        let t0 = Instant::now();
        let dev = mccs_ok(&[&["link", "--connect", &addr, "replay"][..], &args].concat()).stdout;
        let secs = t0.elapsed().as_secs_f64();
        let host = mccs_ok(
            &[
                &[
                    "replay",
                    "--params",
                    "params/table2.toml",
                    "--backend",
                    "fixed",
                ][..],
                &args,
            ]
            .concat(),
        )
        .stdout;
        assert!(
            dev == host,
            "the device's replay differs from the host's fixed replay"
        );
        let rows = dev.iter().filter(|&&b| b == b'\n').count() - 1;
        println!(
            "LINK case=replay rows={rows} seconds={secs:.1} rows_per_s={:.0}",
            rows as f64 / secs
        );
    });
    step(s, "silence fades the force within 120 ticks", || {
        silence(&addr)
    });
    step(s, "the worst tick within the board's budget model", || {
        worst_tick("arm-sim", model)
    });
    // Last: its high-water mark covers every step before. (Two 500-tick black boxes once
    // took the room a replay's start needs, and the stack overwrote the tick's statics.)
    step(s, "the stack keeps 4 KiB free above the statics", || {
        let (used, free) = stack_depth("arm-sim", "qemu-link-sim-arm");
        println!("LINK case=stack used_bytes={used} free_bytes={free}");
        assert!(free >= 4096, "the stack went {used} B deep: {free} B free");
    });
}

/// Where QEMU `name` answers QMP (its monitor's protocol).
fn qmp_socket(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("mccs-qemu-{name}-{}.qmp", std::process::id()))
}

/// A symbol's address in `elf` (rustup's `llvm-nm`, as scripts/size.py finds it).
fn symbol(elf: &Path, name: &str) -> u32 {
    let out = |c: &mut Command| String::from_utf8(c.output().unwrap().stdout).unwrap();
    let sysroot = out(Command::new("rustc").args(["--print", "sysroot"]));
    let host = out(Command::new("rustc").arg("-vV"));
    let host = host.lines().find_map(|l| l.strip_prefix("host: ")).unwrap();
    let nm = Path::new(sysroot.trim()).join(format!("lib/rustlib/{host}/bin/llvm-nm"));
    let syms = out(Command::new(nm).arg(elf));
    let line = syms
        .lines()
        .find(|l| l.split_whitespace().nth(2) == Some(name))
        .unwrap_or_else(|| panic!("no {name} in {}", elf.display()));
    u32::from_str_radix(line.split_whitespace().next().unwrap(), 16).unwrap()
}

/// How deep the board's stack has gone, and the room left above its statics, bytes: its
/// RAM read through QMP (QEMU's RAM starts zeroed; the deepest word written between the
/// end of `.bss` and the stack's top is the stack's high-water mark).
fn stack_depth(name: &str, features: &str) -> (u32, u32) {
    let elf = root().join(format!(
        "target/thumbv7em-none-eabihf/release/haptic-f405-{features}"
    ));
    let (ebss, top) = (symbol(&elf, "__ebss"), symbol(&elf, "_stack_start"));
    let dump = std::env::temp_dir().join(format!("mccs-qemu-{name}-{}.ram", std::process::id()));
    let mut qmp = std::os::unix::net::UnixStream::connect(qmp_socket(name)).unwrap();
    qmp.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    let mut reader = std::io::BufReader::new(qmp.try_clone().unwrap());
    let mut line = String::new();
    let mut ask = |cmd: serde_json::Value| {
        writeln!(qmp, "{cmd}").unwrap();
        loop {
            line.clear();
            std::io::BufRead::read_line(&mut reader, &mut line).unwrap();
            let v: serde_json::Value = serde_json::from_str(&line).unwrap();
            if v.get("return").is_some() || v.get("error").is_some() {
                assert!(v.get("error").is_none(), "QMP: {v}");
                break;
            }
        }
    };
    ask(serde_json::json!({"execute": "qmp_capabilities"}));
    ask(serde_json::json!({"execute": "pmemsave", "arguments": {
        "val": ebss, "size": top - ebss, "filename": dump.display().to_string()}}));
    let ram = std::fs::read(&dump).unwrap();
    let _ = std::fs::remove_file(&dump);
    let deepest = ram
        .chunks(4)
        .position(|w| w.iter().any(|&b| b != 0))
        .map_or(ram.len(), |i| i * 4) as u32;
    (top - ebss - deepest, deepest)
}

/// The worst tick the board logged (its once-a-second line, `worst_tick_cycles`, the
/// SysTick cycles at 168 MHz of QEMU's cycle counter) over the whole run, as
/// instructions under `-icount shift=3` (8 ns each): within the board's budget model
/// (`tick_base_cost + substeps × substep_cost`, the link's work included), and the
/// model within the budget (half a 1 kHz tick, 84,000): `(model, budget)`, the board's.
fn worst_tick(name: &str, (model, budget): (u32, u32)) {
    let log = std::fs::read_to_string(root().join(format!("target/qemu/link-{name}.log"))).unwrap();
    let cycles = log
        .lines()
        .filter_map(|l| {
            l.split("worst_tick_cycles=")
                .nth(1)?
                .split_whitespace()
                .next()?
                .parse::<u64>()
                .ok()
        })
        .max()
        .expect("the board logs its worst tick once a second");
    let instructions = cycles * 1_000_000_000 / (168_000_000 * 8);
    println!(
        "LINK case=trainer_tick n={} worst_instructions={instructions} model_instructions={model} budget={budget}",
        haptic_f405::BOARD.grid
    );
    assert!(
        instructions <= u64::from(model) && model <= budget && budget <= 84_000,
        "the worst tick took {instructions} instructions, the model {model}, the budget {budget}"
    );
}

/// A raw session: `Watch` every tick and `Arm`, frames for 300 ms, then silence with the
/// connection open: the gain reaches zero within 120 ticks of the last frame.
fn silence(addr: &str) {
    let path = addr.strip_prefix("unix:").unwrap();
    let mut s = std::os::unix::net::UnixStream::connect(Path::new(path)).unwrap();
    s.set_read_timeout(Some(Duration::from_millis(20))).unwrap();
    let send = |s: &mut std::os::unix::net::UnixStream, m: &ToDevice| {
        let mut f = [0u8; MAX_FRAME];
        s.write_all(encode(m, &mut f).unwrap()).unwrap();
    };
    let mut decoder = Decoder::new();
    let mut recv = |s: &mut std::os::unix::net::UnixStream| -> Vec<ToHost> {
        let mut b = [0u8; 4096];
        let n = s.read(&mut b).unwrap_or(0);
        let mut out = Vec::new();
        for &x in &b[..n] {
            if let Some(Ok(p)) = decoder.push(x) {
                if let Ok(m) = parse::<ToHost>(p) {
                    out.push(m);
                }
            }
        }
        out
    };
    send(&mut s, &ToDevice::Watch { every: 1 });
    send(&mut s, &ToDevice::Arm);
    let start = Instant::now();
    while start.elapsed() < Duration::from_millis(300) {
        send(&mut s, &ToDevice::Keepalive);
        recv(&mut s);
        std::thread::sleep(Duration::from_millis(10));
    }
    // The last frame: a status, whose answer says the tick the device took it on.
    send(&mut s, &ToDevice::Status);
    let deadline = Instant::now() + Duration::from_secs(20);
    let mut last_tick = None;
    let mut pending = Vec::new();
    while last_tick.is_none() {
        assert!(Instant::now() < deadline, "no status");
        for m in recv(&mut s) {
            match m {
                ToHost::Status(st) => last_tick = Some(st.ticks),
                m => pending.push(m),
            }
        }
    }
    let last_tick = last_tick.unwrap_or(0);
    let zero_at = loop {
        assert!(Instant::now() < deadline, "the gain never reached zero");
        let mut got = std::mem::take(&mut pending);
        got.extend(recv(&mut s));
        let found = got.into_iter().find_map(|m| match m {
            ToHost::Telemetry(t)
                if t.tick > last_tick && t.gain == 0 && !t.flags.contains(Flags::ARMED) =>
            {
                Some(t.tick)
            }
            _ => None,
        });
        if let Some(t) = found {
            break t;
        }
    };
    assert!(
        zero_at - last_tick <= 120,
        "zero {} ticks after the last frame",
        zero_at - last_tick
    );
    println!("LINK case=silence zero_after_ticks={}", zero_at - last_tick);
}

#[test]
fn the_simulated_lever_board_in_qemu_presses_the_tissue() {
    if !wanted() {
        return;
    }
    let s = "1dof";
    let (_qemu, addr) = start("one-dof-sim", &["--sim", "--one-dof"]);
    let device = open(&addr);
    step(s, "hello says a glued 1-DOF device", || {
        let h = device.info().hello;
        assert_eq!(
            (h.device, h.contact),
            (mccs_link::DeviceKind::OneDof, mccs_link::ContactKind::Glued)
        );
        assert_eq!((h.tissue_w, h.tissue_h), (h.grid, h.grid));
    });
    step(s, "its presses render a force along z", || {
        let rx = device.telemetry_stream();
        device.watch(10).unwrap();
        let armed = device.arm().unwrap();
        // 2,500 of the device's ticks (a sample every 10): its time, not the host's, so
        // that a QEMU slowed by other work beside it sees the same presses.
        let got = collect(&rx, Duration::from_secs(60), |g| g.len() >= 250);
        drop(armed);
        let pressed: Vec<&TelemetrySample> = got
            .iter()
            .filter(|t| t.flags.contains(Flags::CONTACT))
            .collect();
        let deepest = got
            .iter()
            .map(|t| t.probe_mm[2])
            .fold(f64::INFINITY, f64::min);
        let most = got.iter().map(|t| t.force_n[2]).fold(0.0, f64::max);
        assert!(deepest < -1.0, "the lever never pressed: {deepest} mm");
        assert!(
            most > 0.3 && pressed.len() > 50,
            "{most} N, {} pressed samples",
            pressed.len()
        );
        assert!(got.iter().all(|t| t.fault == FaultReason::None), "a fault");
        println!("LINK case=one_dof samples={} pressed={} deepest_mm={deepest:.3} most_force_n={most:.3}", got.len(), pressed.len());
    });
}

#[test]
fn a_board_whose_ticks_overrun_ends_in_its_safe_state() {
    if !wanted() {
        return;
    }
    let s = "overrun";
    // The simulated arm board at a quarter of the core's speed: every tick overruns.
    let (_qemu, addr) = start("overrun", &["--sim", "--icount-shift", "5"]);
    let device = open(&addr);
    step(s, "the run of overruns ends in the safe state", || {
        let end = Instant::now() + Duration::from_secs(60);
        let st = loop {
            let st = device.status().unwrap().raw;
            if st.fault != FaultReason::None || Instant::now() > end {
                break st;
            }
            std::thread::sleep(Duration::from_millis(200));
        };
        assert_eq!(st.fault, FaultReason::Overruns, "{st:?}");
        assert!(st.overruns >= haptic_f405::BOARD.max_overruns_in_row);
        let rx = device.telemetry_stream();
        device.watch(10).unwrap();
        let got = collect(&rx, Duration::from_secs(5), |g| g.len() > 20);
        assert!(got.iter().all(|t| t.force_n == [0.0; 3]
            && t.flags.contains(Flags::FAULT)
            && t.fault == FaultReason::Overruns));
        println!(
            "LINK case=overruns overruns={} fault={}",
            st.overruns,
            st.fault.name()
        );
    });
    let _ = scale::GAIN_FULL;
}
