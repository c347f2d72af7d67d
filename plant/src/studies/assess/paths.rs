//! How the report shows a path: relative to where the command ran, so that it names no folder
//! of this machine.

use std::path::{Path, PathBuf};

/// The absolute folders the report names (the scene's, the report's, the working folder) and
/// how it shows them, relative to `cwd`; the longest first.
pub(super) fn roots(cwd: &Path, scene: &Path, dir: &Path) -> Vec<(String, String)> {
    let shown_here = |p: &Path| if cwd.as_os_str().is_empty() { shown(p) } else { shown_relative(p, cwd) };
    let mut roots = Vec::new();
    if !cwd.as_os_str().is_empty() {
        let scene_dir = scene.parent().unwrap_or(Path::new("."));
        let absolute = |p: &Path| shown(&cwd.join(p));
        roots.push((absolute(scene_dir), shown_here(scene_dir)));
        roots.push((absolute(dir), shown_here(dir)));
        roots.push((shown(cwd), ".".to_string()));
        // The longest first: a folder inside another is replaced as itself.
        roots.sort_by_key(|(abs, _)| std::cmp::Reverse(abs.len()));
        roots.retain(|(abs, _)| abs != "/");
    }
    roots
}

/// `path` relative to `cwd` (both taken lexically, `path` joined to `cwd` when relative), with
/// `..` where it lies outside `cwd`: `/work/t/config/a.toml` from `/work/t` is `config/a.toml`,
/// from `/work/u` `../t/config/a.toml`.
pub fn shown_relative(path: &Path, cwd: &Path) -> String {
    let abs = PathBuf::from(shown(&cwd.join(path)));
    let base = PathBuf::from(shown(cwd));
    let a: Vec<_> = abs.components().collect();
    let b: Vec<_> = base.components().collect();
    let common = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out = PathBuf::new();
    for _ in common..b.len() {
        out.push("..");
    }
    for c in &a[common..] {
        out.push(c);
    }
    if out.as_os_str().is_empty() {
        ".".into()
    } else {
        out.display().to_string()
    }
}

/// `text` with each absolute folder of `roots` (followed by `/`) replaced by how the report
/// shows it (`.` drops out: `/work/t/runs/x` with `("/work/t", ".")` is `runs/x`).
pub fn relative_text(text: &str, roots: &[(String, String)]) -> String {
    let mut out = text.to_string();
    for (abs, rel) in roots {
        let to = if rel == "." { String::new() } else { format!("{rel}/") };
        out = out.replace(&format!("{abs}/"), &to);
    }
    out
}

/// Where a relative path of an assessment file points.
pub fn relative_to(file: &Path, path: &str) -> PathBuf {
    file.parent().unwrap_or(Path::new(".")).join(path)
}

/// A path as the report shows it: `.` and each `dir/..` pair dropped, lexically
/// (`config/assess/../paper-10g.toml` is shown `config/paper-10g.toml`); the scene is still
/// loaded by the path as written, which a symbolic link could make differ.
pub fn shown(path: &Path) -> String {
    use std::path::Component;
    let mut kept: Vec<Component> = Vec::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(kept.last(), Some(Component::Normal(_))) => {
                kept.pop();
            }
            c => kept.push(c),
        }
    }
    if kept.is_empty() {
        return ".".into();
    }
    kept.iter().collect::<PathBuf>().display().to_string()
}
