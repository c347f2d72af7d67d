//! A complete controller process in one call: [`serve`] makes any crate that
//! depends on `controller` a controller the plant can start (`[controller]
//! command`) or wait for (`plant run … --controller external`).
//!
//! ```no_run
//! // src/main.rs of your own crate, with `controller = { path = "…/controller" }`:
//! fn main() -> std::process::ExitCode {
//!     // The laws this process serves: yours (a `LawEntry` in your crate) and/or the registry's.
//!     controller::serve(&[controller::pd::LAW])
//! }
//! ```
//!
//! Laws of both kinds (per plane, [`crate::LawEntry`]; of the whole rotor, [`crate::RotorLawEntry`])
//! are served together as [`AnyLaw`]s: `controller::serve(controller::ALL_LAWS)` is the
//! `controller` binary. A per-plane law serves the planar model (2 axes) and, one instance per
//! bearing plane, the two-plane rotor (4 axes); a law of the whole rotor the rotor it drives
//! (a hello it cannot drive is refused with code 3, axes).
//!
//! What [`serve`] does, in order:
//!
//! 1. reads the command line ([`ServeArgs`]: `--run-id ID` or the
//!    `AMB_TESTBED_RUN_ID` environment variable, `--law`, `--config`,
//!    `--pin-core`, `--connect-timeout-s` or `AMB_TESTBED_CONNECT_TIMEOUT_S`,
//!    `--quiet`); installs one SIGINT/SIGTERM handler;
//! 2. takes the run id's controller lock ([`crate::lock`]): a second
//!    controller under a live run id is refused (exit 2, naming the first);
//! 3. waits for the plant's hello, checks it ([`wire::check_hello`]: protocol
//!    version 4, 2 or 4 axes), applies the `--config`/`--law` overrides, and
//!    builds the law the hello names from the laws given to it, for the
//!    rotor the hello describes ([`Hello::rotor_design`]); refuses the run (an
//!    [`Ack`] with a [`Refusal`] code and the reason) when the law is not
//!    among them, cannot drive that rotor, or refuses its parameters;
//! 4. answers every sensor frame of the run's token and session with the
//!    law's currents, each saturated at its plane's limit, through
//!    [`link::Endpoint`] (spin, then block, with the wake protocol both ways:
//!    it asks to be woken before blocking, and wakes the plant when asked);
//! 5. watches the plant's node while it is silent, and ends: 0 on the plant's
//!    STOP frame, 4 when the plant is gone or never says hello, 130 on
//!    SIGINT/SIGTERM (after a STOPPING frame to the plant), 2 on bad input or
//!    a refused hello, 1 on an IPC failure ([`ServeError::exit_code`]).
//!
//! With `AMB_TESTBED_REALTIME_PRIORITY=N` (the plant sets it for the
//! controllers it starts when `controller.realtime_priority = N`), the
//! process puts itself under `SCHED_FIFO` at N and locks its memory, with a
//! warning for each step the system refuses.

use crate::file::{self, Applied, LawOverrides};
use crate::law::{build_among, saturate_axes, AnyLaw, LawError, RotorLaw, ROTOR_AXES};
use crate::link::{self, Endpoint, LinkError, Mailbox, Peer};
use crate::lock::{self, LockError};
use crate::wire::{self, Ack, CommandFrame, Expect, Hello, Refusal, SensorFrame};
use clap::{CommandFactory, FromArgMatches, Parser};
use std::ffi::OsString;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Environment variable with the run id (used when `--run-id` is not given).
pub const RUN_ID_ENV: &str = "AMB_TESTBED_RUN_ID";
/// Environment variable with the wait for the hello (s), used when `--connect-timeout-s` is
/// not given.
pub const CONNECT_TIMEOUT_ENV: &str = "AMB_TESTBED_CONNECT_TIMEOUT_S";
/// Environment variable asking for `SCHED_FIFO` at this priority and locked memory.
pub const REALTIME_PRIORITY_ENV: &str = "AMB_TESTBED_REALTIME_PRIORITY";
/// Fault injection for the end-to-end tests: when set to N, the process kills itself with
/// SIGKILL on the first sensor frame with `seq >= N` of session 1 (a hard crash at a
/// reproducible point; `>=` because a realtime plant may overwrite frames of a stalled
/// controller). A controller that reconnects (session 2 on) is spared.
pub const CRASH_AT_SEQ_ENV: &str = "AMB_CONTROLLER_CRASH_AT_SEQ";

