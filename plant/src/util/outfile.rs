//! The one way the plant creates a file in an output folder, so that no
//! command writes through a link someone left in its `--out` (issue 31 item 6:
//! `soak`, `compare`, `assess`, `campbell`, `ensemble`, `sweep`, `overlay` and
//! `analyze` drew their charts, and `soak` its CSVs and log, through symlinks
//! already in the folder, overwriting files elsewhere).
//!
//! * [`write`]: a file written whole (JSON, TOML, CSV tables, charts): through
//!   a temporary created new in the same folder, renamed over the name
//!   ([`crate::atomic::write`]). A rename replaces a link (symbolic or hard)
//!   by the new file and never touches what it pointed to.
//! * [`create`]: a file streamed as it is made (`trace.csv`, the soak's CSVs,
//!   `controller.log`): whatever non-folder entry holds the name (a link, an
//!   earlier file) is unlinked, and the file is created new (`O_CREAT |
//!   O_EXCL`, which never follows a link), so it is always a fresh regular
//!   file in the folder.
//! * [`png`]: a chart, drawn in memory and handed to [`write`] (plotters'
//!   own `BitMapBackend::new(path)` opens the path and follows a link).
//! * [`folder`]: a folder the command makes inside its output folder
//!   (`points/`): created if missing, refused when a link holds its name.
//!
//! Nothing else in `plant/src` opens a file for writing: a test
//! (`no_writer_bypasses_the_shared_module`) fails on a `File::create`,
//! `fs::write`, `OpenOptions`, `BitMapBackend::new` or `atomic::write` outside
//! this module and `atomic.rs`.

use anyhow::Context;
use std::fs::{File, OpenOptions};
use std::io::{Error, ErrorKind};
use std::path::Path;

/// Writes `bytes` to `path` whole or not at all, replacing whatever entry held the name
/// (a link included) and never writing through it.
pub fn write(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    crate::atomic::write(path, bytes)
}

/// Creates `path` as a new, empty regular file for writing: an entry already at the name
/// (a file of an earlier run, a symbolic or hard link) is unlinked first, never followed;
/// a folder at the name is an error.
pub fn create(path: &Path) -> std::io::Result<File> {
    // Another process may put an entry back between the unlink and the creation: try again.
    for _ in 0..8 {
        match std::fs::symlink_metadata(path) {
            Ok(m) if m.is_dir() => {
                return Err(Error::new(ErrorKind::AlreadyExists, format!("{} is a folder", path.display())))
            }
            Ok(_) => match std::fs::remove_file(path) {
                Ok(()) => {}
                Err(e) if e.kind() == ErrorKind::NotFound => {}
                Err(e) => return Err(e),
            },
            Err(e) if e.kind() == ErrorKind::NotFound => {}
            Err(e) => return Err(e),
        }
        match OpenOptions::new().write(true).create_new(true).open(path) {
            Ok(file) => return Ok(file),
            Err(e) if e.kind() == ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
    Err(Error::new(ErrorKind::AlreadyExists, format!("{}: another process keeps creating it", path.display())))
}

/// Opens `path` again to go on writing it: a file streamed as it was made by an earlier,
/// interrupted run of the same command (a soak continued, `plant soak --resume`), cut to its
/// first `len` bytes (what that run's checkpoint had seen written) and positioned at its end.
/// A link at the name (symbolic or hard) is refused, never followed, as is anything but a
/// regular file and a file shorter than `len`.
pub fn reopen_at(path: &Path, len: u64) -> std::io::Result<File> {
    use std::io::{Seek, SeekFrom};
    use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
    let mut file = OpenOptions::new().read(true).write(true).custom_flags(libc::O_NOFOLLOW).open(path)?;
    let m = file.metadata()?;
    let refuse = |why: String| Err(Error::new(ErrorKind::InvalidData, format!("{}: {why}", path.display())));
    if !m.is_file() || m.nlink() > 1 {
        return refuse("not a regular file of its own (a link, a device or a folder)".into());
    }
    if m.len() < len {
        return refuse(format!("{} bytes, fewer than the {len} written when the checkpoint was taken", m.len()));
    }
    file.set_len(len)?;
    file.seek(SeekFrom::End(0))?;
    Ok(file)
}

/// Moves the entry at `path` (`controller.log`) aside to the first free `controller.N.log`
/// (`N` from 1), so that a file about to be created anew at `path` keeps the earlier one; the
/// entry itself is renamed (a link stays a link, never followed). Nothing at `path`: `None`.
pub fn keep_aside(path: &Path) -> anyhow::Result<Option<std::path::PathBuf>> {
    if std::fs::symlink_metadata(path).is_err() {
        return Ok(None);
    }
    let (stem, ext) = match (path.file_stem(), path.extension()) {
        (Some(s), Some(e)) => (s.to_string_lossy(), format!(".{}", e.to_string_lossy())),
        _ => (path.file_name().unwrap_or_default().to_string_lossy(), String::new()),
    };
    let free = (1..10_000)
        .map(|n| path.with_file_name(format!("{stem}.{n}{ext}")))
        .find(|p| std::fs::symlink_metadata(p).is_err())
        .with_context(|| format!("{}: the names to keep it under (.1 to .9999) are all taken", path.display()))?;
    std::fs::rename(path, &free).with_context(|| format!("keeping {} as {}", path.display(), free.display()))?;
    Ok(Some(free))
}

/// Removes the file at `path` if there is one (nothing there is fine); an error names the file.
pub fn remove(path: &Path) -> anyhow::Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(e).with_context(|| format!("removing {}", path.display()))
        }
        _ => Ok(()),
    }
}

