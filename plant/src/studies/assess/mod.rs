//! `plant assess`: a controller judged the way the field judges one, side by side with
//! others: the stability margin of each control axis (ISO 14839-3, measured through the
//! loop: [`sensitivity`], checked against [`closed_form`]), the vibration of the levitated
//! rotor (ISO 14839-2: [`vibration`]), the probability of recovery against the shock's peak
//! ([`ladder`], on the ensemble machinery) and what each shock costs the touchdown bearing
//! ([`duty`]: [`hertz`] pressures, [`rainflow`] load cycles). [`report`] writes `report.json`,
//! `report.html` (self-contained) and the PNG charts.
//!
//! A controller is the scene with `--set` overrides (a law by name with its
//! `[controller.params]`, or a controller process by `controller.command`): the plant treats it
//! as a black box through the same run loop every other command uses.
//!
//! By job: [`spec`] reads what to assess; `measure` runs one measurement (a quiet run, one axis'
//! sensitivity, how a run failed); `parts` runs and judges each part of one controller;
//! `closed_forms` says which closed form a scene's loop has; [`report`] writes the sections.
//! This file holds the command: load and check everything, assess each controller, write.

pub mod closed_form;
mod closed_forms;
pub mod coupled;
pub mod duty;
mod failure;
pub mod hertz;
mod iso_zone;
pub mod ladder;
#[cfg(test)]
mod linear_check;
pub mod loop_charts;
pub mod margins;
mod measure;
mod outcome;
mod parts;
mod paths;
pub mod rainflow;
pub mod report;
pub mod sensitivity;
pub mod spec;
mod state_space_form;
pub mod vibration;

pub use crate::run::jobs::{jobs_for, COSIM_JOBS};
pub use closed_forms::{closed_form_of, closed_form_of_plane};
pub use measure::measure_axis;
pub use outcome::{AssessError, ClosedFormPeak, ControllerReport, Failure, PartOutcome, Report, SensitivityPart};
pub use parts::UNSTABLE_ZONE;
use parts::{ladder_part, sensitivity_part, vibration_part};
use paths::roots;
pub use paths::{relative_text, relative_to, shown, shown_relative};

use crate::config::{load_scene, ConfigError, ControlMode, Scene};
use crate::cosim::Launch;
use crate::run::run_into;
use anyhow::Context;
use spec::{Assessment, ControllerSpec, Part};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// `plant assess` arguments.
#[derive(clap::Args, Debug, Clone)]
pub struct AssessArgs {
    /// An assessment file (TOML: `scene = "…"`, `[[controller]]` tables, `[sensitivity]`,
    /// `[ladder]`, `[duty]`) or a scene file (its own controller, or `--laws`).
    pub file: PathBuf,
    /// Assess these laws (each in the scene's controller mode) instead of the file's controllers.
    #[arg(long, value_delimiter = ',')]
    pub laws: Vec<String>,
    /// Override a scene key for every controller (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Output folder (default: runs/assess-<file stem>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// No progress lines.
    #[arg(long)]
    pub quiet: bool,
    /// Repeat every counted member of the ladder N times with `plant run --robustness`'s
    /// perturbations and say which are fragile and whether the highest safe shock survives (the
    /// same as `[ladder] robustness = N`, which it overrides).
    #[arg(long, value_name = "N", value_parser = crate::argument::count::<usize>("a number of perturbed runs", 0, crate::robustness::MAX_MEMBERS as u64))]
    pub robustness: Option<usize>,
}

/// The axes a scene's loop has, by name: x then y (the planar model), x_A, y_A, x_B, y_B (the
/// two-plane rotor, its planes in order).
pub fn axis_names(scene: &Scene) -> Vec<&'static str> {
    match scene.planes() {
        1 => vec!["x", "y"],
        _ => vec!["x_A", "y_A", "x_B", "y_B"],
    }
}

/// The override put before a lockstep controller's own (so that its `set` still decides):
/// plant and controller block for each other's frame instead of busy-polling first. An
/// assessment runs [`COSIM_JOBS`] lockstep runs at once, more processes than cores, where a
/// process spinning for its peer's frame holds a core the peer (or another run) needs; a
/// lockstep trace does not depend on how either side waits. Measured on the shared 2-core
/// machine: the report card of `config/assess/external-notch.toml` in 26.7 s instead of 207 s
/// (docs/results/assessment.md). It became the default once the plant stopped listing every
/// iceoryx2 node of the machine at each slice of a reply that was merely late (the reason
/// blocking waits had been slower in a loaded debug build: `cosim::session::check_silence`).
pub const LOCKSTEP_WAIT: &str = "controller.spin_us=0.0";

