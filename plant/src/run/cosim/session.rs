//! The plant's side of one co-simulation: one command per tick (lockstep or
//! realtime), loss, silence and reconnection. This file holds the session's
//! state, its start-up and its end; each of its jobs has a room of its own in
//! `session/`: `handshake.rs` (the hello, the services, the controller's
//! answer), `lockstep.rs` (a tick's command, waiting for the reply),
//! `realtime.rs` (a tick paced by the wall clock, the reply of the tick
//! before), `recovery.rs` (a silent or lost controller: the fallback, the
//! reconnection). The figures it keeps are in [`super::stats`], the IPC
//! benchmark in `bench.rs`.

mod handshake;
mod lockstep;
mod realtime;
mod recovery;

use handshake::Pending;
use recovery::{check_silence, controller_gone};

use super::log::OutputLog;
use super::process::{Child, Program};
use super::stats::{CosimReport, Figures, Scheduling};
use super::{CosimError, PeerEvent};
use crate::config::{ControlMode, CosimSettings, Fallback, Pacing};
use crate::hooks::Hooks;
use controller::link::{self, Endpoint, Ipc, Mailbox, Peer};
use controller::lock::RunLock;
use controller::wire::{self, Ack, CommandFrame, Hello, SensorFrame};
use controller::{saturate_axes, RotorSample, ROTOR_AXES};
use iceoryx2::node::Node;
use std::time::{Duration, Instant};

/// Slice of a blocking wait: the longest a signal or a dead peer goes
/// unnoticed while the plant is blocked.
const SLICE: Duration = Duration::from_millis(1);
/// Sent-time stamps kept for latency figures of late replies.
const RING: usize = 64;
/// How long a controller has to exit after the STOP frame before it is signalled.
const EXIT_GRACE: Duration = Duration::from_secs(2);
/// Blocked waits that the controller never ended with a notification before the plant
/// warns that it does not serve wake requests.
const UNWOKEN_WARNING: u64 = 50;
/// Realtime ticks with a reply due (started, for overruns) before the miss (overrun) budget is
/// checked during the run (it is checked again at the end, over the whole run).
const MISS_BUDGET_MIN_DUE: u64 = 1000;
/// Most controllers a run starts (or waits for) after losing one, with a positive
/// `controller.reconnect_timeout_ms`: a controller lost more often than this is not recovering,
/// and the run ends as `peer_lost`. Without the bound, one that dies on each start was
/// respawned at every tick (about 145 ms each: an hour for a 1.5 s scene, issue 31 item 8).
pub const MAX_RECONNECTIONS: u32 = 8;

pub use plant_sim::digital::Halt;

/// What a lockstep wait saw besides the reply it waited for.
#[derive(Default)]
struct Seen {
    foreign: u64,
    other_session: u64,
    sessions: Vec<u32>,
    other_seq: u64,
}

impl Seen {
    /// A reply of another session.
    fn note_session(&mut self, session: u32) {
        self.other_session += 1;
        if !self.sessions.contains(&session) && self.sessions.len() < 8 {
            self.sessions.push(session);
        }
    }

    /// What the controller sent, in words.
    fn describe(&self) -> String {
        let mut parts = Vec::new();
        if self.other_session > 0 {
            let list: Vec<String> = self.sessions.iter().map(u32::to_string).collect();
            parts.push(format!("{} replies of another session ({})", self.other_session, list.join(", ")));
        }
        if self.foreign > 0 {
            parts.push(format!("{} frames of another run (another token)", self.foreign));
        }
        if self.other_seq > 0 {
            parts.push(format!("{} replies to other samples", self.other_seq));
        }
        if parts.is_empty() {
            "it sent nothing (stopped, e.g. by SIGSTOP, or hung)".into()
        } else {
            format!("it sent only {}", parts.join(", "))
        }
    }
}

/// What the liveness check decided about a missing reply.
enum Verdict {
    Wait,
    Gone(String),
    Silent,
}

