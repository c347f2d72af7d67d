//! The two-plane rotor through the binary (issue 17): the shipped asymmetric scene runs and writes
//! its per-plane trace columns, summary and charts, and `plant analyze` reads its trace back; a
//! sampled run has one law per plane; the bad inputs of the issue are refused at load with exit
//! 2, naming key, value and unit, and nothing is written.
//!
//! Every command runs under a time limit (`output_within`): a hang fails.

mod common;

use common::{assert_exit, output_within, plant_bin, plant_run, read_json, refused, scene, stderr, Csv, TempDir};
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// Refusals happen while the scene loads.
const QUICK: Duration = Duration::from_secs(30);
/// A short run in a debug build on a loaded machine.
const RUN: Duration = Duration::from_secs(180);

/// The asymmetric scene cut to 40 ms (the shock at 10 ms: both planes touch).
const SHORT: &[&str] = &["scene.duration_s=0.04", "shock[0].start_s=0.01"];

#[test]
fn bad_two_plane_input_is_refused_at_load_naming_the_key() {
    let two = scene("two-plane-asymmetric-10g.toml");
    let planar = scene("paper-10g.toml");
    // Bearing planes on the same side of the centre of mass, or at the same position.
    refused(
        "same-side",
        &two,
        &["rotor.bearing_a_mm=20"],
        &["rotor.bearing_a_mm = 20 mm", "must be < 0", "centre of mass"],
    );
    refused("same-side-b", &two, &["rotor.bearing_b_mm=-50"], &["rotor.bearing_b_mm = -50 mm", "must be > 0"]);
    refused("same-place", &two, &["rotor.bearing_a_mm=0", "rotor.bearing_b_mm=0"], &["rotor.bearing_a_mm = 0 mm"]);
    // Inertias not positive.
    refused(
        "it-zero",
        &two,
        &["rotor.transverse_inertia_kg_m2=0"],
        &["rotor.transverse_inertia_kg_m2 = 0 kg·m²", "> 0"],
    );
    refused("ip-negative", &two, &["rotor.polar_inertia_kg_m2=-1e-3"], &["rotor.polar_inertia_kg_m2 = -0.001 kg·m²"]);
    refused("it-nan", &two, &["rotor.transverse_inertia_kg_m2=nan"], &["rotor.transverse_inertia_kg_m2 = NaN kg·m²"]);
    // A sensor plane outside the rotor.
    refused(
        "sensor-off",
        &two,
        &["rotor.sensor_b_mm=400"],
        &["rotor.sensor_b_mm = 400 mm", "must lie on the rotor", "rotor.end_b_mm = 290 mm"],
    );
    // Per-plane tables and two-plane keys in a planar scene, and a plane's table of tables.
    refused(
        "planar-plane-table",
        &planar,
        &["touchdown.b.air_gap_mm=0.2"],
        &["touchdown.b", "two-plane rotor", "planar"],
    );
    refused(
        "planar-it",
        &planar,
        &["rotor.transverse_inertia_kg_m2=0.4"],
        &["rotor.transverse_inertia_kg_m2 = 0.4 kg·m²", "planar"],
    );
    refused("nested", &two, &["touchdown.b.a.air_gap_mm=0.2"], &["touchdown.b", "not another plane's table"]);
    // A plane's own bad value is named as the plane's key; an unknown key in it too.
    refused("plane-gap", &two, &["touchdown.b.air_gap_mm=-1"], &["touchdown.b.air_gap_mm = -1 mm"]);
    refused("plane-unknown", &two, &["contact.a.frition_static=0.2"], &["contact.a", "frition_static"]);
    // The Campbell diagram of a planar scene.
    let dir = TempDir::new("campbell-planar");
    let out =
        output_within(Command::new(plant_bin()).arg("campbell").arg(&planar).arg("--out").arg(dir.join("c")), QUICK);
    assert_exit(&out, 2);
    assert!(stderr(&out).contains("needs a two-plane scene"), "{}", stderr(&out));
    // A two-plane scene with an amplifier or a sensor filter: not linearised (the diagram would
    // leave their states out), refused naming what is on.
    for (set, needle) in
        [("amb.amplifier=true", "amb.amplifier = true"), ("sensor.bandwidth_hz=5000", "sensor.bandwidth_hz > 0")]
    {
        let out = output_within(
            Command::new(plant_bin()).arg("campbell").arg(&two).args(["--set", set]).arg("--out").arg(dir.join("h")),
            QUICK,
        );
        assert_exit(&out, 2);
        assert!(stderr(&out).contains(needle) && stderr(&out).contains("ideal loop"), "{}", stderr(&out));
    }
    // A law of the whole rotor on a planar scene.
    refused("modal-planar", &planar, &["controller.mode=sampled", "controller.law=modal"], &["modal"]);
}

