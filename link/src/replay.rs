//! One tick of a replay in the fixed-point core, as [`ReplayRow`]'s raw values: the same
//! code for `mccs replay --backend fixed` on the host and `mccs link replay` on the
//! device, so that the two print the same rows.

use crate::message::ReplayRow;
use mccs::{Arith, Length, Proxy, Shape, Solver, Window};

/// Bit 0 of [`ReplayRow::flags`]: in contact.
pub const CONTACT: u8 = 1;
/// Bit 1: slipping.
pub const SLIPPING: u8 = 2;
/// Bit 2: `point` holds the proxy.
pub const PROXY: u8 = 4;

/// The displacement of the free node (`1 … nodes − 1`) that moved most: the largest
/// exact squared length (`i64` of the raw bits), the first on a tie.
pub fn max_displacement<const N: usize, const E: usize, const S: usize, A: Arith>(
    s: &Solver<N, E, S, A>,
) -> [i32; 3] {
    let nodes = s.topology().node_count() as u16;
    let mut best = ([0i32; 3], -1i64);
    for i in 1..nodes {
        if let Some(d) = s.displacement(i) {
            let b = d.map(|c| c.to_bits());
            let sq: i64 = b.iter().map(|&c| c as i64 * c as i64).sum();
            if sq > best.1 {
                best = (b, sq);
            }
        }
    }
    best.0
}

/// A glued tick: the probe at `probe` (Q24 mm) on the standard patch.
pub fn glued<const N: usize, const E: usize, const S: usize, A: Arith>(
    s: &mut Solver<N, E, S, A>,
    tick: u32,
    probe: [Length; 3],
) -> ReplayRow {
    let f = s.step(probe);
    let contact = s.topology().contact();
    ReplayRow {
        tick,
        force: f.map(|c| c.to_bits()),
        point: s
            .displacement(contact)
            .map_or([0; 3], |d| d.map(|c| c.to_bits())),
        origin: [0; 2],
        max_disp: max_displacement(s),
        flags: 0,
        shifts: 0,
    }
}

/// A roaming tick: the probe at `probe` (Q24 mm, the tissue's frame) on a window of the
/// tissue.
pub fn roaming<const N: usize, const E: usize, const S: usize, A: Arith, Sh: Shape>(
    s: &mut Solver<N, E, S, A>,
    proxy: &mut Proxy,
    window: &mut Window<E, Sh>,
    tick: u32,
    probe: [Length; 3],
) -> ReplayRow {
    let f = s.step_roaming(probe, proxy, window);
    let point = s.proxy_point_in(proxy, window);
    let mut flags = 0;
    if proxy.grid_position().is_some() {
        flags |= CONTACT;
    }
    if proxy.slipping() {
        flags |= SLIPPING;
    }
    if point.is_some() {
        flags |= PROXY;
    }
    ReplayRow {
        tick,
        force: f.map(|c| c.to_bits()),
        point: point.map_or([0; 3], |q| q.map(|c| c.to_bits())),
        origin: window.origin_mm().map(|c| c.to_bits()),
        max_disp: max_displacement(s),
        flags,
        shifts: window.shifts(),
    }
}
