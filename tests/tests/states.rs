//! `plant run --save-state-at` and `--from-state`: a run continued from a saved state writes
//! the rows of the run that never stopped, with the controller in the plant's process and in a
//! controller process (lockstep); another controller may take over from the same state; bad
//! snapshots and bad times are refused naming the file or the flag, exit 2, nothing written.

mod common;
#[path = "common/edits.rs"]
mod edits;

use common::*;
use std::path::Path;

/// The data lines of a `trace.csv` (the header dropped).
fn rows(dir: &Path) -> Vec<String> {
    read_text(&dir.join("trace.csv")).lines().skip(1).map(str::to_owned).collect()
}

fn header(dir: &Path) -> String {
    read_text(&dir.join("trace.csv")).lines().next().unwrap_or_default().to_owned()
}

/// A lockstep run killed at any point can be continued from its last snapshot: the
/// continuation's rows are the uninterrupted run's after the snapshot, byte for byte, and the
/// snapshot names its own time; a sampled run on the two-plane rotor likewise.
#[test]
fn a_run_continued_from_a_saved_state_writes_the_rows_of_the_run_that_never_stopped() {
    let tmp = TempDir::new("states-continue");
    for (scene, sets) in [
        ("cosim-10g.toml", vec!["scene.duration_s=0.06", "shock[0].start_s=0.01", "output.plots=false"]),
        (
            "two-plane-asymmetric-10g.toml",
            vec!["scene.duration_s=0.05", "shock[0].start_s=0.01", "output.plots=false", "controller.mode=\"sampled\""],
        ),
    ] {
        let whole = tmp.join(&format!("{scene}-whole"));
        let mut cmd = plant_run(&scene_path(scene), &whole, &sets);
        cmd.args(["--save-state-at", "0.02,0.0301"]);
        let out = output(&mut cmd);
        assert_exit(&out, 0);
        for (t, file) in [(0.02, "state-0.02.json"), (0.0301, "state-0.0301.json")] {
            let snap = read_json(&whole.join(file));
            let at = num(&snap, "t_s");
            assert!(at >= t && at < t + 5e-5 + 1e-12, "{file}: saved at {at} s for {t} s");
            let rest = tmp.join(&format!("{scene}-from-{t}"));
            let mut cmd = plant_run(&scene_path(scene), &rest, &sets);
            cmd.arg("--from-state").arg(whole.join(file));
            let out = output(&mut cmd);
            assert_exit(&out, 0);
            let (all, tail) = (rows(&whole), rows(&rest));
            assert_eq!(header(&whole), header(&rest));
            assert!(!tail.is_empty() && tail.len() < all.len());
            assert_eq!(&all[all.len() - tail.len()..], &tail[..], "{scene} from {file}");
            let first_t: f64 = tail[0].split(',').next().unwrap().parse().unwrap();
            assert!(first_t > at, "the continuation starts after the state's time");
        }
    }
}

fn scene_path(name: &str) -> std::path::PathBuf {
    workspace_root().join("config").join(name)
}