/// The plant's side of a co-simulation.
pub struct Session {
    mode: ControlMode,
    pub(super) run_id: String,
    settings: CosimSettings,
    // Field order is drop order: ports before the node, the run-id lock last.
    pub(super) frames: Endpoint<SensorFrame, CommandFrame>,
    /// Realtime with a priority: the open `/dev/cpu_dma_latency` request (0 µs) for the run.
    _idle_latency: Option<std::fs::File>,
    handshake: Mailbox<Hello, Ack>,
    _node: Node<Ipc>,
    child: Option<Child>,
    program: Option<Program>,
    /// The output of the controllers started (after `child`: dropped once it is reaped).
    log: OutputLog,
    _lock: RunLock,
    hello: Hello,
    limits: [f64; ROTOR_AXES],
    bias: [f64; ROTOR_AXES],
    period: f64,
    /// False while the controller is lost.
    connected: bool,
    lost_since: Option<Instant>,
    /// Controllers lost so far in this run ([`MAX_RECONNECTIONS`]).
    losses: u32,
    pending: Option<Pending>,
    /// First sample sent in the current session.
    first_seq: u64,
    last_cmd: [f64; ROTOR_AXES],
    controller: String,
    /// Process id of the connected controller (from its handshake ack).
    controller_pid: Option<u32>,
    // Realtime.
    start: Option<Instant>,
    /// When the plant woke for the current realtime tick (its start, for the execution time).
    woke: Option<Instant>,
    sent_ns: [u64; RING],
    last_heard: Instant,
    /// Realtime: what the controller sent since its last reply of this session (for the
    /// message when it is silent past `controller.lockstep_timeout_ms`).
    silent: Seen,
    next_check: Duration,
    wall_start: Instant,
    /// What the controller runs differently from the hello (its ack's `[controller]` table).
    overrides: Option<toml::Table>,
    figures: Figures,
    scheduling: Scheduling,
    wake_warned: bool,
    /// The controller's node, looked up while it is silent (paced: [`link::PeerWatch`]).
    watch: link::PeerWatch,
    /// Plant and controller on one core under `SCHED_FIFO`: demotes a controller that holds
    /// the core ([`super::watchdog`]).
    watchdog: Option<super::watchdog::Watchdog>,
}

impl Session {
    /// Starts the latency figures afresh (after a warm-up). They live in
    /// fixed-size histograms, so a run's memory does not grow with its number of ticks.
    pub fn reset_figures(&mut self) {
        self.figures.reset_latencies();
    }

    /// What the connected controller runs differently from the scene (the `[controller]`
    /// table of its handshake's overrides), if anything.
    pub fn overrides(&self) -> Option<&toml::Table> {
        self.overrides.as_ref()
    }

    /// Takes the bias command and the current limits (A, per axis) of the design the
    /// controller runs (its overrides), before the loop.
    pub fn adopt(&mut self, bias: [f64; ROTOR_AXES], limits: [f64; ROTOR_AXES]) {
        self.bias = bias;
        self.last_cmd = bias;
        self.limits = limits;
    }

    /// Process id of the controller now connected, as its handshake ack gave it
    /// (`None` while none is connected).
    pub fn controller_pid(&self) -> Option<u32> {
        self.controller_pid.filter(|_| self.connected)
    }

    /// The run id.
    pub fn run_id(&self) -> &str {
        &self.run_id
    }

    /// Samples of delay the transport itself adds: the delay line gets that
    /// many fewer prefilled commands.
    pub fn inherent_delay(&self) -> u32 {
        match self.mode {
            ControlMode::Realtime => 1,
            _ => 0,
        }
    }

    /// Realtime: `Some(why)` if the share of the run's ticks so far that went without the
    /// controller's reply exceeds `controller.max_miss_fraction` (checked over at least
    /// `min_due` such ticks): the deadline misses, and the fallback ticks while no controller was
    /// connected. Either way the loop that ran was not the scene's.
    pub fn miss_budget_exceeded(&self, min_due: u64) -> Option<String> {
        if self.mode != ControlMode::Realtime {
            return None;
        }
        self.figures.miss_budget(self.settings.max_miss_fraction, min_due)
    }

    /// Realtime: `Some(why)` if the share of ticks started more than a period late so far
    /// exceeds `controller.max_overrun_fraction` (checked over at least `min_ticks` ticks).
    pub fn overrun_budget_exceeded(&self, min_ticks: u64) -> Option<String> {
        let f = &self.figures;
        let budget = self.settings.max_overrun_fraction;
        let over = self.mode == ControlMode::Realtime && f.ticks >= min_ticks.max(1) && f.overrun_fraction() > budget;
        over.then(|| {
            format!(
                "realtime: {} plant overruns (ticks started more than a period late) in {} ticks ({:.3} %) exceed \
                 controller.max_overrun_fraction = {budget} (1 is no limit)",
                f.overruns,
                f.ticks,
                100.0 * f.overrun_fraction()
            )
        })
    }

    /// Realtime: when the plant woke for the current tick (the tick's start); `None` in lockstep.
    pub fn tick_started(&self) -> Option<Instant> {
        self.woke
    }

    fn event(&mut self, kind: &'static str, t_s: f64, seq: u64, detail: String) {
        let wall_s = self.wall_start.elapsed().as_secs_f64();
        self.figures.events.push(PeerEvent { kind, t_s, seq, wall_s, detail });
    }