/// The default wait for the hello (s).
pub const DEFAULT_CONNECT_TIMEOUT_S: f64 = 30.0;

/// How often at most a silent plant that is not this process's parent is looked up by its
/// node (a listing of the machine's iceoryx2 nodes; slower ones are paced further by their
/// cost, [`link::PeerWatch`]).
const LIVENESS_EVERY: Duration = Duration::from_millis(20);

/// Slice of a blocking wait: the longest a signal goes unnoticed while blocked.
const SLICE: Duration = Duration::from_millis(1);

/// Exit codes of a controller process, one per kind of ending.
pub mod exit {
    /// The plant ended the run.
    pub const OK: u8 = 0;
    /// An IPC failure.
    pub const IO: u8 = 1;
    /// Bad arguments or file, unknown law, a refused hello, another protocol version, a run
    /// id in use.
    pub const BAD_INPUT: u8 = 2;
    /// The plant died or never said hello.
    pub const PLANT_LOST: u8 = 4;
    /// SIGINT or SIGTERM.
    pub const INTERRUPTED: u8 = 130;
}

/// The command line of a controller process (any crate served by [`serve`]).
#[derive(Parser, Debug, Clone)]
#[command(version, about = "AMB controller process: serves one plant run over iceoryx2")]
pub struct ServeArgs {
    /// Run id printed by `plant run … --controller external` (or passed by the plant);
    /// default: the `AMB_TESTBED_RUN_ID` environment variable.
    #[arg(long)]
    pub run_id: Option<String>,
    /// Run this law instead of the one the plant asks for (a law this controller serves);
    /// the plant's `[controller.params]` are then not used.
    #[arg(long)]
    pub law: Option<String>,
    /// A TOML file whose `[controller]` table overrides the law design and `[controller.params]`
    /// its parameters (a scene file works); its `rate_hz`, if given, must match the plant's.
    /// What it changes is sent back to the plant, which records it in the run folder.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Pin this process to a CPU core.
    #[arg(long)]
    pub pin_core: Option<usize>,
    /// How long to wait for the plant's hello (s); default: `AMB_TESTBED_CONNECT_TIMEOUT_S`,
    /// else 30.
    #[arg(long)]
    pub connect_timeout_s: Option<f64>,
    /// No start-up and end lines.
    #[arg(long)]
    pub quiet: bool,
}

/// How to serve a run, checked.
#[derive(Debug, Clone, PartialEq)]
pub struct ServeOptions {
    /// The run id (valid: [`wire::valid_run_id`]).
    pub run_id: String,
    /// `--law`: a law to run instead of the plant's.
    pub law: Option<String>,
    /// `--config`: the overrides file.
    pub config: Option<PathBuf>,
    /// Core to pin to.
    pub pin_core: Option<usize>,
    /// How long to wait for the hello.
    pub connect_timeout: Duration,
    /// No start-up and end lines.
    pub quiet: bool,
    /// `SCHED_FIFO` priority and locked memory ([`REALTIME_PRIORITY_ENV`]).
    pub realtime_priority: Option<i32>,
    /// Fault injection ([`CRASH_AT_SEQ_ENV`]).
    pub crash_at: Option<u64>,
}

