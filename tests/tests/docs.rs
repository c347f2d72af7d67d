//! The documentation holds together: every relative link between the pages,
//! or to a file of the repository, resolves (with its `#anchor`, if any, to a
//! heading of the page it names); every scene, sweep or programme file a page
//! names exists; every page of the guide, the results and the developer notes
//! is reachable from the README; and the README stays a short front door.
//!
//! Links are read as Markdown writes them, `[text](target)`; code spans and
//! fenced blocks are skipped (their brackets are code, not links). Anchors
//! follow GitHub's rule: the heading's text in lower case, every character
//! other than a letter, a digit, `-`, `_` or a space dropped, spaces turned
//! into `-`, and `-1`, `-2` … for repeated headings.

mod common;

use std::collections::{BTreeSet, HashMap};
use std::fs;
use std::path::{Component, Path, PathBuf};

/// Every Markdown file of the repository that users or developers read.
fn pages() -> Vec<PathBuf> {
    let root = common::workspace_root();
    let mut out = vec![root.join("README.md")];
    let mut stack = vec![root.join("docs"), root.join("bench"), root.join("examples"), root.join("python")];
    while let Some(dir) = stack.pop() {
        let Ok(entries) = fs::read_dir(&dir) else { continue };
        for entry in entries.flatten() {
            let path = entry.path();
            let name = entry.file_name().to_string_lossy().to_string();
            if path.is_dir() {
                // Build outputs and virtual environments hold other projects' Markdown.
                if !matches!(name.as_str(), "target" | ".venv" | "venv" | "node_modules") && !name.starts_with('.') {
                    stack.push(path);
                }
            } else if name.ends_with(".md") {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// The text of a page with code spans and fenced blocks blanked (line structure kept).
fn prose(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            out.push('\n');
            continue;
        }
        if fenced {
            out.push('\n');
            continue;
        }
        let mut in_code = false;
        for c in line.chars() {
            if c == '`' {
                in_code = !in_code;
                out.push(' ');
            } else {
                out.push(if in_code { ' ' } else { c });
            }
        }
        out.push('\n');
    }
    out
}

/// The `(line, target)` of every `[text](target)` link of a page.
fn links(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (n, line) in prose(text).lines().enumerate() {
        let bytes = line.as_bytes();
        let mut i = 0;
        while let Some(off) = line[i..].find("](") {
            let start = i + off + 2;
            let mut depth = 1;
            let mut end = start;
            while end < bytes.len() {
                match bytes[end] {
                    b'(' => depth += 1,
                    b')' => {
                        depth -= 1;
                        if depth == 0 {
                            break;
                        }
                    }
                    _ => {}
                }
                end += 1;
            }
            if end < bytes.len() {
                let target = line[start..end].split_whitespace().next().unwrap_or("").to_string();
                out.push((n + 1, target));
            }
            i = end.min(bytes.len().saturating_sub(1)).max(start);
            if i >= line.len() {
                break;
            }
        }
    }
    out
}

/// GitHub's anchors of a page's headings.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut out = BTreeSet::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced || !line.starts_with('#') {
            continue;
        }
        let title = line.trim_start_matches('#').trim();
        let slug: String = title
            .to_lowercase()
            .chars()
            .filter(|c| c.is_alphanumeric() || matches!(c, '-' | '_' | ' '))
            .map(|c| if c == ' ' { '-' } else { c })
            .collect();
        let n = seen.entry(slug.clone()).or_insert(0);
        out.insert(if *n == 0 { slug.clone() } else { format!("{slug}-{n}") });
        *n += 1;
    }
    out
}

/// `path` with `.` and `..` resolved lexically.
fn normalise(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}

fn rel(path: &Path) -> String {
    path.strip_prefix(common::workspace_root()).unwrap_or(path).display().to_string()
}

