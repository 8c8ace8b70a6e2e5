//! The library's top-level modules (`criterion`, `engine`, `pattern`, `sampling`, `surface`,
//! `topology`, `io`, `verify`, …) form a graph with no cycle: each rule has one home and the
//! data path runs one way down (docs/ARCHITECTURE.md draws it). This test reads the sources,
//! collects every `crate::X` path outside comments, string literals and `#[cfg(test)]` items,
//! and fails naming the cycle when one appears.
//!
//! It is a text scan rather than a `syn` parse to keep the dev-dependencies to the brief's list;
//! the sources are rustfmt-formatted, which keeps the scan simple (see `strip`).

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// Top-level module name → the set of top-level modules its non-test code names.
type Graph = BTreeMap<String, BTreeSet<String>>;

#[test]
fn top_level_modules_have_no_import_cycle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let graph = module_graph(&src);
    assert!(
        graph.len() > 8,
        "expected the library's modules under {}, found {:?}",
        src.display(),
        graph.keys()
    );
    let cycles = strongly_connected(&graph).into_iter().filter(|c| c.len() > 1).collect::<Vec<_>>();
    assert!(
        cycles.is_empty(),
        "top-level modules import each other in a cycle: {}\n(edges: {})",
        cycles.iter().map(|c| format!("{{{}}}", c.join(", "))).collect::<Vec<_>>().join(", "),
        cycles
            .iter()
            .flat_map(|c| c
                .iter()
                .flat_map(|a| graph[a].iter().filter(|b| c.contains(b)).map(move |b| format!("{a} → {b}"))))
            .collect::<Vec<_>>()
            .join(", ")
    );
}

/// The scan itself must see a cycle when there is one and must not see paths in comments,
/// strings or test code — otherwise the test above could pass on a broken scan.
#[test]
fn the_scan_finds_what_it_should_and_only_that() {
    let text = r#"
use crate::engine::Plan; // crate::io in a comment
/* crate::verify in a block comment */
fn f() { let s = "crate::surface"; let c = '{'; crate::pattern::x(); }
use crate::{mesh::Mesh, topology};
#[cfg(test)]
mod tests {
    use crate::scene::Scene;
    fn g<'a>(x: &'a str) -> char { '}' }
}
"#;
    let names: BTreeSet<String> =
        ["engine", "io", "verify", "surface", "pattern", "mesh", "topology", "scene"]
            .iter()
            .map(|s| s.to_string())
            .collect();
    let found = referenced_modules(&strip(text), &names);
    let expected: BTreeSet<String> =
        ["engine", "pattern", "mesh", "topology"].iter().map(|s| s.to_string()).collect();
    assert_eq!(found, expected);

    let mut graph = Graph::new();
    graph.insert("a".into(), ["b".to_string()].into());
    graph.insert("b".into(), ["c".to_string()].into());
    graph.insert("c".into(), ["a".to_string()].into());
    graph.insert("d".into(), ["a".to_string()].into());
    let cycles = strongly_connected(&graph).into_iter().filter(|c| c.len() > 1).collect::<Vec<_>>();
    assert_eq!(cycles, vec![vec!["a".to_string(), "b".to_string(), "c".to_string()]]);
}

fn module_graph(src: &Path) -> Graph {
    let mut names = BTreeSet::new();
    for entry in fs::read_dir(src).unwrap() {
        let path = entry.unwrap().path();
        let stem = path.file_stem().unwrap().to_string_lossy().to_string();
        if path.is_dir() || (path.extension().is_some_and(|e| e == "rs") && stem != "lib") {
            names.insert(stem);
        }
    }
    // `crate::Error` and `crate::Result` are the root's re-exports of `error`.
    let mut graph = Graph::new();
    for name in &names {
        let mut files = Vec::new();
        let dir = src.join(name);
        if dir.is_dir() {
            rust_files(&dir, &mut files);
        } else {
            files.push(src.join(format!("{name}.rs")));
        }
        let mut uses = BTreeSet::new();
        for file in files {
            let text = fs::read_to_string(&file).unwrap();
            if is_test_only_file(&file, src) {
                continue;
            }
            let stripped = strip(&text);
            for used in referenced_modules(&stripped, &names) {
                uses.insert(used);
            }
            if stripped.contains("crate::Error") || stripped.contains("crate::Result") {
                uses.insert("error".into());
            }
        }
        uses.remove(name);
        graph.insert(name.clone(), uses);
    }
    graph
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// A file declared as `#[cfg(test)] mod name;` by its parent is test code.
fn is_test_only_file(file: &Path, src: &Path) -> bool {
    let stem = file.file_stem().unwrap().to_string_lossy().to_string();
    let parent_dir = file.parent().unwrap();
    let candidates = if stem == "mod" {
        let dir_name = parent_dir.file_name().unwrap().to_string_lossy().to_string();
        let up = parent_dir.parent().unwrap();
        vec![
            (up.join(format!("{dir_name}.rs")), dir_name.clone()),
            (up.join("mod.rs"), dir_name.clone()),
            (up.join("lib.rs"), dir_name),
        ]
    } else {
        vec![
            (parent_dir.join("mod.rs"), stem.clone()),
            (parent_dir.with_extension("rs"), stem.clone()),
            (src.join("lib.rs"), stem),
        ]
    };
    candidates.iter().any(|(parent, name)| {
        fs::read_to_string(parent).is_ok_and(|text| {
            let lines: Vec<&str> = text.lines().map(str::trim).collect();
            lines.windows(2).any(|w| {
                w[0] == "#[cfg(test)]"
                    && (w[1] == format!("mod {name};") || w[1] == format!("pub mod {name};"))
            })
        })
    })
}

/// The names in `names` that `text` reaches as `crate::name`, including in `use crate::{a, b::c}`.
fn referenced_modules(text: &str, names: &BTreeSet<String>) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let mut rest = text;
    while let Some(at) = rest.find("crate::") {
        let after = &rest[at + "crate::".len()..];
        if let Some(group) = after.strip_prefix('{') {
            let end = matching_brace(group);
            for item in split_top_level(&group[..end]) {
                let head: String =
                    item.trim().chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                if names.contains(&head) {
                    found.insert(head);
                }
            }
        } else {
            let head: String = after.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            if names.contains(&head) {
                found.insert(head);
            }
        }
        rest = after;
    }
    found
}

