//! Running a sweep or an ensemble: the command line, the check of what a folder holds, the
//! units of this shard (and round), and the merge once every point is decided.

use super::store::{self, Manifest, Unit};
use super::{Shard, Sweep, SweepError};
use crate::config::Scene;
use crate::ensemble::member::{self, MemberResult, Point};
use crate::ensemble::point::{progress, Progress};
use crate::hooks::Cancel;
use crate::run::{run, Outcome};
use crate::summary::{snake_name as name_of, Summary};
use anyhow::Context;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// Options shared by `plant sweep` and `plant ensemble`.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct RunArgs {
    /// Output folder (default: runs/sweep-<file stem>, runs/ensemble-<scene stem>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Run only this shard's units: points i with i % N == I, ensemble members j of point i
    /// with (i + j) % N == I. Merge by copying the `points/` folders of all shards together
    /// and running `--merge` (a shared folder merges by itself when the last unit lands).
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Ensembles: run only round R (batch R of every point not decided by its batches
    /// 0 … R−1); the earlier rounds must be complete (else exit 7).
    #[arg(long, value_name = "R")]
    pub round: Option<usize>,
    /// Only merge: write the tables and charts from the units present; exits 7 listing what
    /// is missing or corrupt.
    #[arg(long)]
    pub merge: bool,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Re-run units that do not match this sweep or are corrupt (they are named), instead of
    /// refusing them with exit 2.
    #[arg(long)]
    pub rerun_mismatched: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// `plant sweep` arguments.
#[derive(clap::Args, Debug, Clone)]
pub struct SweepArgs {
    /// Sweep file (TOML).
    pub sweep: PathBuf,
    /// Common options.
    #[command(flatten)]
    pub run: RunArgs,
}

/// `plant sweep`: loads the sweep file (exit 2 on bad input) and runs or merges it.
pub fn command(args: &SweepArgs) -> anyhow::Result<()> {
    let sweep = Sweep::load(&args.sweep)?;
    let stem = args.sweep.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let dir = args.run.out.clone().unwrap_or_else(|| PathBuf::from("runs").join(format!("sweep-{stem}")));
    execute(&sweep, &dir, &args.run)
}

/// Runs (or merges) a loaded sweep into `dir` as the options say; prints what it did.
pub fn execute(sweep: &Sweep, dir: &Path, args: &RunArgs) -> anyhow::Result<()> {
    let what = if sweep.ensemble.is_some() { "ensemble" } else { "sweep" };
    if let Some(e) = &sweep.ensemble {
        if let Some(scene) = sweep_scene(sweep, 0) {
            eprintln!("plant: {}", member::setting_description(&scene, e));
        }
        if let Some(r) = args.round {
            if r >= e.rounds() {
                return Err(crate::config::ConfigError::Range {
                    key: "--round".into(),
                    value: r.to_string(),
                    unit: String::new(),
                    why: format!("this ensemble has rounds 0 to {}", e.rounds() - 1),
                }
                .into());
            }
        }
    }
    if let Some(n) = args.jobs {
        if let Err(e) = rayon::ThreadPoolBuilder::new().num_threads(n.max(1)).build_global() {
            eprintln!("plant: warning: --jobs {n}: {e}");
        }
    }
    std::fs::create_dir_all(dir.join("points")).with_context(|| format!("creating {}", dir.display()))?;
    let manifest = Manifest::of(sweep)?;
    match Manifest::read(dir) {
        Ok(Some(old)) if old != manifest => eprintln!(
            "plant: note: {} changed since this folder was made ({}); every unit is checked against the new one",
            dir.join("manifest.json").display(),
            old.differences(&manifest).join(", ")
        ),
        Err(e) => eprintln!("plant: note: {} unreadable ({e}); writing a new one", dir.join("manifest.json").display()),
        _ => {}
    }
    let started = std::time::Instant::now();
    let mut found = check_folder(sweep, dir)?;
    if found.out_of_range > 0 {
        eprintln!(
            "plant: note: {} result file(s) beyond this sweep's points or members are ignored",
            found.out_of_range
        );
    }
    for s in &found.strays {
        eprintln!("plant: note: ignoring {}", s.display());
    }
    if args.merge {
        if !found.mismatch.is_empty() {
            return Err(SweepError::Mismatch { dir: dir.to_path_buf(), units: names(sweep, &found.mismatch) }.into());
        }
        // A signal lets the merge finish its files (each written whole), then exits 130.
        let (stop, failed) = crate::signal::install();
        if let Some(w) = failed {
            eprintln!("plant: warning: {w}");
        }
        let written = merge_or_list(sweep, dir, &found, true)?;
        eprintln!("plant: merged {written} into {}", dir.display());
        if stop.load(Ordering::Relaxed) {
            return Err(SweepError::Interrupted.into());
        }
        return Ok(());
    }
    let bad: Vec<(Unit, String)> = found.corrupt.iter().chain(&found.mismatch).cloned().collect();
    if !bad.is_empty() {
        if !args.rerun_mismatched {
            return Err(SweepError::Mismatch { dir: dir.to_path_buf(), units: names(sweep, &bad) }.into());
        }
        for (unit, why) in &bad {
            eprintln!("plant: re-running {} of {}: {why}", unit.file(), sweep.point_name(unit.point));
            let path = unit.path(dir);
            std::fs::remove_file(&path).with_context(|| format!("removing {}", path.display()))?;
        }
        found.corrupt.clear();
        found.mismatch.clear();
    }
    manifest.write(dir)?;

    let (stop, failed) = crate::signal::install();
    if let Some(w) = failed {
        eprintln!("plant: warning: {w}");
    }
    let shard = args.shard.unwrap_or(Shard::ALL);
    let progress_bar = !args.quiet && std::io::stderr().is_terminal();
    let outcome = match &sweep.ensemble {
        None => run_single(sweep, dir, shard, stop, progress_bar, &mut found),
        Some(_) => run_members(sweep, dir, shard, args.round, stop, progress_bar, &mut found),
    }?;
    let complete = merge_or_list(sweep, dir, &found, false);
    if let Err(e) = &complete {
        if e.downcast_ref::<SweepError>().is_none() {
            // Writing the merged outputs failed (exit 1), as opposed to "not complete yet".
            return complete.map(|_| ());
        }
    }
    eprintln!(
        "plant: {what} {}: ran {} unit(s) in {:.1} s, reused {}, failed {}; {}",
        dir.display(),
        outcome.ran,
        started.elapsed().as_secs_f64(),
        outcome.reused,
        outcome.failed.len(),
        match (&complete, outcome.waiting) {
            (Ok(written), _) => format!("every point decided; {written} written"),
            (Err(_), 0) => "not every point is decided yet".to_string(),
            (Err(_), n) => format!("{n} point(s) wait for other shards' units"),
        }
    );
    if outcome.interrupted {
        return Err(SweepError::Interrupted.into());
    }
    if !outcome.failed.is_empty() {
        return Err(SweepError::Failed { failed: outcome.failed }.into());
    }
    Ok(())
}

/// The scene of point `i`, if it loads (it did at validation).
fn sweep_scene(sweep: &Sweep, i: usize) -> Option<Scene> {
    sweep.scene_for(i).ok()
}

fn names(sweep: &Sweep, units: &[(Unit, String)]) -> Vec<String> {
    units.iter().map(|(u, why)| format!("{} of {}: {why}", u.file(), sweep.point_name(u.point))).collect()
}

/// The result of one point, as stored in `points/NNNNN.json` (single runs).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PointResult {
    /// Point index.
    pub index: usize,
    /// Value of the swept key.
    pub value: f64,
    /// Value of the second key (maps), else null.
    pub value2: Option<f64>,
    /// Run status (`completed`, `diverged`).
    pub status: String,
    /// Post-shock motion mode.
    pub post_shock_mode: String,
    /// Steady class.
    pub steady_class: String,
    /// Period k.
    pub period_k: Option<u32>,
    /// Contact share over the last 200 revolutions.
    pub contact_fraction: f64,
    /// Mean whirl rate over the steady window (Hz, negative = backward).
    pub whirl_hz: f64,
    /// Largest rotor radius (m).
    pub max_radius_m: f64,
    /// Largest contact force (N).
    pub max_contact_force_n: f64,
    /// Poincaré points of the steady window: (n, x_m, y_m).
    pub poincare: Vec<(i64, f64, f64)>,
}

