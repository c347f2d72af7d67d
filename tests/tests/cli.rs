//! End-to-end tests of the `plant run` command line: the files a run writes,
//! how `--set` overrides reach the run, exit codes and messages for bad
//! input (2), divergence (3) and SIGINT/SIGTERM (130), determinism, and
//! agreement of the plant's housing motion with the `shock-table` binary.
//!
//! Every run is a short slice of the study's 10 G scene (`paper-10g.toml`,
//! 50–80 ms with the shock moved to 10 ms) so the file runs in seconds in
//! a debug build. Expectations come from the scene's inputs (duration,
//! rates, overrides) or are recomputed here from `trace.csv`, never read
//! back from the figures under test.

mod common;

use common::{
    assert_exit, num, output_within, plant_run, read_json, scene, shock_table_bin, stderr, Csv, Png, TempDir,
    SERIES_BLUE, SHORT,
};
use std::process::Command;

/// One short run (or a `shock-table` call) in a debug build on a loaded machine: a hang fails.
const RUN: std::time::Duration = std::time::Duration::from_secs(300);

/// The columns every trace must carry.
const TRACE_COLUMNS: &[&str] =
    &["t_s", "dx_m", "dy_m", "xb_m", "yb_m", "race_speed_rad_s", "contact_force_n", "ix_a", "iy_a", "housing_y_m"];

/// Asserts `actual` is within `tol` of `expected`.
fn assert_close(actual: f64, expected: f64, tol: f64, what: &str) {
    assert!((actual - expected).abs() <= tol, "{what}: {actual} differs from {expected} by more than {tol}");
}

/// Asserts a trace holds rows `0, dt, 2 dt, …` up to `end` (s): the row
/// count is `end / dt + 1` within one row, times start at zero, increase
/// strictly by `dt`, and the last row is at `end`.
fn assert_sampled_up_to(trace: &Csv, end: f64, rate_hz: f64) {
    let t = trace.column("t_s");
    let dt = 1.0 / rate_hz;
    let expected_rows = end * rate_hz + 1.0;
    assert!(
        (t.len() as f64 - expected_rows).abs() <= 1.0,
        "{} rows for {end} s at {rate_hz} Hz, expected {expected_rows} ± 1",
        t.len()
    );
    assert_eq!(t[0], 0.0, "the first row is not at t = 0");
    for (i, w) in t.windows(2).enumerate() {
        assert!(w[1] > w[0], "times not increasing at row {}: {} then {}", i + 1, w[0], w[1]);
        assert_close(w[1] - w[0], dt, 1e-9 * dt, &format!("spacing at row {}", i + 1));
    }
    assert_close(*t.last().unwrap(), end, 1e-9 * dt, "time of the last row");
}

#[test]
fn run_writes_trace_summary_scene_and_plots() {
    let (duration, rate) = (0.05, 20_000.0);
    let dir = TempDir::new("writes");
    // A folder that does not exist yet, two levels deep: the run creates it.
    let out = dir.join("nested/run");
    let run = output_within(
        &mut plant_run(
            &scene("paper-10g.toml"),
            &out,
            &["scene.duration_s=0.05", "shock[0].start_s=0.01", "output.rate_hz=20000", "output.plots=true"],
        ),
        RUN,
    );
    assert_exit(&run, 0);

    let trace = Csv::read(&out.join("trace.csv"));
    for col in TRACE_COLUMNS {
        assert!(trace.header.iter().any(|h| h == col), "trace.csv lacks column {col}: {:?}", trace.header);
    }
    assert_sampled_up_to(&trace, duration, rate);
    for (c, name) in trace.header.iter().enumerate() {
        assert!(trace.rows.iter().all(|r| r[c].is_finite()), "non-finite value in column {name} of a completed run");
    }

    let summary = read_json(&out.join("summary.json"));
    assert_eq!(summary["status"], "completed", "{summary:#}");
    for key in [
        "max_radius_m",
        "contact_fraction",
        "max_contact_force_n",
        "max_race_speed_rpm",
        "wall_time_s",
        "realtime_factor",
    ] {
        assert!(num(&summary, key).is_finite(), "`{key}` is not finite in {summary:#}");
    }
    for key in ["steps", "rhs_evals"] {
        assert!(summary[key].as_u64().is_some_and(|n| n > 0), "`{key}` is not a positive count in {summary:#}");
    }
    for key in ["model", "integrator"] {
        assert!(summary[key].is_object(), "`{key}` is not an object in {summary:#}");
    }
    assert_close(num(&summary, "simulated_s"), duration, 1e-12, "simulated_s");
    let wall = num(&summary, "wall_time_s");
    assert!(wall > 0.0, "wall_time_s = {wall}");
    assert_close(num(&summary, "realtime_factor"), duration / wall, 1e-9 * duration / wall, "realtime_factor");

    // scene.toml is the resolved scene: a valid scene file carrying the overrides.
    let resolved: toml::Table = std::fs::read_to_string(out.join("scene.toml")).unwrap().parse().unwrap();
    assert_eq!(resolved["scene"]["duration_s"].as_float(), Some(duration));
    assert_eq!(resolved["shock"][0]["start_s"].as_float(), Some(0.01));

    // Each chart is a PNG with its data drawn (the first series' colour over many pixels of
    // the plotting region): a blank or axes-only chart fails.
    for (png, min_pixels) in [("orbit.png", 300), ("radius.png", 1000), ("race_speed.png", 500), ("currents.png", 1000)]
    {
        let n = Png::read(&out.join(png)).count_in_plot(SERIES_BLUE);
        assert!(n >= min_pixels, "{png}: {n} pixels of the data colour");
    }
}

