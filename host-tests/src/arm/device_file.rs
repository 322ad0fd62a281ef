//! The device file (TOML, docs/arm.md): `[arm]`, `[joint.a]`, `[joint.b]`, `[joint.c]`,
//! optionally `[gravity]`; every key required but `gravity.g`. The same strictness as a
//! parameter file: an unknown key (with the nearest known one), a missing one, a
//! non-number or a value out of its range is one line naming the file, the line and the
//! key.

use crate::paramfile::{key_line, nearest_in, section_line};
use mccs::{ArmSpec, GravitySpec, JointSpec};
use std::path::Path;

/// The keys of `[arm]`.
const ARM: [&str; 4] = [
    "base_height_mm",
    "upper_arm_mm",
    "forearm_mm",
    "tissue_origin_mm",
];
/// The keys of each `[joint.*]`.
const JOINT: [&str; 13] = [
    "counts_per_rev",
    "ratio",
    "sign",
    "home_count",
    "home_angle_deg",
    "torque_constant_nm_per_a",
    "max_current_a",
    "continuous_current_a",
    "thermal_time_constant_s",
    "duty_offset",
    "dead_band",
    "min_angle_deg",
    "max_angle_deg",
];
/// The keys of `[gravity]` (`g` optional: 9.81 m/s²).
const GRAVITY: [&str; 5] = [
    "upper_arm_mass_kg",
    "upper_arm_com_mm",
    "forearm_mass_kg",
    "forearm_com_mm",
    "g",
];

/// Every key as `section.key`.
fn all_keys() -> Vec<String> {
    let mut v: Vec<String> = ARM.iter().map(|k| format!("arm.{k}")).collect();
    for j in ["a", "b", "c"] {
        v.extend(JOINT.iter().map(|k| format!("joint.{j}.{k}")));
    }
    v.extend(GRAVITY.iter().map(|k| format!("gravity.{k}")));
    v.extend(["arm", "joint.a", "joint.b", "joint.c", "gravity"].map(String::from));
    v
}

/// Reads and checks a device file.
pub fn read(path: &Path) -> Result<ArmSpec, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    parse(&text, path)
}

/// Parses and checks device-file text; `path` names it in errors.
pub fn parse(text: &str, path: &Path) -> Result<ArmSpec, String> {
    let file = path.display().to_string();
    let at = |section: &str, key: &str| match key_line(text, section, key) {
        Some(l) => format!("{file}: line {l}: {section}.{key}"),
        None => format!("{file}: {section}.{key}"),
    };
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
        let line = e
            .span()
            .map(|s| text[..s.start.min(text.len())].lines().count().max(1));
        let msg = e.message().lines().next().unwrap_or("").to_string();
        match line {
            Some(l) => format!("{file}: line {l}: invalid TOML: {msg}"),
            None => format!("{file}: invalid TOML: {msg}"),
        }
    })?;
    // Unknown sections and keys first: a typo is named, with what was meant.
    let unknown = |name: &str, line: Option<usize>| {
        let place = line.map_or(format!("{file}: "), |l| format!("{file}: line {l}: "));
        match nearest_in(name, all_keys()) {
            Some(n) => format!("{place}{name}: unknown key; did you mean {n}?"),
            None => {
                format!("{place}{name}: unknown key (docs/arm.md lists the device file's keys)")
            }
        }
    };
    for (name, value) in &table {
        let keys: &[&str] = match name.as_str() {
            "arm" => &ARM,
            "gravity" => &GRAVITY,
            "joint" => {
                let Some(joints) = value.as_table() else {
                    return Err(unknown(name, section_line(text, name)));
                };
                for (j, v) in joints {
                    let section = format!("joint.{j}");
                    if !["a", "b", "c"].contains(&j.as_str()) || !v.is_table() {
                        return Err(unknown(&section, section_line(text, &section)));
                    }
                    if let Some(k) = v
                        .as_table()
                        .unwrap()
                        .keys()
                        .find(|k| !JOINT.contains(&k.as_str()))
                    {
                        return Err(unknown(
                            &format!("{section}.{k}"),
                            key_line(text, &section, k),
                        ));
                    }
                }
                continue;
            }
            _ => return Err(unknown(name, section_line(text, name))),
        };
        let Some(t) = value.as_table() else {
            return Err(unknown(name, section_line(text, name)));
        };
        if let Some(k) = t.keys().find(|k| !keys.contains(&k.as_str())) {
            return Err(unknown(&format!("{name}.{k}"), key_line(text, name, k)));
        }
    }
    let section = |name: &str| -> Option<&toml::Table> {
        let mut t = &table;
        for part in name.split('.') {
            t = t.get(part)?.as_table()?;
        }
        Some(t)
    };
    let number = |sec: &str, key: &str| -> Result<f64, String> {
        let v = section(sec)
            .and_then(|t| t.get(key))
            .ok_or_else(|| format!("{}: missing", at(sec, key)))?;
        match v {
            toml::Value::Float(x) => Ok(*x),
            toml::Value::Integer(i) => Ok(*i as f64),
            _ => Err(format!("{}: must be a number", at(sec, key))),
        }
    };
    let rule = |sec: &str, key: &str, ok: bool, what: &str| {
        if ok {
            Ok(())
        } else {
            Err(format!("{}: {what}", at(sec, key)))
        }
    };
    let length = |key: &str, zero_ok: bool| -> Result<f64, String> {
        let v = number("arm", key)?;
        let ok = v.is_finite() && v <= 1000.0 && (v > 0.0 || (zero_ok && v == 0.0));
        rule(
            "arm",
            key,
            ok,
            if zero_ok {
                "must be 0 … 1000 mm"
            } else {
                "must be > 0 and ≤ 1000 mm"
            },
        )?;
        Ok(v)
    };
    let base_height_mm = length("base_height_mm", true)?;
    let upper_arm_mm = length("upper_arm_mm", false)?;
    let forearm_mm = length("forearm_mm", false)?;
    let origin = section("arm")
        .and_then(|t| t.get("tissue_origin_mm"))
        .ok_or_else(|| format!("{}: missing", at("arm", "tissue_origin_mm")))?;
    let origin: Vec<f64> = origin
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
                .collect()
        })
        .unwrap_or_default();
    let tissue_origin_mm: [f64; 3] = origin
        .try_into()
        .ok()
        .filter(|o: &[f64; 3]| o.iter().all(|v| v.is_finite() && v.abs() <= 2000.0))
        .ok_or_else(|| {
            format!(
                "{}: must be [x, y, z]: three numbers of mm, each within ±2000",
                at("arm", "tissue_origin_mm")
            )
        })?;
    let mut joints = Vec::new();
    for j in ["a", "b", "c"] {
        joints.push(joint(&format!("joint.{j}"), &number, &rule)?);
    }
    let gravity = match section("gravity") {
        None => None,
        Some(t) => {
            let m = |k: &str| -> Result<f64, String> {
                let v = number("gravity", k)?;
                rule("gravity", k, v.is_finite() && v >= 0.0, "must be ≥ 0")?;
                Ok(v)
            };
            let g = if t.contains_key("g") {
                number("gravity", "g")?
            } else {
                9.81
            };
            rule(
                "gravity",
                "g",
                g.is_finite() && g.abs() <= 100.0,
                "must be within ±100 m/s²",
            )?;
            Some(GravitySpec {
                upper_arm_mass_kg: m("upper_arm_mass_kg")?,
                upper_arm_com_mm: m("upper_arm_com_mm")?,
                forearm_mass_kg: m("forearm_mass_kg")?,
                forearm_com_mm: m("forearm_com_mm")?,
                g,
            })
        }
    };
    let spec = ArmSpec {
        base_height_mm,
        upper_arm_mm,
        forearm_mm,
        tissue_origin_mm,
        joints: [joints[0], joints[1], joints[2]],
        gravity,
    };
    spec.validate().map_err(|e| format!("{file}: {e}"))?;
    Ok(spec)
}

