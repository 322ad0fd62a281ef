//! `docs/architecture.md` against the code: every module of every crate (the core, the
//! link, the firmware, the board, the client, the host) has a row, every row names a
//! module that exists, each module imports only what its row allows — an item imported
//! through the crate's root (`crate::Controller`) counted as the module that defines
//! it — and the modules' imports form no circle.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The rows of the module table under `heading`: module → the sibling modules it may
/// import (`None`: any, the row says it formats other types).
fn rows(doc: &str, heading: &str) -> BTreeMap<String, Option<BTreeSet<String>>> {
    let section = doc
        .split("\n## ")
        .find(|s| s.starts_with(heading))
        .unwrap_or_else(|| panic!("docs/architecture.md: no section {heading}"));
    let mut out = BTreeMap::new();
    for line in section.lines().filter(|l| l.starts_with("| `")) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let (first, last) = (cells[1], cells[cells.len() - 2]);
        let allowed = if last.contains("the types it formats")
            || last.contains("all of the above")
            || last.contains("everything")
        {
            None
        } else {
            Some(
                last.split('`')
                    .skip(1)
                    .step_by(2)
                    .map(|m| m.split("::").next().unwrap_or(m).to_string())
                    .collect(),
            )
        };
        for name in first.split('`').skip(1).step_by(2) {
            let module = name
                .trim_start_matches("bin/")
                .split(['/', '.'])
                .next()
                .unwrap_or(name);
            out.insert(module.to_string(), allowed.clone());
        }
    }
    out
}

/// Every `.rs` file under `dir`.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(files(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    out
}

/// The top-level modules a file refers to through `crate::…` (in `use` lists too),
/// outside its unit tests (`#[cfg(test)] mod tests`).
fn imports(text: &str) -> BTreeSet<String> {
    let text = text.split("#[cfg(test)]\nmod tests").next().unwrap_or(text);
    let mut out = BTreeSet::new();
    let code: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n");
    let mut rest = code.as_str();
    while let Some(i) = rest.find("crate::") {
        rest = &rest[i + 7..];
        if let Some(list) = rest.strip_prefix('{') {
            let end = list.find('}').unwrap_or(list.len());
            for item in list[..end].split(',') {
                let m: String = item
                    .trim()
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !m.is_empty() {
                    out.insert(m);
                }
            }
        } else {
            let m: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            out.insert(m);
        }
    }
    out
}

/// The items a crate's root re-exports (`pub use module::{A, B}`), by the module that
/// defines them.
fn reexports(src: &Path) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let text = std::fs::read_to_string(src.join("lib.rs")).unwrap_or_default();
    let flat = text.replace('\n', " ");
    let mut rest = flat.as_str();
    while let Some(i) = rest.find("pub use ") {
        rest = &rest[i + 8..];
        let end = rest.find(';').unwrap_or(rest.len());
        let stmt = rest[..end].trim();
        rest = &rest[end..];
        let Some((module, items)) = stmt.split_once("::") else {
            continue;
        };
        let items = items.trim().trim_start_matches('{').trim_end_matches('}');
        for item in items.split(',') {
            let name = item.trim().rsplit("::").next().unwrap_or("").trim();
            if !name.is_empty() && name.chars().next().is_some_and(char::is_uppercase) {
                out.insert(name.to_string(), module.trim().to_string());
            }
        }
    }
    out
}

/// Checks one crate's `src` against its section; returns its module graph. Rows in
/// `outside` name what is not under `src` (the host's `tests/`).
fn check_crate(src: &Path, heading: &str) -> BTreeMap<String, BTreeSet<String>> {
    check_crate_but(src, heading, &[])
}