#[test]
fn summary_max_radius_matches_trace() {
    let dir = TempDir::new("max-radius");
    let out = dir.join("run");
    assert_exit(&output_within(&mut plant_run(&scene("paper-10g.toml"), &out, SHORT), RUN), 0);
    let trace = Csv::read(&out.join("trace.csv"));
    let summary = read_json(&out.join("summary.json"));

    let (dx, dy) = (trace.column("dx_m"), trace.column("dy_m"));
    let radius = dx.iter().zip(&dy).map(|(x, y)| x.hypot(*y)).fold(0.0, f64::max);
    assert_close(num(&summary, "max_radius_m"), radius, 1e-12 * radius, "max_radius_m");
    // The 10 G shock must drive the rotor across the 0.15 mm air gap, or this
    // scene does not exercise the contact figures below.
    assert!(radius > 0.15e-3, "max radius {radius} m never reaches the air gap");

    let force = trace.column("contact_force_n");
    let max_force = force.iter().copied().fold(0.0, f64::max);
    assert_close(num(&summary, "max_contact_force_n"), max_force, 1e-12 * max_force, "max_contact_force_n");

    let rpm =
        trace.column("race_speed_rad_s").iter().map(|w| w.abs() * 60.0 / std::f64::consts::TAU).fold(0.0, f64::max);
    assert_close(num(&summary, "max_race_speed_rpm"), rpm, 1e-9 * rpm, "max_race_speed_rpm");

    // 50 ms is shorter than the 200-revolution steady window (0.4 s at
    // 500 Hz), so the window is the whole run.
    let in_contact = force.iter().filter(|f| **f > 0.0).count() as f64 / force.len() as f64;
    assert_close(num(&summary, "contact_fraction"), in_contact, 1e-12, "contact_fraction");
}

/// The damping ratio of a free decay from its successive peaks (log decrement), on the rows
/// of `x`.
fn damping_of_decay(t: &[f64], x: &[f64]) -> f64 {
    let peaks: Vec<(f64, f64)> =
        (1..x.len() - 1).filter(|&i| x[i] > x[i - 1] && x[i] >= x[i + 1] && x[i] > 0.0).map(|i| (t[i], x[i])).collect();
    assert!(peaks.len() >= 4, "too few peaks: {peaks:?}");
    let n = (peaks.len() - 1) as f64;
    let delta = (peaks[0].1 / peaks[peaks.len() - 1].1).ln() / n;
    delta / (4.0 * std::f64::consts::PI.powi(2) + delta * delta).sqrt()
}

