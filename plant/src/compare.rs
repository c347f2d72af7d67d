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
//! Also stability maps of the sampled law ([`stability_maps`]) and a
//! comparison of control laws on one scene ([`compare_laws`]). Each table
//! is one row type, its fields the columns in order: `compare.csv`
//! ([`RateRow`]), `stability_map.csv` ([`MapPoint`]), `laws.csv`
//! ([`LawRow`]).

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
    let free = tr.contact_force_n.iter().position(|f| *f > 0.0).unwrap_or(tr.len());
    Ok(Some((
        damping_from_decay(&tr.t_s[..free], &tr.dx_m[..free]),
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
            if mode == ControlMode::Sampled {
                traces.push((format!("sampled {} kHz", rate / 1e3), r));
            }
        }
    }
    crate::table::write_with_header(&out.join("compare.csv"), COMPARE_HEADER, &rows)?;
    plots(out, &traces, start, &continuous)?;
    let planned = 1 + rates.len() * modes.len();
    interrupted(stop, || format!("{} of {planned} configurations finished, written to compare.csv", rows.len()))?;
    Ok(rows)
}

/// Header of `compare.csv`.
pub const COMPARE_HEADER: &str = "rate_hz,mode,status,rms_dev_m,max_dev_m,damping_ratio,recover_s,post_shock_mode";

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
            radius_um: idx.iter().map(|&i| tr.dx_m[i].hypot(tr.dy_m[i]) * 1e6).collect(),
            x_um: idx.iter().map(|&i| tr.dx_m[i] * 1e6).collect(),
            y_um: idx.iter().map(|&i| tr.dy_m[i] * 1e6).collect(),
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
}

