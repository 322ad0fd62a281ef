//! What to change so that a force table over the product's bound meets it: the fewest
//! more knots, or the widest narrower domain, each found by building and measuring
//! ([`remedy`]). The refusal line of every fixed-point path ends with it
//! (`build::refusal`).

use mccs::{ForceTable, TableBound};

/// What one of [`remedy`]'s builds gave.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Tried {
    /// Built within the product's bound, which it measured at this.
    Meets(TableBound),
    /// Built, over the bound.
    Misses,
    /// Not built (the builder refused the domain) or out of builds: stop that way.
    Stop,
}

/// Tables a refusal's [`remedy`] may build, at most: each that misses the bound takes
/// longest with 129 knots for a spring with a preload (the builder tries every
/// placement): `docs/cli.md` gives the time of one refusal.
const REMEDY_BUILDS: usize = 16;

/// [`remedy`]'s first steps in the domain: sixths of it.
const STEPS: usize = 6;

/// [`remedy`]'s halvings of the step where a domain first met the bound.
const HALVINGS: usize = 3;

/// What to change so that a table `t` over `[from, to]` that misses the product's bound
/// (with the formats able to meet it) meets it, found by building and measuring
/// ([`search`]).
pub(super) fn remedy<const S: usize>(law: &mccs::Law, from: f64, to: f64) -> String {
    let build = |segments: usize, a: f64, b: f64| -> Tried {
        let built = match segments {
            32 => ForceTable::<32>::from_law_best(law, a, b).map(|t| t.max_error()),
            64 => ForceTable::<64>::from_law_best(law, a, b).map(|t| t.max_error()),
            128 => ForceTable::<128>::from_law_best(law, a, b).map(|t| t.max_error()),
            _ => ForceTable::<S>::from_law_best(law, a, b).map(|t| t.max_error()),
        };
        match built {
            Ok(Some(r)) if r.within(&TableBound::PRODUCT) => Tried::Meets(r),
            Ok(_) => Tried::Misses,
            // No nonlinear phase left, too narrow: nothing further that way.
            Err(_) => Tried::Stop,
        }
    };
    search(build, S, (from, to), (law.strain_t(), law.strain_c()))
}

/// [`remedy`]'s search, `build(segments, from, to)` building and measuring one table:
/// the fewest knots above `segments + 1` that meet the bound over the whole domain
/// `(from, to)`; else the widest domains it found with the same knots, one with a lower
/// `--to` and one with a higher `--from`. Each steps across the part of the domain where
/// the law bends, `bends` (`Δ(F_T)` to the solid point `Δ(F_C)`; from the bend's end
/// where the domain reaches past it: the law is straight there), by sixths of it, then
/// halves the last step three times. At most [`REMEDY_BUILDS`] builds. Each value it
/// names is one it built and measured, rounded to 0.001 inward, so that the command it
/// names builds that table. Where nothing it tried meets the bound, it says so.
fn search(
    mut build: impl FnMut(usize, f64, f64) -> Tried,
    segments: usize,
    (from, to): (f64, f64),
    bends: (f64, f64),
) -> String {
    let mut builds = 0;
    let mut tried = |s: usize, a: f64, b: f64| -> Tried {
        if builds >= REMEDY_BUILDS {
            return Tried::Stop;
        }
        builds += 1;
        build(s, a, b)
    };
    let measured = |flag: &str, r: &TableBound, to_at: f64| {
        format!(
            "{flag} (measured: force {:.1e} of F({to_at}), stiffness {:.1e})",
            r.force, r.stiffness
        )
    };
    // The fewest knots above these that meet it over the whole domain.
    for more in [32, 64, 128].into_iter().filter(|&m| m > segments) {
        if let Tried::Meets(r) = tried(more, from, to) {
            return format!(
                "more knots meet it: {}",
                measured(&format!("--knots {}", more + 1), &r, to)
            );
        }
    }
    // Lower `to`, and raise `from`: each a remedy of its own.
    let mut found = Vec::new();
    for lower_to in [true, false] {
        let Some((x, r)) = narrow_one_end(&mut tried, segments, (from, to), bends, lower_to) else {
            continue;
        };
        found.push(if lower_to {
            measured(&format!("mccs table --to {x}"), &r, x)
        } else {
            measured(&format!("mccs table --from {x}"), &r, to)
        });
    }
    if !found.is_empty() {
        return format!("a narrower domain meets it: {}", found.join(" or "));
    }
    let knots = if segments < 128 {
        "neither more knots nor a"
    } else {
        "no"
    };
    format!("{knots} narrower domain it tried (mccs table: lowering --to, raising --from) meets it")
}

