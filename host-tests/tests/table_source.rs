//! `mccs table` emits Rust source that firmware `include!`s: it must be the table the core
//! builds at start-up, bit for bit, and the committed copy must be current.

use mccs::{ForceTable, ForceTable64, Params, Strain};
use std::process::Command;

static COMMITTED: ForceTable64 = include!("../../tables/table2.rs");

static STIFFER: ForceTable64 = include!("../../tables/table2_stiffer.rs");

/// `ForceTable::new` builds, bit for bit, what `mccs table` emits (its measured error
/// included): Table 2's and the demo's stiffer tissue's.
#[test]
fn included_table_is_bit_identical_to_the_runtime_build() {
    let built = ForceTable64::new(&Params::TABLE2).unwrap();
    assert_eq!(COMMITTED, built);
    assert!(built.max_error().is_some());
    let toml = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../params/table2-stiffer.toml"
    ))
    .unwrap();
    let mut stiffer = Params::TABLE2;
    stiffer.cone.shear_modulus *= 1.25;
    assert!(toml.contains(&format!("shear_modulus = {:e}", stiffer.cone.shear_modulus)));
    assert_eq!(STIFFER, ForceTable64::new(&stiffer).unwrap());
    for i in -1000..=1000 {
        let e = Strain::from_num(i as f64 / 500.0);
        assert_eq!(
            COMMITTED.force_and_stiffness(e),
            built.force_and_stiffness(e)
        );
    }
}

#[test]
fn committed_tables_are_what_the_cli_emits() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    for (params, knots, table) in [
        ("params/table2.toml", "65", "tables/table2.rs"),
        ("params/stiff-series.toml", "65", "tables/stiff_series.rs"),
        ("params/steep-kink.toml", "65", "tables/steep_kink.rs"),
        (
            "params/near-transition.toml",
            "65",
            "tables/near_transition.rs",
        ),
        (
            "params/table2-stiffer.toml",
            "65",
            "tables/table2_stiffer.rs",
        ),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_mccs"))
            .args(["table", "--params", params, "--knots", knots])
            .current_dir(root)
            .output()
            .unwrap();
        assert!(out.status.success());
        let committed = std::fs::read_to_string(format!("{root}/{table}")).unwrap();
        let emitted = String::from_utf8(out.stdout).unwrap();
        assert!(
            emitted == committed,
            "{table} is stale: run `mccs table --params {params} --knots {knots} --out {table}`"
        );
    }
}

/// The board's tissue (`boards/f405/tissue.rs`) is what the command in its own first line
/// emits today: the table the board flashes is the table `mccs table` shows.
#[test]
fn the_boards_tissue_is_what_its_command_emits() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let committed = std::fs::read_to_string(format!("{root}/boards/f405/tissue.rs")).unwrap();
    let command = committed
        .lines()
        .next()
        .and_then(|l| l.split('`').nth(1))
        .expect("a `mccs table …` command in its first line");
    let args: Vec<&str> = command.split_whitespace().skip(1).collect();
    assert_eq!(args.first(), Some(&"table"), "{command}");
    let out = Command::new(env!("CARGO_BIN_EXE_mccs"))
        .args(&args)
        .current_dir(root)
        .output()
        .unwrap();
    assert!(out.status.success(), "{command}");
    assert!(
        String::from_utf8(out.stdout).unwrap() == committed,
        "boards/f405/tissue.rs is stale: run `{command} --out boards/f405/tissue.rs`"
    );
}

#[test]
fn every_knot_count_renders_and_round_trips() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    for knots in ["17", "33", "65", "129"] {
        let out = Command::new(env!("CARGO_BIN_EXE_mccs"))
            .args(["table", "--params", "params/table2.toml", "--knots", knots])
            .current_dir(root)
            .output()
            .unwrap();
        assert!(out.status.success());
        let text = String::from_utf8(out.stdout).unwrap();
        let segs = knots.parse::<usize>().unwrap() - 1;
        assert!(text.contains(&format!("mccs::ForceTable::<{segs}>::from_raw")));
        assert_eq!(text.matches("\n        [").count(), segs);
    }
    // A table emitted to a file for another domain matches the runtime build too.
    let t = ForceTable::<32>::with_domain(&Params::TABLE2, -0.2, 1.5).unwrap();
    let text = mccs_host::cli::render_table("", &t, &[]);
    let last = t.raw().segments[31];
    assert!(text.contains(&format!(
        "[{}, {}, {}, {}],\n    ],",
        last[0], last[1], last[2], last[3]
    )));
}

#[test]
fn table_errors_are_one_line_exit_2() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    for (args, needle) in [
        (vec!["--knots", "64"], "--knots"),
        (vec!["--from", "0.5", "--to", "0.5"], "--to"),
        (vec!["--from", "-0.5", "--to", "0.1"], "--to"),
        (vec!["--from", "2", "--to", "3"], "--from"),
        (vec!["--from", "nan"], "--from"),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_mccs"))
            .args(["table", "--params", "params/table2.toml"])
            .args(&args)
            .current_dir(root)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(out.stdout.is_empty());
        assert_eq!(err.lines().count(), 1);
        assert!(err.contains(needle), "{err}");
    }
}
