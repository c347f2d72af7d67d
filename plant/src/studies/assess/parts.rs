//! The parts of one controller's assessment, each run and judged on its own: the sensitivity
//! (every axis at each speed, with the closed forms beside it), the vibration of the levitated
//! rotor and the shock ladder.

use super::closed_forms::closed_forms;
use super::measure::{
    measure_axis_or_abandon, measure_kind, plane_gaps, quiet_run_overrides, run_failure, setup_failure,
};
use super::spec::{self, Assessment, ControllerSpec};
use super::{axis_names, duty, ladder, margins, sensitivity, vibration};
use super::{Failure, PartOutcome, SensitivityPart};
use crate::config::Scene;
use crate::cosim::Launch;
use crate::run::jobs::jobs_for;
use crate::run::{run_into, Outcome};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// A sensitivity part that failed or was interrupted: how, why, and the part with the axes
/// measured before it (none: `None`).
type PartialSensitivity = (Failure, String, Option<Box<SensitivityPart>>);

/// The sensitivity part of one controller: every axis at each speed, in parallel.
pub(super) fn sensitivity_part(
    scene: &Scene,
    a: &Assessment,
    stop: &AtomicBool,
    log: &(dyn Fn(&str) + Sync),
) -> Result<SensitivityPart, PartialSensitivity> {
    let speed = scene.rotor.speed() / std::f64::consts::TAU;
    let speeds: Vec<f64> = a.speeds.iter().map(|s| if *s == spec::Speed::Rated { speed } else { 0.0 }).collect();
    let jobs: Vec<(usize, f64)> =
        speeds.iter().flat_map(|s| (0..axis_names(scene).len()).map(move |k| (k, *s))).collect();
    // One axis failing fails the part: the others stop there instead of running on for nothing.
    let abandon = AtomicBool::new(false);
    let results: Vec<_> = jobs_for(scene, || {
        jobs.par_iter()
            .map(|&(k, s)| {
                let r = measure_axis_or_abandon(scene, k, s, &a.sensitivity, stop, Some(&abandon));
                match &r {
                    Ok(x) => {
                        let peak = x
                            .peak
                            .as_ref()
                            .map_or(String::new(), |p| format!(", {:.2} dB at {:.2} Hz", p.s_db, p.f_hz));
                        log(&format!("  axis {} at {:.0} Hz: zone {}{peak}", x.axis, x.speed_hz, x.zone));
                    }
                    Err(_) => abandon.store(true, Ordering::Relaxed),
                }
                r
            })
            .collect()
    });
    let mut axes = Vec::new();
    let mut errors = Vec::new();
    for r in results {
        match r {
            Ok(x) => axes.push(x),
            Err(sensitivity::MeasureError::Abandoned) => {}
            Err(e) => errors.push((measure_kind(&e), e.to_string())),
        }
    }
    let simulated_s = axes.iter().map(|x| x.simulated_s).sum();
    let (closed_form, closed_form_planes, closed_form_axes) = closed_forms(scene, &a.sensitivity, &speeds, &axes);
    for f in &closed_form_axes {
        let peak = f.s_db.map_or(String::new(), |d| format!(", {d:.2} dB at {:.2} Hz", f.f_hz.unwrap_or(f64::NAN)));
        let diff = f.measured_difference_db.map_or(String::new(), |d| format!("; measured within {d:.2} dB"));
        log(&format!("  closed form {} at {:.0} Hz: zone {}{peak}{diff}", f.axis, f.speed_hz, f.zone));
    }
    let margins = margins::of(scene, &axes);
    let part = SensitivityPart {
        axes,
        closed_form,
        closed_form_planes,
        closed_form_axes,
        margins,
        simulated_s,
        settings: a.sensitivity.clone(),
    };
    if let Some(worst) = errors.iter().max_by_key(|e| e.0.rank()) {
        // The axes often fail alike (one controller command, one interruption): each reason once.
        let mut reasons: Vec<&str> = Vec::new();
        for (_, why) in &errors {
            if !reasons.contains(&why.as_str()) {
                reasons.push(why);
            }
        }
        let mut why = reasons.join("; ");
        // The axes measured before the failure are kept, and said to be all there is.
        let kept = (!part.axes.is_empty()).then(|| Box::new(part));
        if let Some(p) = &kept {
            let names: Vec<String> = p.axes.iter().map(|x| format!("{} at {:.0} Hz", x.axis, x.speed_hz)).collect();
            why.push_str(&format!(
                "; measured before it: {} of {} axes ({})",
                names.len(),
                jobs.len(),
                names.join(", ")
            ));
        }
        return Err((worst.0, why, kept));
    }
    Ok(part)
}