/// What a folder holds, checked.
#[derive(Default)]
pub struct Folder {
    /// Good single-run points.
    pub points: BTreeMap<usize, PointResult>,
    /// Good members, per point.
    pub members: BTreeMap<usize, BTreeMap<usize, MemberResult>>,
    /// Corrupt units, with why.
    pub corrupt: Vec<(Unit, String)>,
    /// Units made for something else, with why.
    pub mismatch: Vec<(Unit, String)>,
    /// Files beyond the points or members of this sweep.
    pub out_of_range: usize,
    /// Files under `points/` that are not unit files.
    pub strays: Vec<PathBuf>,
}

/// The verification part of a member's key.
fn verification(sweep: &Sweep) -> Option<String> {
    sweep.ensemble.as_ref().map(|e| {
        if e.verify {
            format!("dop853 rtol {:e}, late {}, rebound {}", e.verify_rtol, e.verify_late, e.verify_rebound)
        } else {
            "none".into()
        }
    })
}

/// The key a unit must have.
fn expected_key(sweep: &Sweep, scene: &Scene, unit: Unit) -> anyhow::Result<String> {
    match (&sweep.ensemble, unit.member) {
        (Some(e), Some(j)) => {
            let sets = sweep.point_sets(unit.point);
            let point = Point { path: &sweep.scene_path, sets: &sets, scene, index: unit.point };
            let (member_sets, _, _) = member::member_overrides(&point, e, j);
            let member_scene = crate::config::load_scene(&sweep.scene_path, &member_sets)?;
            store::unit_key(&member_scene, unit, verification(sweep))
        }
        _ => store::unit_key(scene, unit, None),
    }
}

