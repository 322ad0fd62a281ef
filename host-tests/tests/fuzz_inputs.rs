//! Every fuzz target's check (`mccs_host::fuzz_checks`) on stable, without a sanitizer,
//! over the committed inputs (`fuzz/seeds/<target>/`: a seed corpus and every crash a
//! fuzzing run found, kept as a regression) and whatever a local fuzzing run left
//! (`fuzz/corpus/`, `fuzz/artifacts/`): a change that breaks a parser's promise fails
//! here, not only at the next fuzzing (`scripts/fuzz.sh`).

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The files under `dir`, if it exists.
fn inputs(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut out: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file())
        .collect();
    out.sort();
    out
}

#[test]
fn every_fuzz_target_holds_on_its_committed_and_found_inputs() {
    let targets: Vec<&str> = mccs_host::fuzz_checks::TARGETS
        .iter()
        .map(|(n, _)| *n)
        .collect();
    // Every target of the fuzz crate has its check here.
    let manifest = std::fs::read_to_string(root().join("fuzz/Cargo.toml")).unwrap();
    for name in manifest
        .lines()
        .filter_map(|l| l.strip_prefix("name = \""))
        .map(|l| l.trim_end_matches('"'))
    {
        if name != "mccs-fuzz" {
            assert!(
                targets.contains(&name),
                "fuzz target {name} has no check in fuzz_checks"
            );
        }
    }
    for (name, check) in mccs_host::fuzz_checks::TARGETS {
        let seeds = inputs(&root().join("fuzz/seeds").join(name));
        assert!(!seeds.is_empty(), "fuzz/seeds/{name}/ is empty");
        let mut all = seeds;
        all.extend(inputs(&root().join("fuzz/corpus").join(name)));
        all.extend(inputs(&root().join("fuzz/artifacts").join(name)));
        for path in &all {
            let data = std::fs::read(path).unwrap();
            let r = std::panic::catch_unwind(|| check(&data));
            assert!(
                r.is_ok(),
                "{name}: {} breaks the target's promise",
                path.display()
            );
        }
        println!("FUZZ_INPUTS target={name} inputs={}", all.len());
    }
}

/// The crash a 30-second fuzzing run found in `fit_data` (a quoted header over two lines
/// gave a two-line error): one line now.
#[test]
fn a_quoted_header_over_two_lines_is_a_one_line_error() {
    let data = [0x22, 0x01, 0x3a, 0x27, 0x27, 0x27, 0x0a, 0x27, 0x27];
    let e = mccs_host::fit::parse_data(std::str::from_utf8(&data).unwrap(), "x.csv").unwrap_err();
    let line = e.to_string();
    assert!(!line.contains('\n'), "{line:?}");
    assert!(
        line.starts_with("x.csv: row 1: the header must be `strain,force_n`, not "),
        "{line}"
    );
}
