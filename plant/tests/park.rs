//! The parked race (`plant::park`) on the impact scene `config/paper-3g.toml`: its rest
//! position, the gap test and the parked derivative.

use plant::config::load_scene;
use plant::model::{ix, Model, State};
use plant::model::{Control, N};
use plant::park::{clear, margin, rest_position};
use std::path::Path;

fn model() -> Model {
    let scene = load_scene(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/paper-3g.toml"), &[]).unwrap();
    let gains = plant::run::plane_gains(&scene).unwrap()[0];
    Model { params: scene.plane(0).clone(), base: scene.base, control: Control::Continuous(gains), race_parked: false }
}

/// Under gravity alone the rest position is the initial state's sag, straight down.
#[test]
fn rest_position_under_gravity_is_the_sag() {
    let m = model();
    let p = &m.params;
    let eps = rest_position(p, [0.0, -p.gravity].into(), p.cage_phase);
    let sag = plant::initial::race_sag(p);
    assert!(eps[0].abs() < 1e-15, "{eps:?}");
    assert!((eps[1] - sag).abs() < 1e-12, "{} against {sag}", eps[1]);
}

/// A centred rotor at rest is clear; one a margin short of the race is not; a rotor moving
/// fast towards the race is not clear even though it is far from it now.
#[test]
fn clear_bounds_the_closing_over_the_step() {
    let m = model();
    let h = 5e-5;
    let mut y: State = [0.0; N];
    y[ix::YB] = plant::initial::race_sag(&m.params);
    assert!(clear(&m, 0.0, h, &y));
    let gap = m.params.contact.gap;
    y[ix::YR] = y[ix::YB] + gap - 0.5 * margin(&m.params);
    assert!(!clear(&m, 0.0, h, &y));
    y[ix::YR] = y[ix::YB] + 0.5 * gap;
    assert!(clear(&m, 0.0, h, &y));
    y[ix::VYR] = 0.5 * gap / h; // would cross the rest of the gap within the step
    assert!(!clear(&m, 0.0, h, &y));
}

/// With the race parked the derivative freezes its translation and matches the full model
/// for the rotor wherever the gap is open.
#[test]
fn parked_derivative_matches_the_rotor_rows_and_freezes_the_race() {
    let mut m = model();
    let mut y: State = [0.0; N];
    y[ix::YB] = plant::initial::race_sag(&m.params);
    y[ix::XR] = 3e-5;
    y[ix::VYR] = 0.01;
    y[ix::WR] = m.params.speed;
    y[ix::WB] = 50.0;
    let full = m.evaluate(0.0, &y).dy;
    m.race_parked = true;
    let parked = m.evaluate(0.0, &y).dy;
    for i in [ix::XR, ix::YR, ix::TR, ix::VXR, ix::VYR, ix::WR, ix::TB, ix::WB] {
        assert_eq!(parked[i], full[i], "component {i}");
    }
    for i in [ix::XB, ix::YB, ix::VXB, ix::VYB] {
        assert_eq!(parked[i], 0.0, "component {i}");
    }
}