/// Removes from `dir` the files an earlier command of the same kind may have left there, so
/// that none of them sits beside this command's results as if it were one of them: `names`
/// are file names, each with at most one `*` standing for any run of characters
/// (`sensitivity_*.png`). Other files, and folders, stay.
pub fn clear_earlier(dir: &Path, names: &[&str]) -> anyhow::Result<()> {
    let matches = |file: &str| {
        names.iter().any(|n| match n.split_once('*') {
            None => file == *n,
            Some((head, tail)) => {
                file.len() >= head.len() + tail.len() && file.starts_with(head) && file.ends_with(tail)
            }
        })
    };
    let entries = std::fs::read_dir(dir).with_context(|| format!("listing {}", dir.display()))?;
    for entry in entries {
        let entry = entry.with_context(|| format!("listing {}", dir.display()))?;
        let is_dir = entry.file_type().is_ok_and(|t| t.is_dir());
        if !is_dir && entry.file_name().to_str().is_some_and(matches) {
            remove(&entry.path()).context("an earlier run's file")?;
        }
    }
    Ok(())
}

/// Creates the folder `path` (and its parents) if missing; a symbolic link at `path` is
/// refused, so that the files written into it stay inside the output folder.
pub fn folder(path: &Path) -> anyhow::Result<()> {
    if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
        anyhow::bail!("{} is a symbolic link: a folder the command writes into must be a real folder", path.display());
    }
    std::fs::create_dir_all(path).with_context(|| format!("creating {}", path.display()))?;
    if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
        anyhow::bail!("{} is a symbolic link: a folder the command writes into must be a real folder", path.display());
    }
    Ok(())
}

/// An RGB image of `size` pixels, `rgb` row by row, as PNG bytes (the encoding plotters'
/// own file output uses).
pub fn png_bytes(rgb: &[u8], size: (u32, u32)) -> anyhow::Result<Vec<u8>> {
    use image::ImageEncoder;
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(rgb, size.0, size.1, image::ColorType::Rgb8)
        .context("encoding PNG")?;
    Ok(bytes)
}

