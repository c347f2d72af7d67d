//! End-to-end tests of what a run writes (issue 11 items 4–6, issue 13 item 5):
//! `plant run` needs the same memory for a long run as for a short one; `plant
//! analyze` reads `trace.csv` strictly and writes nothing when it fails; a
//! diverged run's maxima are over the rows before the failure, with the
//! failing state on its own; a divergence at t = 0 exits 3 with its time and
//! state; a reused output folder keeps no file of the previous run; a folder
//! in use by a live run is refused to a second command; the charts show the
//! data (decoded, not just a PNG signature).

mod common;

use common::*;
use std::process::Command;
use std::time::Duration;

/// Generous: debug builds on a loaded 2-core machine.
const LIMIT: Duration = Duration::from_secs(600);

fn analyze(dir: &std::path::Path) -> std::process::Output {
    output_within(Command::new(plant_bin()).arg("analyze").arg(dir), LIMIT)
}

#[cfg(target_os = "linux")]
#[test]
fn plant_run_memory_does_not_grow_with_the_run_length() {
    let dir = TempDir::new("outputs-rss");
    // The cheapest setting: RK4, one step per 0.5 ms tick, race parked while clear; output at
    // 1 kHz, charts on (their data are part of what must stay bounded).
    let sets =
        |d: &str| vec![format!("scene.duration_s={d}"), "controller.rate_hz=2000".into(), "output.rate_hz=1000".into()];
    let mut peak = Vec::new();
    // 40 s is past every bounded store's size (orbit 50 000 rows, 4096 chart bins, 20 000
    // transient Poincaré points, 1024 spectrogram columns); 160 s has four times its rows.
    for d in ["40", "160"] {
        let s = sets(d);
        let s: Vec<&str> = s.iter().map(String::as_str).collect();
        let (code, kib) =
            peak_rss_within(&mut plant_run(&scene("levitation-1g.toml"), &dir.join(&format!("run{d}")), &s), LIMIT);
        assert_eq!(code, Some(0), "{d} s run failed");
        let rows = std::fs::read_to_string(dir.join(&format!("run{d}")).join("trace.csv")).unwrap().lines().count();
        assert!(rows > 1000 * d.parse::<usize>().unwrap(), "{rows} rows");
        peak.push(kib as f64);
    }
    // Before the streaming writer the trace alone (19 columns × 8 B per row, plus the
    // charts' copies) grew by tens of MiB from the short run to the long one.
    let ratio = peak[1] / peak[0];
    assert!(ratio < 1.15, "peak RSS {} KiB for 160 s against {} KiB for 40 s: ratio {ratio:.3}", peak[1], peak[0]);
}

/// Runs paper-3g for 50 ms into `out` and returns its summary.json text.
fn short_run(out: &std::path::Path, plots: bool) -> String {
    let plots = format!("output.plots={plots}");
    let sets = ["scene.duration_s=0.05", "shock[0].start_s=0.01", plots.as_str()];
    assert_exit(&output_within(&mut plant_run(&scene("paper-3g.toml"), out, &sets), LIMIT), 0);
    std::fs::read_to_string(out.join("summary.json")).expect("summary.json")
}

#[test]
fn analyze_refuses_corrupt_traces_naming_file_line_and_column_and_writes_nothing() {
    let dir = TempDir::new("outputs-analyze");
    let out = dir.join("run");
    short_run(&out, false);
    let good = std::fs::read_to_string(out.join("trace.csv")).unwrap();
    let lines: Vec<&str> = good.lines().collect();
    let n = lines.len();
    let with_line = |i: usize, replacement: &str| {
        let mut l: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
        l[i] = replacement.to_string();
        l.join("\n") + "\n"
    };
    let fields = |i: usize| lines[i].split(',').map(str::to_string).collect::<Vec<String>>();
    let mut backwards = fields(n - 1);
    backwards[0] = fields(n - 3)[0].clone();
    let mut repeated = fields(n - 1);
    repeated[0] = fields(n - 2)[0].clone();
    let mut not_a_number = fields(40);
    not_a_number[2] = "1.3x4e-4".into();
    // Cut in the middle of dy (the third field) of the last row: dy alone reads as a number.
    let last = lines[n - 1];
    let cut_at = last.match_indices(',').nth(1).map(|(i, _)| i + 5).unwrap();
    let cases: Vec<(&str, String, String, &str)> = vec![
        (
            "cut in a number",
            format!("{}\n{}", lines[..n - 1].join("\n"), &last[..cut_at]),
            format!("line {n}"),
            "cut row",
        ),
        ("ragged", with_line(20, &format!("{},0e0", lines[20])), "line 21".into(), "20 fields where the header has 19"),
        (
            "not a number",
            with_line(40, &not_a_number.join(",")),
            "line 41, column dy_m".into(),
            "`1.3x4e-4` is not a number",
        ),
        ("backwards", with_line(n - 1, &backwards.join(",")), format!("line {n}, column t_s"), "runs backwards"),
        ("repeated", with_line(n - 1, &repeated.join(",")), format!("line {n}, column t_s"), "repeats"),
    ];
    let summary_before = std::fs::read(out.join("summary.json")).unwrap();
    for (what, text, at, why) in cases {
        std::fs::write(out.join("trace.csv"), text).unwrap();
        let o = analyze(&out);
        assert_exit(&o, 2);
        let err = stderr(&o);
        assert!(err.contains("trace.csv") && err.contains(&at) && err.contains(why), "{what}: {err}");
        assert!(!err.contains("plot") && !err.contains("chart"), "{what}: blames a chart: {err}");
        assert_eq!(std::fs::read(out.join("summary.json")).unwrap(), summary_before, "{what}: summary.json rewritten");
    }
    // The intact trace analyses, and summary.json is the run's with the analysis merged.
    std::fs::write(out.join("trace.csv"), &good).unwrap();
    assert_exit(&analyze(&out), 0);
    let again = read_json(&out.join("summary.json"));
    assert_eq!(again["status"], "completed");
    // No temporary file of the atomic write is left behind.
    let leftovers: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.file_name().to_string_lossy().into_owned()))
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