    fn frame(&self, sample: &RotorSample) -> SensorFrame {
        SensorFrame {
            seq: sample.seq,
            t_s: sample.t_s,
            token: self.hello.token,
            sent_ns: wire::monotonic_ns(),
            status: 0,
            session: self.hello.session,
            axes: self.hello.axes,
            reserved: 0,
            sensor_v: wire::rotor_axes_of(sample.sensor_v, self.hello.axes),
            speed_rad_s: sample.speed_rad_s,
            angle_rad: sample.angle_rad,
        }
    }

    /// A reply's currents on the axes in use (the others are 0 on the wire and unused),
    /// saturated. A non-finite one is passed on as it is (the run loop holds, counts and
    /// judges them, [`crate::invalid`]) and is not kept as the last current (held on a miss
    /// or a loss).
    fn accept(&mut self, reply: &CommandFrame) -> [f64; ROTOR_AXES] {
        let mut current = reply.current_axes();
        current[self.hello.axes as usize..].iter_mut().for_each(|i| *i = 0.0);
        let current = saturate_axes(current, self.limits);
        if current.iter().all(|i| i.is_finite()) {
            self.last_cmd = current;
        }
        current
    }

    /// Ends the session: tells the controller the run is over, reaps the
    /// child, and returns the figures.
    pub fn finish(mut self, t_s: f64, seq: u64) -> CosimReport {
        if self.connected {
            let stop = SensorFrame {
                status: SensorFrame::STOP,
                session: self.hello.session,
                token: self.hello.token,
                axes: self.hello.axes,
                ..Default::default()
            };
            let _ = self.frames.send_and_wake(stop);
        }
        if let Some(mut child) = self.child.take() {
            match child.reap(EXIT_GRACE) {
                Some(status) if status.success() => {}
                Some(status) => self.event("stopped", t_s, seq, format!("controller process ended: {status}")),
                None => self.event("stopped", t_s, seq, "controller process could not be reaped".into()),
            }
        }
        let f = std::mem::take(&mut self.figures);
        CosimReport {
            mode: if self.mode == ControlMode::Realtime { "realtime" } else { "lockstep" },
            run_id: self.run_id.clone(),
            controller: self.controller.clone(),
            controller_command: match &self.program {
                Some(Program::Command { argv, .. }) => Some(argv.clone()),
                _ => None,
            },
            sessions: self.hello.session,
            messages_sent: f.sent,
            messages_received: f.received,
            sequence_gaps: f.gaps,
            stale_replies: f.stale,
            invalid_replies: 0, // counted by the run loop, which fills it in
            foreign_frames: f.foreign,
            deadline_misses: f.misses.total,
            deadline_miss_fraction: f.miss_fraction(),
            longest_miss_burst: f.misses.longest_burst,
            plant_overruns: f.overruns,
            plant_overrun_fraction: f.overrun_fraction(),
            schedule_held: (self.mode == ControlMode::Realtime).then_some(f.misses.total == 0 && f.overruns == 0),
            fallback_ticks: f.fallback_ticks,
            blocking_waits: self.frames.blocks(),
            woken_waits: self.frames.woken(),
            timed_out_waits: self.frames.timeouts(),
            unwoken_waits: self.frames.unwoken(),
            node_lookups: self.watch.lookups(),
            scheduling: self.scheduling.clone(),
            latency_us: f.latency.percentiles(),
            round_trip_us: (self.mode == ControlMode::Lockstep).then(|| f.round_trip.percentiles()),
            tet_us: None,
            peer_events: f.events,
            controller_overrides: self.overrides.take(),
        }
    }
}

/// Why a loss was declared when the controller said it was stopped (SIGINT/SIGTERM to it).
const STOPPED_BY_SIGNAL: &str = "the controller was stopped by a signal (it sent STOPPING)";

/// The digital loop's view of the session ([`plant_sim::digital::Remote`]): each method the
/// session's own.
impl plant_sim::digital::Remote for Session {
    type Report = CosimReport;

    fn inherent_delay(&self) -> u32 {
        Session::inherent_delay(self)
    }

    fn controller_pid(&self) -> Option<u32> {
        Session::controller_pid(self)
    }

    fn command(&mut self, sample: &RotorSample, hooks: &mut dyn Hooks) -> Result<[f64; ROTOR_AXES], Halt> {
        Session::command(self, sample, hooks)
    }

    fn tick_started(&self) -> Option<Instant> {
        Session::tick_started(self)
    }

    fn miss_budget_exceeded(&self, min_due: u64) -> Option<String> {
        Session::miss_budget_exceeded(self, min_due)
    }

    fn overrun_budget_exceeded(&self, min_ticks: u64) -> Option<String> {
        Session::overrun_budget_exceeded(self, min_ticks)
    }

    fn finish(self, t_s: f64, seq: u64, invalid_replies: u64) -> CosimReport {
        let mut report = Session::finish(self, t_s, seq);
        report.invalid_replies = invalid_replies;
        report
    }
}