fn check_crate_but(
    src: &Path,
    heading: &str,
    outside: &[&str],
) -> BTreeMap<String, BTreeSet<String>> {
    let doc = std::fs::read_to_string(root().join("docs/architecture.md")).unwrap();
    let mut table = rows(&doc, heading);
    for o in outside {
        table.remove(*o);
    }
    let items = reexports(src);
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in files(src) {
        let rel = f.strip_prefix(src).unwrap();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        // (The crate's root; a file compiled for unit tests only, `test_*.rs`.)
        let name = f.file_name().unwrap_or_default().to_string_lossy();
        if first == "lib.rs" || first == "main.rs" || name.starts_with("test_") {
            continue;
        }
        let module = first
            .trim_start_matches("bin")
            .trim_end_matches(".rs")
            .to_string();
        let module = if module.is_empty() {
            // A bin: its own file or folder name.
            let name = rel
                .components()
                .nth(1)
                .unwrap()
                .as_os_str()
                .to_string_lossy();
            name.trim_end_matches(".rs").to_string()
        } else {
            module
        };
        let allowed = table.get(&module).unwrap_or_else(|| {
            panic!(
                "{}: no row for module `{module}` in docs/architecture.md ({heading})",
                f.display()
            )
        });
        let text = std::fs::read_to_string(&f).unwrap();
        let deps: BTreeSet<String> = imports(&text)
            .into_iter()
            .map(|m| items.get(&m).cloned().unwrap_or(m))
            .filter(|m| *m != module && table.contains_key(m))
            .collect();
        if let Some(allowed) = allowed {
            for d in &deps {
                assert!(
                    allowed.contains(d),
                    "{}: imports `{d}`, which its row in docs/architecture.md does not allow",
                    f.display()
                );
            }
        }
        graph.entry(module).or_default().extend(deps);
    }
    for module in table.keys() {
        assert!(
            graph.contains_key(module),
            "docs/architecture.md ({heading}): `{module}` names no module under {}",
            src.display()
        );
    }
    graph
}

/// A circle in `graph`, if there is one.
fn circle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(i) = path.iter().position(|p| p == n) {
            return Some(path[i..].to_vec());
        }
        if done.contains(n) {
            return None;
        }
        path.push(n.to_string());
        for d in graph.get(n).into_iter().flatten() {
            if let Some(c) = visit(d, graph, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(n.to_string());
        None
    }
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|n| visit(n, graph, &mut Vec::new(), &mut done))
}

#[test]
fn the_core_matches_its_drawing_and_has_no_circle() {
    let graph = check_crate(&root().join("src"), "The core");
    assert_eq!(circle(&graph), None, "import circle in the core");
}

#[test]
fn the_board_crate_matches_its_drawing_and_has_no_circle() {
    let graph = check_crate(&root().join("boards/f405/src"), "The board firmware");
    assert_eq!(circle(&graph), None, "import circle in the board crate");
}

#[test]
fn the_firmware_crate_matches_its_drawing_and_has_no_circle() {
    let graph = check_crate(&root().join("firmware/src"), "The device layer");
    assert_eq!(circle(&graph), None, "import circle in the firmware crate");
}

#[test]
fn the_link_crate_matches_its_drawing_and_has_no_circle() {
    let graph = check_crate(&root().join("link/src"), "The link's protocol");
    assert_eq!(circle(&graph), None, "import circle in the link crate");
}

#[test]
fn the_client_crate_matches_its_drawing_and_has_no_circle() {
    let graph = check_crate(&root().join("client/src"), "The scene's library");
    assert_eq!(circle(&graph), None, "import circle in the client crate");
}

#[test]
fn the_host_crate_matches_its_drawing_and_has_no_circle() {
    let graph = check_crate_but(&root().join("host-tests/src"), "The host", &["tests"]);
    assert_eq!(circle(&graph), None, "import circle in the host crate");
}

/// An item imported through a crate's root counts as its module: `crate::Controller`
/// is `controller`.
#[test]
fn items_through_the_root_count_as_their_module() {
    let items = reexports(&root().join("firmware/src"));
    assert_eq!(
        items.get("Controller").map(String::as_str),
        Some("controller")
    );
    assert_eq!(items.get("Mailbox").map(String::as_str), Some("mailbox"));
    assert_eq!(items.get("Slot").map(String::as_str), Some("slot"));
}