/// From one saved state, another law and other gains take over (the re-levitation question);
/// the rows before the state's time are not written again.
#[test]
fn another_controller_takes_over_from_a_saved_state() {
    let tmp = TempDir::new("states-takeover");
    let sets = ["scene.duration_s=0.04", "shock[0].start_s=0.005", "output.plots=false", "controller.mode=\"sampled\""];
    let whole = tmp.join("whole");
    let mut cmd = plant_run(&scene_path("cosim-10g.toml"), &whole, &sets);
    cmd.args(["--save-state-at", "0.02"]);
    assert_exit(&output(&mut cmd), 0);
    let state = whole.join("state-0.02.json");
    let mut tails = Vec::new();
    for extra in [&["controller.law=\"relev\""][..], &["controller.law=\"pd\"", "controller.stiffness_n_per_m=2e6"][..]]
    {
        let out_dir = tmp.join(&format!("from-{}", tails.len()));
        let mut all = sets.to_vec();
        all.extend_from_slice(extra);
        let mut cmd = plant_run(&scene_path("cosim-10g.toml"), &out_dir, &all);
        cmd.arg("--from-state").arg(&state);
        let out = output(&mut cmd);
        assert_exit(&out, 0);
        let summary = read_json(&out_dir.join("summary.json"));
        assert_eq!(summary["status"], "completed");
        // 20 ms after the state is within the takeover's settling (50 revolutions, 0.1 s): the
        // grade covers every row after the start, and the run says so.
        let takeover = &summary["takeover"];
        assert_eq!(takeover["settled"], false, "{takeover}");
        assert!(num(takeover, "first_row_s") > 0.02 && (num(takeover, "settle_s") - 0.1).abs() < 1e-12, "{takeover}");
        assert!(summary.get("recovery_from_start_s").is_some(), "{summary}");
        let said = format!("{}{}", String::from_utf8_lossy(&out.stdout), stderr(&out));
        assert!(said.contains("the run ended within its 0.100 s of settling"), "{said}");
        let started = num(&summary, "started_s");
        assert!((started - 0.02).abs() < 5e-5, "started_s {started}");
        // The figures cover the time from the state on.
        assert!(num(&summary, "contact_time_s") <= 0.04 - started + 1e-12);
        tails.push(rows(&out_dir));
    }
    assert_eq!(tails[0].len(), tails[1].len());
    assert_ne!(tails[0], tails[1], "another law gives another continuation");
}

/// Bad snapshots and bad times: exit 2, the message names the file or the flag and the
/// difference, and the output folder is not created.
#[test]
fn bad_states_and_times_are_refused_before_anything_is_written() {
    let tmp = TempDir::new("states-bad");
    let sets = ["scene.duration_s=0.03", "shock[0].start_s=0.005", "output.plots=false", "controller.mode=\"sampled\""];
    let good = tmp.join("good");
    let mut cmd = plant_run(&scene_path("cosim-10g.toml"), &good, &sets);
    cmd.args(["--save-state-at", "0.01"]);
    assert_exit(&output(&mut cmd), 0);
    let state = good.join("state-0.01.json");
    let text = read_text(&state);
    let write = |name: &str, body: &str| {
        let p = tmp.join(name);
        std::fs::write(&p, body).unwrap();
        p
    };
    let two_plane = scene_path("two-plane-asymmetric-10g.toml");
    let cases: Vec<(std::path::PathBuf, Vec<String>, &str)> = vec![
        (write("truncated.json", &text[..text.len() / 3]), vec![], "truncated.json"),
        (write("v99.json", &text.replacen("\"format\": 1", "\"format\": 99", 1)), vec![], "format 99"),
        (write("notes.txt", "hello"), vec![], "not a snapshot"),
        (state.clone(), vec!["rotor.mass_kg=12.0".into()], "rotor.mass_kg"),
        (state.clone(), vec!["scene.duration_s=0.005".into()], "nothing to run"),
    ];
    for (i, (file, extra, needle)) in cases.iter().enumerate() {
        let out_dir = tmp.join(&format!("refused-{i}"));
        let mut all: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        all.extend(extra.iter().cloned());
        let all: Vec<&str> = all.iter().map(String::as_str).collect();
        let mut cmd = plant_run(&scene_path("cosim-10g.toml"), &out_dir, &all);
        cmd.arg("--from-state").arg(file);
        let out = output(&mut cmd);
        assert_exit(&out, 2);
        let err = stderr(&out);
        assert!(err.contains(needle), "case {i}: {err}");
        assert!(!out_dir.exists(), "case {i}: nothing written");
    }
    // Another rotor model.
    let out_dir = tmp.join("refused-two-plane");
    let mut cmd = plant_run(&two_plane, &out_dir, &["output.plots=false"]);
    cmd.arg("--from-state").arg(&state);
    let out = output(&mut cmd);
    assert_exit(&out, 2);
    assert!(stderr(&out).contains("rotor.model is planar in the snapshot, two_plane in the scene"), "{}", stderr(&out));
    assert!(!out_dir.exists());
    // Times outside the run, or not ascending.
    for (times, needle) in
        [("0.5", "outside the run"), ("0.02,0.01", "ascending"), ("-1", "outside the run"), ("nan", "outside")]
    {
        let out_dir = tmp.join("refused-times");
        let mut cmd = plant_run(&scene_path("cosim-10g.toml"), &out_dir, &sets);
        cmd.arg(format!("--save-state-at={times}"));
        let out = output(&mut cmd);
        assert_exit(&out, 2);
        assert!(stderr(&out).contains("--save-state-at") && stderr(&out).contains(needle), "{times}: {}", stderr(&out));
        assert!(!out_dir.exists());
    }
}

