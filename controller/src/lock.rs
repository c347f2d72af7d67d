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
//! (`/tmp/amb-testbed`), machine-wide like iceoryx2's own resources. Lock
//! files are left in place when released: deleting one while another
//! process may be opening it would let two processes hold "the" lock.

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

/// A held run-id lock; released when dropped (or when the process ends).
#[derive(Debug)]
pub struct RunLock {
    _file: File,
    path: PathBuf,
}

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
    let dir = lock_dir();
    let path = dir.join(format!("{run_id}.{role}.lock"));
    let io = |source| LockError::Io { run_id: run_id.to_string(), path: path.display().to_string(), source };
    if !dir.is_dir() {
        std::fs::create_dir_all(&dir).map_err(io)?;
        // Machine-wide like /tmp: any user may add a lock; best effort.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let _ = std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o1777));
        }
    }
    let mut file = OpenOptions::new().read(true).write(true).create(true).truncate(false).open(&path).map_err(io)?;
    match file.try_lock() {
        Ok(()) => {}
        Err(TryLockError::WouldBlock) => {
            let mut holder = String::new();
            let _ = file.read_to_string(&mut holder);
            let holder = holder.trim();
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
    let args: Vec<String> = std::env::args().collect();
    let text = format!("pid {} ({})\n", std::process::id(), args.join(" "));
    file.set_len(0)
        .and_then(|()| file.seek(SeekFrom::Start(0)))
        .and_then(|_| file.write_all(text.as_bytes()))
        .map_err(io)?;
    Ok(RunLock { _file: file, path })
}
