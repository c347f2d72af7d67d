//! End-to-end tests of ensembles (`plant ensemble`, `[ensemble]` in sweep files) and of the
//! checks of a sweep folder (manifest, keys, checksums: issue 11 item 3). Scenes are cut to
//! 60 ms and ensembles to a few members so that the debug build runs them in seconds; every
//! child is killed after a time limit (`output_within`).

mod common;

use common::*;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

const LIMIT: Duration = Duration::from_secs(240);

/// Short 10 G scene: 60 ms, shock at 5 ms.
const SHORT_SETS: [&str; 2] = ["scene.duration_s=0.06", "shock[0].start_s=0.005"];

fn ensemble_cmd(out: &Path, sets: &[&str], extra: &[&str]) -> Command {
    let mut cmd = Command::new(plant_bin());
    cmd.arg("ensemble").arg(scene("paper-10g.toml")).arg("--out").arg(out).args(extra);
    for s in SHORT_SETS.iter().chain(sets) {
        cmd.args(["--set", s]);
    }
    cmd
}

/// A sweep file over the shock peak with an `[ensemble]` table.
fn ensemble_sweep(dir: &TempDir, name: &str, points: usize, ensemble: &str) -> PathBuf {
    let path = dir.join(name);
    let text = format!(
        "scene = {:?}\nset = [\"scene.duration_s=0.06\", \"shock[0].start_s=0.005\"]\nkey = \"shock[0].peak_g\"\nfrom = 1.0\nto = 10.0\npoints = {points}\n\n[ensemble]\n{ensemble}\n",
        scene("paper-10g.toml").display().to_string()
    );
    std::fs::write(&path, text).expect("writing the sweep file");
    path
}

/// A CSV with words and numbers, as text: header and rows of fields.
fn table(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = read_text(path);
    let mut lines = text.lines();
    let header = lines.next().expect("header").split(',').map(str::to_string).collect();
    (header, lines.map(|l| l.split(',').map(str::to_string).collect()).collect())
}

