//! The initial state of a scene: [`plant_physics::initial`] with the conditions the scene gives.

use crate::config::Scene;
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

/// The initial state of a two-plane scene whose rotor is `machine`.
pub fn two_plane_initial_state(
    scene: &Scene,
    machine: &plant_physics::two_plane::Params,
) -> plant_physics::two_plane::State {
    let ic = initial_conditions(scene);
    plant_physics::two_plane::initial::initial_state(
        machine,
        &plant_physics::two_plane::initial::InitialConditions {
            unbalance_orbit: ic.unbalance_orbit,
            unbalance_phase: ic.unbalance_phase,
            stiffness: ic.stiffness,
            damping_ratio: ic.damping_ratio,
            gravity_bias: ic.gravity_bias,
            rotor_offset: ic.rotor_offset,
            slope_offset: scene.initial.slope_offset,
        },
    )
}

/// The initial state of a planar scene whose bearing is `params`.
pub fn initial_state(scene: &Scene, params: &crate::model::Params) -> State {
    plant_physics::initial::initial_state(params, &initial_conditions(scene))
}
