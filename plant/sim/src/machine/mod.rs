//! The rotor models the run loop steps, behind one trait: the planar model (one bearing plane,
//! the study's, [`planar`]), the two-plane rotor (two bearing planes, tilt, [`two_plane`]) and
//! the flexible rotor (a reduced finite-element shaft on two bearing planes, [`flexible`]).
//! The loop ([`crate::run`]) is generic over it, so that the planar model runs the very code it
//! ran before the second plane existed: its `trace.csv` is unchanged byte for byte.
//!
//! This is the model's side of the rotor seam (the scene's is [`crate::config::Rotor`]): what
//! differs between rotor models (its tolerances, what it senses, parks and records, each
//! plane's state for the touchdown bearing's duty, its failing state) is answered here, one
//! file per model.

mod flexible;
pub mod mechanics;
mod planar;
mod two_plane;

pub use flexible::{mid_span, mid_span_weight, FlexibleFailure, FlexibleLinear};
pub use mechanics::{Mechanics, Signal};
pub use planar::PlanarFailure;
pub use two_plane::{RaceFailure, TwoPlaneFailure};

use crate::model::{Control, Params, Release};
use crate::rows::Record;
use controller::{saturate, PdGains};
use nalgebra::Vector2;
use plant_physics::initial::InitialConditions;
use plant_physics::integrate::System;
use serde::Serialize;
use shock_table::Programme;

/// How far [`Machine::contact_state`] presses the rotor into each race (m): about a kilonewton of
/// contact on the study's bearing.
pub const CONTACT_DEPTH: f64 = 2e-6;

/// A whirl mode of a rotor linearised on its continuous PD ([`Linearised`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WhirlMode {
    /// Cylindrical, conical, or the n-th bending mode.
    pub kind: plant_physics::flex::linear::ModeKind,
    /// Forward, backward (or mixed: nodes whirling each way).
    pub whirl: plant_physics::flex::Whirl,
    /// Damped natural frequency (Hz).
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping_ratio: f64,
}

/// A rotor linearised about the centred, levitated rotor on the continuous PD of each plane:
/// what `plant campbell` draws (the model's side of [`crate::config::Rotor::linearised`]).
pub trait Linearised {
    /// The whirl modes at spin speed `speed` (rad/s), ascending in frequency: the rigid rotor's
    /// four, and a flexible rotor's bending modes below its cutoff beside them.
    fn whirl_modes(&self, speed: f64) -> Result<Vec<WhirlMode>, WhirlError>;
}

/// Why a linearised rotor's whirl modes could not be computed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum WhirlError {
    /// The two-plane rotor's eigenvalues.
    #[error("{0}")]
    TwoPlane(#[from] plant_physics::two_plane::linear::ModesError),
    /// The flexible rotor's eigenvalues.
    #[error("{0}")]
    Flexible(#[from] plant_physics::flex::modes::ModesError),
}

/// One bearing plane's state at an output time, for a sink that needs what a row does not hold
/// (the race's angle and acceleration, each ball's load: the touchdown bearing's duty).
#[derive(Clone, Copy, Debug)]
pub struct PlaneState<'p> {
    /// The plane's bearing parameters.
    pub params: &'p Params,
    /// Normal rotor – race contact force magnitude (N).
    pub normal: f64,
    /// Tangential (friction) rotor – race contact force (N).
    pub tangential: f64,
    /// The rotor at the plane's bearing: position and velocity relative to the housing.
    pub rotor: (Vector2<f64>, Vector2<f64>),
    /// The race: position and velocity relative to the housing.
    pub race: (Vector2<f64>, Vector2<f64>),
    /// Rotor spin speed (rad/s).
    pub rotor_speed: f64,
    /// Race angle (rad).
    pub race_angle: f64,
    /// Race speed (rad/s).
    pub race_speed: f64,
    /// Race angular acceleration (rad/s²).
    pub race_accel: f64,
}

/// A rotor model's failing state, as [`Machine::failure`] gives it for the model that `P` (its
/// parameters, on `N` states) builds: `failure_state` in `summary.json`
/// ([`crate::config::FailureState`] holds one of each model's, from the list of models).
pub type FailureOf<P, const N: usize> = <<P as Builds<N>>::Machine as Machine<N>>::Failure;

/// What a model's initial state is built from besides its parameters: the scene's `[initial]`
/// table and the levitation design ([`crate::initial::start`] reads them from a scene).
pub struct Start<'a> {
    /// The conditions of the planar model's start (each plane's of the two-plane rotor's).
    pub conditions: InitialConditions,
    /// Offset added to the slopes (rad), x then y: a rotor that tilts.
    pub slope_offset: [f64; 2],
    /// The run's law at rest ([`crate::rest_law`]), asked only by a model whose rest depends on
    /// it (the flexible rotor's sag): building the law is left to the model that needs it.
    pub law_at_rest: &'a dyn Fn() -> LawAtRest,
}

/// The run's law at rest, as a model's start asks of it ([`crate::rest_law`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LawAtRest {
    /// Each plane's static gain where it is not the design's `k_p` ([`crate::rest_law::static_gains`]).
    pub static_gains: [Option<f64>; 2],
    /// Whether every plane's law holds its weight from the start ([`crate::rest_law::holds_weight`]).
    pub holds_weight: bool,
}

/// A rotor model's parameters, as the run loop builds the model from them: one implementation
/// per model on `N` states, in the model's file (the list of models, `config::models`, names
/// each model's parameters and `N`; `stepper::with_machine` builds through this).
pub trait Builds<const N: usize> {
    /// The model the run loop steps.
    type Machine: Machine<N> + Clone + 'static;