#[test]
fn every_relative_link_resolves_to_a_file_and_heading() {
    let mut broken = Vec::new();
    let mut checked = 0;
    for page in pages() {
        let text = fs::read_to_string(&page).unwrap();
        for (line, target) in links(&text) {
            if target.is_empty()
                || target.starts_with("http://")
                || target.starts_with("https://")
                || target.starts_with("mailto:")
            {
                continue;
            }
            checked += 1;
            let (file, anchor) = match target.split_once('#') {
                Some((f, a)) => (f, Some(a)),
                None => (target.as_str(), None),
            };
            let dest = if file.is_empty() { page.clone() } else { normalise(&page.parent().unwrap().join(file)) };
            if !dest.exists() {
                broken.push(format!("{}:{line}: `{target}`: no file {}", rel(&page), rel(&dest)));
                continue;
            }
            if let Some(anchor) = anchor {
                if dest.extension().is_some_and(|e| e == "md") {
                    let known = anchors(&fs::read_to_string(&dest).unwrap());
                    if !known.contains(anchor) {
                        broken.push(format!(
                            "{}:{line}: `{target}`: {} has no heading `#{anchor}`",
                            rel(&page),
                            rel(&dest)
                        ));
                    }
                }
            }
        }
    }
    assert!(checked > 40, "only {checked} links found: the link reader is broken");
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

/// Paths like `config/x.toml`, `config/sweeps/y.toml` or `examples/python/z.toml` named in a
/// page's text (code spans included: that is where commands name them).
fn named_files(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        for prefix in ["config/", "examples/"] {
            let mut from = 0;
            while let Some(off) = line[from..].find(prefix) {
                let start = from + off;
                from = start + prefix.len();
                // Part of a longer path (`docs/…/config/`, `plant/src/config/`): not a scene file.
                if start > 0 && !matches!(line.as_bytes()[start - 1], b' ' | b'`' | b'(' | b'"' | b'\'' | b'=' | b'[') {
                    continue;
                }
                let end = line[start..]
                    .find(|c: char| !(c.is_ascii_alphanumeric() || matches!(c, '/' | '.' | '_' | '-')))
                    .map_or(line.len(), |e| start + e);
                let path = line[start..end].trim_end_matches('.');
                // `config/sweeps/NAME.toml`: a placeholder, not a file.
                let stem = path.rsplit('/').next().unwrap_or("").trim_end_matches(".toml");
                let placeholder = stem.chars().all(|c| c.is_ascii_uppercase() || c == '_');
                if path.ends_with(".toml") && !placeholder && !path.contains('*') && !path.contains('<') {
                    out.push((n + 1, path.to_string()));
                }
            }
        }
    }
    out
}

#[test]
fn every_scene_file_a_page_names_exists() {
    let root = common::workspace_root();
    let mut missing = Vec::new();
    let mut checked = 0;
    for page in pages() {
        let text = fs::read_to_string(&page).unwrap();
        for (line, path) in named_files(&text) {
            checked += 1;
            // Paths are named from the repository's root; a page inside an example may name its
            // own files from its folder.
            let ok = root.join(&path).exists() || page.parent().unwrap().join(&path).exists();
            if !ok {
                missing.push(format!("{}:{line}: names {path}, which does not exist", rel(&page)));
            }
        }
    }
    assert!(checked > 20, "only {checked} scene files named: the reader is broken");
    assert!(missing.is_empty(), "scene files named but missing:\n{}", missing.join("\n"));
}

#[test]
fn every_guide_results_and_developer_page_is_linked_from_the_readme() {
    let root = common::workspace_root();
    let readme = fs::read_to_string(root.join("README.md")).unwrap();
    let linked: BTreeSet<PathBuf> =
        links(&readme).into_iter().map(|(_, t)| normalise(&root.join(t.split('#').next().unwrap()))).collect();
    let mut orphans = Vec::new();
    for dir in ["docs/guide", "docs/results", "docs/dev"] {
        for entry in fs::read_dir(root.join(dir)).unwrap().flatten() {
            let path = entry.path();
            if path.extension().is_some_and(|e| e == "md") && !linked.contains(&path) {
                orphans.push(rel(&path));
            }
        }
    }
    assert!(orphans.is_empty(), "pages a newcomer cannot find from the README: {orphans:?}");
}

/// The README's crate table lists every workspace member (by its folder, as `` `plant/fmu/` ``).
#[test]
fn the_readmes_crate_table_lists_every_workspace_member() {
    let root = common::workspace_root();
    let manifest: toml::Table = fs::read_to_string(root.join("Cargo.toml")).unwrap().parse().unwrap();
    let members = manifest["workspace"]["members"].as_array().expect("workspace.members");
    let readme = fs::read_to_string(root.join("README.md")).unwrap();
    let table: Vec<&str> = readme.lines().filter(|l| l.starts_with("| `")).collect();
    assert!(!members.is_empty() && !table.is_empty());
    for m in members {
        let folder = format!("`{}/`", m.as_str().expect("a path"));
        assert!(table.iter().any(|row| row.contains(&folder)), "README's crate table has no row for {folder}");
    }
}

