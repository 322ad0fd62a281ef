//! The state of the patch's nodes, as the per-tick arithmetic reads and writes it, and
//! the loop that hands each spring its two ends.
//!
//! Formats: displacement from rest in mm ([`crate::units::LEN_FRAC`], held within
//! ±[`DISP_LIMIT`]); velocity as the arithmetic stores it (mm/s in Q16 for
//! [`crate::arith::Wide`], `C_v v` in N for [`crate::arith::Narrow`]), held within the
//! equivalent of ±16384 mm/s; the force accumulator of the current substep in N
//! ([`crate::units::FORCE_FRAC`]).

use crate::q::V3;
use crate::topology::{Edge, Topology, GROUND};

/// Largest displacement from rest, mm in Q24: just under 64 mm.
pub const DISP_LIMIT: i32 = 1 << DISP_LIMIT_BITS;
/// [`DISP_LIMIT`] as a power of two.
pub const DISP_LIMIT_BITS: u32 = 30;
/// Largest speed, mm/s in Q16: just under 16384 mm/s.
pub const VEL_LIMIT: i32 = 1 << 30;
/// [`VEL_LIMIT`] in mm/s.
pub const VEL_LIMIT_MM_S: f64 = 16384.0;

/// One node's state: displacement from rest, stored velocity and the force accumulator of
/// the current substep, together so that a spring reaches all of an end through one
/// address. In declaration order (`repr(C)`, 36 bytes: the ARMv7E-M spring loop reads
/// it by offset, `arith/wide_dsp/`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C)]
pub struct Node {
    /// Displacement from rest, Q24 mm.
    pub u: V3,
    /// Velocity as the arithmetic stores it.
    pub v: V3,
    /// Force accumulator, Q20 N.
    pub f: V3,
}

impl Node {
    /// At rest, no force.
    pub const ZERO: Self = Self {
        u: [0; 3],
        v: [0; 3],
        f: [0; 3],
    };
}

/// Both ends of one spring as the arithmetic reads them: displacements (Q24 mm) and
/// stored velocities. A fixed end (the ground) is at rest.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SpringEnds {
    /// Displacement of end `a`.
    pub ua: V3,
    /// Displacement of end `b`.
    pub ub: V3,
    /// Velocity of end `a`.
    pub va: V3,
    /// Velocity of end `b`.
    pub vb: V3,
}

/// Both ends of one spring as the kernels take them: displacements by value, velocities
/// by reference (read late, so that they are not held in registers across the table
/// lookup).
#[derive(Clone, Copy, Debug)]
pub struct Ends<'a> {
    /// Displacement of end `a`.
    pub ua: V3,
    /// Displacement of end `b`.
    pub ub: V3,
    /// Velocity of end `a`.
    pub va: &'a V3,
    /// Velocity of end `b`.
    pub vb: &'a V3,
}

impl<'a> Ends<'a> {
    /// The ends of a spring between `na` and `nb` (`None`: the ground, at rest).
    #[inline(always)]
    pub fn of(na: &'a Node, nb: Option<&'a Node>) -> Self {
        const REST: V3 = [0; 3];
        match nb {
            Some(nb) => Self {
                ua: na.u,
                ub: nb.u,
                va: &na.v,
                vb: &nb.v,
            },
            None => Self {
                ua: na.u,
                ub: [0; 3],
                va: &na.v,
                vb: &REST,
            },
        }
    }
}

impl<'a> From<&'a SpringEnds> for Ends<'a> {
    #[inline(always)]
    fn from(e: &'a SpringEnds) -> Self {
        Self {
            ua: e.ua,
            ub: e.ub,
            va: &e.va,
            vb: &e.vb,
        }
    }
}

