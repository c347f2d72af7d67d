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
use crate::cosim::stats::{Tet, TickTime};
use crate::cosim::{CosimError, CosimReport, Halt, Launch, Session};
use crate::hardware::{Wired, EXTRA, EXTRA_UNIPOLAR};
pub use crate::hooks::{Hooks, Quiet};
use crate::initial::initial_state;
use crate::integrate::{IntegrationError, Integrator, Settings, Stats, System};
use crate::machine::Machine;
use crate::model::{Control, Model, RaceWhenClear};
use crate::sensor::Sensor;
use crate::trace::{Record, Trace};
use controller::{build_rotor_law, saturate, saturate_axes, wrap_angle, PdGains, RotorLaw, RotorSample, ROTOR_AXES};
use plant_physics::two_plane;
use std::collections::VecDeque;
use std::time::{Duration, Instant};

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
    /// Realtime: the plant-overrun fraction exceeded `controller.max_overrun_fraction`.
    OverrunBudget(String),
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
    /// The thread that takes a realtime run's samples could not be started.
    #[error("starting the thread that takes the run's samples: {0}")]
    Thread(std::io::Error),
}

/// Where the loop's output samples go (at the scene's output rate, from the
/// integrator's dense output): a [`Trace`] in memory (`plant compare`, sweeps,
/// benches), the streaming run folder of `plant run` ([`crate::output`]), an
/// online monitor for `plant soak`. The loop itself keeps nothing per sample or
/// per tick (co-simulation latencies go to fixed-size histograms).
pub trait Sink {
    /// The sample at one output time: the state's row(s) with the forces the model gives there.
    fn sample(&mut self, record: &Record);

    /// The same sample as the planar model's state, after [`Sink::sample`] (planar runs only):
    /// for a sink that needs what a row does not hold (the race's angle and acceleration, each
    /// ball's load: the assessment's touchdown-bearing duty). The default ignores it.
    fn planar_state(&mut self, _model: &crate::model::Model, _t: f64, _y: &crate::model::State) {}

    /// The same for the two-plane rotor's state, after [`Sink::sample`] (two-plane runs only):
    /// each touchdown bearing's duty. The default ignores it.
    fn two_plane_state(
        &mut self,
        _model: &plant_physics::two_plane::Model,
        _t: f64,
        _y: &plant_physics::two_plane::State,
    ) {
    }
}

