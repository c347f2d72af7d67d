//! `controller`: the AMB controller as its own process. It serves one run of
//! the plant over iceoryx2 (`controller --run-id ID`): answers the plant's
//! hello, then for every sensor frame runs the law (the same
//! [`controller::build_law`] code the plant runs in `sampled` mode),
//! saturates the current and replies. See `controller::wire` for the protocol.
//!
//! Exit codes: 0 the plant ended the run; 1 an IPC failure; 2 bad input (bad
//! arguments or file, unknown law, a refused hello); 4 the plant is gone
//! (its process died, or no hello came in time); 130 SIGINT/SIGTERM.

use anyhow::anyhow;
use clap::Parser;
use controller::file::{self, LawOverrides};
use controller::link::{self, Endpoint, Mailbox, Peer};
use controller::wire::{self, Ack, CommandFrame, Expect, Hello, Refusal, SensorFrame};
use controller::{build_law, saturate, LawSpec, Sample, LAW_NAMES};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Exit codes, one per kind of ending.
mod exit {
    /// An IPC failure.
    pub const IO: u8 = 1;
    /// Bad arguments or file, unknown law, refused hello.
    pub const BAD_INPUT: u8 = 2;
    /// The plant died or never said hello.
    pub const PLANT_LOST: u8 = 4;
    /// SIGINT or SIGTERM.
    pub const INTERRUPTED: u8 = 130;
}

/// Fault injection for the end-to-end tests: when set to N, the process
/// kills itself with SIGKILL on the first sensor frame with `seq >= N` of
/// session 1 (a hard crash, as `kill -9` from outside, at a reproducible
/// point of the run; `>=` because a realtime plant may overwrite frames of a
/// stalled controller). A controller that reconnects (session 2 on) is
/// spared, so the tests can watch the run carry on.
const CRASH_AT_SEQ_ENV: &str = "AMB_CONTROLLER_CRASH_AT_SEQ";

/// How often a silent plant is looked up by its node (a directory listing).
const LIVENESS_EVERY: Duration = Duration::from_millis(20);

/// Slice of a blocking wait: the longest a signal goes unnoticed while blocked.
const SLICE: Duration = Duration::from_millis(1);

static STOP: AtomicBool = AtomicBool::new(false);

#[derive(Parser)]
#[command(name = "controller", version, about = "AMB controller process: serves one plant run over iceoryx2")]
struct Cli {
    /// Run id printed by `plant run … --controller external` (or passed by the plant).
    #[arg(long)]
    run_id: String,
    /// Run this law instead of the one the plant asks for.
    #[arg(long)]
    law: Option<String>,
    /// A TOML file whose `[controller]` table overrides the law design (a scene file works);
    /// its `rate_hz`, if given, must match the plant's.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Pin this process to a CPU core.
    #[arg(long)]
    pin_core: Option<usize>,
    /// How long to wait for the plant's hello (s).
    #[arg(long, default_value_t = 30.0)]
    connect_timeout_s: f64,
    /// No start-up line.
    #[arg(long)]
    quiet: bool,
}

