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
//!
//! Then what the bending adds ([`machine_against_rigid`], issue 30 item 4): the shipped flexible
//! machine (`config/flexible-10g.toml`, the whole scene) against the rigid two-plane rotor of its
//! rigid body ([`rigid_twin`]): each touchdown bearing's peak force, time in contact, friction
//! energy and recovery (`models_flexible.csv`), and a row of `models.csv` (scene
//! `flexible-10g`: the rigid rotor's error and speed-up against the flexible one).

use super::rows::{self, MachineRow, ModelRow};
use super::{measure, with_integrator, BenchScene, IntegratorSetting, WINDOW};
use crate::assess::duty::{Bearing, DutySink};
use crate::config::{load_scene, Scene};
use crate::integrate::Method;
use crate::plot::{self, PointGroup};
use crate::run::{run, run_into, Quiet, RunResult};
use crate::summary::{PlaneSummary, Summary};
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
    let mut rows = Vec::new();
    for b in super::scenes(config_dir)? {
        let (t0, t1, gap) = (b.window_start, b.window_start + WINDOW, b.scene.plane(0).contact.gap);
        // Accurate runs for the error (model differences, not integration error).
        let accurate = |s: &Scene| run(&with_integrator(s, Method::Dp5, IntegratorSetting::Rtol(1e-10)), &mut Quiet);
        let full = overridden(&b, FULL)?;
        let full_trace = accurate(&full)?.trace;
        // The scene's own integrator for the cost.
        let full_cost = measure(&full, repeats)?.best_wall / full.duration;
        rows.push(reference_row(b.name, "full", full_cost));
        for v in VARIANTS {
            let mut sets: Vec<&str> = FULL.to_vec();
            sets.extend_from_slice(v.sets);
            let scene = overridden(&b, &sets)?;
            let error = window_error(&accurate(&scene)?.trace, &full_trace, t0, t1, gap);
            let cost = measure(&scene, repeats)?.best_wall / scene.duration;
            rows.push(variant_row(b.name, v.name, error, cost, full_cost, log));
        }
    }
    for b in super::scenes(config_dir)? {
        rows.extend(second_plane(&b, repeats, log)?);
    }
    let flexible = load_scene(&config_dir.join(FLEXIBLE), &["output.plots=false".to_string()])
        .with_context(|| format!("loading {}", config_dir.join(FLEXIBLE).display()))?;
    let (summary_rows, machine_rows) = machine_against_rigid(&flexible, repeats, Some(1e-10), log)?;
    rows.extend(summary_rows);
    crate::table::write_with_header(&out.join("models_flexible.csv"), rows::MACHINE_HEADER, &machine_rows)?;
    crate::table::write_with_header(&out.join("models.csv"), rows::MODELS_HEADER, &rows)?;
    charts(out, &rows)?;
    Ok(rows)
}

/// Draws `models_<scene>.png` for the three bench scenes from the rows.
fn charts(out: &Path, rows: &[ModelRow]) -> anyhow::Result<()> {
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
    Ok(())
}

/// The row of a reference model (no error against itself, speed-up 1) of wall `cost` s per
/// simulated second.
fn reference_row(scene: &str, variant: &str, cost: f64) -> ModelRow {
    ModelRow {
        scene: scene.into(),
        variant: variant.into(),
        err_rms: 0.0,
        err_max: 0.0,
        wall_s_per_sim_s: cost,
        speedup: 1.0,
    }
}

/// The row of a variant with its error `(rms, max)` against the reference, of wall `cost` s per
/// simulated second against the reference's `reference_cost`; said in the log.
fn variant_row(
    scene: &str,
    variant: &str,
    (rms, max): (f64, f64),
    cost: f64,
    reference_cost: f64,
    log: &mut dyn FnMut(&str),
) -> ModelRow {
    log(&format!("{scene}: {variant}: error rms {rms:.2e} max {max:.2e}, speed-up {:.2}", reference_cost / cost));
    ModelRow {
        scene: scene.into(),
        variant: variant.into(),
        err_rms: rms,
        err_max: max,
        wall_s_per_sim_s: cost,
        speedup: reference_cost / cost,
    }
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
    let mut rows = vec![reference_row(b.name, "planar study model", planar_cost)];
    for v in TWO_PLANE_VARIANTS {
        let sets: Vec<&str> = STUDY.iter().chain(SYMMETRIC_TWO_PLANE).chain(v.sets).copied().collect();
        let scene = overridden(b, &sets)?;
        let trace = accurate(&scene)?.trace;
        let error = (0..2).fold((0.0f64, 0.0f64), |(rms, max), i| {
            let (r, m) = window_error(&trace.plane(i), &reference, t0, t1, gap);
            (rms.max(r), max.max(m))
        });
        let cost = measure(&scene, repeats)?.best_wall / scene.duration;
        rows.push(variant_row(b.name, v.name, error, cost, planar_cost, log));
    }
    Ok(rows)
}

