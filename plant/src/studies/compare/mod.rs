//! Sampled against continuous control (`plant compare`): the same scene with
//! the continuous PD (the study's setup) and with the law sampled at each
//! rate, in-process and over iceoryx2 (lockstep).
//!
//! Per run: the deviation from the continuous run (rotor displacement,
//! RMS and max over the first 100 ms after the shock), the effective damping
//! ratio of the levitated loop from a free decay (a separate run: no shock,
//! no unbalance, 20 µm initial offset; log decrement of the peaks), the time
//! to recover (from the shock start to the last rotor – race contact) and the
//! post-shock mode.
//!
//! The other forms, a file each: stability maps of the sampled law ([`maps`]), a
//! comparison of control laws on one scene ([`laws`]), realtime against lockstep
//! ([`realtime`]). Each table is one row type, its fields the columns in order:
//! `compare.csv` ([`RateRow`]), `stability_map.csv` ([`MapPoint`]), `laws.csv`
//! ([`LawRow`]), `realtime.csv` ([`RealtimeRow`]).

pub mod laws;
pub mod maps;
pub mod realtime;
pub mod robust;

pub use laws::{compare_laws, LawRow, LAWS_HEADER};
pub use maps::{stability_maps, MapPoint, MAP_HEADER};
pub use realtime::{compare_realtime, RealtimeRow, REALTIME_HEADER};

use crate::analysis::classify::MotionMode;
use crate::config::{load_scene, ControlMode, Scene};
use crate::exit::Ending;
use crate::hooks::Cancel;
use crate::plot::{self, PointGroup, Scale, Series};
use crate::run::{run, Outcome, RunResult};
use crate::status::Status;
use crate::summary::{recovery_time, snake_name, Summary};
use crate::table::{plain, sci};
use anyhow::Context;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// Window after the shock for the deviation (s).
pub const WINDOW: f64 = 0.1;

crate::table::table_row! {
/// One compared configuration: a row of `compare.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct RateRow {
    /// Controller rate (Hz); 0 for the continuous run.
    #[serde(with = "plain")]
    pub rate_hz: f64,
    /// `continuous`, `sampled` or `lockstep`.
    pub mode: ControlMode,
    /// How the run ended.
    pub status: Status,
    /// RMS deviation of the rotor displacement from the continuous run (m).
    #[serde(with = "sci")]
    pub rms_dev_m: f64,
    /// Max deviation (m).
    #[serde(with = "sci")]
    pub max_dev_m: f64,
    /// Damping ratio of the levitated loop measured from a free decay.
    #[serde(with = "sci")]
    pub damping_ratio: f64,
    /// Time from the shock start to the last contact (s); NaN if still in contact at the end.
    #[serde(with = "sci")]
    pub recover_s: f64,
    /// Post-shock mode.
    pub post_shock_mode: MotionMode,
}
}

fn with(path: &Path, base: &[String], extra: &[String]) -> anyhow::Result<Scene> {
    let mut sets = base.to_vec();
    sets.extend_from_slice(extra);
    Ok(load_scene(path, &sets)?)
}

/// Damping ratio from the peaks of a decaying oscillation `x(t)`.
pub fn damping_from_decay(t: &[f64], x: &[f64]) -> f64 {
    let peaks: Vec<(f64, f64)> = (1..x.len().saturating_sub(1))
        .filter(|&i| x[i] > x[i - 1] && x[i] >= x[i + 1] && x[i] > 0.0)
        .map(|i| (t[i], x[i]))
        .collect();
    if peaks.len() < 3 {
        return f64::NAN;
    }
    let n = peaks.len() - 1;
    let delta = (peaks[0].1 / peaks[n].1).ln() / n as f64;
    delta / (4.0 * std::f64::consts::PI * std::f64::consts::PI + delta * delta).sqrt()
}