#[test]
fn the_circle_finder_finds_circles() {
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    g.entry("a".into()).or_default().insert("b".into());
    g.entry("b".into()).or_default().insert("c".into());
    g.entry("c".into()).or_default();
    assert_eq!(circle(&g), None);
    g.entry("c".into()).or_default().insert("a".into());
    assert!(circle(&g).is_some());
}

/// The spring loops read every edge's nodes without a bounds check, resting on
/// `Topology::add_edge` being the only writer of an edge's ends: no function in the core
/// hands out a mutable edge (returns `&mut Edge` or `&mut [Edge]`) or writes an edge's
/// end.
#[test]
fn only_add_edge_writes_an_edges_ends() {
    let src = root().join("src");
    for f in files(&src) {
        let text = std::fs::read_to_string(&f).unwrap();
        for (i, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            let hands_out = ["-> &mut Edge", "-> &mut [Edge]", "Option<&mut Edge>"]
                .iter()
                .any(|t| code.contains(t));
            // `e.a = …` or `edge.b = …`, not a comparison (`e.b == GROUND`).
            let writes_end = ["e.a", "e.b", "edge.a", "edge.b"].iter().any(|end| {
                code.match_indices(end).any(|(at, _)| {
                    let rest = code[at + end.len()..].trim_start();
                    rest.starts_with('=') && !rest.starts_with("==")
                })
            });
            assert!(
                !hands_out && !writes_end,
                "{}:{}: {line}",
                f.display(),
                i + 1
            );
        }
    }
}

/// The `unsafe` blocks of the firmware and the board: at most 15, each argued by a
/// `// SAFETY:` comment in the lines just above it (issue 59: one pattern for `'static`
/// buffers, `Slot`, and no hand-rolled ones).
#[test]
fn the_firmware_s_unsafe_blocks_are_few_and_each_argued() {
    let mut blocks = Vec::new();
    for dir in ["firmware/src", "boards"] {
        for path in files(&root().join(dir)) {
            let text = std::fs::read_to_string(&path).unwrap();
            let lines: Vec<&str> = text.lines().collect();
            for (i, line) in lines.iter().enumerate() {
                if line.trim_start().starts_with("//") || !line.contains("unsafe {") {
                    continue;
                }
                let argued = lines[i.saturating_sub(4)..i]
                    .iter()
                    .any(|l| l.contains("// SAFETY:"));
                blocks.push((format!("{}:{}", path.display(), i + 1), argued));
            }
        }
    }
    let unargued: Vec<&String> = blocks.iter().filter(|b| !b.1).map(|b| &b.0).collect();
    assert!(
        unargued.is_empty(),
        "unsafe without a SAFETY comment: {unargued:?}"
    );
    assert!(
        blocks.len() <= 15,
        "{} unsafe blocks in firmware/ and boards/ (at most 15): {:?}",
        blocks.len(),
        blocks.iter().map(|b| &b.0).collect::<Vec<_>>()
    );
}

/// The board's platform facts come from `build.rs` as cfgs (`qemu_run`, `link_on`,
/// `simulated_plant`, …), not as feature tests scattered over the code: at most 8
/// `#[cfg(feature` in `boards/`.
#[test]
fn the_board_tests_few_features_directly() {
    let count: usize = files(&root().join("boards"))
        .iter()
        .map(|p| {
            std::fs::read_to_string(p)
                .unwrap()
                .matches("cfg(feature")
                .count()
        })
        .sum();
    assert!(count <= 8, "{count} `cfg(feature` in boards/ (at most 8)");
}