fn col(header: &[String], name: &str) -> usize {
    header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

/// Wilson's 95 % interval, written out here independently of the plant's.
fn wilson(k: f64, n: f64) -> (f64, f64) {
    let z: f64 = 1.959964;
    let p = k / n;
    let d = 1.0 + z * z / n;
    let c = (p + z * z / (2.0 * n)) / d;
    let h = z * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt() / d;
    (c - h, c + h)
}

#[test]
fn a_scene_ensemble_writes_statistics_members_and_verifies_close_calls() {
    let dir = TempDir::new("ensemble-scene");
    let out = dir.join("out");
    let o = output_within(
        &mut ensemble_cmd(
            &out,
            &["ensemble.members=4", "ensemble.seed=7", "ensemble.verify_rtol=1e-6", "ensemble.verify_rebound=1"],
            &[],
        ),
        LIMIT,
    );
    assert_exit(&o, 0);
    assert!(stderr(&o).contains("overriding the scene's integrator"), "{}", stderr(&o));
    let (h, rows) = table(&out.join("members.csv"));
    assert_eq!(rows.len(), 4);
    let angles: Vec<f64> = rows.iter().map(|r| r[col(&h, "angle_deg")].parse().expect("angle")).collect();
    assert!(angles.iter().all(|a| (0.0..360.0).contains(a)), "{angles:?}");
    for r in &rows {
        let (mode, first) = (&r[col(&h, "mode")], &r[col(&h, "first_mode")]);
        // With verify_rebound = 1 every rebounding member is close to a decision and verified.
        if first == "rebound" || first == "diverged" {
            assert_eq!(r[col(&h, "verified")], "true", "{r:?}");
        }
        assert_eq!(r[col(&h, "numerically_sensitive")] == "true", mode != first, "{r:?}");
        // The unbalance phase at t = 0 is the drawn angle at the shock's arrival less
        // 500 Hz × 5 ms = 2.5 turns.
        let phase: f64 = r[col(&h, "drawn")].trim_start_matches("rotor.unbalance_phase_deg=").parse().expect("phase");
        let angle: f64 = r[col(&h, "angle_deg")].parse().expect("angle");
        assert!(((phase + 900.0 - angle).rem_euclid(360.0)).min((angle - phase - 900.0).rem_euclid(360.0)) < 1e-6);
    }
    let recovered = rows.iter().filter(|r| r[col(&h, "mode")] == "recovered").count() as f64;
    let (sh, stats) = table(&out.join("ensemble.csv"));
    assert_eq!(stats.len(), 1);
    let get = |name: &str| stats[0][col(&sh, name)].parse::<f64>().expect(name);
    assert_eq!(get("members"), 4.0);
    assert_eq!(get("recovered"), recovered);
    let (lo, hi) = wilson(recovered, 4.0);
    assert!((get("p_lo") - lo.max(0.0)).abs() < 1e-6 && (get("p_hi") - hi.min(1.0)).abs() < 1e-6);
    let forces: Vec<f64> = rows.iter().map(|r| r[col(&h, "max_contact_force_n")].parse().expect("force")).collect();
    assert_eq!(get("worst_contact_force_n"), forces.iter().copied().fold(0.0, f64::max));
    let json = read_json(&out.join("ensemble.json"));
    assert_eq!(json["points"][0]["members"], 4);
    assert!(json["member_setting"].as_str().unwrap_or_default().contains("rk4"));
    assert!(std::fs::read(out.join("members.png")).unwrap_or_default().starts_with(b"\x89PNG"));
    let manifest = read_json(&out.join("manifest.json"));
    assert!(manifest["program"].as_str().unwrap_or_default().starts_with("plant "));
    assert_eq!(manifest["hash"].as_str().unwrap_or_default().len(), 64);
}

#[test]
fn sharded_rounds_merge_equal_to_one_machine() {
    let dir = TempDir::new("ensemble-shards");
    // 1 G recovers (all agree after the first batch of 2); 10 G does not: its members decide
    // the round structure. Three shards over a shared folder, round by round.
    let file = ensemble_sweep(&dir, "s.toml", 2, "members = 4\nbatch = 2\nagree = 2\nseed = 3\nverify = false");
    let whole = dir.join("whole");
    assert_exit(&output_within(&mut plant_sweep(&file, &whole, &["--jobs", "2"]), LIMIT), 0);
    let shared = dir.join("shared");
    for round in ["0", "1"] {
        for shard in ["0/3", "1/3", "2/3"] {
            let o = output_within(
                &mut plant_sweep(&file, &shared, &["--shard", shard, "--round", round, "--jobs", "1"]),
                LIMIT,
            );
            assert_exit(&o, 0);
        }
    }
    // The last shard of the last round merged by itself; --merge rewrites the same.
    assert_exit(&output_within(&mut plant_sweep(&file, &shared, &["--merge"]), LIMIT), 0);
    for f in ["points.csv", "members.csv", "poincare.csv", "sweep.json"] {
        assert_eq!(read_text(&shared.join(f)), read_text(&whole.join(f)), "{f} differs");
    }
    let (h, rows) = table(&whole.join("points.csv"));
    assert_eq!(
        &h[..10],
        [
            "value",
            "post_shock_mode",
            "steady_class",
            "period_k",
            "contact_fraction",
            "whirl_hz",
            "max_radius_m",
            "max_contact_force_n",
            "status",
            "index"
        ]
    );
    for c in [
        "members",
        "p_recovered",
        "p_lo",
        "p_hi",
        "recovery_median_s",
        "recovery_p90_s",
        "worst_contact_force_n",
        "numerically_sensitive",
    ] {
        col(&h, c);
    }
    assert_eq!(rows[0][col(&h, "members")], "2", "1 G: every member recovers, the first batch decides");
    assert_eq!(rows[0][col(&h, "stopped_by")], "agree");
    for png in ["recovery_probability.png", "bifurcation_x.png", "bifurcation_y.png"] {
        assert!(std::fs::read(whole.join(png)).unwrap_or_default().starts_with(b"\x89PNG"), "{png}");
    }
}

#[test]
fn a_round_whose_earlier_round_is_missing_exits_7() {
    let dir = TempDir::new("ensemble-round");
    let file = ensemble_sweep(&dir, "s.toml", 1, "members = 4\nbatch = 2\nverify = false");
    let o = output_within(&mut plant_sweep(&file, &dir.join("out"), &["--round", "1"]), LIMIT);
    assert_exit(&o, 7);
    assert!(stderr(&o).contains("round 0"), "{}", stderr(&o));
}

#[test]
fn bad_ensembles_exit_2_naming_key_value_and_unit() {
    let dir = TempDir::new("ensemble-bad");
    let cases: [(&str, &str); 7] = [
        ("members = 0", "ensemble.members = 0 members"),
        ("members = 20000", "ensemble.members = 20000 members"),
        ("seed = 1.5", "ensemble.seed = 1.5"),
        ("peak_rel = 2.0", "ensemble.peak_rel = 2"),
        ("[[ensemble.vary]]\nkey = \"rotor.bogus_um\"\nfrom = 1.0\nto = 2.0", "bogus_um"),
        (
            "[[ensemble.vary]]\nkey = \"contact.friction_dynamic\"\nfrom = -0.1\nto = 0.1",
            "contact.friction_dynamic = -0.1",
        ),
        ("[[ensemble.vary]]\nkey = \"shock[0].peak_g\"\nfrom = 1.0\nto = 2.0", "is both swept and drawn"),
    ];
    for (i, (ensemble, expected)) in cases.iter().enumerate() {
        let file = ensemble_sweep(&dir, &format!("bad{i}.toml"), 2, ensemble);
        let out = dir.join(&format!("out{i}"));
        let o = output_within(&mut plant_sweep(&file, &out, &[]), LIMIT);
        assert_exit(&o, 2);
        assert!(stderr(&o).contains(expected), "{ensemble}: {}", stderr(&o));
        assert!(!out.join("points").exists(), "{ensemble}: nothing may run");
    }
    // The same through a scene's [ensemble] and --set.
    let o = output_within(&mut ensemble_cmd(&dir.join("s"), &["ensemble.members=0"], &[]), LIMIT);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("ensemble.members = 0 members"), "{}", stderr(&o));
}