#[test]
fn the_readme_is_a_short_front_door_starting_with_the_two_commands() {
    let readme = fs::read_to_string(common::workspace_root().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(lines <= 200, "README.md has {lines} lines; the guide pages hold the rest");
    let first_block = readme.split("```sh").nth(1).and_then(|b| b.split("```").next()).unwrap_or("");
    assert!(
        first_block.contains("target/release/plant run") && first_block.contains("cargo test --workspace --locked"),
        "the README's first code block must hold the main job and the test command:\n{first_block}"
    );
    let ci = fs::read_to_string(common::workspace_root().join(".ci/run")).unwrap();
    assert!(ci.contains("cargo test --workspace --locked"), ".ci/run must run the README's test command");
}

#[test]
fn the_link_reader_finds_links_and_skips_code() {
    let text = "see [a](x.md) and [b](y.md#z) `[c](not.md)`\n```\n[d](no.md)\n```\n[e](w (1).md)";
    let found: Vec<String> = links(text).into_iter().map(|(_, t)| t).collect();
    assert_eq!(found, ["x.md", "y.md#z", "w"]);
    let a = anchors("# The `plant` CLI\n## Bounds\n## Bounds\n### Big sweeps on a cluster (Slurm)");
    assert!(a.contains("the-plant-cli") && a.contains("bounds") && a.contains("bounds-1"), "{a:?}");
    assert!(a.contains("big-sweeps-on-a-cluster-slurm"), "{a:?}");
}

/// The key table of `docs/guide/scenes.md`: for each `[table]` row, the keys its cell lists
/// outside parentheses, each with the text of the parentheses that follow it (its default and
/// notes), if any.
fn guide_key_table() -> HashMap<String, Vec<(String, Option<String>)>> {
    let text = fs::read_to_string(common::workspace_root().join("docs/guide/scenes.md")).expect("scenes.md");
    let mut rows = HashMap::new();
    for line in text.lines() {
        let Some(rest) = line.strip_prefix("| `[") else { continue };
        let Some((table, cell)) = rest.split_once("]` |") else { continue };
        let cell = cell.trim().trim_end_matches('|');
        let chars: Vec<char> = cell.chars().collect();
        let (mut i, mut depth, mut keys) = (0, 0usize, Vec::new());
        while i < chars.len() {
            match chars[i] {
                '`' => {
                    let end = (i + 1..chars.len()).find(|&j| chars[j] == '`').unwrap_or(chars.len());
                    let token: String = chars[i + 1..end].iter().collect();
                    i = end + 1;
                    if depth > 0 {
                        continue;
                    }
                    let mut j = i;
                    while j < chars.len() && chars[j] == ' ' {
                        j += 1;
                    }
                    let mut note = None;
                    if j < chars.len() && chars[j] == '(' {
                        // The balanced parentheses after the key (code spans inside are skipped).
                        let (mut k, mut d, mut code) = (j, 0usize, false);
                        while k < chars.len() {
                            match chars[k] {
                                '`' => code = !code,
                                '(' if !code => d += 1,
                                ')' if !code => {
                                    d -= 1;
                                    if d == 0 {
                                        break;
                                    }
                                }
                                _ => {}
                            }
                            k += 1;
                        }
                        note = Some(chars[j + 1..k.min(chars.len())].iter().collect());
                        i = k + 1;
                    }
                    keys.push((token, note));
                }
                '(' => {
                    depth += 1;
                    i += 1;
                }
                ')' => {
                    depth = depth.saturating_sub(1);
                    i += 1;
                }
                _ => i += 1,
            }
        }
        rows.insert(table.to_string(), keys);
    }
    rows
}

/// What a note in the guide says the default is: its first word, before any `;`, `,`, `:` or
/// `\|` (a list of choices starts with the default).
#[derive(Debug, PartialEq)]
enum GuideDefault {
    Number(f64),
    Bool(bool),
    Literal(String),
    Absent,
    /// Words, not a value (`(file stem)`, `(per-group overrides)`): not checked.
    Described,
}

fn guide_default(note: &str) -> GuideDefault {
    let head = note.split([';', ',', ':']).next().unwrap_or_default();
    let head = head.split("\\|").next().unwrap_or_default().trim();
    let first = head.split_whitespace().next().unwrap_or_default();
    if let Some(lit) = first.strip_prefix('`').and_then(|s| s.strip_suffix('`')) {
        return GuideDefault::Literal(lit.to_string());
    }
    match first {
        "true" => GuideDefault::Bool(true),
        "false" => GuideDefault::Bool(false),
        "none" => GuideDefault::Absent,
        _ => first.replace('−', "-").parse().map_or(GuideDefault::Described, GuideDefault::Number),
    }
}

/// Every key that `scene_table!` declares (plant/sim/src/config/raw.rs) is in the guide's key table,
/// with the declared default where the guide gives one, and the guide gives no default for a
/// key that is not declared.
#[test]
fn the_guides_scene_keys_and_defaults_are_the_declared_ones() {
    let guide = guide_key_table();
    let defaults = toml::Table::try_from(plant::config::RawScene::default()).expect("the default scene serialises");
    let mut problems = Vec::new();
    for (table, keys) in plant::config::RawScene::tables() {
        let declared = defaults[table].as_table().expect("a table");
        for k in declared.keys() {
            assert!(keys.contains(&k.as_str()), "[{table}] {k} is serialised but not in KEYS");
        }
        let Some(row) = guide.get(table) else {
            problems.push(format!("[{table}]: no row in the key table"));
            continue;
        };
        for key in keys {
            let Some((_, note)) = row.iter().find(|(k, _)| k == key) else {
                problems.push(format!("{table}.{key}: declared, not in the guide"));
                continue;
            };
            let value = declared.get(*key);
            let agrees = match note.as_deref().map(guide_default) {
                None | Some(GuideDefault::Described) => true,
                Some(GuideDefault::Number(x)) => match value {
                    Some(toml::Value::Float(f)) => *f == x,
                    Some(toml::Value::Integer(i)) => *i as f64 == x,
                    _ => false,
                },
                Some(GuideDefault::Bool(b)) => value == Some(&toml::Value::Boolean(b)),
                Some(GuideDefault::Literal(s)) => match value {
                    Some(toml::Value::String(v)) => *v == s,
                    Some(v) => v.to_string() == s,
                    None => false,
                },
                Some(GuideDefault::Absent) => value.is_none(),
            };
            if !agrees {
                problems.push(format!(
                    "{table}.{key}: the guide says ({}), the default is {value:?}",
                    note.as_deref().unwrap_or("")
                ));
            }
        }
        for (k, note) in row {
            if note.is_some() && !keys.contains(&k.as_str()) {
                problems.push(format!("{table}.{k}: in the guide with a default, not declared"));
            }
        }
    }
    assert!(
        problems.is_empty(),
        "docs/guide/scenes.md against plant/sim/src/config/raw.rs:\n  {}",
        problems.join("\n  ")
    );
}

#[test]
fn the_key_table_reader_reads_keys_notes_and_defaults() {
    assert_eq!(guide_default("1.5; at most 1e6"), GuideDefault::Number(1.5));
    assert_eq!(guide_default("−90: ball 0 straight down"), GuideDefault::Number(-90.0));
    assert_eq!(guide_default("`held` \\| `free`"), GuideDefault::Literal("held".into()));
    assert_eq!(guide_default("`[]`, e.g. `[0, 1]`"), GuideDefault::Literal("[]".into()));
    assert_eq!(guide_default("0 = `substeps`: substeps while"), GuideDefault::Number(0.0));
    assert_eq!(guide_default("none: the built-in `controller`"), GuideDefault::Absent);
    assert_eq!(guide_default("file stem"), GuideDefault::Described);
    let rows = guide_key_table();
    let rotor = &rows["rotor"];
    assert!(rotor.contains(&("mass_kg".to_string(), Some("11.5".to_string()))), "{rotor:?}");
    let touchdown = &rows["touchdown"];
    assert!(!touchdown.iter().any(|(k, _)| k.contains('+')), "a code span inside a note is not a key");
}

/// The fenced code blocks of a page: `(line of the fence, info string, text)`.
fn code_blocks(text: &str) -> Vec<(usize, String, String)> {
    let mut out = Vec::new();
    let mut open: Option<(usize, String, String)> = None;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim_start();
        if let Some(info) = t.strip_prefix("```") {
            match open.take() {
                Some(block) => out.push(block),
                None => open = Some((i + 1, info.trim().to_string(), String::new())),
            }
        } else if let Some((_, _, body)) = open.as_mut() {
            body.push_str(line);
            body.push('\n');
        }
    }
    out
}