/// Reads and checks every unit file present.
fn check_folder(sweep: &Sweep, dir: &Path) -> anyhow::Result<Folder> {
    let (units, strays) = store::present(dir);
    let mut found = Folder { strays, ..Default::default() };
    let members = sweep.ensemble.as_ref().map_or(0, |e| e.members);
    let in_range: Vec<Unit> = units
        .into_iter()
        .filter(|u| {
            let ok = u.point < sweep.len() && u.member.is_none_or(|j| j < members);
            found.out_of_range += usize::from(!ok);
            ok
        })
        .collect();
    let mut scenes: BTreeMap<usize, Scene> = BTreeMap::new();
    for u in &in_range {
        if let std::collections::btree_map::Entry::Vacant(v) = scenes.entry(u.point) {
            v.insert(sweep.scene_for(u.point)?);
        }
    }
    enum Read {
        Point(PointResult),
        Member(Box<MemberResult>),
    }
    let read: Vec<(Unit, anyhow::Result<Found2<Read>>)> = in_range
        .par_iter()
        .map(|&u| {
            let r = (|| -> anyhow::Result<Found2<Read>> {
                let scene = &scenes[&u.point];
                match (&sweep.ensemble, u.member) {
                    (None, None) => {
                        let key = expected_key(sweep, scene, u)?;
                        Ok(convert(
                            store::read_unit::<PointResult>(dir, u, &key, |p| {
                                (p.index != u.point).then(|| format!("holds point {} (wrong index)", p.index))
                            }),
                            Read::Point,
                        ))
                    }
                    (Some(_), Some(_)) => {
                        let key = expected_key(sweep, scene, u)?;
                        Ok(convert(
                            store::read_unit::<MemberResult>(dir, u, &key, |m| {
                                (m.point != u.point || Some(m.member) != u.member)
                                    .then(|| format!("holds point {} member {} (wrong index)", m.point, m.member))
                            }),
                            |m| Read::Member(Box::new(m)),
                        ))
                    }
                    (None, Some(_)) => Ok(Found2::Mismatch("a member's file in a sweep without ensemble".into())),
                    (Some(_), None) => Ok(Found2::Mismatch("a single run's file in an ensemble sweep".into())),
                }
            })();
            (u, r)
        })
        .collect();
    for (u, r) in read {
        match r? {
            Found2::Missing => {}
            Found2::Good(Read::Point(p)) => {
                found.points.insert(u.point, p);
            }
            Found2::Good(Read::Member(m)) => {
                found.members.entry(u.point).or_default().insert(m.member, *m);
            }
            Found2::Corrupt(why) => found.corrupt.push((u, why)),
            Found2::Mismatch(why) => found.mismatch.push((u, why)),
        }
    }
    Ok(found)
}

/// [`store::Found`] with the result mapped.
enum Found2<T> {
    Missing,
    Good(T),
    Corrupt(String),
    Mismatch(String),
}

fn convert<T, U>(f: store::Found<T>, map: impl FnOnce(T) -> U) -> Found2<U> {
    match f {
        store::Found::Missing => Found2::Missing,
        store::Found::Good(t) => Found2::Good(map(t)),
        store::Found::Corrupt(w) => Found2::Corrupt(w),
        store::Found::Mismatch(w) => Found2::Mismatch(w),
    }
}

/// What a run did.
#[derive(Default)]
struct RunOutcome {
    ran: usize,
    reused: usize,
    failed: Vec<String>,
    interrupted: bool,
    /// Points waiting for other shards' units.
    waiting: usize,
}