/// Distance of the rotor displacement from the reference's over the window (m): (RMS, max);
/// infinite for a run that did not complete.
fn deviation(r: &RunResult, reference: &RunResult, start: f64) -> (f64, f64) {
    if r.run.outcome != Outcome::Completed {
        return (f64::INFINITY, f64::INFINITY);
    }
    if r.trace.planes() == 1 {
        return crate::trace::window_error(&r.trace, &reference.trace, start, start + WINDOW, 1.0);
    }
    // The worse of the two bearing planes.
    (0..r.trace.planes()).fold((0.0, 0.0), |(rms, max), i| {
        let (a, b) = (r.trace.plane(i), reference.trace.plane(i));
        let (e_rms, e_max) = crate::trace::window_error(&a, &b, start, start + WINDOW, 1.0);
        (f64::max(rms, e_rms), f64::max(max, e_max))
    })
}

/// Time from `start` to the last contact of any bearing plane (s); `None` if one is still
/// touching at the end.
fn recovery(r: &RunResult, start: f64) -> Option<f64> {
    (0..r.trace.planes()).try_fold(0.0, |latest: f64, i| recovery_time(&r.trace.plane(i), start).map(|t| latest.max(t)))
}

/// A free decay of the levitated loop: 20 µm initial offset, no unbalance, the shocks moved
/// past its end, 0.6 s. Returns the damping ratio of the part before any rotor – race contact
/// (a growing oscillation that reaches the race is capped by it, which would fake the
/// estimate), whether a contact happened, and whether the run completed.
fn free_decay(
    scene_path: &Path,
    base: &[String],
    extra: &[String],
    shocks: usize,
    stop: &AtomicBool,
) -> anyhow::Result<Option<(f64, bool, bool)>> {
    let mut sets = extra.to_vec();
    sets.extend([
        "rotor.eccentricity_um=0.0".to_string(),
        "initial.rotor_x_um=20.0".to_string(),
        "scene.duration_s=0.6".to_string(),
    ]);
    sets.extend((0..shocks).map(|i| format!("shock[{i}].start_s=1000.0")));
    let Some(r) = finished(&with(scene_path, base, &sets)?, stop)? else { return Ok(None) };
    let tr = &r.trace;
    let free = tr.loads.contact_force_n.iter().position(|f| *f > 0.0).unwrap_or(tr.len());
    Ok(Some((
        damping_from_decay(&tr.t_s[..free], &tr.motion.dx_m[..free]),
        free < tr.len(),
        r.run.outcome == Outcome::Completed,
    )))
}

/// One run of a comparison, stopped by `stop` (SIGINT/SIGTERM): `None` once the flag is set
/// (a run it stopped part-way is not kept), so that the comparison writes the runs it finished.
fn finished(scene: &Scene, stop: &AtomicBool) -> anyhow::Result<Option<RunResult>> {
    if stop.load(Ordering::Relaxed) {
        return Ok(None);
    }
    match run(scene, &mut Cancel(stop)) {
        Ok(r) if r.run.outcome == Outcome::Interrupted => Ok(None),
        Ok(r) => Ok(Some(r)),
        // A co-simulated run interrupted while it waited for its controller.
        Err(_) if stop.load(Ordering::Relaxed) => Ok(None),
        Err(e) => Err(e.into()),
    }
}

/// `Err` (exit 130) when `stop` was set, also while the outputs were written: `what`
/// says what was written.
fn interrupted(stop: &AtomicBool, what: impl FnOnce() -> String) -> anyhow::Result<()> {
    if stop.load(Ordering::Relaxed) {
        return Err(Ending::Interrupted(what()).into());
    }
    Ok(())
}

/// The error of a comparison interrupted before its first run finished: nothing written.
fn nothing_finished() -> anyhow::Error {
    Ending::Interrupted("before the first run finished; nothing was written".into()).into()
}

