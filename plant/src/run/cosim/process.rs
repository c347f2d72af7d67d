//! The controller process the plant starts and reaps: the built-in
//! `controller` binary, or the scene's `controller.command` (any executable
//! that speaks the wire protocol).
//!
//! The child runs in its own process group with stdin from `/dev/null` and
//! its stdout and stderr into a pipe the plant drains into `controller.log`
//! ([`super::log`]), so a Ctrl-C in the terminal reaches the plant only, which then ends the run in order (a STOP frame, then the child
//! exits 0). Dropping a [`Child`] that is still running sends SIGTERM, then
//! SIGKILL after a grace period, and waits for it: no controller outlives a
//! plant that exits (a plant killed with SIGKILL cannot do this; its
//! controller notices the dead node and exits).
//!
//! # The command contract
//!
//! The plant runs `controller.command` exactly (`argv[0]` looked up in `PATH`
//! when it has no `/`), with `--run-id <ID>` appended and the environment
//! variables [`RUN_ID_ENV`] (the run id), [`CONNECT_TIMEOUT_ENV`] (how long
//! the plant waits for the handshake, s) and, with
//! `controller.realtime_priority = N > 0`, [`REALTIME_PRIORITY_ENV`] = the controller's own
//! priority, next to the plant's `N` (the session's `controller_priority`).
//! Relative paths were resolved against the scene file's folder when the
//! scene loaded (see `config::validate`). A command that does not exist or is
//! not executable is refused before anything starts ([`resolve`]).

use super::CosimError;
pub use controller::serve::{CONNECT_TIMEOUT_ENV, REALTIME_PRIORITY_ENV, RUN_ID_ENV};
use std::os::unix::fs::PermissionsExt;
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

/// What the plant starts.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Program {
    /// The built-in `controller` binary: `exe --run-id ID --quiet --connect-timeout-s S
    /// [--pin-core N]`.
    Builtin(PathBuf),
    /// A scene's `controller.command`: `argv… --run-id ID` (the executable checked).
    Command {
        /// The command as given (paths resolved against the scene's folder).
        argv: Vec<String>,
        /// `argv[0]` as found (in `PATH` if it has no `/`).
        exe: PathBuf,
    },
}

impl Program {
    /// The program, for messages.
    pub fn describe(&self) -> String {
        match self {
            Program::Builtin(exe) => exe.display().to_string(),
            Program::Command { argv, .. } => format!("`{}` (controller.command)", argv.join(" ")),
        }
    }
}

/// Checks a `controller.command`: `argv[0]` must name an executable regular file (a path, or
/// a name found in `PATH`).
pub fn resolve(argv: &[String]) -> Result<Program, CosimError> {
    let Some(first) = argv.first() else {
        return Err(CosimError::Command { argv0: String::new(), why: "the command is empty".into() });
    };
    let refuse = |why: String| CosimError::Command { argv0: first.clone(), why };
    let exe = if first.contains('/') {
        PathBuf::from(first)
    } else {
        let path = std::env::var_os("PATH").unwrap_or_default();
        std::env::split_paths(&path)
            .map(|dir| dir.join(first))
            .find(|p| p.is_file())
            .ok_or_else(|| refuse(format!("no executable of that name in PATH ({})", PathBuf::from(&path).display())))?
    };
    let meta = std::fs::metadata(&exe).map_err(|e| refuse(format!("{}: {e}", exe.display())))?;
    if !meta.is_file() {
        return Err(refuse(format!("{} is not a file", exe.display())));
    }
    if meta.permissions().mode() & 0o111 == 0 {
        return Err(refuse(format!(
            "{} is not executable (mode {:o}; chmod +x it, or name its interpreter first, e.g. [\"python3\", \"{first}\"])",
            exe.display(),
            meta.permissions().mode() & 0o7777
        )));
    }
    Ok(Program::Command { argv: argv.to_vec(), exe })
}

/// A running controller process.
pub struct Child {
    child: std::process::Child,
    program: Program,
}

/// Arguments of a controller process.
pub struct Args<'a> {
    /// Run id.
    pub run_id: &'a str,
    /// Core to pin it to.
    pub pin_core: Option<usize>,
    /// Its wait for the hello (s).
    pub connect_timeout_s: f64,
    /// Its `SCHED_FIFO` priority (0: off).
    pub realtime_priority: u32,
}