/// How a serve loop ended.
enum End {
    /// The plant sent STOP.
    Finished,
    /// SIGINT/SIGTERM.
    Interrupted,
    /// The plant's node is gone.
    PlantLost(String),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    iceoryx2::prelude::set_log_level_from_env_or(iceoryx2::prelude::LogLevel::Fatal);
    if let Err(e) = ctrlc::set_handler(|| STOP.store(true, Ordering::SeqCst)) {
        eprintln!("controller: warning: cannot install the Ctrl-C handler: {e}");
    }
    let fail = |code: u8, e: anyhow::Error| {
        eprintln!("controller: error: {e:#}");
        ExitCode::from(code)
    };
    let run_id = match wire::valid_run_id(&cli.run_id) {
        Ok(id) => id.to_string(),
        Err(e) => return fail(exit::BAD_INPUT, anyhow!(e)),
    };
    let mut overrides = match &cli.config {
        Some(path) => match file::load(path) {
            Ok(o) => o,
            Err(e) => return fail(exit::BAD_INPUT, e.into()),
        },
        None => LawOverrides::default(),
    };
    if let Some(law) = &cli.law {
        if !LAW_NAMES.contains(&law.as_str()) {
            return fail(exit::BAD_INPUT, controller::LawError::Unknown(law.clone()).into());
        }
        overrides.law = Some(law.clone());
    }
    if !(cli.connect_timeout_s.is_finite() && cli.connect_timeout_s > 0.0) {
        return fail(
            exit::BAD_INPUT,
            anyhow!("--connect-timeout-s {} s: must be a finite number > 0", cli.connect_timeout_s),
        );
    }
    if let Some(core) = cli.pin_core {
        if let Err(e) = link::pin_to_core(core) {
            return fail(exit::BAD_INPUT, anyhow!("--pin-core {core}: {e}"));
        }
    }
    match serve(&cli, &run_id, &overrides) {
        Ok(End::Finished) => ExitCode::SUCCESS,
        Ok(End::Interrupted) => {
            eprintln!("controller: interrupted; told the plant (run {run_id}) and stopped");
            ExitCode::from(exit::INTERRUPTED)
        }
        Ok(End::PlantLost(why)) => {
            eprintln!("controller: {why}; exiting");
            ExitCode::from(exit::PLANT_LOST)
        }
        Err(Failure::BadInput(e)) => fail(exit::BAD_INPUT, e),
        Err(Failure::Io(e)) => fail(exit::IO, e),
    }
}

/// Why serving failed.
enum Failure {
    /// A refused hello or a bad design.
    BadInput(anyhow::Error),
    /// IPC trouble.
    Io(anyhow::Error),
}

impl From<link::LinkError> for Failure {
    fn from(e: link::LinkError) -> Self {
        match e {
            link::LinkError::Incompatible { .. } => Failure::BadInput(e.into()),
            other => Failure::Io(other.into()),
        }
    }
}

