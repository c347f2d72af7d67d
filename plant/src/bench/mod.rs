//! Measurements of the testbed itself (`plant bench …`): what each integrator
//! costs for the accuracy it reaches, what each model simplification costs
//! for the speed it gains, and the engineering figures each integrator
//! setting gives on full-length runs.
//!
//! * [`accuracy`]: work-precision data of every integrator on three scenes,
//!   the reference they are measured against, the stability limits of the
//!   fixed-step methods, and the scipy peer's rows (`accuracy.csv`,
//!   `stability.csv`, charts).
//! * [`models`]: the error and speed-up of each model simplification
//!   against the most detailed model (`models.csv`, charts).
//! * [`engineering`]: peak contact force, largest radius, contact fraction
//!   and post-shock mode per integrator setting on full-length runs
//!   (`engineering.csv`).
//! * [`tick`]: the plant's execution time per tick, alone, on the realtime setting and on the
//!   scene's own integrator (`tick.csv`).
//! * [`host`]: how late this host starts a realtime run's ticks with nothing to compute,
//!   sleeping and spinning (`host.csv`): the floor under every realtime run's overruns.
//! * [`rows`]: the columns of each table the benches write and read.
//! * [`peer`]: the spec an independent implementation of the derivative
//!   reads.
//!
//! This module holds what they share:
//!
//! * Scenes: `levitation` (1 G, no contact), `impact` (3 G: the rotor hits
//!   the race and bounces), `rub` (10 G: sustained rubbing). Each runs to
//!   50 ms after the shock, with continuous PD and a trace on the
//!   controller-tick grid.
//! * Error: `|Δ − Δ_ref| / r_0` of the rotor position relative to the
//!   housing, on the tick grid over the 50 ms after the shock (RMS and max).
//! * Cost: wall time of the simulation loop per simulated second (minimum
//!   of `repeats` runs, one thread).
//! * Tolerances of the adaptive methods scale per component: positions by
//!   r_0, angles by 2π, velocities by r_0 Ω and angular speeds by Ω
//!   (Ω the rotor speed): `atol_i = rtol × scale_i`.

pub mod accuracy;
pub mod engineering;
pub mod host;
pub mod models;
pub mod peer;
pub mod rows;
pub mod tick;

use crate::config::{load_scene, Scene};
use crate::integrate::Method;
use crate::model::N;
use crate::run::{run, Outcome, Quiet, RunResult};
use crate::trace::Trace;
use anyhow::Context;
use std::path::Path;

/// A scene of the bench.
pub struct BenchScene {
    /// Short name.
    pub name: &'static str,
    /// What it exercises.
    pub what: &'static str,
    /// The scene, ready to run.
    pub scene: Scene,
    /// Start of the error window (s): the shock start.
    pub window_start: f64,
}

/// The override that parks the race while the rotor – race gap is clear.
pub const PARKED: &str = "touchdown.race_when_clear=\"parked\"";

/// Window after the shock over which errors are measured (s).
pub const WINDOW: f64 = 0.05;

/// The three bench scenes, from the scene files in `config_dir`.
pub fn scenes(config_dir: &Path) -> anyhow::Result<Vec<BenchScene>> {
    let make = |name, what, file: &str, peak: f64| -> anyhow::Result<BenchScene> {
        let path = config_dir.join(file);
        let probe = load_scene(&path, &[]).with_context(|| format!("loading {}", path.display()))?;
        let start = probe.first_shock_start();
        let rate = 1.0 / probe.controller.period;
        let sets = vec![
            format!("shock[0].peak_g={peak:?}"),
            format!("scene.duration_s={:?}", start + WINDOW),
            format!("output.rate_hz={rate:?}"),
            "output.plots=false".to_string(),
        ];
        let scene = load_scene(&path, &sets).with_context(|| format!("loading {}", path.display()))?;
        Ok(BenchScene { name, what, scene, window_start: start })
    };
    Ok(vec![
        make("levitation", "1 G: levitated, no contact", "paper-3g.toml", 1.0)?,
        make("impact", "3 G: impact on the race and bounces", "paper-3g.toml", 3.0)?,
        make("rub", "10 G: sustained rubbing", "paper-10g.toml", 10.0)?,
    ])
}

