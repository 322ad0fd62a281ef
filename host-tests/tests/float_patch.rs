//! The benchmark's floating-point comparator computes the same patch as the fixed-point
//! solver (else its instruction counts would compare different work).

use mccs::{ForceTable64, Length, Params, Solver, SolverConfig, Topology};
use mccs_firmware::float_patch::FloatPatch;

#[test]
fn float_comparators_track_the_fixed_point_solver() {
    let table = ForceTable64::new(&Params::TABLE2).unwrap();
    let cfg = SolverConfig::default();
    let topo = Topology::<10, 61>::standard_patch(5, 2.5).unwrap();
    let mut fixed = Solver::new(topo.clone(), table, &cfg).unwrap();
    let n = fixed.substeps();
    let mut f64p = FloatPatch::<f64, 10, 61, 64>::new(&topo, &table, &cfg, n);
    let mut f32p = FloatPatch::<f32, 10, 61, 64>::new(&topo, &table, &cfg, n);
    let probe = [Length::ZERO, Length::ZERO, Length::from_num(-0.5)];
    for _ in 0..300 * n {
        fixed.substep_probe(probe);
        f64p.substep([0.0, 0.0, -0.5]);
        f32p.substep([0.0, 0.0, -0.5]);
    }
    let z = fixed.displacement(topo.contact()).unwrap()[2].to_num::<f64>();
    let z64 = f64p.contact_displacement()[2];
    let z32 = f32p.contact_displacement()[2] as f64;
    assert!(z < -0.1, "pressed in: {z}");
    assert!((z64 - z).abs() < 1e-4 * z.abs(), "f64 {z64} vs fixed {z}");
    assert!((z32 - z).abs() < 1e-3 * z.abs(), "f32 {z32} vs fixed {z}");
}
