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
//! Each form a file: the rates against the continuous PD ([`rates`]), stability maps of the
//! sampled law ([`maps`]), a comparison of control laws on one scene ([`laws`]), realtime against
//! lockstep ([`realtime`]); this file holds the command and what the forms share. Each table is one row type, its fields the columns in order:
//! `compare.csv` ([`RateRow`]), `stability_map.csv` ([`MapPoint`]), `laws.csv`
//! ([`LawRow`]), `realtime.csv` ([`RealtimeRow`]).

pub mod laws;
pub mod maps;
pub mod rates;
pub mod realtime;
pub mod robust;

pub use laws::{compare_laws, LawRow, LAWS_HEADER};
pub use maps::{stability_maps, MapPoint, MAP_HEADER};
pub use rates::{compare, RateRow, COMPARE_HEADER, WINDOW};
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

/// The output folder `out` made, and the overrides every run of a form starts from: the
/// command's `sets`, no plots (the form draws its own).
fn prepare(out: &Path, sets: &[String]) -> anyhow::Result<Vec<String>> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    Ok(sets.iter().cloned().chain(["output.plots=false".to_string()]).collect())
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

/// The files `plant compare` writes into its folder, over all its forms (rates and their
/// stability maps, laws, realtime, `--robustness`): an earlier comparison's are removed first,
/// so that another form's table, or a robustness table this one was not asked for, is not
/// left beside its results.
pub const FILES: &[&str] = &[
    "compare.csv",
    "compare_orbit.png",
    "compare_radius.png",
    "compare_robustness.csv",
    "compare_robustness.json",
    "laws.csv",
    "laws_current.png",
    "laws_orbit.png",
    "laws_radius.png",
    "realtime.csv",
    "realtime_radius.png",
    "stability_map.csv",
    "stability_*.png",
];

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
    crate::outfile::clear_earlier(&dir, FILES)?;
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