/// One spring's force as the loop of [`for_each_spring`] calls it (a trait with an
/// always-inlined method rather than a closure, whose inlining the compiler would be
/// free to refuse: the loop must be one function).
pub(crate) trait SpringKernel {
    /// The force on end `a` (Q20 N); advances the spring's warm-start value `warm`.
    fn force(&self, edge: &Edge, ends: Ends<'_>, warm: &mut i32) -> V3;
}

/// Runs `kernel` on every spring of `topo` and accumulates its result, the force on end
/// `a` (Q20 N), on `a` and, negated, on `b`. `warm` holds one value per spring, advanced
/// by `force`. A spring to a fixed point has the ground as `b` (the topology sees to it):
/// its branch reads no second node and writes only `a`.
#[inline(always)]
#[allow(unsafe_code)]
pub(crate) fn for_each_spring<const NODES: usize, const EDGES: usize>(
    topo: &Topology<NODES, EDGES>,
    warm: &mut [i32; EDGES],
    nodes: &mut [Node; NODES],
    kernel: &impl SpringKernel,
) {
    let base = nodes.as_mut_ptr();
    for (e, w) in topo.edges().iter().zip(warm.iter_mut()) {
        // SAFETY: a `Topology<NODES, _>` holds at most NODES node slots, and its edges'
        // ends are written only by `Topology::add_edge` (its edges are private; the one
        // way to change an edge afterwards, `Topology::rest_geometry`, sets no end),
        // which stores only indices of existing slots, never the ground as `a`, and never
        // `a == b` (that spring would be shorter than 1 mm). So both pointers are in bounds
        // of the exclusively borrowed `nodes` and point at different nodes. The shared
        // references to the ends end with the call to the kernel, before the accumulators
        // are written.
        let f_on_a = unsafe {
            let na = &*base.add(e.a as usize);
            if e.b == GROUND {
                kernel.force(e, Ends::of(na, None), w)
            } else {
                let f = kernel.force(e, Ends::of(na, Some(&*base.add(e.b as usize))), w);
                // At most MAX_SPRINGS_PER_NODE springs of ≤ 64 N each: the sums fit.
                let fb = &mut (*base.add(e.b as usize)).f;
                *fb = core::array::from_fn(|k| fb[k].wrapping_sub(f[k]));
                f
            }
        };
        // SAFETY: as above; no other reference into `nodes` is live here.
        let fa = unsafe { &mut (*base.add(e.a as usize)).f };
        *fa = core::array::from_fn(|k| fa[k].wrapping_add(f_on_a[k]));
    }
}

/// [`for_each_spring`] over slices, out of line and with checked indices: one copy per
/// kernel whatever the topology's size, for a loop that is rarely run (a table with a
/// lower corner, [`crate::ForceTable::lower_corner`]: inlined into every patch size, its
/// copies overflowed the M3 bench's flash). The same results, the same order; a spring
/// whose node is not in `nodes` (never, for a topology's edges and its own nodes) is
/// skipped.
#[inline(never)]
pub(crate) fn for_each_spring_checked(
    edges: &[Edge],
    warm: &mut [i32],
    nodes: &mut [Node],
    kernel: &impl SpringKernel,
) {
    for (e, w) in edges.iter().zip(warm.iter_mut()) {
        let (a, b) = (e.a as usize, e.b as usize);
        let grounded = e.b == GROUND;
        let f = {
            let (Some(na), nb) = (nodes.get(a), nodes.get(b)) else {
                continue;
            };
            match (grounded, nb) {
                (true, _) => kernel.force(e, Ends::of(na, None), w),
                (false, Some(nb)) => kernel.force(e, Ends::of(na, Some(nb)), w),
                (false, None) => continue,
            }
        };
        if !grounded {
            if let Some(nb) = nodes.get_mut(b) {
                nb.f = core::array::from_fn(|k| nb.f[k].wrapping_sub(f[k]));
            }
        }
        if let Some(na) = nodes.get_mut(a) {
            na.f = core::array::from_fn(|k| na.f[k].wrapping_add(f[k]));
        }
    }
}
