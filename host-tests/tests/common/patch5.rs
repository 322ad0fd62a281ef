//! The N = 5 standard patch at 2.5 mm, Table 2, default configuration, and its proxy:
//! what `proxy.rs` and `cap.rs` drive.

use std::any::Any;
use std::cell::RefCell;

use mccs::{Arith, ForceTable64, Params, ProxyConfig, Solver, SolverConfig, Topology};

/// The patch's side.
pub const N: usize = 5;
/// Its spacing, mm.
pub const SPACING: f64 = 2.5;
/// The solver of that patch in arithmetic `A`.
pub type Fixed<A> = Solver<10, 61, 64, A>;

/// The patch's solver at rest: built once per arithmetic and test thread, then cloned
/// (the build, whose stability estimate is most of its time, is deterministic, and the
/// property tests start from rest a few thousand times).
pub fn fixed<A: Arith>() -> Fixed<A> {
    thread_local! {
        static BUILT: RefCell<Vec<Box<dyn Any>>> = const { RefCell::new(Vec::new()) };
    }
    BUILT.with_borrow_mut(|built| {
        if let Some(s) = built.iter().find_map(|b| b.downcast_ref::<Fixed<A>>()) {
            return s.clone();
        }
        let s = build::<A>();
        built.push(Box::new(s.clone()));
        s
    })
}

/// The patch's solver at rest, built.
pub fn build<A: Arith>() -> Fixed<A> {
    let topo = Topology::standard_patch(N, SPACING).unwrap();
    let table = ForceTable64::new(&Params::TABLE2).unwrap();
    Solver::with_arith(topo, table, &SolverConfig::default(), A::default()).unwrap()
}

/// The proxy configuration of the patch with friction `mu` and probe radius `radius`.
pub fn proxy_config(mu: (f64, f64), radius: f64) -> ProxyConfig {
    ProxyConfig {
        grid: N,
        spacing: SPACING,
        mu_s: mu.0,
        mu_k: mu.1,
        probe_radius: radius,
    }
}

/// The default device maximum as the core holds it (N), with a hair for the `f64`
/// magnitude's rounding.
pub fn device_max() -> f64 {
    mccs::Force::from_num(SolverConfig::default().coupling.max_force).to_num::<f64>() + 1e-12
}
