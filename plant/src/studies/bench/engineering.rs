//! Engineering figures across integrators on full-length runs (`plant bench engineering`).
//!
//! The 50 ms trajectory error of `plant bench accuracy` is a strict measure: after repeated
//! impacts small differences grow. What a study reads off a long run are its figures: the peak
//! rotor – race contact force, the largest rotor radius, the contact fraction over the last 200
//! revolutions and the post-shock mode. This bench runs the full-length impact (3 G) and rub
//! (10 G) scenes with each method at a representative setting (including each scene's shipped
//! default and the parked race), and compares those figures with a reference run (DOP853 at
//! rtol 1e-12 with scaled absolute tolerances, free race). The co-simulation scene
//! (`cosim-10g.toml`, its law sampled in the plant) runs on its own setting and on the realtime
//! one. Writes
//! `engineering.csv` (columns in [`super::rows::EngineeringRow`]).

use super::rows::{EngineeringRow, ENGINEERING_HEADER};
use super::{measure, with_integrator, IntegratorSetting};
use crate::analysis::classify::{MotionMode, SteadyClass};
use crate::config::{load_scene, Scene};
use crate::integrate::Method;
use crate::run::Outcome;
use crate::status::Status;
use crate::summary::{snake_name, Summary};
use anyhow::Context;
use std::path::{Path, PathBuf};

/// One run's figures.
#[derive(Clone, Debug)]
pub struct Figures {
    /// Scene.
    pub scene: String,
    /// What ran (method, setting, model).
    pub label: String,
    /// `completed` or `diverged`.
    pub status: Status,
    /// Peak contact force (N).
    pub peak_contact_force_n: f64,
    /// Largest rotor radius (m).
    pub max_radius_m: f64,
    /// Contact fraction over the last 200 revolutions.
    pub contact_fraction: f64,
    /// Post-shock mode.
    pub post_shock_mode: MotionMode,
    /// Steady class of the end of the run.
    pub steady_class: SteadyClass,
    /// Wall seconds per simulated second (fastest of the repeats).
    pub wall_s_per_sim_s: f64,
}

fn figures(scene_name: &str, label: String, scene: &Scene, repeats: usize) -> anyhow::Result<Figures> {
    let m = measure(scene, repeats)?;
    let s = Summary::new(scene, &m.result);
    Ok(Figures {
        scene: scene_name.into(),
        label,
        status: if m.result.run.outcome == Outcome::Completed { Status::Completed } else { Status::Diverged },
        peak_contact_force_n: s.max_contact_force_n.unwrap_or(f64::NAN),
        max_radius_m: s.max_radius_m.unwrap_or(f64::NAN),
        contact_fraction: s.contact_fraction,
        post_shock_mode: s.analysis.post_shock_mode,
        steady_class: s.analysis.steady_class,
        wall_s_per_sim_s: m.best_wall / scene.duration,
    })
}

fn parked(scene: &Scene, method: Method) -> anyhow::Result<Scene> {
    // Re-validated with the override; the integrator settings chosen on `scene` are kept.
    let mut s = scene.reload(&[super::PARKED.to_string()])?;
    s.integrator = scene.integrator.clone();
    s.integrator.contact_substeps = s.integrator.substeps.max(crate::stability::safe_contact_substeps(&s, method));
    Ok(s)
}

