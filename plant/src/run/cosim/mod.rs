//! Co-simulation with the controller as a separate process over iceoryx2
//! (`controller.mode = "lockstep"` or `"realtime"`); the protocol is in
//! [`controller::wire`], the plumbing in [`controller::link`].
//!
//! # Timing (tick `k` at `t_k = k T`, delay `d = controller.delay_samples`)
//!
//! - `lockstep`: at tick `k` the plant publishes sensor frame `k` and waits
//!   for the reply to `k` (busy-polling `controller.spin_us`, then blocking
//!   on an event), then treats it exactly as `sampled` mode treats the
//!   in-process law's output: saturated, pushed into the delay line
//!   prefilled with `d` bias commands, applied from tick `k + d`. With the
//!   same law code on the other side and `f64` on the wire, a lockstep run
//!   is bit-identical to the `sampled` run of the same scene.
//! - `realtime`: tick `k` starts at wall time `start + k T`. The plant takes
//!   the reply to sample `k − 1` (it had one period), publishes frame `k`
//!   and integrates the period. A reply missing at its tick is a deadline
//!   miss and the last current is held; a reply that comes later is stale
//!   and dropped. The reply is one sample old by construction, so the
//!   delay line is prefilled with `d − 1` commands and `d ≥ 1`. A plant
//!   step that ends after the next tick's start is a plant overrun. How the
//!   processes wait (`controller.pacing`, `controller.pin_cores`): on cores of
//!   their own a spinning plant's controller spins too (at least 100 periods
//!   before it blocks); on one shared core the controller never spins and
//!   runs one `SCHED_FIFO` level above the plant, answering each frame at
//!   once ([`watchdog`] gives the core back to the plant if it stops
//!   blocking).
//!
//! # Faults
//!
//! While a reply is missing for `controller.reply_timeout_ms`, the plant
//! looks up the controller's node (and its own child process): dead or gone
//! is a lost peer; alive is waited for (lockstep: a controller under a
//! debugger is not lost) or counted as misses (realtime). On a loss the
//! plant records a peer event and applies `controller.fallback` (`hold`
//! the last current, `bias` current only, or `stop`). With
//! `controller.reconnect_timeout_ms > 0` it then waits for a new controller
//! (it respawns the one it started itself; an external one is restarted
//! by the user): lockstep pauses the simulation meanwhile (the fallback
//! answers the lost sample), realtime keeps pacing with the fallback.
//! Without a reconnection the run stops as `peer_lost` (exit code 4).
//! A controller that stops on SIGINT/SIGTERM says so (a STOPPING frame); the
//! plant treats it as a lost controller (fallback, reconnection, else
//! `peer_lost`, exit code 4).
//!
//! A plant (lockstep or realtime) waiting on a controller that is alive but
//! silent (stopped with SIGSTOP, hung, answering another session) gives up
//! after `controller.lockstep_timeout_ms`, says what it saw in the meantime
//! (nothing, replies of another session, frames of another run) and treats
//! the controller as lost. A realtime run whose share of ticks without the
//! controller's reply (deadline misses, fallback ticks) exceeds
//! `controller.max_miss_fraction` (default 1 %) ends as `miss_budget` (exit
//! 6), one whose plant overruns exceed `controller.max_overrun_fraction`
//! (default 5 %) as `overrun_budget` (exit 10): a realtime run that is
//! `completed` ran the scene's loop within those budgets.
//!
//! # Isolation
//!
//! A plant holds its run id's lock ([`controller::lock`]) for its whole
//! life: a second plant under a live run id is refused (exit 2, naming the
//! first); the kernel releases the lock of a crashed plant. Each run draws a
//! random token ([`new_token`]) that the hello and every frame carry; a frame
//! or an ack with another token (a second run under the same run id, a stale
//! or a foreign process) is never applied, and is counted in
//! `foreign_frames`.

mod bench;
pub mod log;
pub mod process;
pub mod session;
pub mod stats;
pub mod watchdog;

pub use bench::bench_round_trips;
pub use session::{Halt, Session};
pub use stats::{CosimReport, Latencies, Misses, Percentiles};

use controller::link::LinkError;
use serde::Serialize;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU32, Ordering};

/// Where the controller process comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ControllerProcess {
    /// The plant starts it: the given executable; else the scene's `controller.command`, if
    /// any; else `controller` next to the running one.
    Spawn(Option<PathBuf>),
    /// The user starts `controller --run-id ID`; the plant waits for it.
    External,
}

/// How a co-simulation run is launched (command-line choices, not physics).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Launch {
    /// Who starts the controller.
    pub controller: ControllerProcess,
    /// Run id; `None` = a fresh one (process id, counter, time).
    pub run_id: Option<String>,
    /// The file that gets the output of the controller processes the plant starts
    /// (`controller.log` in the run folder); `None`: drained, only its last lines kept for the
    /// messages ([`log`]).
    pub log: Option<PathBuf>,
}

