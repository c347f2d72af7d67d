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

pub mod cosim;
pub mod jobs;
pub mod offload;

pub use plant_sim::run::{bias_of, plane_gains, settings_with, Outcome, PlaneStates, RunError, Sink, TickCost};
pub use plant_sim::{digital, stepper};

use crate::config::{ControlMode, Scene};
use crate::cosim::{CosimError, CosimReport, Launch, Session};
use crate::digital::{DigitalLoop, Source};
pub use crate::hooks::{Hooks, Quiet};
use crate::integrate::Stats;
use crate::snapshot::{DigitalState, Snapshot, SnapshotError};
use crate::stepper::{Command, Plant};
use crate::trace::{Record, Trace};
use controller::{build_rotor_law, RotorLaw};
use plant_sim::run::PlantError;
use std::time::Instant;

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

impl From<PlantError> for SetupError {
    fn from(e: PlantError) -> Self {
        match e {
            PlantError::Law(e) => SetupError::Law(e),
            PlantError::State(e) => SetupError::State(e),
        }
    }
}

/// Whether `scene`'s plant can start from `snapshot` ([`plant_sim::start::check_start`]), before
/// anything starts or is written.
pub fn check_start(scene: &Scene, snapshot: &Snapshot) -> Result<(), SetupError> {
    Ok(plant_sim::start::check_start(scene, snapshot)?)
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
    /// Where it started and ended in simulated time, and how long it took.
    pub clock: RunClock,
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

/// A run's clock: simulated time at its start and end, and the wall time of its loop.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RunClock {
    /// Simulated time reached (s).
    pub simulated: f64,
    /// Where the run started (s): 0, or a saved state's time (`plant run --from-state`).
    pub started: f64,
    /// Wall time of the loop (s).
    pub wall_time: f64,
}

impl SinkRun {
    /// The simulated time this run covered (s): from its start (0, or a saved state's time) to
    /// where it ended.
    pub fn span(&self) -> f64 {
        self.clock.simulated - self.clock.started
    }
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
    mut source: Source<Session>,
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
    mut digital: DigitalLoop<Session>,
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
    let ticks = sink.wants_ticks();
    while outcome == Outcome::Completed && !plant.finished() {
        let tick_start = Instant::now();
        let command = match digital.command(plant.sample(), hooks) {
            Ok(command) => command,
            Err(ended) => {
                outcome = ended;
                break;
            }
        };
        if ticks {
            if let Command::Held(applied) = &command {
                sink.tick(plant.sample(), applied);
            }
        }
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
        clock: RunClock { simulated: t, started, wall_time },
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

#[cfg(test)]
mod tests;