/// Runs point `i` of a sweep of single runs; `None` when it was interrupted.
pub fn run_point(sweep: &Sweep, i: usize, stop: &AtomicBool) -> anyhow::Result<Option<(Scene, PointResult)>> {
    let scene = sweep.scene_for(i)?;
    let result = run(&scene, &mut Cancel(stop))?;
    if result.run.outcome == Outcome::Interrupted {
        return Ok(None);
    }
    let s = Summary::new(&scene, &result);
    let (value, value2) = sweep.values(i);
    let a = &s.analysis;
    let p = PointResult {
        index: i,
        value,
        value2: (sweep.axes.len() > 1).then_some(value2),
        status: s.status.name().to_string(),
        post_shock_mode: name_of(&a.post_shock_mode),
        steady_class: name_of(&a.steady_class),
        period_k: a.period_k,
        contact_fraction: s.contact_fraction,
        whirl_hz: a.whirl_hz,
        max_radius_m: s.max_radius_m.unwrap_or(0.0), // stored as a number (null would not read back)
        max_contact_force_n: s.max_contact_force_n.unwrap_or(0.0),
        poincare: a.section.iter().filter(|p| p.t_s >= a.steady_window_s[0]).map(|p| (p.n, p.x_m, p.y_m)).collect(),
    };
    Ok(Some((scene, p)))
}

