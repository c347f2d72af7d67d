//! The digital loop as one piece: from what the controller reads at a tick to the command the
//! plant applies over it.
//!
//! At tick `k` the loop takes the plant's sample ([`crate::stepper::Plant::sample`]), adds an
//! excitation's sine at the summing point if a sensitivity measurement asks for one
//! ([`Hooks::excitation`]), asks the law for its command (the PD inside the derivative, a law
//! in this process, or the controller process over the wire: a [`Remote`], the CLI's
//! co-simulation session), saturates it,
//! holds the last valid command in place of a non-finite one within the budget
//! ([`crate::invalid`]), and delays it `delay_samples` ticks (less the transport's own sample in
//! realtime): the command applied over tick `k` was computed from sample `k − d`.
//!
//! Every mode drives this one loop (the CLI's `plant::run`); `plant::check`'s replay feeds a
//! recorded run's samples through the same command path ([`CommandPath`]).

use crate::config::Scene;
use crate::hooks::Hooks;
use crate::invalid::InvalidCommands;
use crate::run::Outcome;
use crate::stepper::Command;
use controller::{saturate_axes, RotorLaw, RotorSample, ROTOR_AXES};
use std::collections::VecDeque;
use std::time::Instant;

/// Why the loop must stop at this tick (a [`Remote`]'s answer).
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

/// A law in another process, as the loop sees it: the CLI's co-simulation session
/// (`plant::cosim::Session`, over iceoryx2). The seam keeps the transport out of this crate.
pub trait Remote {
    /// What the remote reports when the run ends (the co-simulation's figures).
    type Report;
    /// Ticks of delay the transport itself adds (realtime: one sample).
    fn inherent_delay(&self) -> u32;
    /// The controller process serving now, if connected.
    fn controller_pid(&self) -> Option<u32>;
    /// The (saturated) command for `sample`, or why the loop must stop.
    fn command(&mut self, sample: &RotorSample, hooks: &mut dyn Hooks) -> Result<[f64; ROTOR_AXES], Halt>;
    /// Realtime: when the plant woke for the current tick.
    fn tick_started(&self) -> Option<Instant>;
    /// `Some(why)` when the deadline misses are past their budget (`min_due` ticks at least).
    fn miss_budget_exceeded(&self, min_due: u64) -> Option<String>;
    /// `Some(why)` when the plant's overruns are past their budget (`min_ticks` at least).
    fn overrun_budget_exceeded(&self, min_ticks: u64) -> Option<String>;
    /// Ends the session at `t_s` after `seq` ticks, `invalid_replies` of them non-finite.
    fn finish(self, t_s: f64, seq: u64, invalid_replies: u64) -> Self::Report;
}

/// Where the command of each tick comes from.
pub enum Source<R: Remote> {
    /// The PD inside the derivative.
    Continuous,
    /// The law in this process: one per plane (decentralised) or one of the whole rotor.
    InProcess(Box<dyn RotorLaw>),
    /// The law in the controller process.
    Cosim(Box<R>),
}

/// Saturation, the invalid-command budget and the delay line: what happens to a law's answer
/// before the plant applies it. The same for a law in this process, the controller process and
/// a recorded run's replay.
#[derive(Clone, Debug)]
pub struct CommandPath {
    limits: [f64; ROTOR_AXES],
    invalid: InvalidCommands<ROTOR_AXES>,
    /// The commands not yet applied, oldest first.
    line: VecDeque<[f64; ROTOR_AXES]>,
}

/// What [`CommandPath::push`] makes of one answer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pushed {
    /// The command applied over this tick (the one computed `delay` ticks before).
    pub applied: [f64; ROTOR_AXES],
    /// This tick's answer was the run's first non-finite one (held in its place).
    pub first_invalid: bool,
}

impl CommandPath {
    /// A path whose commands before any answer are `bias`, saturated at `limits`, delayed
    /// `delay` ticks, with the budget of non-finite answers `max_burst` in a row and
    /// `max_fraction` of the ticks.
    pub fn new(
        bias: [f64; ROTOR_AXES],
        limits: [f64; ROTOR_AXES],
        delay: usize,
        max_burst: u64,
        max_fraction: f64,
    ) -> Self {
        let mut line = VecDeque::with_capacity(delay + 1);
        line.extend(std::iter::repeat_n(bias, delay));
        Self { limits, invalid: InvalidCommands::new(bias, max_burst, max_fraction), line }
    }

