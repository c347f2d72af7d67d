//! Speed against accuracy (`plant bench accuracy`): work-precision data of
//! every integrator on the bench scenes ([`super::scenes`]), the reference
//! they are measured against, and the stability limits of the fixed-step
//! methods.
//!
//! * Reference: DOP853 at rtol 1e-13; it is checked against DP5 at rtol
//!   1e-11, and the error between the two is the floor below which the
//!   chart cannot resolve differences.
//! * Each method runs over a grid of settings ([`grid`]); RK4 and DP5 also
//!   with the race parked while the gap is clear.
//! * Stability: the largest fixed step that runs the window without
//!   divergence and with a max scaled error below 1, found by doubling and
//!   bisection, next to the estimate of [`crate::stability`].
//! * The scipy peer (`bench/peer/`) can run on the same scenes, reference
//!   and error measure; its rows join the charts.
//!
//! Writes `accuracy.csv`, `stability.csv`, `reference_<scene>.csv`,
//! `scene_<scene>.toml`, `work_precision_<scene>.png` and
//! `failure_<scene>_<method>.png` (columns in [`super::rows`]).

use super::rows::{self, AccuracyRow, AccuracyStatus, ReferenceRow, StabilityRow};
use super::{atol_scale, measure, method_name, with_integrator, BenchScene, IntegratorSetting, WINDOW};
use crate::config::Scene;
use crate::integrate::Method;
use crate::plot::{self, PointGroup, Scale, Series};
use crate::run::{run, Outcome, Quiet};
use crate::trace::window_error;
use crate::trace::Trace;
use anyhow::Context;
use std::path::{Path, PathBuf};

/// The fixed-step methods whose stability limits the bench finds (and whose failure charts
/// `--redraw` draws again from `stability.csv`).
const FIXED_STEP: [Method; 3] = [Method::ExplicitEuler, Method::SymplecticEuler, Method::Rk4];

/// The settings swept for each method.
pub fn grid(quick: bool) -> Vec<(Method, Vec<IntegratorSetting>)> {
    let rtols: Vec<IntegratorSetting> = if quick {
        vec![IntegratorSetting::Rtol(1e-4), IntegratorSetting::Rtol(1e-7)]
    } else {
        (3..=10).map(|k| IntegratorSetting::Rtol(10f64.powi(-k))).collect()
    };
    let subs: Vec<IntegratorSetting> = if quick {
        vec![IntegratorSetting::Substeps(4), IntegratorSetting::Substeps(32)]
    } else {
        [1, 2, 4, 8, 16, 32, 64].map(IntegratorSetting::Substeps).to_vec()
    };
    vec![
        (Method::Dp5, rtols.clone()),
        (Method::Dop853, rtols),
        (Method::Rk4, subs.clone()),
        (Method::SymplecticEuler, subs.clone()),
        (Method::ExplicitEuler, subs),
    ]
}

/// The reference of a bench scene and its floor.
pub struct Reference {
    /// DOP853 at rtol 1e-13.
    pub trace: Trace,
    /// Scaled error between the reference and DP5 at rtol 1e-11: (RMS, max).
    pub floor: (f64, f64),
    /// Largest contact force of the reference (N).
    pub peak_contact_force: f64,
}

/// Computes the reference of a scene.
pub fn reference(b: &BenchScene) -> anyhow::Result<Reference> {
    let r = run(&with_integrator(&b.scene, Method::Dop853, IntegratorSetting::Rtol(1e-13)), &mut Quiet)?;
    anyhow::ensure!(
        r.run.outcome == Outcome::Completed,
        "{}: the DOP853 reference did not complete: {:?}",
        b.name,
        r.run.outcome
    );
    let check = run(&with_integrator(&b.scene, Method::Dp5, IntegratorSetting::Rtol(1e-11)), &mut Quiet)?;
    let floor =
        window_error(&check.trace, &r.trace, b.window_start, b.window_start + WINDOW, b.scene.plane(0).contact.gap);
    let peak = r.trace.loads.contact_force_n.iter().copied().fold(0.0, f64::max);
    Ok(Reference { trace: r.trace, floor, peak_contact_force: peak })
}