#[test]
fn set_override_changes_the_run() {
    let dir = TempDir::new("override");
    let paper = scene("paper-10g.toml");
    let run = |name: &str, sets: &[&str]| {
        let out = dir.join(name);
        assert_exit(&output_within(&mut plant_run(&paper, &out, sets), RUN), 0);
        out
    };
    // A free decay (no unbalance, a 20 µm offset, the shock after the end): the override of
    // the damping ratio reaches the dynamics, as the log decrement of the rotor's decay shows.
    let decay = ["scene.duration_s=0.12", "shock[0].start_s=1", "rotor.eccentricity_um=0", "initial.rotor_x_um=20"];
    for (name, xi) in [("decay-base", 0.01), ("decay-damped", 0.02)] {
        let mut sets: Vec<String> = decay.iter().map(|s| s.to_string()).collect();
        sets.push("output.plots=false".into());
        if xi != 0.01 {
            sets.push(format!("controller.damping_ratio={xi}"));
        }
        let out = run(name, &sets.iter().map(String::as_str).collect::<Vec<_>>());
        let resolved: toml::Table = std::fs::read_to_string(out.join("scene.toml")).unwrap().parse().unwrap();
        assert_eq!(resolved["controller"]["damping_ratio"].as_float(), Some(xi), "the resolved scene's ratio");
        let trace = Csv::read(&out.join("trace.csv"));
        let measured = damping_of_decay(&trace.column("t_s"), &trace.column("dx_m"));
        assert!((measured - xi).abs() < 0.03 * xi, "{name}: damping ratio {measured}, set {xi}");
    }

    // Half the output rate: half the intervals, sampling the same motion.
    let base = run("base", SHORT);
    let sets: Vec<&str> = SHORT.iter().copied().chain(["output.rate_hz=10000"]).collect();
    let coarse = run("coarse", &sets);
    let base_trace = Csv::read(&base.join("trace.csv"));
    let coarse_trace = Csv::read(&coarse.join("trace.csv"));
    assert_eq!(
        coarse_trace.rows.len() - 1,
        (base_trace.rows.len() - 1) / 2,
        "rows at 10 kHz ({}) vs 20 kHz ({})",
        coarse_trace.rows.len(),
        base_trace.rows.len()
    );
    assert_sampled_up_to(&coarse_trace, 0.05, 10_000.0);
    let (t, dx, dy) = (base_trace.column("t_s"), base_trace.column("dx_m"), base_trace.column("dy_m"));
    let (ct, cdx, cdy) = (coarse_trace.column("t_s"), coarse_trace.column("dx_m"), coarse_trace.column("dy_m"));
    for i in 0..ct.len() {
        assert_close(ct[i], t[2 * i], 1e-12, "time of a shared row");
        assert_close(cdx[i], dx[2 * i], 1e-9, &format!("dx_m at t = {}", ct[i]));
        assert_close(cdy[i], dy[2 * i], 1e-9, &format!("dy_m at t = {}", ct[i]));
    }
}

/// Runs `plant run <scene> --set …` expecting bad input: exit 2, no panic,
/// nothing written, and every needle in the message.
fn assert_bad_input(name: &str, scene_file: &std::path::Path, sets: &[&str], needles: &[&str]) {
    let dir = TempDir::new(name);
    let out = dir.join("run");
    let run = output_within(&mut plant_run(scene_file, &out, sets), RUN);
    let err = stderr(&run);
    assert_exit(&run, 2);
    assert!(!err.contains("panicked"), "bad input made the plant panic:\n{err}");
    for needle in needles {
        assert!(err.contains(needle), "the message does not mention {needle:?}:\n{err}");
    }
    assert!(!out.exists(), "bad input still created the output folder {}", out.display());
}

#[test]
fn unknown_key_exits_2_naming_the_key() {
    assert_bad_input("unknown-key", &scene("paper-10g.toml"), &["rotor.bogus=1"], &["bogus", "rotor"]);
}

#[test]
fn out_of_range_value_exits_2_naming_key_value_and_unit() {
    assert_bad_input(
        "out-of-range",
        &scene("paper-10g.toml"),
        &["touchdown.air_gap_mm=-1"],
        &["touchdown.air_gap_mm", "-1", "mm"],
    );
}

#[test]
fn relev_rule_out_of_order_exits_2_naming_both_radii() {
    assert_bad_input(
        "relev-radii",
        &scene("relev-10g.toml"),
        &["controller.params.exit_um=200"],
        &["law relev", "controller.params.exit_um", "200", "µm", "controller.params.enter_um = 120"],
    );
}

#[test]
fn unknown_law_exits_2_listing_known_laws() {
    let mut needles = vec!["nope", "pd"];
    needles.extend(controller::law_names());
    assert_bad_input("unknown-law", &scene("paper-10g.toml"), &["controller.law=nope"], &needles);
}

#[test]
fn malformed_toml_file_exits_2_naming_file_and_line() {
    let dir = TempDir::new("malformed-toml");
    let file = dir.join("broken.toml");
    std::fs::write(&file, "[scene\nduration_s = 0.05\n").unwrap();
    assert_bad_input("malformed-toml-run", &file, &[], &[&file.display().to_string(), "line 1"]);
}

#[test]
fn missing_scene_file_exits_2_naming_the_file() {
    let dir = TempDir::new("missing-file");
    let file = dir.join("no-such-scene.toml");
    assert_bad_input("missing-file-run", &file, &[], &[&file.display().to_string()]);
}

#[test]
fn bad_shock_exits_2_naming_key_value_and_unit() {
    assert_bad_input("bad-shock", &scene("paper-10g.toml"), &["shock[0].f2_hz=-3"], &["shock[0]", "f2_hz", "-3", "Hz"]);
}

