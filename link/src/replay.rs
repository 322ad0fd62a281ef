//! A replay, both ways: the patch and solver a host asks for ([`ReplaySpec`]), the probe
//! path it streams ([`PathPoint`]: 12 bytes a tick), and the rows the device answers
//! ([`ReplayRow`], with its flags); and one replay tick in the fixed-point core, the same
//! code for `mccs replay --backend fixed` on the host and `mccs link replay` on the
//! device, so that the two print the same rows.

use mccs::{Arith, Length, Proxy, Shape, Solver, Window};
use postcard_schema::Schema;
use serde::{Deserialize, Serialize};

/// Bit 0 of [`ReplayRow::flags`]: in contact.
pub const CONTACT: u8 = 1;
/// Bit 1: slipping.
pub const SLIPPING: u8 = 2;
/// Bit 2: `point` holds the proxy.
pub const PROXY: u8 = 4;

/// A replay tick's raw outputs; the host prints them as `mccs replay` does.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ReplayRow {
    /// The tick (0: the path's first sample).
    pub tick: u32,
    /// The device force, Q20 N.
    pub force: [i32; 3],
    /// Glued: the contact node's displacement; roaming: the proxy point in the window's
    /// frame (when [`PROXY`] is set), Q24 mm.
    pub point: [i32; 3],
    /// Roaming: the window's origin, Q24 mm.
    pub origin: [i32; 2],
    /// The displacement of the node that moved most, Q24 mm.
    pub max_disp: [i32; 3],
    /// [`CONTACT`], [`SLIPPING`], [`PROXY`].
    pub flags: u8,
    /// Roaming: the window's shifts so far.
    pub shifts: u32,
}

/// The patch and solver of a replay: `mccs replay`'s options.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq)]
pub struct ReplaySpec {
    /// `--grid`.
    pub grid: u8,
    /// `--spacing`, mm.
    pub spacing_mm: f64,
    /// `--rate`, Hz.
    pub tick_hz: f64,
    /// `--node-mass`, kg.
    pub node_mass_kg: f64,
    /// `--spring-damping`, N·s/m.
    pub spring_damping: f64,
    /// `--coupling-stiffness`, N/mm.
    pub coupling_stiffness: f64,
    /// `--coupling-damping`, N·s/m.
    pub coupling_damping: f64,
    /// `--max-force`, N.
    pub max_force: f64,
    /// `--integrator symplectic-damped`.
    pub symplectic: bool,
    /// `--arith narrow`.
    pub narrow: bool,
    /// Path samples (ticks) to come.
    pub samples: u32,
    /// The first sample's `x, y`, mm, as the host read it: where a roaming window
    /// starts (the host's own replay starts it there, before any rounding).
    pub start: [f64; 2],
    /// `--tissue` and its options.
    pub roaming: Option<RoamSpec>,
}

/// A roaming replay's tissue, friction and probe.
#[derive(Serialize, Deserialize, Schema, Clone, Copy, Debug, PartialEq)]
pub struct RoamSpec {
    /// Tissue nodes along `x`.
    pub tissue_w: u8,
    /// Tissue nodes along `y`.
    pub tissue_h: u8,
    /// Static friction.
    pub mu_s: f64,
    /// Kinetic friction.
    pub mu_k: f64,
    /// Probe radius, mm.
    pub probe_radius: f64,
    /// A spherical cap's radius, mm (none: flat).
    pub cap_radius: Option<f64>,
}

/// One probe position of a replay's path: `x, y, z`, Q24 mm, each an `i32`
/// little-endian (12 bytes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PathPoint(pub [i32; 3]);

impl PathPoint {
    /// Bytes a point takes.
    pub const BYTES: usize = 12;
    /// The most points one [`crate::ToDevice::ReplayPath`] carries (its frame stays
    /// within [`crate::MAX_FRAME`]).
    pub const PER_FRAME: usize = 16;

    /// Its bytes.
    pub fn to_bytes(self) -> [u8; 12] {
        let mut out = [0u8; 12];
        for (slot, c) in out.chunks_exact_mut(4).zip(self.0) {
            slot.copy_from_slice(&c.to_le_bytes());
        }
        out
    }

    /// The point in 12 bytes.
    pub fn from_bytes(b: &[u8; 12]) -> PathPoint {
        let w = |i: usize| i32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
        PathPoint([w(0), w(4), w(8)])
    }

    /// The points in `bytes` (a whole number of them), or `None`.
    pub fn all(bytes: &[u8]) -> Option<impl Iterator<Item = PathPoint> + '_> {
        bytes.len().is_multiple_of(Self::BYTES).then(|| {
            bytes.chunks_exact(Self::BYTES).map(|c| {
                let mut b = [0u8; 12];
                b.copy_from_slice(c);
                PathPoint::from_bytes(&b)
            })
        })
    }
}

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
