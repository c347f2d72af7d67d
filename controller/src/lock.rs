//! One process per role and run id: an exclusive lock on a small file.
//!
//! A plant (or a controller) takes `<lock dir>/<run_id>.<role>.lock` with an
//! exclusive `flock(2)` ([`std::fs::File::try_lock`]) before it opens any
//! service of the run, and holds it for its life. The kernel releases it when
//! the process ends, however it ends (SIGKILL included), so a crashed run
//! never blocks the next one, while a live one refuses a second process
//! under the same run id with a message naming it (the holder writes its
//! pid and command line into the file).
//!
//! The lock folder is `$AMB_TESTBED_LOCK_DIR`, else `<temp dir>/amb-testbed`
//! (`/tmp/amb-testbed`), machine-wide like iceoryx2's own resources.
//!
//! **No file is left behind.** A holder deletes its lock file when it
//! releases it, and [`acquire`] deletes the files of holders that died
//! without releasing (SIGKILL), so the folder does not fill up run after
//! run. Deleting a lock file is safe because a taker checks, once it holds
//! the lock, that the path still names the file it locked (same inode); if
//! the file was deleted between its open and its lock, it starts again. So
//! a file is deleted only by a process that holds its lock, and a lock held
//! on a deleted file is never taken for the run id's.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::PathBuf;

/// Environment variable naming the lock folder (default `<temp dir>/amb-testbed`).
pub const LOCK_DIR_ENV: &str = "AMB_TESTBED_LOCK_DIR";

/// Why a run id could not be taken.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// Another live process holds the run id in this role.
    #[error("run id {run_id} is in use by a live {role}: {holder} (lock {path}); pick another --run-id or stop that process")]
    InUse {
        /// The run id.
        run_id: String,
        /// `plant` or `controller`.
        role: String,
        /// What the holder wrote (its pid and command line).
        holder: String,
        /// The lock file.
        path: String,
    },
    /// The lock file could not be created or locked.
    #[error("cannot lock run id {run_id} ({path}): {source}")]
    Io {
        /// The run id.
        run_id: String,
        /// The lock file.
        path: String,
        /// Cause.
        source: std::io::Error,
    },
}

/// A held run-id lock; released (and its file deleted) when dropped, released by the kernel
/// when the process ends otherwise.
#[derive(Debug)]
pub struct RunLock {
    _file: File,
    path: PathBuf,
}

impl Drop for RunLock {
    fn drop(&mut self) {
        // Deleted while still held: a process that opened the file meanwhile finds, once it
        // holds the lock, that the path no longer names that file, and starts again.
        let _ = std::fs::remove_file(&self.path);
    }
}

/// How often [`acquire`] starts again when the file it locked was deleted meanwhile (each
/// time means another process released or cleaned the same run id within microseconds).
const RETRIES: usize = 100;

impl RunLock {
    /// The lock file.
    pub fn path(&self) -> &std::path::Path {
        &self.path
    }
}

/// The lock folder: `$AMB_TESTBED_LOCK_DIR`, else `<temp dir>/amb-testbed`.
pub fn lock_dir() -> PathBuf {
    match std::env::var_os(LOCK_DIR_ENV) {
        Some(dir) if !dir.is_empty() => PathBuf::from(dir),
        _ => std::env::temp_dir().join("amb-testbed"),
    }
}

/// Takes run id `run_id` for `role` (`plant`, `controller`), or says who holds it. `run_id`
/// must be valid ([`crate::wire::valid_run_id`]: no `/`).
///
/// ```
/// let dir = std::env::temp_dir().join(format!("lock-doc-{}", std::process::id()));
/// std::env::set_var(controller::lock::LOCK_DIR_ENV, &dir);
/// let held = controller::lock::acquire("doc-run", "plant").unwrap();
/// let second = controller::lock::acquire("doc-run", "plant").unwrap_err().to_string();
/// assert!(second.contains("in use") && second.contains(&std::process::id().to_string()), "{second}");
/// drop(held);
/// assert!(controller::lock::acquire("doc-run", "plant").is_ok());
/// ```
pub fn acquire(run_id: &str, role: &str) -> Result<RunLock, LockError> {
    acquire_in(&lock_dir(), run_id, role)
}

/// [`acquire`] in lock folder `dir`.
fn acquire_in(dir: &std::path::Path, run_id: &str, role: &str) -> Result<RunLock, LockError> {
    let path = dir.join(format!("{run_id}.{role}.lock"));
    let io = |source| LockError::Io { run_id: run_id.to_string(), path: path.display().to_string(), source };
    if !dir.is_dir() {
        std::fs::create_dir_all(dir).map_err(io)?;
        // Machine-wide like /tmp: any user may add a lock; best effort.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let _ = std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o1777));
        }
    }
    remove_stale(dir, &path);
    for attempt in 0..RETRIES {
        let mut file =
            OpenOptions::new().read(true).write(true).create(true).truncate(false).open(&path).map_err(io)?;
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                let mut holder = String::new();
                let _ = file.read_to_string(&mut holder);
                let holder = holder.trim();
                // No name yet: the holder may be another process's `remove_stale`, which locks
                // every lock file it finds for a moment to see whether it is stale (and a file
                // just created, not yet locked by its owner, looks so): a controller started
                // beside others (a ladder's members) was refused its own fresh run id. A real
                // holder writes its name at once; wait for it a little.
                if holder.is_empty() && attempt + 1 < RETRIES {
                    std::thread::sleep(std::time::Duration::from_millis(2));
                    continue;
                }
                return Err(LockError::InUse {
                    run_id: run_id.to_string(),
                    role: role.to_string(),
                    holder: if holder.is_empty() {
                        "a process that has not written its name yet".into()
                    } else {
                        holder.into()
                    },
                    path: path.display().to_string(),
                });
            }
            Err(TryLockError::Error(e)) => return Err(io(e)),
        }
        if !names_file(&path, &file) {
            continue; // deleted by its releasing holder between our open and our lock
        }
        let args: Vec<String> = std::env::args().collect();
        let text = format!("pid {} ({})\n", std::process::id(), args.join(" "));
        file.set_len(0)
            .and_then(|()| file.seek(SeekFrom::Start(0)))
            .and_then(|_| file.write_all(text.as_bytes()))
            .map_err(io)?;
        return Ok(RunLock { _file: file, path });
    }
    Err(io(std::io::Error::other(format!("the lock file was deleted under this process {RETRIES} times in a row"))))
}

