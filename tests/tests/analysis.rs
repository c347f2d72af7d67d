//! End-to-end tests of the per-run analysis: `plant run` writes the analysis
//! keys and plots, and `plant analyze DIR` recomputes them on a run folder.

mod common;

use common::*;
use std::process::Command;

/// One short run or analysis in a debug build on a loaded machine: a hang fails.
const LIMIT: std::time::Duration = std::time::Duration::from_secs(300);

#[test]
fn analyze_recomputes_the_analysis_of_a_run_folder() {
    let dir = TempDir::new("analyze");
    let out = dir.join("run");
    let sets = ["scene.duration_s=0.3", "shock[0].start_s=0.01", "output.plots=false"];
    assert_exit(&output_within(&mut plant_run(&scene("paper-10g.toml"), &out, &sets), LIMIT), 0);
    let first = read_json(&out.join("summary.json"));
    for key in ["post_shock_mode", "steady_class"] {
        assert!(first[key].is_string(), "summary.json: {key} is not a name: {first:#}");
    }
    // The steady window is the whole run (0.3 s is shorter than 200 revolutions at 500 Hz):
    // its contact fraction is the share of trace rows with a contact force, counted here.
    assert_eq!(num(&first, "steady_window_start_s"), 0.0);
    let force = Csv::read(&out.join("trace.csv")).column("contact_force_n");
    let touching = force.iter().filter(|f| **f > 0.0).count() as f64 / force.len() as f64;
    assert!((num(&first, "steady_contact_fraction") - touching).abs() < 1e-12, "{first:#} vs {touching}");
    // 10 G reaches the race and keeps touching it: never "recovered" while still in contact.
    assert!(touching > 0.5, "contact in {touching} of the rows");
    assert!(["rebound", "dry_whirl"].contains(&first["post_shock_mode"].as_str().unwrap_or_default()), "{first:#}");
    // The unbalance drives the rotor at its speed: the synchronous line (500 Hz) is among the
    // dominant frequencies.
    let lines: Vec<f64> =
        first["dominant_frequencies_hz"].as_array().expect("a list").iter().filter_map(|f| f.as_f64()).collect();
    assert!(lines.iter().any(|f| (f - 500.0).abs() < 1.0), "no 500 Hz line in {lines:?}");

    // Analyse the folder again from trace.csv and scene.toml alone.
    std::fs::remove_file(out.join("summary.json")).expect("remove summary");
    let o = output_within(Command::new(plant_bin()).arg("analyze").arg(&out), LIMIT);
    assert_exit(&o, 0);
    let again = read_json(&out.join("summary.json"));
    for key in ["post_shock_mode", "steady_class", "period_k", "whirl_hz", "steady_contact_fraction"] {
        assert_eq!(again[key], first[key], "{key} differs after analyze");
    }
    // The trace is written with 17 significant digits, so the spectrum peaks agree closely.
    let (a, b) = (&first["dominant_frequencies_hz"][0], &again["dominant_frequencies_hz"][0]);
    assert!((a.as_f64().unwrap_or(f64::NAN) - b.as_f64().unwrap_or(0.0)).abs() < 1e-6, "{a} vs {b}");
    // The charts show the data (decoded: a blank chart fails).
    for png in ["spectrum.png", "whirl_spectrum.png", "poincare.png"] {
        let n = Png::read(&out.join(png)).count_in_plot(SERIES_BLUE);
        assert!(n > 100, "{png}: {n} pixels of the data colour");
    }
    let spectrogram = Png::read(&out.join("spectrogram.png"));
    let mut colours = spectrogram.rgb.clone();
    colours.sort_unstable();
    colours.dedup();
    assert!(colours.len() > 100, "spectrogram.png: {} colours, no colour map drawn", colours.len());
}

#[test]
fn analyze_on_a_folder_without_a_run_exits_2() {
    let dir = TempDir::new("analyze-empty");
    let o = output_within(Command::new(plant_bin()).arg("analyze").arg(dir.join("nothing")), LIMIT);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("scene.toml"), "{}", stderr(&o));
}

/// Issue 21 item 7: `plant analyze` read `trace.csv` without a bound (a link to `/dev/zero`
/// ran forever, a FIFO blocked forever) and died by SIGTERM without a word. What is not a
/// trace is refused at once (exit 2, naming the file), and a signal ends it with exit 130,
/// saying what it wrote.
#[cfg(target_os = "linux")]
#[test]
fn analyze_refuses_what_is_not_a_trace_and_exits_130_on_a_signal() {
    let dir = TempDir::new("analyze-hostile");
    let out = dir.join("run");
    assert_exit(&output_within(&mut plant_run(&scene("paper-10g.toml"), &out, SHORT), LIMIT), 0);
    for (name, make) in [
        (
            "zero",
            &(|p: &std::path::Path| std::os::unix::fs::symlink("/dev/zero", p).unwrap()) as &dyn Fn(&std::path::Path),
        ),
        ("fifo", &|p: &std::path::Path| {
            assert!(Command::new("mkfifo").arg(p).status().unwrap().success());
        }),
    ] {
        let copy = dir.join(name);
        std::fs::create_dir_all(&copy).unwrap();
        std::fs::copy(out.join("scene.toml"), copy.join("scene.toml")).unwrap();
        make(&copy.join("trace.csv"));
        let o = output_within(Command::new(plant_bin()).arg("analyze").arg(&copy), LIMIT);
        assert_exit(&o, 2);
        assert!(stderr(&o).contains("trace.csv") && stderr(&o).contains("not a regular file"), "{}", stderr(&o));
        assert!(!copy.join("summary.json").exists(), "{name}: nothing is written");
    }
    let before = read_text(&out.join("summary.json"));
    let analyze = Proc::spawn(Command::new(plant_bin()).arg("analyze").arg(&out));
    wait_for_handler(analyze.id(), libc::SIGTERM);
    analyze.signal(libc::SIGTERM);
    let (code, log) = analyze.finish_within(LIMIT);
    assert_eq!(code, Some(130), "{log}");
    assert!(log.contains("plant: interrupted by a signal;"), "{log}");
    if log.contains("nothing was written") {
        assert_eq!(read_text(&out.join("summary.json")), before);
    }
}