impl ServeOptions {
    /// Options for run `run_id` with the defaults (30 s for the hello, nothing overridden).
    pub fn new(run_id: &str) -> Result<Self, ServeError> {
        let run_id = wire::valid_run_id(run_id).map_err(ServeError::BadArgument)?.to_string();
        Ok(Self {
            run_id,
            law: None,
            config: None,
            pin_core: None,
            connect_timeout: Duration::from_secs_f64(DEFAULT_CONNECT_TIMEOUT_S),
            quiet: false,
            realtime_priority: None,
            crash_at: None,
        })
    }

    /// Checks the arguments, completed from the environment (`get` reads a variable:
    /// `std::env::var`, or a map in tests).
    pub fn from_args(args: &ServeArgs, get: impl Fn(&str) -> Option<String>) -> Result<Self, ServeError> {
        let run_id = match (&args.run_id, get(RUN_ID_ENV)) {
            (Some(id), _) => id.clone(),
            (None, Some(id)) => id,
            (None, None) => {
                return Err(ServeError::BadArgument(format!("no run id: pass --run-id ID or set {RUN_ID_ENV}")))
            }
        };
        let mut opts = Self::new(&run_id)?;
        let timeout = match (args.connect_timeout_s, get(CONNECT_TIMEOUT_ENV)) {
            (Some(s), _) => ("--connect-timeout-s", s.to_string(), s),
            (None, Some(text)) => {
                let s = text.trim().parse::<f64>().unwrap_or(f64::NAN);
                (CONNECT_TIMEOUT_ENV, text, s)
            }
            (None, None) => ("", String::new(), DEFAULT_CONNECT_TIMEOUT_S),
        };
        let (source, text, seconds) = timeout;
        if !(seconds.is_finite() && seconds > 0.0 && seconds <= 1e6) {
            return Err(ServeError::BadArgument(format!("{source} {text} s: must be a finite number > 0 and <= 1e6")));
        }
        opts.connect_timeout = Duration::from_secs_f64(seconds);
        if let Some(text) = get(REALTIME_PRIORITY_ENV) {
            match text.trim().parse::<i32>() {
                Ok(p) if (1..=99).contains(&p) => opts.realtime_priority = Some(p),
                Ok(0) => {}
                _ => {
                    return Err(ServeError::BadArgument(format!(
                        "{REALTIME_PRIORITY_ENV}={text}: must be an integer from 0 (off) to 99"
                    )))
                }
            }
        }
        opts.law = args.law.clone();
        opts.config = args.config.clone();
        opts.pin_core = args.pin_core;
        opts.quiet = args.quiet;
        opts.crash_at = get(CRASH_AT_SEQ_ENV).and_then(|v| v.parse().ok());
        Ok(opts)
    }
}

/// Endings of a controller process that are not successes, each with its exit code.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// A command-line argument or environment variable is invalid.
    #[error("{0}")]
    BadArgument(String),
    /// The `--config` file is unreadable or invalid.
    #[error(transparent)]
    Config(#[from] file::FileError),
    /// `--law` names a law this controller does not serve.
    #[error("--law {name}: this controller serves {}", served.join(", "))]
    UnknownLaw {
        /// The name asked for.
        name: String,
        /// The laws served.
        served: Vec<&'static str>,
    },
    /// Another live controller holds the run id.
    #[error(transparent)]
    Lock(#[from] LockError),
    /// This controller refused the plant's hello (it was told why).
    #[error("refused the plant's hello ({}): {message}", Refusal::describe(*code))]
    Refused {
        /// The [`Refusal`] code sent.
        code: u32,
        /// The message sent.
        message: String,
    },
    /// The plant is gone, or never said hello.
    #[error("{0}; exiting")]
    PlantLost(String),
    /// SIGINT/SIGTERM; the plant was told.
    #[error("interrupted; told the plant (run {run_id}) and stopped")]
    Interrupted {
        /// The run.
        run_id: String,
    },
    /// An iceoryx2 failure, or a peer of another protocol version.
    #[error("{context}{0}", context = .1.as_deref().map(|c| format!("{c}: ")).unwrap_or_default())]
    Link(LinkError, Option<String>),
}

impl From<LinkError> for ServeError {
    fn from(e: LinkError) -> Self {
        ServeError::Link(e, None)
    }
}

impl ServeError {
    /// The exit code of this ending.
    pub fn exit_code(&self) -> u8 {
        match self {
            ServeError::BadArgument(_)
            | ServeError::Config(_)
            | ServeError::UnknownLaw { .. }
            | ServeError::Lock(LockError::InUse { .. })
            | ServeError::Refused { .. }
            | ServeError::Link(LinkError::Incompatible { .. }, _) => exit::BAD_INPUT,
            ServeError::PlantLost(_) => exit::PLANT_LOST,
            ServeError::Interrupted { .. } => exit::INTERRUPTED,
            ServeError::Link(LinkError::Ipc { .. }, _) | ServeError::Lock(LockError::Io { .. }) => exit::IO,
        }
    }
}

/// How a served run ended well (the plant's STOP).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Served {
    /// Sensor frames answered.
    pub answered: u64,
    /// Waits that ran out of their spin budget and blocked.
    pub blocks: u64,
}