impl Sink for Trace {
    fn sample(&mut self, record: &Record) {
        self.push(record);
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

/// Continuous PD gains for a scene's controller design (plane A's, for a two-plane rotor).
pub fn design_gains(scene: &Scene) -> Result<PdGains, controller::LawError> {
    PdGains::from_design(&scene.design().pd(), &scene.params.loop_constants)
}

/// Continuous PD gains of each bearing plane's design (one for the planar model).
pub fn plane_gains(scene: &Scene) -> Result<Vec<PdGains>, controller::LawError> {
    scene.plane_designs().iter().map(|d| PdGains::from_design(&d.pd(), &d.constants)).collect()
}

/// Integrator settings for a scene, with the macro step as the largest step.
pub fn integrator_settings(scene: &Scene) -> Settings<{ crate::model::N }> {
    settings_with(scene, scene.integrator.atol)
}

/// Integrator settings for a scene's model of `N` state components, absolute tolerances `atol`.
pub fn settings_with<const N: usize>(scene: &Scene, atol: [f64; N]) -> Settings<N> {
    let s = &scene.integrator;
    Settings {
        method: s.method,
        substeps: s.substeps,
        rtol: s.rtol,
        atol,
        h_max: scene.controller.period,
        max_steps: 1_000_000,
        ..Settings::new(s.method)
    }
}

/// Where the command of each tick comes from.
enum Source {
    /// The PD inside the derivative.
    Continuous,
    /// The law in this process: one per plane (decentralised) or one of the whole rotor.
    InProcess(Box<dyn RotorLaw>),
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
    /// Final state (ordered as the model's state: [`crate::model::ix`] or
    /// [`plant_physics::two_plane::ix`]).
    pub final_state: Vec<f64>,
    /// Co-simulation figures (`lockstep`, `realtime`).
    pub cosim: Option<CosimReport>,
    /// Macro steps run with a race parked (`touchdown.race_when_clear = "parked"`), summed over
    /// the bearing planes.
    pub parked_steps: u64,
    /// Bearing planes of the model (1 or 2).
    pub planes: usize,
    /// Ticks whose command was non-finite (the last valid one was held).
    pub invalid_commands: u64,
    /// Time with an amplifier at its voltage limit (s); `None` without amplifiers.
    pub voltage_saturation_s: Option<f64>,
    /// The cost of the ticks: the most model evaluations in one, and the execution times.
    pub ticks: TickCost,
}

/// What the ticks of a run cost.
#[derive(Clone, Debug, Default)]
pub struct TickCost {
    /// The most evaluations of the model the integrator made in one tick.
    pub max_rhs_evals: u64,
    /// The plant's execution time per tick (co-simulation runs, or [`Hooks::time_ticks`]).
    pub tet: Option<Box<Tet>>,
}

/// Runs a scene from its initial state, sending every output sample (from
/// `t = 0`, at the scene's output rate) to `sink`.
pub fn run_into(
    scene: &Scene,
    launch: &Launch,
    hooks: &mut dyn Hooks,
    sink: &mut dyn Sink,
) -> Result<SinkRun, SetupError> {
    let params = &scene.controller.params;
    let source = match scene.controller.mode {
        ControlMode::Continuous => Source::Continuous,
        ControlMode::Sampled => {
            Source::InProcess(build_rotor_law(&scene.controller.law, &scene.rotor_design(), params)?)
        }
        ControlMode::Lockstep | ControlMode::Realtime => {
            // A design the controller would refuse is bad input here, before any process starts
            // (a controller command checks the laws it serves itself, in the handshake).
            if scene.controller.cosim.command.is_none() {
                build_rotor_law(&scene.controller.law, &scene.rotor_design(), params)?;
            }
            Source::Cosim(Box::new(Session::connect(scene, launch, bias_of(scene, &plane_gains(scene)?), hooks)?))
        }
    };
    run_from(scene, source, hooks, sink)
}

/// The bias currents per axis (A) of each plane's design `gains`, each within its plane's
/// limit (unused axes 0).
pub(crate) fn bias_of(scene: &Scene, gains: &[PdGains]) -> [f64; ROTOR_AXES] {
    let mut bias = [0.0; ROTOR_AXES];
    for (i, g) in gains.iter().enumerate() {
        let b = saturate(g.bias_a, scene.plane(i).current_limit);
        bias[2 * i..2 * i + 2].copy_from_slice(&b);
    }
    bias
}

/// Runs a scene with `law` in this process, as `controller.mode = "sampled"` runs a law of
/// the registry (whatever the scene's mode): the sensor read at each tick, the command
/// saturated, delayed `delay_samples` ticks and held. A lockstep run of the same law in a
/// controller process writes the same trace, bit for bit. See [`crate::check`].
pub fn run_law_into(
    scene: &Scene,
    law: Box<dyn RotorLaw>,
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
    let gains = plane_gains(scene)?;
    let bias = bias_of(scene, &gains);
    let limits = scene.rotor_design().current_limits();
    if let (Source::Cosim(session), Some(_)) = (&mut source, &effective) {
        session.adopt(bias, limits);
    }
    let control = |i: usize| match source {
        Source::Continuous => Control::Continuous(gains[i]),
        _ => Control::Held([bias[2 * i], bias[2 * i + 1]]),
    };
    let hw = &scene.hardware;
    let controls = if scene.two_plane.is_some() { [control(0), control(1)] } else { [control(0); 2] };
    let [p, v, ..] = scene.integrator.atol_groups;
    match &scene.two_plane {
        None => {
            let model = Model {
                params: scene.params.clone(),
                base: scene.base.clone(),
                control: control(0),
                race_parked: false,
            };
            let y = initial_state(scene);
            if hw.is_unipolar() {
                const NA: usize = crate::model::N + EXTRA_UNIPOLAR;
                let wired = Wired::<Model, { crate::model::N }, NA>::new(model, controls, hw.clone());
                let y = wired.initial(&y);
                let settings = settings_with(scene, extended::<{ crate::model::N }, NA>(scene.integrator.atol, p, v));
                return drive(scene, wired, y, settings, source, (bias, limits), &gains, hooks, sink);
            }
            if hw.is_on() {
                const NA: usize = crate::model::N + EXTRA;
                let wired = Wired::<Model, { crate::model::N }, NA>::new(model, controls, hw.clone());
                let y = wired.initial(&y);
                let settings = settings_with(scene, extended::<{ crate::model::N }, NA>(scene.integrator.atol, p, v));
                return drive(scene, wired, y, settings, source, (bias, limits), &gains, hooks, sink);
            }
            drive(scene, model, y, integrator_settings(scene), source, (bias, limits), &gains, hooks, sink)
        }
        Some(params) => {
            let model = two_plane::Model {
                params: params.clone(),
                base: scene.base.clone(),
                control: [control(0), control(1)],
                race_parked: [false; 2],
            };
            let y = crate::initial::two_plane_initial_state(scene, params);
            if hw.is_unipolar() {
                const NA: usize = two_plane::N + EXTRA_UNIPOLAR;
                let wired = Wired::<two_plane::Model, { two_plane::N }, NA>::new(model, controls, hw.clone());
                let y = wired.initial(&y);
                let atol = extended::<{ two_plane::N }, NA>(scene.integrator.two_plane_atol(), p, v);
                return drive(scene, wired, y, settings_with(scene, atol), source, (bias, limits), &gains, hooks, sink);
            }
            if hw.is_on() {
                const NA: usize = two_plane::N + EXTRA;
                let wired = Wired::<two_plane::Model, { two_plane::N }, NA>::new(model, controls, hw.clone());
                let y = wired.initial(&y);
                let atol = extended::<{ two_plane::N }, NA>(scene.integrator.two_plane_atol(), p, v);
                return drive(scene, wired, y, settings_with(scene, atol), source, (bias, limits), &gains, hooks, sink);
            }
            let settings = settings_with(scene, scene.integrator.two_plane_atol());
            drive(scene, model, y, settings, source, (bias, limits), &gains, hooks, sink)
        }
    }
}

/// The model's tolerances `atol` with the hardware's after them ([`crate::hardware::atol`]).
fn extended<const N: usize, const NA: usize>(atol: [f64; N], p: f64, v: f64) -> [f64; NA] {
    let mut a = [0.0; NA];
    a[..N].copy_from_slice(&atol);
    a[N..].copy_from_slice(&crate::hardware::atol(p, v)[..NA - N]);
    a
}

/// Hands the output sample of state `y` at time `t` to `sink` (and its state: on the planar
/// model [`Sink::planar_state`], on the two-plane rotor [`Sink::two_plane_state`]).
#[inline]
fn feed<const N: usize, M: Machine<N>>(model: &M, sink: &mut dyn Sink, t: f64, y: &[f64; N]) {
    sink.sample(&model.record(t, y));
    if let (Some(planar), Ok(state)) = (model.planar(), <&crate::model::State>::try_from(&y[..])) {
        sink.planar_state(planar, t, state);
    } else if let (Some(m), Ok(state)) = (model.two_plane(), <&plant_physics::two_plane::State>::try_from(&y[..])) {
        sink.two_plane_state(m, t, state);
    }
}

/// The macro-step loop (module doc) for a model of `N` state components starting at `y`.
#[allow(clippy::too_many_arguments)]
fn drive<const N: usize, M: Machine<N>>(
    scene: &Scene,
    mut model: M,
    mut y: [f64; N],
    settings: Settings<N>,
    mut source: Source,
    (bias, limits): ([f64; ROTOR_AXES], [f64; ROTOR_AXES]),
    gains: &[PdGains],
    hooks: &mut dyn Hooks,
    sink: &mut dyn Sink,
) -> Result<SinkRun, SetupError> {
    let planes = M::PLANES;
    // The plane whose continuous PD read the previous tick's sine.
    let mut excited: Option<usize> = None;
    let mut integrator = Integrator::new(settings);
    let period = scene.controller.period;
    let ticks = (scene.duration / period).ceil() as u64;
    let out_dt = scene.output_interval;
    feed(&model, sink, 0.0, &y);
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
    let mut queue: VecDeque<[f64; ROTOR_AXES]> = VecDeque::with_capacity(delay + 1);
    queue.extend(std::iter::repeat_n(bias, delay));
    let mut sensor = Sensor::new(scene.sensor);
    let c = &scene.controller;
    let mut invalid = crate::invalid::InvalidCommands::new(bias, c.max_invalid_burst, c.max_invalid_fraction);
    let guards = Guards::new(scene, &model);
    let breakpoints = scene.base.breakpoints();
    let mut next_breakpoint = 0;
    let mut parked_steps = 0u64;

    let mut controller_pid = match &source {
        Source::Cosim(session) => session.controller_pid(),
        _ => None,
    };
    let mut cost = TickCost {
        max_rhs_evals: 0,
        tet: (matches!(source, Source::Cosim(_)) || hooks.time_ticks()).then(|| Box::new(Tet::new(ticks))),
    };
    let start = Instant::now();
    let mut outcome = Outcome::Completed;
    let mut t = 0.0;
    for k in 0..ticks {
        let tick_start = Instant::now();
        let t0 = k as f64 * period;
        let t1 = ((k + 1) as f64 * period).min(scene.duration);
        // Every axis's sensor (the planes in order, one noise sequence) and the keyphasor: the
        // rotor's speed and its angle wrapped to [0, 2π), from the state.
        let (angle, speed) = model.spin(&y);
        let mut sample = RotorSample {
            seq: k,
            t_s: t0,
            axes: 2 * planes as u32,
            speed_rad_s: speed,
            angle_rad: wrap_angle(angle),
            ..Default::default()
        };
        // Every axis's sensor, in every mode: the continuous PD reads its signal inside the
        // derivative, but an excitation hook reads the sensor signal here too.
        for i in 0..planes {
            let gain = model.bearing(i).loop_constants.sensor_gain_v_per_m;
            let v = sensor.read_with_gain(model.sensed(&y, i), gain);
            sample.sensor_v[2 * i..2 * i + 2].copy_from_slice(&v);
        }
        // The summing point of a sensitivity measurement (one plane's axes): added to what a
        // law reads, handed to the plane's continuous PD, which reads it inside the derivative.
        let excitation = hooks.excitation(k, t0, &sample.sensor_v[..2 * planes]).filter(|e| e.plane < planes);
        if let Some(e) = excitation {
            let axes = &mut sample.sensor_v[2 * e.plane..2 * e.plane + 2];
            axes.iter_mut().zip(e.sine.at(t0).0).for_each(|(v, e)| *v += e);
        }
        if let Source::Continuous = &source {
            // The plane excited before goes back to its plain PD, the one excited now reads its sine.
            if let Some(i) = excited.filter(|i| excitation.is_none_or(|e| e.plane != *i)) {
                model.set_control(i, Control::Continuous(gains[i]));
            }
            if let Some(e) = excitation {
                model.set_control(e.plane, Control::ContinuousExcited(gains[e.plane], e.sine));
            }
            excited = excitation.map(|e| e.plane);
        }
        let command = match &mut source {
            Source::Continuous => None,
            Source::InProcess(law) => Some(saturate_axes(law.update(&sample), limits)),
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
                        Halt::OverrunBudget(why) => Outcome::OverrunBudget(why),
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
                            "warning: the controller's command for sample {} (t = {} s) is non-finite, {:?} A: \
                             the last valid command is held for it and for every later non-finite one, up to \
                             controller.max_invalid_burst = {} in a row (counted in summary.json, invalid_commands)",
                            sample.seq,
                            sample.t_s,
                            &cmd[..2 * planes],
                            c.max_invalid_burst
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
                for i in 0..planes {
                    model.set_control(i, Control::Held([applied[2 * i], applied[2 * i + 1]]));
                }
            }
        }
        // A realtime tick starts when the plant wakes at its wall-clock time.
        let tick_start = match &source {
            Source::Cosim(session) => session.tick_started().unwrap_or(tick_start),
            _ => tick_start,
        };
        let commanded = Instant::now();
        // Park or release each race; the fixed step is the contact one while any race is free.
        let mut changed = false;
        for i in 0..planes {
            if let RaceWhenClear::Parked(release) = model.bearing(i).race_when_clear {
                let clear = model.race_clear(t0, t1 - t0, &y, i);
                if clear && !model.parked(i) {
                    model.park_race(&mut y, i);
                    model.set_parked(i, true);
                    changed = true;
                } else if !clear && (model.parked(i) || k == 0) {
                    if model.parked(i) {
                        model.release_race(t0, &mut y, i, release);
                    }
                    model.set_parked(i, false);
                    changed = true;
                }
                parked_steps += u64::from(model.parked(i));
            }
        }
        if changed {
            let all_parked = (0..planes).all(|i| model.parked(i));
            integrator.set_substeps(if all_parked {
                scene.integrator.substeps
            } else {
                scene.integrator.contact_substeps
            });
        }
        out_times.clear();
        while (next_out as f64) * out_dt <= t1 + 1e-9 * out_dt {
            out_times.push(((next_out as f64) * out_dt).min(t1));
            next_out += 1;
        }
        let (evals, touching) = (integrator.stats().rhs_evals, cost.tet.is_some() && touching(&model, &y, planes));
        let mut rows = Duration::ZERO;
        let integrating = Instant::now();
        let step = advance_across_breakpoints(
            &mut integrator,
            &model,
            (t0, t1),
            &mut y,
            &out_times,
            (&breakpoints, &mut next_breakpoint),
            |ts, ys| match cost.tet {
                // The output rows' time is the sink's, not the integration's.
                Some(_) => {
                    let row = Instant::now();
                    feed(&model, sink, ts, ys);
                    rows += row.elapsed();
                }
                None => feed(&model, sink, ts, ys),
            },
        );
        cost.max_rhs_evals = cost.max_rhs_evals.max(integrator.stats().rhs_evals - evals);
        if let Some(tet) = cost.tet.as_mut() {
            let end = Instant::now();
            let ns = |d: Duration| d.as_nanos() as u64;
            tet.record(
                k,
                TickTime {
                    command_ns: ns(commanded - tick_start),
                    integration_ns: ns((end - integrating).saturating_sub(rows)),
                    tick_ns: ns(end - tick_start),
                    contact: touching || self::touching(&model, &y, planes),
                },
            );
        }
        t = t1;
        if let Err(e) = step.map_err(RunError::from).and_then(|()| guards.check(&model, t1, &y)) {
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
                } else if let Some(why) = session.overrun_budget_exceeded(1) {
                    outcome = Outcome::OverrunBudget(why);
                }
            }
            let mut report = session.finish(t, (t / period).round() as u64);
            report.tet_us = cost.tet.as_ref().map(|tet| tet.report());
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
        final_state: y.to_vec(),
        cosim,
        parked_steps,
        planes,
        ticks: cost,
        invalid_commands,
        voltage_saturation_s: model.voltage_saturation(&y),
    })
}