    /// The model with the housing's motion `base` and `controls` (one per plane; a model of one
    /// plane takes the first), each race free.
    fn machine(&self, base: &Programme, controls: [Control; 2]) -> Self::Machine;

    /// The model's initial state: levitated on the unbalance orbit, each race at rest.
    fn initial_state(&self, start: &Start<'_>) -> [f64; N];
}

/// A rotor model on a state of `N` numbers with one or two bearing planes, each with its AMB,
/// sensor and touchdown bearing.
pub trait Machine<const N: usize>: System<N> {
    /// Bearing planes: 1 (planar) or 2.
    const PLANES: usize;

    /// Plane `i`'s bearing: its touchdown bearing, AMB and loop constants (a planar model's
    /// parameters; for the two-plane rotor, those of the plane's share).
    fn bearing(&self, i: usize) -> &Params;

    /// Sets plane `i`'s control for the coming macro step.
    fn set_control(&mut self, i: usize, control: Control);

    /// The rotor's displacement at plane `i`'s sensor, relative to the housing (m), along the
    /// plane's own axes (u, v): x then y unless the plane's axes are turned
    /// ([`plant_physics::axes`]). What the sensor reads, the wire carries and the law sees.
    fn sensed(&self, y: &[f64; N], i: usize) -> [f64; 2];

    /// Whether plane `i`'s race is parked.
    fn parked(&self, i: usize) -> bool;

    /// Parks (`true`) or frees plane `i`'s race for the coming macro step.
    fn set_parked(&mut self, i: usize, parked: bool);

    /// Whether the rotor stays clear of plane `i`'s race over `[t0, t0 + h]` ([`crate::park`]).
    fn race_clear(&self, t0: f64, h: f64, y: &[f64; N], i: usize) -> bool;

    /// Holds plane `i`'s race in the housing frame (its velocity set to zero).
    fn park_race(&self, y: &mut [f64; N], i: usize);

    /// Releases plane `i`'s race at time `t` as `release` says.
    fn release_race(&self, t: f64, y: &mut [f64; N], i: usize, release: Release);

    /// Plane `i`'s radii relative to the housing (m): the rotor at the bearing, and the race.
    fn radii(&self, y: &[f64; N], i: usize) -> (f64, f64);

    /// The rotor's spin angle (rad, unwrapped) and speed (rad/s) in state `y`: the keyphasor.
    fn spin(&self, y: &[f64; N]) -> (f64, f64);

    /// Whether the rotor touches plane `i`'s race (their distance exceeds the gap).
    fn touching(&self, y: &[f64; N], i: usize) -> bool;

    /// The output sample of state `y` at time `t`.
    fn record(&self, t: f64, y: &[f64; N]) -> Record;

    /// The state `levitated` (the model's initial state) with the rotor pressed [`CONTACT_DEPTH`]
    /// into each bearing plane's race, straight down and centred on the race in x, everything
    /// else as it was: the tick in contact that `plant bench tick` repeats ([`crate::bench`]).
    fn contact_state(&self, levitated: &[f64; N]) -> [f64; N];

    /// Each bearing plane's state at time `t` in state `y` ([`PlaneState`]), handed to `visit`
    /// with the plane's index: what the touchdown bearing's duty reads
    /// ([`crate::run::Sink::planes`]).
    fn plane_states(&self, t: f64, y: &[f64; N], visit: &mut dyn FnMut(usize, &PlaneState<'_>));

    /// Absolute tolerances per state component, laid out from those of positions (m),
    /// velocities (m/s), angles (rad) and angular speeds (rad/s).
    fn atol(groups: [f64; 4]) -> [f64; N]
    where
        Self: Sized;

    /// The state components this model uses, counted by the integrator's RMS error norm
    /// ([`crate::integrate::Settings::rms_count`]): all N, unless the state has slots the
    /// model leaves at zero (the flexible rotor's reduced coordinates past its basis).
    fn used_components(&self) -> usize {
        N
    }

    /// The model's failing state (`failure_state` in `summary.json`); non-finite values are
    /// written as `null`.
    type Failure: Clone + std::fmt::Debug + PartialEq + Serialize;

    /// The failing state of a run stopped at time `t` in state `y` (`failure_state` in
    /// `summary.json`).
    fn failure(t: f64, y: &[f64; N]) -> Self::Failure
    where
        Self: Sized;

    /// The rate of [`Machine::sensed`] (m/s): the rotor's velocity at plane `i`'s sensor (through
    /// a sensor's front end, the rate of what it reads, [`crate::hardware`]).
    fn sensed_rate(&self, y: &[f64; N], i: usize) -> [f64; 2];

    /// Plane `i`'s continuous PD current in state `y` (A): the PD on what the plane's sensor
    /// reads ([`Machine::sensed`]) and its rate, saturated at the plane's limit. For the bare
    /// models, what their `Control::Continuous(gains)` applies.
    fn pd_current(&self, gains: &PdGains, y: &[f64; N], i: usize) -> [f64; 2] {
        let p = self.bearing(i);
        let a_s = p.loop_constants.sensor_gain_v_per_m;
        let (d, v) = (self.sensed(y, i), self.sensed_rate(y, i));
        saturate(gains.current([d[0] * a_s, d[1] * a_s], [v[0] * a_s, v[1] * a_s]), p.current_limit)
    }

    /// The rotor's velocity at plane `i`'s bearing, relative to the housing (m/s), along the
    /// plane's own axes (its coils' motional voltages).
    fn bearing_velocity(&self, y: &[f64; N], i: usize) -> [f64; 2];

    /// Time spent with an amplifier at its voltage limit (s), for a model with amplifiers
    /// ([`crate::hardware`]).
    fn voltage_saturation(&self, _y: &[f64; N]) -> Option<f64> {
        None
    }
}