/// The files an assessment writes into its folder (`N`: the controller's number): an earlier
/// assessment's are removed first, so that no chart of a controller this one does not have,
/// or of a part it does not run, is left beside its report.
pub const FILES: &[&str] = &[
    "report.html",
    "report.json",
    "sensitivity_*.png",
    "open_loop_*.png",
    "duty_ball_pressure.png",
    "duty_friction.png",
    "ladder_probability.png",
    "ladder_recovery.png",
];

/// A co-simulated controller started once, for one tick, before anything is measured: a
/// command that cannot run, a controller that refuses the run or speaks another protocol is
/// found here, with the exit code `plant run` gives it (bad input: 2), instead of failing every
/// part of the assessment. A controller lost in that tick is left to the parts to report.
fn controller_starts(scene: &Scene, stop: &AtomicBool) -> anyhow::Result<()> {
    let sets = [format!("scene.duration_s={:?}", scene.controller.period), "output.plots=false".to_string()];
    let one_tick = scene.reload(&sets)?;
    let mut trace = crate::trace::Trace::with_capacity(4);
    run_into(&one_tick, &Launch::default(), &mut crate::hooks::Cancel(stop), &mut trace)?;
    Ok(())
}

/// Assesses one controller.
fn assess_controller(
    a: &Assessment,
    c: &ControllerSpec,
    stop: &AtomicBool,
    log: &(dyn Fn(&str) + Sync),
) -> anyhow::Result<ControllerReport> {
    let started = Instant::now();
    let scene = load_scene(&a.scene, &c.sets)?;
    let mut report = ControllerReport {
        label: c.label.clone(),
        set: c.own.clone(),
        law: if scene.controller.mode == ControlMode::Continuous {
            "continuous PD".into()
        } else {
            scene.controller.law.clone()
        },
        mode: crate::summary::snake_name(&scene.controller.mode),
        rate_hz: scene.controller.rate_hz,
        sensitivity: PartOutcome::skipped("not asked for"),
        vibration: PartOutcome::skipped("not asked for"),
        ladder: PartOutcome::skipped("not asked for"),
        verdict: String::new(),
        wall_s: 0.0,
    };
    let interrupted = || stop.load(Ordering::Relaxed);
    let mut decay_at_speed = None;
    if a.parts.contains(&Part::Sensitivity) && !interrupted() {
        log(&format!("{}: sensitivity (ISO 14839-3)", c.label));
        let t = Instant::now();
        report.sensitivity = match sensitivity_part(&scene, a, stop, log) {
            Ok(p) => {
                decay_at_speed = p
                    .axes
                    .iter()
                    .filter(|x| x.speed_hz > 0.0 || p.axes.iter().all(|y| y.speed_hz == 0.0))
                    .map(|x| x.decay_per_s)
                    .reduce(f64::min);
                PartOutcome::measured(p, t.elapsed().as_secs_f64())
            }
            Err((kind, why, kept)) => {
                PartOutcome { result: kept.map(|p| *p), ..PartOutcome::failed(kind, why, t.elapsed().as_secs_f64()) }
            }
        };
    }
    let mut levitated = true;
    if a.parts.contains(&Part::Vibration) && !interrupted() {
        log(&format!("{}: vibration (ISO 14839-2)", c.label));
        let t = Instant::now();
        report.vibration = match vibration_part(&scene, decay_at_speed, stop) {
            Ok(mut v) => {
                // A loop the sensitivity part found unstable has no steady orbit: its window is a
                // growing transient, not a vibration to grade.
                if decay_at_speed.is_some_and(|s| s < 0.0) {
                    v.zone = UNSTABLE_ZONE.into();
                    v.planes.iter_mut().for_each(|p| p.zone = UNSTABLE_ZONE.into());
                }
                PartOutcome::measured(v, t.elapsed().as_secs_f64())
            }
            Err((kind, why)) => {
                levitated = kind != Failure::NotGradable;
                PartOutcome::failed(kind, why, t.elapsed().as_secs_f64())
            }
        };
    }
    if a.parts.contains(&Part::Ladder) && !interrupted() {
        report.ladder = ladder_part(a, c, &scene, levitated, decay_at_speed, stop, log)?;
    }
    if interrupted() {
        mark_not_measured(&mut report, &a.parts);
    }
    report.verdict = report::verdict(&report, a.ladder.duty_g, a.ladder.min_p);
    report.wall_s = started.elapsed().as_secs_f64();
    Ok(report)
}