/// True when `path` names the open `file` (same device and inode).
fn names_file(path: &std::path::Path, file: &File) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (std::fs::metadata(path), file.metadata()) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (path, file);
        true
    }
}

/// Deletes the lock files in `dir` whose holder died without releasing them (they can be
/// locked), except `keep` (taken next). Best effort: a file of another user, or one a live
/// process holds, stays.
fn remove_stale(dir: &std::path::Path, keep: &std::path::Path) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let path = entry.path();
        if path == keep || path.extension().is_none_or(|e| e != "lock") {
            continue;
        }
        let Ok(file) = OpenOptions::new().read(true).write(true).open(&path) else { continue };
        if file.try_lock().is_ok() && names_file(&path, &file) {
            let _ = std::fs::remove_file(&path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("lock-unit-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    fn files(dir: &std::path::Path) -> Vec<String> {
        let mut names: Vec<String> =
            std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        names
    }

    /// Issue 21 item 7: lock files were never removed (384 after about 190 runs).
    #[test]
    fn a_released_lock_leaves_no_file() {
        let dir = scratch("released");
        for i in 0..5 {
            let plant = acquire_in(&dir, &format!("run{i}"), "plant").unwrap();
            let controller = acquire_in(&dir, &format!("run{i}"), "controller").unwrap();
            assert_eq!(files(&dir), [format!("run{i}.controller.lock"), format!("run{i}.plant.lock")]);
            drop((plant, controller));
        }
        assert!(files(&dir).is_empty(), "{:?}", files(&dir));
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A controller started beside others was refused its own fresh run id: another process's
    /// `remove_stale` held the new file's lock for a moment (it locks every lock file to see
    /// whether it is stale), and the owner took that for a live holder. A lock held for a
    /// moment by a process that writes no name is now waited for.
    #[test]
    fn a_lock_held_for_a_moment_by_a_stale_scan_is_waited_for() {
        let dir = scratch("scan");
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("fresh.controller.lock");
        let scanner = OpenOptions::new().read(true).write(true).create(true).truncate(false).open(&path).unwrap();
        scanner.try_lock().unwrap();
        let released = std::thread::spawn(move || {
            std::thread::sleep(std::time::Duration::from_millis(20));
            drop(scanner);
        });
        let lock = acquire_in(&dir, "fresh", "controller");
        released.join().unwrap();
        assert!(lock.is_ok(), "{:?}", lock.err().map(|e| e.to_string()));
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// The file of a holder that died without releasing (SIGKILL) goes at the next acquire;
    /// a live holder's stays, and so does its lock.
    #[test]
    fn the_files_of_dead_holders_are_removed_and_the_live_ones_kept() {
        let dir = scratch("stale");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("dead.plant.lock"), "pid 1 (killed)\n").unwrap();
        std::fs::write(dir.join("notes.txt"), "not a lock").unwrap();
        let live = acquire_in(&dir, "live", "plant").unwrap();
        assert_eq!(files(&dir), ["live.plant.lock", "notes.txt"]);
        let other = acquire_in(&dir, "other", "plant").unwrap();
        assert_eq!(files(&dir), ["live.plant.lock", "notes.txt", "other.plant.lock"]);
        let e = acquire_in(&dir, "live", "plant").unwrap_err().to_string();
        assert!(e.contains("in use") && e.contains(&std::process::id().to_string()), "{e}");
        drop((live, other));
        assert_eq!(files(&dir), ["notes.txt"]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A process that opened the file before its holder released (and deleted) it holds a lock
    /// on a deleted file: it must not take that for the run id's.
    #[test]
    fn a_lock_on_a_deleted_file_is_not_the_run_ids() {
        let dir = scratch("deleted");
        let held = acquire_in(&dir, "r", "plant").unwrap();
        let early = File::open(held.path()).unwrap();
        assert!(names_file(held.path(), &early));
        let path = held.path().to_path_buf();
        drop(held);
        early.try_lock().expect("the released inode can be locked");
        assert!(!names_file(&path, &early), "the path no longer names the early opener's file");
        let again = acquire_in(&dir, "r", "plant").expect("a new file is taken");
        assert!(names_file(again.path(), &File::open(again.path()).unwrap()));
        drop((early, again));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