/// Set by the one SIGINT/SIGTERM handler of [`serve`].
static STOP: AtomicBool = AtomicBool::new(false);

/// The whole controller process: reads the command line and the environment, serves one
/// run with `laws` (per-plane [`crate::LawEntry`]s, [`crate::RotorLawEntry`]s or [`AnyLaw`]s),
/// prints the ending once (`<program>: …`) and returns its exit code. Call it from `main`
/// (see the module doc).
pub fn serve<L: Copy + Into<AnyLaw>>(laws: &[L]) -> ExitCode {
    serve_from(std::env::args_os().collect(), laws)
}

/// [`serve`] with the command line given (the program name first).
pub fn serve_from<L: Copy + Into<AnyLaw>>(argv: Vec<OsString>, laws: &[L]) -> ExitCode {
    ExitCode::from(serve_code(argv, laws))
}

/// [`serve_from`], the exit code as a number (for the C API, which returns it).
pub fn serve_code<L: Copy + Into<AnyLaw>>(argv: Vec<OsString>, laws: &[L]) -> u8 {
    let program = argv
        .first()
        .map(|p| std::path::Path::new(p).file_name().unwrap_or(p.as_os_str()).to_string_lossy().into_owned())
        .unwrap_or_else(|| "controller".into());
    let command = ServeArgs::command().bin_name(program.clone());
    let args = match command.try_get_matches_from(argv).and_then(|m| ServeArgs::from_arg_matches(&m)) {
        Ok(a) => a,
        // --help and --version print and exit 0; a malformed command line exits 2.
        Err(e) => e.exit(),
    };
    iceoryx2::prelude::set_log_level_from_env_or(iceoryx2::prelude::LogLevel::Fatal);
    if let Err(e) = ctrlc::set_handler(|| STOP.store(true, Ordering::SeqCst)) {
        eprintln!("{program}: warning: cannot install the Ctrl-C handler: {e}");
    }
    let ended = ServeOptions::from_args(&args, |k| std::env::var(k).ok())
        .and_then(|opts| run(&opts, laws, &STOP, &mut |w| eprintln!("{program}: {w}")));
    match ended {
        Ok(_) => exit::OK,
        Err(e) => {
            let code = e.exit_code();
            if matches!(code, exit::PLANT_LOST | exit::INTERRUPTED) {
                eprintln!("{program}: {e}");
            } else {
                eprintln!("{program}: error: {e}");
            }
            code
        }
    }
}

