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

/// Runs a bench study into its folder: `out`, default `runs/<default>`, created first; returns
/// the path of `table` there (the table the study wrote).
pub fn study_into(
    out: Option<&Path>,
    default: &str,
    table: &str,
    study: impl FnOnce(&Path) -> anyhow::Result<()>,
) -> anyhow::Result<std::path::PathBuf> {
    let dir = crate::output::out_dir(out, default);
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    study(&dir)?;
    Ok(dir.join(table))
}

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

/// Per-component scale of the planar model's absolute tolerances ([`atol_scale_groups`] laid
/// out as [`crate::model::ix`]).
pub fn atol_scale(scene: &Scene) -> [f64; N] {
    <crate::model::Model as crate::machine::Machine<N>>::atol(scene.atol_scale_groups())
}

/// The scene with another integrator.
pub fn with_integrator(scene: &Scene, method: Method, setting: IntegratorSetting) -> Scene {
    let mut s = scene.clone();
    s.integrator.method = method;
    match setting {
        IntegratorSetting::Rtol(rtol) => {
            s.integrator.rtol = rtol;
            s.integrator.atol_groups = scene.atol_scale_groups().map(|g| rtol * g);
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
    let mut best_wall = result.run.clock.wall_time;
    if result.run.outcome == Outcome::Completed {
        for _ in 1..repeats {
            best_wall = best_wall.min(run(scene, &mut Quiet)?.run.clock.wall_time);
        }
    }
    Ok(Measured { result, best_wall })
}

/// A method's name as the scene file writes it (`dp5`, `symplectic_euler`).
pub fn method_name(m: Method) -> String {
    crate::summary::snake_name(&m)
}

#[cfg(test)]
mod tests {
    use super::*;

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