/// The functions of non-test source (`src/`, `firmware/`, `boards/`, `client/`, `link/`,
/// `host-tests/src/`; not `#[cfg(test)]` items nor `test_*.rs` files) and their lengths
/// in lines, from `fn` to its closing brace, each with the few lines above it.
fn function_lengths() -> Vec<(String, usize, String)> {
    let mut out = Vec::new();
    let dirs = [
        "src",
        "firmware/src",
        "boards",
        "client/src",
        "link/src",
        "host-tests/src",
    ];
    for dir in dirs {
        for path in files(&root().join(dir)) {
            let p = path.to_string_lossy();
            if ["/tests/", "/benches/", "/fuzz/", "/examples/"]
                .iter()
                .any(|d| p.contains(d))
            {
                continue;
            }
            // (A file compiled for unit tests only, `test_*.rs`, as in `check_crate_but`.)
            let name = path.file_name().unwrap_or_default().to_string_lossy();
            if name.starts_with("test_") {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            let lines: Vec<&str> = text.lines().collect();
            let mut i = 0;
            while i < lines.len() {
                let l = lines[i].trim_start();
                let skip_test = l.starts_with("#[cfg(test)]");
                let is_fn = !skip_test && is_fn_line(l);
                if !(skip_test || is_fn) {
                    i += 1;
                    continue;
                }
                let first = if skip_test { i + 1 } else { i };
                let (end, braced) = item_end(&lines, first);
                if is_fn && braced {
                    let above = lines[i.saturating_sub(8)..i].join("\n");
                    out.push((format!("{}:{}", path.display(), i + 1), end - i + 1, above));
                }
                i = if braced { end + 1 } else { i + 1 };
            }
        }
    }
    out
}

/// Whether a trimmed line starts a function item.
fn is_fn_line(l: &str) -> bool {
    let mut rest = l;
    for prefix in [
        "pub(crate) ",
        "pub(super) ",
        "pub ",
        "const ",
        "async ",
        "unsafe ",
        "extern \"C\" ",
    ] {
        rest = rest.strip_prefix(prefix).unwrap_or(rest);
    }
    rest.starts_with("fn ")
}

/// The line that closes the item starting at `first` (braces counted, comments aside),
/// and whether it had a body at all.
fn item_end(lines: &[&str], first: usize) -> (usize, bool) {
    let mut depth = 0i32;
    let mut started = false;
    for (j, line) in lines.iter().enumerate().skip(first) {
        let code = line.split("//").next().unwrap_or("");
        depth += code.matches('{').count() as i32 - code.matches('}').count() as i32;
        started |= code.contains('{');
        if started && depth <= 0 {
            return (j, true);
        }
        if !started && code.trim_end().ends_with(';') {
            return (j, false);
        }
    }
    (lines.len() - 1, started)
}

/// Short functions (issue 59): none over 120 lines, and at most 3 over 80, each with a
/// comment above it that says why it stays whole (`Whole on purpose`).
#[test]
fn functions_are_short_and_the_long_ones_say_why() {
    let all = function_lengths();
    assert!(
        all.len() > 1000,
        "the scan found only {} functions",
        all.len()
    );
    let over_120: Vec<_> = all
        .iter()
        .filter(|f| f.1 > 120)
        .map(|f| (&f.0, f.1))
        .collect();
    assert!(
        over_120.is_empty(),
        "functions over 120 lines: {over_120:?}"
    );
    let over_80: Vec<_> = all.iter().filter(|f| f.1 > 80).collect();
    let unexplained: Vec<_> = over_80
        .iter()
        .filter(|f| !f.2.contains("Whole on purpose"))
        .map(|f| (&f.0, f.1))
        .collect();
    assert!(
        unexplained.is_empty(),
        "over 80 lines without a reason: {unexplained:?}"
    );
    assert!(
        over_80.len() <= 3,
        "{} functions over 80 lines (at most 3): {:?}",
        over_80.len(),
        over_80.iter().map(|f| (&f.0, f.1)).collect::<Vec<_>>()
    );
}
