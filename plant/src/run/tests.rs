//! The plant's tests that run it through the CLI's loop ([`crate::run`]) and its files: a saved
//! state continues bit for bit, on every rotor model; the snapshot's file.

use crate::config::Scene;
use crate::run::{run_into_from, Hooks, Quiet};
use crate::snapshot::Snapshot;
use crate::stepper::*;
use crate::trace::Trace;
use std::path::Path;

/// A shipped scene, 30 ms long with the shock at 5 ms, and `sets`.
fn scene(file: &str, sets: &[&str]) -> Scene {
    let mut all = vec!["scene.duration_s=0.03", "shock[0].start_s=0.005", "output.plots=false"];
    all.extend_from_slice(sets);
    crate::shipped(file, &all)
}

/// Hooks that save the state at the given times.
struct Saving {
    at: Vec<f64>,
    saved: Vec<Snapshot>,
}

impl Hooks for Saving {
    fn save_state_at(&self) -> &[f64] {
        &self.at
    }
    fn state_saved(&mut self, _at: f64, snapshot: Snapshot) {
        self.saved.push(snapshot);
    }
}

fn rows(trace: &Trace) -> Vec<Vec<u64>> {
    use crate::trace::Columns as _;
    let values = |r: crate::trace::Record| r.a.values().into_iter().chain(r.b.map(|b| b.values()).unwrap_or_default());
    trace.records().map(|r| values(r).map(|v| v.to_bits()).collect()).collect()
}

/// The run loop restored at a tick writes the rows of the run that never stopped, bit for
/// bit, with the digital loop's delay line carried over: on the planar model, the two-plane
/// rotor, a scene with amplifiers and a sensor front end, a noisy sensor and a parked race
/// under the fixed-step integrator.
#[test]
fn a_run_restored_at_a_tick_writes_the_rows_of_the_run_that_never_stopped() {
    let cases = [
        scene("cosim-10g.toml", &["controller.mode=\"sampled\"", "sensor.noise_v_rms=0.01", "sensor.adc_bits=14"]),
        scene("two-plane-asymmetric-10g.toml", &["controller.mode=\"sampled\""]),
        scene("realistic-10g.toml", &[]),
        scene(
            "paper-10g.toml",
            &[
                "integrator.method=\"rk4\"",
                "integrator.substeps=1",
                "integrator.contact_substeps=3",
                "touchdown.race_when_clear=\"parked\"",
                "touchdown.race_release=\"equilibrium\"",
                "controller.mode=\"sampled\"",
                "controller.delay_samples=2",
            ],
        ),
        scene("paper-10g.toml", &[]),
        scene("flexible-10g.toml", &["controller.mode=\"sampled\""]),
    ];
    for s in &cases {
        let mut hooks = Saving { at: vec![0.004, 0.0123], saved: Vec::new() };
        let mut whole = Trace::with_capacity(1000);
        let run = run_into_from(s, &Default::default(), &mut hooks, &mut whole, None).unwrap();
        assert_eq!(run.outcome, crate::run::Outcome::Completed, "{}", s.name);
        assert_eq!(hooks.saved.len(), 2);
        for snap in &hooks.saved {
            let mut rest = Trace::with_capacity(1000);
            let resumed = run_into_from(s, &Default::default(), &mut Quiet, &mut rest, Some(snap)).unwrap();
            let (all, tail) = (rows(&whole), rows(&rest));
            assert!(!tail.is_empty() && tail.len() < all.len(), "{}: {} of {} rows", s.name, tail.len(), all.len());
            let from = all.len() - tail.len();
            let differ = (0..tail.len()).find(|&i| all[from + i] != tail[i]);
            assert_eq!(differ, None, "{}: resumed at {} s, the rows differ from row {from} + this", s.name, snap.t_s);
            assert_eq!(
                resumed.final_state.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                run.final_state.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
            );
            assert_eq!(resumed.stats, run.stats, "{}: the integrator's counters go on", s.name);
        }
    }
}