fn bar(len: usize, shown: bool, what: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(len as u64);
    if shown {
        bar.set_style(
            indicatif::ProgressStyle::with_template(&format!(
                "{{bar:40}} {{pos}}/{{len}} {what}, {{elapsed}} elapsed, ETA {{eta}}"
            ))
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
    } else {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    bar
}

fn run_single(
    sweep: &Sweep,
    dir: &Path,
    shard: Shard,
    stop: &AtomicBool,
    progress_bar: bool,
    found: &mut Folder,
) -> anyhow::Result<RunOutcome> {
    let mine: Vec<usize> = (0..sweep.len()).filter(|&i| shard.owns(i, None)).collect();
    let todo: Vec<usize> = mine.iter().copied().filter(|i| !found.points.contains_key(i)).collect();
    let mut out = RunOutcome { reused: mine.len() - todo.len(), ..Default::default() };
    let bar = bar(todo.len(), progress_bar, "points");
    let results: Vec<(usize, anyhow::Result<Option<PointResult>>)> = todo
        .par_iter()
        .map(|&i| {
            if stop.load(Ordering::Relaxed) {
                return (i, Ok(None));
            }
            let r = run_point(sweep, i, stop).and_then(|r| match r {
                None => Ok(None),
                Some((scene, p)) => {
                    let key = store::unit_key(&scene, Unit { point: i, member: None }, None)?;
                    store::write_unit(dir, Unit { point: i, member: None }, &key, &p)?;
                    Ok(Some(p))
                }
            });
            bar.inc(1);
            (i, r)
        })
        .collect();
    bar.finish_and_clear();
    for (i, r) in results {
        match r {
            Ok(Some(p)) => {
                out.ran += 1;
                found.points.insert(i, p);
            }
            Ok(None) => out.interrupted = true,
            Err(e) => fail(&mut out, e, sweep.point_name(i))?,
        }
    }
    Ok(out)
}

/// A unit failed: bad input stops everything (exit 2); anything else is reported (exit 3).
fn fail(out: &mut RunOutcome, e: anyhow::Error, name: String) -> anyhow::Result<()> {
    if e.downcast_ref::<crate::config::ConfigError>().is_some() {
        return Err(e.context(format!("{name}: bad input")));
    }
    out.failed.push(format!("{name}: {e:#}"));
    Ok(())
}

/// `present[j]` = recovered? of a point's members.
fn recovered_map(members: Option<&BTreeMap<usize, MemberResult>>) -> BTreeMap<usize, bool> {
    members.map_or_else(BTreeMap::new, |m| m.iter().map(|(j, r)| (*j, r.counted().mode == "recovered")).collect())
}

fn run_members(
    sweep: &Sweep,
    dir: &Path,
    shard: Shard,
    round: Option<usize>,
    stop: &AtomicBool,
    progress_bar: bool,
    found: &mut Folder,
) -> anyhow::Result<RunOutcome> {
    let Some(spec) = &sweep.ensemble else { return Ok(RunOutcome::default()) };
    let mut out = RunOutcome::default();
    let scenes: Vec<Scene> = (0..sweep.len()).map(|i| sweep.scene_for(i)).collect::<Result<_, _>>()?;
    let sets: Vec<Vec<String>> = (0..sweep.len()).map(|i| sweep.point_sets(i)).collect();
    out.reused = found.members.values().map(|m| m.len()).sum();
    loop {
        let mut todo: Vec<Unit> = Vec::new();
        let mut behind: Vec<String> = Vec::new();
        out.waiting = 0;
        for i in 0..sweep.len() {
            let Progress::Needs { round: r, missing } = progress(spec, &recovered_map(found.members.get(&i))) else {
                continue;
            };
            if let Some(want) = round {
                if r < want {
                    behind.push(format!("{} round {r}: members {:?} missing", sweep.point_name(i), missing));
                }
                if r != want {
                    continue;
                }
            }
            let mine: Vec<Unit> = missing
                .iter()
                .filter(|&&j| shard.owns(i, Some(j)))
                .map(|&j| Unit { point: i, member: Some(j) })
                .collect();
            if mine.is_empty() {
                out.waiting += 1;
            }
            todo.extend(mine);
        }
        if !behind.is_empty() {
            return Err(SweepError::Incomplete { dir: dir.to_path_buf(), missing: behind, corrupt: Vec::new() }.into());
        }
        if todo.is_empty() || stop.load(Ordering::Relaxed) {
            break;
        }
        let bar = bar(todo.len(), progress_bar, "members");
        let results: Vec<(Unit, anyhow::Result<Option<MemberResult>>)> = todo
            .par_iter()
            .map(|&u| {
                if stop.load(Ordering::Relaxed) {
                    return (u, Ok(None));
                }
                let i = u.point;
                let point = Point { path: &sweep.scene_path, sets: &sets[i], scene: &scenes[i], index: i };
                let j = u.member.unwrap_or(0);
                let r = member::run_member(&point, spec, j, stop).and_then(|m| {
                    if let Some(m) = &m {
                        let key = expected_key(sweep, &scenes[i], u)?;
                        store::write_unit(dir, u, &key, m)?;
                    }
                    Ok(m)
                });
                bar.inc(1);
                (u, r)
            })
            .collect();
        bar.finish_and_clear();
        for (u, r) in results {
            match r {
                Ok(Some(m)) => {
                    out.ran += 1;
                    found.members.entry(u.point).or_default().insert(m.member, m);
                }
                Ok(None) => out.interrupted = true,
                Err(e) => fail(&mut out, e, format!("{} member {}", sweep.point_name(u.point), u.member.unwrap_or(0)))?,
            }
        }
        if out.interrupted || !out.failed.is_empty() || round.is_some() {
            break;
        }
    }
    Ok(out)
}

/// Writes the merged outputs when every point is decided and present, else lists what is
/// missing (or corrupt) as [`SweepError::Incomplete`]. Returns what was written.
fn merge_or_list(sweep: &Sweep, dir: &Path, found: &Folder, loud: bool) -> anyhow::Result<String> {
    let mut missing = Vec::new();
    let corrupt = names(sweep, &found.corrupt);
    match &sweep.ensemble {
        None => {
            for i in 0..sweep.len() {
                if !found.points.contains_key(&i) {
                    missing.push(format!("{} of {}", Unit { point: i, member: None }.file(), sweep.point_name(i)));
                }
            }
        }
        Some(spec) => {
            for i in 0..sweep.len() {
                if let Progress::Needs { round, missing: m } = progress(spec, &recovered_map(found.members.get(&i))) {
                    let first = m.first().copied().unwrap_or(0);
                    let last = m.last().copied().unwrap_or(0);
                    missing.push(format!(
                        "{} round {round}: {} member(s) missing ({}{})",
                        sweep.point_name(i),
                        m.len(),
                        Unit { point: i, member: Some(first) }.file(),
                        if m.len() > 1 { format!(" … {last:05}.json") } else { String::new() }
                    ));
                }
            }
        }
    }
    if !missing.is_empty() || (loud && !corrupt.is_empty()) {
        return Err(SweepError::Incomplete { dir: dir.to_path_buf(), missing, corrupt }.into());
    }
    match &sweep.ensemble {
        None => {
            let points: Vec<&PointResult> = found.points.values().collect();
            super::merge::write_single(sweep, dir, &points)?;
            Ok("points.csv, poincare.csv and the diagrams".into())
        }
        Some(spec) => {
            let mut counted: Vec<(Vec<&MemberResult>, &'static str)> = Vec::new();
            for i in 0..sweep.len() {
                let map = found.members.get(&i);
                let (members, stopped_by) = match progress(spec, &recovered_map(map)) {
                    Progress::Decided { members, stopped_by } => (members, stopped_by),
                    Progress::Needs { .. } => (0, "members"), // not reached: listed as missing above
                };
                let list: Vec<&MemberResult> =
                    map.map(|m| m.range(..members).map(|(_, r)| r).collect()).unwrap_or_default();
                counted.push((list, stopped_by));
            }
            super::merge::write_ensemble(sweep, dir, &counted)
        }
    }
}
