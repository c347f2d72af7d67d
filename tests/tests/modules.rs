//! No module cycle in `plant/src`, `plant/sim/src` or `controller/src`: at every level of each library's module
//! tree, the modules under one parent import each other without a cycle (`sweep` and
//! `ensemble` used to import each other, and the laws the registry that lists them).
//!
//! Each library is read from its `lib.rs` down its `mod` declarations (inline modules
//! included), tokenised with `proc-macro2` (comments and string contents are not paths). Every
//! path that starts at `crate::`, `$crate::`, `super::` or `self::` — in a `use` tree or in code
//! — is resolved to the module it names (through every module's `use` items, re-exports
//! included, so `crate::ControlLaw` is `law` and, under `config`, `super::Rotor` is `rotor`). A path from module `a::x::…` to `a::y::…` is an edge `x → y`
//! under parent `a`; a path between a module and its own ancestor or descendant is not (a
//! parent re-exporting its children, a child reading its parent's types). The test fails
//! naming each cycle.

use proc_macro2::{Delimiter, TokenStream, TokenTree};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::str::FromStr;

type ModPath = Vec<String>;

/// One library: its modules and the paths each one uses.
#[derive(Default)]
struct Library {
    modules: BTreeSet<ModPath>,
    /// Every module's `use` items (re-exports and imports): (module, name) → the absolute path
    /// the name comes from, so that `super::Rotor` through `config`'s `pub use rotor::Rotor` is
    /// `config::rotor` (issue 41: `config::rotor` and `config::validate` once imported each
    /// other through their parent's re-exports, unseen).
    reexports: BTreeMap<(ModPath, String), ModPath>,
    /// (module, a path it uses, already made absolute).
    uses: Vec<(ModPath, ModPath)>,
}

/// The file of module `name` declared in the file `from` (module path `at`).
fn module_file(from: &Path, at_root_of_dir: bool, name: &str) -> Option<PathBuf> {
    let dir = if at_root_of_dir { from.parent()?.to_path_buf() } else { from.parent()?.join(from.file_stem()?) };
    [dir.join(format!("{name}.rs")), dir.join(name).join("mod.rs")].into_iter().find(|p| p.exists())
}

/// Splits a brace group of a `use` tree at its top-level commas.
fn split_commas(stream: TokenStream) -> Vec<Vec<TokenTree>> {
    let mut parts = vec![Vec::new()];
    for t in stream {
        match &t {
            TokenTree::Punct(p) if p.as_char() == ',' => parts.push(Vec::new()),
            _ => parts.last_mut().expect("one part").push(t),
        }
    }
    parts.into_iter().filter(|p| !p.is_empty()).collect()
}

/// The paths a path expression or `use` tree starting at `tokens[0]` names: `a::b::{c, d::e}`
/// gives `a::b::c` and `a::b::d::e`.
fn paths(tokens: &[TokenTree]) -> Vec<ModPath> {
    let mut prefix = ModPath::new();
    let mut i = 0;
    while i < tokens.len() {
        match &tokens[i] {
            TokenTree::Ident(id) => prefix.push(id.to_string()),
            TokenTree::Group(g) if g.delimiter() == Delimiter::Brace => {
                return split_commas(g.stream())
                    .iter()
                    .flat_map(|part| paths(part))
                    .map(|tail| prefix.iter().cloned().chain(tail).collect())
                    .collect();
            }
            _ => break,
        }
        // Continue only through `::`.
        match (tokens.get(i + 1), tokens.get(i + 2)) {
            (Some(TokenTree::Punct(a)), Some(TokenTree::Punct(b))) if a.as_char() == ':' && b.as_char() == ':' => {
                i += 3
            }
            _ => break,
        }
    }
    vec![prefix]
}

impl Library {
    fn read(src: &Path) -> Library {
        let mut lib = Library::default();
        lib.read_file(&src.join("lib.rs"), &[], true);
        lib
    }

    fn read_file(&mut self, file: &Path, at: &[String], dir_root: bool) {
        let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let tokens = TokenStream::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        self.modules.insert(at.to_vec());
        self.read_tokens(tokens, file, at, dir_root);
    }