/// Runs the comparison and writes `compare.csv` and the plots into `out`.
pub fn compare(
    scene_path: &Path,
    sets: &[String],
    rates: &[f64],
    cosim: bool,
    out: &Path,
    log: &mut dyn FnMut(&str),
    stop: &AtomicBool,
) -> anyhow::Result<Vec<RateRow>> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let base: Vec<String> = sets.iter().cloned().chain(["output.plots=false".to_string()]).collect();
    let continuous = with(scene_path, &base, &["controller.mode=\"continuous\"".into()])?;
    let start = continuous.first_shock_start();
    // All traces on the same grid: the output rate of the scene.
    let reference = finished(&continuous, stop)?.ok_or_else(nothing_finished)?;
    let shocks = continuous.shock_count();
    let decay = |extra: &[String]| free_decay(scene_path, &base, extra, shocks, stop).map(|d| d.map(|(xi, _, _)| xi));
    let row = |rate: f64, mode: ControlMode, r: &RunResult, scene: &Scene, xi: f64| {
        let (rms, max) = if mode == ControlMode::Continuous { (0.0, 0.0) } else { deviation(r, &reference, start) };
        let s = Summary::new(scene, r);
        RateRow {
            rate_hz: rate,
            mode,
            status: s.status,
            rms_dev_m: rms,
            max_dev_m: max,
            damping_ratio: xi,
            recover_s: recovery(r, start).unwrap_or(f64::NAN),
            post_shock_mode: s.analysis.post_shock_mode,
        }
    };
    let Some(xi) = decay(&["controller.mode=\"continuous\"".into()])? else { return Err(nothing_finished()) };
    let mut rows = vec![row(0.0, ControlMode::Continuous, &reference, &continuous, xi)];
    log(&format!("continuous: damping ratio {:.4}", rows[0].damping_ratio));
    // Each run's robustness answer, when asked for (`--robustness N`; robust.rs).
    let mut answers = Vec::new();
    let continuous_sets: Vec<String> = base.iter().cloned().chain(["controller.mode=\"continuous\"".into()]).collect();
    let summary = Summary::new(&continuous, &reference);
    answers.extend(robust::answer(scene_path, &continuous_sets, &continuous, &summary, "continuous", log, stop)?);
    let mut traces: Vec<(String, RunResult)> = vec![("continuous".into(), reference.clone())];
    let modes = if cosim { vec![ControlMode::Sampled, ControlMode::Lockstep] } else { vec![ControlMode::Sampled] };
    'rates: for &rate in rates {
        for &mode in &modes {
            let name = snake_name(&mode);
            let extra = vec![format!("controller.mode=\"{name}\""), format!("controller.rate_hz={rate:?}")];
            let scene = with(scene_path, &base, &extra)?;
            let Some(r) = finished(&scene, stop)? else { break 'rates };
            let xi = if mode == ControlMode::Sampled {
                let Some(xi) = decay(&extra)? else { break 'rates };
                xi
            } else {
                rows.last().map_or(f64::NAN, |r| r.damping_ratio)
            };
            let rw = row(rate, mode, &r, &scene, xi);
            log(&format!(
                "{name} at {rate} Hz: {}, deviation rms {:.2e} m max {:.2e} m, damping ratio {:.4}, {}, {}",
                rw.status,
                rw.rms_dev_m,
                rw.max_dev_m,
                rw.damping_ratio,
                recovered(rw.recover_s),
                rw.post_shock_mode
            ));
            rows.push(rw);
            let sets: Vec<String> = base.iter().cloned().chain(extra.iter().cloned()).collect();
            let label = format!("{name} {rate} Hz");
            answers.extend(robust::answer(scene_path, &sets, &scene, &Summary::new(&scene, &r), &label, log, stop)?);
            if mode == ControlMode::Sampled {
                traces.push((format!("sampled {} kHz", rate / 1e3), r));
            }
        }
    }
    crate::table::write_with_header(&out.join("compare.csv"), COMPARE_HEADER, &rows)?;
    robust::write(out, &answers)?;
    plots(out, &traces, start, &continuous)?;
    let planned = 1 + rates.len() * modes.len();
    interrupted(stop, || format!("{} of {planned} configurations finished, written to compare.csv", rows.len()))?;
    Ok(rows)
}

/// Header of `compare.csv`.
pub const COMPARE_HEADER: &str = RateRow::HEADER;

/// The first [`WINDOW`] after the shock of one run, in ms and µm.
struct Window {
    t_ms: Vec<f64>,
    radius_um: Vec<f64>,
    x_um: Vec<f64>,
    y_um: Vec<f64>,
}

