//! The device file (TOML, docs/arm.md): `[arm]`, `[joint.a]`, `[joint.b]`, `[joint.c]`,
//! optionally `[gravity]` and `[stability]`; every key required but `gravity.g`. The same strictness as a
//! parameter file: an unknown key (with the nearest known one), a missing one, a
//! non-number or a value out of its range is one line naming the file, the line and the
//! key.

use crate::paramfile::{key_line, nearest_in, section_line};
use mccs::{ArmSpec, GravitySpec, JointSpec};
use mccs_client::shown::Shown;
use mccs_client::shown::ShownPath;
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

/// The keys of `[stability]`.
const STABILITY: [&str; 2] = ["coupling_damping_n_s_m", "max_coupling_n_mm"];

/// Every key as `section.key`.
fn all_keys() -> Vec<String> {
    let mut v: Vec<String> = ARM.iter().map(|k| format!("arm.{k}")).collect();
    for j in ["a", "b", "c"] {
        v.extend(JOINT.iter().map(|k| format!("joint.{j}.{k}")));
    }
    v.extend(GRAVITY.iter().map(|k| format!("gravity.{k}")));
    v.extend(STABILITY.iter().map(|k| format!("stability.{k}")));
    v.extend(
        [
            "arm",
            "joint.a",
            "joint.b",
            "joint.c",
            "gravity",
            "stability",
        ]
        .map(String::from),
    );
    v
}

/// The arm's stable region as measured on its simulated body (`mccs arm stability`,
/// docs/safety.md): at each coupling damping, the largest coupling stiffness with which
/// a held press showed no cycle and put out no energy.
#[derive(Clone, Debug, PartialEq)]
pub struct StableRegion {
    /// `(damping N·s/m, stiffness N/mm)`, the dampings rising.
    pub points: Vec<(f64, f64)>,
}

impl StableRegion {
    /// The region's stiffness at `damping`: a measured one's, or between two the lower
    /// of theirs (nothing is known between them; None: outside them).
    pub fn max_coupling(&self, damping: f64) -> Option<f64> {
        mccs::arm::stable_region::stable_coupling(&self.points, damping)
    }
}

/// Reads a device file's `[stability]` (None: the file has none).
pub fn read_stability(path: &Path) -> Result<Option<StableRegion>, String> {
    let text = mccs_client::input::read_text(path, mccs_client::input::CONFIG_BYTES)
        .map_err(|e| format!("{}: cannot read: {e}", ShownPath(path)))?;
    parse_stability(&text, path)
}

/// Parses and checks a device file's `[stability]`: two lists of 1 to 16 numbers of
/// the same length, the dampings (0 … 1000 N·s/m) rising, each stiffness > 0 and
/// ≤ 1000 N/mm. The rest of the file is checked as [`parse`] does.
pub fn parse_stability(text: &str, path: &Path) -> Result<Option<StableRegion>, String> {
    with_doc(text, path, |doc| {
        spec_of(doc)?;
        stability_of(doc)
    })
}