impl Default for Launch {
    /// The plant starts the `controller` next to its own executable, with a fresh run id.
    fn default() -> Self {
        Self { controller: ControllerProcess::Spawn(None), run_id: None, log: None }
    }
}

/// A fresh run id: `<pid>-<counter>-<ms since 1970, hex>`, unique per
/// process and call.
pub fn new_run_id() -> String {
    static COUNTER: AtomicU32 = AtomicU32::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let ms = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_millis()).unwrap_or(0);
    format!("{}-{n}-{ms:x}", std::process::id())
}

/// A fresh run token: 8 bytes of `/dev/urandom`, else a hash of the process id and the time;
/// never 0.
pub fn new_token() -> u64 {
    use std::hash::{BuildHasher, Hash, Hasher};
    use std::io::Read;
    let mut bytes = [0u8; 8];
    let random = std::fs::File::open("/dev/urandom").and_then(|mut f| f.read_exact(&mut bytes)).is_ok();
    let token = if random {
        u64::from_ne_bytes(bytes)
    } else {
        // RandomState is seeded per process by the standard library.
        let mut h = std::collections::hash_map::RandomState::new().build_hasher();
        std::process::id().hash(&mut h);
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0)
            .hash(&mut h);
        h.finish()
    };
    token.max(1)
}

/// Why a co-simulation could not start.
#[derive(Debug, thiserror::Error)]
pub enum CosimError {
    /// No controller executable where it was looked for.
    #[error("controller executable not found at {} ({why}): build it with `cargo build --release` (it is built next to `plant`), or start one yourself and pass `--controller external`", path.display())]
    ControllerMissing {
        /// Where it was looked for.
        path: PathBuf,
        /// Why it is not usable.
        why: String,
    },
    /// The executable could not be started.
    #[error("cannot start the controller {}: {why}", path.display())]
    Spawn {
        /// Executable.
        path: PathBuf,
        /// OS error.
        why: String,
    },
    /// The child exited before the handshake.
    #[error("the controller process {program} exited before the handshake ({status}{hint}){output}", hint = exit_hint(*code))]
    ControllerExited {
        /// What was started.
        program: String,
        /// Exit status as text.
        status: String,
        /// Exit code, if any.
        code: Option<i32>,
        /// Its last output and where the rest is (`; its last output (…/controller.log): "…"`).
        output: String,
    },
    /// `controller.command` does not exist or is not executable (nothing was started).
    #[error("controller.command: cannot run {argv0:?}: {why}")]
    Command {
        /// The command's first element.
        argv0: String,
        /// What is wrong.
        why: String,
    },
    /// Another live plant (or controller) holds the run id.
    #[error(transparent)]
    Lock(#[from] controller::lock::LockError),
    /// The controller refused the hello.
    #[error("the controller refused the run ({reason}): {message}")]
    Refused {
        /// Refusal kind.
        reason: &'static str,
        /// Its message.
        message: String,
    },
    /// Nobody answered the hello in time.
    #[error("no controller answered within {waited_s} s for run id {run_id}{hint}")]
    NoController {
        /// How long the plant waited (s).
        waited_s: f64,
        /// Run id.
        run_id: String,
        /// What to do.
        hint: String,
    },
    /// SIGINT/SIGTERM while waiting for the controller.
    #[error("interrupted while waiting for the controller")]
    Interrupted,
    /// iceoryx2 failure.
    #[error(transparent)]
    Link(#[from] LinkError),
    /// A bad run id (from `--run-id`).
    #[error("{0}")]
    RunId(String),
    /// Core pinning failed.
    #[error("controller.pin_cores: {0}")]
    Pin(String),
    /// The law's parameter document does not fit the hello.
    #[error("{0}")]
    Params(#[from] controller::ParamsError),
    /// The controller's handshake answer is malformed, or of another protocol version.
    #[error("the controller's handshake answer is malformed: {0}")]
    Protocol(String),
    /// The controller's handshake overrides change what is not the controller's to change
    /// ([`crate::config::CONTROLLER_OVERRIDE_KEYS`], a current limit above the scene's).
    #[error("the controller {controller} sent back {why}: refused, nothing of it applied")]
    Overrides {
        /// The controller: its program, its description and pid.
        controller: String,
        /// The key, its value and the rule.
        why: String,
    },
}

/// What an early exit code of a controller says (the codes of `controller::serve`).
fn exit_hint(code: Option<i32>) -> &'static str {
    match code {
        Some(2) => ": it refused the run, or found a peer of another protocol version",
        Some(4) => ": it saw no plant",
        Some(1) => ": an IPC failure or an error of its own",
        _ => "",
    }
}

/// Something that happened to the peer, for `summary.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PeerEvent {
    /// `connected`, `lost`, `reconnected`, `stopped`.
    pub kind: &'static str,
    /// Simulated time (s).
    pub t_s: f64,
    /// Tick index.
    pub seq: u64,
    /// Wall time since the loop started (s).
    pub wall_s: f64,
    /// Details (the controller's description, the cause of a loss, the fallback applied).
    pub detail: String,
}