/// A four-axis scene with a controller that runs two axes only: it refuses the hello with
/// status 3, and the plant exits 2 naming the refusal (the run's record says `refused`).
#[test]
fn a_two_axis_controller_refuses_the_two_plane_rotor() {
    let dir = TempDir::new("two-plane-two-axes");
    let out = dir.join("run");
    let command = format!("controller.command=[{:?}, \"--mode\", \"two-axes\"]", common::rogue_bin().display());
    let sets = ["scene.duration_s=0.005", "controller.mode=lockstep", "output.plots=false", &command];
    let run = output_within(&mut plant_run(&scene("two-plane-asymmetric-10g.toml"), &out, &sets), RUN);
    assert_exit(&run, 2);
    let err = stderr(&run);
    assert!(err.contains("runs 2 axes, the plant asks for 4"), "{err}");
    assert_eq!(read_json(&out.join("summary.json"))["status"], "refused");
}

/// The two-plane rotor co-simulated in lockstep (4 axes on the wire, the built-in controller)
/// gives the trace of the same law run in-process (sampled), bit for bit: per-plane `pd`
/// decentralised and the centralised `modal`.
#[test]
fn lockstep_two_plane_run_is_the_sampled_run() {
    for law in ["pd", "modal"] {
        let dir = TempDir::new(&format!("two-plane-lockstep-{law}"));
        let law_set = format!("controller.law={law}");
        let base =
            ["scene.duration_s=0.03", "shock[0].start_s=0.01", "controller.damping_ratio=0.026", "output.plots=false"];
        let runs: Vec<Csv> = ["sampled", "lockstep"]
            .iter()
            .map(|mode| {
                let out = dir.join(mode);
                let mode_set = format!("controller.mode={mode}");
                let sets: Vec<&str> = base.iter().copied().chain([mode_set.as_str(), law_set.as_str()]).collect();
                let run = output_within(&mut plant_run(&scene("two-plane-asymmetric-10g.toml"), &out, &sets), RUN);
                assert_exit(&run, 0);
                two_plane_trace(&out)
            })
            .collect();
        assert_eq!(runs[0].rows, runs[1].rows, "law {law}: lockstep differs from sampled");
        let contact = runs[0].column("contact_force_n").iter().filter(|f| **f > 0.0).count();
        assert!(contact > 0, "law {law}: the window holds contact");
    }
}

/// Reads `dir/trace.csv` and checks a two-plane header: the planar columns first, under their
/// planar names, then plane B's and the slopes.
fn two_plane_trace(dir: &Path) -> Csv {
    let trace = Csv::read(&dir.join("trace.csv"));
    assert_eq!(trace.header.len(), 37, "{:?}", trace.header);
    assert_eq!(&trace.header[..3], ["t_s", "dx_m", "dy_m"]);
    assert_eq!(trace.header[19], "b_dx_m");
    assert_eq!(trace.header[36], "slope_y_rate_rad_s");
    trace
}

