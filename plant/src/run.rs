//! One scene run: the macro-step loop that owns time.
//!
//! A macro step is one controller period `T`. In `continuous` mode the PD is
//! evaluated inside the derivative; in `sampled` mode the law reads the sensor
//! at each tick `t_k = k T`, and the command computed from sample `k` is
//! applied from tick `k + d` (`d = delay_samples`) and held until the next
//! (zero-order hold). `lockstep` and `realtime` do the same with the law in
//! the controller process ([`crate::cosim`] gives their timing). The
//! integrator restarts at every tick. The trace is recorded at the output
//! rate (dense output inside macro steps).

use crate::config::{ControlMode, Scene};
use crate::cosim::{CosimError, CosimReport, Halt, Launch, Session};
pub use crate::hooks::{Hooks, Quiet};
use crate::initial::initial_state;
use crate::integrate::{IntegrationError, Integrator, Settings, Stats};
use crate::model::{ix, Control, Model, RaceWhenClear, State};
use crate::sensor::Sensor;
use crate::trace::Trace;
use controller::{build_law, saturate, wrap_angle, ControlLaw, PdGains, Sample};
use std::collections::VecDeque;

/// Why a run stopped before its end.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunError {
    /// The integrator failed (non-finite state, step-size underflow, stall).
    #[error("numerical divergence: {0}")]
    Integration(#[from] IntegrationError),
    /// A body left the clearance by more than the guard: the contact model has failed.
    #[error("numerical divergence at t = {t} s: {what} = {value_m:.4e} m exceeds the guard {limit_m:.4e} m; state {state:?}")]
    RadiusGuard {
        /// Time (s).
        t: f64,
        /// Which radius.
        what: &'static str,
        /// Its value (m).
        value_m: f64,
        /// The limit (m).
        limit_m: f64,
        /// The state.
        state: Vec<f64>,
    },
}

impl RunError {
    /// Time at which the run failed (s).
    pub fn time(&self) -> f64 {
        match self {
            RunError::Integration(
                IntegrationError::NonFinite { t, .. }
                | IntegrationError::StepSizeUnderflow { t, .. }
                | IntegrationError::TooManySteps { t, .. },
            ) => *t,
            RunError::RadiusGuard { t, .. } => *t,
        }
    }

    /// The state the run failed in (SI, ordered as [`crate::model::ix`]).
    pub fn state(&self) -> &[f64] {
        match self {
            RunError::Integration(
                IntegrationError::NonFinite { state, .. }
                | IntegrationError::StepSizeUnderflow { state, .. }
                | IntegrationError::TooManySteps { state, .. },
            ) => state,
            RunError::RadiusGuard { state, .. } => state,
        }
    }
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// Ran to the scene's duration.
    Completed,
    /// Stopped by a numerical failure.
    Diverged(RunError),
    /// Stopped on request (Ctrl-C), or the controller process was stopped by a signal.
    Interrupted,
    /// The controller process was lost and none took its place (co-simulation).
    PeerLost(String),
    /// Realtime: the deadline-miss fraction exceeded `controller.max_miss_fraction`.
    MissBudget(String),
    /// The law's commands were non-finite past `controller.max_invalid_burst` or
    /// `controller.max_invalid_fraction` ([`crate::invalid`]).
    InvalidCommands(String),
}

