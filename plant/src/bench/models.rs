//! What each model simplification costs and gains (`plant bench models`):
//! on each bench scene ([`super::scenes`]), the most detailed model
//! ([`FULL`]) against each simplification on its own and in combination
//! ([`VARIANTS`]). Error: the scaled window error against the full model,
//! both run accurately (DP5 at rtol 1e-10) so that it measures the model,
//! not the integration. Cost: wall time per simulated second with the
//! scene's own integrator. Writes `models.csv` and `models_<scene>.png`.
//!
//! Then what the second bearing plane changes ([`TWO_PLANE_VARIANTS`]): the study's planar model
//! against the symmetric two-plane machine and each asymmetry on its own, the error the larger
//! of the two planes' against the planar trace, the cost against the planar model's.

use super::rows::{self, ModelRow};
use super::{measure, with_integrator, BenchScene, IntegratorSetting, WINDOW};
use crate::config::Scene;
use crate::integrate::Method;
use crate::plot::{self, PointGroup};
use crate::run::{run, Quiet};
use crate::trace::window_error;
use anyhow::Context;
use std::path::{Path, PathBuf};

/// A model variant of the simplification study: a name and the overrides that make it.
pub struct Variant {
    /// Name.
    pub name: &'static str,
    /// Scene overrides.
    pub sets: &'static [&'static str],
}

/// The most detailed model: every ball, a rolling cage, free spin with a speed loop, the
/// nonlinear bearing with flux saturation.
pub const FULL: &[&str] = &[
    "touchdown.support=\"balls\"",
    "touchdown.cage=\"rotating\"",
    "rotor.spin=\"free\"",
    "amb.force_law=\"nonlinear\"",
];

/// Each simplification on its own, the study's model (all of the study's choices) and everything simplified.
pub const VARIANTS: &[Variant] = &[
    Variant { name: "lumped race support", sets: &["touchdown.support=\"lumped\""] },
    Variant { name: "fixed balls", sets: &["touchdown.cage=\"fixed\""] },
    Variant { name: "speed held", sets: &["rotor.spin=\"held\""] },
    Variant { name: "linear bearing", sets: &["amb.force_law=\"linear\""] },
    Variant { name: "race parked when clear", sets: &["touchdown.race_when_clear=\"parked\""] },
    Variant {
        name: "race parked (released where held)",
        sets: &["touchdown.race_when_clear=\"parked\"", "touchdown.race_release=\"held\""],
    },
    Variant { name: "study model", sets: &["rotor.spin=\"held\"", "amb.force_law=\"linear\""] },
    Variant {
        name: "all simplified",
        sets: &[
            "touchdown.support=\"lumped\"",
            "touchdown.cage=\"fixed\"",
            "rotor.spin=\"held\"",
            "amb.force_law=\"linear\"",
        ],
    },
];

/// The study's model choices (speed held, linear bearing): the planar reference of the
/// two-plane rows.
pub const STUDY: &[&str] = &["rotor.spin=\"held\"", "amb.force_law=\"linear\""];

/// The study's planar scene as its symmetric two-plane machine (docs/MODEL.md §10.1).
pub const SYMMETRIC_TWO_PLANE: &[&str] =
    &["rotor.model=\"two_plane\"", "rotor.mass_kg=23.0", "rotor.polar_inertia_kg_m2=0.01162"];

/// What the second plane changes: the symmetric two-plane machine, then one asymmetry at a
/// time. Their rows compare each plane's motion with the planar study model's (the larger of
/// the two planes' errors) and their cost with its cost.
pub const TWO_PLANE_VARIANTS: &[Variant] = &[
    Variant { name: "two-plane: symmetric", sets: &[] },
    Variant {
        name: "two-plane: centre of mass 60 mm off mid-span",
        sets: &[
            "rotor.bearing_a_mm=-120.0",
            "rotor.bearing_b_mm=240.0",
            "rotor.end_a_mm=-170.0",
            "rotor.end_b_mm=290.0",
        ],
    },
    Variant { name: "two-plane: couple unbalance 50 µrad", sets: &["rotor.couple_unbalance_urad=50.0"] },
    Variant {
        name: "two-plane: sensors 30 mm outboard",
        sets: &["rotor.sensor_a_mm=-210.0", "rotor.sensor_b_mm=210.0"],
    },
    Variant { name: "two-plane: gap of plane B 0.25 mm", sets: &["touchdown.b.air_gap_mm=0.25"] },
];

fn overridden(b: &BenchScene, sets: &[&str]) -> anyhow::Result<Scene> {
    Ok(b.scene.reload(&sets.iter().map(|s| s.to_string()).collect::<Vec<_>>())?)
}