/// Serves one run of the plant with `laws`: handshake, then one reply per sensor frame
/// until the plant's STOP (`Ok`), or a [`ServeError`]. `stop` is the signal flag (set it
/// to end the run: the plant is told); `say` gets the start-up and end lines and warnings.
pub fn run<L: Copy + Into<AnyLaw>>(
    opts: &ServeOptions,
    laws: &[L],
    stop: &AtomicBool,
    say: &mut dyn FnMut(&str),
) -> Result<Served, ServeError> {
    let laws: Vec<AnyLaw> = laws.iter().map(|&l| l.into()).collect();
    let served: Vec<&'static str> = laws.iter().map(AnyLaw::name).collect();
    let mut overrides = match &opts.config {
        Some(path) => file::load_for(path, &served)?,
        None => LawOverrides::default(),
    };
    for w in &overrides.warnings {
        say(&format!("warning: {w}"));
    }
    if let Some(law) = &opts.law {
        if !served.contains(&law.as_str()) {
            return Err(ServeError::UnknownLaw { name: law.clone(), served });
        }
        overrides.law = Some(law.clone());
    }
    if let Some(core) = opts.pin_core {
        link::pin_to_core(core).map_err(|e| ServeError::BadArgument(format!("--pin-core {core}: {e}")))?;
    }
    if let Some(priority) = opts.realtime_priority {
        for refused in link::realtime(priority) {
            say(&format!("warning: {REALTIME_PRIORITY_ENV}={priority}: {refused}; carrying on without it"));
        }
    }
    let run_id = opts.run_id.as_str();
    let _lock = lock::acquire(run_id, "controller")?;
    let node = link::node(run_id, "controller")?;
    let handshake: Mailbox<Ack, Hello> = Mailbox::open(&node, run_id, "ack", "hello")?;
    let mut frames: Endpoint<CommandFrame, SensorFrame> =
        Endpoint::open(&node, run_id, "command", "sensor", Duration::from_micros(200))?;

    // Hello: wait for the plant.
    let started = Instant::now();
    let hello = loop {
        if stop.load(Ordering::SeqCst) {
            return Err(ServeError::Interrupted { run_id: run_id.to_string() });
        }
        if let Some(h) = handshake.try_receive()? {
            break h;
        }
        if started.elapsed() > opts.connect_timeout {
            return Err(ServeError::PlantLost(format!(
                "no hello from a plant with run id {run_id} within {} s (start it with `plant run SCENE --controller external --run-id {run_id}`)",
                opts.connect_timeout.as_secs_f64()
            )));
        }
        // node.wait only sleeps here: signals are handled by the flag (see crate::link).
        let _ = node.wait(Duration::from_millis(1));
    };
    let Built { mut law, limits, description, .. } = match accept(&hello, run_id, &overrides, &laws, say) {
        Ok(built) => {
            let ack = Ack::new(hello.session, hello.token, 0, built.law.name(), &built.description)
                .with_overrides(&built.document);
            match ack {
                Ok(a) => handshake.send(a)?,
                Err(len) => {
                    let message =
                        format!("the overrides document is {len} bytes: the limit is {}", wire::OVERRIDES_LEN);
                    return Err(refuse(&handshake, &hello, Refusal::Params, message));
                }
            }
            built
        }
        Err((why, message)) => return Err(refuse(&handshake, &hello, why, message)),
    };
    frames.set_spin(Duration::from_nanos(hello.spin_ns));
    if !opts.quiet {
        say(&format!("serving run {run_id} (session {}, pid {}): {description}", hello.session, std::process::id()));
    }

    let (session, token, axes) = (hello.session, hello.token, hello.axes);
    let mut last_heard = Instant::now();
    // The plant that started this process is its parent: its death shows in `getppid` (the
    // process is handed to another parent), a system call, where a node lookup lists every
    // iceoryx2 node of the machine (paced for a plant that is not the parent: link::PeerWatch).
    let parent = (hello.plant_pid != 0 && parent_pid() == hello.plant_pid).then_some(hello.plant_pid);
    let mut watch = link::PeerWatch::new(run_id, "plant");
    let mut lost: Option<String> = None;
    let mut answered: u64 = 0;
    loop {
        if stop.load(Ordering::Relaxed) {
            let bye = CommandFrame {
                status: CommandFrame::STOPPING,
                session,
                token,
                axes,
                sent_ns: wire::monotonic_ns(),
                ..Default::default()
            };
            frames.send_and_wake(bye)?;
            return Err(ServeError::Interrupted { run_id: run_id.to_string() });
        }
        let frame = frames.wait(SLICE, || {
            if stop.load(Ordering::Relaxed) {
                return false;
            }
            if parent.is_some_and(|p| p != parent_pid()) {
                lost =
                    Some(format!("the plant of run {run_id} died (this process, its child, has another parent now)"));
                return false;
            }
            if parent.is_none() && last_heard.elapsed() >= LIVENESS_EVERY {
                match watch.paced(LIVENESS_EVERY) {
                    None | Some(Peer::Alive) => {}
                    Some(Peer::Dead) => {
                        lost = Some(format!("the plant of run {run_id} died (its node is dead)"));
                        return false;
                    }
                    Some(Peer::Absent) => {
                        lost = Some(format!("the plant of run {run_id} is gone (its node no longer exists)"));
                        return false;
                    }
                }
            }
            true
        })?;
        let Some(frame) = frame else {
            match lost.take() {
                Some(why) => return Err(ServeError::PlantLost(why)),
                None => continue, // a signal: answered at the top of the loop
            }
        };
        // Token first: a frame of another run (same run id), a stale or a foreign process is
        // never looked at further.
        if frame.token != token {
            continue;
        }
        last_heard = Instant::now();
        // STOP before the session: the run is over, whichever session this process serves.
        if frame.status & SensorFrame::STOP != 0 {
            if !opts.quiet {
                say(&format!("run {run_id} ended: answered {answered} frames, blocked {} times", frames.blocks()));
            }
            return Ok(Served { answered, blocks: frames.blocks() });
        }
        if frame.session != session {
            continue; // a frame of another session (an earlier one still buffered, or a later controller's)
        }
        if session == 1 && opts.crash_at.is_some_and(|n| frame.seq >= n) {
            // SAFETY: kill(2) on our own pid; no memory is involved.
            unsafe { libc::kill(libc::getpid(), libc::SIGKILL) };
        }
        let received_ns = wire::monotonic_ns();
        // The hello's axis count, whatever the frame says: the law was built for it.
        let sample = wire::SensorFrame { axes, ..frame }.rotor_sample();
        let current = saturate_axes(law.update(&sample), limits);
        answered += 1;
        frames.send(CommandFrame {
            seq: frame.seq,
            token,
            received_ns,
            sent_ns: wire::monotonic_ns(),
            status: 0,
            session,
            axes,
            reserved: 0,
            current_a: wire::rotor_axes_of(current, axes),
        })?;
    }
}

