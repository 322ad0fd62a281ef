//! Gravity from static poses (`mccs arm calibrate`, docs/arm.md): the arm held still at
//! poses across its workspace, each with the duties that hold it, gives the gravity
//! torques the drive must add, `τ_B = −G_B sin B` and `τ_C = G_C sin C` (the twin's
//! `∂U/∂θ`), and from them the two masses, the centres of mass being the device file's.
//!
//! Each joint's torque is fitted as a line in `sin θ`, `τ = a sin θ + c`: the slope is
//! the gravity coefficient, and the intercept `c`, which a right trim leaves at zero, is
//! reported as a duty so that an offset the trims miss shows instead of biasing the
//! masses. A slope needs the poses spread: `sin θ` over at least [`MIN_SPREAD`] for each
//! of B and C, and at least [`MIN_POSES`] poses.

use super::ArmTwin;
use mccs::{ArmSpec, GravitySpec};

/// The fewest poses a fit takes.
pub const MIN_POSES: usize = 8;

/// The least spread of `sin θ` (largest less smallest) over the poses, for B and for C:
/// about 12° about the vertical, more elsewhere.
pub const MIN_SPREAD: f64 = 0.2;

/// One static pose: the joints' counts and the duties of B and C that hold it still
/// (fractions of full duty, as `mccs arm torque` prints them: before the amplifier's
/// trims, which the firmware applies after).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeldPose {
    /// Counts A, B, C.
    pub counts: [f64; 3],
    /// Duties B and C, −1 … 1.
    pub duty: [f64; 2],
}

/// What the fit found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GravityFit {
    /// `G_B = g (m_u c_u + m_f L_b)` and `G_C = g m_f c_f`, N·mm.
    pub coefficients_nmm: [f64; 2],
    /// The masses, kg, from the coefficients and the file's centres of mass and `g`.
    pub upper_arm_mass_kg: f64,
    /// See `upper_arm_mass_kg`.
    pub forearm_mass_kg: f64,
    /// The lines' intercepts as duties (B, C): zero with right trims.
    pub offset_duty: [f64; 2],
    /// The residuals' RMS as duties (B, C).
    pub rms_duty: [f64; 2],
}

/// The arm's gravity fitted to `poses`, or why not (one line).
pub fn fit(twin: &ArmTwin, poses: &[HeldPose]) -> Result<GravityFit, String> {
    let spec = &twin.spec;
    let Some(g) = spec.gravity else {
        return Err(
            "the device file has no [gravity] section: it gives the centres of mass and g, and the fit finds the masses"
                .into(),
        );
    };
    if poses.len() < MIN_POSES {
        return Err(format!(
            "{} poses; the fit needs at least {MIN_POSES}",
            poses.len()
        ));
    }
    let mut lines: [Line; 2] = Default::default();
    for p in poses {
        let t = twin.angles(p.counts);
        for (k, line) in lines.iter_mut().enumerate() {
            let joint = k + 1;
            let tau = p.duty[k] * duty_to_nmm(spec, joint);
            line.points.push((t[joint].sin(), tau));
        }
    }
    let mut coefficients_nmm = [0.0; 2];
    let mut offset_duty = [0.0; 2];
    let mut rms_duty = [0.0; 2];
    for (k, line) in lines.iter().enumerate() {
        let name = ["B", "C"][k];
        let spread = line.spread();
        if spread < MIN_SPREAD {
            return Err(format!(
                "joint {name}: the poses' sin θ spans {spread:.3}; the fit needs at least {MIN_SPREAD} (spread the poses over the joint's range)"
            ));
        }
        let (slope, intercept, rms) = line.fit();
        let per_duty = duty_to_nmm(spec, k + 1);
        // τ_B = −G_B sin B, τ_C = G_C sin C.
        coefficients_nmm[k] = if k == 0 { -slope } else { slope };
        offset_duty[k] = intercept / per_duty;
        rms_duty[k] = rms / per_duty.abs();
    }
    masses(spec, &g, coefficients_nmm).map(|(upper_arm_mass_kg, forearm_mass_kg)| GravityFit {
        coefficients_nmm,
        upper_arm_mass_kg,
        forearm_mass_kg,
        offset_duty,
        rms_duty,
    })
}

/// N·mm of joint `k`'s torque per unit of duty (signed: the joint's sign; the inverse
/// of the twin's `duties`).
fn duty_to_nmm(spec: &ArmSpec, k: usize) -> f64 {
    let j = &spec.joints[k];
    1000.0 * j.ratio * j.torque_constant_nm_per_a * j.max_current_a * j.sign
}