/// Issue 31 item 11: `plant analyze` took a trace longer than its scene (another run's, or a
/// `scene.toml` edited since) and analysed it against this scene's duration. A row past the
/// scene's end is refused (exit 2), naming the file, the line, its time and the scene's
/// duration; nothing is written. The trace of the scene's own length still reads.
#[test]
fn analyze_refuses_a_trace_longer_than_its_scene() {
    let dir = TempDir::new("outputs-analyze-longer");
    let out = dir.join("run");
    short_run(&out, false);
    let scene_text = std::fs::read_to_string(out.join("scene.toml")).unwrap();
    let at = scene_text.lines().filter(|l| l.trim_start().starts_with("duration_s = ")).count();
    assert_eq!(at, 1, "scene.toml has one duration_s:\n{scene_text}");
    let line = scene_text.lines().find(|l| l.trim_start().starts_with("duration_s = ")).unwrap();
    assert_eq!(line.trim(), "duration_s = 0.05", "{scene_text}");
    std::fs::write(out.join("scene.toml"), scene_text.replace(line, "duration_s = 0.03")).unwrap();
    // The first row past 0.03 s, counted from the trace itself (header on line 1).
    let times = Csv::read(&out.join("trace.csv")).column("t_s");
    let first = times.iter().position(|t| *t > 0.03 + 1e-9).expect("rows past 0.03 s");
    let summary = std::fs::read(out.join("summary.json")).unwrap();
    let o = analyze(&out);
    assert_exit(&o, 2);
    let err = stderr(&o);
    assert!(err.contains("trace.csv") && err.contains(&format!("line {}, column t_s", first + 2)), "{err}");
    assert!(err.contains("past the end of the scene") && err.contains("scene.duration_s = 0.03 s"), "{err}");
    assert!(err.contains(&format!("{:e}", times[first])), "{err}");
    assert_eq!(std::fs::read(out.join("summary.json")).unwrap(), summary, "summary.json rewritten");
    std::fs::write(out.join("scene.toml"), &scene_text).unwrap();
    assert_exit(&analyze(&out), 0);
}

#[test]
fn a_reused_out_folder_keeps_no_file_of_the_previous_run() {
    let dir = TempDir::new("outputs-reuse");
    let out = dir.join("run");
    short_run(&out, true);
    for f in ["orbit.png", "radius.png", "poincare.png"] {
        assert!(out.join(f).is_file(), "{f} missing after the first run");
    }
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    short_run(&out, false);
    let names: Vec<String> =
        std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert!(names.iter().all(|n| !n.ends_with(".png")), "charts of the first run kept: {names:?}");
    // Only what a run writes is removed.
    assert_eq!(std::fs::read_to_string(out.join("notes.txt")).unwrap(), "mine");
}