/// `plant compare`: the rate comparison (and maps), or the law comparison; `warn` gets the
/// scene's own warnings once (deprecated keys), not once per compared run. Returns the table
/// written.
pub fn command(req: &Request, log: &mut dyn FnMut(&str), warn: &mut dyn FnMut(&str)) -> anyhow::Result<PathBuf> {
    for w in &load_scene(req.scene, req.set)?.warnings {
        warn(w);
    }
    let stem = req.scene.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let dir = req.out.map_or_else(|| PathBuf::from("runs").join(format!("compare-{stem}")), Path::to_path_buf);
    let _claim = crate::claim::claim(&dir, true)?;
    let stop = crate::interrupt::stop_flag();
    if let Some(runs) = req.realtime {
        compare_realtime(req.scene, req.set, runs, &dir, log, &stop)?;
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

    use crate::config::shipped as scene;

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

/// One point of a stability map: a row of `stability_map.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct MapPoint {
    /// `rate_damping` or `rate_delay`.
    pub map: &'static str,
    /// Controller rate (Hz).
    #[serde(with = "plain")]
    pub rate_hz: f64,
    /// Design damping ratio or delay in samples.
    #[serde(with = "plain")]
    pub value: f64,
    /// Damping ratio measured on the free decay (NaN if it diverged).
    #[serde(with = "sci")]
    pub damping_measured: f64,
    /// `unstable`, or `stable (<post-shock mode>)`.
    pub class: String,
}

/// Header of `stability_map.csv`.
pub const MAP_HEADER: &str = "map,rate_hz,value,damping_measured,class";

/// Stability maps of the sampled law: rate × design damping ratio and rate × delay (samples).
/// A point is unstable when its free decay grows (or diverges); a stable point is labelled
/// with the post-shock mode of the scene run at that setting.
pub fn stability_maps(
    scene_path: &Path,
    sets: &[String],
    rates: &[f64],
    out: &Path,
    log: &mut dyn FnMut(&str),
    stop: &AtomicBool,
) -> anyhow::Result<Vec<MapPoint>> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let base: Vec<String> = sets.iter().cloned().chain(["output.plots=false".to_string()]).collect();
    let probe = with(scene_path, &base, &[])?;
    let shocks = probe.shock_count();
    let mut points = Vec::new();
    let grids: [(&'static str, &'static str, Vec<f64>); 2] = [
        ("rate_damping", "controller.damping_ratio", vec![0.005, 0.01, 0.02, 0.03, 0.05, 0.1]),
        ("rate_delay", "controller.delay_samples", vec![0.0, 1.0, 2.0, 3.0]),
    ];
    let planned: usize = grids.iter().map(|g| g.2.len() * rates.len()).sum();
    'maps: for (map, key, values) in grids {
        for &rate in rates {
            for &v in &values {
                let value = if key.ends_with("delay_samples") { format!("{}", v as u32) } else { format!("{v:?}") };
                let extra = vec![
                    "controller.mode=\"sampled\"".to_string(),
                    format!("controller.rate_hz={rate:?}"),
                    format!("{key}={value}"),
                ];
                let Some((decay_xi, touched, completed)) = free_decay(scene_path, &base, &extra, shocks, stop)? else {
                    break 'maps;
                };
                let xi = if completed || touched { decay_xi } else { f64::NAN };
                let class = if xi.is_nan() || xi <= 0.0 || touched {
                    "unstable".to_string()
                } else {
                    let scene = with(scene_path, &base, &extra)?;
                    let Some(r) = finished(&scene, stop)? else { break 'maps };
                    let s = Summary::new(&scene, &r);
                    if r.run.outcome == Outcome::Completed {
                        format!("stable ({})", snake_name(&s.analysis.post_shock_mode))
                    } else {
                        "stable (diverged after the shock)".to_string()
                    }
                };
                log(&format!("{map}: {rate} Hz, {key} = {value}: measured damping {xi:.4}, {class}"));
                points.push(MapPoint { map, rate_hz: rate, value: v, damping_measured: xi, class });
            }
        }
    }
    crate::table::write_with_header(&out.join("stability_map.csv"), MAP_HEADER, &points)?;
    for (map, ylabel) in [("rate_damping", "design damping ratio ξ_e"), ("rate_delay", "delay (samples)")] {
        let mut classes: Vec<String> = points.iter().filter(|p| p.map == map).map(|p| p.class.clone()).collect();
        classes.sort();
        classes.dedup();
        let groups_data: Vec<(String, Vec<f64>, Vec<f64>)> = classes
            .iter()
            .map(|c| {
                let sel: Vec<&MapPoint> = points.iter().filter(|p| p.map == map && &p.class == c).collect();
                (c.clone(), sel.iter().map(|p| p.rate_hz / 1e3).collect(), sel.iter().map(|p| p.value).collect())
            })
            .collect();
        let groups: Vec<PointGroup> =
            groups_data.iter().map(|g| PointGroup { label: &g.0, x: &g.1, y: &g.2 }).collect();
        plot::scatter(
            &out.join(format!("stability_{map}.png")),
            &format!("{}: sampled {} — stability by rate and {}", probe.name, probe.controller.law, ylabel),
            "controller rate (kHz)",
            ylabel,
            &groups,
            false,
        )
        .or_else(|e| match e {
            // A map interrupted before its first point has nothing to draw.
            plot::PlotError::NoData { .. } if stop.load(Ordering::Relaxed) => Ok(()),
            e => Err(e),
        })?;
    }
    interrupted(stop, || format!("{} of {planned} map points finished, written to stability_map.csv", points.len()))?;
    Ok(points)
}

/// One law of a law comparison (`plant compare --laws`): a row of `laws.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct LawRow {
    /// Law name.
    pub law: String,
    /// Controller mode the scene ran in.
    pub mode: ControlMode,
    /// How the run ended.
    pub status: Status,
    /// Time from the shock start to the last rotor – race contact (s); NaN if still touching at the end.
    #[serde(with = "sci")]
    pub recovery_s: f64,
    /// Post-shock mode.
    pub post_shock_mode: MotionMode,
    /// Peak rotor – race force (N).
    #[serde(with = "sci")]
    pub max_contact_force_n: f64,
    /// Time in contact (s).
    #[serde(with = "sci")]
    pub contact_time_s: f64,
    /// Contact fraction over the last 200 revolutions.
    #[serde(with = "sci")]
    pub steady_contact_fraction: f64,
    /// Whirl frequency of the steady response (Hz, negative backward).
    #[serde(with = "sci")]
    pub whirl_hz: f64,
}

/// Header of `laws.csv`.
pub const LAWS_HEADER: &str =
    "law,mode,status,recovery_s,post_shock_mode,max_contact_force_n,contact_time_s,steady_contact_fraction,whirl_hz";