#[test]
fn bad_race_when_clear_exits_2_naming_key_and_value() {
    assert_bad_input(
        "bad-race-when-clear",
        &scene("paper-3g.toml"),
        &["touchdown.race_when_clear=\"asleep\""],
        &["touchdown.race_when_clear", "asleep", "parked"],
    );
}

#[test]
fn malformed_set_exits_2_naming_the_argument() {
    assert_bad_input("malformed-set", &scene("paper-10g.toml"), &["novalue"], &["--set", "novalue", "KEY=VALUE"]);
}

/// Regression: a key added by `--set` is reported as an error of the scene
/// file, which does not contain it (`config/paper-10g.toml: unknown field
/// `bogus` … in `rotor``), sending the user to look in the wrong place.
#[test]
fn unknown_key_from_set_is_blamed_on_set() {
    assert_bad_input("unknown-key-set", &scene("paper-10g.toml"), &["rotor.bogus=1"], &["--set", "rotor.bogus"]);
}

#[test]
fn divergence_exits_3_with_time_and_state() {
    // Explicit Euler is unstable for any undamped oscillator, and one step
    // per 0.5 ms controller period (2 kHz, 1 substep) is far beyond the
    // period of the stiff ball/rotor–race contacts the 10 G shock drives the
    // rotor into: the state blows up within a few steps of the first impact.
    let (rate, duration) = (20_000.0, 0.05);
    let dir = TempDir::new("diverge");
    let out = dir.join("run");
    let sets: Vec<&str> = SHORT
        .iter()
        .copied()
        .chain(["integrator.method=explicit_euler", "integrator.substeps=1", "controller.rate_hz=2000"])
        .chain(["output.rate_hz=20000"])
        .collect();
    let run = output_within(&mut plant_run(&scene("paper-10g.toml"), &out, &sets), RUN);
    let err = stderr(&run);
    assert_exit(&run, 3);
    assert!(!err.contains("panicked"), "divergence made the plant panic:\n{err}");
    assert!(err.contains("t = "), "the message does not name the time:\n{err}");
    assert!(err.contains("state"), "the message does not give the state:\n{err}");

    let summary = read_json(&out.join("summary.json"));
    assert_eq!(summary["status"], "diverged", "{summary:#}");
    let failed = num(&summary, "failure_time_s");
    assert!(failed > 0.0 && failed < duration, "failure_time_s = {failed} outside (0, {duration})");
    assert_close(num(&summary, "simulated_s"), failed, 1e-12, "simulated_s of a diverged run");
    assert!(err.contains(&format!("t = {failed}")), "the message does not name t = {failed}:\n{err}");

    let trace = Csv::read(&out.join("trace.csv"));
    assert_sampled_up_to(&trace, failed, rate);
}

#[test]
fn deterministic_runs_give_identical_traces() {
    let dir = TempDir::new("determinism");
    let mut traces = Vec::new();
    for mode in ["continuous", "sampled"] {
        let set_mode = format!("controller.mode={mode}");
        let sets: Vec<&str> = SHORT.iter().copied().chain([set_mode.as_str()]).collect();
        let mut pair = Vec::new();
        for attempt in ["a", "b"] {
            let out = dir.join(&format!("{mode}-{attempt}"));
            assert_exit(&output_within(&mut plant_run(&scene("paper-10g.toml"), &out, &sets), RUN), 0);
            assert_eq!(read_json(&out.join("summary.json"))["model"]["control_mode"], mode);
            pair.push(std::fs::read(out.join("trace.csv")).unwrap());
        }
        assert!(pair[0] == pair[1], "two {mode} runs of the same scene wrote different traces");
        traces.push(pair.swap_remove(0));
    }
    // Guards the test itself: the mode override must have changed the run.
    assert!(traces[0] != traces[1], "continuous and sampled runs wrote the same trace");
}

