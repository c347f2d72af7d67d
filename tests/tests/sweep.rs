//! End-to-end tests of `plant sweep`: a tiny sweep, shards merged equal one
//! unsharded run, an interrupted sweep resumes, and the hostile inputs of issue 21
//! (item 7) that the grid engine refuses or cleans up.

mod common;

use common::*;

/// A sweep file over the 10 G scene's shock peak, kept short.
fn sweep_file(dir: &TempDir, points: usize) -> std::path::PathBuf {
    let path = dir.join("sweep.toml");
    let text = format!(
        "scene = {:?}\nset = [\"scene.duration_s=0.1\", \"shock[0].start_s=0.01\"]\nkey = \"shock[0].peak_g\"\nfrom = 1.0\nto = 10.0\npoints = {points}\n",
        scene("paper-10g.toml").display().to_string()
    );
    std::fs::write(&path, text).expect("writing the sweep file");
    path
}

#[test]
fn tiny_sweep_writes_points_poincare_and_diagrams() {
    let dir = TempDir::new("sweep-tiny");
    let file = sweep_file(&dir, 2);
    let out = dir.join("out");
    let o = output(&mut plant_sweep(&file, &out, &[]));
    assert_exit(&o, 0);
    // points.csv mixes numbers and words: read it as text.
    let text = read_text(&out.join("points.csv"));
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    for col in [
        "value",
        "post_shock_mode",
        "steady_class",
        "period_k",
        "contact_fraction",
        "whirl_hz",
        "max_radius_m",
        "max_contact_force_n",
    ] {
        assert!(header.contains(&col), "points.csv lacks {col}: {header:?}");
    }
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let col = |name: &str| header.iter().position(|h| *h == name).expect("column");
    let num = |row: &Vec<&str>, name: &str| row[col(name)].parse::<f64>().expect("number");
    assert_eq!(rows.len(), 2);
    assert_eq!((num(&rows[0], "value"), num(&rows[1], "value")), (1.0, 10.0));
    // 1 G does not reach the 0.15 mm gap and recovers; 10 G does reach it.
    assert!(num(&rows[0], "max_radius_m") < 0.15e-3 && num(&rows[1], "max_radius_m") > 0.15e-3);
    assert_eq!(rows[0][col("post_shock_mode")], "recovered");
    // One Poincaré point per revolution of the 0.1 s run at 500 Hz, for each value.
    let pc = Csv::read(&out.join("poincare.csv"));
    assert_eq!(&pc.header[..4], ["value", "n", "x_m", "y_m"]);
    let at_1g = pc.column("value").iter().filter(|v| **v == 1.0).count();
    assert!((49..=51).contains(&at_1g), "{at_1g} points at 1 G");
    for png in ["bifurcation_x.png", "bifurcation_y.png"] {
        let bytes = std::fs::read(out.join(png)).unwrap_or_default();
        assert!(bytes.starts_with(b"\x89PNG"), "{png} missing");
    }
}

#[test]
fn shards_merged_equal_an_unsharded_sweep() {
    let dir = TempDir::new("sweep-shards");
    let file = sweep_file(&dir, 3);
    let (whole, a, b) = (dir.join("whole"), dir.join("a"), dir.join("b"));
    assert_exit(&output(&mut plant_sweep(&file, &whole, &[])), 0);
    assert_exit(&output(&mut plant_sweep(&file, &a, &["--shard", "0/2"])), 0);
    assert_exit(&output(&mut plant_sweep(&file, &b, &["--shard", "1/2"])), 0);
    assert!(!a.join("points.csv").exists(), "a shard alone must not claim the whole result");
    // "Another machine's" shard: copy its points in, then merge.
    for entry in std::fs::read_dir(b.join("points")).expect("shard b points") {
        let entry = entry.expect("entry");
        std::fs::copy(entry.path(), a.join("points").join(entry.file_name())).expect("copy");
    }
    assert_exit(&output(&mut plant_sweep(&file, &a, &["--merge"])), 0);
    assert_eq!(read_text(&a.join("points.csv")), read_text(&whole.join("points.csv")));
    assert_eq!(read_text(&a.join("poincare.csv")), read_text(&whole.join("poincare.csv")));
    // Issue 21 item 7: a signal during `--merge` killed it outright; it finishes its files
    // (each whole) and exits 130.
    #[cfg(target_os = "linux")]
    {
        let merge = Proc::spawn(&mut plant_sweep(&file, &a, &["--merge"]));
        wait_for_handler(merge.id(), libc::SIGTERM);
        merge.signal(libc::SIGTERM);
        let (code, log) = merge.finish_within(std::time::Duration::from_secs(300));
        assert_eq!(code, Some(130), "{log}");
        assert_eq!(read_text(&a.join("points.csv")), read_text(&whole.join("points.csv")));
    }
}