/// Runs the scene once per law (in the scene's controller mode, so a co-simulation scene runs
/// the controller process), and writes `laws.csv` and overlaid plots of the whole run. The
/// scene's `[controller.params]` go to its own law only; the other laws run with their
/// default parameters.
pub fn compare_laws(
    scene_path: &Path,
    sets: &[String],
    laws: &[String],
    out: &Path,
    log: &mut dyn FnMut(&str),
    stop: &AtomicBool,
) -> anyhow::Result<Vec<LawRow>> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let base: Vec<String> = sets.iter().cloned().chain(["output.plots=false".to_string()]).collect();
    let mut rows = Vec::new();
    let mut runs: Vec<(String, RunResult)> = Vec::new();
    let mut probe = None;
    let own = with(scene_path, &base, &[])?.controller.law;
    for law in laws {
        // The scene's `[controller.params]` belong to its own law; another law runs on its defaults.
        let mut extra = vec![format!("controller.law=\"{law}\"")];
        if *law != own {
            extra.push("controller.params={}".to_string());
        }
        let scene = with(scene_path, &base, &extra)?;
        let Some(r) = finished(&scene, stop)? else { break };
        let s = Summary::new(&scene, &r);
        let row = LawRow {
            law: law.clone(),
            mode: scene.controller.mode,
            status: s.status,
            recovery_s: s.recovery_s.unwrap_or(f64::NAN),
            post_shock_mode: s.analysis.post_shock_mode,
            max_contact_force_n: s.max_contact_force_n.unwrap_or(f64::NAN),
            contact_time_s: s.contact_time_s,
            steady_contact_fraction: s.analysis.steady_contact_fraction,
            whirl_hz: s.analysis.whirl_hz,
        };
        log(&format!(
            "{law} ({}): {}, {}, {}, peak force {:.0} N, {:.4} s in contact, whirl {:.1} Hz",
            snake_name(&row.mode),
            row.status,
            recovered(row.recovery_s),
            row.post_shock_mode,
            row.max_contact_force_n,
            row.contact_time_s,
            row.whirl_hz
        ));
        rows.push(row);
        runs.push((law.clone(), r));
        probe = Some(scene);
    }
    if rows.is_empty() {
        return Err(nothing_finished());
    }
    crate::table::write_with_header(&out.join("laws.csv"), LAWS_HEADER, &rows)?;
    if let Some(scene) = probe {
        law_plots(out, &runs, &scene)?;
    }
    interrupted(stop, || format!("{} of {} laws finished, written to laws.csv", rows.len(), laws.len()))?;
    Ok(rows)
}

fn law_plots(out: &Path, runs: &[(String, RunResult)], scene: &Scene) -> anyhow::Result<()> {
    let name = &scene.name;
    let gap = gap_words(scene);
    // Each plane's radius and coil current of each law's run.
    let planes: Vec<(String, crate::trace::Trace)> = runs.iter().flat_map(|(l, r)| plane_traces(l, &r.trace)).collect();
    let radius: Vec<Vec<f64>> = planes.iter().map(|(_, t)| t.radius().iter().map(|v| v * 1e6).collect()).collect();
    let current: Vec<Vec<f64>> =
        planes.iter().map(|(_, t)| t.ix_a.iter().zip(&t.iy_a).map(|(x, y)| x.hypot(*y)).collect()).collect();
    let series = |ys: &[Vec<f64>]| -> Vec<(String, Vec<f64>, Vec<f64>)> {
        planes.iter().zip(ys).map(|((l, t), y)| (l.clone(), t.t_s.clone(), y.clone())).collect()
    };
    for (file, title, ylabel, data) in [
        ("laws_radius.png", format!("{name}: rotor radius by law ({gap})"), "radius (µm)", &radius),
        ("laws_current.png", format!("{name}: coil current magnitude by law"), "|i| (A)", &current),
    ] {
        let d = series(data);
        let s: Vec<Series> = d.iter().map(|(l, x, y)| Series { label: l, x, y }).collect();
        plot::lines(&out.join(file), &title, "time (s)", ylabel, &s, Scale::Linear)?;
    }
    let start = scene.first_shock_start();
    let orbits: Vec<(String, Vec<f64>, Vec<f64>)> = planes
        .iter()
        .map(|(l, tr)| {
            let idx: Vec<usize> = (0..tr.len()).filter(|&i| tr.t_s[i] >= start).collect();
            (
                l.clone(),
                idx.iter().map(|&i| tr.dx_m[i] * 1e6).collect(),
                idx.iter().map(|&i| tr.dy_m[i] * 1e6).collect(),
            )
        })
        .collect();
    let groups: Vec<PointGroup> = orbits.iter().map(|(l, x, y)| PointGroup { label: l, x, y }).collect();
    plot::scatter(
        &out.join("laws_orbit.png"),
        &format!("{name}: orbits after the shock, by law"),
        "x (µm)",
        "y (µm)",
        &groups,
        true,
    )?;
    Ok(())
}