    /// A law's answer saturated at the limits.
    pub fn saturate(&self, answer: [f64; ROTOR_AXES]) -> [f64; ROTOR_AXES] {
        saturate_axes(answer, self.limits)
    }

    /// Takes a law's (saturated) answer to `sample` and gives the command applied over this
    /// tick, or why the run must end.
    pub fn push(&mut self, answer: [f64; ROTOR_AXES], sample: &RotorSample) -> Result<Pushed, String> {
        let checked = self.invalid.check(answer, sample)?;
        self.line.push_back(checked.command);
        let applied = self.line.pop_front().unwrap_or(checked.command);
        Ok(Pushed { applied, first_invalid: checked.first })
    }

    /// Non-finite answers so far.
    pub fn invalid_count(&self) -> u64 {
        self.invalid.count()
    }

    /// At the run's end: `Some(why)` if the share of non-finite answers is past the budget.
    pub fn at_end(&self) -> Option<String> {
        self.invalid.at_end()
    }

    /// The commands in the delay line, oldest first (a snapshot's).
    pub fn in_flight(&self) -> Vec<[f64; ROTOR_AXES]> {
        self.line.iter().copied().collect()
    }

    /// Puts `commands` in flight (a snapshot's delay line): as they are when the line has their
    /// length; otherwise the line keeps its length, each place holding the newest of them.
    pub fn set_in_flight(&mut self, commands: &[[f64; ROTOR_AXES]]) {
        let Some(newest) = commands.last() else { return };
        if commands.len() == self.line.len() {
            self.line.clear();
            self.line.extend(commands.iter().copied());
        } else {
            self.line.iter_mut().for_each(|c| *c = *newest);
        }
    }

    /// `controller.max_invalid_burst`, for messages.
    pub fn max_burst(&self) -> u64 {
        self.invalid.max_burst()
    }
}

/// Samples a snapshot keeps of what the law read last ([`DigitalLoop::recent`]): a law whose
/// memory is at most this many samples (a backward difference, a delay, an FIR filter)
/// continues bit for bit after [`DigitalLoop::prime`].
pub const RECENT: usize = 32;

/// The digital loop of one run (module doc).
pub struct DigitalLoop<R: Remote> {
    source: Source<R>,
    path: CommandPath,
    controller_pid: Option<u32>,
    /// The last [`RECENT`] samples the law read, a ring (`recent_next` the oldest once full).
    recent: [RotorSample; RECENT],
    recent_len: usize,
    recent_next: usize,
}

impl<R: Remote> DigitalLoop<R> {
    /// The loop of `scene`, its commands from `source`, `bias` before any (A, per axis),
    /// saturated at `limits`.
    pub fn new(scene: &Scene, source: Source<R>, bias: [f64; ROTOR_AXES], limits: [f64; ROTOR_AXES]) -> Self {
        let inherent = match &source {
            Source::Cosim(session) => session.inherent_delay(),
            _ => 0,
        };
        let c = &scene.controller;
        let delay = c.delay_samples.saturating_sub(inherent) as usize;
        let controller_pid = match &source {
            Source::Cosim(session) => session.controller_pid(),
            _ => None,
        };
        let path = CommandPath::new(bias, limits, delay, c.max_invalid_burst, c.max_invalid_fraction);
        Self { source, path, controller_pid, recent: [RotorSample::default(); RECENT], recent_len: 0, recent_next: 0 }
    }

    /// The samples the law read last, oldest first (at most [`RECENT`]; a snapshot's).
    pub fn recent(&self) -> Vec<RotorSample> {
        let start = if self.recent_len < RECENT { 0 } else { self.recent_next };
        (0..self.recent_len).map(|i| self.recent[(start + i) % RECENT]).collect()
    }

    /// Feeds `samples` (a snapshot's [`DigitalLoop::recent`]) to the law, its answers unused:
    /// a law that starts here then has the memory it had when the snapshot was taken, if that
    /// memory is no longer than the samples. A law in this process or in the controller process
    /// (over the wire, as ordinary ticks); the PD inside the derivative has none.
    pub fn prime(&mut self, samples: &[RotorSample], hooks: &mut dyn Hooks) -> Result<(), Outcome> {
        for s in samples {
            match &mut self.source {
                Source::Continuous => return Ok(()),
                Source::InProcess(law) => {
                    law.update(s);
                }
                Source::Cosim(session) => {
                    session.command(s, hooks).map_err(outcome_of)?;
                }
            }
            self.remember(s);
        }
        Ok(())
    }

