//! The flexible rotor through the binary (issue 30): the shipped scene runs and writes the
//! two-plane rotor's trace layout, `plant analyze` reads it back, a sampled run and a lockstep
//! co-simulation give the same trace, and the bad inputs of the issue are refused at load with
//! exit 2, naming key, value and unit, nothing written.
//!
//! Every command runs under a time limit (`output_within`): a hang fails.

mod common;

use common::{assert_exit, output_within, plant_bin, plant_run, read_json, refused, scene, stderr, Csv, TempDir};
use std::process::Command;
use std::time::Duration;

/// A short run in a debug build on a loaded machine.
const RUN: Duration = Duration::from_secs(180);

/// The shipped scene cut to 25 ms (the shock at 7 ms: both planes touch).
const SHORT: &[&str] = &["scene.duration_s=0.025", "shock[0].start_s=0.007", "output.plots=false"];

#[test]
fn bad_flexible_input_is_refused_at_load_naming_the_key() {
    let flex = scene("flexible-10g.toml");
    // Nodes out of range; an AMB on the wrong side of the centre of mass.
    refused("amb-range", &flex, &["rotor.amb_b_node=40"], &["rotor.amb_b_node = 40", "nodes 0 to 16"]);
    refused("sensor-range", &flex, &["rotor.sensor_a_node=17"], &["rotor.sensor_a_node = 17", "out of range"]);
    refused("td-range", &flex, &["rotor.touchdown_b_node=99"], &["rotor.touchdown_b_node = 99"]);
    refused("amb-side", &flex, &["rotor.amb_a_node=12"], &["rotor.amb_a_node = 12", "centre of mass"]);
    // A shaft element of zero length or negative diameter; a material without its modulus.
    refused(
        "zero-length",
        &flex,
        &["rotor.shaft.element=[{length_mm=0.0, outer_diameter_mm=40.0, material=\"steel\"}]"],
        &["rotor.shaft", "element[0]: length_mm = 0 mm must be positive"],
    );
    refused(
        "no-modulus",
        &flex,
        &["rotor.shaft.materials.steel.modulus_pa=-1"],
        &["rotor.shaft", "modulus_pa = -1 Pa", "must be positive"],
    );
    // A cutoff that keeps nothing (the free shaft's rigid-body modes are at 0 Hz: any positive
    // cutoff keeps them), or one that keeps more modes than the state holds.
    refused("cutoff-zero", &flex, &["rotor.cutoff_hz=0"], &["rotor.cutoff_hz = 0 Hz"]);
    refused("cutoff-high", &flex, &["rotor.cutoff_hz=1e6"], &["rotor.cutoff_hz = 1000000 Hz", "room for"]);
    refused("zeta", &flex, &["rotor.modal_damping=-0.1"], &["rotor.modal_damping = -0.1"]);
    // A ROSS file that is not there, and both descriptions at once.
    refused("ross-missing", &flex, &["rotor.ross_file=\"nowhere.toml\""], &["rotor.ross_file = nowhere.toml"]);
    // The rigid rotor's geometry in a flexible scene, and the flexible keys in a rigid one.
    refused("rigid-key", &flex, &["rotor.bearing_a_mm=-100"], &["rotor.bearing_a_mm = -100 mm", "shaft"]);
    refused(
        "flex-key-in-rigid",
        &scene("two-plane-asymmetric-10g.toml"),
        &["rotor.amb_a_node=2"],
        &["rotor.amb_a_node = 2", "flexible"],
    );
}