#[test]
fn asymmetric_scene_writes_planes_and_tilt_and_analyze_reads_it_back() {
    let dir = TempDir::new("two-plane-asym");
    let out = dir.join("run");
    let run = output_within(&mut plant_run(&scene("two-plane-asymmetric-10g.toml"), &out, SHORT), RUN);
    assert_exit(&run, 0);
    let trace = two_plane_trace(&out);
    // Plane A is nearer the centre of mass: it touches first, and the rotor tilts.
    let summary = read_json(&out.join("summary.json"));
    let planes = &summary["planes"];
    let first = |p: &str| {
        planes[p]["first_contact_s"].as_f64().unwrap_or_else(|| panic!("plane {p} never touched: {planes:#}"))
    };
    assert!(first("a") < first("b"), "{planes:#}");
    assert!(planes["tilt"]["max_tilt_rad"].as_f64().unwrap() > 1e-4, "{planes:#}");
    assert_eq!(summary["model"]["rotor"], "two_plane");
    // The trace's slopes are what the per-plane columns say: (x_B − x_A) / (z_B − z_A).
    let (xa, xb, a) = (trace.column("dx_m"), trace.column("b_dx_m"), trace.column("slope_x_rad"));
    for k in (0..xa.len()).step_by(97) {
        let slope = (xb[k] - xa[k]) / 0.36;
        assert!((slope - a[k]).abs() <= 1e-9 * a[k].abs().max(1e-6), "row {k}: {slope:e} against {:e}", a[k]);
    }
    for file in ["orbit_a.png", "orbit_b.png", "radius.png", "contact_force.png", "tilt.png", "spectrum_b.png"] {
        assert!(out.join(file).exists(), "no {file}");
    }
    assert!(!out.join("orbit.png").exists());
    // `plant analyze` reads the two-plane trace back and finds the run's analysis per plane.
    let before = summary.clone();
    let analyze = output_within(Command::new(plant_bin()).arg("analyze").arg(&out), RUN);
    assert_exit(&analyze, 0);
    let after = read_json(&out.join("summary.json"));
    for key in ["post_shock_mode", "steady_class", "dominant_frequencies_hz"] {
        assert_eq!(after[key], before[key], "{key}");
        for p in ["a", "b"] {
            assert_eq!(after["planes"][p][key], before["planes"][p][key], "plane {p}: {key}");
        }
    }
    assert_eq!(after["planes"]["tilt"], before["planes"]["tilt"]);
    // A trace without its plane B columns is refused for a two-plane scene.
    let text = std::fs::read_to_string(out.join("trace.csv")).unwrap();
    let cut: String = text.lines().map(|l| l.split(',').take(19).collect::<Vec<_>>().join(",") + "\n").collect();
    std::fs::write(out.join("trace.csv"), cut).unwrap();
    let analyze = output_within(Command::new(plant_bin()).arg("analyze").arg(&out), RUN);
    assert_exit(&analyze, 2);
    assert!(stderr(&analyze).contains("no plane B columns"), "{}", stderr(&analyze));
}

/// In `sampled` mode each plane has its own law, built from its own design (its load share):
/// the asymmetric rotor's planes get different gravity bias currents.
#[test]
fn sampled_two_plane_run_has_a_law_per_plane() {
    let dir = TempDir::new("two-plane-sampled");
    let out = dir.join("run");
    let sets =
        ["scene.duration_s=0.005", "controller.mode=sampled", "controller.damping_ratio=0.026", "output.plots=false"];
    let run = output_within(&mut plant_run(&scene("two-plane-asymmetric-10g.toml"), &out, &sets), RUN);
    assert_exit(&run, 0);
    let trace = two_plane_trace(&out);
    let (iya, iyb) = (trace.column("iy_a"), trace.column("b_iy_a"));
    // m_i g / k_i: 2/3 and 1/3 of 23 kg.
    let bias = |share: f64| share * 23.0 * 9.80665 / 216.0;
    assert!((iya[0] - bias(2.0 / 3.0)).abs() < 1e-9, "{}", iya[0]);
    assert!((iyb[0] - bias(1.0 / 3.0)).abs() < 1e-9, "{}", iyb[0]);
}