/// An interrupted assessment: each part asked for and not reached says so.
fn mark_not_measured(report: &mut ControllerReport, parts: &[Part]) {
    for (status, part) in [
        (report.sensitivity.status, "sensitivity"),
        (report.vibration.status, "vibration"),
        (report.ladder.status, "ladder"),
    ] {
        if status == "skipped" && parts.iter().any(|p| p.name() == part) {
            match part {
                "sensitivity" => {
                    report.sensitivity =
                        PartOutcome::failed(Failure::Interrupted, "not measured: interrupted".into(), 0.0)
                }
                "vibration" => {
                    report.vibration =
                        PartOutcome::failed(Failure::Interrupted, "not measured: interrupted".into(), 0.0)
                }
                _ => report.ladder = PartOutcome::failed(Failure::Interrupted, "not measured: interrupted".into(), 0.0),
            }
        }
    }
}

/// `plant assess`: loads everything first (bad input: exit 2 before anything runs), assesses
/// each controller, writes the report (also when a part failed or the run was interrupted).
pub fn command(args: &AssessArgs, stop: &AtomicBool) -> anyhow::Result<PathBuf> {
    let started = Instant::now();
    let mut a = spec::load(&args.file, &args.set, &args.laws)?;
    a.ladder.robustness = args.robustness.unwrap_or(a.ladder.robustness);
    // A warning is said even with --quiet: it changes how the report reads.
    for w in &a.warnings {
        eprintln!("plant assess: warning: {w}");
    }
    for c in a.controllers.iter_mut() {
        if load_scene(&a.scene, &c.sets)?.controller.mode == ControlMode::Lockstep {
            c.sets.insert(0, LOCKSTEP_WAIT.into());
        }
    }
    let first = check_scenes(&a, stop)?;
    let stem = args.file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let dir = args.out.clone().unwrap_or_else(|| PathBuf::from("runs").join(format!("assess-{stem}")));
    let _claim = crate::claim::claim(&dir, true)?;
    crate::outfile::clear_earlier(&dir, FILES)?;
    let quiet = args.quiet;
    let log = move |l: &str| {
        if !quiet {
            eprintln!("plant assess: {l}");
        }
    };
    let bearing = first.as_ref().map(|s| duty::Bearing::of_scene(s, a.materials, a.capacity_fraction));
    // Paths as seen from where the command ran: the report names no folder of this machine.
    let cwd = std::env::current_dir().unwrap_or_default();
    let shown_here = |p: &Path| if cwd.as_os_str().is_empty() { shown(p) } else { shown_relative(p, &cwd) };
    let roots = roots(&cwd, &a.scene, &dir);
    let mut report = Report {
        program: format!("plant {}", env!("CARGO_PKG_VERSION")),
        file: shown_here(&args.file),
        scene: shown_here(&a.scene),
        out: shown_here(&dir),
        parts: a.parts.iter().map(|p| p.name().to_string()).collect(),
        bearing,
        ladder_settings: a.ladder.clone(),
        warnings: a.warnings.clone(),
        controllers: Vec::new(),
        interrupted: false,
        wall_s: 0.0,
        roots,
    };
    for c in &a.controllers {
        let r = assess_controller(&a, c, stop, &log)?;
        log(&format!("{}: {} ({:.1} s)", r.label, r.verdict, r.wall_s));
        report.controllers.push(r);
        if stop.load(Ordering::Relaxed) {
            break;
        }
    }
    for c in a.controllers.iter().skip(report.controllers.len()) {
        report.controllers.push(not_assessed(c));
    }
    report.interrupted = stop.load(Ordering::Relaxed);
    report.wall_s = started.elapsed().as_secs_f64();
    report::write(&dir, &report)?;
    log(&format!("wrote {}", dir.join("report.html").display()));
    failed(&report, &dir)?;
    // A signal while the report was written: every part was measured and the report is whole,
    // but the command was asked to stop (exit 130, as `run` and `soak` do).
    if stop.load(Ordering::Relaxed) {
        let message = "interrupted while the report was written (every part was measured)".to_string();
        return Err(AssessError { kind: Failure::Interrupted, message, dir: dir.display().to_string() }.into());
    }
    Ok(dir)
}