fn serve(cli: &Cli, run_id: &str, overrides: &LawOverrides) -> Result<End, Failure> {
    let node = link::node(run_id, "controller")?;
    let handshake: Mailbox<Ack, Hello> = Mailbox::open(&node, run_id, "ack", "hello")?;
    let mut frames: Endpoint<CommandFrame, SensorFrame> =
        Endpoint::open(&node, run_id, "command", "sensor", Duration::from_micros(200))?;

    // Hello: wait for the plant.
    let started = Instant::now();
    let hello = loop {
        if STOP.load(Ordering::SeqCst) {
            return Ok(End::Interrupted);
        }
        if let Some(h) = handshake.try_receive()? {
            break h;
        }
        if started.elapsed().as_secs_f64() > cli.connect_timeout_s {
            return Ok(End::PlantLost(format!(
                "no hello from a plant with run id {run_id} within {} s (start it with `plant run SCENE --controller external --run-id {run_id}`)",
                cli.connect_timeout_s
            )));
        }
        // node.wait only sleeps here: signals are handled by the ctrlc flag (see controller::link).
        let _ = node.wait(Duration::from_millis(1));
    };
    let refuse = |why: Refusal, message: String| -> Result<End, Failure> {
        handshake.send(Ack::new(hello.session, why.code(), "", &message))?;
        Err(Failure::BadInput(anyhow!("refused the plant's hello ({}): {message}", Refusal::describe(why.code()))))
    };
    if let Err((why, message)) = wire::check_hello(&hello, &Expect { run_id, rate_hz: overrides.rate_hz }) {
        return refuse(why, message);
    }
    let plant_law = wire::str_of(&hello.law).into_owned();
    let law_name = overrides.law.clone().unwrap_or(plant_law);
    let limit = overrides.current_limit_a.unwrap_or(hello.current_limit_a);
    let spec = LawSpec {
        law: &law_name,
        stiffness_n_per_m: overrides.stiffness_n_per_m.unwrap_or(hello.stiffness_n_per_m),
        damping_ratio: overrides.damping_ratio.unwrap_or(hello.damping_ratio),
        period_s: hello.period_s,
        gravity_bias: overrides.gravity_bias.unwrap_or(hello.gravity_bias != 0),
        current_limit_a: limit,
        delay_samples: hello.delay_samples,
        relev: overrides.relev(hello.relev()),
    };
    let mut law = match build_law(&spec, &hello.loop_constants()) {
        Ok(l) => l,
        Err(e) => return refuse(Refusal::Law, e.to_string()),
    };
    let description = format!(
        "{law_name}: k_e = {} N/m, xi_e = {}, i_max = {limit} A at {} Hz",
        spec.stiffness_n_per_m, spec.damping_ratio, hello.rate_hz
    );
    handshake.send(Ack::new(hello.session, 0, &law_name, &description))?;
    frames.set_spin(Duration::from_nanos(hello.spin_ns));
    if !cli.quiet {
        eprintln!(
            "controller: serving run {run_id} (session {}, pid {}): {description}",
            hello.session,
            std::process::id()
        );
    }

    let crash_at: Option<u64> = std::env::var(CRASH_AT_SEQ_ENV).ok().and_then(|v| v.parse().ok());
    let session = hello.session;
    let mut last_heard = Instant::now();
    let mut last_check = Instant::now();
    let mut lost: Option<String> = None;
    let mut answered: u64 = 0;
    loop {
        if STOP.load(Ordering::Relaxed) {
            let bye = CommandFrame {
                status: CommandFrame::STOPPING,
                session,
                sent_ns: wire::monotonic_ns(),
                ..Default::default()
            };
            frames.send_and_wake(bye)?;
            return Ok(End::Interrupted);
        }
        let frame = frames.wait(SLICE, || {
            if STOP.load(Ordering::Relaxed) {
                return false;
            }
            if last_check.elapsed() >= LIVENESS_EVERY && last_heard.elapsed() >= LIVENESS_EVERY {
                last_check = Instant::now();
                match link::peer(run_id, "plant") {
                    Peer::Alive => {}
                    Peer::Dead => {
                        lost = Some(format!("the plant of run {run_id} died (its node is dead)"));
                        return false;
                    }
                    Peer::Absent => {
                        lost = Some(format!("the plant of run {run_id} is gone (its node no longer exists)"));
                        return false;
                    }
                }
            }
            true
        })?;
        let Some(frame) = frame else {
            match lost.take() {
                Some(why) => return Ok(End::PlantLost(why)),
                None => continue, // STOP: answered at the top of the loop
            }
        };
        last_heard = Instant::now();
        if frame.status & SensorFrame::STOP != 0 {
            if !cli.quiet {
                eprintln!(
                    "controller: run {run_id} ended: answered {answered} frames, blocked {} times",
                    frames.blocks()
                );
            }
            return Ok(End::Finished);
        }
        if frame.session != session {
            continue; // a frame of an earlier session, still in the buffer
        }
        if session == 1 && crash_at.is_some_and(|n| frame.seq >= n) {
            // SAFETY: kill(2) on our own pid; no memory is involved.
            unsafe { libc::kill(libc::getpid(), libc::SIGKILL) };
        }
        let received_ns = wire::monotonic_ns();
        let sample = Sample { seq: frame.seq, t_s: frame.t_s, sensor_v: frame.sensor_v };
        let current_a = saturate(law.update(&sample), limit);
        answered += 1;
        frames.send(CommandFrame {
            seq: frame.seq,
            current_a,
            received_ns,
            sent_ns: wire::monotonic_ns(),
            status: 0,
            session,
        })?;
    }
}