impl Window {
    /// Of a trace in the planar columns (one bearing plane's, [`crate::trace::Trace::plane`]).
    fn of(tr: &crate::trace::Trace, start: f64) -> Self {
        let idx: Vec<usize> = (0..tr.len()).filter(|&i| tr.t_s[i] >= start && tr.t_s[i] <= start + WINDOW).collect();
        Window {
            t_ms: idx.iter().map(|&i| (tr.t_s[i] - start) * 1e3).collect(),
            radius_um: idx.iter().map(|&i| tr.motion.dx_m[i].hypot(tr.motion.dy_m[i]) * 1e6).collect(),
            x_um: idx.iter().map(|&i| tr.motion.dx_m[i] * 1e6).collect(),
            y_um: idx.iter().map(|&i| tr.motion.dy_m[i] * 1e6).collect(),
        }
    }
}

/// The air gap in a chart's title: `air gap 250 µm`, or each bearing plane's of a two-plane rotor.
fn gap_words(scene: &Scene) -> String {
    let um = |i: usize| scene.plane(i).contact.gap * 1e6;
    match scene.planes() {
        1 => format!("air gap {:.0} µm", um(0)),
        _ => format!("air gaps A {:.0} µm, B {:.0} µm", um(0), um(1)),
    }
}

/// Each bearing plane's trace (in the planar columns) with its label: `label` for a planar run,
/// `label A`, `label B` for a two-plane one (each plane's radius is against its own gap).
fn plane_traces(label: &str, trace: &crate::trace::Trace) -> Vec<(String, crate::trace::Trace)> {
    match trace.planes() {
        1 => vec![(label.to_owned(), trace.clone())],
        n => (0..n).map(|i| (format!("{label} {}", ["A", "B"][i]), trace.plane(i))).collect(),
    }
}

fn plots(out: &Path, traces: &[(String, RunResult)], start: f64, scene: &Scene) -> anyhow::Result<()> {
    let (gap, name) = (gap_words(scene), &scene.name);
    let data: Vec<(String, Window)> =
        traces.iter().flat_map(|(l, r)| plane_traces(l, &r.trace)).map(|(l, t)| (l, Window::of(&t, start))).collect();
    let radius: Vec<Series> = data.iter().map(|(l, d)| Series { label: l, x: &d.t_ms, y: &d.radius_um }).collect();
    plot::lines(
        &out.join("compare_radius.png"),
        &format!("{name}: rotor radius, first {:.0} ms after the shock ({gap})", WINDOW * 1e3),
        "time after the shock (ms)",
        "radius (µm)",
        &radius,
        Scale::Linear,
    )?;
    let orbits: Vec<PointGroup> = data.iter().map(|(l, d)| PointGroup { label: l, x: &d.x_um, y: &d.y_um }).collect();
    plot::scatter(
        &out.join("compare_orbit.png"),
        &format!("{name}: orbits, first {:.0} ms after the shock", WINDOW * 1e3),
        "x (µm)",
        "y (µm)",
        &orbits,
        true,
    )?;
    Ok(())
}

/// What `plant compare` was asked to do.
pub struct Request<'a> {
    /// The scene file.
    pub scene: &'a Path,
    /// `--set` overrides.
    pub set: &'a [String],
    /// Controller rates of the sampled (and lockstep) runs (Hz).
    pub rates: &'a [f64],
    /// Output folder (default `runs/compare-<scene file stem>`).
    pub out: Option<&'a Path>,
    /// Also run each rate over iceoryx2 (lockstep).
    pub cosim: bool,
    /// Also draw the stability maps.
    pub maps: bool,
    /// Compare these laws instead of rates.
    pub laws: &'a [String],
    /// Realtime against lockstep instead of rates: this many realtime runs.
    pub realtime: Option<usize>,
    /// Each compared run's robustness answer with this many perturbed members
    /// (`compare_robustness.csv`; the same as `--set robustness.members=N`).
    pub robustness: Option<u32>,
    /// `--live ADDR` of `--realtime`: the realtime runs served live ([`compare_realtime`]).
    pub live: Option<&'a str>,
}