/// Issue 40 item 4: every field of a real saved state, edited (each number to 0, −1, ±1e300,
/// 2^64 − 1 and a small change; each string and boolean changed), is refused (exit 2, the
/// file named, nothing written) or gives the rows of the untouched state. Twice: as edited (the
/// seal no longer matches), and re-sealed as a careful editor would (the fields' own checks
/// against the scene and the physics). The known instances are named by their fields.
#[test]
fn every_edited_field_of_a_saved_state_is_refused_or_changes_nothing() {
    let tmp = TempDir::new("states-edited");
    let sets = ["scene.duration_s=0.02", "shock[0].start_s=0.005", "output.plots=false", "controller.mode=\"sampled\""];
    let scene = scene_path("cosim-10g.toml");
    let good = tmp.join("good");
    let mut cmd = plant_run(&scene, &good, &sets);
    cmd.args(["--save-state-at", "0.01"]);
    assert_exit(&output(&mut cmd), 0);
    let state = good.join("state-0.01.json");
    let text = read_text(&state);
    let reference = {
        let dir = tmp.join("untouched");
        let mut cmd = plant_run(&scene, &dir, &sets);
        cmd.arg("--from-state").arg(&state);
        assert_exit(&output(&mut cmd), 0);
        rows(&dir)
    };
    assert!(!reference.is_empty());
    let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    // Re-sealed edits: every field but the state's numbers other than the rotor's position
    // (x, y: the first two in every model) set 1 m or more from the centre, the sensor's noise generator and the samples'
    // voltages, speeds and the commands in flight, which a plant may hold at values other
    // than these (only the seal tells that they were edited); the seal itself is the one
    // recomputed.
    let free = |path: &str, value: &serde_json::Value| {
        let far = value.as_f64().is_some_and(|v| v.abs() >= 1.0);
        (path.starts_with("state[") && !(matches!(path, "state[0]" | "state[1]") && far))
            || path == "sensor_rng"
            || path == "seal"
            || path.starts_with("digital.in_flight")
            || path.ends_with(".sensor_v[0]")
            || path.contains(".sensor_v[")
            || path.ends_with(".speed_rad_s")
    };
    let mut cases = Vec::new();
    for e in edits::edits(&doc, &["state"]) {
        let resealed = if free(&e.path, &e.value) {
            None
        } else {
            // The plant's own seal, as an editor with the source would compute it; an edit
            // that no longer parses as a state is refused as such either way.
            serde_json::from_value::<plant::snapshot::Snapshot>(e.doc.clone()).ok().map(|mut s| {
                s.seal();
                serde_json::to_string_pretty(&s).unwrap()
            })
        };
        let plain = serde_json::to_string_pretty(&e.doc).unwrap();
        cases.push((format!("{} = {}", e.path, e.value), plain));
        if let Some(r) = resealed {
            cases.push((format!("{} = {} (re-sealed)", e.path, e.value), r));
        }
    }
    assert!(cases.len() > 200, "{} cases", cases.len());
    let numbered: Vec<(usize, &(String, String))> = cases.iter().enumerate().collect();
    let results = edits::on_two_threads(&numbered, |(i, (what, body))| {
        let file = tmp.join(&format!("edited-{i}.json"));
        std::fs::write(&file, body).unwrap();
        let dir = tmp.join(&format!("run-{i}"));
        let mut cmd = plant_run(&scene, &dir, &sets);
        cmd.arg("--from-state").arg(&file);
        let out = output_within(&mut cmd, std::time::Duration::from_secs(120));
        let err = stderr(&out);
        let verdict = match out.status.code() {
            Some(2) if dir.exists() => Err("exit 2 but the output folder was created".to_owned()),
            Some(2) if !err.contains(&format!("edited-{i}.json")) => Err(format!("the file is not named: {err}")),
            Some(2) => Ok(Some(err)),
            Some(0) if rows(&dir) == reference => Ok(None),
            Some(0) => Err("exit 0 with other rows".to_owned()),
            other => Err(format!("exit {other:?}: {err}")),
        };
        let _ = std::fs::remove_dir_all(&dir);
        (what.clone(), verdict)
    });
    edits::assert_refused_or_harmless(&results);
    // The known instances, refused for what they are.
    let said = |what: &str| edits::refusal(&results, what);
    let max = u64::MAX;
    for (what, needles) in [
        ("next_output = 0 (re-sealed)".to_owned(), &["next_output = 0", "the first output row after"][..]),
        (
            format!("next_output = {max} (re-sealed)"),
            &["next_output = 18446744073709551615", "the first output row after"][..],
        ),
        ("next_output = 1e+300".to_owned(), &["not a whole snapshot"][..]),
        (format!("steps = {max} (re-sealed)"), &["steps = 18446744073709551615", "at most 2^53"][..]),
        (format!("rhs_evals = {max} (re-sealed)"), &["rhs_evals = 18446744073709551615"][..]),
        ("adaptive.h = 0 (re-sealed)".to_owned(), &["adaptive"][..]),
        ("state[0] = -1 (re-sealed)".to_owned(), &["state: the rotor radius = 1.0", "m: at most 0.0003"][..]),
        ("next_output = 0".to_owned(), &["seal", "edited"][..]),
        ("fingerprint[0][1] = \"0\"".to_owned(), &["rotor.model is 0 in the snapshot"][..]),
    ] {
        let err = said(&what);
        for n in needles {
            assert!(err.contains(n), "{what}: {n:?} not in {err:?}");
        }
    }
}