/// How an integrator is tuned at one point of a bench: a tolerance or a step count.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IntegratorSetting {
    /// Adaptive: relative tolerance (absolute tolerances scaled from it).
    Rtol(f64),
    /// Fixed step: substeps per controller period.
    Substeps(u32),
}

impl std::fmt::Display for IntegratorSetting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            IntegratorSetting::Rtol(r) => write!(f, "rtol={r:e}"),
            IntegratorSetting::Substeps(n) => write!(f, "substeps={n}"),
        }
    }
}

/// Scale of the absolute tolerances of positions, velocities, angles and angular speeds (see
/// the module doc): plane A's gap, the gap times the spin speed, a turn, the spin speed.
pub fn atol_scale_groups(scene: &Scene) -> [f64; 4] {
    let (r0, w) = (scene.plane(0).contact.gap, scene.rotor.speed().max(1.0));
    [r0, r0 * w, std::f64::consts::TAU, w]
}

/// Per-component scale of the planar model's absolute tolerances ([`atol_scale_groups`] laid
/// out as [`crate::model::ix`]).
pub fn atol_scale(scene: &Scene) -> [f64; N] {
    <crate::model::Model as crate::machine::Machine<N>>::atol(atol_scale_groups(scene))
}

/// The scene with another integrator.
pub fn with_integrator(scene: &Scene, method: Method, setting: IntegratorSetting) -> Scene {
    let mut s = scene.clone();
    s.integrator.method = method;
    match setting {
        IntegratorSetting::Rtol(rtol) => {
            s.integrator.rtol = rtol;
            s.integrator.atol_groups = atol_scale_groups(scene).map(|g| rtol * g);
        }
        IntegratorSetting::Substeps(n) => s.integrator.substeps = n,
    }
    s
}

/// One run measured: its first trace, the best wall time, the evaluations.
pub struct Measured {
    /// The result of the first run.
    pub result: RunResult,
    /// Fastest wall time of the repeats (s).
    pub best_wall: f64,
}

/// Runs a scene `repeats` times (stopping early after a divergence).
pub fn measure(scene: &Scene, repeats: usize) -> anyhow::Result<Measured> {
    let result = run(scene, &mut Quiet)?;
    let mut best_wall = result.run.wall_time;
    if result.run.outcome == Outcome::Completed {
        for _ in 1..repeats {
            best_wall = best_wall.min(run(scene, &mut Quiet)?.run.wall_time);
        }
    }
    Ok(Measured { result, best_wall })
}

/// Scaled error `|Δ − Δ_ref| / r_0` on the common samples of `[t0, t1]`: (RMS, max).
/// A trace that stops early (diverged) counts as infinite error.
pub fn window_error(trace: &Trace, reference: &Trace, t0: f64, t1: f64, gap: f64) -> (f64, f64) {
    let (mut sum, mut max, mut n) = (0.0, 0.0_f64, 0usize);
    for (i, &t) in reference.t_s.iter().enumerate() {
        if t < t0 - 1e-12 || t > t1 + 1e-12 {
            continue;
        }
        let Some(&tt) = trace.t_s.get(i) else { return (f64::INFINITY, f64::INFINITY) };
        if (tt - t).abs() > 1e-9 {
            return (f64::INFINITY, f64::INFINITY);
        }
        let e = (trace.dx_m[i] - reference.dx_m[i]).hypot(trace.dy_m[i] - reference.dy_m[i]) / gap;
        if !e.is_finite() {
            return (f64::INFINITY, f64::INFINITY);
        }
        sum += e * e;
        max = max.max(e);
        n += 1;
    }
    if n == 0 {
        (f64::INFINITY, f64::INFINITY)
    } else {
        ((sum / n as f64).sqrt(), max)
    }
}