/// A key's number: `(section, key)`, or the line naming why not.
type NumberAt<'a> = dyn Fn(&str, &str) -> Result<f64, String> + 'a;
/// A key's range: `(section, key, within, what it must be)`.
type Rule<'a> = dyn Fn(&str, &str, bool, &str) -> Result<(), String> + 'a;

/// The section `sec` (`joint.a` …) of a device file: each key read by `number` and held
/// by `rule` to its range, naming the file, line and key.
fn joint(sec: &str, number: &NumberAt, rule: &Rule) -> Result<JointSpec, String> {
    let n = |k: &str| number(sec, k);
    let positive = |k: &str| -> Result<f64, String> {
        let v = n(k)?;
        rule(sec, k, v.is_finite() && v > 0.0, "must be > 0")?;
        Ok(v)
    };
    let counts_per_rev = positive("counts_per_rev")?;
    let ratio = positive("ratio")?;
    rule(
        sec,
        "counts_per_rev",
        (16.0..=(1u64 << 30) as f64).contains(&(counts_per_rev * ratio)),
        "counts_per_rev × ratio (counts per joint turn) must be 16 … 2^30",
    )?;
    let sign = n("sign")?;
    rule(sec, "sign", sign == 1.0 || sign == -1.0, "must be 1 or -1")?;
    let home_count = n("home_count")?;
    rule(
        sec,
        "home_count",
        home_count.fract() == 0.0 && home_count.abs() <= i32::MAX as f64,
        "must be a whole number of counts",
    )?;
    let torque_constant_nm_per_a = positive("torque_constant_nm_per_a")?;
    let max_current_a = positive("max_current_a")?;
    let continuous_current_a = positive("continuous_current_a")?;
    rule(
        sec,
        "continuous_current_a",
        continuous_current_a <= max_current_a,
        "must be at most max_current_a",
    )?;
    let thermal_time_constant_s = n("thermal_time_constant_s")?;
    rule(
        sec,
        "thermal_time_constant_s",
        (1.0..=10_000.0).contains(&thermal_time_constant_s),
        "must be 1 … 10000 s",
    )?;
    let duty_offset = n("duty_offset")?;
    rule(
        sec,
        "duty_offset",
        (-0.2..=0.2).contains(&duty_offset),
        "must be -0.2 … 0.2 (of full duty)",
    )?;
    let dead_band = n("dead_band")?;
    rule(
        sec,
        "dead_band",
        (0.0..=0.2).contains(&dead_band),
        "must be 0 … 0.2 (of full duty)",
    )?;
    let angle = |k: &str| -> Result<f64, String> {
        let v = n(k)?;
        rule(
            sec,
            k,
            v.is_finite() && v.abs() <= 180.0,
            "must be within ±180°",
        )?;
        Ok(v)
    };
    let home_angle_deg = angle("home_angle_deg")?;
    let min_angle_deg = angle("min_angle_deg")?;
    let max_angle_deg = angle("max_angle_deg")?;
    rule(
        sec,
        "min_angle_deg",
        min_angle_deg < home_angle_deg && home_angle_deg < max_angle_deg,
        "must be below home_angle_deg, and max_angle_deg above it",
    )?;
    Ok(JointSpec {
        counts_per_rev,
        ratio,
        sign,
        home_count: home_count as i32,
        home_angle_deg,
        torque_constant_nm_per_a,
        max_current_a,
        continuous_current_a,
        thermal_time_constant_s,
        duty_offset,
        dead_band,
        min_angle_deg,
        max_angle_deg,
    })
}