/// The shipped scene, cut short: both planes touch, the trace has the two-plane rotor's 37
/// columns and the mid-span's two after them, the summary names the model, `plant analyze` reads the trace back
/// (and gives the mid-span orbit's largest radius and chart); a sampled run
/// and a lockstep co-simulation (4 axes on the wire) of the same law give the same trace (the
/// continuous PD is the unit tests' `machine::flexible`).
#[test]
fn flexible_scene_runs_in_every_mode_and_analyze_reads_it_back() {
    let dir = TempDir::new("flexible");
    let mut traces = Vec::new();
    for mode in ["sampled", "lockstep"] {
        let out = dir.join(mode);
        let mode_set = format!("controller.mode={mode}");
        let sets: Vec<&str> = SHORT.iter().copied().chain([mode_set.as_str()]).collect();
        let run = output_within(&mut plant_run(&scene("flexible-10g.toml"), &out, &sets), RUN);
        assert_exit(&run, 0);
        let trace = Csv::read(&out.join("trace.csv"));
        assert_eq!(trace.header.len(), 39, "{:?}", trace.header);
        assert_eq!(trace.header[19], "b_dx_m");
        assert_eq!(trace.header[37..], ["mid_dx_m", "mid_dy_m"], "the rotor at mid-span, last");
        let summary = read_json(&out.join("summary.json"));
        assert_eq!(summary["model"]["rotor"], "flexible");
        assert_eq!(summary["status"], "completed", "{mode}: {summary:#}");
        for p in ["a", "b"] {
            assert!(summary["planes"][p]["first_contact_s"].as_f64().is_some(), "{mode}: plane {p} never touched");
        }
        if mode == "sampled" {
            let before = summary.clone();
            let analyze = output_within(Command::new(plant_bin()).arg("analyze").arg(&out), RUN);
            assert_exit(&analyze, 0);
            let after = read_json(&out.join("summary.json"));
            assert_eq!(after["planes"]["a"]["post_shock_mode"], before["planes"]["a"]["post_shock_mode"]);
            // The mid-span orbit: its largest radius from the trace's last two columns, and its chart.
            let mid = |row: &Vec<f64>| row[37].hypot(row[38]);
            let largest = trace.rows.iter().map(mid).fold(0.0, f64::max);
            let got = after["mid_span"]["max_radius_m"].as_f64().expect("mid_span.max_radius_m");
            assert!((got - largest).abs() <= 1e-9 * largest, "analyze {got}, trace {largest}");
            assert!(out.join("orbit_mid.png").is_file(), "analyze draws the mid-span orbit");
        }
        traces.push(trace);
    }
    assert_eq!(traces[0].rows, traces[1].rows, "lockstep differs from sampled");
}

/// `plant campbell` of the flexible scene (issue 30 item 3): campbell.csv has the rigid rotor's
/// four modes and the first bending mode's pair beside them at every speed (forward above
/// backward once spinning), campbell.png is drawn, and the log says that no free decays were
/// run (they check the two-plane rotor's linearisation).
#[test]
fn campbell_of_a_flexible_scene_shows_its_bending_modes() {
    let dir = TempDir::new("flexible-campbell");
    let out = dir.join("c");
    let run = output_within(
        Command::new(plant_bin())
            .arg("campbell")
            .arg(scene("flexible-10g.toml"))
            .args(["--points", "3", "--max-speed-hz", "300", "--out"])
            .arg(&out),
        RUN,
    );
    assert_exit(&run, 0);
    assert!(stderr(&run).contains("no free decays"), "{}", stderr(&run));
    assert!(out.join("campbell.png").is_file());
    let text = std::fs::read_to_string(out.join("campbell.csv")).expect("campbell.csv");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("speed_hz,mode,whirl,frequency_hz,damping_ratio"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    for speed in ["0.0", "150.0", "300.0"] {
        let at: Vec<&Vec<&str>> = rows.iter().filter(|r| r[0] == speed).collect();
        let of = |mode: &str| at.iter().filter(|r| r[1] == mode).count();
        assert_eq!((of("cylindrical"), of("conical"), of("bending_1")), (2, 2, 2), "{speed} Hz: {at:?}");
        let bending: Vec<(&str, f64)> =
            at.iter().filter(|r| r[1] == "bending_1").map(|r| (r[2], r[3].parse().expect("Hz"))).collect();
        assert!(bending.iter().all(|(_, f)| (440.0..560.0).contains(f)), "{bending:?}");
        if speed == "300.0" {
            let hz = |w: &str| bending.iter().find(|b| b.0 == w).map(|b| b.1).expect("whirl");
            assert!(hz("forward") > hz("backward") + 10.0, "{bending:?}");
        }
    }
}