#[test]
fn interrupted_sweep_keeps_its_points_and_resumes() {
    let dir = TempDir::new("sweep-resume");
    let file = sweep_file(&dir, 6);
    let out = dir.join("out");
    let child = plant_sweep(&file, &out, &["--jobs", "1"]).stderr(std::process::Stdio::piped()).spawn().expect("start");
    // Wait for the first finished point, then interrupt.
    let first = out.join("points").join("00000.json");
    let started = std::time::Instant::now();
    while !first.exists() {
        assert!(started.elapsed().as_secs() < 120, "no point finished in 2 minutes");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    unsafe {
        libc::kill(child.id() as i32, libc::SIGINT);
    }
    let o = child.wait_with_output().expect("wait");
    let done = std::fs::read_dir(out.join("points"))
        .expect("points")
        .filter(|e| e.as_ref().is_ok_and(|e| e.path().extension().is_some_and(|x| x == "json")))
        .count();
    if o.status.code() == Some(0) {
        // The sweep finished before the signal landed: nothing to resume, but nothing lost.
        assert_eq!(done, 6);
        return;
    }
    assert_exit(&o, 130);
    assert!((1..6).contains(&done), "{done} points kept");
    assert!(!out.join("points.csv").exists());
    // Resume: only the missing points run.
    let o = output(&mut plant_sweep(&file, &out, &[]));
    assert_exit(&o, 0);
    assert!(stderr(&o).contains(&format!("reused {done}")), "{}", stderr(&o));
    let whole = dir.join("whole");
    assert_exit(&output(&mut plant_sweep(&file, &whole, &[])), 0);
    assert_eq!(read_text(&out.join("points.csv")), read_text(&whole.join("points.csv")));
}

#[test]
fn bad_sweep_file_exits_2_naming_the_key() {
    let dir = TempDir::new("sweep-bad");
    let path = dir.join("bad.toml");
    std::fs::write(
        &path,
        format!(
            "scene = {:?}\nkey = \"rotor.bogus\"\nfrom = 1.0\nto = 2.0\npoints = 2\n",
            scene("paper-10g.toml").display().to_string()
        ),
    )
    .expect("write");
    let o = output(&mut plant_sweep(&path, &dir.join("out"), &[]));
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("bogus"), "{}", stderr(&o));
    std::fs::write(
        &path,
        format!(
            "scene = {:?}\nkey = \"rotor.mass_kg\"\nfrom = 1.0\nto = 2.0\npoints = 0\n",
            scene("paper-10g.toml").display().to_string()
        ),
    )
    .expect("write");
    let o = output(&mut plant_sweep(&path, &dir.join("out"), &[]));
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("points = 0"), "{}", stderr(&o));
}

#[test]
fn two_key_map_writes_value2_and_the_mode_map() {
    let dir = TempDir::new("sweep-map");
    let path = dir.join("map.toml");
    let text = format!(
        "scene = {:?}\nset = [\"scene.duration_s=0.06\", \"shock[0].start_s=0.005\"]\nkey = \"shock[0].peak_g\"\nfrom = 1.0\nto = 10.0\npoints = 2\n\n[map]\nkey = \"controller.damping_ratio\"\nfrom = 0.01\nto = 0.1\npoints = 2\nspacing = \"log\"\n",
        scene("paper-10g.toml").display().to_string()
    );
    std::fs::write(&path, text).expect("write");
    let out = dir.join("out");
    assert_exit(&output(&mut plant_sweep(&path, &out, &[])), 0);
    let text = read_text(&out.join("points.csv"));
    let header: Vec<&str> = text.lines().next().expect("header").split(',').collect();
    let v2 = header.iter().position(|h| *h == "value2").expect("value2 column");
    let v1 = header.iter().position(|h| *h == "value").expect("value column");
    let pairs: Vec<(f64, f64)> = text
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[v1].parse().expect("value"), f[v2].parse().expect("value2"))
        })
        .collect();
    // The first key varies fastest; log spacing of the second.
    assert_eq!(pairs, vec![(1.0, 0.01), (10.0, 0.01), (1.0, 0.1), (10.0, 0.1)]);
    assert!(std::fs::read(out.join("map.png")).unwrap_or_default().starts_with(b"\x89PNG"));
}

