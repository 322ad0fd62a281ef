//! One table everywhere: every `--backend fixed` path evaluates the table `mccs table`
//! emits for the same parameters and knots, and refuses where it refuses, with the same
//! line (issue #51).

use super::*;
use mccs::{ForceTable, Strain};
use rand::SeedableRng;

/// The strains the curves below print: the default domain in steps of 0.05.
const STRAINS: [&str; 6] = ["--from", "-0.5", "--to", "0.95", "--step", "0.05"];

/// `mccs ARGS` as (exit status, stdout, stderr).
fn run(args: &[&str]) -> (Option<i32>, String, String) {
    let out = mccs(args);
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// On springs drawn afresh (a seed no other test uses), `mccs curve --backend fixed`
/// meets the bound or refuses exactly where `mccs table` does: a refusal is the same
/// line; a table it runs is the one `ForceTable::new` builds (what `mccs table` emits),
/// to the printed digit. `patch` and `replay` refuse the first refused spring with that
/// line too, and every path runs it under `--accept-error`, with a warning.
#[test]
fn the_fixed_paths_run_the_table_mccs_table_emits() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x5151);
    let (mut met, mut refused) = (0, 0);
    for i in 0..20 {
        if met >= 2 && refused >= 2 {
            break;
        }
        let (p, _) = crate::table_bound::spring(&mut rng);
        let file = temp_file(
            &format!("drawn-{i}.toml"),
            &mccs_host::paramfile::to_toml(&p),
        );
        let f = file.to_str().unwrap();
        let table = run(&["table", "--params", f]);
        let curve = run(&[
            &["curve", "--params", f, "--backend", "fixed"][..],
            &STRAINS,
        ]
        .concat());
        assert_eq!(table.0, curve.0, "spring {i}: {} / {}", table.2, curve.2);
        if table.0 == Some(2) {
            // Any refusal (the bound, or a law straight over the whole domain): the
            // same line.
            assert_eq!(table.2, curve.2, "spring {i}");
            assert!(curve.1.is_empty());
            if !table.2.contains("misses the bound") {
                continue;
            }
            refused += 1;
            if refused == 1 {
                for args in [
                    vec![
                        "patch",
                        "--params",
                        f,
                        "--backend",
                        "fixed",
                        "--indent",
                        "1",
                    ],
                    vec![
                        "replay",
                        "--params",
                        f,
                        "--backend",
                        "fixed",
                        "--probe",
                        "params/stroke.csv",
                    ],
                ] {
                    let out = run(&args);
                    assert_eq!((out.0, &out.2), (Some(2), &table.2), "{args:?}");
                    let accepted = run(&[&args[..], &["--accept-error"]].concat());
                    assert_eq!(accepted.0, Some(0), "{args:?}: {}", accepted.2);
                    assert!(
                        accepted.2.contains("used anyway (--accept-error)"),
                        "{}",
                        accepted.2
                    );
                }
            }
            continue;
        }
        met += 1;
        assert_eq!(table.0, Some(0), "spring {i}: {}", table.2);
        let t = ForceTable::<64>::new(&p).unwrap();
        for row in curve.1.lines().skip(1) {
            let v: Vec<&str> = row.split(',').collect();
            let (f, k) = t.force_and_stiffness(Strain::from_num(v[0].parse::<f64>().unwrap()));
            assert_eq!(
                (v[1], v[2]),
                (
                    &*f.to_num::<f64>().to_string(),
                    &*k.to_num::<f64>().to_string()
                ),
                "spring {i} at {}",
                v[0]
            );
        }
    }
    println!("ONE_TABLE met={met} refused={refused}");
    assert!(
        met >= 2 && refused >= 2,
        "{met} met, {refused} refused: draw more"
    );
}

/// The same default knots everywhere: `mccs table`, `curve`, `patch` and `replay`
/// without `--knots` run the 65-knot table, and take `--knots` alike.
#[test]
fn every_fixed_path_takes_the_same_knots() {
    let t2 = "params/table2.toml";
    for knots in ["17", "129"] {
        let curve = mccs_ok(
            &[
                &[
                    "curve",
                    "--params",
                    t2,
                    "--backend",
                    "fixed",
                    "--knots",
                    knots,
                ][..],
                &STRAINS,
            ]
            .concat(),
        );
        let segs: usize = knots.parse::<usize>().unwrap() - 1;
        let text = String::from_utf8(curve.stdout).unwrap();
        let row = text.lines().nth(25).unwrap();
        let e: f64 = row.split(',').next().unwrap().parse().unwrap();
        let f = match segs {
            16 => ForceTable::<16>::new(&mccs::Params::TABLE2)
                .unwrap()
                .force(Strain::from_num(e)),
            _ => ForceTable::<128>::new(&mccs::Params::TABLE2)
                .unwrap()
                .force(Strain::from_num(e)),
        };
        assert_eq!(
            row.split(',').nth(1).unwrap(),
            f.to_num::<f64>().to_string()
        );
        for args in [
            vec![
                "patch",
                "--params",
                t2,
                "--backend",
                "fixed",
                "--indent",
                "1",
                "--duration",
                "0.01",
                "--knots",
                knots,
            ],
            vec![
                "replay",
                "--params",
                t2,
                "--backend",
                "fixed",
                "--probe",
                "params/stroke.csv",
                "--knots",
                knots,
            ],
        ] {
            mccs_ok(&args);
        }
    }
    for (cmd, extra) in [("curve", &STRAINS[..]), ("patch", &["--indent", "1"][..])] {
        let out = mccs(
            &[
                &[cmd, "--params", t2, "--knots", "64"][..],
                extra,
                &["--backend", "fixed"],
            ]
            .concat(),
        );
        assert_one_line_error(&out, &["--knots", "must be 17, 33, 65 or 129"]);
        let out = mccs(&[&[cmd, "--params", t2, "--knots", "65"][..], extra].concat());
        assert_one_line_error(&out, &["--knots: only with --backend fixed"]);
    }
}
