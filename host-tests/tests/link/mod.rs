//! The host link (`mccs-link`, docs/link.md): its codec here; the device's side of it in
//! `device.rs` (its force gain over arbitrary runs in `guard.rs`, the whole device over
//! arbitrary runs of the link in `any_run.rs`; how a replay ends when its host does not see
//! it through in `replay_ends.rs`); the firmware in QEMU behind `mccs link`
//! in `qemu.rs`.

mod any_run;
mod cli;
mod codec;
mod device;
mod guard;
mod messages;
mod qemu;
mod replay_ends;
mod replies;
mod rig;
mod scene_api;

/// `mccs link --connect ADDR mesh --seconds S --every 1` on a device whose live patch is
/// the standard one of `grid`: each mesh by its `seq`, as its tick and its nodes in
/// order, the deepest any node was (mm, its `z`), and the free nodes. Held here, for
/// every device: one mesh, one tick; every mesh but the last (which the run's end may
/// cut) has every free node once, in order, each in its place of the surface grid;
/// meshes at least `least_every` ticks apart (the link's byte budget).
fn mesh_run(addr: &str, seconds: &str, grid: usize, least_every: u32) -> (Meshes, f64, usize) {
    let out = crate::cli::mccs_ok(&[
        "link",
        "--connect",
        addr,
        "mesh",
        "--seconds",
        seconds,
        "--every",
        "1",
    ]);
    let csv = String::from_utf8(out.stdout).unwrap();
    let inner = grid - 2;
    let free = inner * inner;
    let mut meshes = Meshes::default();
    let mut deepest = 0.0f64;
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("seq,tick,node,i,j,x_mm,y_mm,z_mm"));
    for l in lines {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        let (seq, tick, node) = (v[0] as u32, v[1] as u32, v[2] as usize);
        assert_eq!(
            (v[3] as usize, v[4] as usize),
            (1 + node / inner, 1 + node % inner),
            "{l}"
        );
        deepest = deepest.min(v[7]);
        let e = meshes.entry(seq).or_insert((tick, Vec::new()));
        assert_eq!(e.0, tick, "{l}: one mesh, one tick");
        e.1.push(node);
    }
    for (seq, (_, nodes)) in meshes.iter().take(meshes.len().saturating_sub(1)) {
        assert_eq!(
            *nodes,
            (0..free).collect::<Vec<_>>(),
            "mesh {seq} without every node"
        );
    }
    let ticks: Vec<u32> = meshes.values().map(|(t, _)| *t).collect();
    assert!(
        ticks.windows(2).all(|w| w[1] - w[0] >= least_every),
        "closer than {least_every} ticks: {ticks:?}"
    );
    (meshes, -deepest, free)
}

/// Meshes by `seq`: their tick and their nodes.
type Meshes = std::collections::BTreeMap<u32, (u32, Vec<usize>)>;