    fn remember(&mut self, sample: &RotorSample) {
        self.recent[self.recent_next] = *sample;
        self.recent_next = (self.recent_next + 1) % RECENT;
        self.recent_len = (self.recent_len + 1).min(RECENT);
    }

    /// The commands come from the controller process (whose ticks are always timed).
    pub fn is_cosim(&self) -> bool {
        matches!(self.source, Source::Cosim(_))
    }

    /// The controller process connected at the start, if any.
    pub fn controller_pid(&self) -> Option<u32> {
        self.controller_pid
    }

    /// The command path (its delay line, for a snapshot).
    pub fn path(&self) -> &CommandPath {
        &self.path
    }

    /// The same, to put a snapshot's commands in flight.
    pub fn path_mut(&mut self) -> &mut CommandPath {
        &mut self.path
    }

    /// Realtime: when the plant woke for the current tick.
    pub fn tick_started(&self) -> Option<Instant> {
        match &self.source {
            Source::Cosim(session) => session.tick_started(),
            _ => None,
        }
    }

    /// The command over the tick of `sample` (what the plant read), or how the run ends.
    pub fn command(&mut self, sample: &RotorSample, hooks: &mut dyn Hooks) -> Result<Command, Outcome> {
        // Bearing planes of the rotor: the sample's axes, two each.
        let planes = sample.axes as usize / 2;
        let mut sample = *sample;
        // The summing point of a sensitivity measurement (one plane's axes): added to what a
        // law reads, handed to the plane's continuous PD, which reads it inside the derivative.
        let excitation =
            hooks.excitation(sample.seq, sample.t_s, &sample.sensor_v[..2 * planes]).filter(|e| e.plane < planes);
        if let Some(e) = excitation {
            let axes = &mut sample.sensor_v[2 * e.plane..2 * e.plane + 2];
            axes.iter_mut().zip(e.sine.at(sample.t_s).0).for_each(|(v, e)| *v += e);
        }
        let answer = match &mut self.source {
            Source::Continuous => return Ok(Command::Continuous(excitation)),
            Source::InProcess(law) => self.path.saturate(law.update(&sample)),
            Source::Cosim(session) => match session.command(&sample, hooks) {
                Ok(cmd) => {
                    let pid = session.controller_pid();
                    if pid != self.controller_pid {
                        self.controller_pid = pid;
                        if let Some(pid) = pid {
                            hooks.controller_connected(pid);
                        }
                    }
                    cmd
                }
                Err(halt) => return Err(outcome_of(halt)),
            },
        };
        self.remember(&sample);
        // (The session saturates what comes over the wire itself.)
        let pushed = self.path.push(answer, &sample).map_err(Outcome::InvalidCommands)?;
        if pushed.first_invalid {
            hooks.note(&format!(
                "warning: the controller's command for sample {} (t = {} s) is non-finite, {:?} A: \
                 the last valid command is held for it and for every later non-finite one, up to \
                 controller.max_invalid_burst = {} in a row (counted in summary.json, invalid_commands)",
                sample.seq,
                sample.t_s,
                &answer[..2 * planes],
                self.path.max_burst()
            ));
        }
        Ok(Command::Held(pushed.applied))
    }

    /// Ends the loop at `t` (s): the run's outcome judged over all its ticks (a run that
    /// completed may still be past a budget), and the co-simulation's figures.
    pub fn finish(self, mut outcome: Outcome, t: f64, period: f64) -> (Outcome, Option<R::Report>, u64) {
        if outcome == Outcome::Completed {
            if let Some(why) = self.path.at_end() {
                outcome = Outcome::InvalidCommands(why);
            }
        }
        let invalid = self.path.invalid_count();
        let cosim = match self.source {
            Source::Cosim(session) => {
                if outcome == Outcome::Completed {
                    if let Some(why) = session.miss_budget_exceeded(1) {
                        outcome = Outcome::MissBudget(why);
                    } else if let Some(why) = session.overrun_budget_exceeded(1) {
                        outcome = Outcome::OverrunBudget(why);
                    }
                }
                Some(session.finish(t, (t / period).round() as u64, invalid))
            }
            _ => None,
        };
        (outcome, cosim, invalid)
    }
}

/// How a run ends when the session halts.
fn outcome_of(halt: Halt) -> Outcome {
    match halt {
        Halt::Lost(why) => Outcome::PeerLost(why),
        Halt::Interrupted(_) => Outcome::Interrupted,
        Halt::MissBudget(why) => Outcome::MissBudget(why),
        Halt::OverrunBudget(why) => Outcome::OverrunBudget(why),
    }
}
