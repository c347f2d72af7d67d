//! What each rotor model says of itself: the [`RotorParams`] trait, one implementation per
//! model, each in its file (`planar.rs`, `two_plane.rs`, `flexible.rs`). [`super::Rotor`]
//! dispatches to it once ([`super::Rotor::params`]); a capability one model has and the others
//! do not (bending, a linear open loop, whirl modes) is a method with a default, so a new model
//! says only what it has.

pub(in crate::config) mod flexible;
mod planar;
mod two_plane;

use super::raw::RawScene;
use super::RotorModel;
use crate::machine::{FailureState, Linearised};
use crate::model::Params;
use plant_physics::flex::linear::OpenLoop;
use plant_physics::flex::ross::UsedBearing;
use plant_physics::flex::ross_amb::UsedAmb;
use plant_physics::two_plane as rigid;

/// A rotor model's parameters, as the scene and the rest of the plant ask of them.
pub trait RotorParams {
    /// The model's name as `rotor.model` writes it.
    fn model(&self) -> RotorModel;

    /// Bearing planes: each with its AMB, sensor and touchdown bearing.
    fn planes(&self) -> usize;

    /// Plane `i`'s bearing: its touchdown bearing, AMB, loop constants and its share of the
    /// rotor (the planar model's whole parameters). Panics if `i` is not a plane.
    fn plane(&self, i: usize) -> &Params;

    /// Plane `i`'s bearing, mutable (a sweep or a test that moves one plane's value).
    fn plane_mut(&mut self, i: usize) -> &mut Params;

    /// Absolute tolerances per state component of the model, laid out from those of positions
    /// (m), velocities (m/s), angles (rad) and angular speeds (rad/s)
    /// ([`crate::machine::Machine::atol`]).
    fn atol(&self, groups: [f64; 4]) -> Vec<f64>;

    /// The failing state of a run that stopped at time `t` in state `y` (the model's part of
    /// the state first); `None` if `y` holds less than the model's state.
    fn failure(&self, t: f64, y: &[f64]) -> Option<FailureState>;

    /// Writes the model's defaults into the raw scene it was built from (as the user would have
    /// written them, in the file's units), so that the resolved `scene.toml` states them. The
    /// default: the model has none beyond the scene table's own.
    fn record_defaults(&self, _raw: &mut RawScene) {}

    /// The rigid rotor on two bearing planes that the model is, or whose rigid body it bends
    /// about (the flexible rotor's: mass, inertias and unbalance from its elements, its planes
    /// at the nodes' stations); `None` for a model with one plane and no tilt.
    fn rigid_body(&self) -> Option<&rigid::Params> {
        None
    }

    /// The first plane whose sensor is not at its bearing; `None` when collocated.
    fn non_collocated_plane(&self) -> Option<usize> {
        None
    }

    /// A bending rotor's mid-span node's place between its touchdown nodes, 0 at A's and 1 at
    /// B's (its trace's `mid_dx_m`, `mid_dy_m`); `None` for a rotor that does not bend.
    fn mid_span_weight(&self) -> Option<f64> {
        None
    }

    /// The rotor linearised about the centre on the continuous PD `gains` of each plane, for its
    /// whirl modes (`plant campbell`); `None` for a model with no whirl modes to tell apart.
    fn linearised(&self, _gains: &[controller::PdGains]) -> Option<Box<dyn Linearised>> {
        None
    }

    /// A machine file's plain bearings and what became of each (a ROSS file's, `summary.json`'s
    /// `ross_bearings`); none by default.
    fn file_bearings(&self) -> &[UsedBearing] {
        &[]
    }

    /// A machine file's AMB elements made the planes' AMBs (`summary.json`'s `ross_ambs`); none
    /// by default.
    fn file_ambs(&self) -> &[UsedAmb] {
        &[]
    }

    /// The open loop from the AMB currents to the sensor displacements of all axes, where the
    /// closed form of `plant assess` needs it whole; `None` where the closed forms of
    /// `assess::closed_form` serve.
    fn open_loop(&self) -> Option<OpenLoop> {
        None
    }
}