fn matching_brace(text: &str) -> usize {
    let mut depth = 0usize;
    for (i, c) in text.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => return i,
            '}' => depth -= 1,
            _ => {}
        }
    }
    text.len()
}

fn split_top_level(text: &str) -> Vec<&str> {
    let (mut parts, mut depth, mut start) = (Vec::new(), 0usize, 0);
    for (i, c) in text.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth = depth.saturating_sub(1),
            ',' if depth == 0 => {
                parts.push(&text[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&text[start..]);
    parts
}

/// The text with comments, string and char literals blanked and `#[cfg(test)]` items removed.
fn strip(text: &str) -> String {
    remove_test_items(&blank_comments_and_literals(text))
}

fn blank_comments_and_literals(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < text.len() {
        let rest = &text[i..];
        let b = rest.as_bytes();
        if rest.starts_with("//") {
            i += rest.find('\n').unwrap_or(rest.len());
        } else if rest.starts_with("/*") {
            i += rest.find("*/").map_or(rest.len(), |e| e + 2);
        } else if let Some(raw) = rest.strip_prefix("r#\"") {
            i += 3 + raw.find("\"#").map_or(raw.len(), |e| e + 2);
            out.push_str("\"\"");
        } else if b[0] == b'"' {
            let mut j = 1;
            while j < b.len() && b[j] != b'"' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            i += (j + 1).min(rest.len());
            out.push_str("\"\"");
        } else if b[0] == b'\'' && b.len() > 3 && b[1] == b'\\' {
            // An escaped char literal: '\n', '\'', '\u{…}'.
            i += 2 + rest[2..].find('\'').map_or(rest.len() - 2, |e| e + 1);
            out.push_str("' '");
        } else if b[0] == b'\'' && rest[1..].chars().nth(1) == Some('\'') {
            // A plain char literal such as '{' (a lifetime has no closing quote after one char).
            i += 1 + rest[1..].chars().next().unwrap().len_utf8() + 1;
            out.push_str("' '");
        } else {
            let c = rest.chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

/// Removes each `#[cfg(test)]` attribute with the item after it: up to its `;` or the end of
/// its balanced `{ … }` (braces are balanced once literals are blanked).
fn remove_test_items(text: &str) -> String {
    const ATTR: &str = "#[cfg(test)]";
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(ATTR) {
        out.push_str(&rest[..at]);
        let item = &rest[at + ATTR.len()..];
        let mut depth = 0usize;
        let mut end = item.len();
        for (k, c) in item.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 {
                        end = k + 1;
                        break;
                    }
                }
                ';' if depth == 0 => {
                    end = k + 1;
                    break;
                }
                _ => {}
            }
        }
        rest = &item[end..];
    }
    out.push_str(rest);
    out
}

/// Tarjan's strongly connected components, each sorted, in discovery order.
fn strongly_connected(graph: &Graph) -> Vec<Vec<String>> {
    struct State<'g> {
        graph: &'g Graph,
        index: BTreeMap<&'g str, usize>,
        low: BTreeMap<&'g str, usize>,
        stack: Vec<&'g str>,
        on_stack: BTreeSet<&'g str>,
        out: Vec<Vec<String>>,
    }
    fn visit<'g>(s: &mut State<'g>, v: &'g str) {
        let n = s.index.len();
        s.index.insert(v, n);
        s.low.insert(v, n);
        s.stack.push(v);
        s.on_stack.insert(v);
        for w in s.graph.get(v).into_iter().flatten() {
            let w = w.as_str();
            if !s.graph.contains_key(w) {
                continue;
            }
            if !s.index.contains_key(w) {
                visit(s, w);
                let low = s.low[v].min(s.low[w]);
                s.low.insert(v, low);
            } else if s.on_stack.contains(w) {
                let low = s.low[v].min(s.index[w]);
                s.low.insert(v, low);
            }
        }
        if s.low[v] == s.index[v] {
            let mut component = Vec::new();
            loop {
                let w = s.stack.pop().unwrap();
                s.on_stack.remove(w);
                component.push(w.to_string());
                if w == v {
                    break;
                }
            }
            component.sort();
            s.out.push(component);
        }
    }
    let mut s = State {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !s.index.contains_key(v.as_str()) {
            visit(&mut s, v);
        }
    }
    s.out
}

/// Prints the graph (`cargo test --test module_graph -- --nocapture print`): handy when
/// moving a rule, to see who depends on what.
#[test]
fn print_module_graph() {
    let graph = module_graph(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    for (module, uses) in &graph {
        println!("{module} → {}", uses.iter().cloned().collect::<Vec<_>>().join(", "));
    }
}