/// The narrowest step of one end of the domain (`to` lowered, or `from` raised) that
/// meets the bound, by sixths of the span where the law bends, then halved: the end's
/// value and its measured bound, or `None` where no step met it.
fn narrow_one_end(
    tried: &mut dyn FnMut(usize, f64, f64) -> Tried,
    segments: usize,
    (from, to): (f64, f64),
    bends: (f64, f64),
    lower_to: bool,
) -> Option<(f64, TableBound)> {
    let (bends_from, bends_to) = (from.max(bends.0), to.min(bends.1));
    let span = bends_to - bends_from;
    // The bend's end first, where the domain reaches past it.
    let (end, start) = if lower_to {
        (to, bends_to)
    } else {
        (from, bends_from)
    };
    let first = if start == end { 1 } else { 0 };
    let sign = if lower_to { -1.0 } else { 1.0 };
    let at = |x: f64| {
        let r = if lower_to {
            (x * 1000.0).floor()
        } else {
            (x * 1000.0).ceil()
        };
        r / 1000.0
    };
    let domain = |x: f64| if lower_to { (from, x) } else { (x, to) };
    let mut last_bad = end;
    let mut good = None;
    for k in first..STEPS {
        let x = at(start + sign * span * k as f64 / STEPS as f64);
        if x == last_bad {
            continue;
        }
        let (a, b) = domain(x);
        match tried(segments, a, b) {
            Tried::Meets(r) => {
                good = Some((x, r));
                break;
            }
            Tried::Misses => last_bad = x,
            Tried::Stop => break,
        }
    }
    let (mut x, mut r) = good?;
    // Halve the step between the last that missed and the first that met.
    for _ in 0..HALVINGS {
        let mid = at(0.5 * (x + last_bad));
        if mid == x || mid == last_bad {
            break;
        }
        let (a, b) = domain(mid);
        match tried(segments, a, b) {
            Tried::Meets(m) => (x, r) = (mid, m),
            Tried::Misses => last_bad = mid,
            Tried::Stop => break,
        }
    }
    Some((x, r))
}

#[cfg(test)]
mod tests {
    use super::{search, Tried, REMEDY_BUILDS};
    use mccs::TableBound;

    const MET: TableBound = TableBound {
        force: 1e-6,
        stiffness: 1e-4,
    };

    /// Runs [`search`] with `meets(segments, from, to)` as the builder, recording each
    /// build: the message and the builds.
    fn run(
        segments: usize,
        domain: (f64, f64),
        meets: impl Fn(usize, f64, f64) -> bool,
    ) -> (String, Vec<(usize, f64, f64, bool)>) {
        let mut log = Vec::new();
        let msg = search(
            |s, a, b| {
                let ok = meets(s, a, b);
                log.push((s, a, b, ok));
                if ok {
                    Tried::Meets(MET)
                } else {
                    Tried::Misses
                }
            },
            segments,
            domain,
            (0.2, 0.8),
        );
        (msg, log)
    }

    /// The value after `flag` in `msg`.
    fn value(msg: &str, flag: &str) -> Option<f64> {
        msg.split(flag).nth(1)?.split(' ').next()?.parse().ok()
    }

    /// Every remedy named is a build that met the bound, with that very value; the
    /// builds stay within their budget; the domain found is within one last step of the
    /// widest that meets.
    #[test]
    fn a_named_remedy_is_a_table_it_built_and_measured() {
        for (cut_to, cut_from) in [(0.6, 0.3), (0.79, 0.21), (0.35, 0.65), (0.5, 0.5)] {
            let meets = |_: usize, a: f64, b: f64| b <= cut_to || a >= cut_from;
            let (msg, log) = run(128, (-0.5, 0.95), meets);
            assert!(log.len() <= REMEDY_BUILDS, "{msg}");
            let to = value(&msg, "--to ").unwrap();
            let from = value(&msg, "--from ").unwrap();
            assert!(log.contains(&(128, -0.5, to, true)), "{msg} {log:?}");
            assert!(log.contains(&(128, from, 0.95, true)), "{msg} {log:?}");
            // Sixths of the bend (0.6 wide), halved three times: within 0.0125 + 0.001.
            assert!(to <= cut_to && to > cut_to - 0.014, "{msg}");
            assert!(from >= cut_from && from < cut_from + 0.014, "{msg}");
        }
    }

    /// The fewest knots that meet the bound over the whole domain come first.
    #[test]
    fn more_knots_come_first_and_the_fewest() {
        let (msg, log) = run(16, (-0.5, 0.95), |s, _, _| s >= 64);
        assert!(
            msg.starts_with("more knots meet it: --knots 65 (measured: "),
            "{msg}"
        );
        assert_eq!(log.len(), 2);
    }

    /// Nothing meets: it says so, within its budget, and names no value.
    #[test]
    fn where_nothing_meets_it_says_so() {
        for segments in [16, 128] {
            let (msg, log) = run(segments, (-0.5, 0.95), |_, _, _| false);
            assert!(log.len() <= REMEDY_BUILDS);
            assert!(
                !msg.contains("--to ") || msg.contains("lowering --to"),
                "{msg}"
            );
            assert!(
                msg.ends_with(
                    "narrower domain it tried (mccs table: lowering --to, raising --from) meets it"
                ),
                "{msg}"
            );
            assert_eq!(
                msg.starts_with("neither more knots"),
                segments < 128,
                "{msg}"
            );
        }
    }

    /// A domain reaching far past the bend steps across the bend, from its end.
    #[test]
    fn a_wide_domain_steps_across_the_bend() {
        let (msg, log) = run(128, (-100.0, 100.0), |_, _, b| b <= 0.5);
        assert_eq!(log[0], (128, -100.0, 0.8, false));
        let to = value(&msg, "--to ").unwrap();
        assert!(to <= 0.5 && to > 0.486, "{msg}");
    }
}
