//! The contract of a run, whoever drives it (the CLI's loop, the FMU, a test): how it ends
//! ([`Outcome`], [`RunError`]), where its samples go ([`Sink`], [`PlaneStates`]), what its ticks
//! cost ([`TickCost`]), and the designs' gains and bias.

use crate::config::Scene;
use crate::integrate::{IntegrationError, Settings};
use crate::rows::Record;
use crate::snapshot::SnapshotError;
use crate::tick_time::Tet;
use controller::{saturate, PdDesign, PdGains, RotorSample, ROTOR_AXES};

/// Why a plant could not be built, or started from a saved state.
#[derive(Debug, thiserror::Error)]
pub enum PlantError {
    /// The controller design is invalid.
    #[error("{0}")]
    Law(#[from] controller::LawError),
    /// The state to start from does not fit the scene, or could not be read.
    #[error("the state to start from: {0}")]
    State(#[from] SnapshotError),
}

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

    /// One controller tick of a sampled or co-simulated loop, before the tick's rows: the
    /// sample the law read and the command (A, the wire's axis order) applied over the tick.
    /// Called only if [`Sink::wants_ticks`]; the default ignores it.
    fn tick(&mut self, _sample: &RotorSample, _command: &[f64; ROTOR_AXES]) {}

    /// Whether the sink takes [`Sink::tick`] (the recordings of issue 42); false by default,
    /// so that a run's loop hands ticks to no one who does not ask.
    fn wants_ticks(&self) -> bool {
        false
    }
}

/// Every row kept in memory, in order: the simplest sink (an FMU's outputs or the CLI's
/// `Trace` keep less or more).
impl Sink for Vec<Record> {
    fn sample(&mut self, record: &Record) {
        self.push(*record);
    }
}

/// The bearing planes of one output sample, as the rotor model gives them
/// ([`crate::machine::Machine::plane_states`]).
pub trait PlaneStates {
    /// The sample's time (s).
    fn time(&self) -> f64;

    /// Hands each plane's state to `visit`, with the plane's index.
    fn visit(&self, visit: &mut dyn FnMut(usize, &crate::machine::PlaneState<'_>));
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

/// What the ticks of a run cost.
#[derive(Clone, Debug, Default)]
pub struct TickCost {
    /// The most evaluations of the model the integrator made in one tick.
    pub max_rhs_evals: u64,
    /// The plant's execution time per tick (co-simulation runs, or [`Hooks::time_ticks`]).
    pub tet: Option<Box<Tet>>,
}

/// The bias currents per axis (A) of each plane's design `gains`, each within its plane's
/// limit (unused axes 0).
///
/// A law that holds the weight itself from the start without the gravity bias
/// ([`crate::rest_law::holds_weight`]: `ross_pid`'s preloaded integral) answers its first sample
/// with the weight's current: so do the commands before its first answer (the command delay's),
/// or the rotor would drop for those ticks.
pub fn bias_of(scene: &Scene, gains: &[PdGains]) -> [f64; ROTOR_AXES] {
    let held: Vec<Option<PdGains>> = if !scene.controller.gravity_bias && crate::rest_law::holds_weight(scene) {
        let with_bias = |d: &controller::Design| PdDesign { gravity_bias: true, ..d.pd() };
        scene.plane_designs().iter().map(|d| PdGains::from_design(&with_bias(d), &d.constants).ok()).collect()
    } else {
        Vec::new()
    };
    let mut bias = [0.0; ROTOR_AXES];
    for (i, g) in gains.iter().enumerate() {
        let own = held.get(i).copied().flatten().map_or(g.bias_a, |w| scene.plane(i).axes.pair_to_plane(w.bias_a));
        let b = saturate(own, scene.plane(i).current_limit);
        bias[2 * i..2 * i + 2].copy_from_slice(&b);
    }
    bias
}