/// One run of a realtime comparison (`plant compare --realtime`): a row of `realtime.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct RealtimeRow {
    /// 0 for the lockstep run, 1… for the realtime runs.
    pub run: usize,
    /// `lockstep` or `realtime`.
    pub mode: ControlMode,
    /// How the run ended.
    pub status: Status,
    /// Ticks whose reply was missing (realtime).
    pub deadline_misses: u64,
    /// Their share of the ticks with a reply due.
    #[serde(with = "sci")]
    pub deadline_miss_fraction: f64,
    /// Longest run of consecutive misses.
    pub longest_miss_burst: u64,
    /// Ticks started more than a period late (realtime).
    pub plant_overruns: u64,
    /// The plant's whole tick, 99.9th percentile (µs).
    #[serde(with = "sci")]
    pub tick_p999_us: f64,
    /// … largest (µs).
    #[serde(with = "sci")]
    pub tick_max_us: f64,
    /// The integration alone, 99.9th percentile (µs).
    #[serde(with = "sci")]
    pub integration_p999_us: f64,
    /// … largest (µs).
    #[serde(with = "sci")]
    pub integration_max_us: f64,
    /// Sensor frame published → reply published, 99.9th percentile (µs).
    #[serde(with = "sci")]
    pub latency_p999_us: f64,
    /// Post-shock mode.
    pub post_shock_mode: MotionMode,
    /// Time from the shock start to the last contact (s); NaN if still in contact at the end.
    #[serde(with = "sci")]
    pub recovery_s: f64,
    /// Peak rotor – race force (N).
    #[serde(with = "sci")]
    pub max_contact_force_n: f64,
    /// Largest rotor radius (m).
    #[serde(with = "sci")]
    pub max_radius_m: f64,
    /// Contact fraction over the last 200 revolutions.
    #[serde(with = "sci")]
    pub steady_contact_fraction: f64,
    /// RMS distance of the rotor displacement from the lockstep run's over the whole run (m).
    #[serde(with = "sci")]
    pub rms_dev_m: f64,
    /// Largest distance (m).
    #[serde(with = "sci")]
    pub max_dev_m: f64,
    /// The trace is the lockstep run's, bit for bit (every run without a deadline miss is).
    pub same_as_lockstep: bool,
    /// The machine's load average over the last minute when the run ended.
    #[serde(with = "sci")]
    pub load_1min: f64,
}

/// Header of `realtime.csv`.
pub const REALTIME_HEADER: &str = "run,mode,status,deadline_misses,deadline_miss_fraction,longest_miss_burst,\
plant_overruns,tick_p999_us,tick_max_us,integration_p999_us,integration_max_us,latency_p999_us,post_shock_mode,\
recovery_s,max_contact_force_n,max_radius_m,steady_contact_fraction,rms_dev_m,max_dev_m,same_as_lockstep,load_1min";

