//! The module graph of `controller/src` has no cycle (issue 20): each module's
//! `crate::…` paths, read from its source (comments left out; a name the crate
//! root re-exports, `crate::Sample`, is resolved through `lib.rs`), are its
//! edges. A cycle fails the test, naming the modules on it and the line that
//! closes it, so a new one is found the day it is written.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Code without comments: full-line comments dropped, a trailing `// …` cut (outside strings).
fn code_lines(text: &str) -> Vec<(usize, String)> {
    text.lines()
        .enumerate()
        .filter_map(|(i, line)| {
            let trimmed = line.trim_start();
            if trimmed.starts_with("//") {
                return None;
            }
            let mut in_string = false;
            let bytes = line.as_bytes();
            let mut end = line.len();
            for j in 0..bytes.len() {
                match bytes[j] {
                    b'"' if j == 0 || bytes[j - 1] != b'\\' => in_string = !in_string,
                    b'/' if !in_string && bytes.get(j + 1) == Some(&b'/') => {
                        end = j;
                        break;
                    }
                    _ => {}
                }
            }
            Some((i + 1, line[..end].to_string()))
        })
        .collect()
}

/// The identifiers that follow `crate::` on a line.
fn crate_paths(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = line;
    while let Some(at) = rest.find("crate::") {
        let after = &rest[at + "crate::".len()..];
        let name: String = after.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
        if !name.is_empty() {
            out.push(name);
        } else if after.starts_with('{') {
            // `crate::{a, b::C}`: each first segment.
            let inner = &after[1..after.find('}').unwrap_or(after.len())];
            for part in inner.split(',') {
                let first: String = part.trim().chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                if !first.is_empty() {
                    out.push(first);
                }
            }
        }
        rest = after;
    }
    out
}

#[test]
fn the_controller_modules_form_no_cycle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut modules = BTreeSet::new();
    for entry in std::fs::read_dir(&src).unwrap() {
        let path = entry.unwrap().path();
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        if path.extension().is_some_and(|e| e == "rs") && stem != "lib" && stem != "main" {
            modules.insert(stem);
        }
    }
    assert!(modules.len() >= 10 && modules.contains("law") && modules.contains("registry"), "{modules:?}");

    // What the crate root re-exports: `pub use module::{A, b}` makes `crate::A` module's.
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    let mut reexported: BTreeMap<String, String> = BTreeMap::new();
    for (_, line) in code_lines(&lib) {
        let Some(rest) = line.trim().strip_prefix("pub use ") else { continue };
        let Some((module, names)) = rest.split_once("::") else { continue };
        for name in names.trim_end_matches(';').trim_matches(|c| c == '{' || c == '}').split(',') {
            let name = name.trim();
            if !name.is_empty() {
                reexported.insert(name.to_string(), module.to_string());
            }
        }
    }

    // Edges, with the first line that makes each.
    let mut edges: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    for module in &modules {
        let text = std::fs::read_to_string(src.join(format!("{module}.rs"))).unwrap();
        let out = edges.entry(module.clone()).or_default();
        for (n, line) in code_lines(&text) {
            for name in crate_paths(&line) {
                let target = if modules.contains(&name) {
                    name.clone()
                } else if let Some(m) = reexported.get(&name) {
                    m.clone()
                } else {
                    panic!("{module}.rs:{n}: crate::{name} is neither a module nor re-exported by lib.rs");
                };
                if &target != module {
                    out.entry(target).or_insert_with(|| format!("{module}.rs:{n}: {}", line.trim()));
                }
            }
        }
    }

    // Depth-first search for a back edge.
    fn visit(
        m: &str,
        edges: &BTreeMap<String, BTreeMap<String, String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(at) = path.iter().position(|p| p == m) {
            let mut cycle = path[at..].to_vec();
            cycle.push(m.to_string());
            return Some(cycle);
        }
        if done.contains(m) {
            return None;
        }
        path.push(m.to_string());
        for next in edges.get(m).into_iter().flat_map(|e| e.keys()) {
            if let Some(cycle) = visit(next, edges, path, done) {
                return Some(cycle);
            }
        }
        path.pop();
        done.insert(m.to_string());
        None
    }
    let mut done = BTreeSet::new();
    for m in &modules {
        if let Some(cycle) = visit(m, &edges, &mut Vec::new(), &mut done) {
            let why: Vec<String> = cycle.windows(2).map(|w| edges[&w[0]][&w[1]].clone()).collect();
            panic!("module cycle in controller/src: {}\n{}", cycle.join(" -> "), why.join("\n"));
        }
    }
}
