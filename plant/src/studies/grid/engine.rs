//! Running a grid: the command-line options, the check of what a folder holds, the units of
//! this shard (and round), progress and cancellation, and the merge once every point is
//! decided. One engine for every [`Work`]: a sweep of single runs and an ensemble differ only
//! in what their work says.

use super::store::{self, Found, Manifest, Unit};
use super::{Grid, GridError, Point, Progress, Shard, Work};
use crate::config::ConfigError;
use anyhow::Context;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// Most worker threads `--jobs` may ask for: far beyond any machine's cores, and far below
/// what starts to thrash one.
pub const MAX_JOBS: usize = 1024;

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
    /// 0 … R−1); the earlier rounds must be complete (else exit 7). A sweep of single runs
    /// has round 0 only.
    #[arg(long, value_name = "R", value_parser = crate::argument::count::<usize>("a round", 0, 10_000))]
    pub round: Option<usize>,
    /// Only merge: write the tables and charts from the units present; exits 7 listing what
    /// is missing or corrupt.
    #[arg(long)]
    pub merge: bool,
    /// Worker threads (default: all cores; at most 1024; 0 is one).
    #[arg(long, value_parser = parse_jobs)]
    pub jobs: Option<usize>,
    /// Re-run units that do not match this sweep or are corrupt (they are named), instead of
    /// refusing them with exit 2.
    #[arg(long)]
    pub rerun_mismatched: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// `--jobs N`: a number of worker threads, at most [`MAX_JOBS`] (clap exits 2 with this message
/// otherwise, naming the value).
fn parse_jobs(s: &str) -> Result<usize, String> {
    let n: usize = s.trim().parse().map_err(|_| format!("{s}: not a number of worker threads"))?;
    if n > MAX_JOBS {
        return Err(format!("{n} worker threads: must be at most {MAX_JOBS}"));
    }
    Ok(n)
}

/// Runs (or merges) a validated grid into `dir` as the options say; prints what it did.
pub fn execute<W: Work>(grid: &Grid, work: &W, dir: &Path, args: &RunArgs) -> anyhow::Result<()> {
    if let Some(note) = grid.point(0).ok().and_then(|p| work.describe(&p.scene)) {
        eprintln!("plant: {note}");
    }
    if let Some(r) = args.round {
        if r >= work.rounds() {
            let why = match work.members() {
                None => "a sweep of single runs has one round, 0 (rounds are batches of ensemble members)".into(),
                Some(_) => format!("this ensemble has rounds 0 to {}", work.rounds() - 1),
            };
            let e = ConfigError::Range { key: "--round".into(), value: r.to_string(), unit: String::new(), why };
            return Err(e.into());
        }
    }
    if let Some(n) = args.jobs {
        if let Err(e) = rayon::ThreadPoolBuilder::new().num_threads(n.max(1)).build_global() {
            eprintln!("plant: warning: --jobs {n}: {e}");
        }
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    crate::outfile::folder(&dir.join("points"))?;
    let removed = store::remove_temporaries(dir);
    if !removed.is_empty() {
        eprintln!("plant: note: removed {} temporary file(s) of writes a kill interrupted", removed.len());
    }
    let manifest = Manifest::of(grid, work)?;
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
    let mut found = check_folder(grid, work, dir)?;
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
            return Err(GridError::Mismatch { dir: dir.to_path_buf(), units: names(grid, &found.mismatch) }.into());
        }
        // A signal lets the merge finish its files (each written whole), then exits 130.
        let stop = crate::interrupt::stop_flag();
        let written = merge_or_list(grid, work, dir, &found, true)?;
        eprintln!("plant: merged {written} into {}", dir.display());
        if stop.load(std::sync::atomic::Ordering::Relaxed) {
            return Err(GridError::Interrupted.into());
        }
        return Ok(());
    }
    let bad: Vec<(Unit, String)> = found.corrupt.iter().chain(&found.mismatch).cloned().collect();
    if !bad.is_empty() {
        if !args.rerun_mismatched {
            return Err(GridError::Mismatch { dir: dir.to_path_buf(), units: names(grid, &bad) }.into());
        }
        for (unit, why) in &bad {
            eprintln!("plant: re-running {} of {}: {why}", unit.file(), grid.point_name(unit.point));
            let path = unit.path(dir);
            std::fs::remove_file(&path).with_context(|| format!("removing {}", path.display()))?;
        }
        found.corrupt.clear();
        found.mismatch.clear();
    }
    manifest.write(dir)?;

    let stop = crate::interrupt::stop_flag();
    let shard = args.shard.unwrap_or(Shard::ALL);
    let progress_bar = !args.quiet && std::io::stderr().is_terminal();
    let outcome = run_units(grid, work, dir, shard, args.round, &stop, progress_bar, &mut found)?;
    let complete = merge_or_list(grid, work, dir, &found, false);
    if let Err(e) = &complete {
        if e.downcast_ref::<GridError>().is_none() {
            // Writing the merged outputs failed (exit 1), as opposed to "not complete yet".
            return complete.map(|_| ());
        }
    }
    eprintln!(
        "plant: {} {}: ran {} unit(s) in {:.1} s, reused {}, failed {}; {}",
        work.what(),
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
    // Also a signal that came while the merged outputs were written (each whole): exit 130.
    if outcome.interrupted || stop.load(Ordering::Relaxed) {
        return Err(GridError::Interrupted.into());
    }
    if !outcome.failed.is_empty() {
        return Err(GridError::Failed { failed: outcome.failed }.into());
    }
    Ok(())
}