/// Every controller's scene loads before anything runs (an unknown law, a bad key: exit 2), and
/// its controller starts; the first controller's scene.
fn check_scenes(a: &Assessment, stop: &AtomicBool) -> anyhow::Result<Option<Scene>> {
    let mut first = None;
    for c in &a.controllers {
        let scene = load_scene(&a.scene, &c.sets)?;
        if scene.hardware.is_on() {
            return Err(ConfigError::Range {
                key: "amb.amplifier".into(),
                value: "true".into(),
                unit: String::new(),
                why: "plant assess measures the ideal loop; a scene with an amplifier or a sensor front end \
                      (amb.amplifier, sensor.bandwidth_hz, sensor.range_um, sensor.runout) is not assessed yet"
                    .into(),
            }
            .into());
        }
        if a.parts.contains(&Part::Ladder) {
            ladder::rung_overrides(&scene, 1.0).map_err(|e| ConfigError::Range {
                key: "ladder".into(),
                value: a.scene.display().to_string(),
                unit: String::new(),
                why: e.to_string(),
            })?;
            for g in &a.ladder.peaks_g {
                let mut s = c.sets.clone();
                s.extend(ladder::rung_overrides(&scene, *g)?);
                load_scene(&a.scene, &s)?;
            }
        }
        if matches!(scene.controller.mode, ControlMode::Lockstep | ControlMode::Realtime) {
            controller_starts(&scene, stop).with_context(|| format!("{}: starting its controller", c.label))?;
        }
        first.get_or_insert(scene);
    }
    Ok(first)
}

/// A controller the interrupted assessment did not reach.
fn not_assessed(c: &ControllerSpec) -> ControllerReport {
    let mut r = ControllerReport {
        label: c.label.clone(),
        set: c.own.clone(),
        law: String::new(),
        mode: String::new(),
        rate_hz: 0.0,
        sensitivity: PartOutcome::failed(Failure::Interrupted, "not measured: interrupted".into(), 0.0),
        vibration: PartOutcome::failed(Failure::Interrupted, "not measured: interrupted".into(), 0.0),
        ladder: PartOutcome::failed(Failure::Interrupted, "not measured: interrupted".into(), 0.0),
        verdict: String::new(),
        wall_s: 0.0,
    };
    r.verdict = "not assessed: interrupted".into();
    r
}