/// Largest stable substep found: the smallest substeps count (1 … 4096) for which the window
/// runs without divergence and with a max scaled error below 1; returns (step, substeps).
pub fn stability_limit(b: &BenchScene, method: Method, reference: &Trace) -> anyhow::Result<Option<(f64, u32)>> {
    let stable = |n: u32| -> anyhow::Result<bool> {
        let s = with_integrator(&b.scene, method, IntegratorSetting::Substeps(n));
        let r = run(&s, &mut Quiet)?;
        let (_, max) =
            window_error(&r.trace, reference, b.window_start, b.window_start + WINDOW, s.plane(0).contact.gap);
        Ok(r.run.outcome == Outcome::Completed && max < 1.0)
    };
    // Double until stable, then bisect between the last unstable and the first stable count.
    let mut hi = 1u32;
    while !stable(hi)? {
        if hi >= 4096 {
            return Ok(None);
        }
        hi *= 2;
    }
    let mut lo = hi / 2;
    if lo >= 1 {
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if stable(mid)? {
                hi = mid;
            } else {
                lo = mid;
            }
        }
    }
    Ok(Some((b.scene.controller.period / hi as f64, hi)))
}

/// What `plant bench accuracy` measured.
pub struct AccuracyReport {
    /// All rows (Rust, then any peer rows).
    pub rows: Vec<AccuracyRow>,
    /// Per scene: name, reference floor (RMS, max).
    pub floors: Vec<(String, (f64, f64))>,
    /// Per scene and fixed-step method: the step found and the step estimated.
    pub stability: Vec<StabilityRow>,
}

/// Where the scipy peer lives and how to run it.
#[derive(Clone, Debug)]
pub struct Peer {
    /// Python interpreter (with scipy and numba).
    pub python: PathBuf,
    /// `bench/peer/run_peer.py`.
    pub script: PathBuf,
}

/// Runs the peer on one scene: writes its spec, runs `run_peer.py`, reads its rows.
fn run_peer(peer: &Peer, b: &BenchScene, out: &Path, quick: bool, repeats: usize) -> anyhow::Result<Vec<AccuracyRow>> {
    let spec_path = out.join(format!("spec_{}.json", b.name));
    let spec = super::peer::spec(&b.scene, 0, 1, Some(atol_scale(&b.scene)))?;
    crate::outfile::write(&spec_path, serde_json::to_string(&spec)?.as_bytes())?;
    let csv = out.join(format!("peer_{}.csv", b.name));
    let rtols = if quick { "1e-4,1e-7" } else { "1e-3,1e-4,1e-5,1e-6,1e-7,1e-8,1e-9,1e-10" };
    let status = std::process::Command::new(&peer.python)
        .arg(&peer.script)
        .arg(&spec_path)
        .arg(out.join(format!("reference_{}.csv", b.name)))
        .args(["--scene", b.name, "--rtols", rtols, "--repeats", &repeats.to_string(), "--out"])
        .arg(&csv)
        .status()
        .with_context(|| format!("starting the peer: {} {}", peer.python.display(), peer.script.display()))?;
    anyhow::ensure!(status.success(), "the peer failed on {} ({status})", b.name);
    rows::read_accuracy(&csv)
}

/// One timed run of a bench scene as a row of `accuracy.csv`.
fn timed_row(
    b: &BenchScene,
    reference: &Trace,
    s: &Scene,
    implementation: &str,
    method: Method,
    setting: IntegratorSetting,
    repeats: usize,
) -> anyhow::Result<AccuracyRow> {
    let (t0, t1) = (b.window_start, b.window_start + WINDOW);
    let m = measure(s, repeats)?;
    let (rms, max) = window_error(&m.result.trace, reference, t0, t1, b.scene.plane(0).contact.gap);
    let ok = m.result.run.outcome == Outcome::Completed && rms.is_finite();
    let (text, rtol, substeps) = AccuracyRow::setting_columns(setting);
    Ok(AccuracyRow {
        scene: b.name.to_string(),
        implementation: implementation.into(),
        method: method_name(method),
        setting: text,
        rtol,
        substeps,
        status: if ok { AccuracyStatus::Ok } else { AccuracyStatus::Diverged },
        err_rms: Some(rms),
        err_max: Some(max),
        wall_s_per_sim_s: m.best_wall / b.scene.duration,
        rhs_evals: Some(m.result.run.stats.rhs_evals),
        sim_s: Some(m.result.run.clock.simulated),
    })
}

/// A row as a log line.
fn describe(r: &AccuracyRow) -> String {
    let opt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.2e}"));
    format!(
        "{}: {} {} {}: error rms {} max {}, {:.3e} s per simulated s, {} evaluations ({})",
        r.scene,
        r.implementation,
        r.method,
        r.setting,
        opt(r.err_rms),
        opt(r.err_max),
        r.wall_s_per_sim_s,
        r.rhs_evals.map_or("-".to_string(), |n| n.to_string()),
        r.status
    )
}

