//! The plant's side of one co-simulation: one command per tick (lockstep or
//! realtime), loss, silence and reconnection. The handshake is in
//! `session/handshake.rs`, the figures it keeps in [`super::stats`], the IPC
//! benchmark in `bench.rs`.

mod handshake;

use handshake::Pending;

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

/// Why the loop must stop at this tick.
#[derive(Debug, Clone, PartialEq)]
pub enum Halt {
    /// The controller is gone (or silent past `controller.lockstep_timeout_ms`) and no other
    /// took its place.
    Lost(String),
    /// SIGINT/SIGTERM to the plant.
    Interrupted(String),
    /// Realtime: the deadline-miss fraction exceeded `controller.max_miss_fraction`.
    MissBudget(String),
    /// Realtime: the plant-overrun fraction exceeded `controller.max_overrun_fraction`.
    OverrunBudget(String),
}

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

    /// The command for sample `k` to push into the delay line: the reply to
    /// `k` (lockstep) or to `k − 1` (realtime), or a fallback.
    pub fn command(&mut self, sample: &RotorSample, hooks: &mut dyn Hooks) -> Result<[f64; ROTOR_AXES], Halt> {
        if let Some(w) = &self.watchdog {
            w.tick();
            if let Some(pid) = w.take_demoted() {
                let why = format!(
                    "the controller (pid {pid}) held the shared core for {} s without letting the plant tick: put \
                     under the normal scheduler; a controller on the plant's core must block between frames",
                    super::watchdog::STALL.as_secs_f64()
                );
                self.event("controller_demoted", sample.t_s, sample.seq, why.clone());
                hooks.note(&format!("warning: {why}"));
                self.scheduling.controller = controller::link::policy(pid).to_string();
                self.scheduling.controller_priority = None;
            }
        }
        match self.mode {
            ControlMode::Realtime => self.realtime(sample, hooks),
            _ => self.lockstep(sample, hooks),
        }
    }

    pub(super) fn lockstep(&mut self, sample: &RotorSample, hooks: &mut dyn Hooks) -> Result<[f64; ROTOR_AXES], Halt> {
        let k = sample.seq;
        let frame = self.frame(sample);
        let t0 = Instant::now();
        if let Err(e) = self.frames.send(frame) {
            return self.on_lost(sample, format!("IPC failure: {e}"), hooks);
        }
        self.figures.sent += 1;
        let session = self.hello.session;
        let timeout = Duration::from_secs_f64(self.settings.reply_timeout);
        let deadline = Duration::from_secs_f64(self.settings.lockstep_timeout);
        let mut next_check = timeout;
        let mut verdict = Verdict::Wait;
        let mut seen = Seen::default();
        loop {
            let (child, log, watch) = (&mut self.child, &mut self.log, &mut self.watch);
            let waited = self.frames.wait(SLICE, || {
                if hooks.cancelled() {
                    return false;
                }
                verdict = check_silence(t0, &mut next_check, timeout, deadline, child, log, watch);
                matches!(verdict, Verdict::Wait)
            });
            let reply = match waited {
                Ok(Some(r)) => r,
                Ok(None) => match std::mem::replace(&mut verdict, Verdict::Wait) {
                    Verdict::Gone(why) => return self.on_lost(sample, why, hooks),
                    Verdict::Silent => return self.on_silent(sample, &seen, hooks),
                    Verdict::Wait => return Err(Halt::Interrupted("interrupted by a signal".into())),
                },
                Err(e) => return self.on_lost(sample, format!("IPC failure: {e}"), hooks),
            };
            // Token first: another run's frame (same run id), a stale or a foreign process's.
            let applied = if reply.token != self.hello.token {
                self.figures.foreign += 1;
                seen.foreign += 1;
                false
            } else if reply.session != session {
                seen.note_session(reply.session);
                false
            } else if reply.status & CommandFrame::STOPPING != 0 {
                return self.on_lost(sample, STOPPED_BY_SIGNAL.into(), hooks);
            } else {
                self.figures.received += 1;
                self.figures.note_reply_seq(reply.seq);
                if reply.seq != k {
                    self.figures.stale += 1;
                    seen.other_seq += 1;
                }
                reply.seq == k
            };
            if !applied {
                // A stream of frames that are not the reply keeps the wait from blocking, so
                // the deadline is checked here too. Only the deadline: the node lookup costs
                // milliseconds, and a plant that reads slower than another publisher sends
                // would never reach the controller's reply (a subscriber takes from its first
                // publisher with data first).
                if t0.elapsed() < deadline {
                    continue;
                }
                return match controller_gone(&mut self.child, &mut self.log, &mut self.watch, None) {
                    Some(why) => self.on_lost(sample, why, hooks),
                    None => self.on_silent(sample, &seen, hooks),
                };
            }
            self.figures.round_trip.record(t0.elapsed().as_nanos() as u64);
            self.figures.latency.record(reply.sent_ns.saturating_sub(frame.sent_ns));
            self.warn_if_never_woken(hooks);
            return Ok(self.accept(&reply));
        }
    }

    /// Warns once when the controller never serves the plant's wake requests: every reply
    /// then waits for a timed wake-up of the plant (see docs/wire-protocol.md).
    fn warn_if_never_woken(&mut self, hooks: &mut dyn Hooks) {
        if !self.wake_warned && self.frames.woken() == 0 && self.frames.unwoken() >= UNWOKEN_WARNING {
            self.wake_warned = true;
            hooks.note(&format!(
                "warning: the controller never wakes the plant: {} replies were found only after a timed wait ran out. \
                 A controller must serve the plant's wake requests (`command/wake`: notify the `command` event \
                 service after publishing a reply when a wake request is pending, docs/wire-protocol.md); \
                 the run goes on, much slower",
                self.frames.unwoken()
            ));
        }
    }

    /// A live controller that did not answer within `controller.lockstep_timeout_ms`.
    fn on_silent(
        &mut self,
        sample: &RotorSample,
        seen: &Seen,
        hooks: &mut dyn Hooks,
    ) -> Result<[f64; ROTOR_AXES], Halt> {
        let pid = self.controller_pid.map(|p| format!(" (pid {p})")).unwrap_or_default();
        let why = match self.mode {
            ControlMode::Realtime => format!(
                "no reply for controller.lockstep_timeout_ms = {} ms (up to sample {}) although the controller{pid} is \
                 alive: {}",
                self.settings.lockstep_timeout * 1e3,
                sample.seq,
                seen.describe()
            ),
            _ => format!(
                "no reply to sample {} within controller.lockstep_timeout_ms = {} ms although the controller{pid} is alive: {}",
                sample.seq,
                self.settings.lockstep_timeout * 1e3,
                seen.describe()
            ),
        };
        self.on_lost(sample, why, hooks)
    }

    /// A lost controller at sample `k`: record it, then the fallback, then
    /// (lockstep) a blocking reconnection or the end of the run.
    fn on_lost(&mut self, sample: &RotorSample, why: String, hooks: &mut dyn Hooks) -> Result<[f64; ROTOR_AXES], Halt> {
        self.connected = false;
        self.lost_since = Some(Instant::now());
        let (cmd, applied) = match self.settings.fallback {
            Fallback::Hold => (self.last_cmd, "holding the last current"),
            Fallback::Bias => (self.bias, "bias current only"),
            Fallback::Stop => (self.last_cmd, "stopping (controller.fallback = \"stop\")"),
        };
        hooks.note(&format!("controller lost at t = {} s (sample {}): {why}; {applied}", sample.t_s, sample.seq));
        self.event("lost", sample.t_s, sample.seq, format!("{why}; {applied}"));
        if let Some(mut child) = self.child.take() {
            child.reap(Duration::ZERO);
        }
        if self.settings.fallback == Fallback::Stop || self.settings.reconnect_timeout <= 0.0 {
            return Err(Halt::Lost(format!("controller lost at t = {} s (sample {}): {why}", sample.t_s, sample.seq)));
        }
        self.losses += 1;
        if self.losses > MAX_RECONNECTIONS {
            return Err(Halt::Lost(format!(
                "controller lost at t = {} s (sample {}): {why}; lost {} times in this run: no further reconnection \
                 (at most {MAX_RECONNECTIONS} per run)",
                sample.t_s, sample.seq, self.losses
            )));
        }
        self.last_cmd = cmd;
        if let Err(e) = self.spawn() {
            return Err(Halt::Lost(format!("{why}; cannot start a new controller: {e}")));
        }
        hooks.note(&format!(
            "waiting up to {} s for a controller to reconnect (run id {})",
            self.settings.reconnect_timeout, self.run_id
        ));
        if self.mode == ControlMode::Realtime {
            self.begin_handshake();
            self.figures.fallback_ticks += 1;
            return Ok(cmd);
        }
        match self.handshake_blocking(self.settings.reconnect_timeout, hooks) {
            Ok(()) => {
                self.first_seq = sample.seq + 1;
                self.figures.last_reply_seq = None;
                self.figures.fallback_ticks += 1;
                let detail = self.controller.clone();
                self.event("reconnected", sample.t_s, sample.seq, detail);
                hooks.note(&format!("controller reconnected: {}", self.controller));
                Ok(cmd)
            }
            Err(CosimError::Interrupted) => Err(Halt::Interrupted("interrupted by a signal".into())),
            Err(e) => Err(Halt::Lost(format!(
                "controller lost at t = {} s (sample {}): {why}; no reconnection: {e}",
                sample.t_s, sample.seq
            ))),
        }
    }

    fn realtime(&mut self, sample: &RotorSample, hooks: &mut dyn Hooks) -> Result<[f64; ROTOR_AXES], Halt> {
        let k = sample.seq;
        let start = *self.start.get_or_insert_with(Instant::now);
        let deadline = start + Duration::from_secs_f64(k as f64 * self.period);
        pace_until(deadline, self.settings.pacing);
        let woke = Instant::now();
        self.woke = Some(woke);
        self.figures.ticks += 1;
        if woke > deadline + Duration::from_secs_f64(self.period) {
            self.figures.overruns += 1;
            if let Some(why) = self.overrun_budget_exceeded(MISS_BUDGET_MIN_DUE) {
                return Err(Halt::OverrunBudget(why));
            }
        }
        if hooks.cancelled() {
            return Err(Halt::Interrupted("interrupted by a signal".into()));
        }

        // Replies that came in since the last tick.
        let session = self.hello.session;
        let mut fresh: Option<CommandFrame> = None;
        loop {
            let reply = match self.frames.try_receive() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => return self.on_lost(sample, format!("IPC failure: {e}"), hooks),
            };
            if reply.token != self.hello.token {
                self.figures.foreign += 1;
                self.silent.foreign += 1;
                continue;
            }
            if reply.session != session || !self.connected {
                if self.connected {
                    self.silent.note_session(reply.session);
                }
                continue;
            }
            if reply.status & CommandFrame::STOPPING != 0 {
                return self.on_lost(sample, STOPPED_BY_SIGNAL.into(), hooks);
            }
            self.figures.received += 1;
            self.last_heard = Instant::now();
            self.silent = Seen::default();
            self.next_check = Duration::from_secs_f64(self.settings.reply_timeout);
            self.figures.note_reply_seq(reply.seq);
            if reply.seq + (RING as u64) > k && reply.seq < k {
                self.figures.latency.record(reply.sent_ns.saturating_sub(self.sent_ns[reply.seq as usize % RING]));
            }
            if reply.seq + 1 == k {
                fresh = Some(reply);
            } else {
                self.figures.stale += 1;
            }
        }

        let cmd = if !self.connected {
            self.figures.fallback_ticks += 1;
            if let Some(why) = self.miss_budget_exceeded(MISS_BUDGET_MIN_DUE) {
                return Err(Halt::MissBudget(why));
            }
            match self.poll_handshake(hooks) {
                Some(Ok(())) => {
                    self.first_seq = k;
                    self.figures.last_reply_seq = None;
                    let detail = self.controller.clone();
                    self.event("reconnected", sample.t_s, k, detail);
                    hooks.note(&format!("controller reconnected: {}", self.controller));
                }
                Some(Err(e)) => return Err(Halt::Lost(format!("no reconnection: {e}"))),
                None => {
                    let waited = self.lost_since.map_or(0.0, |t| t.elapsed().as_secs_f64());
                    if waited > self.settings.reconnect_timeout {
                        return Err(Halt::Lost(format!(
                            "controller lost; none reconnected within {} s",
                            self.settings.reconnect_timeout
                        )));
                    }
                }
            }
            self.last_cmd
        } else if k == 0 || k <= self.first_seq {
            self.last_cmd // nothing due yet: the bias (or the fallback after a reconnection)
        } else {
            self.figures.due += 1;
            match fresh {
                Some(reply) => {
                    self.figures.misses.record(false);
                    self.accept(&reply)
                }
                None => {
                    self.figures.misses.record(true);
                    if let Some(why) = self.miss_budget_exceeded(MISS_BUDGET_MIN_DUE) {
                        return Err(Halt::MissBudget(why));
                    }
                    if self.last_heard.elapsed() >= self.next_check {
                        self.next_check += Duration::from_secs_f64(self.settings.reply_timeout);
                        // A child of ours still running is alive: its exit is all there is to
                        // watch, and a `waitpid` tells it. Listing the run's nodes reads the
                        // file system (/tmp/iceoryx2) inside the tick, where a slow disk turns
                        // a burst of misses into a longer one; an external controller has no
                        // other sign of life.
                        let running = self.child.as_mut().is_some_and(|c| c.exited().is_none());
                        if !running {
                            let every = Some(Duration::from_secs_f64(self.settings.reply_timeout));
                            if let Some(why) = controller_gone(&mut self.child, &mut self.log, &mut self.watch, every) {
                                return self.on_lost(sample, why, hooks);
                            }
                        }
                        // Alive but silent (stopped, hung, answering another session) for
                        // controller.lockstep_timeout_ms: lost, as in lockstep.
                        if self.last_heard.elapsed().as_secs_f64() >= self.settings.lockstep_timeout {
                            let seen = std::mem::take(&mut self.silent);
                            return self.on_silent(sample, &seen, hooks);
                        }
                    }
                    self.last_cmd
                }
            }
        };

        if self.connected {
            let frame = self.frame(sample);
            self.sent_ns[k as usize % RING] = frame.sent_ns;
            if let Err(e) = self.frames.send(frame) {
                return self.on_lost(sample, format!("IPC failure: {e}"), hooks);
            }
            self.figures.sent += 1;
        }
        Ok(cmd)
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