/// The rotor touches one of its races (the rotor – race contact force is not zero).
fn touching<const N: usize, M: Machine<N>>(model: &M, y: &[f64; N], planes: usize) -> bool {
    (0..planes).any(|i| model.touching(y, i))
}

/// Advances over `[t0, t1]`, ending a step at every breakpoint of the base motion inside it
/// (where the housing acceleration or its slope jumps): a step across such a kink has an
/// O(h²) local error whatever the method's order. `breakpoints` is sorted; `next` is the index
/// of the first one not yet passed. Samples at `times` go to `sample`.
fn advance_across_breakpoints<const N: usize, S: System<N>, F: FnMut(f64, &[f64; N])>(
    integrator: &mut Integrator<N>,
    model: &S,
    (t0, t1): (f64, f64),
    y: &mut [f64; N],
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

/// Radius limits beyond which the contact model has failed, per bearing plane.
struct Guards {
    /// (rotor, race) limits of each plane (m).
    limits: Vec<(f64, f64)>,
}

impl Guards {
    fn new<const N: usize, M: Machine<N>>(scene: &Scene, model: &M) -> Self {
        let g = scene.integrator.radius_guard;
        let limits = (0..M::PLANES)
            .map(|i| {
                let p = model.bearing(i);
                (p.contact.gap + p.balls.clearance + g, p.balls.clearance + g)
            })
            .collect();
        Self { limits }
    }

    fn check<const N: usize, M: Machine<N>>(&self, model: &M, t: f64, y: &[f64; N]) -> Result<(), RunError> {
        const NAMES: [[&str; 2]; 2] =
            [["rotor radius at bearing A", "race A radius"], ["rotor radius at bearing B", "race B radius"]];
        for (i, &(rotor_limit, race_limit)) in self.limits.iter().enumerate() {
            let (rotor, race) = model.radii(y, i);
            let [rotor_name, race_name] = if M::PLANES == 1 { ["rotor radius", "race radius"] } else { NAMES[i] };
            let fail = |what, value_m, limit_m| RunError::RadiusGuard { t, what, value_m, limit_m, state: y.to_vec() };
            if rotor > rotor_limit {
                return Err(fail(rotor_name, rotor, rotor_limit));
            }
            if race > race_limit {
                return Err(fail(race_name, race, race_limit));
            }
        }
        Ok(())
    }
}