/// A method's name as the scene file writes it (`dp5`, `symplectic_euler`).
pub fn method_name(m: Method) -> String {
    crate::summary::snake_name(&m)
}

/// An argument of a bench command that cannot be used (bad input: exit 2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadArgument(pub String);

/// A bench stopped by SIGINT/SIGTERM (exit 130): what it had finished was written, as the
/// text says.
#[derive(Debug, thiserror::Error)]
#[error("interrupted: {0}")]
pub struct Interrupted(pub String);

/// The output folder of a bench: `out`, or `runs/<default>`.
pub fn out_dir(out: Option<&Path>, default: &str) -> std::path::PathBuf {
    out.map_or_else(|| Path::new("runs").join(default), Path::to_path_buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trace(t: &[f64], dx: &[f64], dy: &[f64]) -> Trace {
        let mut tr = Trace::default();
        for i in 0..t.len() {
            let mut row = [0.0; crate::trace::WIDTH];
            row[0] = t[i];
            row[1] = dx[i];
            row[2] = dy[i];
            tr.push_row(&row);
        }
        tr
    }

    #[test]
    fn window_error_is_the_rms_and_max_distance_over_the_window_scaled_by_the_gap() {
        let t = [0.0, 1.0, 2.0, 3.0];
        let reference = trace(&t, &[0.0; 4], &[0.0; 4]);
        // Distances 5 (outside the window), 3, 4 (inside), 100 (outside); gap 2.
        let run = trace(&t, &[3.0, 0.0, 4.0, 100.0], &[4.0, 3.0, 0.0, 0.0]);
        let (rms, max) = window_error(&run, &reference, 1.0, 2.0, 2.0);
        assert_eq!(max, 2.0);
        assert!((rms - (12.5_f64 / 4.0).sqrt()).abs() < 1e-15, "{rms}");
        // A run that stopped before the window's end, or off the reference's grid, is infinitely wrong.
        let short = trace(&t[..2], &[0.0; 2], &[0.0; 2]);
        assert_eq!(window_error(&short, &reference, 1.0, 2.0, 2.0), (f64::INFINITY, f64::INFINITY));
        let shifted = trace(&[0.0, 1.5, 2.0, 3.0], &[0.0; 4], &[0.0; 4]);
        assert_eq!(window_error(&shifted, &reference, 1.0, 2.0, 2.0), (f64::INFINITY, f64::INFINITY));
        // An empty window too.
        assert_eq!(window_error(&run, &reference, 5.0, 6.0, 2.0), (f64::INFINITY, f64::INFINITY));
    }

    #[test]
    fn tolerances_scale_per_component_and_settings_reach_the_integrator() {
        let scene = crate::config::validate(crate::config::RawScene::default(), Path::new(".")).unwrap();
        let s = with_integrator(&scene, Method::Dop853, IntegratorSetting::Rtol(1e-8));
        assert_eq!(s.integrator.method, Method::Dop853);
        assert_eq!(s.integrator.rtol, 1e-8);
        let (r0, w) = (scene.plane(0).contact.gap, scene.rotor.speed());
        let atol = scene.rotor.atol(s.integrator.atol_groups);
        assert_eq!(atol[0], 1e-8 * r0);
        assert_eq!(atol[2], 1e-8 * std::f64::consts::TAU);
        assert_eq!(atol[6], 1e-8 * (r0 * w));
        assert_eq!(atol[11], 1e-8 * w);
        let f = with_integrator(&scene, Method::Rk4, IntegratorSetting::Substeps(7));
        assert_eq!((f.integrator.method, f.integrator.substeps), (Method::Rk4, 7));
        assert_eq!(IntegratorSetting::Rtol(1e-4).to_string(), "rtol=1e-4");
        assert_eq!(IntegratorSetting::Substeps(32).to_string(), "substeps=32");
    }
}