#[test]
fn later_invalid_points_and_huge_maps_exit_2_before_running() {
    let dir = TempDir::new("sweep-invalid");
    let path = dir.join("s.toml");
    // The third point has a negative air gap.
    std::fs::write(
        &path,
        format!(
            "scene = {:?}\nset = [\"scene.duration_s=0.06\"]\nkey = \"touchdown.air_gap_mm\"\nfrom = 0.2\nto = -0.1\npoints = 3\n",
            scene("paper-10g.toml").display().to_string()
        ),
    )
    .expect("write");
    let out = dir.join("out");
    let o = output_within(&mut plant_sweep(&path, &out, &[]), LIMIT);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("touchdown.air_gap_mm = -0.1 mm"), "{}", stderr(&o));
    assert!(!out.join("points").exists());
    std::fs::write(
        &path,
        format!(
            "scene = {:?}\nkey = \"rotor.mass_kg\"\nfrom = 1.0\nto = 2.0\npoints = 100000\n[map]\nkey = \"rotor.speed_hz\"\nfrom = 1.0\nto = 2.0\npoints = 100000\n",
            scene("paper-10g.toml").display().to_string()
        ),
    )
    .expect("write");
    let o = output_within(&mut plant_sweep(&path, &out, &[]), Duration::from_secs(30));
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("100000 × 100000 = 10000000000 points"), "{}", stderr(&o));
}

/// A sweep of single runs (cheap) for the folder checks.
fn plain_sweep(dir: &TempDir, set: &str) -> PathBuf {
    let path = dir.join("plain.toml");
    std::fs::write(
        &path,
        format!(
            "scene = {:?}\nset = [\"scene.duration_s=0.06\", \"shock[0].start_s=0.005\"{set}]\nkey = \"shock[0].peak_g\"\nfrom = 1.0\nto = 10.0\npoints = 3\n",
            scene("paper-10g.toml").display().to_string()
        ),
    )
    .expect("write");
    path
}