/// Runs the work-precision and stability bench, writing into the folder `out` (made and
/// cleared by [`command`]); with `peer`, the scipy peer runs on the same scenes, references
/// and error measure, and its rows join the charts.
pub fn accuracy(
    config_dir: &Path,
    out: &Path,
    quick: bool,
    repeats: usize,
    peer: Option<&Peer>,
    log: &mut dyn FnMut(&str),
) -> anyhow::Result<AccuracyReport> {
    let mut report = AccuracyReport { rows: Vec::new(), floors: Vec::new(), stability: Vec::new() };
    for b in super::scenes(config_dir)? {
        let (t0, t1) = (b.window_start, b.window_start + WINDOW);
        log(&format!("{}: reference (DOP853 rtol 1e-13, checked with DP5 rtol 1e-11)", b.name));
        let reference = reference(&b)?;
        report.floors.push((b.name.to_string(), reference.floor));
        log(&format!(
            "{}: reference floor (DP5 1e-11 against DOP853 1e-13): rms {:.2e}, max {:.2e}; peak contact force {:.0} N",
            b.name, reference.floor.0, reference.floor.1, reference.peak_contact_force
        ));
        write_reference(&out.join(format!("reference_{}.csv", b.name)), &reference.trace, t0, t1)?;
        crate::outfile::write(&out.join(format!("scene_{}.toml", b.name)), b.scene.to_toml()?.as_bytes())?;
        for (method, settings) in grid(quick) {
            for setting in settings {
                let s = with_integrator(&b.scene, method, setting);
                let row = timed_row(&b, &reference.trace, &s, "rust", method, setting, repeats)?;
                log(&describe(&row));
                report.rows.push(row);
            }
        }
        // The race parked while the gap is clear, on the methods it can make cheaper: RK4 (with
        // the substeps the stability estimate asks for while the race is free) and DP5.
        let parked = b.scene.reload(&[super::PARKED.to_string()])?;
        for (method, settings) in grid(quick).into_iter().filter(|(m, _)| matches!(m, Method::Rk4 | Method::Dp5)) {
            for setting in settings {
                let mut s = with_integrator(&parked, method, setting);
                s.integrator.contact_substeps =
                    s.integrator.substeps.max(crate::stability::safe_contact_substeps(&s, method));
                let row = timed_row(&b, &reference.trace, &s, "rust parked", method, setting, repeats)?;
                log(&describe(&row));
                report.rows.push(row);
            }
        }
        if let Some(peer) = peer {
            log(&format!("{}: scipy peer (RK45, DOP853, LSODA)", b.name));
            let rows = run_peer(peer, &b, out, quick, repeats)?;
            for r in &rows {
                log(&describe(r));
            }
            report.rows.extend(rows);
        }
        for method in FIXED_STEP {
            let found = stability_limit(&b, method, &reference.trace)?;
            let estimate = crate::stability::estimate(&b.scene, method, reference.peak_contact_force);
            log(&format!(
                "{}: {} stable from step {:?} (estimate {:.3e} s)",
                b.name,
                method_name(method),
                found,
                estimate
            ));
            if let Some((_, n)) = found {
                if n > 1 {
                    failure_plot(out, &b, method, n / 2, &reference.trace)?;
                }
            }
            report.stability.push(StabilityRow {
                scene: b.name.to_string(),
                method: method_name(method),
                largest_stable_step_s: found.map(|(h, _)| h),
                substeps: found.map(|(_, n)| n),
                estimated_step_s: estimate,
            });
        }
    }
    rows::write_accuracy(&out.join("accuracy.csv"), &report.rows)?;
    crate::table::write_with_header(&out.join("stability.csv"), rows::STABILITY_HEADER, &report.stability)?;
    Ok(report)
}

/// Writes the reference's rotor position over `[t0, t1]` for the peer.
fn write_reference(path: &Path, trace: &Trace, t0: f64, t1: f64) -> anyhow::Result<()> {
    let rows: Vec<ReferenceRow> = (0..trace.len())
        .filter(|&i| trace.t_s[i] >= t0 - 1e-12 && trace.t_s[i] <= t1 + 1e-12)
        .map(|i| ReferenceRow { t_s: trace.t_s[i], dx_m: trace.motion.dx_m[i], dy_m: trace.motion.dy_m[i] })
        .collect();
    crate::table::write_with_header(path, rows::REFERENCE_HEADER, &rows)
}