/// Why a run could not start.
#[derive(Debug, thiserror::Error)]
pub enum SetupError {
    /// The controller design is invalid.
    #[error("{0}")]
    Law(#[from] controller::LawError),
    /// The controller process could not be started or connected.
    #[error("{0}")]
    Cosim(#[from] CosimError),
    /// The design an external controller runs instead of the scene's is not a valid scene.
    #[error("the controller's overrides: {0}")]
    Overrides(#[from] crate::config::ConfigError),
}

/// Where the loop's output samples go (at the scene's output rate, from the
/// integrator's dense output): a [`Trace`] in memory (`plant compare`, sweeps,
/// benches), the streaming run folder of `plant run` ([`crate::output`]), an
/// online monitor for `plant soak`. The loop itself keeps nothing per sample or
/// per tick (co-simulation latencies go to fixed-size histograms).
pub trait Sink {
    /// The state `y` at time `t` (s); `model` holds the command applied then.
    fn sample(&mut self, model: &Model, t: f64, y: &State);
}

impl Sink for Trace {
    fn sample(&mut self, model: &Model, t: f64, y: &State) {
        self.push(model, t, y);
    }
}

/// A finished (or stopped) run with its trace in memory.
#[derive(Clone, Debug)]
pub struct RunResult {
    /// Recorded trace.
    pub trace: Trace,
    /// How the run went.
    pub run: SinkRun,
}

/// Continuous PD gains for a scene's controller design.
pub fn design_gains(scene: &Scene) -> Result<PdGains, controller::LawError> {
    PdGains::from_design(&scene.design().pd(), &scene.params.loop_constants)
}

/// Integrator settings for a scene, with the macro step as the largest step.
pub fn integrator_settings(scene: &Scene) -> Settings<{ crate::model::N }> {
    let s = &scene.integrator;
    Settings {
        method: s.method,
        substeps: s.substeps,
        rtol: s.rtol,
        atol: s.atol,
        h_max: scene.controller.period,
        max_steps: 1_000_000,
        ..Settings::new(s.method)
    }
}

/// Where the command of each tick comes from.
enum Source {
    /// The PD inside the derivative.
    Continuous,
    /// The law in this process.
    InProcess(Box<dyn ControlLaw>),
    /// The law in the controller process.
    Cosim(Box<Session>),
}

/// Runs a scene from its initial state; a co-simulation starts the
/// `controller` next to the running executable.
pub fn run(scene: &Scene, hooks: &mut dyn Hooks) -> Result<RunResult, SetupError> {
    run_with(scene, &Launch::default(), hooks)
}

/// Runs a scene from its initial state, launching a co-simulation as `launch` says.
pub fn run_with(scene: &Scene, launch: &Launch, hooks: &mut dyn Hooks) -> Result<RunResult, SetupError> {
    let mut trace = Trace::with_capacity((scene.duration / scene.output_interval).ceil() as usize + 2);
    let run = run_into(scene, launch, hooks, &mut trace)?;
    Ok(RunResult { trace, run })
}

/// How a run went, whatever its [`Sink`] kept.
#[derive(Clone, Debug)]
pub struct SinkRun {
    /// Integrator statistics.
    pub stats: Stats,
    /// Simulated time reached (s).
    pub simulated: f64,
    /// Wall time of the loop (s).
    pub wall_time: f64,
    /// How it ended.
    pub outcome: Outcome,
    /// Final state.
    pub final_state: State,
    /// Co-simulation figures (`lockstep`, `realtime`).
    pub cosim: Option<CosimReport>,
    /// Macro steps run with the race parked (`touchdown.race_when_clear = "parked"`).
    pub parked_steps: u64,
    /// Ticks whose command was non-finite (the last valid one was held).
    pub invalid_commands: u64,
}

/// Runs a scene from its initial state, sending every output sample (from
/// `t = 0`, at the scene's output rate) to `sink`.
pub fn run_into(
    scene: &Scene,
    launch: &Launch,
    hooks: &mut dyn Hooks,
    sink: &mut dyn Sink,
) -> Result<SinkRun, SetupError> {
    let gains = design_gains(scene)?;
    let limit = scene.params.current_limit;
    let bias = saturate(gains.bias_a, limit);
    let (design, params) = (scene.design(), &scene.controller.params);
    let source = match scene.controller.mode {
        ControlMode::Continuous => Source::Continuous,
        ControlMode::Sampled => Source::InProcess(build_law(&scene.controller.law, &design, params)?),
        ControlMode::Lockstep | ControlMode::Realtime => {
            // A design the controller would refuse is bad input here, before any process starts
            // (a controller command checks the laws it serves itself, in the handshake).
            if scene.controller.cosim.command.is_none() {
                build_law(&scene.controller.law, &design, params)?;
            }
            Source::Cosim(Box::new(Session::connect(scene, launch, bias, hooks)?))
        }
    };
    run_from(scene, source, hooks, sink)
}

/// Runs a scene with `law` in this process, as `controller.mode = "sampled"` runs a law of
/// the registry (whatever the scene's mode): the sensor read at each tick, the command
/// saturated, delayed `delay_samples` ticks and held. A lockstep run of the same law in a
/// controller process writes the same trace, bit for bit. See [`crate::check`].
pub fn run_law_into(
    scene: &Scene,
    law: Box<dyn ControlLaw>,
    hooks: &mut dyn Hooks,
    sink: &mut dyn Sink,
) -> Result<SinkRun, SetupError> {
    run_from(scene, Source::InProcess(law), hooks, sink)
}

/// The loop, from a command source.
fn run_from(
    scene: &Scene,
    mut source: Source,
    hooks: &mut dyn Hooks,
    sink: &mut dyn Sink,
) -> Result<SinkRun, SetupError> {
    // An external controller may run a design of its own (its `--config` or `--law`): the run
    // is then the scene with those overrides, initial state and bias included, so that the
    // scene it records reproduces it.
    let effective = match &source {
        Source::Cosim(session) => session.overrides().map(|o| scene.with_controller_overrides(o)).transpose()?,
        _ => None,
    };
    let scene = effective.as_ref().unwrap_or(scene);
    let gains = design_gains(scene)?;
    let limit = scene.params.current_limit;
    let bias = saturate(gains.bias_a, limit);
    if let (Source::Cosim(session), Some(_)) = (&mut source, &effective) {
        session.adopt(bias, limit);
    }
    let mut model = Model {
        params: scene.params.clone(),
        base: scene.base.clone(),
        control: match source {
            Source::Continuous => Control::Continuous(gains),
            _ => Control::Held(bias),
        },
        race_parked: false,
    };
    let mut integrator = Integrator::new(integrator_settings(scene));
    let mut y = initial_state(scene);
    let period = scene.controller.period;
    let ticks = (scene.duration / period).ceil() as u64;
    let out_dt = scene.output_interval;
    sink.sample(&model, 0.0, &y);
    let mut next_out: u64 = 1;
    // Output samples per tick; a period longer than the run holds only the run's samples.
    let mut out_times: Vec<f64> = Vec::with_capacity((period.min(scene.duration) / out_dt).ceil() as usize + 2);
    let inherent = match &mut source {
        Source::Cosim(session) => {
            if let Some(pid) = session.controller_pid() {
                hooks.controller_connected(pid);
            }
            session.inherent_delay()
        }
        _ => 0,
    };
    let delay = scene.controller.delay_samples.saturating_sub(inherent) as usize;
    let mut queue: VecDeque<[f64; 2]> = VecDeque::with_capacity(delay + 1);
    queue.extend(std::iter::repeat_n(bias, delay));
    let mut sensor = Sensor::new(scene.sensor);
    let c = &scene.controller;
    let mut invalid = crate::invalid::InvalidCommands::new(bias, c.max_invalid_burst, c.max_invalid_fraction);
    let guards = Guards::new(scene);
    let breakpoints = scene.base.breakpoints();
    let mut next_breakpoint = 0;
    let mut parked_steps = 0u64;

    let mut controller_pid = match &source {
        Source::Cosim(session) => session.controller_pid(),
        _ => None,
    };
    let start = std::time::Instant::now();
    let mut outcome = Outcome::Completed;
    let mut t = 0.0;
    for k in 0..ticks {
        let t0 = k as f64 * period;
        let t1 = ((k + 1) as f64 * period).min(scene.duration);
        // The keyphasor: the rotor's speed and its angle wrapped to [0, 2π), from the state.
        let mut sample = Sample {
            seq: k,
            t_s: t0,
            sensor_v: sensor.read([y[ix::XR], y[ix::YR]]),
            speed_rad_s: y[ix::WR],
            angle_rad: wrap_angle(y[ix::TR]),
        };
        let excitation = hooks.excitation(k, t0, &sample.sensor_v);
        if let Some(sine) = excitation {
            sample.sensor_v.iter_mut().zip(sine.at(t0).0).for_each(|(v, e)| *v += e);
        }
        if let Source::Continuous = source {
            model.control = excitation.map_or(Control::Continuous(gains), |e| Control::ContinuousExcited(gains, e));
        }
        let command = match &mut source {
            Source::Continuous => None,
            Source::InProcess(law) => Some(saturate(law.update(&sample), limit)),
            Source::Cosim(session) => match session.command(&sample, hooks) {
                Ok(cmd) => {
                    let pid = session.controller_pid();
                    if pid != controller_pid {
                        controller_pid = pid;
                        if let Some(pid) = pid {
                            hooks.controller_connected(pid);
                        }
                    }
                    Some(cmd)
                }
                Err(halt) => {
                    outcome = match halt {
                        Halt::Lost(why) => Outcome::PeerLost(why),
                        Halt::Interrupted(_) => Outcome::Interrupted,
                        Halt::MissBudget(why) => Outcome::MissBudget(why),
                    };
                    break;
                }
            },
        };
        if let Some(cmd) = command {
            let cmd = match invalid.check(cmd, &sample) {
                Ok(checked) => {
                    if checked.first {
                        hooks.note(&format!(
                            "warning: the controller's command for sample {} (t = {} s) is non-finite, {cmd:?} A: \
                             the last valid command is held for it and for every later non-finite one, up to \
                             controller.max_invalid_burst = {} in a row (counted in summary.json, invalid_commands)",
                            sample.seq, sample.t_s, c.max_invalid_burst
                        ));
                    }
                    checked.command
                }
                Err(why) => {
                    outcome = Outcome::InvalidCommands(why);
                    break;
                }
            };
            queue.push_back(cmd);
            if let Some(applied) = queue.pop_front() {
                model.control = Control::Held(applied);
            }
        }
        if let RaceWhenClear::Parked(release) = scene.params.race_when_clear {
            let clear = crate::park::clear(&model, t0, t1 - t0, &y);
            if clear && !model.race_parked {
                crate::park::park(&mut y);
                model.race_parked = true;
                integrator.set_substeps(scene.integrator.substeps);
            } else if !clear && (model.race_parked || k == 0) {
                if model.race_parked {
                    crate::park::release(&model, t0, &mut y, release);
                }
                model.race_parked = false;
                integrator.set_substeps(scene.integrator.contact_substeps);
            }
            parked_steps += u64::from(model.race_parked);
        }
        out_times.clear();
        while (next_out as f64) * out_dt <= t1 + 1e-9 * out_dt {
            out_times.push(((next_out as f64) * out_dt).min(t1));
            next_out += 1;
        }
        let step = advance_across_breakpoints(
            &mut integrator,
            &model,
            (t0, t1),
            &mut y,
            &out_times,
            (&breakpoints, &mut next_breakpoint),
            |ts, ys| sink.sample(&model, ts, ys),
        );
        t = t1;
        if let Err(e) = step.map_err(RunError::from).and_then(|()| guards.check(t1, &y)) {
            // The run reached the failure, not the end of its macro step (an integration
            // error stops inside it).
            t = e.time();
            outcome = Outcome::Diverged(e);
            break;
        }
        hooks.progress(t1);
        if hooks.cancelled() {
            outcome = Outcome::Interrupted;
            break;
        }
    }
    let wall_time = start.elapsed().as_secs_f64();
    // A run that completed is judged over all its ticks.
    if outcome == Outcome::Completed {
        if let Some(why) = invalid.at_end() {
            outcome = Outcome::InvalidCommands(why);
        }
    }
    let cosim = match source {
        Source::Cosim(session) => {
            if outcome == Outcome::Completed {
                if let Some(why) = session.miss_budget_exceeded(1) {
                    outcome = Outcome::MissBudget(why);
                }
            }
            let mut report = session.finish(t, (t / period).round() as u64);
            report.invalid_replies = invalid.count();
            Some(report)
        }
        _ => None,
    };
    let invalid_commands = invalid.count();
    Ok(SinkRun {
        stats: integrator.stats(),
        simulated: t,
        wall_time,
        outcome,
        final_state: y,
        cosim,
        parked_steps,
        invalid_commands,
    })
}

/// Advances over `[t0, t1]`, ending a step at every breakpoint of the base motion inside it
/// (where the housing acceleration or its slope jumps): a step across such a kink has an
/// O(h²) local error whatever the method's order. `breakpoints` is sorted; `next` is the index
/// of the first one not yet passed. Samples at `times` go to `sample`.
fn advance_across_breakpoints<F: FnMut(f64, &State)>(
    integrator: &mut Integrator<{ crate::model::N }>,
    model: &Model,
    (t0, t1): (f64, f64),
    y: &mut State,
    times: &[f64],
    (breakpoints, next): (&[f64], &mut usize),
    mut sample: F,
) -> Result<(), IntegrationError> {
    let tiny = 1e-9 * (t1 - t0);
    let mut from = t0;
    let mut done = 0;
    while *next < breakpoints.len() && breakpoints[*next] < t1 - tiny {
        let b = breakpoints[*next];
        *next += 1;
        if b <= from + tiny {
            continue;
        }
        let upto = done + times[done..].partition_point(|t| *t <= b);
        integrator.advance_dense(model, from, b, y, &times[done..upto], &mut sample)?;
        done = upto;
        from = b;
    }
    integrator.advance_dense(model, from, t1, y, &times[done..], sample)
}

/// Radius limits beyond which the contact model has failed.
struct Guards {
    rotor: f64,
    race: f64,
}

impl Guards {
    fn new(scene: &Scene) -> Self {
        let p = &scene.params;
        let g = scene.integrator.radius_guard;
        Self { rotor: p.contact.gap + p.balls.clearance + g, race: p.balls.clearance + g }
    }

    fn check(&self, t: f64, y: &State) -> Result<(), RunError> {
        let rotor = y[ix::XR].hypot(y[ix::YR]);
        let race = y[ix::XB].hypot(y[ix::YB]);
        let fail = |what, value_m, limit_m| RunError::RadiusGuard { t, what, value_m, limit_m, state: y.to_vec() };
        if rotor > self.rotor {
            return Err(fail("rotor radius", rotor, self.rotor));
        }
        if race > self.race {
            return Err(fail("race radius", race, self.race));
        }
        Ok(())
    }
}
