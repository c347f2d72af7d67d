//! `plant bench ensemble`: ensemble throughput and the check of the members' setting.
//!
//! Runs the same members of a scene (default `config/paper-10g.toml`: 1.5 s, 10 G) one after
//! the other on one thread, three ways: on the fast setting without verification, on the fast
//! setting with verification (what an ensemble runs), and on the scene's own integrator. It
//! reports members per core-second of each and how many members the fast setting classifies
//! as the scene's own setting does, and writes one row per member to `bench.csv`.

use crate::ensemble::member::{run_member, setting_description, MemberResult};
use crate::ensemble::spec::{EnsembleSpec, MemberSetting};
use crate::grid::{Mode, Point};
use anyhow::Context;
use serde::Serialize;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// `plant bench ensemble` arguments.
#[derive(clap::Args, Debug, Clone)]
pub struct BenchArgs {
    /// Scene file (its `[ensemble]` table gives the draws, if it has one).
    #[arg(long, default_value = "config/paper-10g.toml")]
    pub scene: PathBuf,
    /// Override a scene key (repeatable), e.g. `--set touchdown.air_gap_mm=0.24`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Members run each way.
    #[arg(long, default_value_t = 16, value_parser = crate::argument::count::<usize>("a number of members", 1, 10_000))]
    pub members: usize,
    /// Output folder (default: runs/bench-ensemble).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// One member of `bench.csv`.
#[derive(Serialize)]
struct BenchCsvRow {
    member: usize,
    angle_deg: Option<f64>,
    fast_mode: Mode,
    verified_mode: Mode,
    scene_mode: Mode,
    fast_agrees_with_scene: bool,
    fast_recovery_s: Option<f64>,
    scene_recovery_s: Option<f64>,
    fast_max_contact_force_n: f64,
    scene_max_contact_force_n: f64,
    fast_wall_s: f64,
    verified_wall_s: f64,
    scene_wall_s: f64,
}

/// What the bench measured.
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    /// Members run each way.
    pub members: usize,
    /// Members per core-second, fast setting.
    pub fast_per_core_s: f64,
    /// Members per core-second, fast setting with verification.
    pub verified_per_core_s: f64,
    /// Members per core-second, the scene's own setting.
    pub scene_per_core_s: f64,
    /// Members whose fast mode equals the scene setting's mode.
    pub agree: usize,
    /// Members whose counted mode (fast, verified where close) equals the scene setting's mode.
    pub agree_verified: usize,
    /// Members verified.
    pub verified: usize,
}

/// Runs the bench (see the module doc).
pub fn bench(args: &BenchArgs, log: &mut dyn FnMut(&str)) -> anyhow::Result<BenchReport> {
    let mut sets = args.set.clone();
    sets.push("output.plots=false".into());
    let scene = crate::config::load_scene(&args.scene, &sets)?;
    let base = EnsembleSpec::from_table(&scene.resolved()?.ensemble.unwrap_or_default())?;
    if !(1..=crate::ensemble::spec::MAX_MEMBERS).contains(&args.members) {
        return Err(crate::config::ConfigError::Range {
            key: "--members".into(),
            value: args.members.to_string(),
            unit: " members".into(),
            why: format!("must be between 1 and {}", crate::ensemble::spec::MAX_MEMBERS),
        }
        .into());
    }
    let dir = args.out.clone().unwrap_or_else(|| PathBuf::from("runs").join("bench-ensemble"));
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let point = Point { path: &args.scene, sets: sets.clone(), scene: scene.clone(), index: 0, values: Vec::new() };
    let stop = AtomicBool::new(false);
    let ways = [
        ("fast", EnsembleSpec { integrator: MemberSetting::Fast, verify: false, ..base.clone() }),
        ("fast + verification", EnsembleSpec { integrator: MemberSetting::Fast, verify: true, ..base.clone() }),
        ("scene", EnsembleSpec { integrator: MemberSetting::Scene, verify: false, ..base.clone() }),
    ];
    log(&format!(
        "{} members of {} ({} s simulated each), one thread",
        args.members,
        args.scene.display(),
        scene.duration
    ));
    log(&setting_description(&scene, &ways[1].1));
    let mut results: Vec<Vec<MemberResult>> = Vec::new();
    let mut rates = Vec::new();
    for (name, spec) in &ways {
        let started = Instant::now();
        let mut rows = Vec::new();
        for j in 0..args.members {
            let m = run_member(&point, spec, j, &stop)?.context("interrupted")?;
            rows.push(m);
        }
        let wall = started.elapsed().as_secs_f64();
        let rate = args.members as f64 / wall;
        log(&format!("{name}: {wall:.2} s, {rate:.2} members per core-second"));
        rates.push(rate);
        results.push(rows);
    }
    let (fast, verified, own) = (&results[0], &results[1], &results[2]);
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut report = BenchReport {
        members: args.members,
        fast_per_core_s: rates[0],
        verified_per_core_s: rates[1],
        scene_per_core_s: rates[2],
        agree: 0,
        agree_verified: 0,
        verified: verified.iter().filter(|m| m.verified.is_some()).count(),
    };
    for ((f, v), s) in fast.iter().zip(verified).zip(own) {
        let agrees = f.run.mode == s.run.mode;
        report.agree += usize::from(agrees);
        report.agree_verified += usize::from(v.counted().mode == s.run.mode);
        w.serialize(BenchCsvRow {
            member: f.member,
            angle_deg: f.angle_deg,
            fast_mode: f.run.mode,
            verified_mode: v.counted().mode,
            scene_mode: s.run.mode,
            fast_agrees_with_scene: agrees,
            fast_recovery_s: f.run.recovery_s,
            scene_recovery_s: s.run.recovery_s,
            fast_max_contact_force_n: f.run.max_contact_force_n,
            scene_max_contact_force_n: s.run.max_contact_force_n,
            fast_wall_s: f.run.wall_time_s,
            verified_wall_s: v.run.wall_time_s + v.verified.as_ref().map_or(0.0, |x| x.wall_time_s),
            scene_wall_s: s.run.wall_time_s,
        })?;
    }
    let bytes = w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))?;
    crate::outfile::write(&dir.join("bench.csv"), &bytes)?;
    crate::outfile::write(&dir.join("bench.json"), (serde_json::to_string_pretty(&report)? + "\n").as_bytes())?;
    log(&format!(
        "modes: fast = scene setting for {}/{} members; fast with verification = scene setting for {}/{} ({} verified)",
        report.agree, report.members, report.agree_verified, report.members, report.verified
    ));
    Ok(report)
}
