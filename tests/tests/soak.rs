//! End-to-end tests of `plant soak` (issue 6 §3): both processes over
//! iceoryx2 through a short programme of shocks.
//!
//! What is pinned: `soak.csv` has one row per shock and agrees with
//! `soak.json` (recovered count, largest force, contact time); a lockstep
//! soak loses no message and misses no deadline; the RSS of both processes
//! is sampled (the controller's is a process other than the plant's); a
//! shock strong enough to reach the race shows contact time and force; the
//! 2 G shock of `soak-short` recovers and the 10 G one leaves the rotor
//! rubbing (cosim-10g with the naive PD); a criterion that cannot be met
//! exits 5 naming it with its measured value; a malformed programme exits 2
//! naming the key; a soak killed with SIGKILL leaves whole rows and
//! `--resume` continues it to the uninterrupted soak's files.

mod common;
#[path = "common/edits.rs"]
mod edits;

use common::{
    assert_exit, controller_bin, num, output_within, plant_bin, read_json, stderr, workspace_root, Csv, Png, TempDir,
    SERIES_BLUE,
};
use std::path::Path;
use std::process::Command;

/// One short soak in a debug build on a loaded machine: a hang fails.
const LIMIT: std::time::Duration = std::time::Duration::from_secs(600);

fn soak(programme: &Path, out: &Path, sets: &[&str]) -> Command {
    let mut cmd = Command::new(plant_bin());
    cmd.arg("soak").arg(programme).arg("--out").arg(out).arg("--quiet");
    for s in sets {
        cmd.args(["--set", s]);
    }
    cmd
}

fn short_programme() -> std::path::PathBuf {
    workspace_root().join("config").join("soak").join("soak-short.toml")
}