/// The radius of a run just beyond its stability limit, against the reference.
fn failure_plot(out: &Path, b: &BenchScene, method: Method, substeps: u32, reference: &Trace) -> anyhow::Result<()> {
    let s = with_integrator(&b.scene, method, IntegratorSetting::Substeps(substeps));
    let r = run(&s, &mut Quiet)?;
    let ms = |t: &Trace| t.t_s.iter().map(|t| t * 1e3).collect::<Vec<f64>>();
    let um = |t: &Trace| t.radius().iter().map(|r| r * 1e6).collect::<Vec<f64>>();
    let (tr, rr, tf, rf) = (ms(reference), um(reference), ms(&r.trace), um(&r.trace));
    let label = format!(
        "{} with {substeps} substep{} (h = {:.2e} s)",
        method_name(method),
        if substeps == 1 { "" } else { "s" },
        s.controller.period / substeps as f64
    );
    plot::lines(
        &out.join(format!("failure_{}_{}.png", b.name, method_name(method))),
        &format!("{}: {} just beyond its stability limit", b.name, method_name(method)),
        "time (ms)",
        "rotor radius (µm)",
        &[Series { label: "reference (DOP853)", x: &tr, y: &rr }, Series { label: &label, x: &tf, y: &rf }],
        Scale::Log10,
    )
    .map_err(anyhow::Error::from)
}

/// Draws one work-precision chart per scene from the rows (Rust and peer).
pub fn charts(out: &Path, rows: &[AccuracyRow], floors: &[(String, (f64, f64))]) -> anyhow::Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    let scenes: Vec<String> = rows.iter().fold(Vec::new(), |mut v, r| {
        if !v.contains(&r.scene) {
            v.push(r.scene.clone());
        }
        v
    });
    for scene in scenes {
        let mut lines: Vec<(String, Vec<f64>, Vec<f64>)> = Vec::new();
        let (mut dx, mut dy) = (Vec::new(), Vec::new());
        let here: Vec<&AccuracyRow> = rows.iter().filter(|r| r.scene == scene).collect();
        let top = here.iter().filter(|r| r.status == AccuracyStatus::Ok).map(|r| r.rms()).fold(1.0, f64::max);
        for r in &here {
            let name = format!("{} {}", r.implementation, r.method);
            let at = match lines.iter().position(|l| l.0 == name) {
                Some(i) => i,
                None => {
                    lines.push((name, Vec::new(), Vec::new()));
                    lines.len() - 1
                }
            };
            if r.status == AccuracyStatus::Ok && r.rms() > 0.0 {
                lines[at].1.push(r.wall_s_per_sim_s);
                lines[at].2.push(r.rms());
            } else if r.wall_s_per_sim_s.is_finite() && r.wall_s_per_sim_s > 0.0 {
                dx.push(r.wall_s_per_sim_s);
                dy.push(top * 3.0);
            }
        }
        let floor = floors.iter().find(|f| f.0 == scene).map(|f| f.1 .0);
        let path = out.join(format!("work_precision_{scene}.png"));
        let series: Vec<Series> = lines.iter().map(|l| Series { label: &l.0, x: &l.1, y: &l.2 }).collect();
        let marks = [PointGroup { label: "diverged (drawn at the top)", x: &dx, y: &dy }];
        plot::loglog(
            &path,
            &format!(
                "{scene}: error against cost{}",
                floor.map_or(String::new(), |f| format!(" (reference floor {f:.1e})"))
            ),
            "wall time per simulated second (s)",
            "RMS error / air gap, 50 ms after the shock",
            &series,
            if dx.is_empty() { &[] } else { &marks },
        )?;
        written.push(path);
    }
    Ok(written)
}

