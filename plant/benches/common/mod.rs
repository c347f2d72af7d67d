//! The model and states the derivative is measured on, shared by the criterion bench
//! (`benches/model.rs`, time) and `examples/derivative_count.rs` (instruction counts), so
//! that both measure the same thing.

use plant::config::{validate, RawScene};
use plant::model::{ix, Control, Model, State};
use plant::run::design_gains;
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
    let gains = design_gains(&scene).expect("gains");
    let model = Model {
        params: scene.params.clone(),
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