/// Starts a 20 s run, waits for its first progress line (printed after
/// about one second of running, so the signal handler is in place), sends
/// `signal`, and checks the run stops with code 130 and writes its results
/// up to the time reached.
#[cfg(unix)]
fn assert_signal_flushes_results(name: &str, signal: libc::c_int) {
    use std::io::BufRead;
    use std::process::Stdio;
    use std::time::{Duration, Instant};

    let (duration, rate) = (20.0, 20_000.0);
    let dir = TempDir::new(name);
    let out = dir.join("run");
    let mut child = plant_run(
        &scene("paper-10g.toml"),
        &out,
        &["scene.duration_s=20", "output.rate_hz=20000", "output.plots=false"],
    )
    .stdout(Stdio::null())
    .stderr(Stdio::piped())
    .spawn()
    .expect("starting plant");
    let pipe = child.stderr.take().expect("piped stderr");
    let (tx, rx) = std::sync::mpsc::channel();
    let reader = std::thread::spawn(move || {
        for line in std::io::BufReader::new(pipe).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });

    let mut log = Vec::new();
    let deadline = Instant::now() + Duration::from_secs(60);
    let progress_t = loop {
        match rx.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
            Ok(line) => {
                let t = line.strip_prefix("plant: t = ").and_then(|rest| rest.split('/').next()?.parse::<f64>().ok());
                log.push(line);
                if let Some(t) = t {
                    break t;
                }
            }
            Err(_) => {
                let _ = child.kill();
                let _ = child.wait();
                panic!("no progress line from the plant within 60 s:\n{}", log.join("\n"));
            }
        }
    };
    assert!(child.try_wait().unwrap().is_none(), "the run ended before the signal:\n{}", log.join("\n"));

    let pid = libc::pid_t::try_from(child.id()).expect("pid fits pid_t");
    // SAFETY: kill(2) has no memory-safety preconditions; `pid` is our own
    // child, not yet waited for, so it cannot have been reused.
    assert_eq!(unsafe { libc::kill(pid, signal) }, 0, "kill({pid}, {signal}) failed");
    let deadline = Instant::now() + Duration::from_secs(30);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("the plant did not stop within 30 s of signal {signal}");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    reader.join().unwrap();
    log.extend(rx.try_iter());
    let log = log.join("\n");
    assert_eq!(status.code(), Some(130), "exit status {status} after signal {signal}; stderr:\n{log}");
    assert!(log.contains("interrupted"), "no word of the interruption on stderr:\n{log}");

    let summary = read_json(&out.join("summary.json"));
    assert_eq!(summary["status"], "interrupted", "{summary:#}");
    let reached = num(&summary, "simulated_s");
    // The progress line rounds t to 1 ms.
    assert!(
        reached >= progress_t - 0.5e-3 && reached < duration,
        "simulated_s = {reached}, expected in [{progress_t} - 0.5 ms, {duration}) (the progress line had shown {progress_t} s)"
    );
    assert_sampled_up_to(&Csv::read(&out.join("trace.csv")), reached, rate);
}

#[cfg(unix)]
#[test]
fn sigint_flushes_results() {
    assert_signal_flushes_results("sigint", libc::SIGINT);
}

#[cfg(unix)]
#[test]
fn sigterm_flushes_results() {
    assert_signal_flushes_results("sigterm", libc::SIGTERM);
}

#[test]
fn shock_table_cli_agrees_with_plant_housing_lift() {
    // The 10 G pulse (t1 + t2 ≈ 56 ms) starting at 10 ms is over by 80 ms;
    // after it the housing rests at its lift h.
    let (start, duration) = (0.01, 0.08);
    let dir = TempDir::new("lift");
    let out = dir.join("run");
    let run = output_within(
        &mut plant_run(
            &scene("paper-10g.toml"),
            &out,
            &["scene.duration_s=0.08", "shock[0].start_s=0.01", "output.plots=false"],
        ),
        RUN,
    );
    assert_exit(&run, 0);

    let table = output_within(Command::new(shock_table_bin()).args(["table", "--peaks-g", "10", "--json"]), RUN);
    assert_exit(&table, 0);
    let table: serde_json::Value = serde_json::from_slice(&table.stdout).expect("shock-table printed JSON");
    let row = &table["rows"][0];
    assert_eq!(num(row, "a1_g"), 10.0, "{table:#}");
    let pulse_end = start + num(row, "t1_s") + num(row, "t2_s");
    assert!(pulse_end < duration, "the pulse ends at {pulse_end} s, after the run");
    let lift = num(row, "h_mm") * 1e-3;

    let trace = Csv::read(&out.join("trace.csv"));
    let (t, hx, hy) = (trace.column("t_s"), trace.column("housing_x_m"), trace.column("housing_y_m"));
    assert_close(*t.last().unwrap(), duration, 1e-12, "time of the last row");
    assert_close(*hy.last().unwrap(), lift, 1e-9, "final housing_y_m vs shock-table's h");
    // The shock is along +y (direction 90°) and starts at `start`.
    assert!(hx.iter().all(|x| x.abs() < 1e-12), "the housing moved along x");
    assert!(
        t.iter().zip(&hy).filter(|(t, _)| **t <= start).all(|(_, y)| *y == 0.0),
        "the housing moved before the shock started"
    );
}