#[test]
fn a_diverged_run_reports_maxima_before_the_failure_and_the_failing_state() {
    let dir = TempDir::new("outputs-diverged");
    let out = dir.join("run");
    let o = output_within(&mut plant_run(&scene("paper-printed-magnetics.toml"), &out, &["output.plots=false"]), LIMIT);
    assert_exit(&o, 3);
    let s = read_json(&out.join("summary.json"));
    assert_eq!(s["status"], "diverged");
    let failed = num(&s, "failure_time_s");
    // Independent of the plant's reader: the largest radius over the rows before the failure.
    let trace = Csv::read(&out.join("trace.csv"));
    let (t, x, y) = (trace.column("t_s"), trace.column("dx_m"), trace.column("dy_m"));
    let before = (0..t.len()).filter(|&i| t[i] < failed).map(|i| x[i].hypot(y[i])).fold(0.0, f64::max);
    let at = (0..t.len()).filter(|&i| t[i] >= failed).map(|i| x[i].hypot(y[i])).fold(0.0, f64::max);
    assert_eq!(num(&s, "max_radius_m"), before);
    assert!(at > before, "the failing row should be the largest: {at} vs {before}");
    // The guard: air gap + ball clearance + radius_guard_mm = 0.15 + 0.01 + 0.5 mm.
    let guard = 0.66e-3;
    assert!(num(&s, "max_radius_m") < guard, "{s:#}");
    let fs = &s["failure_state"];
    assert_eq!(num(fs, "t_s"), failed);
    assert!(num(fs, "rotor_radius_m") > guard, "{fs:#}");
    assert!((num(fs, "rotor_radius_m") - at).abs() <= 1e-12 * at, "{fs:#} vs {at}");
}

#[test]
fn a_divergence_at_t0_exits_3_with_its_time_and_state() {
    let dir = TempDir::new("outputs-diverged-t0");
    let out = dir.join("run");
    // A rotor started a metre off-centre: the step size collapses at t = 0.
    let o = output_within(&mut plant_run(&scene("paper-10g.toml"), &out, &["initial.rotor_x_um=1e6"]), LIMIT);
    assert_exit(&o, 3);
    let err = stderr(&o);
    assert!(err.contains("at t = 0 s") && err.contains("[0.99") && err.contains("numerical divergence"), "{err}");
    let s = read_json(&out.join("summary.json"));
    assert_eq!(s["status"], "diverged");
    assert_eq!(num(&s, "failure_time_s"), 0.0);
    assert!(s["error"].as_str().unwrap_or_default().contains("at t = 0 s"), "{s:#}");
    // Issue 21 item 7: the run reached t = 0, not the end of the failing macro step (the
    // report said "results up to t = 0.00005 s", one sample off), and no row came before the
    // failure, so there is no largest radius (it said 0.0).
    assert_eq!(num(&s, "simulated_s"), 0.0, "{s:#}");
    assert!(err.contains("results up to t = 0 s were written"), "{err}");
    for key in ["max_radius_m", "max_contact_force_n", "max_race_speed_rpm"] {
        assert!(s[key].is_null(), "{key}: {s:#}");
    }
}

#[test]
fn run_charts_show_the_data() {
    let dir = TempDir::new("outputs-charts");
    let out = dir.join("run");
    short_run(&out, true);
    // Each chart holds its first series, drawn in the first palette colour, over many pixels
    // of its plotting region: a blank or axes-only chart fails.
    for (chart, min_pixels) in
        [("orbit.png", 300), ("radius.png", 1000), ("currents.png", 1000), ("race_speed.png", 500)]
    {
        let png = Png::read(&out.join(chart));
        let n = png.count_in_plot(SERIES_BLUE);
        assert!(n >= min_pixels, "{chart}: {n} pixels of the data colour");
    }
}

/// Two commands on one `--out` at once used to mix their files (one run's `summary.json`
/// beside the other's `trace.csv`, both exit 0). The first run here holds its folder while it
/// waits for an external controller that never comes; a second `plant run` and a `plant
/// analyze` on that folder are refused with exit 2 naming the holder, and leave the folder as
/// the first run wrote it; the first, interrupted, writes its own summary.
#[test]
fn a_folder_in_use_by_a_live_run_is_refused_to_a_second_command() {
    let dir = TempDir::new("claimed-out");
    let out = dir.join("run");
    let id = format!("claim{}", std::process::id());
    let mut cmd = plant_run(&scene("cosim-10g.toml"), &out, &["controller.connect_timeout_ms=120000"]);
    cmd.args(["--controller", "external", "--run-id", &id]);
    let mut first = Proc::spawn(&mut cmd);
    let deadline = std::time::Instant::now() + LIMIT;
    while !out.join("scene.toml").exists() {
        assert!(std::time::Instant::now() < deadline, "the first run never prepared its folder");
        assert!(first.running(), "the first run ended before the test could start");
        std::thread::sleep(Duration::from_millis(20));
    }
    let scene_before = std::fs::read(out.join("scene.toml")).unwrap();

    let second = output_within(&mut plant_run(&scene("paper-3g.toml"), &out, &["scene.duration_s=0.01"]), LIMIT);
    assert_exit(&second, 2);
    let err = stderr(&second);
    assert!(err.contains("in use by a live process") && err.contains(&format!("pid {}", first.id())), "{err}");
    let analyzed = analyze(&out);
    assert_exit(&analyzed, 2);
    assert!(stderr(&analyzed).contains("in use by a live process"), "{}", stderr(&analyzed));
    assert_eq!(std::fs::read(out.join("scene.toml")).unwrap(), scene_before, "the second run touched the folder");

    first.signal(libc::SIGINT);
    let (code, log) = first.finish_within(LIMIT);
    assert_eq!(code, Some(130), "{log}");
    let summary = read_json(&out.join("summary.json"));
    assert_eq!(summary["scene"], "cosim-10g", "{summary:#}");
    assert_eq!(summary["status"], "interrupted", "{summary:#}");
    // The folder is free again.
    let again = analyze(&out);
    assert!(!stderr(&again).contains("in use"), "{}", stderr(&again));
}