/// Realtime against lockstep (`plant compare SCENE --realtime --runs N`): the scene in
/// realtime `runs` times, and once in lockstep on the same integrator setting (the realtime
/// one, [`Scene::fixed_step_overrides`] unless `integrator.realtime = "scene"`), so that the
/// only difference is the wall clock: a realtime run without a deadline miss is the lockstep
/// run bit for bit, and a run that differs shows what the host did to the outcome. Writes
/// `realtime.csv` ([`RealtimeRow`]) and `realtime_radius.png`.
pub fn compare_realtime(
    scene_path: &Path,
    sets: &[String],
    runs: usize,
    out: &Path,
    log: &mut dyn FnMut(&str),
    stop: &AtomicBool,
) -> anyhow::Result<Vec<RealtimeRow>> {
    if !(1..=1000).contains(&runs) {
        return Err(crate::exit::BadArgument(format!("--runs {runs}: must be between 1 and 1000")).into());
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let base: Vec<String> = sets.iter().cloned().chain(["output.plots=false".to_string()]).collect();
    let realtime = with(scene_path, &base, &["controller.mode=\"realtime\"".into()])?;
    // The realtime scene as resolved holds its integrator setting: the lockstep twin keeps it.
    let lockstep = realtime.reload(&["controller.mode=\"lockstep\"".into()])?;
    let reference = finished(&lockstep, stop)?.ok_or_else(nothing_finished)?;
    let start = lockstep.first_shock_start();
    let row = |n: usize, scene: &Scene, r: &RunResult| {
        let s = Summary::new(scene, r);
        let c = s.cosim.clone();
        let tet = c.as_ref().and_then(|c| c.tet_us).unwrap_or_default();
        let (rms, max) = match r.run.outcome {
            Outcome::Completed => crate::trace::window_error(&r.trace, &reference.trace, 0.0, scene.duration, 1.0),
            _ => (f64::INFINITY, f64::INFINITY),
        };
        RealtimeRow {
            run: n,
            mode: scene.controller.mode,
            status: s.status,
            deadline_misses: c.as_ref().map_or(0, |c| c.deadline_misses),
            deadline_miss_fraction: c.as_ref().map_or(0.0, |c| c.deadline_miss_fraction),
            longest_miss_burst: c.as_ref().map_or(0, |c| c.longest_miss_burst),
            plant_overruns: c.as_ref().map_or(0, |c| c.plant_overruns),
            tick_p999_us: tet.tick.p999,
            tick_max_us: tet.tick.max,
            integration_p999_us: tet.integration.p999,
            integration_max_us: tet.integration.max,
            latency_p999_us: c.as_ref().map_or(f64::NAN, |c| c.latency_us.p999),
            post_shock_mode: s.analysis.post_shock_mode,
            recovery_s: recovery_time(&r.trace, start).unwrap_or(f64::NAN),
            max_contact_force_n: s.max_contact_force_n.unwrap_or(f64::NAN),
            max_radius_m: s.max_radius_m.unwrap_or(f64::NAN),
            steady_contact_fraction: s.analysis.steady_contact_fraction,
            rms_dev_m: rms,
            max_dev_m: max,
            same_as_lockstep: same_bits(&r.trace, &reference.trace),
            load_1min: crate::bench::tick::load_average(),
        }
    };
    let say = |r: &RealtimeRow| {
        format!(
            "{} {}: {}, {} deadline misses ({:.3} %, longest burst {}), {} plant overruns, tick p99.9 {:.1} µs max {:.1} µs; \
             {}, {}, peak force {:.0} N; {}; load {:.2}",
            snake_name(&r.mode),
            r.run,
            r.status,
            r.deadline_misses,
            100.0 * r.deadline_miss_fraction,
            r.longest_miss_burst,
            r.plant_overruns,
            r.tick_p999_us,
            r.tick_max_us,
            r.post_shock_mode,
            recovered(r.recovery_s),
            r.max_contact_force_n,
            if r.same_as_lockstep { "the lockstep trace bit for bit".to_string() } else { format!("max {:.2e} m from lockstep", r.max_dev_m) },
            r.load_1min
        )
    };
    let mut rows = vec![row(0, &lockstep, &reference)];
    log(&say(&rows[0]));
    let mut traces: Vec<(String, RunResult)> = Vec::new();
    for n in 1..=runs {
        let Some(r) = finished(&realtime, stop)? else { break };
        let rw = row(n, &realtime, &r);
        log(&say(&rw));
        rows.push(rw);
        if traces.len() < 9 {
            traces.push((format!("realtime {n}"), r));
        }
    }
    crate::table::write_with_header(&out.join("realtime.csv"), REALTIME_HEADER, &rows)?;
    traces.insert(0, ("lockstep".into(), reference));
    let radius: Vec<(String, Vec<f64>, Vec<f64>)> = traces
        .iter()
        .flat_map(|(l, r)| plane_traces(l, &r.trace))
        .map(|(l, t)| (l, t.t_s.clone(), t.radius().iter().map(|v| v * 1e6).collect()))
        .collect();
    let series: Vec<Series> = radius.iter().map(|(l, x, y)| Series { label: l, x, y }).collect();
    plot::lines(
        &out.join("realtime_radius.png"),
        &format!("{}: rotor radius, realtime against lockstep ({})", realtime.name, gap_words(&realtime)),
        "time (s)",
        "radius (µm)",
        &series,
        Scale::Linear,
    )?;
    interrupted(stop, || format!("{} of {} runs finished, written to realtime.csv", rows.len(), runs + 1))?;
    Ok(rows)
}

/// Two traces hold the same numbers, bit for bit.
fn same_bits(a: &crate::trace::Trace, b: &crate::trace::Trace) -> bool {
    a.len() == b.len() && a.rows().zip(b.rows()).all(|(x, y)| x.iter().zip(&y).all(|(p, q)| p.to_bits() == q.to_bits()))
}