/// Issue 21, item 7: `--jobs 1000000` started 4,015 threads. The bound is the engine's, so it
/// holds for `plant sweep` and `plant ensemble` alike, and nothing runs.
#[test]
fn jobs_past_the_bound_exit_2_naming_the_value_and_the_limit() {
    let dir = TempDir::new("sweep-jobs");
    let file = sweep_file(&dir, 2);
    let out = dir.join("out");
    let o = output(&mut plant_sweep(&file, &out, &["--jobs", "1000000"]));
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("1000000") && stderr(&o).contains("at most 1024"), "{}", stderr(&o));
    assert!(!out.exists(), "nothing may run");
    let mut ensemble = std::process::Command::new(plant_bin());
    ensemble.arg("ensemble").arg(scene("paper-10g.toml")).arg("--out").arg(&out).args(["--jobs", "1025"]);
    let o = output(&mut ensemble);
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("1025") && stderr(&o).contains("at most 1024"), "{}", stderr(&o));
    assert!(!out.exists(), "nothing may run");
}

/// Issue 21, item 7: `--round 1` was accepted on a sweep without ensembles (and ran it whole).
#[test]
fn a_round_past_a_single_run_sweeps_only_round_exits_2() {
    let dir = TempDir::new("sweep-round");
    let file = sweep_file(&dir, 2);
    let out = dir.join("out");
    let o = output(&mut plant_sweep(&file, &out, &["--round", "1"]));
    assert_exit(&o, 2);
    assert!(stderr(&o).contains("--round = 1") && stderr(&o).contains("one round"), "{}", stderr(&o));
    assert!(!out.join("points").exists(), "nothing may run");
    // Round 0 is the whole sweep.
    assert_exit(&output(&mut plant_sweep(&file, &out, &["--round", "0"])), 0);
    assert!(out.join("points.csv").exists());
}

/// Issue 21, item 7: a temporary point file that a SIGKILL left half-written survived the
/// resume. A resume (or a merge) removes the temporaries of dead writers, in the folder, in
/// `points/` and in a point's member folder, and leaves a live writer's (another shard's:
/// it holds a lock on it) alone.
#[test]
fn a_resume_removes_what_killed_writes_left_and_keeps_live_ones() {
    let dir = TempDir::new("sweep-temporaries");
    let file = sweep_file(&dir, 2);
    let out = dir.join("out");
    assert_exit(&output(&mut plant_sweep(&file, &out, &[])), 0);
    let points = read_text(&out.join("points.csv"));
    // What a write killed half-way leaves: the temporary of an atomic write (its pid long gone).
    let dead = [
        out.join("points").join(".00001.json.tmp4194000-7"),
        out.join(".points.csv.tmp4194000-9"),
        out.join("points").join("00001").join(".00003.json.tmp4194000-8"),
    ];
    std::fs::create_dir_all(out.join("points").join("00001")).expect("member folder");
    for d in &dead {
        std::fs::write(d, b"{\"key\":\"12").expect("a half-written temporary");
    }
    let live = out.join("points").join(".00000.json.tmp4194001-0");
    std::fs::write(&live, b"{").expect("a live temporary");
    let holder = std::fs::OpenOptions::new().write(true).open(&live).expect("open");
    holder.lock().expect("lock");
    let o = output(&mut plant_sweep(&file, &out, &[]));
    assert_exit(&o, 0);
    assert!(stderr(&o).contains("removed 3 temporary file(s)"), "{}", stderr(&o));
    for d in &dead {
        assert!(!d.exists(), "{} survived the resume", d.display());
    }
    assert!(live.exists(), "a live writer's temporary was removed");
    assert_eq!(read_text(&out.join("points.csv")), points);
    drop(holder);
    assert_exit(&output(&mut plant_sweep(&file, &out, &["--merge"])), 0);
    assert!(!live.exists(), "--merge leaves a dead writer's temporary");
}

/// Issue 21, item 7: a type error in a sweep file pointed at line 1, column 1 without the key
/// (the swept key's fields were read through `#[serde(flatten)]`).
#[test]
fn sweep_file_type_errors_point_at_the_key() {
    let dir = TempDir::new("sweep-types");
    let path = dir.join("bad.toml");
    let scene = scene("paper-10g.toml").display().to_string();
    for (body, line) in [
        ("key = \"rotor.mass_kg\"\nfrom = 1.0\nto = \"two\"\npoints = 2\n", "to = \"two\""),
        ("key = \"rotor.mass_kg\"\nfrom = 1.0\nto = 2.0\npoints = 2.5\n", "points = 2.5"),
        ("key = \"rotor.mass_kg\"\nfrom = 1.0\nto = 2.0\npoints = 2\nspacing = 3\n", "spacing = 3"),
        ("key = \"rotor.mass_kg\"\nfrom = 1.0\nto = 2.0\npoints = 2\nbogus = 1\n", "bogus = 1"),
    ] {
        std::fs::write(&path, format!("scene = {scene:?}\n{body}")).expect("write");
        let o = output(&mut plant_sweep(&path, &dir.join("out"), &[]));
        assert_exit(&o, 2);
        let err = stderr(&o);
        assert!(err.contains(line) && !err.contains("line 1, column 1"), "{body}: {err}");
    }
}