#[test]
fn short_soak_writes_consistent_per_shock_and_overall_figures() {
    controller_bin();
    let dir = TempDir::new("soak-short");
    let out = dir.join("out");
    let run = output_within(&mut soak(&short_programme(), &out, &[]), LIMIT);
    assert_exit(&run, 0);

    let shocks = Csv::read(&out.join("soak.csv"));
    let json = read_json(&out.join("soak.json"));
    assert_eq!(json["status"], "completed");
    assert_eq!(shocks.rows.len(), 2, "one row per shock");
    assert_eq!(num(&json, "shocks") as usize, 2);
    assert_eq!(shocks.column("index"), [0.0, 1.0]);
    assert_eq!(shocks.column("start_s"), [0.02, 0.45]);
    assert_eq!(shocks.column("peak_g"), [2.0, 10.0]);
    assert!(shocks.column("complete").iter().all(|c| *c == 1.0));

    // soak.csv and soak.json agree.
    let recovered = shocks.column("recovered");
    assert_eq!(recovered.iter().sum::<f64>(), num(&json, "recovered"));
    let force = shocks.column("max_contact_force_n");
    assert_eq!(force.iter().copied().fold(0.0, f64::max), num(&json, "max_contact_force_n"));
    let contact = shocks.column("contact_time_s");
    assert!((contact.iter().sum::<f64>() - num(&json, "contact_time_s")).abs() < 1e-12);

    // Both shocks reach the race (2 G already pushes the rotor past the 150 µm gap on k_e = 1e6 N/m).
    for (i, (&f, &c)) in force.iter().zip(&contact).enumerate() {
        assert!(f > 0.0 && c > 0.0, "shock {i}: force {f} N, contact {c} s");
    }
    let recovery = shocks.column("recovery_s");
    // 2 G: a few impacts, then clear well before the 10 G shock.
    assert_eq!(recovered[0], 1.0);
    assert!(recovery[0] > 0.0 && recovery[0] < 0.43 - 0.1, "recovery {}", recovery[0]);
    assert!(contact[0] < recovery[0]);
    // 10 G: the naive PD leaves the rotor rubbing to the end.
    assert_eq!(recovered[1], 0.0);
    assert!(recovery[1].is_nan());
    assert!(contact[1] > 0.1 && force[1] > force[0], "contact {} s, force {} N", contact[1], force[1]);
    assert_eq!(json["recovery_s"]["max"].as_f64(), Some(recovery[0]));

    // Lockstep: every message answered, no deadline to miss.
    assert_eq!(num(&json, "sequence_gaps"), 0.0);
    assert_eq!(num(&json, "deadline_misses"), 0.0);
    let cosim = &json["cosim"];
    assert_eq!(num(cosim, "messages_sent"), num(cosim, "messages_received"));
    let ticks = (num(&json, "planned_s") * 20_000.0).ceil();
    assert_eq!(num(cosim, "messages_sent"), ticks);

    // RSS of both processes, sampled over the whole run.
    let rss = Csv::read(&out.join("rss.csv"));
    let t = rss.column("t_sim_s");
    assert!(rss.rows.len() >= 10, "{} RSS samples", rss.rows.len());
    assert!(t.windows(2).all(|w| w[1] > w[0]));
    assert!(t[0] < 0.01 && (t[t.len() - 1] - num(&json, "planned_s")).abs() < 1e-9);
    for col in ["plant_rss_kib", "controller_rss_kib"] {
        assert!(rss.column(col).iter().all(|k| *k > 1000.0), "{col}: {:?}", rss.column(col));
    }
    assert_eq!(num(&json["rss"], "samples") as usize, rss.rows.len());
    assert_eq!(num(&json["rss"]["controller"], "end_kib"), rss.column("controller_rss_kib")[t.len() - 1]);
    let controller = cosim["controller"].as_str().unwrap_or_default();
    assert!(controller.contains("(pid "), "{controller}");

    let criteria = json["criteria"].as_array().expect("criteria");
    assert_eq!(criteria.len(), 3);
    assert!(criteria.iter().all(|c| c["passed"] == true), "{criteria:#?}");
    assert_eq!(json["passed"], true);
    for f in ["scene.toml", "envelope.csv"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    // The charts show the data (decoded: a blank chart fails); recovery and force have a
    // point per shock, the envelope and the memory a line.
    for (png, min_pixels) in [("radius.png", 300), ("recovery.png", 10), ("max_force.png", 10), ("rss.png", 100)] {
        let n = Png::read(&out.join(png)).count_in_plot(SERIES_BLUE);
        assert!(n >= min_pixels, "{png}: {n} pixels of the data colour");
    }

    // A second soak into the same folder, without charts, leaves none of the first one's
    // beside its results: every chart the first drew is gone.
    let pngs = || {
        let mut names: Vec<String> = std::fs::read_dir(&out)
            .expect("the soak's folder")
            .filter_map(|e| e.ok()?.file_name().into_string().ok())
            .filter(|n| n.ends_with(".png"))
            .collect();
        names.sort();
        names
    };
    assert_eq!(pngs(), ["max_force.png", "radius.png", "recovery.png", "rss.png", "tet.png"]);
    let again = output_within(&mut soak(&short_programme(), &out, &["output.plots=false"]), LIMIT);
    assert_exit(&again, 0);
    assert_eq!(pngs(), Vec::<String>::new(), "an earlier soak's charts left in the folder");
    assert_eq!(read_json(&out.join("soak.json"))["status"], "completed");
}

#[test]
fn an_impossible_criterion_exits_5_and_names_it() {
    controller_bin();
    let dir = TempDir::new("soak-criterion");
    // One 3 G shock, 0.25 s: it reaches the race, so no contact force of 1 N or less.
    let programme = dir.join("one.toml");
    let scene = workspace_root().join("config").join("cosim-10g.toml");
    std::fs::write(
        &programme,
        format!(
            "scene = {scene:?}\nset = [\"output.plots=false\"]\nsettle_s = 0.15\nrss_every_s = 0.05\n\
             [recovery]\nhold_s = 0.05\n\
             [[shock]]\nkind = \"double_half_sine\"\npeak_g = 3.0\nf1_hz = 10.0\nf2_hz = 80.0\nstart_s = 0.02\n\
             [criteria]\nmax_contact_force_n = 1.0\nmax_sequence_gaps = 0\n"
        ),
    )
    .unwrap();
    let out = dir.join("out");
    let run = output_within(&mut soak(&programme, &out, &[]), LIMIT);
    assert_exit(&run, 5);
    let err = stderr(&run);
    let json = read_json(&out.join("soak.json"));
    let force = num(&json, "max_contact_force_n");
    assert!(force > 1.0);
    assert!(err.contains("criterion failed: max_contact_force_n: measured"), "{err}");
    assert!(err.contains("limit <= 1 N"), "{err}");
    assert!(!err.contains("criterion failed: max_sequence_gaps"), "{err}");
    assert_eq!(json["passed"], false);
    let verdicts = json["criteria"].as_array().unwrap();
    let v = verdicts.iter().find(|v| v["criterion"] == "max_contact_force_n").unwrap();
    assert_eq!((v["passed"].as_bool(), v["measured"].as_f64()), (Some(false), Some(force)));
    // No plots when the scene says so.
    assert!(!out.join("radius.png").exists());
}

#[test]
fn malformed_programmes_exit_2_naming_the_key() {
    let dir = TempDir::new("soak-bad");
    let scene = workspace_root().join("config").join("cosim-10g.toml");
    let cases: [(&str, &str); 8] = [
        ("settle_s = 1.0\n[random]\ncount = 5\nseed = 1\nspacing_s = [1.0, 1.2]\nbogus = 3\n", "bogus"),
        ("settle_s = 1.0\n[random]\ncount = 5\nseed = 1\nspacing_s = [0.1, 0.2]\n", "random.spacing_s"),
        (
            "settle_s = 1.0\n[random]\ncount = 5\nseed = 1\nspacing_s = [1.0, 1.2]\npeak_g = [5.0, 2.0]\n",
            "random.peak_g = [5, 2] G",
        ),
        ("settle_s = 1.0\nmode = \"fast\"\n[random]\ncount = 5\nseed = 1\nspacing_s = [1.0, 1.2]\n", "mode = \"fast\""),
        // Issue 21 item 7: no lower bound (a row of rss.csv per tick and more).
        (
            "settle_s = 1.0\nrss_every_s = 1e-300\n[random]\ncount = 5\nseed = 1\nspacing_s = [1.0, 1.2]\n",
            "rss_every_s = 1e-300 s",
        ),
        // Issue 21 item 7: large settle_s or start_s were reported as scene.duration_s.
        ("settle_s = 1e7\n[random]\ncount = 5\nseed = 1\nspacing_s = [1.0, 1.2]\n", "settle_s = 10000000 s"),
        (
            "settle_s = 2000.0\n[random]\ncount = 5\nseed = 1\nspacing_s = [1.0, 1.2]\n",
            "settle_s = 2000 s: the soak lasts",
        ),
        (
            "settle_s = 1.0\n[[shock]]\nkind = \"half_sine\"\npeak_g = 2.0\nduration_s = 0.01\nstart_s = 5e6\n",
            "shock[0].start_s = 5000000 s: the soak lasts",
        ),
    ];
    for (i, (body, needle)) in cases.iter().enumerate() {
        let programme = dir.join(&format!("bad{i}.toml"));
        std::fs::write(&programme, format!("scene = {scene:?}\n{body}")).unwrap();
        let run = output_within(&mut soak(&programme, &dir.join("out"), &[]), LIMIT);
        assert_exit(&run, 2);
        assert!(stderr(&run).contains(needle), "case {i}: expected {needle:?} in:\n{}", stderr(&run));
    }
    assert!(!dir.join("out").exists(), "nothing runs on bad input");
}

/// Issue 21 item 7: a soak whose controller never starts left no `soak.json`; it says why
/// (status `not_started`, the error) beside `scene.toml`, like a run's `summary.json`.
#[test]
fn a_soak_whose_controller_never_starts_leaves_soak_json() {
    let dir = TempDir::new("soak-not-started");
    let out = dir.join("out");
    let run = output_within(&mut soak(&short_programme(), &out, &["controller.command=[\"false\"]"]), LIMIT);
    assert_exit(&run, 4);
    let report = read_json(&out.join("soak.json"));
    assert_eq!(report["status"], "not_started", "{report:#}");
    assert!(report["error"].as_str().unwrap_or_default().contains("exited before the handshake"), "{report:#}");
    assert_eq!(report["passed"], false);
    assert!(out.join("scene.toml").is_file());
}

/// Issue 11 item 8: a soak killed with SIGKILL leaves every file it writes as it goes with its
/// header and whole rows only (no torn last row, no missing header). Issue 28 item 5: it
/// continues from its last checkpoint (`plant soak --resume`), and its `soak.csv` and
/// `envelope.csv` are then byte for byte those of the soak that never stopped; a resume under
/// another programme, on a folder without a checkpoint, or from a checkpoint whose monitor was
/// edited (a shock index out of range, issue 40 item 7) is refused with exit 2 and touches
/// nothing.
#[cfg(target_os = "linux")]
#[test]
fn a_soak_killed_with_sigkill_leaves_whole_rows_and_resumes_to_the_uninterrupted_files() {
    use std::time::{Duration, Instant};
    controller_bin();
    let dir = TempDir::new("soak-resume");
    let scene = workspace_root().join("config").join("cosim-10g.toml");
    let programme = |peak: f64| {
        let shocks: String = [2.0, peak, 6.0]
            .iter()
            .enumerate()
            .map(|(i, g)| {
                format!(
                    "[[shock]]\nkind = \"double_half_sine\"\npeak_g = {g}\nf1_hz = 10.0\nf2_hz = 80.0\nstart_s = {}\n",
                    0.02 + 0.12 * i as f64
                )
            })
            .collect();
        format!(
            "scene = {scene:?}\nset = [\"output.plots=false\", \"controller.rate_hz=5000\", \"output.rate_hz=5000\"]\n\
             settle_s = 0.1\nrss_every_s = 0.02\n[recovery]\nhold_s = 0.05\n{shocks}"
        )
    };
    let file = dir.join("three.toml");
    std::fs::write(&file, programme(10.0)).unwrap();

    // The soak that never stops.
    let whole = dir.join("whole");
    let out = output_within(&mut soak(&file, &whole, &[]), LIMIT);
    assert_exit(&out, 0);
    assert!(!whole.join("soak-state.json").exists(), "a completed soak keeps no checkpoint");

    // The same soak, killed once its checkpoint at the second shock is written.
    let cut = dir.join("cut");
    let mut child = soak(&file, &cut, &[]).spawn().expect("start plant soak");
    let pid = child.id();
    let deadline = Instant::now() + Duration::from_secs(300);
    let checkpoint_t = || -> f64 {
        std::fs::read_to_string(cut.join("soak-state.json"))
            .ok()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .and_then(|v| v["plant"]["t_s"].as_f64())
            .unwrap_or(0.0)
    };
    while checkpoint_t() < 0.14 {
        assert!(child.try_wait().expect("poll").is_none(), "the soak ended before it was killed");
        assert!(Instant::now() < deadline, "no checkpoint at the second shock within 300 s");
        std::thread::sleep(Duration::from_millis(10));
    }
    let controller: Vec<u32> = std::fs::read_to_string(format!("/proc/{pid}/task/{pid}/children"))
        .unwrap_or_default()
        .split_whitespace()
        .filter_map(|p| p.parse().ok())
        .collect();
    assert!(child.try_wait().expect("poll").is_none(), "the soak ended before it was killed");
    unsafe { libc::kill(pid as libc::pid_t, libc::SIGKILL) };
    child.wait().expect("reap plant");
    for cpid in controller {
        unsafe { libc::kill(cpid as libc::pid_t, libc::SIGKILL) };
    }
    let t = checkpoint_t();
    let headers = [
        ("soak.csv", plant::soak::SOAK_CSV_HEADER),
        ("envelope.csv", plant::soak::ENVELOPE_CSV_HEADER),
        ("rss.csv", plant::soak::RSS_CSV_HEADER),
    ];
    for (name, header) in headers {
        let text = std::fs::read_to_string(cut.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some(header), "{name}: no header (killed after t = {t} s)");
        assert!(text.ends_with('\n'), "{name}: a torn last row (killed after t = {t} s):\n{text}");
        let width = header.split(',').count();
        for (n, line) in lines.enumerate() {
            let fields: Vec<&str> = line.split(',').collect();
            assert_eq!(fields.len(), width, "{name} line {}: {line:?}", n + 2);
            for f in fields {
                // rss.csv leaves a size it could not read empty.
                assert!(f.is_empty() || f.parse::<f64>().is_ok(), "{name} line {}: {f:?} in {line:?}", n + 2);
            }
        }
    }

    // Another programme (the second shock's peak) is refused, naming it, and nothing is touched.
    let before: Vec<(String, Vec<u8>)> = ["soak.csv", "envelope.csv", "rss.csv", "soak-state.json"]
        .iter()
        .map(|n| (n.to_string(), std::fs::read(cut.join(n)).unwrap()))
        .collect();
    // (The same file name: the scene's name is the programme file's.)
    std::fs::create_dir_all(dir.join("other")).unwrap();
    let other = dir.join("other").join("three.toml");
    std::fs::write(&other, programme(12.0)).unwrap();
    let out = output_within(soak(&other, &cut, &[]).arg("--resume"), LIMIT);
    assert_exit(&out, 2);
    assert!(stderr(&out).contains("scene.shock[1].peak_g is 10"), "{}", stderr(&out));
    let out = output_within(soak(&file, &cut, &["controller.damping_ratio=0.03"]).arg("--resume"), LIMIT);
    assert_exit(&out, 2);
    assert!(stderr(&out).contains("damping_ratio"), "{}", stderr(&out));
    for (name, bytes) in &before {
        assert_eq!(&std::fs::read(cut.join(name)).unwrap(), bytes, "{name} was touched by a refused resume");
    }
    let out = output_within(soak(&file, &dir.join("nothing"), &[]).arg("--resume"), LIMIT);
    assert_exit(&out, 2);
    assert!(stderr(&out).contains("no checkpoint"), "{}", stderr(&out));

    // An edited checkpoint's monitor (issue 40 item 7: a shock index out of range panicked):
    // each refused with exit 2, naming the field, nothing touched.
    let saved: serde_json::Value = read_json(&cut.join("soak-state.json"));
    let figure = serde_json::json!({
        "index": 99, "start_s": 0.02, "end_s": 0.1, "recovered": true, "recovery_s": 0.01,
        "max_contact_force_n": 0.0, "contact_time_s": 0.0, "contact_episodes": 0, "max_radius_m": 1e-5,
        "complete": true
    });
    type Edit<'a> = (&'a str, &'a dyn Fn(&mut serde_json::Value));
    let edits: [Edit; 4] = [
        ("figures[0].index = 99", &|c| c["figures"] = serde_json::json!([figure])),
        ("tracker.current = 99", &|c| c["tracker"]["current"] = 99.into()),
        ("tracker.starts has 1 shock starts", &|c| c["tracker"]["starts"] = serde_json::json!([0.02])),
        ("envelope.bin is 0.5 s", &|c| c["envelope"]["bin"] = 0.5.into()),
    ];
    for (says, edit) in edits {
        let mut c = saved.clone();
        edit(&mut c);
        // Re-sealed (the plant's own seal, as an editor with the source would compute it), so
        // that the refusal is the field's own check, not the seal's.
        let c = reseal(&c).expect("a checkpoint");
        std::fs::write(cut.join("soak-state.json"), serde_json::to_string(&c).unwrap()).unwrap();
        let out = output_within(soak(&file, &cut, &[]).arg("--resume"), LIMIT);
        assert_exit(&out, 2);
        assert!(stderr(&out).contains(says) && stderr(&out).contains("edited or foreign"), "{says}: {}", stderr(&out));
        for (name, bytes) in before.iter().filter(|(n, _)| n != "soak-state.json") {
            assert_eq!(&std::fs::read(cut.join(name)).unwrap(), bytes, "{name} was touched by a refused resume");
        }
    }
    let original = &before.iter().find(|(n, _)| n == "soak-state.json").unwrap().1;
    std::fs::write(cut.join("soak-state.json"), original).unwrap();

    // Issue 40 item 4: every field of the checkpoint edited is refused before a file is
    // touched, or resumes to the uninterrupted soak's files.
    every_edited_field_is_refused_or_changes_nothing(&dir, &file, &cut, &whole, &saved);

    // The resume goes on from the checkpoint to the uninterrupted soak's files.
    let out = output_within(soak(&file, &cut, &[]).arg("--resume"), LIMIT);
    assert_exit(&out, 0);
    for name in ["soak.csv", "envelope.csv"] {
        let (a, b) = (std::fs::read(whole.join(name)).unwrap(), std::fs::read(cut.join(name)).unwrap());
        assert!(a == b, "{name} resumed from t = {t} s differs from the uninterrupted soak's");
    }
    let (a, b) = (read_json(&whole.join("soak.json")), read_json(&cut.join("soak.json")));
    assert_eq!(b["resumed_from_s"].as_f64(), Some(t), "{b:#}");
    for key in
        ["status", "shocks", "shocks_completed", "recovered", "recovery_s", "max_contact_force_n", "contact_time_s"]
    {
        assert_eq!(a[key], b[key], "soak.json {key}");
    }
    assert!(!cut.join("soak-state.json").exists(), "a completed soak keeps no checkpoint");
    assert!(cut.join("controller.1.log").is_file(), "the killed soak's controller.log is kept");
}

/// The checkpoint `c` sealed as the plant seals it, if it still parses as one.
fn reseal(c: &serde_json::Value) -> Option<serde_json::Value> {
    let mut parsed: plant::soak::checkpoint::Checkpoint = serde_json::from_value(c.clone()).ok()?;
    parsed.seal();
    serde_json::to_value(&parsed).ok()
}

/// Each field of the checkpoint `saved` of the soak in `cut` (of programme `file`) edited (each
/// number to 0, −1, ±1e300, 2^64 − 1 and a small change; each string and boolean changed; the
/// programme's leaves one in 7, long arrays at three entries): `--resume` in a copy of `cut`
/// refuses it (exit 2, the file named, the soak's files untouched) or writes `whole`'s
/// `soak.csv` and `envelope.csv`. Twice: as edited (the seal no longer matches), and re-sealed
/// for the checkpoint's own fields (the plant's are a saved state's, held by states.rs), but
/// for the accumulators of the window and bin under way (any non-negative maxima and counts a
/// soak could hold: only the seal tells them edited), which are re-sealed only at −1.
fn every_edited_field_is_refused_or_changes_nothing(
    dir: &TempDir,
    file: &Path,
    cut: &Path,
    whole: &Path,
    saved: &serde_json::Value,
) {
    let files: Vec<(String, Vec<u8>)> = std::fs::read_dir(cut)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read(&p).unwrap()))
        .collect();
    let free = |path: &str| {
        path.starts_with("tracker.acc.")
            || matches!(
                path,
                "tracker.in_contact" | "tracker.clear_since" | "envelope.max_radius" | "envelope.max_force"
            )
    };
    let mut programme_leaves = 0usize;
    let mut last = String::new();
    let mut cases: Vec<(String, String)> = Vec::new();
    for e in edits::edits(saved, &[]) {
        if e.path.starts_with("programme") {
            if e.path != last {
                programme_leaves += 1;
            }
            last = e.path.clone();
            if programme_leaves % 7 != 1 {
                continue;
            }
        }
        cases.push((format!("{} = {}", e.path, e.value), serde_json::to_string(&e.doc).unwrap()));
        let own = !e.path.starts_with("plant") && !e.path.starts_with("programme") && e.path != "seal";
        if own && (!free(&e.path) || e.value == -1) {
            if let Some(r) = reseal(&e.doc) {
                cases.push((format!("{} = {} (re-sealed)", e.path, e.value), serde_json::to_string(&r).unwrap()));
            }
        }
    }
    assert!(cases.len() > 300, "{} cases", cases.len());
    let soak_csv = std::fs::read(whole.join("soak.csv")).unwrap();
    let envelope_csv = std::fs::read(whole.join("envelope.csv")).unwrap();
    let numbered: Vec<(usize, &(String, String))> = cases.iter().enumerate().collect();
    let results = edits::on_two_threads(&numbered, |(i, (what, body))| {
        let run = dir.join(&format!("edited-{i}"));
        std::fs::create_dir_all(&run).unwrap();
        for (name, bytes) in &files {
            std::fs::write(run.join(name), bytes).unwrap();
        }
        std::fs::write(run.join("soak-state.json"), body).unwrap();
        let out = output_within(soak(file, &run, &[]).arg("--resume"), LIMIT);
        let err = stderr(&out);
        let touched = files
            .iter()
            .filter(|(n, _)| n != "soak-state.json")
            .find(|(n, bytes)| std::fs::read(run.join(n)).ok().as_ref() != Some(bytes))
            .map(|(n, _)| n.clone());
        let verdict = match out.status.code() {
            Some(2) if touched.is_some() => Err(format!("exit 2 but {touched:?} was touched")),
            // The checkpoint named, or the soak's file it does not match.
            Some(2) if !["soak-state.json", "soak.csv", "envelope.csv"].iter().any(|n| err.contains(n)) => {
                Err(format!("no file named: {err}"))
            }
            Some(2) => Ok(Some(err)),
            Some(0)
                if std::fs::read(run.join("soak.csv")).unwrap() == soak_csv
                    && std::fs::read(run.join("envelope.csv")).unwrap() == envelope_csv =>
            {
                Ok(None)
            }
            Some(0) => Err("exit 0 with other soak.csv or envelope.csv".to_owned()),
            other => Err(format!("exit {other:?}: {err}")),
        };
        let _ = std::fs::remove_dir_all(&run);
        (what.clone(), verdict)
    });
    edits::assert_refused_or_harmless(&results);
    // The known instances, refused for what they are.
    let said = |what: &str| edits::refusal(&results, what);
    for (what, needles) in [
        ("plant.adaptive.h = 0", &["seal"][..]),
        ("plant.next_output = 0", &["seal"][..]),
        ("rows = 0 (re-sealed)", &["rows = 0"][..]),
        ("soak_csv_bytes = 0 (re-sealed)", &["soak_csv_bytes = 0"][..]),
        ("envelope_csv_bytes = 0 (re-sealed)", &["envelope_csv_bytes = 0"][..]),
        ("figures[0].max_contact_force_n = 0 (re-sealed)", &["soak_csv_bytes"][..]),
        ("tracker.last_t = 0 (re-sealed)", &["tracker.last_t = 0"][..]),
    ] {
        let err = said(what);
        for n in needles {
            assert!(err.contains(n), "{what}: {n:?} not in {err:?}");
        }
    }
}
