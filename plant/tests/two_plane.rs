//! The planar model is the two-plane rotor's symmetric case (docs/MODEL.md §10.5): a shipped
//! planar scene run as the symmetric two-plane machine (`rotor.model = "two_plane"`, twice the
//! mass and polar inertia, every other default the symmetric machine's) gives the planar trace
//! at each plane, bit for bit where the integrator takes the same steps: the fixed-step methods,
//! levitated and in contact. Its slopes stay zero.

use plant::config::{load_scene, Scene};
use plant::run::{run, Outcome, Quiet};
use plant::trace::{Columns as _, Trace};
use std::path::{Path, PathBuf};

fn shipped(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("config").join(name)
}

/// The overrides that make a planar scene its symmetric two-plane machine.
const SYMMETRIC: [&str; 3] = ["rotor.model=two_plane", "rotor.mass_kg=23", "rotor.polar_inertia_kg_m2=0.01162"];

fn traces(file: &str, sets: &[&str]) -> (Trace, Trace) {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let planar: Scene = load_scene(&shipped(file), &sets).unwrap();
    let two_sets: Vec<String> = sets.iter().cloned().chain(SYMMETRIC.iter().map(|s| s.to_string())).collect();
    let two: Scene = load_scene(&shipped(file), &two_sets).unwrap();
    assert!(planar.planes() == 1 && two.planes() == 2);
    let p = run(&planar, &mut Quiet).unwrap();
    let t = run(&two, &mut Quiet).unwrap();
    assert_eq!(p.run.outcome, Outcome::Completed);
    assert_eq!(t.run.outcome, Outcome::Completed);
    (p.trace, t.trace)
}

/// Each plane's rows of the two-plane trace against the planar rows, bit for bit; no tilt.
fn assert_bit_identical(planar: &Trace, two: &Trace) -> usize {
    assert_eq!(planar.len(), two.len());
    let mut contact_rows = 0;
    for (i, (p, r)) in planar.rows().zip(two.records()).enumerate() {
        for plane in 0..2 {
            let q = r.plane(plane);
            for (c, (a, b)) in p.values().iter().zip(&q.values()).enumerate() {
                assert_eq!(
                    a.to_bits(),
                    b.to_bits(),
                    "row {i}, plane {plane}, column {}: {a:e} against {b:e}",
                    Trace::COLUMNS[c]
                );
            }
        }
        let [sa, sb] = r.slopes().unwrap();
        assert!(sa == 0.0 && sb == 0.0, "row {i}: slopes {sa:e}, {sb:e}");
        contact_rows += usize::from(p.loads.contact_force_n > 0.0);
    }
    contact_rows
}

/// The shipped levitation scene (RK4, one step per tick, the races parked while clear).
#[test]
fn symmetric_levitation_scene_is_the_planar_trace_bit_for_bit() {
    let (planar, two) = traces("levitation-1g.toml", &["scene.duration_s=0.2", "output.plots=false"]);
    assert_bit_identical(&planar, &two);
}

/// The 10 G scene through its first impacts on a fixed step (RK4 at the contact-safe substeps):
/// contact, friction, the race on its balls, bit for bit.
#[test]
fn symmetric_contact_scene_on_a_fixed_step_is_the_planar_trace_bit_for_bit() {
    let sets = ["scene.duration_s=0.045", "integrator.method=rk4", "integrator.substeps=40", "output.plots=false"];
    let (planar, two) = traces("paper-10g.toml", &sets);
    let contact = assert_bit_identical(&planar, &two);
    assert!(contact > 20, "the window must hold contact: {contact} rows");
}

/// `plant campbell`'s check, at 500 Hz on the asymmetric scene with its sensors 30 mm outboard
/// (centre of mass off mid-span, non-collocated): each whirl mode of the linearisation is found
/// in a simulated free decay of the full model within 1 % (it is found to 1e-11: the decay is
/// linear and the integrator's phase error at these frequencies is far below), the gyroscopic
/// split with its sign (forward conical above backward).
#[test]
fn free_decay_frequencies_are_the_campbell_frequencies() {
    let sets: Vec<String> = ["rotor.sensor_a_mm=-150", "rotor.sensor_b_mm=270"].iter().map(|s| s.to_string()).collect();
    let scene = load_scene(&shipped("two-plane-asymmetric-10g.toml"), &sets).unwrap();
    let rotor = plant::campbell::linear_rotor(&scene).unwrap();
    let hz = 500.0;
    let linear = rotor.modes(hz * std::f64::consts::TAU).unwrap();
    assert!(linear[2].frequency_hz > linear[3].frequency_hz + 5.0, "{linear:?}");
    let fitted = plant::campbell::free_decay(&scene, hz).unwrap();
    for row in plant::campbell::match_modes(hz, &linear, &fitted) {
        assert!(row.error_rel.abs() < 0.01, "{row:?}");
        assert!((row.decay_damping_ratio - row.linear_damping_ratio).abs() < 1e-3, "{row:?}");
    }
}
