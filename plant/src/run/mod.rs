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

pub mod digital;
pub mod stepper;

use crate::config::{ControlMode, Scene};
use crate::cosim::stats::Tet;
use crate::cosim::{CosimError, CosimReport, Launch, Session};
use crate::digital::{DigitalLoop, Source};
pub use crate::hooks::{Hooks, Quiet};
use crate::integrate::{IntegrationError, Settings, Stats};
use crate::snapshot::{DigitalState, Snapshot, SnapshotError};
use crate::stepper::{Command, Plant};
use crate::trace::{Record, Trace};
use controller::{build_rotor_law, saturate, PdGains, RotorLaw, ROTOR_AXES};
use std::time::Instant;

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
    /// The state to start from does not fit the scene, or could not be read.
    #[error("the state to start from: {0}")]
    State(#[from] SnapshotError),
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

    /// The same sample's bearing planes, after [`Sink::sample`], for a sink that needs what a
    /// row does not hold (the race's angle and acceleration, each ball's load: the
    /// assessment's touchdown-bearing duty): `planes` hands each plane's
    /// [`crate::machine::PlaneState`] to a visitor, computed only if the sink asks. The default
    /// ignores it.
    fn planes(&mut self, _planes: &dyn PlaneStates) {}
}

/// The bearing planes of one output sample, as the rotor model gives them
/// ([`crate::machine::Machine::plane_states`]).
pub trait PlaneStates {
    /// The sample's time (s).
    fn time(&self) -> f64;

