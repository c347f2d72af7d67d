//! The measurement runs of an assessment: a scene made into a quiet run without shocks, one
//! axis' sensitivity measured through the run loop ([`measure_axis`]), and how a run or its
//! setup failed, as the report's [`Failure`].

use super::sensitivity;
use super::{axis_names, Failure};
use crate::config::{ControlMode, Scene};
use crate::cosim::Launch;
use crate::ensemble::member::setting_overrides;
use crate::ensemble::spec::MemberSetting;
use crate::run::{run_into, Outcome};
use std::cell::Cell;
use std::rc::Rc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Each bearing plane's air gap (m).
pub(super) fn plane_gaps(scene: &Scene) -> Vec<f64> {
    scene.rotor.bearings().map(|p| p.contact.gap).collect()
}

/// Each bearing plane's sensor gain (V/m).
fn plane_sensor_gains(scene: &Scene) -> Vec<f64> {
    scene.rotor.bearings().map(|p| p.loop_constants.sensor_gain_v_per_m).collect()
}

/// The initial offsets that put the rotor `offset_um` (µm) off on axis `axis` at its sensor:
/// the planar model's x or y; on the two-plane rotor, a translation and a slope that move the
/// axis' own plane's sensor by `offset_um` and leave the other plane's sensor where it was (both
/// modes, translation and tilt, start to move).
fn initial_offsets(scene: &Scene, axis: usize, offset_um: f64) -> Vec<String> {
    scene.rotor.sensor_offset(axis, offset_um)
}

/// Overrides of a measurement run without shocks: the shocks moved past `duration`, the fast
/// setting, the output at `output_hz`, no plots.
pub(super) fn quiet_run_overrides(scene: &Scene, duration: f64, output_hz: f64, substeps: u32) -> Vec<String> {
    let mut s: Vec<String> = setting_overrides(scene, MemberSetting::Fast);
    s.retain(|o| !o.starts_with("integrator.substeps"));
    s.push(format!("integrator.substeps={substeps}"));
    s.extend((0..scene.shock_count()).map(|i| format!("shock[{i}].start_s={:?}", duration + 10.0)));
    s.push(format!("scene.duration_s={duration:?}"));
    s.push(format!("output.rate_hz={output_hz:?}"));
    s.push("output.plots=false".into());
    s
}

pub(super) fn run_failure(outcome: &Outcome, stop: &AtomicBool) -> Option<(Failure, String)> {
    match outcome {
        Outcome::Completed => None,
        // Ctrl-C in a terminal also reaches a controller process of the same process group,
        // which then stops: the run was interrupted, not its controller lost.
        _ if stop.load(Ordering::Relaxed) => Some((Failure::Interrupted, "interrupted".into())),
        Outcome::Interrupted => None,
        Outcome::Diverged(e) => Some((Failure::Diverged, e.to_string())),
        Outcome::PeerLost(why) => Some((Failure::PeerLost, why.clone())),
        Outcome::MissBudget(why) | Outcome::OverrunBudget(why) => Some((Failure::PeerLost, why.clone())),
        Outcome::InvalidCommands(why) => Some((Failure::InvalidCommands, why.clone())),
    }
}

/// Measures the sensitivity of axis `axis` at rotor speed `speed_hz` (0: standstill).
pub fn measure_axis(
    scene: &Scene,
    axis: usize,
    speed_hz: f64,
    settings: &sensitivity::Settings,
    stop: &AtomicBool,
) -> Result<sensitivity::AxisResult, sensitivity::MeasureError> {
    measure_axis_or_abandon(scene, axis, speed_hz, settings, stop, None)
}

/// [`measure_axis`], stopping early (`MeasureError::Abandoned`) once `abandon` is set.
pub(super) fn measure_axis_or_abandon(
    scene: &Scene,
    axis: usize,
    speed_hz: f64,
    settings: &sensitivity::Settings,
    stop: &AtomicBool,
    abandon: Option<&AtomicBool>,
) -> Result<sensitivity::AxisResult, sensitivity::MeasureError> {
    use sensitivity::MeasureError;
    let continuous = scene.controller.mode == ControlMode::Continuous;
    let period = scene.controller.period;
    // The continuous PD reads the sine inside the derivative: steps of at most 1/20 of its period.
    let substeps = if continuous { ((20.0 * settings.f_max_hz * period).ceil() as u32).max(1) } else { 1 };
    let cap = sensitivity::RUN_CAP_S;
    let mut sets = quiet_run_overrides(scene, cap, 1000.0, substeps);
    sets.push(format!("rotor.speed_hz={speed_hz:?}"));
    sets.extend(initial_offsets(scene, axis, settings.probe_um));
    let run_scene = scene.reload(&sets).map_err(|e| MeasureError::Run { kind: Failure::Other, why: e.to_string() })?;
    let touched = Rc::new(Cell::new(None));
    let names = axis_names(scene);
    let mut m = sensitivity::Measure::new(
        settings.clone(),
        axis,
        names.get(axis).copied().unwrap_or("?"),
        period,
        !continuous,
        plane_sensor_gains(scene)[axis / 2],
        plane_gaps(scene)[axis / 2],
        speed_hz,
        stop,
        touched.clone(),
    );
    if let Some(flag) = abandon {
        m = m.abandon_on(flag);
    }
    let mut watch = sensitivity::ContactWatch { touched, gaps: plane_gaps(scene) };
    let run = run_into(&run_scene, &Launch::default(), &mut m, &mut watch);
    // Stopped by another axis' failure (while running or still connecting), not by Ctrl-C.
    let abandoned = || abandon.is_some_and(|a| a.load(Ordering::Relaxed)) && !stop.load(Ordering::Relaxed);
    let run = match run {
        Ok(run) => run,
        Err(crate::run::SetupError::Cosim(crate::cosim::CosimError::Interrupted)) if abandoned() => {
            return Err(MeasureError::Abandoned)
        }
        Err(e) => return Err(MeasureError::Run { kind: setup_failure(&e, stop), why: e.to_string() }),
    };
    if run.outcome == Outcome::Interrupted && abandoned() {
        return Err(MeasureError::Abandoned);
    }
    if let Some((kind, why)) = run_failure(&run.outcome, stop) {
        return Err(MeasureError::Run { kind, why });
    }
    m.result(run.clock.simulated)
}

pub(super) fn setup_failure(e: &crate::run::SetupError, stop: &AtomicBool) -> Failure {
    if stop.load(Ordering::Relaxed) {
        return Failure::Interrupted;
    }
    match e {
        crate::run::SetupError::Cosim(crate::cosim::CosimError::Interrupted) => Failure::Interrupted,
        crate::run::SetupError::Cosim(_) => Failure::PeerLost,
        _ => Failure::Other,
    }
}

pub(super) fn measure_kind(e: &sensitivity::MeasureError) -> Failure {
    match e {
        sensitivity::MeasureError::Touched { .. }
        | sensitivity::MeasureError::TouchedMulti { .. }
        | sensitivity::MeasureError::Level { .. } => Failure::NotGradable,
        sensitivity::MeasureError::Run { kind, .. } => *kind,
        sensitivity::MeasureError::Abandoned => Failure::Other,
    }
}
