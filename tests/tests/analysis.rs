//! End-to-end tests of the per-run analysis: `plant run` writes the analysis
//! keys and plots, and `plant analyze DIR` recomputes them on a run folder.

mod common;

use common::*;
use std::process::Command;

#[test]
fn analyze_recomputes_the_analysis_of_a_run_folder() {
    let dir = TempDir::new("analyze");
    let out = dir.join("run");
    let sets = ["scene.duration_s=0.3", "shock[0].start_s=0.01", "output.plots=false"];
    assert_exit(&output(&mut plant_run(&scene("paper-10g.toml"), &out, &sets)), 0);
    let first = read_json(&out.join("summary.json"));
    for key in ["post_shock_mode", "steady_class", "period_k", "dominant_frequencies_hz", "whirl_hz"] {
        assert!(first.get(key).is_some(), "summary.json lacks {key}");
    }
    // 10 G always reaches the race: never "recovered" while still in contact.
    assert!(num(&first, "steady_contact_fraction") > 0.0);
    assert_ne!(first["post_shock_mode"], "recovered");

    // Analyse the folder again from trace.csv and scene.toml alone.
    std::fs::remove_file(out.join("summary.json")).expect("remove summary");
    let o = output(Command::new(plant_bin()).arg("analyze").arg(&out));
    assert_exit(&o, 0);
    let again = read_json(&out.join("summary.json"));
    for key in ["post_shock_mode", "steady_class", "period_k", "whirl_hz", "steady_contact_fraction"] {
        assert_eq!(again[key], first[key], "{key} differs after analyze");
    }
    // The trace is written with 17 significant digits, so the spectrum peaks agree closely.
    let (a, b) = (&first["dominant_frequencies_hz"][0], &again["dominant_frequencies_hz"][0]);
    assert!((a.as_f64().unwrap_or(f64::NAN) - b.as_f64().unwrap_or(0.0)).abs() < 1e-6, "{a} vs {b}");
    for png in ["spectrum.png", "whirl_spectrum.png", "spectrogram.png", "poincare.png"] {
        let bytes = std::fs::read(out.join(png)).unwrap_or_default();
        assert!(bytes.starts_with(b"\x89PNG"), "{png} missing");
    }
}

#[test]
fn analyze_on_a_folder_without_a_run_exits_2() {
    let dir = TempDir::new("analyze-empty");
    let o = output(Command::new(plant_bin()).arg("analyze").arg(dir.join("nothing")));
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("scene.toml"), "{}", stderr(&o));
}
