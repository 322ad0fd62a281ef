//! `mccs check`: will a tissue run on a core, before any firmware is built.

use super::*;

/// The line `check` prints, as `(substeps, tick_instructions, budget, fits)`.
fn parse(line: &str) -> (u32, u64, u64, bool) {
    let field = |k: &str| {
        line.split_whitespace()
            .find_map(|kv| kv.strip_prefix(k)?.strip_prefix('='))
            .unwrap_or_else(|| panic!("no {k} in {line:?}"))
    };
    (
        field("substeps").parse().unwrap(),
        field("tick_instructions").parse().unwrap(),
        field("budget").parse().unwrap(),
        field("fits") == "yes",
    )
}

/// A bench figure of the committed baseline.
fn baseline(core: &str, case: &str, key: &str) -> u64 {
    let text = std::fs::read_to_string(root().join("bench/baseline.txt")).unwrap();
    text.lines()
        .find(|l| l.contains(&format!("core={core} ")) && l.contains(&format!("case={case} ")))
        .and_then(|l| {
            l.split_whitespace()
                .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('=')?.parse().ok())
        })
        .unwrap_or_else(|| panic!("no {core} {case} {key}"))
}

/// Table 2's bound over every state of its N × N patch's `substeps` on `core`, as
/// `mccs check` takes it: each spring at the spread of Table 2's paths more (its segments,
/// its two lines, the held edge vector and `l0/l`; it has no corner).
fn table2_bound(core: &str, n: usize, substeps: u64) -> u64 {
    let paths = ["uniform", "below", "above", "stretched", "crushed"]
        .map(|p| baseline(core, &format!("spring_path_{p}"), "instructions"));
    let spread = paths.iter().max().unwrap() - paths.iter().min().unwrap();
    let springs = mccs::topology::standard_capacity(n).1 as u64;
    substeps * (baseline(core, &format!("substep_n{n}"), "instructions") + springs * spread)
}

/// On each core's demo patch, Table 2 at the default configuration: the substeps the
/// bench takes for its largest patch (`largest_patch_1khz`), and the bound over every
/// state of Table 2's paths ([`table2_bound`]: no wider than the bench's over every
/// table's), within half a 1 kHz tick at the core's clock: exit 0, `fits=yes`, and one
/// stderr line saying how it is estimated.
#[test]
fn the_demo_patches_fit_as_the_bench_measures_them() {
    for core in ["m4f", "m3", "m0"] {
        let out = mccs_ok(&["check", "--params", "params/table2.toml", "--core", core]);
        let text = String::from_utf8(out.stdout).unwrap();
        assert_eq!(text.lines().count(), 1, "{text}");
        let (substeps, tick, budget, fits) = parse(text.trim());
        assert_eq!(
            substeps as u64,
            baseline(core, "largest_patch_1khz", "substeps")
        );
        let n = baseline(core, "largest_patch_1khz", "n") as usize;
        assert_eq!(tick, table2_bound(core, n, substeps as u64));
        assert!(tick <= baseline(core, "largest_patch_1khz", "worst_instructions"));
        assert_eq!(
            budget,
            baseline(core, "largest_patch_1khz", "half_tick_instructions")
        );
        assert!(fits);
        let err = String::from_utf8(out.stderr).unwrap();
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.contains("estimated from the bench's measured costs"),
            "{err}"
        );
    }
}

