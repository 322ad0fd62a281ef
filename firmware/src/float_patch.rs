//! `FloatPatch`: the patch substep in floating point (`f32` or `f64`), for the benchmark's
//! comparison with the fixed-point solver only — not used by the firmware.
//!
//! The same algorithm as [`Solver`](mccs::Solver)'s substep: per spring the length (a
//! square root here, the hardware `vsqrt.f32` on a Cortex-M4F, software elsewhere), the
//! strain, the table's cubic, the force along the edge and the relative damping; per node
//! the improved Euler step; the probe coupling on the contact node. Software floating point
//! on the M3 and M0 (and for `f64` everywhere).

use mccs::units::{to_f64, DIR_FRAC, FORCE_FRAC, STRAIN_FRAC};
use mccs::{ForceTable, SolverConfig, Topology};

/// The arithmetic the float patch needs.
pub trait Real:
    Copy
    + PartialOrd
    + core::ops::Add<Output = Self>
    + core::ops::Sub<Output = Self>
    + core::ops::Mul<Output = Self>
    + core::ops::Div<Output = Self>
    + core::ops::Neg<Output = Self>
{
    /// Zero.
    const ZERO: Self;
    /// From an `f64`.
    fn of(x: f64) -> Self;
    /// Square root.
    fn sqrt(self) -> Self;
    /// `self` truncated to an index (`self ≥ 0`).
    fn index(self) -> usize;
    /// An index as a value.
    fn from_index(i: usize) -> Self;
}

/// `Real` for a primitive float, its square root given as a function.
macro_rules! real {
    ($t:ty, $sqrt:expr) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            fn of(x: f64) -> Self {
                x as $t
            }
            #[inline(always)]
            fn index(self) -> usize {
                self as usize
            }
            #[inline(always)]
            fn from_index(i: usize) -> Self {
                i as $t
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                $sqrt(self)
            }
        }
    };
}

real!(f32, sqrt_f32);
real!(f64, libm::sqrt);

#[inline(always)]
fn sqrt_f32(x: f32) -> f32 {
    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    {
        vsqrt(x)
    }
    #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
    {
        libm::sqrtf(x)
    }
}

// The M4F's hardware square root (`libm::sqrtf` is software on thumbv7em). Floats pass in
// `s0` under the eabihf calling convention.
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
core::arch::global_asm!(
    ".fpu fpv4-sp-d16",
    ".section .text.mccs_vsqrtf,\"ax\",%progbits",
    ".global mccs_vsqrtf",
    ".type mccs_vsqrtf,%function",
    ".thumb_func",
    "mccs_vsqrtf:",
    "vsqrt.f32 s0, s0",
    "bx lr",
);

#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
unsafe extern "C" {
    fn mccs_vsqrtf(x: f32) -> f32;
}

#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
fn vsqrt(x: f32) -> f32 {
    // SAFETY: the Cortex-M4F (eabihf: this cfg) has the single-precision FPU the function
    // above needs; it reads s0 and returns in s0, nothing else.
    unsafe { mccs_vsqrtf(x) }
}

#[derive(Clone, Copy)]
struct Spring<T> {
    a: u16,
    b: u16,
    rest: [T; 3],
    l0: T,
    inv_l0: T,
}

/// The patch in floating point; `N` node slots (ground included), `E` springs, `S`
/// table segments.
pub struct FloatPatch<T, const N: usize, const E: usize, const S: usize> {
    springs: [Spring<T>; E],
    n_springs: usize,
    n_nodes: usize,
    contact: usize,
    /// Per segment `[c0, c1, c2, c3]` in N.
    seg: [[T; 4]; S],
    strain_lo: T,
    strain_hi: T,
    per_strain: T,
    k_lo: T,
    f_lo: T,
    k_hi: T,
    f_hi: T,
    /// `h/m`, `h/2`, damping (N·s/mm), coupling (N/mm, N·s/mm, N).
    hm: T,
    half_h: T,
    c_spring: T,
    c_node: T,
    kc: T,
    bc: T,
    fmax: T,
    x: [[T; 3]; N],
    v: [[T; 3]; N],
    f: [[T; 3]; N],
}