/// The shipped flexible machine (in the config folder).
pub const FLEXIBLE: &str = "flexible-10g.toml";

/// The rigid two-plane rotor of a flexible scene's machine: the two-plane rotor
/// (`rotor.model = "two_plane"`) with the shaft's rigid body as the flexible model computed it
/// from its finite elements (mass, centre of mass, `I_t`, `I_p`, the unbalance), its AMBs and
/// touchdown bearings at the AMB nodes' stations and its sensors at the sensor nodes'; every
/// other part of the scene (bearings, contact, loop, controller, shock, integrator) the same.
/// `config/flexible-10g-rigid.toml` is the shipped machine's, to its printed digits.
pub fn rigid_twin(flexible: &Scene) -> anyhow::Result<Scene> {
    let Some(twin) = flexible.rotor.rigid_twin() else {
        anyhow::bail!("scene `{}` has no flexible rotor (rotor.model = \"flexible\")", flexible.name)
    };
    let mut rigid = flexible.clone();
    rigid.rotor = twin;
    rigid.name = format!("{}-rigid", flexible.name);
    Ok(rigid)
}

/// One model's run of the whole scene: its trace, summary and the duty of each touchdown
/// bearing, and the fastest wall time per simulated second of `repeats` runs.
struct MachineRun {
    result: RunResult,
    summary: Summary,
    friction_energy_j: [f64; 2],
    wall_s_per_sim_s: f64,
}

fn machine_run(scene: &Scene, repeats: usize) -> anyhow::Result<MachineRun> {
    let raw = scene.resolved()?;
    let t = &raw.touchdown;
    // The friction energy, time in contact and peak force do not depend on the materials.
    let bearing =
        Bearing::new(Default::default(), t.ball_diameter_mm * 1e-3, t.pitch_diameter_mm * 1e-3, t.width_mm * 1e-3, 0.1);
    let mut trace = crate::trace::Trace::with_capacity((scene.duration / scene.output_interval).ceil() as usize + 2);
    let mut sink = DutySink::new(&mut trace, bearing, scene.plane(0).balls.count());
    let run = run_into(scene, &Default::default(), &mut Quiet, &mut sink)?;
    let duty = sink.finish();
    let mut best = run.clock.wall_time;
    anyhow::ensure!(
        run.outcome == crate::run::Outcome::Completed,
        "scene `{}` did not complete: {:?}",
        scene.name,
        run.outcome
    );
    for _ in 1..repeats {
        best = best.min(crate::run::run(scene, &mut Quiet)?.run.clock.wall_time);
    }
    let result = RunResult { trace, run };
    let summary = Summary::new(scene, &result);
    let friction = |i: usize| duty.planes.get(i).map_or(0.0, |d| d.friction_energy_j);
    Ok(MachineRun {
        summary,
        friction_energy_j: [friction(0), friction(1)],
        wall_s_per_sim_s: best / scene.duration,
        result,
    })
}

