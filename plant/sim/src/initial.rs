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

/// The initial state of a flexible scene whose machine is `params`: at rest on its bearings
/// (the shaft sagged under gravity, the bias currents and the levitation design's loop, or the
/// run's law where it has a static gain: [`plant_physics::flex::initial::static_sag_with`]), with the two-plane rotor's unbalance orbit
/// and the scene's `[initial]` offsets as a rigid motion of the shaft on top of it.
pub fn flexible_initial_state(
    scene: &Scene,
    params: &plant_physics::flex::machine::Params,
) -> plant_physics::flex::machine::State {
    use plant_physics::flex::machine::Model;
    // The rigid rotor's start without its sag under gravity (the shaft's own is solved for
    // below, with or without the gravity bias): its unbalance orbit, offsets and races.
    let ic = initial_conditions(scene);
    let rigid = plant_physics::two_plane::initial::initial_state(
        &params.machine,
        &plant_physics::two_plane::initial::InitialConditions {
            unbalance_orbit: ic.unbalance_orbit,
            unbalance_phase: ic.unbalance_phase,
            stiffness: ic.stiffness,
            damping_ratio: ic.damping_ratio,
            gravity_bias: true,
            rotor_offset: ic.rotor_offset,
            slope_offset: scene.initial.slope_offset,
        },
    );
    let mut y = Model::from_rigid(params, &rigid);
    let design = controller::PdDesign {
        stiffness_n_per_m: scene.controller.stiffness,
        damping_ratio: scene.controller.damping_ratio,
        // A law whose integral holds the weight from the start rests as the bias would hold it.
        gravity_bias: scene.controller.gravity_bias || crate::rest_law::holds_weight(scene),
    };
    // A shaft the levitation design cannot hold still has no equilibrium to start from: it
    // starts straight (the rigid start), and the run shows it move.
    // Held by the run's law at rest where it has a static gain (crate::rest_law).
    let kp = crate::rest_law::static_gains(scene);
    if let Some(sag) = plant_physics::flex::initial::static_sag_with(params, &design, kp, &y) {
        for (k, s) in sag.iter().enumerate() {
            y[k] += s;
        }
    }
    y
}
