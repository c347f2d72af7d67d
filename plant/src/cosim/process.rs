//! The controller process the plant starts and reaps.
//!
//! The child runs in its own process group, so a Ctrl-C in the terminal
//! reaches the plant only, which then ends the run in order (a STOP frame,
//! then the child exits 0). Dropping a [`Child`] that is still running
//! sends SIGTERM, then SIGKILL after a grace period, and waits for it: no
//! controller outlives a plant that exits (a plant killed with SIGKILL
//! cannot do this; its controller notices the dead node and exits).

use super::CosimError;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// Name of the controller executable.
pub const CONTROLLER_EXE: &str = "controller";

/// The controller executable next to the running one (`cargo build` puts
/// `plant` and `controller` in the same folder).
pub fn controller_exe_next_to_current() -> Result<PathBuf, CosimError> {
    let current = std::env::current_exe().map_err(|e| CosimError::ControllerMissing {
        path: PathBuf::from(CONTROLLER_EXE),
        why: format!("cannot locate the running executable: {e}"),
    })?;
    let dir = current.parent().unwrap_or(Path::new("."));
    let path = dir.join(format!("{CONTROLLER_EXE}{}", std::env::consts::EXE_SUFFIX));
    if path.is_file() {
        Ok(path)
    } else {
        Err(CosimError::ControllerMissing { path, why: "no such file".into() })
    }
}

/// A running controller process.
pub struct Child {
    child: std::process::Child,
    exe: PathBuf,
}

/// Arguments of a controller process.
pub struct Args<'a> {
    /// Run id.
    pub run_id: &'a str,
    /// Core to pin it to.
    pub pin_core: Option<usize>,
    /// Its wait for the hello (s).
    pub connect_timeout_s: f64,
}

impl Child {
    /// Starts `exe --run-id … --quiet`.
    pub fn spawn(exe: &Path, args: &Args) -> Result<Self, CosimError> {
        let mut cmd = Command::new(exe);
        cmd.arg("--run-id")
            .arg(args.run_id)
            .arg("--quiet")
            .arg("--connect-timeout-s")
            .arg(args.connect_timeout_s.to_string())
            .stdin(Stdio::null())
            .process_group(0);
        if let Some(core) = args.pin_core {
            cmd.arg("--pin-core").arg(core.to_string());
        }
        let child = cmd.spawn().map_err(|e| CosimError::Spawn { path: exe.to_path_buf(), why: e.to_string() })?;
        Ok(Self { child, exe: exe.to_path_buf() })
    }

    /// Process id.
    pub fn id(&self) -> u32 {
        self.child.id()
    }

    /// The executable.
    pub fn exe(&self) -> &Path {
        &self.exe
    }

    /// The exit status if it has exited (reaped).
    pub fn exited(&mut self) -> Option<ExitStatus> {
        self.child.try_wait().ok().flatten()
    }

    /// Waits up to `grace` for it to exit by itself, then sends SIGTERM,
    /// then SIGKILL; returns its exit status.
    pub fn reap(&mut self, grace: Duration) -> Option<ExitStatus> {
        if let Some(s) = self.wait_for(grace) {
            return Some(s);
        }
        self.signal(libc::SIGTERM);
        if let Some(s) = self.wait_for(Duration::from_secs(2)) {
            return Some(s);
        }
        let _ = self.child.kill();
        self.child.wait().ok()
    }

    fn wait_for(&mut self, grace: Duration) -> Option<ExitStatus> {
        let until = Instant::now() + grace;
        loop {
            if let Some(s) = self.exited() {
                return Some(s);
            }
            if Instant::now() >= until {
                return None;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    fn signal(&self, signal: libc::c_int) {
        if let Ok(pid) = libc::pid_t::try_from(self.child.id()) {
            // SAFETY: kill(2) has no memory-safety preconditions; the child is
            // not reaped yet, so its pid cannot have been reused.
            unsafe { libc::kill(pid, signal) };
        }
    }
}

impl Drop for Child {
    fn drop(&mut self) {
        if self.exited().is_none() {
            self.reap(Duration::ZERO);
        }
    }
}