    fn read_tokens(&mut self, tokens: TokenStream, file: &Path, at: &[String], dir_root: bool) {
        let tokens: Vec<TokenTree> = tokens.into_iter().collect();
        for (i, t) in tokens.iter().enumerate() {
            match t {
                TokenTree::Ident(id) if id == "mod" => {
                    let Some(TokenTree::Ident(name)) = tokens.get(i + 1) else { continue };
                    let mut path = at.to_vec();
                    path.push(name.to_string());
                    match tokens.get(i + 2) {
                        Some(TokenTree::Group(g)) if g.delimiter() == Delimiter::Brace => {
                            self.modules.insert(path.clone());
                            self.read_tokens(g.stream(), file, &path, dir_root);
                            continue;
                        }
                        Some(TokenTree::Punct(p)) if p.as_char() == ';' => {
                            if let Some(child) = module_file(file, dir_root, &name.to_string()) {
                                let is_mod_rs = child.file_name().is_some_and(|n| n == "mod.rs");
                                self.read_file(&child, &path, is_mod_rs);
                            }
                        }
                        _ => {}
                    }
                }
                TokenTree::Ident(id) if (id == "crate" || id == "super" || id == "self") => {
                    // `self` alone (a method receiver) is no path; `crate::`, `super::`, `self::` are.
                    let followed = matches!(
                        (tokens.get(i + 1), tokens.get(i + 2)),
                        (Some(TokenTree::Punct(a)), Some(TokenTree::Punct(b))) if a.as_char() == ':' && b.as_char() == ':'
                    );
                    let after_colons = i >= 2
                        && matches!(&tokens[i - 1], TokenTree::Punct(p) if p.as_char() == ':')
                        && matches!(&tokens[i - 2], TokenTree::Punct(p) if p.as_char() == ':');
                    if !followed || after_colons {
                        continue; // mid-path (`super::super::x` is read from its first `super`)
                    }
                    for p in paths(&tokens[i..]) {
                        if let Some(abs) = absolute(at, &p) {
                            self.uses.push((at.to_vec(), abs));
                        }
                    }
                }
                TokenTree::Ident(id) if id == "use" => {
                    // A `use` item at this module: where each name it brings in comes from.
                    for p in paths(&tokens[i + 1..]) {
                        let Some(name) = p.last().filter(|_| p.len() > 1) else { continue };
                        let target = match p[0].as_str() {
                            "crate" | "super" | "self" => absolute(at, &p),
                            // A path from a child module of this one (2018 paths), else an
                            // outside crate's (not this library's).
                            first => self
                                .declared_child(file, dir_root, first)
                                .then(|| at.iter().chain(&p).cloned().collect()),
                        };
                        if let Some(target) = target {
                            self.reexports.insert((at.to_vec(), name.clone()), target);
                        }
                    }
                }
                TokenTree::Group(g) => self.read_tokens(g.stream(), file, at, dir_root),
                _ => {}
            }
        }
    }

    /// Whether module `name` is declared in `file` (a child of the module being read).
    fn declared_child(&self, file: &Path, dir_root: bool, name: &str) -> bool {
        module_file(file, dir_root, name).is_some()
    }

    /// The module a path names: its longest prefix that is a module, then through the `use`
    /// items of that module (a re-export, at any level) to where the next name comes from.
    fn module_of(&self, path: &[String]) -> ModPath {
        self.module_of_depth(path, 0)
    }

    fn module_of_depth(&self, path: &[String], depth: usize) -> ModPath {
        let mut best = ModPath::new();
        for n in 1..=path.len() {
            if self.modules.contains(&path[..n]) {
                best = path[..n].to_vec();
            }
        }
        if depth < 16 {
            if let Some(next) = path.get(best.len()) {
                if let Some(target) = self.reexports.get(&(best.clone(), next.clone())) {
                    let followed: ModPath = target.iter().chain(&path[best.len() + 1..]).cloned().collect();
                    if followed != path {
                        return self.module_of_depth(&followed, depth + 1);
                    }
                }
            }
        }
        best
    }

    /// Edges between sibling modules, by parent.
    fn edges(&self) -> BTreeMap<ModPath, BTreeSet<(String, String)>> {
        let mut out: BTreeMap<ModPath, BTreeSet<(String, String)>> = BTreeMap::new();
        for (from, path) in &self.uses {
            let to = self.module_of(path);
            let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
            if common < from.len() && common < to.len() {
                out.entry(from[..common].to_vec()).or_default().insert((from[common].clone(), to[common].clone()));
            }
        }
        out
    }
}

/// `crate::a::b`, `super::a`, `self::a` from module `at`, as a path from the crate root.
fn absolute(at: &[String], path: &[String]) -> Option<ModPath> {
    let mut base: ModPath = match path.first()?.as_str() {
        "crate" => Vec::new(),
        "self" => at.to_vec(),
        "super" => at.to_vec(),
        _ => return None,
    };
    let mut rest = &path[1..];
    if path[0] == "super" {
        base.pop()?;
        while rest.first().is_some_and(|s| s == "super") {
            base.pop()?;
            rest = &rest[1..];
        }
    }
    Some(base.into_iter().chain(rest.iter().cloned()).collect())
}