impl<T: Real, const N: usize, const E: usize, const S: usize> FloatPatch<T, N, E, S> {
    /// From a topology, a table and a configuration at `substeps` per tick. The table's
    /// uniform part and lines only: a table with a graded corner (`ForceTable::corner`)
    /// is not modelled (the bench runs Table 2's, which has none).
    pub fn new(
        topo: &Topology<N, E>,
        table: &ForceTable<S>,
        cfg: &SolverConfig,
        substeps: u32,
    ) -> Self {
        let raw = table.raw();
        let h = 1.0 / (cfg.tick_hz * substeps as f64);
        // The line below's slope as its force uses it (`RawTable::slope_lo`).
        let k_lo = to_f64(raw.slope_lo, raw.slope_lo_frac());
        // And the line above's (`RawTable::slope_hi`).
        let k_hi = to_f64(raw.slope_hi, raw.slope_hi_frac());
        // The fixed-point lines floor their product, and the builder puts half a Q20 LSB
        // into their anchors so that the floor rounds (`mccs::table`, `rounding_anchor`):
        // the line in float is the floor's argument less that half.
        let half_lsb = 0.5 / (1u64 << FORCE_FRAC) as f64;
        // The springs and the segments are filled in place (built apart and moved in,
        // their copies overflowed the M0's 16 KiB of stack in the f64 bench case).
        let mut patch = Self {
            springs: [Spring {
                a: 0,
                b: 0,
                rest: [T::ZERO; 3],
                l0: T::ZERO,
                inv_l0: T::ZERO,
            }; E],
            n_springs: topo.edges().len(),
            n_nodes: topo.node_count(),
            contact: topo.contact() as usize,
            seg: [[T::ZERO; 4]; S],
            strain_lo: T::of(to_f64(raw.strain_lo, STRAIN_FRAC)),
            strain_hi: T::of(to_f64(raw.strain_hi, STRAIN_FRAC)),
            per_strain: T::of(raw.index_scale as f64 * raw.index_pre as f64 / (1u64 << 23) as f64),
            k_lo: T::of(k_lo),
            f_lo: T::of(
                to_f64(raw.force_lo, FORCE_FRAC)
                    - half_lsb
                    - k_lo * to_f64(raw.anchor_lo, STRAIN_FRAC),
            ),
            k_hi: T::of(k_hi),
            f_hi: T::of(
                to_f64(raw.force_hi, FORCE_FRAC)
                    - half_lsb
                    - k_hi * to_f64(raw.strain_hi, STRAIN_FRAC),
            ),
            hm: T::of(1000.0 * h / cfg.node_mass),
            half_h: T::of(0.5 * h),
            c_spring: T::of(cfg.spring_damping / 1000.0),
            c_node: T::of(cfg.node_damping / 1000.0),
            kc: T::of(cfg.coupling.stiffness),
            bc: T::of(cfg.coupling.damping / 1000.0),
            fmax: T::of(cfg.coupling.max_force),
            x: [[T::ZERO; 3]; N],
            v: [[T::ZERO; 3]; N],
            f: [[T::ZERO; 3]; N],
        };
        patch.fill_springs(topo);
        patch.fill_segments(table);
        patch
    }

    /// The table's cubic segments in float: C0 … C3 carry 1, 2, 4, 8 times c0 … c3, in
    /// Q(20 + shift) N; C0 less the knots' rounding bias (`mccs::table::knot_bias`).
    fn fill_segments(&mut self, table: &ForceTable<S>) {
        let raw = table.raw();
        let unit = (1u64 << (FORCE_FRAC + raw.shift)) as f64;
        let bias = mccs::table::knot_bias(raw.shift) as f64;
        for (s, c) in self.seg.iter_mut().zip(raw.segments.iter()) {
            *s = core::array::from_fn(|j| {
                let v = if j == 0 {
                    c[0] as f64 - bias
                } else {
                    c[j] as f64
                };
                T::of(v / unit / (1u32 << j) as f64)
            });
        }
    }

    /// The topology's springs: ends, rest vector, rest length and its inverse.
    fn fill_springs(&mut self, topo: &Topology<N, E>) {
        for (s, e) in self.springs.iter_mut().zip(topo.edges()) {
            let l0 = Topology::<N, E>::rest_length(e);
            *s = Spring {
                a: e.a,
                b: e.b,
                rest: e.dir.map(|d| T::of(to_f64(d, DIR_FRAC) * l0)),
                l0: T::of(l0),
                inv_l0: T::of(1.0 / l0),
            };
        }
    }

    #[inline(always)]
    fn force(&self, e: T) -> T {
        if e <= self.strain_lo {
            return self.f_lo + self.k_lo * e;
        }
        if e >= self.strain_hi {
            return self.f_hi + self.k_hi * e;
        }
        let u = (e - self.strain_lo) * self.per_strain;
        let i = u.index().min(S - 1);
        let t = u - T::from_index(i);
        let c = self.seg[i];
        c[0] + t * (c[1] + t * (c[2] + t * c[3]))
    }

    /// One substep with the probe at `probe` (mm, patch frame, not moving).
    pub fn substep(&mut self, probe: [T; 3]) {
        self.f = [[T::ZERO; 3]; N];
        for k in 0..self.n_springs.min(E) {
            let s = self.springs[k];
            let (a, b) = (s.a as usize % N, s.b as usize % N);
            let d: [T; 3] = core::array::from_fn(|j| s.rest[j] + self.x[b][j] - self.x[a][j]);
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let strain = (s.l0 - l) * s.inv_l0;
            let fl = self.force(strain);
            let g = if l > T::ZERO { fl / l } else { T::ZERO };
            for j in 0..3 {
                let on_a = self.c_spring * (self.v[b][j] - self.v[a][j]) - g * d[j];
                self.f[a][j] = self.f[a][j] + on_a;
                self.f[b][j] = self.f[b][j] - on_a;
            }
        }
        let c = self.contact % N;
        if probe[2] < self.x[c][2] {
            for j in 0..3 {
                let mut fc = self.kc * (probe[j] - self.x[c][j]) - self.bc * self.v[c][j];
                if fc > self.fmax {
                    fc = self.fmax;
                }
                if fc < -self.fmax {
                    fc = -self.fmax;
                }
                self.f[c][j] = self.f[c][j] + fc;
            }
        }
        for i in 1..self.n_nodes.min(N) {
            for j in 0..3 {
                let net = self.f[i][j] - self.c_node * self.v[i][j];
                let v_new = self.v[i][j] + self.hm * net;
                self.x[i][j] = self.x[i][j] + self.half_h * (self.v[i][j] + v_new);
                self.v[i][j] = v_new;
            }
        }
    }

    /// The contact node's displacement (for checks).
    pub fn contact_displacement(&self) -> [T; 3] {
        self.x[self.contact % N]
    }
}