impl Child {
    /// Starts the program (see [`Program`] and the module doc), its output into `log`.
    pub fn spawn(program: &Program, args: &Args, log: &mut super::log::OutputLog) -> Result<Self, CosimError> {
        let mut cmd = match program {
            Program::Builtin(exe) => {
                let mut cmd = Command::new(exe);
                cmd.arg("--run-id")
                    .arg(args.run_id)
                    .arg("--quiet")
                    .arg("--connect-timeout-s")
                    .arg(args.connect_timeout_s.to_string());
                if let Some(core) = args.pin_core {
                    cmd.arg("--pin-core").arg(core.to_string());
                }
                cmd
            }
            Program::Command { argv, exe } => {
                let mut cmd = Command::new(exe);
                cmd.arg0(&argv[0]).args(&argv[1..]).arg("--run-id").arg(args.run_id);
                cmd
            }
        };
        let (out, err) = log.attach(&format!("{} for run {}", program.describe(), args.run_id)).map_err(|e| {
            CosimError::Spawn { path: PathBuf::from(program.describe()), why: format!("a pipe for its output: {e}") }
        })?;
        cmd.env(RUN_ID_ENV, args.run_id)
            .env(CONNECT_TIMEOUT_ENV, args.connect_timeout_s.to_string())
            .stdin(Stdio::null())
            .stdout(out)
            .stderr(err)
            .process_group(0);
        if args.realtime_priority > 0 {
            cmd.env(REALTIME_PRIORITY_ENV, args.realtime_priority.to_string());
        } else {
            cmd.env_remove(REALTIME_PRIORITY_ENV);
        }
        let child = cmd.spawn().map_err(|e| match program {
            Program::Builtin(exe) => CosimError::Spawn { path: exe.clone(), why: e.to_string() },
            Program::Command { argv, .. } => CosimError::Command { argv0: argv[0].clone(), why: e.to_string() },
        })?;
        if let (Program::Command { .. }, Some(core)) = (program, args.pin_core) {
            // A command gets no --pin-core: its main thread is pinned from here (threads it starts
            // later inherit the mask).
            pin_pid(child.id(), core).map_err(CosimError::Pin)?;
        }
        Ok(Self { child, program: program.clone() })
    }

    /// Process id.
    pub fn id(&self) -> u32 {
        self.child.id()
    }

    /// What was started.
    pub fn program(&self) -> &Program {
        &self.program
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

/// Pins process `pid`'s main thread to one CPU core.
fn pin_pid(pid: u32, core: usize) -> Result<(), String> {
    let pid = libc::pid_t::try_from(pid).map_err(|_| format!("pid {pid} is out of range"))?;
    if core >= libc::CPU_SETSIZE as usize {
        return Err(format!("core {core} is beyond the CPU set size"));
    }
    // SAFETY: cpu_set_t is plain data; CPU_ZERO/CPU_SET write inside it; sched_setaffinity
    // reads it.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_ZERO(&mut set);
        libc::CPU_SET(core, &mut set);
        if libc::sched_setaffinity(pid, std::mem::size_of::<libc::cpu_set_t>(), &set) != 0 {
            return Err(format!("cannot pin the controller to core {core}: {}", std::io::Error::last_os_error()));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_command_must_exist_and_be_executable() {
        let e = resolve(&["/no/such/controller".into()]).unwrap_err().to_string();
        assert!(e.contains("/no/such/controller") && e.contains("No such file"), "{e}");
        let e = resolve(&["no-such-controller-anywhere".into()]).unwrap_err().to_string();
        assert!(e.contains("no-such-controller-anywhere") && e.contains("PATH"), "{e}");
        let dir = std::env::temp_dir().join(format!("plant-resolve-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let plain = dir.join("plain.py");
        std::fs::write(&plain, "print()\n").unwrap();
        std::fs::set_permissions(&plain, std::fs::Permissions::from_mode(0o644)).unwrap();
        let e = resolve(&[plain.display().to_string()]).unwrap_err().to_string();
        assert!(e.contains("not executable") && e.contains("644"), "{e}");
        let e = resolve(&[dir.display().to_string()]).unwrap_err().to_string();
        assert!(e.contains("not a file"), "{e}");
        assert!(matches!(resolve(&["sh".into(), "-c".into()]), Ok(Program::Command { .. })));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
