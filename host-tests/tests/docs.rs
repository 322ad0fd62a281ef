//! The docs against the code: the tables that restate what the code defines are
//! regenerated here and must match what the docs say.

use mccs::ParamKey;
use std::path::Path;

fn doc(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../docs")
        .join(name);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The text between `<!-- NAME:begin -->` and `<!-- NAME:end -->`.
fn block<'a>(text: &'a str, name: &str) -> &'a str {
    let begin = format!("<!-- {name}:begin -->\n");
    let end = format!("<!-- {name}:end -->");
    let start = text.find(&begin).expect("begin marker") + begin.len();
    let stop = text[start..].find(&end).expect("end marker") + start;
    &text[start..stop]
}

#[test]
fn the_parameter_schema_in_model_md_is_param_key() {
    let mut table = String::from("| key | symbol | unit | required |\n|---|---|---|---|\n");
    for k in ParamKey::ALL {
        let (symbol, unit) = k.symbol_and_unit();
        let required = if k.required() { "yes" } else { "no" };
        table.push_str(&format!(
            "| `{}` | {symbol} | {unit} | {required} |\n",
            k.as_str()
        ));
    }
    assert_eq!(
        block(&doc("model.md"), "schema"),
        table,
        "docs/model.md's schema table is stale; it should read:\n{table}"
    );
}

#[test]
fn no_source_file_cites_a_document_outside_the_repository() {
    fn walk(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, out);
            } else if p
                .extension()
                .is_some_and(|x| x == "rs" || x == "sh" || x == "py")
            {
                out.push(p);
            }
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    for d in [
        "src",
        "firmware/src",
        "host-tests/src",
        "host-tests/tests",
        "scripts",
    ] {
        walk(&root.join(d), &mut files);
    }
    // The starting spec, outside the repository: its name, spelled so that this file
    // does not cite it.
    let outside = ["MODEL", ".md"].concat();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for (n, line) in text.lines().enumerate() {
            assert!(
                !line.contains(&outside),
                "{}:{}: cites {outside}",
                f.display(),
                n + 1
            );
        }
        for cited in text.split("docs/").skip(1) {
            let name: String = cited
                .chars()
                .take_while(|c| c.is_alphanumeric() || matches!(c, '-' | '_' | '.' | '/'))
                .collect();
            if let Some(name) = name.strip_suffix('.').or(Some(&name)) {
                if name.ends_with(".md") {
                    assert!(
                        root.join("docs").join(name).exists(),
                        "{}: cites docs/{name}, which does not exist",
                        f.display()
                    );
                }
            }
        }
    }
}

/// GitHub's anchor for a heading: lower case, punctuation but `-` and `_` dropped,
/// spaces as `-`.
fn anchor_of(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// A page's text without its fenced blocks and code spans (links there are code).
fn prose(text: &str) -> String {
    let mut out = String::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        let mut in_code = false;
        for c in line.chars() {
            if c == '`' {
                in_code = !in_code;
            } else if !in_code {
                out.push(c);
            }
        }
        out.push('\n');
    }
    out
}

/// The anchors of a page's headings.
fn anchors(text: &str) -> Vec<String> {
    let mut fenced = false;
    text.lines()
        .filter(|l| {
            if l.trim_start().starts_with("```") {
                fenced = !fenced;
            }
            !fenced && l.starts_with('#')
        })
        .map(|l| anchor_of(l.trim_start_matches('#')))
        .collect()
}

/// Every relative link of README.md and docs/ (`[text](path)`, `[text](path#anchor)`,
/// `[text](#anchor)`) names a file that exists and, with an anchor, a heading of it.
#[test]
fn every_relative_link_in_the_docs_resolves() {
    let link = |s: &str| -> Vec<String> {
        let mut out = Vec::new();
        let mut rest = s;
        while let Some(i) = rest.find("](") {
            rest = &rest[i + 2..];
            if let Some(end) = rest.find(')') {
                out.push(rest[..end].trim().to_string());
            }
        }
        out
    };
    let mut checked = 0;
    for page in super::doc_snippets::doc_pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for target in link(&prose(&text)) {
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            checked += 1;
            let (path, anchor) = match target.split_once('#') {
                Some((p, a)) => (p, Some(a)),
                None => (target.as_str(), None),
            };
            let file = if path.is_empty() {
                page.clone()
            } else {
                page.parent().unwrap().join(path)
            };
            assert!(
                file.exists(),
                "{}: the link ({target}) names {}, which does not exist",
                page.display(),
                file.display()
            );
            if let Some(a) = anchor {
                let heads = anchors(&std::fs::read_to_string(&file).unwrap());
                assert!(
                    heads.iter().any(|h| h == a),
                    "{}: the link ({target}) names no heading of {}",
                    page.display(),
                    file.display()
                );
            }
        }
    }
    assert!(checked > 20, "{checked} links checked: the scan is broken");
}
