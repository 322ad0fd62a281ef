//! The arm's counts-to-duties chain in `f32` with `micromath`'s `sin`/`cos` (its own
//! approximations, within about 1e-3 of the true values: `micromath` documents them), the
//! peer the bench measures the fixed-point chain against (`case=arm_kinematics_f32`).
//! Not used by any device: the product's chain is the core's [`mccs::Arm`].

use mccs::ArmSpec;
use micromath::F32Ext;

/// The chain's constants in `f32`, the divisions folded in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArmF32 {
    rad_per_count: [f32; 3],
    home: [(f32, i32); 3],
    base: f32,
    upper: f32,
    fore: f32,
    origin: [f32; 3],
    gravity_b: f32,
    gravity_c: f32,
    duty_per_nmm: [f32; 3],
}

impl ArmF32 {
    /// From a spec (start-up code).
    pub fn new(spec: &ArmSpec) -> Self {
        let g = spec.gravity.unwrap_or(mccs::GravitySpec::NONE);
        let j = &spec.joints;
        ArmF32 {
            rad_per_count: core::array::from_fn(|k| {
                (j[k].sign * 2.0 * core::f64::consts::PI / (j[k].counts_per_rev * j[k].ratio))
                    as f32
            }),
            home: core::array::from_fn(|k| {
                (
                    (j[k].home_angle_deg * core::f64::consts::PI / 180.0) as f32,
                    j[k].home_count,
                )
            }),
            base: spec.base_height_mm as f32,
            upper: spec.upper_arm_mm as f32,
            fore: spec.forearm_mm as f32,
            origin: spec.tissue_origin_mm.map(|v| v as f32),
            gravity_b: (g.g
                * (g.upper_arm_mass_kg * g.upper_arm_com_mm
                    + g.forearm_mass_kg * spec.upper_arm_mm)) as f32,
            gravity_c: (g.g * g.forearm_mass_kg * g.forearm_com_mm) as f32,
            duty_per_nmm: core::array::from_fn(|k| {
                (j[k].sign
                    / (j[k].ratio * j[k].torque_constant_nm_per_a * j[k].max_current_a * 1000.0))
                    as f32
            }),
        }
    }

    /// Counts and a force (N) to the probe in the tissue's frame (mm) and the duties
    /// (±1, scaled alike when any would pass 1).
    pub fn chain(&self, counts: [i32; 3], force: [f32; 3]) -> ([f32; 3], [f32; 3]) {
        let t: [f32; 3] = core::array::from_fn(|k| {
            self.home[k].0 + (counts[k].wrapping_sub(self.home[k].1)) as f32 * self.rad_per_count[k]
        });
        // micromath's, on the host too (where `f32` has its own).
        let sc_of = |x: f32| (F32Ext::sin(x), F32Ext::cos(x));
        let (sa, ca) = sc_of(t[0]);
        let (sb, cb) = sc_of(t[1]);
        let (sc, cc) = sc_of(t[2]);
        let r = self.upper * sb + self.fore * sc;
        let p = [
            r * ca - self.origin[0],
            r * sa - self.origin[1],
            self.base + self.upper * cb - self.fore * cc - self.origin[2],
        ];
        let u = ca * force[0] + sa * force[1];
        let v = ca * force[1] - sa * force[0];
        let tau = [
            r * v,
            self.upper * (cb * u - sb * force[2]) - self.gravity_b * sb,
            self.fore * (cc * u + sc * force[2]) + self.gravity_c * sc,
        ];
        let mut d: [f32; 3] = core::array::from_fn(|k| tau[k] * self.duty_per_nmm[k]);
        let most = F32Ext::abs(d[0])
            .max(F32Ext::abs(d[1]))
            .max(F32Ext::abs(d[2]));
        if most > 1.0 {
            let s = 1.0 / most;
            d = d.map(|x| x * s);
        }
        (p, d)
    }
}