/// The law a hello asks for, built, with what the ack says.
struct Built {
    law: Box<dyn RotorLaw>,
    /// Each axis's current limit (A).
    limits: [f64; ROTOR_AXES],
    /// The ack's message: the law and its design.
    description: String,
    /// The overrides document.
    document: String,
}

/// Builds the law a hello asks for among `laws`, or the refusal.
fn accept(
    hello: &Hello,
    run_id: &str,
    overrides: &LawOverrides,
    laws: &[AnyLaw],
    say: &mut dyn FnMut(&str),
) -> Result<Built, (Refusal, String)> {
    wire::check_hello(hello, &Expect { run_id, rate_hz: overrides.rate_hz })?;
    let applied = overrides.apply(hello).map_err(|message| (Refusal::Params, message))?;
    let document = applied.overrides_document();
    let Applied { law: name, rotor, params, warnings, .. } = applied;
    for w in &warnings {
        say(&format!("warning: {w}"));
    }
    let law = build_among(laws, &name, &rotor, &params).map_err(|e| match e {
        LawError::Param { .. } | LawError::UnknownParam { .. } => (Refusal::Params, e.to_string()),
        LawError::Axes { .. } => (Refusal::Axes, e.to_string()),
        LawError::Unknown { .. } | LawError::Design { .. } | LawError::Refused { .. } => (Refusal::Law, e.to_string()),
    })?;
    let a = rotor.plane_a();
    let description = match rotor.planes() {
        [_, b] => format!(
            "{name}: 4 axes, k_e = {} / {} N/m, xi_e = {} / {}, i_max = {} / {} A (planes A / B) at {} Hz",
            a.stiffness_n_per_m,
            b.stiffness_n_per_m,
            a.damping_ratio,
            b.damping_ratio,
            a.current_limit_a,
            b.current_limit_a,
            hello.rate_hz
        ),
        _ => format!(
            "{name}: k_e = {} N/m, xi_e = {}, i_max = {} A at {} Hz",
            a.stiffness_n_per_m, a.damping_ratio, a.current_limit_a, hello.rate_hz
        ),
    };
    Ok(Built { law, limits: rotor.current_limits(), description, document })
}