/// A `Plant` stepped by hand is the run loop: the same rows as `plant run`'s sampled mode.
#[test]
fn a_plant_stepped_by_hand_gives_the_run_loops_rows() {
    let s = scene("cosim-10g.toml", &["controller.mode=\"sampled\"", "controller.delay_samples=0"]);
    let mut loop_trace = Trace::with_capacity(1000);
    run_into_from(&s, &Default::default(), &mut Quiet, &mut loop_trace, None).unwrap();
    let design = s.rotor_design();
    let mut law = controller::build_rotor_law("pd", &design, &s.controller.params).unwrap();
    let limits = design.current_limits();
    let bias = crate::run::bias_of(&s, &crate::run::plane_gains(&s).unwrap());
    let mut plant = Plant::new(&s, &Command::Held(bias)).unwrap();
    let mut mine = Trace::with_capacity(1000);
    plant.record(&mut mine);
    while !plant.finished() {
        let command = controller::saturate_axes(law.update(plant.sample()), limits);
        plant.step(&Command::Held(command), &mut mine).unwrap();
    }
    assert_eq!(rows(&mine), rows(&loop_trace));
}

/// A snapshot goes to a file and back to the same bits; a snapshot of another rotor, another
/// state layout or integrator is refused naming the first difference, and the plant is left
/// as it was.
#[test]
fn snapshots_round_trip_and_refuse_another_scene() {
    let s = scene("cosim-10g.toml", &["controller.mode=\"sampled\""]);
    let bias = crate::run::bias_of(&s, &crate::run::plane_gains(&s).unwrap());
    let mut plant = Plant::new(&s, &Command::Held(bias)).unwrap();
    for _ in 0..37 {
        plant.step(&Command::Held(bias), &mut Trace::with_capacity(4)).unwrap();
    }
    let snap = plant.snapshot();
    let dir = std::env::temp_dir().join(format!("plant-snapshot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(Snapshot::file_name(0.5));
    crate::snapshot::write(&snap, &path).unwrap();
    let back = Snapshot::read(&path).unwrap();
    assert_eq!(back, snap);
    assert!(back.state.iter().zip(&snap.state).all(|(a, b)| a.to_bits() == b.to_bits()));

    let refused = |other: &Scene| {
        let mut p = Plant::new(other, &Command::Held(bias)).unwrap();
        let before = p.state().to_vec();
        let e = p.restore(&snap).unwrap_err().to_string();
        assert_eq!(p.state(), &before[..], "a refused restore leaves the plant as it was");
        e
    };
    let e = refused(&scene("two-plane-asymmetric-10g.toml", &[]));
    assert!(e.contains("rotor.model is planar in the snapshot, two_plane in the scene"), "{e}");
    let e = refused(&scene("cosim-10g.toml", &["rotor.mass_kg=3.0"]));
    assert!(e.contains("rotor.mass_kg"), "{e}");
    let e = refused(&scene("cosim-10g.toml", &["amb.amplifier=true"]));
    assert!(e.contains("state.length"), "{e}");
    let e = refused(&scene("cosim-10g.toml", &["integrator.method=\"dop853\""]));
    assert!(e.contains("integrator.method"), "{e}");
    let e = refused(&scene("cosim-10g.toml", &["controller.rate_hz=10000.0"]));
    assert!(e.contains("controller.rate_hz"), "{e}");
    // The controller, its gains and the shock may differ.
    for other in [
        scene("cosim-10g.toml", &["controller.stiffness_n_per_m=2e6", "controller.law=\"relev\""]),
        scene("cosim-10g.toml", &["shock[0].peak_g=3.0", "scene.duration_s=0.5"]),
    ] {
        Plant::new(&other, &Command::Held(bias)).unwrap().restore(&snap).unwrap();
    }

    // Files that are not a snapshot of this format.
    let text = std::fs::read_to_string(&path).unwrap();
    let bad = |name: &str, body: &str| {
        let p = dir.join(name);
        std::fs::write(&p, body).unwrap();
        let e = Snapshot::read(&p).unwrap_err().to_string();
        assert!(e.contains(name), "{e}");
        e
    };
    let e = bad("truncated.json", &text[..text.len() / 2]);
    assert!(e.contains("truncated"), "{e}");
    let e = bad("format.json", &text.replacen("\"format\": 1", "\"format\": 99", 1));
    assert!(e.contains("format 99"), "{e}");
    let e = bad("trace.csv", "t_s,dx_m\n0,0\n");
    assert!(e.contains("not a snapshot"), "{e}");
    let e = bad("empty.json", "{}");
    assert!(e.contains("not a snapshot"), "{e}");
    let e = Snapshot::read(Path::new("/dev/zero")).unwrap_err().to_string();
    assert!(e.contains("not a regular file"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