/// A lockstep reply is missing since `t0`: every `timeout` the controller is checked (gone: a
/// lost peer); past `deadline` a live one is silent.
///
/// A child of ours that is still running is alive: its exit is all there is to watch, and a
/// `waitpid` tells it. Only an external controller (or a child that exited) is looked up by
/// its node, paced ([`link::PeerWatch`]): a lookup lists every iceoryx2 node of the machine,
/// and unpaced, one at every slice of every wait that outlasted `timeout` (1 ms by default),
/// the lookups took most of a loaded machine's time (292 s of a 370 s debug run of 2 000
/// ticks at a load of 23), which made the replies later still. At the deadline the node is
/// looked up whatever the pacing, to say which it is.
fn check_silence(
    t0: Instant,
    next_check: &mut Duration,
    timeout: Duration,
    deadline: Duration,
    child: &mut Option<Child>,
    log: &mut OutputLog,
    watch: &mut link::PeerWatch,
) -> Verdict {
    let waited = t0.elapsed();
    if waited < *next_check {
        return Verdict::Wait;
    }
    *next_check = waited + timeout;
    if waited >= deadline {
        return match controller_gone(child, log, watch, None) {
            Some(why) => Verdict::Gone(why),
            None => Verdict::Silent,
        };
    }
    if child.as_mut().is_some_and(|c| c.exited().is_none()) {
        return Verdict::Wait;
    }
    match controller_gone(child, log, watch, Some(timeout)) {
        Some(why) => Verdict::Gone(why),
        None => Verdict::Wait,
    }
}