    /// Hands each plane's state to `visit`, with the plane's index.
    fn visit(&self, visit: &mut dyn FnMut(usize, &crate::machine::PlaneState<'_>));
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

/// Continuous PD gains of each bearing plane's design (one for the planar model), the gravity
/// bias in the plane's own axes: `m g / k_i` along y, `(m g / k_i)(sin θ, cos θ)` along (u, v)
/// on axes turned by θ (docs/MODEL.md §3.3), so that the coil pairs share the weight.
pub fn plane_gains(scene: &Scene) -> Result<Vec<PdGains>, controller::LawError> {
    let planes = scene.plane_designs();
    let gains = planes.iter().map(|d| PdGains::from_design(&d.pd(), &d.constants));
    gains
        .enumerate()
        .map(|(i, g)| g.map(|g| PdGains { bias_a: scene.plane(i).axes.pair_to_plane(g.bias_a), ..g }))
        .collect()
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
    /// Where the run started (s): 0, or a saved state's time (`plant run --from-state`).
    pub started: f64,
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

impl SinkRun {
    /// The simulated time this run covered (s): from its start (0, or a saved state's time) to
    /// where it ended.
    pub fn span(&self) -> f64 {
        self.simulated - self.started
    }
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
    run_into_from(scene, launch, hooks, sink, None)
}

/// [`run_into`] from the state `from` if given (`plant run --from-state`): the plant continues
/// from it ([`Plant::restore`]), under this scene's controller and shock programme, and `sink`
/// gets the rows after the snapshot's time.
pub fn run_into_from(
    scene: &Scene,
    launch: &Launch,
    hooks: &mut dyn Hooks,
    sink: &mut dyn Sink,
    from: Option<&Snapshot>,
) -> Result<SinkRun, SetupError> {
    if let Some(snapshot) = from {
        // Refused before a controller process starts.
        check_start(scene, snapshot)?;
    }
    let params = &scene.controller.params;
    let source = match scene.controller.mode {
        ControlMode::Continuous => Source::Continuous,
        ControlMode::Sampled => Source::InProcess(match crate::config::fmu::spec_of(scene) {
            // A controller FMU runs in the plant's process in sampled mode (docs/guide/fmu-controller.md).
            Some(fmu) => controller_fmu::build(&fmu, &scene.rotor_design(), params)?,
            None => build_rotor_law(&scene.controller.law, &scene.rotor_design(), params)?,
        }),
        ControlMode::Lockstep | ControlMode::Realtime => {
            // A design the controller would refuse is bad input here, before any process starts
            // (a controller command checks the laws it serves itself, in the handshake).
            if scene.controller.cosim.command.is_none() {
                build_rotor_law(&scene.controller.law, &scene.rotor_design(), params)?;
            }
            Source::Cosim(Box::new(Session::connect(scene, launch, bias_of(scene, &plane_gains(scene)?), hooks)?))
        }
    };
    run_from(scene, source, hooks, sink, from)
}

/// Whether `scene`'s plant can start from `snapshot` ([`Plant::restore`] into a fresh one): the
/// check made before anything starts or is written.
///
/// In order: the format and the scene's fingerprint (another scene named as such), the seal
/// recomputed from this scene and the snapshot's fields ([`Snapshot::check_seal`]), then each
/// field against the scene and the physics (the plant's restore, the digital loop's part here).
pub fn check_start(scene: &Scene, snapshot: &Snapshot) -> Result<(), SetupError> {
    let mut plant = Plant::new(scene, &Command::Continuous(None))?;
    snapshot.check_against(plant.fingerprint())?;
    snapshot.check_seal(plant.fingerprint())?;
    check_digital(scene, snapshot)?;
    plant.restore(snapshot)?;
    Ok(())
}

/// The digital loop's part of `snapshot` against `scene`: commands within the amplifiers'
/// limits (they are saturated before they enter the delay line), and the samples the law read
/// last those of the ticks before the snapshot's, in order, on the controller's grid.
fn check_digital(scene: &Scene, snapshot: &Snapshot) -> Result<(), SnapshotError> {
    let Some(d) = &snapshot.digital else { return Ok(()) };
    let limits = scene.rotor_design().current_limits();
    for (k, c) in d.in_flight.iter().enumerate() {
        for (a, (&i, &limit)) in c.iter().zip(&limits).enumerate() {
            if i.is_nan() || i.abs() > limit {
                return Err(SnapshotError::field(
                    format!("digital.in_flight[{k}][{a}]"),
                    format!("{i} A"),
                    format!("within the amplifier's current limit, ±{limit} A"),
                ));
            }
        }
    }
    if d.recent.len() > crate::digital::RECENT {
        return Err(SnapshotError::field(
            "digital.recent",
            format!("{} samples", d.recent.len()),
            format!("at most {}", crate::digital::RECENT),
        ));
    }
    let period = scene.controller.period;
    let n = d.recent.len() as u64;
    let planes = scene.rotor_design().planes().len() as u32;
    for (k, r) in d.recent.iter().enumerate() {
        let field = |name: &str| format!("digital.recent[{k}].{name}");
        // The last sample read is that of the tick before the snapshot's.
        let seq = (snapshot.tick + k as u64).checked_sub(n);
        if Some(r.seq) != seq {
            return Err(SnapshotError::field(
                field("seq"),
                r.seq,
                format!("the ticks before the snapshot's tick {} in order, here {seq:?}", snapshot.tick),
            ));
        }
        if (r.t_s - r.seq as f64 * period).abs() > 1e-9 * period.max(r.t_s.abs()) {
            return Err(SnapshotError::field(
                field("t_s"),
                format!("{} s", r.t_s),
                format!("tick {} of {period} s", r.seq),
            ));
        }
        if r.axes != 2 * planes {
            return Err(SnapshotError::field(field("axes"), r.axes, format!("{} ({planes} planes)", 2 * planes)));
        }
        if !(0.0..std::f64::consts::TAU).contains(&r.angle_rad) {
            return Err(SnapshotError::field(
                field("angle_rad"),
                format!("{} rad", r.angle_rad),
                "the keyphasor's angle in [0, 2π)",
            ));
        }
    }
    Ok(())
}

/// The bias currents per axis (A) of each plane's design `gains`, each within its plane's
/// limit (unused axes 0).
pub fn bias_of(scene: &Scene, gains: &[PdGains]) -> [f64; ROTOR_AXES] {
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
    run_from(scene, Source::InProcess(law), hooks, sink, None)
}

/// The loop, from a command source, from the scene's initial state or `from`.
fn run_from(
    scene: &Scene,
    mut source: Source,
    hooks: &mut dyn Hooks,
    sink: &mut dyn Sink,
    from: Option<&Snapshot>,
) -> Result<SinkRun, SetupError> {
    // An external controller may run a design of its own (its `--config` or `--law`): the run
    // is then the scene with those overrides, initial state and bias included, so that the
    // scene it records reproduces it.
    let effective = match &source {
        Source::Cosim(session) => session.overrides().map(|o| scene.with_controller_overrides(o)).transpose()?,
        _ => None,
    };
    let scene = effective.as_ref().unwrap_or(scene);
    let bias = bias_of(scene, &plane_gains(scene)?);
    let limits = scene.rotor_design().current_limits();
    if let (Source::Cosim(session), Some(_)) = (&mut source, &effective) {
        session.adopt(bias, limits);
    }
    let initial = match source {
        Source::Continuous => Command::Continuous(None),
        _ => Command::Held(bias),
    };
    let mut plant = Plant::new(scene, &initial)?;
    let mut digital = DigitalLoop::new(scene, source, bias, limits);
    let mut primed = Ok(());
    if let Some(snapshot) = from {
        plant.restore(snapshot)?;
        if let Some(d) = &snapshot.digital {
            digital.path_mut().set_in_flight(&d.in_flight);
            primed = digital.prime(&d.recent, hooks);
        }
    }
    if digital.is_cosim() || hooks.time_ticks() {
        plant.time_ticks();
    }
    Ok(drive(scene, &mut plant, digital, hooks, sink, (from.is_some(), primed)))
}

/// The macro-step loop (module doc): the digital loop makes each tick's command from what the
/// plant read, the plant steps. A restored plant (`resumed`) does not write its first row
/// again: the run it continues wrote it.
fn drive(
    scene: &Scene,
    plant: &mut Plant,
    mut digital: DigitalLoop,
    hooks: &mut dyn Hooks,
    sink: &mut dyn Sink,
    (resumed, primed): (bool, Result<(), Outcome>),
) -> SinkRun {
    if !resumed {
        plant.record(sink);
    }
    if let Some(pid) = digital.controller_pid() {
        hooks.controller_connected(pid);
    }
    let saves = hooks.save_state_at().to_vec();
    let mut next_save = saves.partition_point(|t| *t < plant.time() - 1e-9 * scene.controller.period);
    let started = plant.time();
    let start = Instant::now();
    let mut outcome = primed.err().unwrap_or(Outcome::Completed);
    while outcome == Outcome::Completed && !plant.finished() {
        let tick_start = Instant::now();
        let command = match digital.command(plant.sample(), hooks) {
            Ok(command) => command,
            Err(ended) => {
                outcome = ended;
                break;
            }
        };
        // A realtime tick starts when the plant wakes at its wall-clock time.
        let tick_start = digital.tick_started().unwrap_or(tick_start);
        if let Err(e) = plant.step_from(&command, sink, tick_start) {
            outcome = Outcome::Diverged(e);
            break;
        }
        let t = plant.time();
        while next_save < saves.len() && saves[next_save] <= t + 1e-9 * scene.controller.period {
            let mut snapshot = plant.snapshot();
            snapshot.digital = Some(DigitalState { in_flight: digital.path().in_flight(), recent: digital.recent() });
            snapshot.seal();
            hooks.state_saved(saves[next_save], snapshot);
            next_save += 1;
        }
        hooks.progress(t);
        if hooks.cancelled() {
            outcome = Outcome::Interrupted;
            break;
        }
        if hooks.finished() {
            break;
        }
    }
    let wall_time = start.elapsed().as_secs_f64();
    let t = plant.time();
    let ticks = plant.take_cost();
    let (outcome, mut cosim, invalid_commands) = digital.finish(outcome, t, scene.controller.period);
    if let Some(report) = cosim.as_mut() {
        report.tet_us = ticks.tet.as_ref().map(|tet| tet.report());
    }
    SinkRun {
        stats: plant.stats(),
        simulated: t,
        started,
        wall_time,
        outcome,
        final_state: plant.state().to_vec(),
        cosim,
        parked_steps: plant.parked_steps(),
        planes: plant.planes(),
        ticks,
        invalid_commands,
        voltage_saturation_s: plant.voltage_saturation(),
    }
}
