//! The host link (`mccs-link`, docs/link.md): its codec here; the device's side of it in
//! `device.rs`; the firmware in QEMU behind `mccs link` in `qemu.rs`.

mod cli;
mod codec;
mod device;
mod qemu;

/// `mccs link mesh`'s CSV on `topo`'s patch: each mesh by its `seq` as its tick and its
/// nodes in order, and the farthest any node was from its rest position, mm. One mesh,
/// one tick (asserted).
fn meshes<const N: usize, const E: usize>(
    csv: &str,
    topo: &mccs::Topology<N, E>,
) -> (std::collections::BTreeMap<u32, (u32, Vec<usize>)>, f64) {
    let mut meshes: std::collections::BTreeMap<u32, (u32, Vec<usize>)> = Default::default();
    let mut worst = 0.0f64;
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("seq,tick,node,x_mm,y_mm,z_mm"));
    for l in lines {
        let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        let (seq, tick, node) = (v[0] as u32, v[1] as u32, v[2] as usize);
        let rest = topo.rest(node as u16 + 1).unwrap();
        for k in 0..3 {
            worst = worst.max((v[3 + k] - rest[k]).abs());
        }
        let e = meshes.entry(seq).or_insert((tick, Vec::new()));
        assert_eq!(e.0, tick, "{l}: one mesh, one tick");
        e.1.push(node);
    }
    (meshes, worst)
}