/// The masses from the coefficients: `m_f = G_C / (g c_f)`, then
/// `m_u = (G_B / g − m_f L_b) / c_u`; refused where a centre of mass or `g` is zero or
/// a mass comes out negative (a sign or a count reversed, say).
fn masses(spec: &ArmSpec, g: &GravitySpec, [gb, gc]: [f64; 2]) -> Result<(f64, f64), String> {
    if !(g.upper_arm_com_mm > 0.0 && g.forearm_com_mm > 0.0 && g.g.abs() > 0.0) {
        return Err("gravity: the centres of mass and g must be nonzero to give masses".into());
    }
    let fore = gc / (g.g * g.forearm_com_mm);
    let upper = (gb / g.g - fore * spec.upper_arm_mm) / g.upper_arm_com_mm;
    if fore < 0.0 || upper < 0.0 {
        return Err(format!(
            "the fit gives negative masses (upper arm {upper:.4} kg, forearm {fore:.4} kg; G_B {gb:.1}, G_C {gc:.1} N·mm): check the joints' signs and the duties' sign"
        ));
    }
    Ok((upper, fore))
}

/// Points `(sin θ, τ)` of one joint.
#[derive(Clone, Debug, Default)]
struct Line {
    points: Vec<(f64, f64)>,
}

impl Line {
    /// Largest `sin θ` less the smallest.
    fn spread(&self) -> f64 {
        let (lo, hi) = self
            .points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.0), hi.max(p.0))
            });
        hi - lo
    }

    /// The least-squares line: slope, intercept and the residuals' RMS.
    fn fit(&self) -> (f64, f64, f64) {
        let n = self.points.len() as f64;
        let (mx, my) = self
            .points
            .iter()
            .fold((0.0, 0.0), |(a, b), p| (a + p.0 / n, b + p.1 / n));
        let (sxy, sxx) = self.points.iter().fold((0.0, 0.0), |(a, b), p| {
            (a + (p.0 - mx) * (p.1 - my), b + (p.0 - mx) * (p.0 - mx))
        });
        let slope = sxy / sxx;
        let intercept = my - slope * mx;
        let sq: f64 = self
            .points
            .iter()
            .map(|p| (p.1 - slope * p.0 - intercept).powi(2))
            .sum();
        (slope, intercept, (sq / n).sqrt())
    }
}

/// `text` (a device file) with `[gravity]`'s two masses set to `fit`'s, every other line
/// (comments too) kept; `None` where a mass's line cannot be found.
pub fn with_masses(text: &str, fit: &GravityFit) -> Option<String> {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    for (key, value) in [
        ("upper_arm_mass_kg", fit.upper_arm_mass_kg),
        ("forearm_mass_kg", fit.forearm_mass_kg),
    ] {
        let at = mccs_client::paramfile::key_line(text, "gravity", key)? - 1;
        let line = lines.get_mut(at)?;
        // The key as written (`key` in the section, or `gravity.key` at the top) kept.
        let (lhs, rhs) = line.split_once('=')?;
        let comment = rhs
            .find('#')
            .map_or("# fitted by `mccs arm calibrate`", |i| &rhs[i..]);
        *line = format!("{}= {value:.4}  {comment}", lhs);
    }
    let mut out = lines.join("\n");
    if text.ends_with('\n') {
        out.push('\n');
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_is_fitted_exactly() {
        let line = Line {
            points: (0..10)
                .map(|i| (i as f64 * 0.1, 3.0 * i as f64 * 0.1 - 0.5))
                .collect(),
        };
        let (a, c, rms) = line.fit();
        assert!((a - 3.0).abs() < 1e-12 && (c + 0.5).abs() < 1e-12 && rms < 1e-12);
        assert!((line.spread() - 0.9).abs() < 1e-12);
    }

    fn fitted() -> GravityFit {
        GravityFit {
            coefficients_nmm: [400.0, 90.0],
            upper_arm_mass_kg: 0.25,
            forearm_mass_kg: 0.125,
            offset_duty: [0.0; 2],
            rms_duty: [0.0; 2],
        }
    }

    #[test]
    fn the_masses_are_rewritten_where_and_as_they_are_written() {
        // In the section, a comment kept; at the top level as `gravity.key`, the key kept.
        let text =
            "[arm]\nx = 1\n[gravity]\nupper_arm_mass_kg = 0.17 # scale\nforearm_mass_kg=0.11\n";
        let out = with_masses(text, &fitted()).unwrap();
        assert_eq!(
            out,
            "[arm]\nx = 1\n[gravity]\nupper_arm_mass_kg = 0.2500  # scale\nforearm_mass_kg= 0.1250  # fitted by `mccs arm calibrate`\n"
        );
        let top = "gravity.upper_arm_mass_kg = 0.17\ngravity.forearm_mass_kg = 0.11";
        let out = with_masses(top, &fitted()).unwrap();
        assert!(
            out.starts_with("gravity.upper_arm_mass_kg = 0.2500"),
            "{out}"
        );
        assert!(!out.ends_with('\n'));
        // A file without them: nothing to rewrite.
        assert_eq!(with_masses("[gravity]\ng = 9.81\n", &fitted()), None);
    }
}