/// `plant bench accuracy --redraw CSV`: the charts of an earlier run drawn again from its rows
/// (`accuracy.csv` and the `stability.csv` beside it), with today's `plot/`. Its timings are
/// kept: only the references (for the floors in the titles) and the runs just beyond each
/// stability limit (for the failure charts) run again, and neither is timed, so the pictures
/// show the earlier run's figures and not this host's load.
fn redraw(config: &Path, csv: &Path, dir: &Path, log: &mut dyn FnMut(&str)) -> anyhow::Result<Vec<PathBuf>> {
    let bad = |flag: &str, e: anyhow::Error| crate::exit::BadArgument(format!("{flag}: {e:#}"));
    let rows = rows::read_accuracy(csv).map_err(|e| bad("--redraw", e))?;
    let stability_csv = csv.with_file_name("stability.csv");
    let stability: Vec<StabilityRow> =
        crate::table::read(&stability_csv).map_err(|e| bad("--redraw (its stability.csv)", e))?;
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    crate::outfile::clear_earlier(dir, CHARTS)?;
    let (mut floors, mut written) = (Vec::new(), Vec::new());
    for b in super::scenes(config)? {
        log(&format!("{}: reference (DOP853 rtol 1e-13, checked with DP5 rtol 1e-11)", b.name));
        let reference = reference(&b)?;
        floors.push((b.name.to_string(), reference.floor));
        for s in stability.iter().filter(|s| s.scene == b.name) {
            let Some(method) = FIXED_STEP.into_iter().find(|m| method_name(*m) == s.method) else {
                continue;
            };
            if let Some(n) = s.substeps.filter(|n| *n > 1) {
                failure_plot(dir, &b, method, n / 2, &reference.trace)?;
                written.push(dir.join(format!("failure_{}_{}.png", b.name, s.method)));
            }
        }
    }
    written.extend(charts(dir, &rows, &floors)?);
    Ok(written)
}

/// What `plant bench accuracy` was asked to do.
pub struct Request<'a> {
    /// Output folder (default `runs/bench-accuracy`).
    pub out: Option<&'a Path>,
    /// The scene folder (`config/`); the peer script is `<config>/../bench/peer/run_peer.py`.
    pub config: &'a Path,
    /// Timed runs per setting (the fastest is kept).
    pub repeats: usize,
    /// The short grid.
    pub quick: bool,
    /// The Python interpreter of the scipy peer, to run it.
    pub peer_python: Option<&'a Path>,
    /// An earlier `accuracy.csv` whose peer rows join the charts.
    pub peer_rows: Option<&'a Path>,
    /// An earlier `accuracy.csv` (with its `stability.csv` beside it) to draw the charts from,
    /// instead of timing the runs again.
    pub redraw: Option<&'a Path>,
}

/// The files `plant bench accuracy` writes into its folder (per bench scene, and the failure
/// charts per fixed-step method that fails): an earlier run's are removed first, so that no
/// failure chart of a method that no longer fails is left beside this run's. `--redraw`
/// removes only the charts ([`CHARTS`]): the table it redraws may be the folder's own.
pub const FILES: &[&str] = &[
    "accuracy.csv",
    "stability.csv",
    "reference_*.csv",
    "scene_*.toml",
    "spec_*.json",
    "peer_*.csv",
    "work_precision_*.png",
    "failure_*.png",
];

/// The charts among [`FILES`].
pub const CHARTS: &[&str] = &["work_precision_*.png", "failure_*.png"];

/// `plant bench accuracy`: runs the bench, joins any earlier peer rows, draws the charts;
/// returns the files written.
pub fn command(req: &Request, log: &mut dyn FnMut(&str)) -> anyhow::Result<Vec<PathBuf>> {
    let dir = crate::output::out_dir(req.out, "bench-accuracy");
    if let Some(csv) = req.redraw {
        return redraw(req.config, csv, &dir, log);
    }
    let peer = req.peer_python.map(|python| Peer {
        script: req.config.join("..").join("bench").join("peer").join("run_peer.py"),
        python: python.to_path_buf(),
    });
    // Read the earlier rows first: they may live in the output folder.
    let earlier = req
        .peer_rows
        .map(|p| rows::read_accuracy(p).map_err(|e| crate::exit::BadArgument(format!("--peer-rows: {e:#}"))))
        .transpose()?
        .unwrap_or_default();
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    crate::outfile::clear_earlier(&dir, FILES)?;
    let mut report = accuracy(req.config, &dir, req.quick, req.repeats, peer.as_ref(), log)?;
    let mut written = vec![dir.join("accuracy.csv"), dir.join("stability.csv")];
    if !earlier.is_empty() {
        report.rows.extend(earlier.into_iter().filter(|r| !r.implementation.starts_with("rust")));
        rows::write_accuracy(&dir.join("accuracy.csv"), &report.rows)?;
    }
    written.extend(charts(&dir, &report.rows, &report.floors)?);
    Ok(written)
}