/// `plant compare`: the rate comparison (and maps), or the law comparison; `warn` gets the
/// scene's own warnings once (deprecated keys), not once per compared run. Returns the table
/// written.
pub fn command(req: &Request, log: &mut dyn FnMut(&str), warn: &mut dyn FnMut(&str)) -> anyhow::Result<PathBuf> {
    let mut set = req.set.to_vec();
    set.extend(req.robustness.map(|n| format!("robustness.members={n}")));
    let req = &Request { set: &set, ..*req };
    let probe = load_scene(req.scene, req.set)?;
    // Bad members (out of range, or a realtime scene's) are refused before anything runs.
    crate::robustness::members(&probe)?;
    for w in &probe.warnings {
        warn(w);
    }
    let stem = req.scene.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let dir = req.out.map_or_else(|| PathBuf::from("runs").join(format!("compare-{stem}")), Path::to_path_buf);
    let _claim = crate::claim::claim(&dir, true)?;
    let stop = crate::interrupt::stop_flag();
    if let Some(runs) = req.realtime {
        compare_realtime(req.scene, req.set, runs, &dir, log, &stop, req.live)?;
        return Ok(dir.join("realtime.csv"));
    }
    if req.laws.is_empty() {
        compare(req.scene, req.set, req.rates, req.cosim, &dir, log, &stop)?;
        if req.maps {
            stability_maps(req.scene, req.set, req.rates, &dir, log, &stop)?;
        }
        Ok(dir.join("compare.csv"))
    } else {
        compare_laws(req.scene, req.set, req.laws, &dir, log, &stop)?;
        Ok(dir.join("laws.csv"))
    }
}

/// Parses `5k,10k,20000` into rates in Hz.
pub fn parse_rates(text: &str) -> Result<Vec<f64>, String> {
    text.split(',')
        .map(|r| {
            let r = r.trim();
            let (num, scale) = match r.strip_suffix(['k', 'K']) {
                Some(n) => (n, 1e3),
                None => (r, 1.0),
            };
            match num.parse::<f64>() {
                Ok(v) if v.is_finite() && v > 0.0 => Ok(v * scale),
                _ => Err(format!("--rates: `{r}` is not a rate in Hz (e.g. 20k or 20000)")),
            }
        })
        .collect()
}

/// The recovery for a progress line: "recovered after 0.1234 s", or "not recovered" for a run
/// still in contact at its end (NaN in the tables).
fn recovered(seconds: f64) -> String {
    if seconds.is_finite() {
        format!("recovered after {seconds:.4} s")
    } else {
        "not recovered".to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::shipped as scene;

    /// A chart of a two-plane rotor names each plane's gap and draws each plane's radius (it
    /// used plane A's gap for the whole rotor).
    #[test]
    fn charts_name_each_planes_gap_and_radius() {
        let planar = scene("paper-10g.toml", &[]);
        assert_eq!(gap_words(&planar), format!("air gap {:.0} µm", planar.plane(0).contact.gap * 1e6));
        let two = scene("two-plane-asymmetric-10g.toml", &["scene.duration_s=0.002", "output.plots=false"]);
        let (a, b) = (two.plane(0).contact.gap * 1e6, two.plane(1).contact.gap * 1e6);
        assert_ne!(a.round(), b.round(), "the asymmetric scene's gaps differ");
        assert_eq!(gap_words(&two), format!("air gaps A {a:.0} µm, B {b:.0} µm"));
        let run = crate::run::run(&two, &mut crate::run::Quiet).unwrap();
        let planes = plane_traces("pd", &run.trace);
        assert_eq!(planes.iter().map(|(l, _)| l.as_str()).collect::<Vec<_>>(), ["pd A", "pd B"]);
        assert_eq!(planes[1].1.radius(), run.trace.plane(1).radius());
        assert_eq!(plane_traces("pd", &run.trace.plane(0)).len(), 1);
    }

    #[test]
    fn rates_with_k_suffix() {
        assert_eq!(parse_rates("5k,10K, 20000").unwrap(), vec![5e3, 1e4, 2e4]);
        assert!(parse_rates("5k,x").unwrap_err().contains("`x`"));
        assert!(parse_rates("-1").is_err());
    }

    #[test]
    fn damping_from_a_known_decay() {
        let (xi, wn) = (0.02_f64, 300.0_f64);
        let wd = wn * (1.0 - xi * xi).sqrt();
        let t: Vec<f64> = (0..20_000).map(|i| i as f64 * 2e-5).collect();
        let x: Vec<f64> = t.iter().map(|t| (-xi * wn * t).exp() * (wd * t).cos()).collect();
        assert!((damping_from_decay(&t, &x) - xi).abs() < 1e-4);
    }
}