#[test]
fn resumes_refuse_edited_stale_and_misplaced_points_and_merges_list_what_is_missing() {
    let dir = TempDir::new("sweep-manifest");
    let file = plain_sweep(&dir, "");
    let out = dir.join("out");
    assert_exit(&output_within(&mut plant_sweep(&file, &out, &[]), LIMIT), 0);
    let original = read_text(&out.join("points.csv"));
    let p1 = out.join("points").join("00001.json");

    // A value edited by hand: refused naming the point, then re-run on request.
    let text = read_text(&p1);
    let edited = text.replacen("\"max_radius_m\":", "\"max_radius_m\":1", 1);
    assert_ne!(edited, text);
    std::fs::write(&p1, &edited).expect("edit");
    let o = output_within(&mut plant_sweep(&file, &out, &[]), LIMIT);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("points/00001.json") && stderr(&o).contains("edited by hand"), "{}", stderr(&o));
    let o = output_within(&mut plant_sweep(&file, &out, &["--rerun-mismatched"]), LIMIT);
    assert_exit(&o, 0);
    assert!(stderr(&o).contains("re-running points/00001.json"), "{}", stderr(&o));
    assert_eq!(read_text(&out.join("points.csv")), original);

    // A point under another index's name.
    std::fs::copy(out.join("points").join("00000.json"), &p1).expect("copy");
    let o = output_within(&mut plant_sweep(&file, &out, &[]), LIMIT);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("wrong index"), "{}", stderr(&o));
    // --merge lists it as corrupt and a deleted one as missing: exit 7.
    std::fs::remove_file(out.join("points").join("00002.json")).expect("remove");
    let o = output_within(&mut plant_sweep(&file, &out, &["--merge"]), LIMIT);
    assert_exit(&o, 7);
    assert!(stderr(&o).contains("points/00002.json") && stderr(&o).contains("points/00001.json"), "{}", stderr(&o));
    // A truncated file is corrupt too.
    let text = read_text(&out.join("points").join("00000.json"));
    std::fs::write(out.join("points").join("00000.json"), &text[..text.len() / 2]).expect("truncate");
    let o = output_within(&mut plant_sweep(&file, &out, &["--merge"]), LIMIT);
    assert_exit(&o, 7);
    assert!(stderr(&o).contains("points/00000.json"), "{}", stderr(&o));
    assert_exit(&output_within(&mut plant_sweep(&file, &out, &["--rerun-mismatched"]), LIMIT), 0);
    assert_eq!(read_text(&out.join("points.csv")), original);

    // The sweep's scene changed (another key): every old point is stale.
    let file = plain_sweep(&dir, ", \"contact.friction_dynamic=0.2\", \"contact.stribeck_dynamic_m_s=0.2\"");
    let o = output_within(&mut plant_sweep(&file, &out, &[]), LIMIT);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("changed since this folder was made (sweep definition, scene)"), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("its key differs") && stderr(&o).contains("point 2 (shock[0].peak_g = 10)"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn bench_ensemble_compares_the_fast_setting_with_the_scenes_own() {
    let dir = TempDir::new("ensemble-bench");
    let out = dir.join("bench");
    let mut cmd = Command::new(plant_bin());
    cmd.args(["bench", "ensemble", "--members", "2", "--out"]).arg(&out).arg("--scene").arg(scene("paper-10g.toml"));
    for s in SHORT_SETS.iter().chain(&["ensemble.verify_rtol=1e-6"]) {
        cmd.args(["--set", s]);
    }
    let o = output_within(&mut cmd, LIMIT);
    assert_exit(&o, 0);
    let (h, rows) = table(&out.join("bench.csv"));
    assert_eq!(rows.len(), 2);
    for r in &rows {
        // On this 10 G scene the fast setting classifies every member as the scene's DP5 does.
        assert_eq!(r[col(&h, "fast_mode")], r[col(&h, "scene_mode")], "{r:?}");
    }
    let json = read_json(&out.join("bench.json"));
    assert!(num(&json, "fast_per_core_s") > 0.0 && num(&json, "scene_per_core_s") > 0.0);
}

/// `plant overlay`: the curves of finished ensemble sweeps in one chart and one table (each
/// point's probability as its sweep wrote it); bad input exits 2 naming the folder: a missing
/// folder, a sweep of single runs, a map, another key, a `--label` count that is not the
/// folders'.
#[test]
fn overlay_draws_ensemble_sweeps_and_refuses_what_is_not_one() {
    let dir = TempDir::new("overlay");
    let file = ensemble_sweep(&dir, "s.toml", 2, "members = 2\nbatch = 2\nagree = 2\nseed = 3\nverify = false");
    let sweep = dir.join("sweep");
    assert_exit(&output_within(&mut plant_sweep(&file, &sweep, &["--quiet"]), LIMIT), 0);
    let overlay = |args: &[&str], dirs: &[&Path], out: &Path| {
        let mut cmd = Command::new(plant_bin());
        cmd.arg("overlay").args(dirs).args(args).arg("--out").arg(out);
        output_within(&mut cmd, LIMIT)
    };
    let out = dir.join("overlay");
    let o = overlay(&["--label", "first", "--label", "second"], &[sweep.as_path(), sweep.as_path()], &out);
    assert_exit(&o, 0);
    assert!(std::fs::read(out.join("overlay.png")).unwrap_or_default().starts_with(b"\x89PNG"));
    let (h, rows) = table(&out.join("overlay.csv"));
    let (sh, srows) = table(&sweep.join("points.csv"));
    assert_eq!(rows.len(), 2 * srows.len());
    for (k, label) in ["first", "second"].iter().enumerate() {
        for (i, s) in srows.iter().enumerate() {
            let r = &rows[k * srows.len() + i];
            assert_eq!(&r[col(&h, "label")], label);
            assert_eq!(r[col(&h, "key")], "shock[0].peak_g");
            for c in ["value", "members", "recovered", "p_recovered", "p_lo", "p_hi"] {
                assert_eq!(r[col(&h, c)], s[col(&sh, c)], "{label}, point {i}, {c}");
            }
        }
    }

    // --redraw: the chart again from the table alone, the crossings found again from its
    // points: the same picture, to the byte.
    let again = dir.join("overlay-again");
    // An earlier overlay's table there would not be this chart's.
    seed_earlier_outputs(&again, &["overlay.csv"]);
    let mut cmd = Command::new(plant_bin());
    cmd.arg("overlay").arg("--redraw").arg(out.join("overlay.csv")).arg("--out").arg(&again);
    assert_exit(&output_within(&mut cmd, LIMIT), 0);
    assert!(
        std::fs::read(again.join("overlay.png")).unwrap() == std::fs::read(out.join("overlay.png")).unwrap(),
        "the redrawn chart differs from the one drawn from the sweeps"
    );
    assert_only_this_runs_outputs(&again, &["overlay.csv"], &["overlay.png"]);
    // Redrawn in its own folder, the table it is drawn from stays.
    let mut cmd = Command::new(plant_bin());
    cmd.arg("overlay").arg("--redraw").arg(out.join("overlay.csv")).arg("--out").arg(&out);
    assert_exit(&output_within(&mut cmd, LIMIT), 0);
    assert!(out.join("overlay.csv").is_file(), "--redraw removed the table it redrew");

    // A sweep of single runs, another key, a map: each refused.
    let plain = dir.join("plain");
    let o = output_within(&mut plant_sweep(&plain_sweep(&dir, ""), &plain, &["--quiet"]), LIMIT);
    assert_exit(&o, 0);
    let json = read_text(&sweep.join("sweep.json"));
    let other = dir.join("other-key");
    std::fs::create_dir_all(&other).unwrap();
    std::fs::write(other.join("sweep.json"), json.replace("\"shock[0].peak_g\"", "\"touchdown.air_gap_mm\"")).unwrap();
    let map = dir.join("map");
    std::fs::create_dir_all(&map).unwrap();
    std::fs::write(
        map.join("sweep.json"),
        json.replace("\"shock[0].peak_g\"", "\"shock[0].peak_g\", \"touchdown.air_gap_mm\""),
    )
    .unwrap();
    let missing = dir.join("no-such-sweep");
    let bad = dir.join("bad-out");
    let cases: [(&[&str], Vec<&Path>, &str); 7] = [
        (&[], vec![sweep.as_path(), missing.as_path()], "no-such-sweep: no such sweep folder"),
        (&[], vec![plain.as_path()], "a sweep of single runs"),
        (&[], vec![sweep.as_path(), other.as_path()], "mismatched axes"),
        (&[], vec![map.as_path()], "a sweep of 2 keys"),
        (&["--label", "one"], vec![sweep.as_path(), sweep.as_path()], "--label given 1 times for 2 sweep folders"),
        (&["--redraw", "overlay.csv"], vec![sweep.as_path()], "cannot be used with"),
        (&["--redraw", "no-such-table.csv"], vec![], "no-such-table.csv"),
    ];
    for (args, dirs, needle) in cases {
        let o = overlay(args, &dirs, &bad);
        assert_exit(&o, 2);
        assert!(stderr(&o).contains(needle), "expected `{needle}` in: {}", stderr(&o));
    }
    assert!(!bad.join("overlay.png").exists(), "a refused overlay wrote a chart");
}

/// `plant run --robustness N` (issue 40 item 1): the run's own files as without it, and
/// `summary.json` gains `robustness`: N perturbed members, every one counted in a mode, the
/// spreads covering the run's own figures, the members really perturbed (their largest radius
/// differs from the run's in the last digits), the verdict on the last line; bad counts and a
/// run from a saved state are refused before anything is written.
#[test]
fn a_run_says_how_robust_its_outcome_is() {
    let dir = TempDir::new("robustness");
    let sets = ["scene.duration_s=0.03", "shock[0].start_s=0.005", "output.plots=false"];
    let plain = dir.join("plain");
    assert_exit(&output_within(&mut plant_run(&scene("paper-10g.toml"), &plain, &sets), LIMIT), 0);
    let out = dir.join("robust");
    let o = output_within(plant_run(&scene("paper-10g.toml"), &out, &sets).args(["--robustness", "2"]), LIMIT);
    assert_exit(&o, 0);
    assert_eq!(read_text(&plain.join("trace.csv")), read_text(&out.join("trace.csv")), "the run itself is unchanged");
    let s = read_json(&out.join("summary.json"));
    let r = &s["robustness"];
    assert_eq!(r["members"], 2, "{r}");
    let counted: u64 = r["modes"].as_object().expect("modes").values().map(|v| v.as_u64().expect("count")).sum();
    assert_eq!(counted, 2, "{r}");
    assert_eq!(r["run_mode"], s["post_shock_mode"], "{r}");
    let same = r["same_mode"].as_u64().expect("same_mode");
    let refined_same = r["integration"]["same_mode"] == true;
    assert_eq!(r["verdict"], if same == 2 && refined_same { "robust" } else { "fragile" }, "{r}");
    for (key, figure) in [("max_contact_force_n", "max_contact_force_n"), ("max_radius_m", "max_radius_m")] {
        let own = num(&s, figure);
        let (lo, hi) = (num(&r[key], "min"), num(&r[key], "max"));
        assert!(lo <= own && own <= hi, "{key}: {own} outside [{lo}, {hi}]");
    }
    let (lo, hi) = (num(&r["max_radius_m"], "min"), num(&r["max_radius_m"], "max"));
    assert!(hi > lo && (hi - lo) < 1e-6 * hi, "perturbed, and only in the last digits: [{lo}, {hi}]");
    assert!(stderr(&o).contains(&format!("plant: robustness: {same} of 2 perturbed runs")), "{}", stderr(&o));
    // The run repeated with its integrator refined (paper-10g: DP5 at rtol 1e-6, atol 1e-9):
    // a tenth of both tolerances, its figures beside the spreads, close to the run's own.
    let i = &r["integration"];
    assert_eq!(i["setting"], "dp5 at rtol 1e-7, atol 1e-10", "{r}");
    assert_eq!(i["same_mode"], i["mode"] == s["post_shock_mode"], "{r}");
    let (own, refined) = (num(&s, "max_contact_force_n"), num(i, "max_contact_force_n"));
    assert!((refined - own).abs() < 0.01 * own, "refined {refined} N against the run's {own} N");
    let radius = (num(&s, "max_radius_m"), num(i, "max_radius_m"));
    assert!((radius.1 - radius.0).abs() < 0.01 * radius.0, "radius {radius:?}");
    assert_eq!(i["converged"], true, "{r}");
    assert!(stderr(&o).contains("integrator refined (dp5 at rtol 1e-7, atol 1e-10)"), "{}", stderr(&o));
    let off = dir.join("no-integration");
    let o = output_within(
        plant_run(&scene("paper-10g.toml"), &off, &sets).args([
            "--robustness",
            "1",
            "--set",
            "robustness.integration=false",
        ]),
        LIMIT,
    );
    assert_exit(&o, 0);
    let r = &read_json(&off.join("summary.json"))["robustness"];
    assert!(r.get("integration").is_none() && r["members"] == 1, "{r}");
    // Bad input: nothing written.
    let bad = dir.join("bad");
    for (extra, says) in [
        (&["--robustness", "300"][..], "`300` is not a number of perturbed runs: a whole number from 0 to 256"),
        (&["--set", "robustness.members=300"][..], "robustness.members = 300: must be 0 (none) to 256"),
        (
            &["--robustness", "2", "--set", "controller.mode=\"realtime\""][..],
            "ask for the robustness of the same scene in lockstep",
        ),
    ] {
        let o = output_within(plant_run(&scene("paper-10g.toml"), &bad, &sets).args(extra), LIMIT);
        assert_exit(&o, 2);
        assert!(stderr(&o).contains(says), "{}", stderr(&o));
        assert!(!bad.exists(), "nothing written");
    }
}
