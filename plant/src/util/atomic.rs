//! Writing a file whole or not at all: through a temporary file in the same
//! folder, flushed to disk, then renamed over the target. A reader, a second
//! process merging the same folder, or a run killed half-way sees either the
//! old file or the new one, never half of either.
//!
//! A process killed during a write (SIGKILL, the OOM killer) leaves its
//! temporary behind (`.NAME.tmpPID-N`). The writer holds an exclusive
//! `flock(2)` on its temporary from creating it to renaming it, which the
//! kernel drops however the process ends, so [`remove_stale`] tells a dead
//! writer's temporary (unlocked) from a live one's (locked), also between
//! shards of a sweep sharing a folder, and removes only the dead ones.

use anyhow::Context;
use std::fs::{File, OpenOptions, TryLockError};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// The temporary name beside `path`: hidden, unique per process and call.
fn temporary(path: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = path.file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.tmp{}-{n}", std::process::id()))
}

/// True for a name [`temporary`] makes: `.NAME.tmpPID-N`.
pub fn is_temporary(name: &str) -> bool {
    let Some((head, n)) = name.strip_prefix('.').and_then(|s| s.rsplit_once('-')) else { return false };
    let Some((_, pid)) = head.rsplit_once(".tmp") else { return false };
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    digits(pid) && digits(n)
}

/// True when `path` still names the file open as `file` (not removed or replaced since).
fn still_names(file: &File, path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (file.metadata(), std::fs::symlink_metadata(path)) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = file;
        path.exists()
    }
}

/// Writes `bytes` to `path` atomically (see the module doc).
///
/// ```
/// let dir = std::env::temp_dir().join(format!("atomic-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// plant::atomic::write(&dir.join("a.txt"), b"whole").unwrap();
/// assert_eq!(std::fs::read(dir.join("a.txt")).unwrap(), b"whole");
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn write(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    // A cleaner may take a temporary between its creation and its lock (it is unlocked for that
    // instant) and remove it: then this one is no longer the file at its name; take another.
    for _ in 0..8 {
        let tmp = temporary(path);
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
            .with_context(|| format!("writing {} (creating {})", path.display(), tmp.display()))?;
        // Where the file system has no locks, the write is still atomic, only not told from a
        // dead one's by `remove_stale` (which then leaves it).
        let _ = file.lock();
        if !still_names(&file, &tmp) {
            continue;
        }
        let written = (|| {
            let mut f = &file;
            f.write_all(bytes)?;
            file.sync_all()
        })();
        if let Err(e) = written {
            let _ = std::fs::remove_file(&tmp);
            return Err(e).with_context(|| format!("writing {}", path.display()));
        }
        // The lock is held until `file` is dropped, after the rename.
        return std::fs::rename(&tmp, path).with_context(|| {
            let _ = std::fs::remove_file(&tmp);
            format!("writing {} (renaming {} over it)", path.display(), tmp.display())
        });
    }
    anyhow::bail!("writing {}: its temporary files were removed under it", path.display())
}

/// Removes the temporaries of writes whose process has ended (killed during the write) from
/// `dir`, leaving those of live writers; returns what it removed.
pub fn remove_stale(dir: &Path) -> Vec<PathBuf> {
    let mut removed = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else { return removed };
    for e in entries.flatten() {
        if !e.file_name().to_str().is_some_and(is_temporary) {
            continue;
        }
        let path = e.path();
        // Read and write: an exclusive lock over NFS needs a writable descriptor.
        let Ok(file) = OpenOptions::new().read(true).write(true).open(&path) else { continue };
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) | Err(TryLockError::Error(_)) => continue,
        }
        if still_names(&file, &path) && std::fs::remove_file(&path).is_ok() {
            removed.push(path);
        }
    }
    removed
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        crate::util::scratch(&format!("atomic-{name}"))
    }

    #[test]
    fn temporaries_are_recognised_by_name() {
        let t = temporary(Path::new("/x/00003.json"));
        assert!(is_temporary(t.file_name().unwrap().to_str().unwrap()), "{}", t.display());
        for name in ["00003.json", ".hidden", ".00003.json.tmp", ".a.tmp12-", ".a.tmpx-1", "a.tmp1-2"] {
            assert!(!is_temporary(name), "{name}");
        }
    }

    #[test]
    fn a_dead_writers_temporary_goes_and_a_live_ones_stays() {
        let dir = scratch("stale");
        let dead = dir.join(".00001.json.tmp4194999-0");
        std::fs::write(&dead, b"{\"key\":").unwrap();
        let live = dir.join(".00002.json.tmp4194999-1");
        std::fs::write(&live, b"{\"key\":").unwrap();
        let holder = OpenOptions::new().write(true).open(&live).unwrap();
        holder.lock().unwrap();
        std::fs::write(dir.join("00003.json"), b"{}").unwrap();
        assert_eq!(remove_stale(&dir), vec![dead.clone()]);
        assert!(!dead.exists() && live.exists() && dir.join("00003.json").exists());
        drop(holder);
        assert_eq!(remove_stale(&dir), vec![live]);
        write(&dir.join("00004.json"), b"whole").unwrap();
        let names: Vec<String> =
            std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        assert_eq!(names.len(), 2, "{names:?}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