/// What the bending adds: the flexible scene `flexible` (run whole, with its own integrator)
/// against its [`rigid_twin`]. Returns the rows of `models.csv` (scene `flexible-10g`: the
/// flexible rotor, speed-up 1, and the rigid rotor with its error, the larger of the two planes',
/// and its speed-up) and of `models_flexible.csv` (each model's figures per touchdown bearing).
/// The error is taken over the 50 ms after the shock (or to the scene's end) between runs at
/// DP5 and `error_rtol` (`None`: the scene's own runs).
pub fn machine_against_rigid(
    flexible: &Scene,
    repeats: usize,
    error_rtol: Option<f64>,
    log: &mut dyn FnMut(&str),
) -> anyhow::Result<(Vec<ModelRow>, Vec<MachineRow>)> {
    let rigid = rigid_twin(flexible)?;
    let name = flexible.name.clone();
    let t0 = flexible.first_shock_start();
    let t1 = (t0 + WINDOW).min(flexible.duration);
    let gap = flexible.plane(0).contact.gap;
    let runs = [machine_run(flexible, repeats)?, machine_run(&rigid, repeats)?];
    // The traces the error is measured on.
    let accurate = |s: &Scene, rtol: f64| -> anyhow::Result<crate::trace::Trace> {
        let short = {
            let mut s = with_integrator(s, Method::Dp5, IntegratorSetting::Rtol(rtol));
            s.duration = t1;
            s
        };
        Ok(run(&short, &mut Quiet)?.trace)
    };
    let traces = match error_rtol {
        Some(rtol) => [accurate(flexible, rtol)?, accurate(&rigid, rtol)?],
        None => [runs[0].result.trace.clone(), runs[1].result.trace.clone()],
    };
    let errors: Vec<(f64, f64)> =
        (0..2).map(|i| window_error(&traces[1].plane(i), &traces[0].plane(i), t0, t1, gap)).collect();
    let models = ["flexible", "rigid two-plane"];
    let mut machine_rows = Vec::new();
    for (k, r) in runs.iter().enumerate() {
        let planes = r.summary.planes.as_ref().context("a two-plane summary")?;
        for (i, (plane, p)) in [("a", &planes.a), ("b", &planes.b)].into_iter().enumerate() {
            let p: &PlaneSummary = p;
            let (err_rms, err_max) = if k == 0 { (0.0, 0.0) } else { errors[i] };
            machine_rows.push(MachineRow {
                scene: name.clone(),
                model: models[k].into(),
                plane: plane.into(),
                peak_contact_force_n: p.max_contact_force_n,
                contact_time_s: p.contact_time_s,
                contact_fraction: p.contact_fraction,
                friction_energy_j: r.friction_energy_j[i],
                recovery_s: p.recovery_s,
                max_radius_m: p.max_radius_m,
                first_contact_s: p.first_contact_s,
                post_shock_mode: p.analysis.post_shock_mode,
                err_rms,
                err_max,
                wall_s_per_sim_s: r.wall_s_per_sim_s,
                speedup: runs[0].wall_s_per_sim_s / r.wall_s_per_sim_s,
            });
            log(&format!(
                "{name}: {} plane {plane}: peak force {:.0} N, contact {:.1} ms, friction {:.3} J, recovery {}",
                models[k],
                p.max_contact_force_n.unwrap_or(f64::NAN),
                p.contact_time_s * 1e3,
                r.friction_energy_j[i],
                p.recovery_s.map_or("none (still touching)".to_string(), |s| format!("{:.1} ms", s * 1e3)),
            ));
        }
    }
    let (rms, max) = errors.iter().fold((0.0f64, 0.0f64), |(a, b), (r, m)| (a.max(*r), b.max(*m)));
    let summary_rows = vec![
        ModelRow {
            scene: name.clone(),
            variant: "flexible rotor".into(),
            err_rms: 0.0,
            err_max: 0.0,
            wall_s_per_sim_s: runs[0].wall_s_per_sim_s,
            speedup: 1.0,
        },
        ModelRow {
            scene: name,
            variant: "rigid two-plane rotor".into(),
            err_rms: rms,
            err_max: max,
            wall_s_per_sim_s: runs[1].wall_s_per_sim_s,
            speedup: runs[0].wall_s_per_sim_s / runs[1].wall_s_per_sim_s,
        },
    ];
    Ok((summary_rows, machine_rows))
}

/// `plant bench models`: runs the study into `out` (default `runs/bench-models`); returns the
/// table written.
pub fn command(
    out: Option<&Path>,
    config: &Path,
    repeats: usize,
    log: &mut dyn FnMut(&str),
) -> anyhow::Result<PathBuf> {
    super::study_into(out, "bench-models", "models.csv", |dir| models(config, dir, repeats, log).map(drop))
}

/// `plant bench models --redraw CSV`: the charts of an earlier `models.csv` drawn again with
/// today's `plot/`, nothing run; returns the folder written.
pub fn redraw(out: Option<&Path>, csv: &Path) -> anyhow::Result<PathBuf> {
    let rows: Vec<ModelRow> =
        crate::table::read(csv).map_err(|e| crate::exit::BadArgument(format!("--redraw: {e:#}")))?;
    let dir = crate::output::out_dir(out, "bench-models");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    charts(&dir, &rows)?;
    Ok(dir)
}