/// The settings compared on each scene: (label, scene).
fn settings(scene: &Scene) -> anyhow::Result<Vec<(String, Scene)>> {
    let d = &scene.integrator;
    let default = match d.method {
        m if m.is_adaptive() => format!("shipped default: {} rtol={:e}", snake_name(&m), d.rtol),
        m => format!("shipped default: {} substeps={}", snake_name(&m), d.substeps),
    };
    let mut v = vec![(default, scene.clone())];
    for (method, setting) in [
        (Method::Dp5, IntegratorSetting::Rtol(1e-6)),
        (Method::Dp5, IntegratorSetting::Rtol(1e-9)),
        (Method::Dop853, IntegratorSetting::Rtol(1e-9)),
        (Method::Rk4, IntegratorSetting::Substeps(4)),
        (Method::Rk4, IntegratorSetting::Substeps(16)),
        (Method::SymplecticEuler, IntegratorSetting::Substeps(8)),
        (Method::SymplecticEuler, IntegratorSetting::Substeps(64)),
    ] {
        v.push((format!("{} {setting}", snake_name(&method)), with_integrator(scene, method, setting)));
    }
    let dp5 = with_integrator(scene, Method::Dp5, IntegratorSetting::Rtol(1e-9));
    v.push(("parked race + dp5 rtol=1e-9".into(), parked(&dp5, Method::Dp5)?));
    let rk4 = with_integrator(scene, Method::Rk4, IntegratorSetting::Substeps(1));
    let rk4 = parked(&rk4, Method::Rk4)?;
    v.push((format!("parked race + rk4 substeps=1 (contact_substeps={})", rk4.integrator.contact_substeps), rk4));
    Ok(v)
}

/// The settings compared on the co-simulation scene: its own and the realtime one
/// ([`Scene::fixed_step_overrides`], what `mode = "realtime"` runs on by default).
fn realtime_settings(scene: &Scene) -> anyhow::Result<Vec<(String, Scene)>> {
    let fixed = scene.reload(&scene.fixed_step_overrides())?;
    let label = format!("realtime fixed: {}", fixed.resolved()?.integrator_and_race());
    Ok(vec![(format!("shipped default: {}", scene.resolved()?.integrator_and_race()), scene.clone()), (label, fixed)])
}

/// Each run's figures as a row of `engineering.csv`, with their differences from the
/// reference run of the same scene (rows of a scene without one are left out).
pub fn table(figures: &[Figures]) -> Vec<EngineeringRow> {
    let rel = |a: f64, b: f64| if b != 0.0 { (a - b) / b } else { a - b };
    figures
        .iter()
        .filter_map(|r| {
            let reference = figures.iter().find(|x| x.scene == r.scene && x.label.starts_with("reference"))?;
            Some(EngineeringRow {
                scene: r.scene.clone(),
                setting: r.label.clone(),
                status: r.status,
                peak_contact_force_n: r.peak_contact_force_n,
                max_radius_m: r.max_radius_m,
                contact_fraction: r.contact_fraction,
                post_shock_mode: r.post_shock_mode,
                steady_class: r.steady_class,
                wall_s_per_sim_s: r.wall_s_per_sim_s,
                peak_force_rel_diff: rel(r.peak_contact_force_n, reference.peak_contact_force_n),
                max_radius_rel_diff: rel(r.max_radius_m, reference.max_radius_m),
                contact_fraction_diff: r.contact_fraction - reference.contact_fraction,
                same_mode: r.post_shock_mode == reference.post_shock_mode && r.steady_class == reference.steady_class,
            })
        })
        .collect()
}

