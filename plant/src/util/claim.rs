//! One live process per output folder.
//!
//! `plant run`, `soak`, `compare` and `analyze` claim their folder for their
//! whole life with an exclusive `flock(2)` on the folder itself
//! ([`std::fs::File::try_lock`] on the directory), so that a second command
//! pointed at the same `--out` is refused (exit 2) instead of mixing its files
//! with the first one's (two runs at once used to leave one run's
//! `summary.json` beside the other's `trace.csv`, both exiting 0). The kernel
//! releases the claim when the process ends, however it ends (SIGKILL
//! included); nothing is left in the folder. A claim also removes the
//! temporaries of atomic writes that a killed process left in the folder
//! ([`crate::atomic::remove_stale`]). A folder the claim created and the
//! command left empty (it failed before writing anything, e.g. `plant
//! compare --laws foo`) is removed again when the claim goes, with the
//! parents it created. Sweeps and ensembles do not take it: their shards
//! share one folder by design and check their own files (and temporaries).

use std::fs::{File, TryLockError};
use std::path::{Path, PathBuf};

/// Why a folder could not be claimed.
#[derive(Debug, thiserror::Error)]
pub enum ClaimError {
    /// Another live process holds the folder.
    #[error("output folder {} is in use by a live process{holder}; wait for it to end or choose another --out", path.display())]
    InUse {
        /// The folder.
        path: PathBuf,
        /// `: pid N (command line)` when `/proc/locks` names it, else empty.
        holder: String,
    },
    /// The folder could not be created, opened or locked.
    #[error("cannot claim output folder {}: {source}", path.display())]
    Io {
        /// The folder.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
}

/// A claimed folder; released when dropped (or when the process ends).
#[derive(Debug)]
pub struct Claim {
    _dir: File,
    /// The folders the claim created, the deepest first.
    created: Vec<PathBuf>,
}

impl Drop for Claim {
    fn drop(&mut self) {
        // `remove_dir` removes only an empty folder: whatever the command wrote stays.
        for dir in &self.created {
            if std::fs::remove_dir(dir).is_err() {
                break;
            }
        }
    }
}

/// Claims `dir`, creating it first when `create` (a run's `--out`); without `create` a
/// missing folder is not an error here (`Ok(None)`: the command says what is missing).
pub fn claim(dir: &Path, create: bool) -> Result<Option<Claim>, ClaimError> {
    let io = |source| ClaimError::Io { path: dir.to_path_buf(), source };
    let mut created = Vec::new();
    if create {
        created =
            dir.ancestors().take_while(|d| !d.as_os_str().is_empty() && !d.exists()).map(Path::to_path_buf).collect();
        std::fs::create_dir_all(dir).map_err(io)?;
    } else if !dir.is_dir() {
        return Ok(None);
    }
    let file = File::open(dir).map_err(io)?;
    match file.try_lock() {
        Ok(()) => {
            // A write of an earlier command killed half-way left its temporary here.
            crate::atomic::remove_stale(dir);
            Ok(Some(Claim { _dir: file, created }))
        }
        Err(TryLockError::WouldBlock) => Err(ClaimError::InUse { path: dir.to_path_buf(), holder: holder(dir) }),
        Err(TryLockError::Error(e)) => Err(io(e)),
    }
}

/// `: pid N (command line)` of the process holding the folder's flock, from `/proc/locks`
/// (Linux; best effort, empty when unknown).
fn holder(dir: &Path) -> String {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let Ok(inode) = std::fs::metadata(dir).map(|m| m.ino()) else { return String::new() };
        let locks = std::fs::read_to_string("/proc/locks").unwrap_or_default();
        // "1: FLOCK  ADVISORY  WRITE 12345 fe:00:901122 0 EOF": pid, then major:minor:inode.
        for line in locks.lines() {
            let f: Vec<&str> = line.split_whitespace().collect();
            if f.len() >= 6 && f[1] == "FLOCK" && f[5].rsplit(':').next() == Some(&inode.to_string()) {
                let pid = f[4];
                let cmd = std::fs::read(format!("/proc/{pid}/cmdline"))
                    .map(|b| {
                        String::from_utf8_lossy(&b).split('\0').filter(|s| !s.is_empty()).collect::<Vec<_>>().join(" ")
                    })
                    .unwrap_or_default();
                return if cmd.is_empty() { format!(": pid {pid}") } else { format!(": pid {pid} ({cmd})") };
            }
        }
    }
    String::new()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_claim_is_refused_until_the_first_is_dropped() {
        let dir = std::env::temp_dir().join(format!("plant-claim-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        assert!(claim(&dir, false).unwrap().is_none(), "a missing folder is not created without `create`");
        assert!(!dir.exists());
        std::fs::create_dir_all(&dir).unwrap();
        let first = claim(&dir, true).unwrap().expect("claimed");
        let second = claim(&dir, true).unwrap_err().to_string();
        assert!(second.contains("in use by a live process"), "{second}");
        assert!(second.contains(&format!("pid {}", std::process::id())), "{second}");
        drop(first);
        assert!(claim(&dir, false).unwrap().is_some());
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing is left in the folder");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Issue 21 item 7: `plant compare --laws foo` failed after creating its folder and left
    /// it empty. A folder the claim created goes with it while empty, parents included; one
    /// that holds a file, or that existed before, stays.
    #[test]
    fn a_folder_the_claim_created_and_left_empty_is_removed() {
        let root = std::env::temp_dir().join(format!("plant-claim-created-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let deep = root.join("a").join("b");
        drop(claim(&deep, true).unwrap());
        assert!(!root.exists(), "the folders the claim created are gone");
        let kept = claim(&deep, true).unwrap();
        std::fs::write(deep.join("summary.json"), "{}").unwrap();
        drop(kept);
        assert!(deep.join("summary.json").is_file(), "a folder with a file stays");
        let empty = root.join("empty");
        std::fs::create_dir_all(&empty).unwrap();
        drop(claim(&empty, true).unwrap());
        assert!(empty.is_dir(), "a folder that existed before stays");
        let _ = std::fs::remove_dir_all(&root);
    }
}