/// The commands of a shell text: lines joined over a trailing `\`, comments dropped.
fn shell_commands(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut current = String::new();
    for line in text.lines() {
        let line = line.split(" #").next().unwrap_or("");
        if line.trim_start().starts_with('#') {
            continue;
        }
        match line.trim_end().strip_suffix('\\') {
            Some(head) => current.push_str(head),
            None => {
                current.push_str(line);
                if !current.trim().is_empty() {
                    out.push(std::mem::take(&mut current));
                }
                current.clear();
            }
        }
    }
    out
}

/// The tables of a TOML text by their header (`[controller]`, `[[controller]]`, …; the lines
/// before the first header under `""`), each with its lines, comments dropped.
fn toml_tables(text: &str) -> Vec<(String, String)> {
    let mut out = vec![(String::new(), String::new())];
    for line in text.lines() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.starts_with('[') && !line.contains('=') {
            out.push((line.to_string(), String::new()));
        } else if let Some((_, body)) = out.last_mut() {
            body.push_str(line);
            body.push('\n');
        }
    }
    out
}

/// Where a TOML text runs a program of its own as the controller without naming its law: a
/// `[controller]` table with `command` and no `law`, an assessment's `[[controller]]` whose
/// `set` gives `controller.command` and no `controller.law`.
fn commands_without_law(toml_text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (header, body) in toml_tables(toml_text) {
        let keys: Vec<&str> = body.lines().filter_map(|l| l.split('=').next()).map(str::trim).collect();
        if header == "[controller]" && keys.contains(&"command") && !keys.contains(&"law") {
            out.push(format!("{header} with command and no law"));
        }
        if header == "[[controller]]" && body.contains("controller.command=") && !body.contains("controller.law=") {
            out.push(format!("{header} {}", body.lines().next().unwrap_or("")));
        }
    }
    out
}