/// The cycles of a directed graph (its strongly connected components of more than one node).
fn cycles(edges: &BTreeSet<(String, String)>) -> Vec<Vec<String>> {
    let nodes: BTreeSet<&String> = edges.iter().flat_map(|(a, b)| [a, b]).collect();
    let reach = |from: &String| -> BTreeSet<String> {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.clone()];
        while let Some(n) = stack.pop() {
            for (a, b) in edges {
                if *a == n && seen.insert(b.clone()) {
                    stack.push(b.clone());
                }
            }
        }
        seen
    };
    let reaches: BTreeMap<&String, BTreeSet<String>> = nodes.iter().map(|n| (*n, reach(n))).collect();
    let mut out: Vec<Vec<String>> = Vec::new();
    for n in &nodes {
        let comp: Vec<String> = nodes
            .iter()
            .filter(|m| reaches[*n].contains(**m) && reaches[**m].contains(*n))
            .map(|m| (*m).clone())
            .collect();
        if comp.len() > 1 && !out.contains(&comp) {
            out.push(comp);
        }
    }
    out
}

fn cycles_of(crate_dir: &str) -> Vec<String> {
    let lib = Library::read(&common::workspace_root().join(crate_dir).join("src"));
    assert!(lib.modules.len() > 5, "{crate_dir}: only {:?} read", lib.modules);
    lib.edges()
        .iter()
        .flat_map(|(parent, edges)| {
            let at = if parent.is_empty() { "crate".to_string() } else { parent.join("::") };
            cycles(edges).into_iter().map(move |c| format!("{crate_dir}: under {at}: {}", c.join(" ↔ ")))
        })
        .collect()
}

mod common;

#[test]
fn plant_has_no_module_cycle() {
    let found = cycles_of("plant");
    assert!(found.is_empty(), "module cycles:\n  {}", found.join("\n  "));
}

#[test]
fn plant_sim_has_no_module_cycle() {
    let found = cycles_of("plant/sim");
    assert!(found.is_empty(), "module cycles:\n  {}", found.join("\n  "));
}

#[test]
fn controller_has_no_module_cycle() {
    let found = cycles_of("controller");
    assert!(found.is_empty(), "controller module cycles:\n  {}", found.join("\n  "));
}

#[test]
fn the_reader_finds_a_cycle_and_resolves_paths() {
    let dir = std::env::temp_dir().join(format!("modules-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("a")).unwrap();
    std::fs::create_dir_all(dir.join("d")).unwrap();
    std::fs::write(dir.join("lib.rs"), "pub mod a; pub mod b; mod c; pub mod d; pub use c::Thing;\n// use crate::b;\n")
        .unwrap();
    // A cycle through a parent's re-exports only (issue 41: `config::rotor` and
    // `config::validate` once imported each other so, unseen).
    std::fs::write(dir.join("d/mod.rs"), "mod p; mod q; pub use p::P; pub use self::q::Q;\n").unwrap();
    std::fs::write(dir.join("d/p.rs"), "pub struct P(super::Q);\n").unwrap();
    std::fs::write(dir.join("d/q.rs"), "use super::P; pub struct Q(Option<Box<P>>);\n").unwrap();
    std::fs::write(dir.join("a/mod.rs"), "pub mod x; pub mod y; pub use x::X;\n").unwrap();
    std::fs::write(dir.join("a/x.rs"), "use super::y::Y; pub struct X; fn f() { let _ = \"crate::b\"; }\n").unwrap();
    std::fs::write(dir.join("a/y.rs"), "pub struct Y(crate::a::x::X);\n").unwrap();
    std::fs::write(dir.join("b.rs"), "use crate::{Thing, a::X}; mod t { use super::super::c; }\n").unwrap();
    std::fs::write(dir.join("c.rs"), "pub struct Thing; fn g() -> crate::b::B { todo!() }\n").unwrap();
    let lib = Library::read(&dir);
    let edges = lib.edges();
    assert_eq!(cycles(&edges[&vec!["a".to_string()]]), vec![vec!["x".to_string(), "y".to_string()]]);
    let root = &edges[&Vec::new()];
    assert!(root.contains(&("b".into(), "c".into())) && root.contains(&("b".into(), "a".into())), "{root:?}");
    assert!(root.contains(&("c".into(), "b".into())), "{root:?}");
    assert_eq!(cycles(root), vec![vec!["b".to_string(), "c".to_string()]]);
    assert!(!root.contains(&("a".into(), "b".into())), "a string or a comment is not a path: {root:?}");
    assert_eq!(cycles(&edges[&vec!["d".to_string()]]), vec![vec!["p".to_string(), "q".to_string()]]);
    let _ = std::fs::remove_dir_all(&dir);
}