/// A patch over its budget says so and exits 1 (the M0's N = 5, the bench's
/// `next_patch_1khz`); a configuration the core cannot run exits 2 with one line naming
/// the cause: a patch the bench does not measure there, a tissue too stiff for the tick,
/// a table over the bound (the table's own line), a spacing under the springs' 1 mm.
#[test]
fn what_does_not_fit_or_cannot_run_says_why() {
    let out = mccs(&[
        "check",
        "--params",
        "params/table2.toml",
        "--core",
        "m0",
        "--grid",
        "5",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let (_, tick, budget, fits) = parse(String::from_utf8_lossy(&out.stdout).trim());
    assert!(!fits && tick > budget);
    let substeps = baseline("m0", "next_patch_1khz", "substeps");
    assert_eq!(tick, table2_bound("m0", 5, substeps));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.lines().last().unwrap().contains("over its budget"),
        "{err}"
    );
    let t2 = "params/table2.toml";
    // What it advises lowers the tick: a heavier node where the estimate sets the
    // substeps; where a heavy node leaves the patch too lightly damped for the estimate
    // (the conservative bound, whatever the mass), more damping or a lighter node; at
    // one substep, a smaller patch or a slower tick only.
    let check = |extra: &[&str]| {
        let out = mccs(&[&["check", "--params", t2][..], extra].concat());
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        (
            out.status.code(),
            err.lines().last().unwrap_or("").to_string(),
        )
    };
    for (args, advice, remedies) in [
        (
            &["--grid", "8", "--node-mass", "1"][..],
            "a smaller --grid, a lower --rate or a heavier --node-mass",
            &[&["--grid", "8", "--node-mass", "5"][..]][..],
        ),
        (
            &["--node-mass", "2000"],
            "more --spring-damping or a lighter --node-mass (the patch is too lightly damped",
            &[
                &["--node-mass", "2000", "--spring-damping", "5"][..],
                &["--node-mass", "1000"],
            ],
        ),
        (
            &["--rate", "5000"],
            "a smaller --grid or a lower --rate (one substep a tick already)",
            &[&["--rate", "4000"]],
        ),
    ] {
        let (code, last) = check(args);
        assert!(
            code == Some(1) && last.contains(advice),
            "{args:?}: {code:?} {last}"
        );
        for r in remedies {
            assert_eq!(check(r).0, Some(0), "{r:?} after {args:?}");
        }
    }
    let stiff = temp_file(
        "stiff40.toml",
        &TABLE2
            .replace("shear_modulus = 1.8472e5", "shear_modulus = 7.3888e6")
            .replace("shear_modulus = 4.9151e5", "shear_modulus = 1.96604e7"),
    );
    for (args, needles) in [
        (
            vec!["--params", t2, "--core", "m0", "--grid", "6"],
            vec![
                "--grid",
                "the bench measures the m0 substep for N = 3, 4, 5 only, not 6",
            ],
        ),
        (
            vec!["--params", stiff.to_str().unwrap()],
            vec!["--rate", "needs 80 substeps per tick"],
        ),
        (
            vec!["--params", t2, "--spacing", "0.5"],
            vec!["--spacing", "must be ≥ 1 mm"],
        ),
        (vec!["--params", t2, "--rate", "0"], vec!["--rate"]),
    ] {
        let out = mccs(&[&["check"][..], &args].concat());
        assert_one_line_error(&out, &needles);
    }
    // A table over the bound: the same line as `mccs table`'s.
    let kinked = temp_file(
        "kinked-check.toml",
        &TABLE2.replace(
            "shear_modulus = 4.9151e5",
            "shear_modulus = 4.9151e5\npreload = 8.1175",
        ),
    );
    let out = mccs(&["check", "--params", kinked.to_str().unwrap()]);
    let table = mccs(&["table", "--params", kinked.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(out.stderr, table.stderr);
}

/// `mccs check --params params/table2.toml --device arm --core <core>`, then `more`.
fn check_arm_table2(core: &str, more: &[&str]) -> std::process::Output {
    let mut args = vec![
        "check",
        "--params",
        "params/table2.toml",
        "--device",
        "arm",
        "--core",
        core,
    ];
    args.extend_from_slice(more);
    mccs(&args)
}

/// `--device arm`: the arm board's whole tick on the M4F's N = 8 patch is the bare
/// patch's bound plus the contact's own cost (the demo's roaming tick less its glued
/// tick), the arm's chain, the link's share with a tissue's swap and a mesh's capture
/// (the board's model: they may fall on one tick), the passivity observer and the
/// velocity tracker, each from the baseline; it fits half a tick. On a core where the
/// bench does not measure the swap and the capture, stderr says they are not in it.
#[test]
fn the_arm_boards_trainer_tick_adds_the_contact_the_chain_the_link_and_the_watch() {
    let out = mccs_ok(&["check", "--params", "params/table2.toml", "--device", "arm"]);
    let (_, tick, budget, fits) = parse(String::from_utf8(out.stdout).unwrap().trim());
    let c = |case: &str| baseline("m4f", case, "instructions");
    let substeps = baseline("m4f", "largest_patch_1khz", "substeps");
    let want = table2_bound("m4f", 8, substeps) + c("tick_roaming_bound") - c("tick")
        + c("arm_kinematics")
        + c("tick_link")
        + c("link_swap_n10")
        + c("link_mesh_n10")
        + c("passivity_observer")
        + c("velocity_tracker");
    assert_eq!(tick, want);
    assert!(fits && tick <= budget);
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("the arm's chain"), "{err}");
    let swap = format!(
        "a tissue's swap {} and a mesh's capture {}",
        c("link_swap_n10"),
        c("link_mesh_n10")
    );
    assert!(err.contains(&swap), "{err}");
    let m0 = check_arm_table2("m0", &[]);
    let err = String::from_utf8(m0.stderr).unwrap();
    assert!(
        err.contains("not in it: a tissue's swap and a mesh's capture"),
        "{err}"
    );
}

/// Each core's largest patch whose trainer tick (`--device arm`) fits half a 1 kHz tick,
/// printed as `TRAINER core= largest_n= tick_instructions= budget=` for the docs: the M4F
/// at N = 8 with the paper's integrator and N = 10 with the symplectic option (the
/// board's; the largest the bench measures a substep of), the M3 at 4, the M0 at 3, each
/// fitting and the next size up, where the bench measures it, not.
#[test]
fn each_cores_largest_trainer_tick() {
    for (core, n, integrator) in [
        ("m4f", 8, "improved-euler"),
        ("m4f", 10, "symplectic-damped"),
        ("m3", 4, "improved-euler"),
        ("m0", 3, "improved-euler"),
    ] {
        let run = |n: u32| {
            let grid = n.to_string();
            check_arm_table2(core, &["--grid", &grid, "--integrator", integrator])
        };
        let at = run(n);
        assert_eq!(at.status.code(), Some(0), "{core} N = {n}, {integrator}");
        let (_, tick, budget, _) = parse(String::from_utf8(at.stdout).unwrap().trim());
        let tag = match integrator {
            "improved-euler" => String::new(),
            _ => "integrator=symplectic_damped ".into(),
        };
        println!("TRAINER core={core} {tag}largest_n={n} tick_instructions={tick} budget={budget}");
        let measured = if core == "m4f" { 10 } else { 8 };
        if n < measured {
            let next = run(n + 1);
            assert_eq!(
                next.status.code(),
                Some(1),
                "{core} N = {}, {integrator}",
                n + 1
            );
        }
    }
}

/// `--device arm` holds the coupling to half the arm's stable region at its damping (the
/// device file's [stability], `mccs arm stability`): at half, it goes on to the tick;
/// over it, or at a damping outside the region, exit 1 with the reason; a device file
/// without the region is a warning.
#[test]
fn the_arm_s_coupling_is_held_to_half_its_stable_region() {
    let file = root().join("devices/woodenhaptics.toml");
    let region = mccs_host::arm::device_file::read_stability(&file)
        .unwrap()
        .unwrap();
    let edge = region.max_coupling(0.5).unwrap();
    let run = |k: f64, b: f64, extra: &[&str]| {
        let (k, b) = (k.to_string(), b.to_string());
        let mut args = vec!["--coupling-stiffness", &k, "--coupling-damping", &b];
        args.extend_from_slice(extra);
        let out = check_arm_table2("m4f", &args);
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).to_string(),
        )
    };
    let (_, err) = run(edge / 2.0, 0.5, &[]);
    assert!(err.contains("within half the arm's stable region"), "{err}");
    let (code, err) = run(edge / 2.0 * 1.01, 0.5, &[]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("over half the arm's stable region at 0.5 N·s/m"),
        "{err}"
    );
    let (code, err) = run(1.0, 999.0, &[]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("outside the arm's measured stable region"),
        "{err}"
    );
    // A device file without [stability]: a warning, and the check goes on.
    let text = std::fs::read_to_string(&file).unwrap();
    let bare = text.split("\n[stability]").next().unwrap().to_string();
    let bare = temp_file("arm_without_region.toml", &bare);
    let (_, err) = run(500.0, 0.5, &["--arm-file", bare.to_str().unwrap()]);
    assert!(err.contains("has no [stability]"), "{err}");
}
