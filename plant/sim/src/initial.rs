//! The initial state of a scene: what the scene gives a model's start ([`start`]: its
//! `[initial]` table, the unbalance phase, the levitation design and the run's law at rest),
//! and each model's initial state from it ([`crate::machine::Builds::initial_state`], in the
//! model's file).

use crate::config::Scene;
use crate::machine::{Builds, LawAtRest, Start};
use crate::model::State;
pub use plant_physics::initial::{race_sag, unbalance_amplitude, InitialConditions};

/// The initial conditions a scene gives: its `[initial]` table, the unbalance phase and the
/// levitation design.
pub fn initial_conditions(scene: &Scene) -> InitialConditions {
    InitialConditions {
        unbalance_orbit: scene.initial.unbalance_orbit,
        unbalance_phase: scene.initial.unbalance_phase,
        stiffness: scene.controller.stiffness,
        damping_ratio: scene.controller.damping_ratio,
        gravity_bias: scene.controller.gravity_bias,
        rotor_offset: scene.initial.rotor_offset,
    }
}

/// The run's law at rest of `scene` ([`crate::rest_law`]).
pub fn law_at_rest(scene: &Scene) -> LawAtRest {
    LawAtRest { static_gains: crate::rest_law::static_gains(scene), holds_weight: crate::rest_law::holds_weight(scene) }
}

/// What `scene` gives a model's start, handed to `with` (the law at rest is built only if the
/// model asks for it).
pub fn start<T>(scene: &Scene, with: impl FnOnce(&Start<'_>) -> T) -> T {
    let law = || law_at_rest(scene);
    with(&Start { conditions: initial_conditions(scene), slope_offset: scene.initial.slope_offset, law_at_rest: &law })
}

/// The initial state of a two-plane scene whose rotor is `machine`.
pub fn two_plane_initial_state(
    scene: &Scene,
    machine: &plant_physics::two_plane::Params,
) -> plant_physics::two_plane::State {
    start(scene, |s| machine.initial_state(s))
}

/// The initial state of a planar scene whose bearing is `params`.
pub fn initial_state(scene: &Scene, params: &crate::model::Params) -> State {
    start(scene, |s| params.initial_state(s))
}

/// The initial state of a flexible scene whose machine is `params`: at rest on its bearings,
/// the rigid rotor's start on top ([`Builds::initial_state`] of its parameters).
pub fn flexible_initial_state(
    scene: &Scene,
    params: &plant_physics::flex::machine::Params,
) -> plant_physics::flex::machine::State {
    start(scene, |s| params.initial_state(s))
}