/// Writes an RGB image as a PNG file through [`write`].
pub fn png(path: &Path, rgb: &[u8], size: (u32, u32)) -> anyhow::Result<()> {
    write(path, &png_bytes(rgb, size).with_context(|| format!("writing {}", path.display()))?)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::path::PathBuf;

    fn scratch(name: &str) -> PathBuf {
        crate::util::scratch(&format!("outfile-{name}"))
    }

    /// An earlier run's files go by name and pattern; the user's other files, a folder whose
    /// name matches, and what a matching link points to stay.
    #[test]
    fn clearing_an_earlier_run_removes_its_files_and_nothing_else() {
        let dir = scratch("clear");
        let out = dir.join("out");
        std::fs::create_dir_all(out.join("sensitivity_9.png")).unwrap();
        let outside = dir.join("precious.png");
        std::fs::write(&outside, b"precious").unwrap();
        std::os::unix::fs::symlink(&outside, out.join("open_loop_2.png")).unwrap();
        let earlier = ["report.html", "sensitivity_1.png", "sensitivity_12.png", "open_loop_.png"];
        let kept = ["notes.txt", "report.html.bak", "my_sensitivity_1.png", "sensitivity_1.png.txt", "sensitivity.png"];
        for n in earlier.iter().chain(&kept) {
            std::fs::write(out.join(n), b"x").unwrap();
        }
        clear_earlier(&out, &["report.html", "sensitivity_*.png", "open_loop_*.png"]).unwrap();
        let mut left: Vec<String> =
            std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
        left.sort();
        let mut want: Vec<String> = kept.iter().map(|n| n.to_string()).collect();
        want.push("sensitivity_9.png".into()); // a folder
        want.sort();
        assert_eq!(left, want);
        assert_eq!(std::fs::read(&outside).unwrap(), b"precious");
        assert!(clear_earlier(&dir.join("missing"), &["a"]).is_err(), "a folder that is not there is an error");
    }

    /// Every way of writing replaces a symbolic or hard link at its name and leaves what it
    /// pointed to as it was.
    #[test]
    fn no_write_goes_through_a_link() {
        let dir = scratch("links");
        let outside = dir.join("outside");
        std::fs::create_dir_all(&outside).unwrap();
        let victim = |n: &str| {
            let p = outside.join(n);
            std::fs::write(&p, b"precious").unwrap();
            p
        };
        let out = dir.join("out");
        std::fs::create_dir_all(&out).unwrap();
        let names = ["a.json", "b.csv", "c.png", "d.json", "e.csv"];
        for (i, n) in names.iter().enumerate() {
            let target = victim(n);
            if i < 3 {
                std::os::unix::fs::symlink(&target, out.join(n)).unwrap();
            } else {
                std::fs::hard_link(&target, out.join(n)).unwrap();
            }
        }
        // A dangling link: creating through it would make a file elsewhere.
        std::os::unix::fs::symlink(outside.join("made.csv"), out.join("f.csv")).unwrap();
        write(&out.join("a.json"), b"{}").unwrap();
        std::io::Write::write_all(&mut create(&out.join("b.csv")).unwrap(), b"x\n").unwrap();
        png(&out.join("c.png"), &[255; 12], (2, 2)).unwrap();
        write(&out.join("d.json"), b"{}").unwrap();
        std::io::Write::write_all(&mut create(&out.join("e.csv")).unwrap(), b"x\n").unwrap();
        std::io::Write::write_all(&mut create(&out.join("f.csv")).unwrap(), b"x\n").unwrap();
        for n in names {
            assert_eq!(std::fs::read(outside.join(n)).unwrap(), b"precious", "{n} was written through");
            let m = std::fs::symlink_metadata(out.join(n)).unwrap();
            assert!(m.is_file(), "{n} is a regular file of its own now");
        }
        assert!(!outside.join("made.csv").exists(), "a dangling link was followed");
        assert!(std::fs::symlink_metadata(out.join("f.csv")).unwrap().is_file());
        // A folder at the name stays and is an error.
        std::fs::create_dir_all(out.join("g.csv")).unwrap();
        assert!(create(&out.join("g.csv")).is_err());
        // A linked subfolder is refused.
        std::os::unix::fs::symlink(&outside, out.join("points")).unwrap();
        let e = folder(&out.join("points")).unwrap_err().to_string();
        assert!(e.contains("symbolic link"), "{e}");
        folder(&out.join("real")).unwrap();
        assert!(out.join("real").is_dir());
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// The non-test code of `plant/src` up to its first `#[cfg(test)]`, per file.
    pub(crate) fn sources() -> Vec<(PathBuf, String)> {
        fn walk(dir: &Path, out: &mut Vec<(PathBuf, String)>) {
            for e in std::fs::read_dir(dir).unwrap().flatten() {
                let p = e.path();
                if p.is_dir() {
                    walk(&p, out);
                } else if p.extension().is_some_and(|x| x == "rs") && p.file_name().is_some_and(|n| n != "tests.rs") {
                    let text = std::fs::read_to_string(&p).unwrap();
                    let code = text.split("#[cfg(test)]").next().unwrap_or_default().to_string();
                    out.push((p, code));
                }
            }
        }
        let mut out = Vec::new();
        // The CLI's sources and the simulation crate's (plant/sim), which it stands on.
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        walk(&root.join("src"), &mut out);
        walk(&root.join("sim/src"), &mut out);
        assert!(out.len() > 50, "plant/src was not found");
        out
    }

    /// The class of issue 31 item 6: a writer that opens its output itself can follow a link.
    /// Every writer of `plant/src` goes through this module (`atomic.rs` is its mechanism);
    /// a new one that does not fails here, named with its line.
    #[test]
    fn no_writer_bypasses_the_shared_module() {
        const FORBIDDEN: &[&str] = &[
            "File::create",
            "fs::write(",
            "OpenOptions::new",
            "BitMapBackend::new(",
            "atomic::write(",
            "Writer::from_path",
            "fs::copy(",
            "fs::rename(",
        ];
        let mut found = Vec::new();
        for (path, code) in sources() {
            let name = path.file_name().unwrap().to_string_lossy();
            if name == "outfile.rs" || name == "atomic.rs" {
                continue;
            }
            for (i, line) in code.lines().enumerate() {
                let line_code = line.split("//").next().unwrap_or_default();
                // A whole name: `RowFile::create` is not `File::create`.
                let whole = |f: &str| {
                    line_code.match_indices(f).any(|(at, _)| {
                        !line_code[..at].chars().next_back().is_some_and(|c| c.is_alphanumeric() || c == '_')
                    })
                };
                if FORBIDDEN.iter().any(|f| whole(f)) {
                    found.push(format!("{}:{}: {}", path.display(), i + 1, line.trim()));
                }
            }
        }
        assert!(found.is_empty(), "writers that bypass plant::outfile:\n{}", found.join("\n"));
    }
}