/// `Some(why)` if the controller's process is gone: our child exited (with its last output),
/// or its node is dead or absent. `paced`: the node is looked up only if the pacing allows
/// ([`link::PeerWatch::paced`] with this interval; not looked up: presumed alive); `None`:
/// looked up now.
fn controller_gone(
    child: &mut Option<Child>,
    log: &mut OutputLog,
    watch: &mut link::PeerWatch,
    paced: Option<Duration>,
) -> Option<String> {
    if let Some(c) = child.as_mut() {
        if let Some(status) = c.exited() {
            log.settle();
            return Some(format!("the controller process exited ({status}){}", log.quote(3)));
        }
    }
    let peer = match paced {
        Some(every) => watch.paced(every)?,
        None => watch.lookup(),
    };
    let why = match peer {
        Peer::Alive => return None,
        Peer::Dead => "the controller's node is dead (its process died)",
        Peer::Absent => "the controller's node is gone",
    };
    // A child of ours whose node went is on its way out: its exit status and last words say why.
    if let Some(c) = child.as_mut() {
        let until = Instant::now() + Duration::from_millis(500);
        while Instant::now() < until {
            if let Some(status) = c.exited() {
                log.settle();
                return Some(format!("{why}: the controller process exited ({status}){}", log.quote(3)));
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        return Some(format!("{why}{}", log.quote(3)));
    }
    Some(why.into())
}

/// Waits for a wall-clock instant. `spin`: sleeps while it is far, then spins.
/// `sleep`: sleeps to it (an absolute `CLOCK_MONOTONIC` sleep, which a timer
/// ends; under `SCHED_FIFO` without timer slack), leaving the core to others.
fn pace_until(deadline: Instant, pacing: Pacing) {
    if pacing == Pacing::Sleep {
        let now = Instant::now();
        if now < deadline {
            link::sleep_until_ns(wire::monotonic_ns() + (deadline - now).as_nanos() as u64);
        }
        return;
    }
    const SPIN: Duration = Duration::from_micros(200);
    loop {
        let now = Instant::now();
        if now >= deadline {
            return;
        }
        let left = deadline - now;
        if left > SPIN {
            std::thread::sleep(left - SPIN);
        } else {
            std::hint::spin_loop();
        }
    }
}