fn names(grid: &Grid, units: &[(Unit, String)]) -> Vec<String> {
    units.iter().map(|(u, why)| format!("{} of {}: {why}", u.file(), grid.point_name(u.point))).collect()
}

/// The unit of `point` in `slot` for this work's layout.
fn unit<W: Work>(work: &W, point: usize, slot: usize) -> Unit {
    Unit { point, member: work.members().map(|_| slot) }
}

/// What a folder holds, checked.
struct Folder<R> {
    /// Good units: point → slot → result.
    results: BTreeMap<usize, BTreeMap<usize, R>>,
    /// Corrupt units, with why.
    corrupt: Vec<(Unit, String)>,
    /// Units made for something else, with why.
    mismatch: Vec<(Unit, String)>,
    /// Files beyond the points or members of this grid.
    out_of_range: usize,
    /// Files under `points/` that are not unit files.
    strays: Vec<PathBuf>,
}

/// Reads and checks every unit file present.
fn check_folder<W: Work>(grid: &Grid, work: &W, dir: &Path) -> anyhow::Result<Folder<W::Result>> {
    let (units, strays) = store::present(dir);
    let mut found =
        Folder { results: BTreeMap::new(), corrupt: Vec::new(), mismatch: Vec::new(), out_of_range: 0, strays };
    let members = work.members().unwrap_or(0);
    let in_range: Vec<Unit> = units
        .into_iter()
        .filter(|u| {
            let ok = u.point < grid.len() && u.member.is_none_or(|j| j < members);
            found.out_of_range += usize::from(!ok);
            ok
        })
        .collect();
    let mut points: BTreeMap<usize, Point> = BTreeMap::new();
    for u in &in_range {
        if let std::collections::btree_map::Entry::Vacant(v) = points.entry(u.point) {
            v.insert(grid.point(u.point)?);
        }
    }
    let read: Vec<(Unit, anyhow::Result<Found<W::Result>>)> = in_range
        .par_iter()
        .map(|&u| {
            let r = (|| -> anyhow::Result<Found<W::Result>> {
                match (work.members(), u.member) {
                    (None, Some(_)) => {
                        return Ok(Found::Mismatch("a member's file in a sweep without ensemble".into()))
                    }
                    (Some(_), None) => return Ok(Found::Mismatch("a single run's file in an ensemble sweep".into())),
                    _ => {}
                }
                let key = work.key(&points[&u.point], u.member)?;
                Ok(store::read_unit::<W::Result>(dir, u, &key, |r| {
                    let (point, member) = work.indices(r);
                    ((point, member) != (u.point, u.member)).then(|| match member {
                        None => format!("holds point {point} (wrong index)"),
                        Some(j) => format!("holds point {point} member {j} (wrong index)"),
                    })
                }))
            })();
            (u, r)
        })
        .collect();
    for (u, r) in read {
        match r? {
            Found::Missing => {}
            Found::Good(result) => {
                found.results.entry(u.point).or_default().insert(u.member.unwrap_or(0), result);
            }
            Found::Corrupt(why) => found.corrupt.push((u, why)),
            Found::Mismatch(why) => found.mismatch.push((u, why)),
        }
    }
    Ok(found)
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

/// A unit failed: bad input stops everything (exit 2); anything else is reported (exit 3).
fn fail(out: &mut RunOutcome, e: anyhow::Error, name: String) -> anyhow::Result<()> {
    if e.downcast_ref::<ConfigError>().is_some() {
        return Err(e.context(format!("{name}: bad input")));
    }
    out.failed.push(format!("{name}: {e:#}"));
    Ok(())
}

/// Runs this shard's units round after round (only `round`, if given) until every point is
/// decided, the next round needs other shards' units, a unit fails, or `stop` is set.
#[allow(clippy::too_many_arguments)]
fn run_units<W: Work>(
    grid: &Grid,
    work: &W,
    dir: &Path,
    shard: Shard,
    round: Option<usize>,
    stop: &AtomicBool,
    progress_bar: bool,
    found: &mut Folder<W::Result>,
) -> anyhow::Result<RunOutcome> {
    let empty = BTreeMap::new();
    let mut out = RunOutcome {
        reused: found
            .results
            .iter()
            .map(|(&i, slots)| slots.keys().filter(|&&j| shard.owns(i, work.members().map(|_| j))).count())
            .sum(),
        ..Default::default()
    };
    loop {
        let mut todo: Vec<Unit> = Vec::new();
        let mut behind: Vec<String> = Vec::new();
        out.waiting = 0;
        for i in 0..grid.len() {
            let Progress::Needs { round: r, missing } = work.progress(found.results.get(&i).unwrap_or(&empty)) else {
                continue;
            };
            if let Some(want) = round {
                if r < want {
                    behind.push(format!("{} round {r}: members {:?} missing", grid.point_name(i), missing));
                }
                if r != want {
                    continue;
                }
            }
            let mine: Vec<Unit> =
                missing.iter().map(|&j| unit(work, i, j)).filter(|u| shard.owns(u.point, u.member)).collect();
            if mine.is_empty() {
                out.waiting += 1;
            }
            todo.extend(mine);
        }
        if !behind.is_empty() {
            return Err(GridError::Incomplete { dir: dir.to_path_buf(), missing: behind, corrupt: Vec::new() }.into());
        }
        if todo.is_empty() || stop.load(Ordering::Relaxed) {
            break;
        }
        let bar = bar(todo.len(), progress_bar, work.noun());
        let results: Vec<(Unit, anyhow::Result<Option<W::Result>>)> = todo
            .par_iter()
            .map(|&u| {
                if stop.load(Ordering::Relaxed) {
                    return (u, Ok(None));
                }
                let r = (|| {
                    let point = grid.point(u.point)?;
                    let result = work.run(&point, u.member, stop)?;
                    if let Some(result) = &result {
                        let key = work.key(&point, u.member)?;
                        store::write_unit(dir, u, &key, result)?;
                    }
                    Ok(result)
                })();
                bar.inc(1);
                (u, r)
            })
            .collect();
        bar.finish_and_clear();
        for (u, r) in results {
            match r {
                Ok(Some(result)) => {
                    out.ran += 1;
                    found.results.entry(u.point).or_default().insert(u.member.unwrap_or(0), result);
                }
                Ok(None) => out.interrupted = true,
                Err(e) => {
                    let name = match u.member {
                        None => grid.point_name(u.point),
                        Some(j) => format!("{} member {j}", grid.point_name(u.point)),
                    };
                    fail(&mut out, e, name)?
                }
            }
        }
        if out.interrupted || !out.failed.is_empty() || round.is_some() {
            break;
        }
    }
    Ok(out)
}

/// Writes the merged outputs when every point is decided and present, else lists what is
/// missing (or corrupt) as [`GridError::Incomplete`]. Returns what was written.
fn merge_or_list<W: Work>(
    grid: &Grid,
    work: &W,
    dir: &Path,
    found: &Folder<W::Result>,
    loud: bool,
) -> anyhow::Result<String> {
    let empty = BTreeMap::new();
    let mut missing = Vec::new();
    let corrupt = names(grid, &found.corrupt);
    let mut counted: Vec<(Vec<&W::Result>, W::Decision)> = Vec::new();
    for i in 0..grid.len() {
        let present = found.results.get(&i).unwrap_or(&empty);
        match work.progress(present) {
            Progress::Decided { counted: n, decision } => {
                counted.push((present.range(..n).map(|(_, r)| r).collect(), decision));
            }
            Progress::Needs { round, missing: m } => {
                let first = unit(work, i, m.first().copied().unwrap_or(0));
                missing.push(match work.members() {
                    None => format!("{} of {}", first.file(), grid.point_name(i)),
                    Some(_) => format!(
                        "{} round {round}: {} member(s) missing ({}{})",
                        grid.point_name(i),
                        m.len(),
                        first.file(),
                        if m.len() > 1 {
                            format!(" … {:05}.json", m.last().copied().unwrap_or(0))
                        } else {
                            String::new()
                        }
                    ),
                });
            }
        }
    }
    if !missing.is_empty() || (loud && !corrupt.is_empty()) {
        return Err(GridError::Incomplete { dir: dir.to_path_buf(), missing, corrupt }.into());
    }
    work.merge(grid, dir, &counted)
}