/// The vibration zone of a loop the sensitivity part measured unstable: not graded.
pub const UNSTABLE_ZONE: &str = "not graded (unstable loop)";

/// The vibration part: the levitated rotor at its speed without shock.
pub(super) fn vibration_part(
    scene: &Scene,
    decay_per_s: Option<f64>,
    stop: &AtomicBool,
) -> Result<vibration::Vibration, (Failure, String)> {
    let speed_hz = scene.rotor.speed() / std::f64::consts::TAU;
    let settle = decay_per_s.filter(|s| *s > 0.0).map_or(1.0, |s| (1000f64.ln() / s).clamp(0.1, 5.0));
    let window = if speed_hz > 0.0 { (50.0 / speed_hz).max(0.2) } else { 0.2 };
    let sets = quiet_run_overrides(scene, settle + window, scene.controller.rate_hz.min(20_000.0), 1);
    let run_scene = scene.reload(&sets).map_err(|e| (Failure::Other, e.to_string()))?;
    let mut sink = vibration::VibrationSink::new(settle, plane_gaps(scene));
    let run = run_into(&run_scene, &Launch::default(), &mut crate::hooks::Cancel(stop), &mut sink)
        .map_err(|e| (setup_failure(&e, stop), e.to_string()))?;
    if let Some(t) = sink.touched {
        return Err((
            Failure::NotGradable,
            format!("not levitated: without a shock the rotor touches the touchdown bearing at t = {t:.4} s"),
        ));
    }
    if let Some(f) = run_failure(&run.outcome, stop) {
        return Err(f);
    }
    if run.outcome == Outcome::Interrupted {
        return Err((Failure::Interrupted, "interrupted".into()));
    }
    // The report's one current limit is plane A's.
    Ok(sink.figures(scene.plane(0).current_limit, speed_hz, settle, window))
}

/// The shock ladder of one controller: none where the rotor was not levitated before the
/// shock; a member may end once decided only where the probe measured the loop stable.
pub(super) fn ladder_part(
    a: &Assessment,
    c: &ControllerSpec,
    scene: &Scene,
    levitated: bool,
    decay_at_speed: Option<f64>,
    stop: &AtomicBool,
    log: &(dyn Fn(&str) + Sync),
) -> anyhow::Result<PartOutcome<ladder::LadderResult>> {
    let interrupted = || stop.load(Ordering::Relaxed);
    if !levitated {
        let why = "not levitated before the shock (see the vibration part): no ladder".to_string();
        return Ok(PartOutcome::failed(Failure::NotGradable, why, 0.0));
    }
    log(&format!("{}: shock ladder", c.label));
    let t = Instant::now();
    let b = duty::Bearing::of_scene(scene, a.materials, a.capacity_fraction);
    let stable = decay_at_speed.is_some_and(|s| s > 0.0);
    let kind = |e: &anyhow::Error| {
        if interrupted() {
            Failure::Interrupted
        } else if e.chain().any(|c| c.is::<ladder::NotControlling>()) {
            Failure::InvalidCommands
        } else if e.chain().any(|c| c.is::<crate::run::SetupError>() || c.is::<ladder::ControllerLost>()) {
            Failure::PeerLost
        } else {
            Failure::Other
        }
    };
    Ok(match ladder::ladder(&a.scene, &c.sets, &a.ladder, b, stable, stop, log) {
        Ok((l, Some(e))) => {
            let kind = kind(&e);
            PartOutcome {
                status: if kind == Failure::Interrupted { "interrupted" } else { "failed" },
                why: Some(format!("{e:#}; the rungs marked incomplete were not decided")),
                failure: Some(kind),
                result: Some(l),
                wall_s: t.elapsed().as_secs_f64(),
            }
        }
        Ok((l, None)) if l.interrupted => PartOutcome {
            status: "interrupted",
            why: Some("interrupted: the rungs marked incomplete were not decided".into()),
            failure: Some(Failure::Interrupted),
            result: Some(l),
            wall_s: t.elapsed().as_secs_f64(),
        },
        Ok((l, None)) => PartOutcome::measured(l, t.elapsed().as_secs_f64()),
        Err(e) => PartOutcome::failed(kind(&e), format!("{e:#}"), t.elapsed().as_secs_f64()),
    })
}
