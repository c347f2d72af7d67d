//! Issue 31 item 6: `soak`, `compare`, `assess`, `campbell`, `ensemble`, `sweep`, `overlay` and
//! `analyze` wrote their charts (and `soak` its CSVs and log) through symbolic links already in
//! `--out`: files elsewhere were overwritten. Every command that writes into a folder is run
//! twice here: once to learn every file it writes (whatever they are: a new output is covered
//! without touching this test), then again into a folder where each of those names is a link
//! out of the folder (a symbolic link to a copy of the file, a hard link to one, a dangling
//! symbolic link). The second run must leave every file outside as it was and create none
//! there. A folder the command writes into (`points/`) that is a link is refused.
//!
//! The unit test `plant::outfile::tests::no_writer_bypasses_the_shared_module` holds the
//! class from the other side: no writer in `plant/src` opens a file but through
//! `plant::outfile`.

mod common;

use common::*;
use std::collections::BTreeMap;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

/// Two short runs of a command in a debug build on a loaded machine: a hang fails.
const LIMIT: Duration = Duration::from_secs(600);

/// Every regular file under `dir`, by its path relative to `dir` (temporaries left out).
fn files(dir: &Path) -> Vec<PathBuf> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())).flatten() {
            let p = e.path();
            let t = e.file_type().unwrap();
            if t.is_dir() {
                walk(root, &p, out);
            } else if t.is_file() && !e.file_name().to_string_lossy().starts_with('.') {
                out.push(p.strip_prefix(root).unwrap().to_path_buf());
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// The contents of every file under `dir`, by relative path.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    files(dir).into_iter().map(|f| (f.clone(), std::fs::read(dir.join(&f)).unwrap())).collect()
}

/// Runs `args` (with `{out}` standing for the output folder) into `out`; returns its output.
fn run(args: &[OsString], out: &Path) -> std::process::Output {
    let args: Vec<OsString> =
        args.iter().map(|a| if a == "{out}" { out.as_os_str().to_os_string() } else { a.clone() }).collect();
    output_within(Command::new(plant_bin()).args(&args), LIMIT)
}

fn os(args: &[&str]) -> Vec<OsString> {
    args.iter().map(OsString::from).collect()
}

/// Runs `args` into `dir/first` to learn what it writes, then into `dir/out` with every file
/// name found there (but `keep`, its inputs) a link out of the folder, and checks that nothing
/// outside changed. `prepare` fills a fresh output folder with what the command reads (for
/// `analyze`: a run). Returns the names found.
fn holds(dir: &TempDir, what: &str, args: &[OsString], keep: &[&str], prepare: &dyn Fn(&Path)) -> Vec<PathBuf> {
    let first = dir.join(&format!("{what}-first"));
    prepare(&first);
    let o = run(args, &first);
    assert_exit(&o, 0);
    let written: Vec<PathBuf> = files(&first).into_iter().filter(|f| !keep.iter().any(|k| Path::new(k) == f)).collect();
    assert!(!written.is_empty(), "{what}: wrote nothing into {}", first.display());

    let out = dir.join(&format!("{what}-out"));
    let outside = dir.join(&format!("{what}-outside"));
    std::fs::create_dir_all(&outside).unwrap();
    prepare(&out);
    let mut dangling = Vec::new();
    for (i, f) in written.iter().enumerate() {
        let name = out.join(f);
        std::fs::create_dir_all(name.parent().unwrap()).unwrap();
        let _ = std::fs::remove_file(&name);
        // The victim holds what the command wrote, so that a command that reads its earlier
        // outputs back (a sweep's unit files, analyze's summary.json) reads what it expects.
        let victim = outside.join(format!("{i:03}-{}", f.file_name().unwrap().to_string_lossy()));
        match i % 3 {
            0 => {
                std::fs::copy(first.join(f), &victim).unwrap();
                std::os::unix::fs::symlink(&victim, &name).unwrap();
            }
            1 => {
                std::fs::copy(first.join(f), &victim).unwrap();
                std::fs::hard_link(&victim, &name).unwrap();
            }
            _ => {
                std::os::unix::fs::symlink(&victim, &name).unwrap();
                dangling.push(victim);
            }
        }
    }
    let victims = snapshot(&outside);
    let o = run(args, &out);
    assert_exit(&o, 0);
    assert_eq!(snapshot(&outside), victims, "{what}: a file outside --out was written through a link");
    for d in &dangling {
        assert!(!d.exists(), "{what}: {} was created through a dangling link", d.display());
    }
    for f in &written {
        let m = std::fs::symlink_metadata(out.join(f)).unwrap();
        // A name the command wrote is now a file of its own; one it only read (a unit file
        // it reused) may still be the link.
        assert!(m.is_file() || m.file_type().is_symlink(), "{what}: {}", f.display());
    }
    written
}

fn nothing(_: &Path) {}

fn sets(pairs: &[&str]) -> Vec<OsString> {
    pairs.iter().flat_map(|s| [OsString::from("--set"), OsString::from(s)]).collect()
}

fn with(mut head: Vec<OsString>, tail: Vec<OsString>) -> Vec<OsString> {
    head.extend(tail);
    head
}

const SHORT_PLOTS: [&str; 3] = ["scene.duration_s=0.05", "shock[0].start_s=0.01", "output.plots=true"];

#[test]
fn run_and_analyze_write_through_no_link() {
    let dir = TempDir::new("links-run");
    let args = with(os(&["run", scene("paper-3g.toml").to_str().unwrap(), "--out", "{out}"]), sets(&SHORT_PLOTS));
    let written = holds(&dir, "run", &args, &[], &nothing);
    assert!(written.iter().any(|f| f.ends_with("orbit.png")), "{written:?}");
    // analyze: a run folder whose analysis outputs are links; scene.toml and trace.csv are its input.
    let prepare = |out: &Path| {
        let o = output_within(&mut plant_run(&scene("paper-3g.toml"), out, SHORT), LIMIT);
        assert_exit(&o, 0);
    };
    let written = holds(&dir, "analyze", &os(&["analyze", "{out}"]), &["scene.toml", "trace.csv"], &prepare);
    assert!(written.iter().any(|f| f.ends_with("spectrum.png")), "{written:?}");
}

#[test]
fn soak_writes_through_no_link() {
    controller_bin();
    let dir = TempDir::new("links-soak");
    // One short 2 G pulse and a short settle, through one lockstep co-simulation: every file a
    // soak writes (the shipped soak-short.toml simulates 0.65 s, twice here, for the same names).
    let programme = dir.join("soak.toml");
    let text = format!(
        "name = \"links\"\nscene = {:?}\nset = [\"controller.law=\\\"pd\\\"\"]\nmode = \"lockstep\"\nsettle_s = 0.03\nrss_every_s = 0.01\n\
         [recovery]\nhold_s = 0.01\nradius_fraction = 0.6\n\
         [[shock]]\nkind = \"half_sine\"\npeak_g = 2.0\nduration_s = 0.005\nstart_s = 0.01\n",
        scene("cosim-10g.toml").display().to_string()
    );
    std::fs::write(&programme, text).unwrap();
    let args = os(&["soak", programme.to_str().unwrap(), "--out", "{out}", "--quiet"]);
    let written = holds(&dir, "soak", &args, &[], &nothing);
    for f in ["soak.csv", "envelope.csv", "rss.csv", "controller.log"] {
        assert!(written.iter().any(|w| w.ends_with(f)), "{f} not among {written:?}");
    }
}

#[test]
fn compare_and_campbell_write_through_no_link() {
    let dir = TempDir::new("links-compare");
    let args = with(
        os(&["compare", scene("paper-10g.toml").to_str().unwrap(), "--rates", "20k", "--no-cosim", "--out", "{out}"]),
        sets(&["scene.duration_s=0.04", "shock[0].start_s=0.01"]),
    );
    let written = holds(&dir, "compare", &args, &[], &nothing);
    assert!(written.iter().any(|f| f.ends_with("compare_radius.png")), "{written:?}");
    let args = os(&[
        "campbell",
        scene("two-plane-asymmetric-10g.toml").to_str().unwrap(),
        "--points",
        "5",
        "--decay-speeds-hz",
        "0",
        "--out",
        "{out}",
    ]);
    let written = holds(&dir, "campbell", &args, &[], &nothing);
    assert!(written.iter().any(|f| f.ends_with("campbell.png")), "{written:?}");
}

#[test]
fn assess_writes_through_no_link() {
    let dir = TempDir::new("links-assess");
    let path = small_assessment(&dir);
    let args = os(&["assess", path.to_str().unwrap(), "--out", "{out}", "--quiet"]);
    let written = holds(&dir, "assess", &args, &[], &nothing);
    assert!(written.iter().any(|f| f.ends_with("report.html")), "{written:?}");
}

#[test]
fn ensemble_sweep_and_overlay_write_through_no_link_and_refuse_a_linked_points_folder() {
    let dir = TempDir::new("links-grid");
    let short = ["scene.duration_s=0.06", "shock[0].start_s=0.005", "ensemble.members=2", "ensemble.verify=false"];
    let args =
        with(os(&["ensemble", scene("paper-10g.toml").to_str().unwrap(), "--out", "{out}", "--quiet"]), sets(&short));
    let written = holds(&dir, "ensemble", &args, &[], &nothing);
    assert!(written.iter().any(|f| f.starts_with("points")), "{written:?}");

    let file = small_ensemble_sweep(&dir);
    let args = os(&["sweep", file.to_str().unwrap(), "--out", "{out}", "--quiet"]);
    let written = holds(&dir, "sweep", &args, &[], &nothing);
    assert!(written.iter().any(|f| f.ends_with("sweep.json")), "{written:?}");

    let sweep = dir.join("sweep-first");
    let args = os(&["overlay", sweep.to_str().unwrap(), "--out", "{out}"]);
    let written = holds(&dir, "overlay", &args, &[], &nothing);
    assert!(written.iter().any(|f| f.ends_with("overlay.png")), "{written:?}");

    // A `points` folder that is a link out of the sweep's folder: refused, nothing written there.
    let out = dir.join("linked-points");
    let elsewhere = dir.join("elsewhere");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::create_dir_all(&elsewhere).unwrap();
    std::os::unix::fs::symlink(&elsewhere, out.join("points")).unwrap();
    let o = run(&os(&["sweep", file.to_str().unwrap(), "--out", "{out}", "--quiet"]), &out);
    assert_ne!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("symbolic link"), "{}", stderr(&o));
    assert_eq!(std::fs::read_dir(&elsewhere).unwrap().count(), 0, "a unit was written through the link");
}

#[test]
fn bench_host_and_tick_write_through_no_link() {
    let dir = TempDir::new("links-bench");
    let args = os(&["bench", "host", "--seconds", "0.01", "--rate-hz", "10000", "--out", "{out}"]);
    holds(&dir, "host", &args, &[], &nothing);
    let args = with(
        os(&[
            "bench",
            "tick",
            "--scene",
            scene("paper-10g.toml").to_str().unwrap(),
            "--repeats",
            "1",
            "--out",
            "{out}",
        ]),
        sets(&["scene.duration_s=0.02", "shock[0].start_s=0.005"]),
    );
    holds(&dir, "tick", &args, &[], &nothing);
}