/// Issue 31: every example that runs a program of its own as the controller
/// (`controller.command`) names the law that program serves (`controller.law`): the plant asks
/// the program for the scene's law, so a copied example whose program serves a law of another
/// name is refused (exit 2) until its author guesses the key. Held for the shell commands and
/// the TOML of every page's code blocks, and for every scene and assessment file under
/// `config/` and `examples/`.
#[test]
fn every_example_that_runs_a_controller_program_names_its_law() {
    let root = common::workspace_root();
    let mut problems = Vec::new();
    for page in pages() {
        let text = fs::read_to_string(&page).unwrap();
        for (line, info, body) in code_blocks(&text) {
            if info.starts_with("toml") {
                for p in commands_without_law(&body) {
                    problems.push(format!("{}:{line}: {p}", rel(&page)));
                }
            } else if matches!(info.as_str(), "sh" | "bash" | "shell" | "console" | "") {
                for c in shell_commands(&body) {
                    if c.contains("controller.command=") && !c.contains("controller.law=") {
                        problems.push(format!("{}:{line}: {}", rel(&page), c.trim()));
                    }
                }
            }
        }
    }
    let mut stack = vec![root.join("config"), root.join("examples")];
    let mut files = 0;
    while let Some(dir) = stack.pop() {
        for entry in fs::read_dir(&dir).unwrap().flatten() {
            let path = entry.path();
            let name = entry.file_name().to_string_lossy().to_string();
            if path.is_dir() {
                if name != "target" && !name.starts_with('.') {
                    stack.push(path);
                }
            } else if name.ends_with(".toml") && name != "Cargo.toml" && name != "pyproject.toml" {
                files += 1;
                for p in commands_without_law(&fs::read_to_string(&path).unwrap()) {
                    problems.push(format!("{}: {p}", rel(&path)));
                }
            }
        }
    }
    assert!(files > 20, "only {files} TOML files found under config/ and examples/");
    assert!(problems.is_empty(), "a controller program without its law:\n  {}", problems.join("\n  "));
}

#[test]
fn the_command_checker_finds_a_program_without_its_law() {
    let assess = "scene = \"s.toml\"\n[[controller]]\nlabel = \"c\"\nset = [\"controller.command=[\\\"./c\\\"]\"]\n";
    assert_eq!(commands_without_law(assess).len(), 1);
    let named = assess.replace("set = [", "set = [\"controller.law=\\\"mine\\\"\", ");
    assert!(commands_without_law(&named).is_empty(), "{named}");
    assert_eq!(commands_without_law("[controller]\nmode = \"lockstep\"\ncommand = [\"./c\"]\n").len(), 1);
    assert!(commands_without_law("[controller]\nlaw = \"mine\"   # served\ncommand = [\"./c\"]\n").is_empty());
    let sh = "plant run x.toml \\\n    --set 'controller.command=[\"./c\"]'\nplant run y.toml --set controller.law=pd --set 'controller.command=[\"./c\"]'\n";
    let commands = shell_commands(sh);
    assert_eq!(commands.len(), 2, "{commands:?}");
    assert!(!commands[0].contains("controller.law=") && commands[1].contains("controller.law="));
}