/// Tells the plant why its hello is refused; the ending to return.
fn refuse(handshake: &Mailbox<Ack, Hello>, hello: &Hello, why: Refusal, message: String) -> ServeError {
    match handshake.send(Ack::new(hello.session, hello.token, why.code(), "", &message)) {
        Ok(()) => ServeError::Refused { code: why.code(), message },
        Err(e) => ServeError::Link(e, Some(format!("telling the plant why its hello is refused: {message}"))),
    }
}

/// The parent process's id (`getppid`).
fn parent_pid() -> u32 {
    // SAFETY: getppid has no preconditions and cannot fail.
    unsafe { libc::getppid() as u32 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    #[test]
    fn exit_codes_follow_the_error_types() {
        let cases: [(ServeError, u8); 8] = [
            (ServeError::BadArgument("x".into()), 2),
            (ServeError::Refused { code: 7, message: "m".into() }, 2),
            (ServeError::UnknownLaw { name: "nope".into(), served: vec!["pd"] }, 2),
            (ServeError::PlantLost("gone".into()), 4),
            (ServeError::Interrupted { run_id: "r".into() }, 130),
            (LinkError::Incompatible { service: "s".into(), peer_type: Some("amb_testbed.v3.Hello".into()) }.into(), 2),
            (ServeError::Link(LinkError::Ipc { what: "w".into(), detail: "d".into() }, Some("while x".into())), 1),
            (
                ServeError::Lock(LockError::InUse {
                    run_id: "r".into(),
                    role: "controller".into(),
                    holder: "pid 1".into(),
                    path: "p".into(),
                }),
                2,
            ),
        ];
        for (err, code) in cases {
            assert_eq!(err.exit_code(), code, "{err}");
        }
    }

    fn parse(args: &[&str], env: &[(&str, &str)]) -> Result<ServeOptions, ServeError> {
        let env: HashMap<String, String> = env.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
        let args = ServeArgs::try_parse_from(std::iter::once("c").chain(args.iter().copied())).unwrap();
        ServeOptions::from_args(&args, |k| env.get(k).cloned())
    }

    #[test]
    fn the_run_id_comes_from_the_argument_else_the_environment() {
        assert_eq!(parse(&["--run-id", "a"], &[(RUN_ID_ENV, "b")]).unwrap().run_id, "a");
        assert_eq!(parse(&[], &[(RUN_ID_ENV, "b")]).unwrap().run_id, "b");
        let e = parse(&[], &[]).unwrap_err().to_string();
        assert!(e.contains("--run-id") && e.contains(RUN_ID_ENV), "{e}");
        assert!(parse(&["--run-id", "a/b"], &[]).unwrap_err().to_string().contains("a/b"));
    }

    #[test]
    fn the_connect_timeout_comes_from_the_argument_else_the_environment() {
        let env = [(CONNECT_TIMEOUT_ENV, "2.5")];
        assert_eq!(parse(&["--run-id", "a"], &env).unwrap().connect_timeout, Duration::from_millis(2500));
        let o = parse(&["--run-id", "a", "--connect-timeout-s", "4"], &env).unwrap();
        assert_eq!(o.connect_timeout, Duration::from_secs(4));
        assert_eq!(parse(&["--run-id", "a"], &[]).unwrap().connect_timeout, Duration::from_secs(30));
        let e = parse(&["--run-id", "a"], &[(CONNECT_TIMEOUT_ENV, "soon")]).unwrap_err().to_string();
        assert!(e.contains(CONNECT_TIMEOUT_ENV) && e.contains("soon"), "{e}");
        assert!(parse(&["--run-id", "a", "--connect-timeout-s=-1"], &[]).is_err());
    }

    #[test]
    fn the_realtime_priority_is_checked() {
        assert_eq!(parse(&["--run-id", "a"], &[(REALTIME_PRIORITY_ENV, "40")]).unwrap().realtime_priority, Some(40));
        assert_eq!(parse(&["--run-id", "a"], &[(REALTIME_PRIORITY_ENV, "0")]).unwrap().realtime_priority, None);
        let e = parse(&["--run-id", "a"], &[(REALTIME_PRIORITY_ENV, "120")]).unwrap_err().to_string();
        assert!(e.contains(REALTIME_PRIORITY_ENV) && e.contains("120"), "{e}");
    }

    /// The hello's rotor decides what is built: a per-plane law runs on 2 or 4 axes, `modal`
    /// on 4 only (a planar hello is refused with code 3, axes), an unknown law with code 5
    /// naming the laws this controller serves.
    #[test]
    fn a_hello_is_built_for_its_rotor_or_refused_with_its_code() {
        let laws = [AnyLaw::from(crate::pd::LAW), AnyLaw::from(crate::modal::LAW)];
        let none = LawOverrides::default();
        let with_law = |mut h: Hello, law: &str| {
            h.law = wire::fixed_str(law);
            h
        };
        let two = Hello::example_two_plane("r");
        let built = accept(&with_law(two, "modal"), "r", &none, &laws, &mut |_| {}).expect("modal on 4 axes");
        assert_eq!(built.law.name(), "modal");
        assert!(built.description.starts_with("modal: 4 axes, k_e = 1000000 / 1000000 N/m"), "{}", built.description);
        let built = accept(&two, "r", &none, &laws, &mut |_| {}).expect("pd on 4 axes");
        assert_eq!((built.law.name(), built.limits), ("pd", [2.0; 4]));
        let planar = Hello::example("r");
        let built = accept(&planar, "r", &none, &laws, &mut |_| {}).expect("pd on 2 axes");
        assert_eq!(built.description, "pd: k_e = 1000000 N/m, xi_e = 0.01, i_max = 2 A at 20000 Hz");
        let (why, message) = accept(&with_law(planar, "modal"), "r", &none, &laws, &mut |_| {}).err().unwrap();
        assert_eq!(why.code(), 3, "{message}");
        assert!(
            message.contains("law modal drives a two-plane rotor (4 axes) only; this rotor has 2 axes"),
            "{message}"
        );
        let (why, message) = accept(&with_law(two, "pid"), "r", &none, &laws, &mut |_| {}).err().unwrap();
        assert_eq!((why.code(), message.as_str()), (5, "unknown controller law `pid` (known laws: pd, modal)"));
    }

    #[test]
    fn a_law_not_served_is_refused_before_anything_opens() {
        let mut opts = ServeOptions::new("serve-unit-law").unwrap();
        opts.law = Some("relev".into());
        let e = run(&opts, &[crate::pd::LAW], &AtomicBool::new(false), &mut |_| {}).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert_eq!(e.to_string(), "--law relev: this controller serves pd");
    }
}