/// A run killed by SIGKILL between two writes of its trace leaves a `trace.csv` of whole
/// rows that `plant analyze` reads: rows reach the file in whole-row chunks (a byte-counting
/// buffer used to leave a row cut in the middle, which the strict reader rightly refuses).
/// A kill that lands during a chunk's write can still cut it (row_file.rs): the test kills
/// once the file has stopped growing, not at the moment it grows.
#[test]
fn a_run_killed_with_sigkill_leaves_whole_rows_that_analyze_reads() {
    let dir = TempDir::new("killed-run");
    for (i, bytes) in [150_000u64, 400_000, 700_000].into_iter().enumerate() {
        let out = dir.join(&format!("run{i}"));
        let mut cmd = plant_run(&scene("paper-10g.toml"), &out, &["scene.duration_s=60", "output.plots=false"]);
        let mut run = Proc::spawn(&mut cmd);
        let trace = out.join("trace.csv");
        let deadline = std::time::Instant::now() + LIMIT;
        while std::fs::metadata(&trace).map_or(0, |m| m.len()) < bytes {
            assert!(
                std::time::Instant::now() < deadline && run.running(),
                "the run did not write {bytes} bytes of trace in time"
            );
            std::thread::sleep(Duration::from_millis(5));
        }
        // Between two writes: the size unchanged over 20 ms (writes come tenths of a second
        // apart and last microseconds).
        let mut size = std::fs::metadata(&trace).map_or(0, |m| m.len());
        loop {
            std::thread::sleep(Duration::from_millis(20));
            let now = std::fs::metadata(&trace).map_or(0, |m| m.len());
            if now == size {
                break;
            }
            size = now;
        }
        run.signal(libc::SIGKILL);
        let (code, _) = run.finish_within(LIMIT);
        assert_eq!(code, None, "run {i}: not ended by SIGKILL");
        let text = std::fs::read_to_string(&trace).unwrap();
        assert!(text.ends_with('\n'), "run {i}: trace.csv ends inside a row");
        assert!(text.lines().all(|l| l.split(',').count() == 19), "run {i}: a ragged row");
        let analyzed = analyze(&out);
        assert_exit(&analyzed, 0);
    }
}

/// Issue 21 item 7: a SIGINT or SIGTERM that came while a run wrote its outputs was
/// swallowed (exit 0, `completed`, 9 of 9). Signalled once `summary.json` is written (the
/// charts come after it), the run still writes every output, says `interrupted` and exits 130.
#[cfg(unix)]
#[test]
fn a_signal_while_the_outputs_are_written_gives_130() {
    let dir = TempDir::new("outputs-late-signal");
    let out = dir.join("run");
    let sets = ["scene.duration_s=0.05", "shock[0].start_s=0.01", "output.plots=true"];
    let run = Proc::spawn(&mut plant_run(&scene("paper-3g.toml"), &out, &sets));
    let summary = out.join("summary.json");
    let deadline = std::time::Instant::now() + LIMIT;
    while !summary.exists() {
        assert!(std::time::Instant::now() < deadline, "no summary.json");
        std::thread::sleep(Duration::from_millis(1));
    }
    run.signal(libc::SIGTERM);
    let (code, log) = run.finish_within(LIMIT);
    assert_eq!(code, Some(130), "{log}");
    let s = read_json(&summary);
    assert_eq!(s["status"], "interrupted", "{s:#}");
    assert_eq!(num(&s, "simulated_s"), 0.05, "the run itself reached its end");
    for chart in ["orbit.png", "radius.png", "currents.png", "spectrum.png"] {
        assert!(out.join(chart).is_file(), "{chart}: nothing already written is lost");
    }
}