/// Measures the error and speed of each simplification against the full model, writing
/// `models.csv` and the charts into `out`.
pub fn models(
    config_dir: &Path,
    out: &Path,
    repeats: usize,
    log: &mut dyn FnMut(&str),
) -> anyhow::Result<Vec<ModelRow>> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut rows = Vec::new();
    for b in super::scenes(config_dir)? {
        let (t0, t1, gap) = (b.window_start, b.window_start + WINDOW, b.scene.plane(0).contact.gap);
        // Accurate runs for the error (model differences, not integration error).
        let accurate = |s: &Scene| run(&with_integrator(s, Method::Dp5, IntegratorSetting::Rtol(1e-10)), &mut Quiet);
        let full = overridden(&b, FULL)?;
        let full_trace = accurate(&full)?.trace;
        // The scene's own integrator for the cost.
        let full_cost = measure(&full, repeats)?.best_wall / full.duration;
        rows.push(ModelRow {
            scene: b.name.into(),
            variant: "full".into(),
            err_rms: 0.0,
            err_max: 0.0,
            wall_s_per_sim_s: full_cost,
            speedup: 1.0,
        });
        for v in VARIANTS {
            let mut sets: Vec<&str> = FULL.to_vec();
            sets.extend_from_slice(v.sets);
            let scene = overridden(&b, &sets)?;
            let (rms, max) = window_error(&accurate(&scene)?.trace, &full_trace, t0, t1, gap);
            let cost = measure(&scene, repeats)?.best_wall / scene.duration;
            log(&format!(
                "{}: {}: error rms {rms:.2e} max {max:.2e}, speed-up {:.2}",
                b.name,
                v.name,
                full_cost / cost
            ));
            rows.push(ModelRow {
                scene: b.name.into(),
                variant: v.name.into(),
                err_rms: rms,
                err_max: max,
                wall_s_per_sim_s: cost,
                speedup: full_cost / cost,
            });
        }
    }
    for b in super::scenes(config_dir)? {
        rows.extend(second_plane(&b, repeats, log)?);
    }
    crate::table::write_with_header(&out.join("models.csv"), rows::MODELS_HEADER, &rows)?;
    for scene in ["levitation", "impact", "rub"] {
        let here: Vec<&ModelRow> = rows
            .iter()
            // The simplifications against the full model; the two-plane rows have another reference.
            .filter(|r| r.scene == scene && r.variant != "full" && r.variant != "planar study model")
            .filter(|r| !r.variant.starts_with("two-plane"))
            .collect();
        let xs: Vec<Vec<f64>> = here.iter().map(|r| vec![r.speedup]).collect();
        let ys: Vec<Vec<f64>> = here.iter().map(|r| vec![r.err_rms.max(1e-12)]).collect();
        let groups: Vec<PointGroup> =
            here.iter().enumerate().map(|(i, r)| PointGroup { label: &r.variant, x: &xs[i], y: &ys[i] }).collect();
        plot::loglog(
            &out.join(format!("models_{scene}.png")),
            &format!("{scene}: error each simplification adds against the speed it gains"),
            "speed-up over the full model",
            "RMS error / air gap against the full model, 50 ms after the shock",
            &[],
            &groups,
        )?;
    }
    Ok(rows)
}

/// The rows of [`TWO_PLANE_VARIANTS`] on one bench scene: each against the planar study model
/// (`planar study model`, speed-up 1), both run accurately for the error; the error is the
/// larger of the two planes'.
fn second_plane(b: &BenchScene, repeats: usize, log: &mut dyn FnMut(&str)) -> anyhow::Result<Vec<ModelRow>> {
    let (t0, t1, gap) = (b.window_start, b.window_start + WINDOW, b.scene.plane(0).contact.gap);
    let accurate = |s: &Scene| run(&with_integrator(s, Method::Dp5, IntegratorSetting::Rtol(1e-10)), &mut Quiet);
    let planar = overridden(b, STUDY)?;
    let reference = accurate(&planar)?.trace;
    let planar_cost = measure(&planar, repeats)?.best_wall / planar.duration;
    let mut rows = vec![ModelRow {
        scene: b.name.into(),
        variant: "planar study model".into(),
        err_rms: 0.0,
        err_max: 0.0,
        wall_s_per_sim_s: planar_cost,
        speedup: 1.0,
    }];
    for v in TWO_PLANE_VARIANTS {
        let sets: Vec<&str> = STUDY.iter().chain(SYMMETRIC_TWO_PLANE).chain(v.sets).copied().collect();
        let scene = overridden(b, &sets)?;
        let trace = accurate(&scene)?.trace;
        let (rms, max) = (0..2).fold((0.0f64, 0.0f64), |(rms, max), i| {
            let (r, m) = window_error(&trace.plane(i), &reference, t0, t1, gap);
            (rms.max(r), max.max(m))
        });
        let cost = measure(&scene, repeats)?.best_wall / scene.duration;
        log(&format!("{}: {}: error rms {rms:.2e} max {max:.2e}, speed-up {:.2}", b.name, v.name, planar_cost / cost));
        rows.push(ModelRow {
            scene: b.name.into(),
            variant: v.name.into(),
            err_rms: rms,
            err_max: max,
            wall_s_per_sim_s: cost,
            speedup: planar_cost / cost,
        });
    }
    Ok(rows)
}

/// `plant bench models`: runs the study into `out` (default `runs/bench-models`); returns the
/// table written.
pub fn command(
    out: Option<&Path>,
    config: &Path,
    repeats: usize,
    log: &mut dyn FnMut(&str),
) -> anyhow::Result<PathBuf> {
    let dir = crate::output::out_dir(out, "bench-models");
    models(config, &dir, repeats, log)?;
    Ok(dir.join("models.csv"))
}