/// A rotor deeper in its race than any contact gets (0.3 mm beyond the 0.15 mm gap), refused
/// by name though its seal is recomputed, and a fingerprint edited to another scene's.
#[test]
fn a_rotor_deep_in_its_race_and_an_edited_fingerprint_are_refused() {
    let tmp = TempDir::new("states-deep");
    let sets = ["scene.duration_s=0.02", "shock[0].start_s=0.005", "output.plots=false", "controller.mode=\"sampled\""];
    let scene = scene_path("cosim-10g.toml");
    let good = tmp.join("good");
    let mut cmd = plant_run(&scene, &good, &sets);
    cmd.args(["--save-state-at", "0.01"]);
    assert_exit(&output(&mut cmd), 0);
    let text = read_text(&good.join("state-0.01.json"));
    let mut deep: plant::snapshot::Snapshot = serde_json::from_str(&text).unwrap();
    // The planar rotor's x and y first: 0.45 mm from the centre, 0.3 mm beyond the gap.
    deep.state[0] = 0.45e-3;
    deep.state[1] = 0.0;
    deep.seal();
    let mut heavy: serde_json::Value = serde_json::from_str(&text).unwrap();
    for pair in heavy["fingerprint"].as_array_mut().unwrap() {
        if pair[0] == "rotor.mass_kg" {
            pair[1] = "12.0".into();
        }
    }
    // Not re-sealed: whoever recomputes the seal for another scene forges a state of it.
    for (name, snapshot, set, needle) in [
        ("deep", serde_json::to_value(&deep).unwrap(), None, "state: the rotor radius = 0.00045 m: at most 0.0003"),
        ("heavy", heavy, Some("rotor.mass_kg=12.0"), "the file was edited"),
    ] {
        let file = tmp.join(&format!("{name}.json"));
        std::fs::write(&file, serde_json::to_string(&snapshot).unwrap()).unwrap();
        let dir = tmp.join(name);
        let mut all = sets.to_vec();
        all.extend(set);
        let mut cmd = plant_run(&scene, &dir, &all);
        cmd.arg("--from-state").arg(&file);
        let out = output(&mut cmd);
        assert_exit(&out, 2);
        assert!(stderr(&out).contains(needle) && stderr(&out).contains(&format!("{name}.json")), "{}", stderr(&out));
        assert!(!dir.exists());
    }
}
