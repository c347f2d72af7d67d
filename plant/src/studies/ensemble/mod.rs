//! Ensembles: recovery as a probability.
//!
//! Whether a rotor comes back after a shock depends on what nobody chooses: the rotor's angle
//! when the shock arrives, the shock's direction and exact peak, the unbalance within its
//! tolerance. An ensemble runs a scene (or each point of a sweep) as a set of members, each a
//! full run with its own draws ([`spec`]), on a cheap integrator setting with the members
//! close to a decision verified at a tight one ([`member`]), adding members where the outcome
//! is uncertain ([`point`]), and reports the probability of recovery with its 95 % interval,
//! the recovery times, the worst contact force and the mode counts ([`stats`], [`merge`],
//! [`charts`]).
//!
//! `plant ensemble SCENE.toml` runs one scene's `[ensemble]`; a sweep file's `[ensemble]`
//! table makes every point of `plant sweep` an ensemble. Both run on the grid engine
//! ([`crate::grid`]: resumable unit files, shards, rounds, manifest, merge) with
//! [`work::Ensemble`] as the work of a point.

pub mod bench;
pub mod charts;
pub mod member;
pub mod merge;
pub mod point;
pub mod record_member;
pub mod spec;
pub mod stats;
pub mod tally;
pub mod work;

use crate::config::load_scene;
use crate::grid::{execute, Grid, Kind, RunArgs};
use spec::EnsembleSpec;
use std::path::PathBuf;
use work::Ensemble;

/// `plant ensemble` arguments.
#[derive(clap::Args, Debug, Clone)]
pub struct EnsembleArgs {
    /// Scene file (TOML) with an `[ensemble]` table (without one: 64 members, seed 1, the
    /// angle at the shock's arrival drawn).
    pub scene: PathBuf,
    /// Override a scene key, e.g. `--set touchdown.air_gap_mm=0.24` or
    /// `--set ensemble.members=128` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Common options.
    #[command(flatten)]
    pub run: RunArgs,
    /// Also record member J (0-based, as in members.csv) after the ensemble: its run as `plant
    /// run --mcap` writes one (trace.csv, summary.json, run.mcap) in `<out>/member-J/`.
    #[arg(long, value_name = "J")]
    pub record_member: Option<usize>,
}

/// `plant ensemble`: loads the scene and its `[ensemble]` (exit 2 on bad input): one point, no
/// swept key; runs or merges it into `--out` (default `runs/ensemble-<scene stem>`).
pub fn command(args: &EnsembleArgs) -> anyhow::Result<()> {
    let scene = load_scene(&args.scene, &args.set)?;
    let table = scene.resolved()?.ensemble.unwrap_or_default();
    let work = Ensemble { spec: EnsembleSpec::from_table(&table)? };
    let grid = Grid {
        kind: Kind::Ensemble,
        definition: serde_json::json!({ "scene": args.scene, "set": args.set }),
        scene_path: args.scene.clone(),
        set: args.set.clone(),
        axes: Vec::new(),
    };
    grid.validate(&work)?;
    if let Some(j) = args.record_member {
        record_member::check(j, work.spec.members)?;
    }
    let stem = args.scene.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let dir = args.run.out.clone().unwrap_or_else(|| PathBuf::from("runs").join(format!("ensemble-{stem}")));
    execute(&grid, &work, &dir, &args.run)?;
    if let Some(j) = args.record_member {
        let out = record_member::record(&grid, &work.spec, j, &dir)?;
        eprintln!("plant ensemble: member {j} recorded in {}", out.join(crate::recording::mcap_file::FILE).display());
    }
    Ok(())
}