/// Runs the comparison and writes `engineering.csv` into the folder `out`.
pub fn engineering(
    config_dir: &Path,
    out: &Path,
    repeats: usize,
    log: &mut dyn FnMut(&str),
) -> anyhow::Result<Vec<EngineeringRow>> {
    let mut runs = Vec::new();
    // The co-simulation scene runs with its law in the plant's process (`sampled`: the
    // arithmetic of lockstep, and of a realtime run without a miss), on its own setting and on
    // the realtime one only.
    let sampled = "controller.mode=\"sampled\"";
    for (name, file, extra) in [
        ("impact", "paper-3g.toml", None),
        ("rub", "paper-10g.toml", None),
        ("cosim-10g", "cosim-10g.toml", Some(sampled)),
    ] {
        let path = config_dir.join(file);
        let mut sets = vec!["output.plots=false".to_string()];
        sets.extend(extra.map(str::to_string));
        let scene = load_scene(&path, &sets).with_context(|| format!("loading {}", path.display()))?;
        let free = scene.reload(&["touchdown.race_when_clear=\"free\"".to_string()])?;
        let reference = with_integrator(&free, Method::Dop853, IntegratorSetting::Rtol(1e-12));
        log(&format!("{name}: reference (DOP853 rtol 1e-12, {} s)", scene.duration));
        let r = figures(name, "reference: dop853 rtol=1e-12".into(), &reference, 1)?;
        anyhow::ensure!(r.status == Status::Completed, "{name}: the reference did not complete");
        log(&format!(
            "{name}: reference: peak contact {:.1} N, max radius {:.2} µm, contact fraction {:.4}, mode {}, {:.3e} s/s",
            r.peak_contact_force_n,
            r.max_radius_m * 1e6,
            r.contact_fraction,
            r.post_shock_mode,
            r.wall_s_per_sim_s
        ));
        runs.push(r);
        let settings = if extra.is_some() { realtime_settings(&scene)? } else { settings(&scene)? };
        for (label, s) in settings {
            let f = figures(name, label, &s, repeats)?;
            log(&format!(
                "{name}: {}: {}, peak contact {:.0} N, max radius {:.1} µm, contact fraction {:.3}, mode {}, {:.3e} s/s",
                f.label,
                f.status,
                f.peak_contact_force_n,
                f.max_radius_m * 1e6,
                f.contact_fraction,
                f.post_shock_mode,
                f.wall_s_per_sim_s
            ));
            runs.push(f);
        }
    }
    let rows = table(&runs);
    crate::table::write_with_header(&out.join("engineering.csv"), ENGINEERING_HEADER, &rows)?;
    Ok(rows)
}

/// `plant bench engineering`: runs the comparison into `out` (default
/// `runs/bench-engineering`); returns the table written.
pub fn command(
    out: Option<&Path>,
    config: &Path,
    repeats: usize,
    log: &mut dyn FnMut(&str),
) -> anyhow::Result<PathBuf> {
    super::study_into(out, "bench-engineering", "engineering.csv", |dir| {
        engineering(config, dir, repeats, log).map(drop)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(scene: &str, label: &str, force: f64, radius: f64, fraction: f64, mode: MotionMode) -> Figures {
        Figures {
            scene: scene.into(),
            label: label.into(),
            status: Status::Completed,
            peak_contact_force_n: force,
            max_radius_m: radius,
            contact_fraction: fraction,
            post_shock_mode: mode,
            steady_class: SteadyClass::Periodic,
            wall_s_per_sim_s: 0.1,
        }
    }

    #[test]
    fn each_row_is_compared_with_its_own_scenes_reference() {
        let figures = [
            run("impact", "reference: dop853 rtol=1e-12", 1000.0, 2e-4, 0.0, MotionMode::Recovered),
            run("rub", "reference: dop853 rtol=1e-12", 4000.0, 3e-4, 0.5, MotionMode::DryWhirl),
            run("impact", "rk4 substeps=4", 1010.0, 1.9e-4, 0.0, MotionMode::Recovered),
            run("rub", "rk4 substeps=4", 3000.0, 3e-4, 0.75, MotionMode::Recovered),
            run("orphan", "rk4 substeps=4", 1.0, 1.0, 1.0, MotionMode::Recovered),
        ];
        let rows = table(&figures);
        assert_eq!(rows.len(), 4, "a scene without a reference has no row");
        assert_eq!((rows[0].peak_force_rel_diff, rows[0].max_radius_rel_diff, rows[0].same_mode), (0.0, 0.0, true));
        let impact = &rows[2];
        assert!((impact.peak_force_rel_diff - 0.01).abs() < 1e-15, "{}", impact.peak_force_rel_diff);
        assert!((impact.max_radius_rel_diff + 0.05).abs() < 1e-12, "{}", impact.max_radius_rel_diff);
        assert!(impact.same_mode);
        let rub = &rows[3];
        assert_eq!((rub.peak_force_rel_diff, rub.contact_fraction_diff, rub.same_mode), (-0.25, 0.25, false));
        assert_eq!(rub.setting, "rk4 substeps=4");
    }
}