/// The stable region a checked document holds, if any.
fn stability_of(doc: &Doc) -> Result<Option<StableRegion>, String> {
    if doc.section("stability").is_none() {
        return Ok(None);
    }
    let list = |key: &str, ok: &dyn Fn(f64) -> bool, rule: &str| -> Result<Vec<f64>, String> {
        let v = doc
            .section("stability")
            .and_then(|t| t.get(key))
            .ok_or_else(|| format!("{}: missing", doc.at("stability", key)))?;
        let xs: Option<Vec<f64>> = v.as_array().map(|a| {
            a.iter()
                .map(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
                .collect::<Option<Vec<f64>>>()
                .unwrap_or_default()
        });
        match xs {
            Some(xs) if (1..=16).contains(&xs.len()) && xs.iter().all(|&x| ok(x)) => Ok(xs),
            _ => Err(format!(
                "{}: must be a list of 1 to 16 numbers, {rule}",
                doc.at("stability", key)
            )),
        }
    };
    let dampings = list(
        "coupling_damping_n_s_m",
        &|b| (0.0..=1000.0).contains(&b),
        "each 0 … 1000 N·s/m",
    )?;
    let stiffness = list(
        "max_coupling_n_mm",
        &|k| k > 0.0 && k <= 1000.0,
        "each > 0 and ≤ 1000 N/mm",
    )?;
    if stiffness.len() != dampings.len() {
        return Err(format!(
            "{}: must have one value for each of coupling_damping_n_s_m's {}",
            doc.at("stability", "max_coupling_n_mm"),
            dampings.len()
        ));
    }
    if dampings.windows(2).any(|w| w[1] <= w[0]) {
        return Err(format!(
            "{}: the dampings must rise",
            doc.at("stability", "coupling_damping_n_s_m")
        ));
    }
    Ok(Some(StableRegion {
        points: dampings.into_iter().zip(stiffness).collect(),
    }))
}

/// `text` with its `[stability]` section set to `region` (the old one, its comments
/// within it, dropped; the new one last), under `comment` (each line a `#` comment).
pub fn with_stability(text: &str, region: &StableRegion, comment: &str) -> String {
    let mut kept: Vec<&str> = Vec::new();
    let mut skipping = false;
    for line in text.lines() {
        let t = line.trim();
        if t.starts_with('[') {
            skipping = t == "[stability]";
        }
        if !skipping {
            kept.push(line);
        }
    }
    while kept.last().is_some_and(|l| l.trim().is_empty()) {
        kept.pop();
    }
    let list = |f: &dyn Fn(&(f64, f64)) -> f64| {
        region
            .points
            .iter()
            .map(|p| format!("{:?}", f(p)))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut out = kept.join("\n");
    out.push_str("\n\n[stability]\n");
    for l in comment.lines() {
        out.push_str(&format!("# {l}\n"));
    }
    out.push_str(&format!(
        "coupling_damping_n_s_m = [{}]\nmax_coupling_n_mm = [{}]\n",
        list(&|p| p.0),
        list(&|p| p.1)
    ));
    out
}

/// Reads and checks a device file.
pub fn read(path: &Path) -> Result<ArmSpec, String> {
    let text = mccs_client::input::read_text(path, mccs_client::input::CONFIG_BYTES)
        .map_err(|e| format!("{}: cannot read: {e}", ShownPath(path)))?;
    parse(&text, path)
}

/// The text as a document with known keys only, handed to `read`.
fn with_doc<T>(
    text: &str,
    path: &Path,
    read: impl FnOnce(&Doc) -> Result<T, String>,
) -> Result<T, String> {
    let file = ShownPath(path).to_string();
    let table = toml_table(text, &file)?;
    let doc = Doc {
        text,
        file: &file,
        table: &table,
    };
    doc.known_keys_only()?;
    read(&doc)
}

/// Parses and checks device-file text; `path` names it in errors.
pub fn parse(text: &str, path: &Path) -> Result<ArmSpec, String> {
    with_doc(text, path, spec_of)
}

/// The arm a checked document describes.
fn spec_of(doc: &Doc) -> Result<ArmSpec, String> {
    let spec = ArmSpec {
        base_height_mm: doc.number("arm", "base_height_mm")?,
        upper_arm_mm: doc.number("arm", "upper_arm_mm")?,
        forearm_mm: doc.number("arm", "forearm_mm")?,
        tissue_origin_mm: doc.tissue_origin()?,
        joints: [
            doc.joint("joint.a")?,
            doc.joint("joint.b")?,
            doc.joint("joint.c")?,
        ],
        gravity: doc.gravity()?,
    };
    // The ranges are the core's (`ArmSpec::check`, the one statement of them); the
    // reader names the file, line and key of the value that breaks one.
    spec.check()
        .map_err(|e| format!("{}: {}", doc.at(e.section(), e.key), e.rule))?;
    Ok(spec)
}

/// The text as TOML, or the line naming where it is not.
fn toml_table(text: &str, file: &str) -> Result<toml::Table, String> {
    text.parse().map_err(|e: toml::de::Error| {
        let line = e
            .span()
            .map(|s| text[..s.start.min(text.len())].lines().count().max(1));
        let msg = e.message().lines().next().unwrap_or("").to_string();
        match line {
            Some(l) => format!("{file}: line {l}: invalid TOML: {msg}"),
            None => format!("{file}: invalid TOML: {msg}"),
        }
    })
}

/// A device file being read: its text (for lines), its name and its table.
struct Doc<'a> {
    text: &'a str,
    file: &'a str,
    table: &'a toml::Table,
}

impl Doc<'_> {
    /// `FILE: line L: section.key` (or without the line when it cannot be found).
    fn at(&self, section: &str, key: &str) -> String {
        match key_line(self.text, section, key) {
            Some(l) => format!("{}: line {l}: {section}.{key}", self.file),
            None => format!("{}: {section}.{key}", self.file),
        }
    }

    /// An unknown section or key, with the nearest known one.
    fn unknown(&self, name: &str, line: Option<usize>) -> String {
        let file = self.file;
        let place = line.map_or(format!("{file}: "), |l| format!("{file}: line {l}: "));
        match nearest_in(name, all_keys()) {
            Some(n) => format!("{place}{}: unknown key; did you mean {n}?", Shown(name)),
            None => {
                format!(
                    "{place}{}: unknown key (docs/arm.md lists the device file's keys)",
                    Shown(name)
                )
            }
        }
    }

    /// Unknown sections and keys first: a typo is named, with what was meant.
    fn known_keys_only(&self) -> Result<(), String> {
        for (name, value) in self.table {
            let keys: &[&str] = match name.as_str() {
                "arm" => &ARM,
                "gravity" => &GRAVITY,
                "stability" => &STABILITY,
                "joint" => {
                    self.known_joints(name, value)?;
                    continue;
                }
                _ => return Err(self.unknown(name, section_line(self.text, name))),
            };
            let Some(t) = value.as_table() else {
                return Err(self.unknown(name, section_line(self.text, name)));
            };
            if let Some(k) = t.keys().find(|k| !keys.contains(&k.as_str())) {
                return Err(self.unknown(&format!("{name}.{k}"), key_line(self.text, name, k)));
            }
        }
        Ok(())
    }

    /// `[joint.a|b|c]` and nothing else, each with the joint's keys only.
    fn known_joints(&self, name: &str, value: &toml::Value) -> Result<(), String> {
        let Some(joints) = value.as_table() else {
            return Err(self.unknown(name, section_line(self.text, name)));
        };
        for (j, v) in joints {
            let section = format!("joint.{j}");
            let keys = match v.as_table() {
                Some(t) if ["a", "b", "c"].contains(&j.as_str()) => t,
                _ => return Err(self.unknown(&section, section_line(self.text, &section))),
            };
            if let Some(k) = keys.keys().find(|k| !JOINT.contains(&k.as_str())) {
                let line = key_line(self.text, &section, k);
                return Err(self.unknown(&format!("{section}.{k}"), line));
            }
        }
        Ok(())
    }

    /// The section `name` (`joint.a` …), if there.
    fn section(&self, name: &str) -> Option<&toml::Table> {
        let mut t = self.table;
        for part in name.split('.') {
            t = t.get(part)?.as_table()?;
        }
        Some(t)
    }

    /// A key's number, or the line naming why not.
    fn number(&self, sec: &str, key: &str) -> Result<f64, String> {
        let v = self
            .section(sec)
            .and_then(|t| t.get(key))
            .ok_or_else(|| format!("{}: missing", self.at(sec, key)))?;
        match v {
            toml::Value::Float(x) => Ok(*x),
            toml::Value::Integer(i) => Ok(*i as f64),
            _ => Err(format!("{}: must be a number", self.at(sec, key))),
        }
    }

    /// `arm.tissue_origin_mm`: three numbers of mm (their range: `ArmSpec::check`).
    fn tissue_origin(&self) -> Result<[f64; 3], String> {
        let origin = self
            .section("arm")
            .and_then(|t| t.get("tissue_origin_mm"))
            .ok_or_else(|| format!("{}: missing", self.at("arm", "tissue_origin_mm")))?;
        let origin: Vec<f64> = origin
            .as_array()
            .map(|a| {
                a.iter()
                    .filter_map(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
                    .collect()
            })
            .unwrap_or_default();
        origin.try_into().map_err(|_| {
            format!(
                "{}: must be [x, y, z]: three numbers of mm, each within ±2000",
                self.at("arm", "tissue_origin_mm")
            )
        })
    }

    /// `[gravity]`, if there (`g` optional: 9.81 m/s²).
    fn gravity(&self) -> Result<Option<GravitySpec>, String> {
        let Some(t) = self.section("gravity") else {
            return Ok(None);
        };
        let m = |k: &str| self.number("gravity", k);
        Ok(Some(GravitySpec {
            upper_arm_mass_kg: m("upper_arm_mass_kg")?,
            upper_arm_com_mm: m("upper_arm_com_mm")?,
            forearm_mass_kg: m("forearm_mass_kg")?,
            forearm_com_mm: m("forearm_com_mm")?,
            g: if t.contains_key("g") { m("g")? } else { 9.81 },
        }))
    }

    /// The section `sec` (`joint.a` …): each key a number, `home_count` a whole one.
    fn joint(&self, sec: &str) -> Result<JointSpec, String> {
        let n = |k: &str| self.number(sec, k);
        let home_count = n("home_count")?;
        if !(home_count.fract() == 0.0 && home_count.abs() <= i32::MAX as f64) {
            return Err(format!(
                "{}: must be a whole number of counts",
                self.at(sec, "home_count")
            ));
        }
        Ok(JointSpec {
            counts_per_rev: n("counts_per_rev")?,
            ratio: n("ratio")?,
            sign: n("sign")?,
            home_count: home_count as i32,
            home_angle_deg: n("home_angle_deg")?,
            torque_constant_nm_per_a: n("torque_constant_nm_per_a")?,
            max_current_a: n("max_current_a")?,
            continuous_current_a: n("continuous_current_a")?,
            thermal_time_constant_s: n("thermal_time_constant_s")?,
            duty_offset: n("duty_offset")?,
            dead_band: n("dead_band")?,
            min_angle_deg: n("min_angle_deg")?,
            max_angle_deg: n("max_angle_deg")?,
        })
    }
}
