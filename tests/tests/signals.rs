//! Issue 31 item 10: every command honours SIGINT/SIGTERM as `run` and `soak` do: it stops,
//! keeps what it had finished, and exits 130. `compare`, `bench host` and `bench tick` had no
//! handler (they died by the signal and kept none of their finished runs); `assess`,
//! `ensemble` and `sweep` exited 0 for a signal that came while they wrote their outputs.
//! Every child is killed after a time limit; the tests wait for what the command says or
//! writes, never for a time.

#![cfg(unix)]

mod common;

use common::*;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// Short runs in a debug build on a loaded 2-core machine: a hang fails.
const LIMIT: Duration = Duration::from_secs(600);

/// Waits until `path` exists (the command wrote it).
fn wait_for_file(path: &Path) {
    let deadline = Instant::now() + LIMIT;
    while !path.exists() {
        assert!(Instant::now() < deadline, "{} never appeared", path.display());
        std::thread::sleep(Duration::from_millis(1));
    }
}

/// Data rows of a CSV file.
fn rows(path: &Path) -> usize {
    read_text(path).lines().count().saturating_sub(1)
}

#[test]
fn compare_keeps_the_configurations_it_finished_and_exits_130() {
    let dir = TempDir::new("signals-compare");
    let out = dir.join("out");
    let mut cmd = Command::new(plant_bin());
    cmd.arg("compare")
        .arg(scene("paper-10g.toml"))
        .args(["--rates", "20k,40k,60k,80k,100k", "--no-cosim", "--out"])
        .arg(&out)
        .args(["--set", "scene.duration_s=0.04", "--set", "shock[0].start_s=0.01"]);
    let mut p = Proc::spawn(&mut cmd);
    p.wait_line("sampled at 20000 Hz");
    p.signal(libc::SIGTERM);
    let (code, log) = p.finish_within(LIMIT);
    assert_eq!(code, Some(130), "{log}");
    assert!(log.contains("plant: interrupted:") && log.contains("configurations finished"), "{log}");
    let n = rows(&out.join("compare.csv"));
    assert!((2..6).contains(&n), "{n} rows: the continuous run and the rates finished before the signal");
    assert!(out.join("compare_radius.png").is_file(), "{log}");
}

#[test]
fn bench_host_keeps_the_loops_it_finished_and_exits_130() {
    let dir = TempDir::new("signals-host");
    let out = dir.join("out");
    let mut p = Proc::spawn(
        Command::new(plant_bin()).args(["bench", "host", "--seconds", "2", "--rate-hz", "1000", "--out"]).arg(&out),
    );
    // The sleeping loop is done; the spinning one runs for 2 s more.
    p.wait_line("sleep:");
    p.signal(libc::SIGINT);
    let (code, log) = p.finish_within(LIMIT);
    assert_eq!(code, Some(130), "{log}");
    assert!(log.contains("1 of 2 loops finished"), "{log}");
    let text = read_text(&out.join("host.csv"));
    assert_eq!(rows(&out.join("host.csv")), 1, "{text}");
    assert!(text.lines().nth(1).unwrap().starts_with("sleep,"), "{text}");
}

#[test]
fn bench_tick_keeps_the_runs_it_finished_and_exits_130() {
    let dir = TempDir::new("signals-tick");
    let out = dir.join("out");
    let mut cmd = Command::new(plant_bin());
    cmd.args(["bench", "tick", "--scene"])
        .arg(scene("paper-10g.toml"))
        .args(["--repeats", "50", "--out"])
        .arg(&out)
        .args(["--set", "scene.duration_s=0.05", "--set", "shock[0].start_s=0.01"]);
    let mut p = Proc::spawn(&mut cmd);
    p.wait_line(", run 1:");
    p.signal(libc::SIGTERM);
    let (code, log) = p.finish_within(LIMIT);
    assert_eq!(code, Some(130), "{log}");
    assert!(log.contains("runs finished"), "{log}");
    let n = rows(&out.join("tick.csv"));
    assert!((1..100).contains(&n), "{n} rows");
}

/// A signal once the merged outputs are being written (`members.csv` is the first): every
/// output is still written, and the command exits 130 instead of 0.
#[test]
fn ensemble_and_sweep_exit_130_for_a_signal_while_they_write_their_outputs() {
    let dir = TempDir::new("signals-grid");
    let out = dir.join("ensemble");
    let mut cmd = Command::new(plant_bin());
    cmd.arg("ensemble").arg(scene("paper-10g.toml")).arg("--out").arg(&out).arg("--quiet");
    for s in ["scene.duration_s=0.06", "shock[0].start_s=0.005", "ensemble.members=2", "ensemble.verify=false"] {
        cmd.args(["--set", s]);
    }
    let p = Proc::spawn(&mut cmd);
    wait_for_file(&out.join("members.csv"));
    p.signal(libc::SIGTERM);
    let (code, log) = p.finish_within(LIMIT);
    assert_eq!(code, Some(130), "{log}");
    assert!(out.join("ensemble.json").is_file(), "{log}");

    let file = small_ensemble_sweep(&dir);
    let out = dir.join("sweep");
    let p = Proc::spawn(&mut plant_sweep(&file, &out, &["--quiet"]));
    wait_for_file(&out.join("members.csv"));
    p.signal(libc::SIGTERM);
    let (code, log) = p.finish_within(LIMIT);
    assert_eq!(code, Some(130), "{log}");
    assert!(out.join("sweep.json").is_file(), "{log}");
}

/// A signal once `report.json` is written (the charts and `report.html` come after it): the
/// report is whole, the command exits 130.
#[test]
fn assess_exits_130_for_a_signal_while_it_writes_the_report() {
    let dir = TempDir::new("signals-assess");
    let path = small_assessment(&dir);
    let out = dir.join("out");
    let p = Proc::spawn(Command::new(plant_bin()).arg("assess").arg(&path).arg("--out").arg(&out).arg("--quiet"));
    wait_for_file(&out.join("report.json"));
    p.signal(libc::SIGTERM);
    let (code, log) = p.finish_within(LIMIT);
    assert_eq!(code, Some(130), "{log}");
    assert!(log.contains("interrupted"), "{log}");
    assert!(out.join("report.html").is_file(), "{log}");
}
