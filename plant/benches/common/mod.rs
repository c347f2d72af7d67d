//! The models and states the derivative is measured on, shared by the criterion bench
//! (`benches/model.rs`, time) and `examples/derivative_count.rs` (instruction counts), so
//! that both measure the same thing: the planar model, and the two-plane rotor (the default
//! scene as its symmetric two-plane machine) with both planes in the planar contact state.

use plant::config::{validate, RawScene};
use plant::model::{ix, Control, Model, State};
use std::path::Path;

/// The default scene under a 10 G shock starting at t = 0, with the continuous PD.
pub fn model() -> (Model, plant::config::Scene) {
    let raw = RawScene {
        shock: vec![toml::from_str(
            "kind = \"double_half_sine\"\npeak_g = 10.0\nf1_hz = 10.0\nf2_hz = 80.0\nstart_s = 0.0",
        )
        .expect("shock")],
        ..Default::default()
    };
    let scene = validate(raw, Path::new(".")).expect("scene");
    let gains = plant::run::plane_gains(&scene).expect("gains")[0];
    let model = Model {
        params: scene.plane(0).clone(),
        base: scene.base.clone(),
        control: Control::Continuous(gains),
        race_parked: false,
    };
    (model, scene)
}

/// Rotor pressed 160 µm down into the race, race pushed onto the lower balls, both moving.
pub fn contact_state() -> State {
    let mut y = [0.0; plant::model::N];
    y[ix::YR] = -165e-6;
    y[ix::XR] = 3e-6;
    y[ix::YB] = -14e-6;
    y[ix::XB] = 1e-6;
    y[ix::VXR] = 0.05;
    y[ix::VYR] = -0.02;
    y[ix::WR] = std::f64::consts::TAU * 500.0;
    y[ix::WB] = 1000.0;
    y[ix::TB] = 0.3;
    y
}

/// The default scene's symmetric two-plane machine under the same shock, the continuous PD at
/// each plane.
#[allow(dead_code)]
pub fn two_plane_model() -> (plant_physics::two_plane::Model, plant::config::Scene) {
    let mut raw = RawScene {
        shock: vec![toml::from_str(
            "kind = \"double_half_sine\"\npeak_g = 10.0\nf1_hz = 10.0\nf2_hz = 80.0\nstart_s = 0.0",
        )
        .expect("shock")],
        ..Default::default()
    };
    raw.rotor.model = plant::config::RotorModel::TwoPlane.default_keys();
    raw.rotor.mass_kg = 23.0;
    raw.rotor.polar_inertia_kg_m2 = 11.62e-3;
    let scene = validate(raw, Path::new(".")).expect("scene");
    let gains = plant::run::plane_gains(&scene).expect("gains");
    let model = plant_physics::two_plane::Model {
        params: match &scene.rotor {
            plant::config::Rotor::TwoPlane(p) => p.clone(),
            other => panic!("a two-plane scene, not {:?}", other.model()),
        },
        base: scene.base.clone(),
        control: [Control::Continuous(gains[0]), Control::Continuous(gains[1])],
        race_parked: [false; 2],
    };
    (model, scene)
}

/// [`contact_state`] at both planes of the two-plane rotor: the axis 165 µm down and moving, no
/// tilt, each race pushed onto its lower balls.
#[allow(dead_code)]
pub fn two_plane_contact_state() -> plant_physics::two_plane::State {
    use plant_physics::two_plane::ix as t;
    let p = contact_state();
    let mut y = [0.0; plant_physics::two_plane::N];
    for (from, to) in [(ix::XR, t::X), (ix::YR, t::Y), (ix::TR, t::TR)] {
        y[to] = p[from];
        y[to + t::V] = p[from + 6];
    }
    for race in t::RACE {
        for k in 0..3 {
            y[race + k] = p[ix::XB + k];
            y[race + k + t::V] = p[ix::XB + k + 6];
        }
    }
    y
}