/// The worst failure of any part of any controller, as the command's error.
fn failed(report: &Report, dir: &Path) -> anyhow::Result<()> {
    let failures: Vec<(Failure, String)> = report
        .controllers
        .iter()
        .flat_map(|c| {
            [
                ("sensitivity", &c.sensitivity.failure, &c.sensitivity.why),
                ("vibration", &c.vibration.failure, &c.vibration.why),
                ("ladder", &c.ladder.failure, &c.ladder.why),
            ]
            .into_iter()
            .filter_map(move |(part, f, why)| {
                f.map(|f| (f, format!("{}: {part}: {}", c.label, why.clone().unwrap_or_default())))
            })
        })
        .collect();
    if let Some(worst) = failures.iter().map(|f| f.0).max_by_key(|f| f.rank()) {
        let message = if worst == Failure::Interrupted {
            "interrupted".to_string()
        } else {
            failures.iter().map(|f| f.1.as_str()).collect::<Vec<_>>().join("; ")
        };
        return Err(AssessError { kind: worst, message, dir: dir.display().to_string() }.into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::shown;
    use std::path::Path;

    /// The two-plane symmetric machine (the study's plane twice, 23 kg, I_p = 0.01162 kg m²,
    /// collocated sensors at ±l) under the continuous PD, every axis measured at standstill.
    /// Exciting one plane is half the common excitation and half the differential one: with
    /// identical loops the rotor's modes decouple into the cylindrical loop (the plane's load
    /// share, the planar model's mass: the planar closed form) and the conical loop (mass
    /// I_t / (2 l²) per plane), so `S_AA = (S_cyl + S_con) / 2`, in closed form. The measured
    /// peak of each axis must match that peak within 0.5 dB and 1 %; the cylindrical closed form
    /// must be the planar model's. (It is not `S_cyl` alone: the conical loop pulls the
    /// measured peak below the planar one, by 3.4 dB on this machine.)
    #[test]
    fn a_symmetric_two_plane_machine_is_measured_on_four_axes_against_its_modal_closed_form() {
        use super::{closed_form, closed_form_of_plane, measure_axis, sensitivity};
        use rayon::prelude::*;
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/paper-10g.toml");
        let sets = ["controller.mode=\"continuous\"", "controller.damping_ratio=0.2"].map(String::from);
        let planar = crate::config::load_scene(&path, &sets).expect("planar scene");
        let mut two_sets = sets.to_vec();
        two_sets.extend(
            ["rotor.model=\"two_plane\"", "rotor.mass_kg=23", "rotor.polar_inertia_kg_m2=0.01162"].map(String::from),
        );
        let scene = crate::config::load_scene(&path, &two_sets).expect("two-plane scene");
        let crate::config::Rotor::TwoPlane(m) = &scene.rotor else { panic!("two-plane") };
        let l = m.planes[1].station;
        assert!((m.planes[0].station + l).abs() < 1e-12 && m.planes.iter().all(|p| p.sensor == p.station));
        let (pd, cyl) = closed_form_of_plane(&scene, 0).expect("closed form");
        // The cylindrical loop is the planar model's loop.
        assert_eq!(Some((pd, cyl)), closed_form_of_plane(&planar, 0));
        let con = closed_form::AxisPlant { mass: m.rotor.transverse_inertia / (2.0 * l * l), ..cyl };
        let s_aa = |f: f64| 0.5 * (closed_form::sensitivity(&cyl, &pd, f) + closed_form::sensitivity(&con, &pd, f));
        let mut settings = sensitivity::Settings::for_gap(scene.plane(0).contact.gap);
        settings.f_min_hz = 20.0;
        settings.f_max_hz = 200.0;
        settings.points = 6;
        settings.probe_s = 0.3;
        settings.resolution = 0.01;
        let grid = sensitivity::log_grid(settings.f_min_hz, settings.f_max_hz, 20_000);
        let (f_peak, s_peak) =
            grid.iter().map(|f| (*f, s_aa(*f).norm())).fold((0.0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
        let db = |s: f64| 20.0 * s.log10();
        let stop = std::sync::atomic::AtomicBool::new(false);
        let axes: Vec<_> = (0..4).into_par_iter().map(|k| measure_axis(&scene, k, 0.0, &settings, &stop)).collect();
        for (k, axis) in axes.into_iter().enumerate() {
            let axis = axis.expect("measured");
            assert_eq!(axis.axis, ["x_A", "y_A", "x_B", "y_B"][k]);
            assert!(axis.stable, "{axis:?}");
            let peak = axis.peak.as_ref().expect("peak");
            assert!(
                (peak.s_db - db(s_peak)).abs() < 0.5,
                "{}: {} dB, closed form {} dB",
                axis.axis,
                peak.s_db,
                db(s_peak)
            );
            assert!(
                (peak.f_hz / f_peak - 1.0).abs() < 0.01,
                "{}: {} Hz, closed form {f_peak} Hz",
                axis.axis,
                peak.f_hz
            );
            for p in &axis.points {
                let cf = db(s_aa(p.f_hz).norm());
                assert!(
                    (p.s_db - cf).abs() < 0.3,
                    "{} at {} Hz: {} dB, closed form {cf} dB",
                    axis.axis,
                    p.f_hz,
                    p.s_db
                );
            }
        }
        // Not the planar peak: the conical loop lowers it.
        let planar_peak = db(closed_form::peak(&cyl, &pd, settings.f_min_hz, settings.f_max_hz).1);
        assert!(planar_peak - db(s_peak) > 1.0, "planar {planar_peak} dB, S_AA {} dB", db(s_peak));
    }

    #[test]
    fn paths_are_shown_relative_to_where_the_command_ran() {
        use super::{relative_text, shown_relative};
        let here = Path::new("/work/t");
        assert_eq!(shown_relative(Path::new("/work/t/config/a.toml"), here), "config/a.toml");
        assert_eq!(shown_relative(Path::new("config/assess/../a.toml"), here), "config/a.toml");
        assert_eq!(shown_relative(Path::new("/work/u/a.toml"), here), "../u/a.toml");
        assert_eq!(shown_relative(Path::new("/tmp/x"), here), "../../tmp/x");
        assert_eq!(shown_relative(Path::new("/work/t"), here), ".");
        let roots = [("/work/t/config".to_string(), "config".to_string()), ("/work/t".to_string(), ".".to_string())];
        assert_eq!(
            relative_text("run /work/t/config/x and /work/t/runs/y; /work/tt/z", &roots),
            "run config/x and runs/y; /work/tt/z"
        );
    }

    #[test]
    fn a_scene_path_is_shown_without_dot_dot() {
        assert_eq!(shown(Path::new("config/assess/../paper-10g.toml")), "config/paper-10g.toml");
        assert_eq!(shown(Path::new("./a/./b/../../c.toml")), "c.toml");
        assert_eq!(shown(Path::new("../x/../../y.toml")), "../../y.toml");
        assert_eq!(shown(Path::new("/etc/../a.toml")), "/a.toml");
        assert_eq!(shown(Path::new("a/..")), ".");
    }
}
