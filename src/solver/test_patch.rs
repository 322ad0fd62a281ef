//! The unit tests' patch: the N = 5 standard patch at 2.5 mm, Table 2, default
//! configuration, and a frictionless point proxy on it.

use crate::{ForceTable64, Params, Proxy, ProxyConfig, Solver, SolverConfig, Topology};

/// A Table 2 solver on `topo` (N = 5 at 2.5 mm) and a frictionless point proxy.
pub(super) fn patch_and_proxy(topo: Topology<10, 61>) -> (Solver<10, 61, 64>, Proxy) {
    let table = ForceTable64::new(&Params::TABLE2).unwrap();
    let s = Solver::<10, 61, 64>::new(topo, table, &SolverConfig::default()).unwrap();
    let config = ProxyConfig {
        grid: 5,
        spacing: 2.5,
        mu_s: 0.0,
        mu_k: 0.0,
        probe_radius: 0.0,
    };
    let proxy = s.proxy(&config).unwrap();
    (s, proxy)
}
