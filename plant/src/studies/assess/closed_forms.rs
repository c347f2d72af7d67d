//! Which closed form a scene's loop has: the PD's ([`closed_form`]) where the law is a PD around
//! levitation, plane by plane, and its peak sensitivity over the measured band; a `state_space`
//! law's on any rotor, else the coupled loop of a rotor that gives its whole open loop, per axis.

use super::coupled::{self, AxisClosedForm};
use super::sensitivity;
use super::{closed_form, state_space_form, ClosedFormPeak};
use crate::config::{ControlMode, Scene};

/// The closed form of the scene's law, where it has one (plane A's, [`closed_form_of_plane`]).
pub fn closed_form_of(scene: &Scene) -> Option<closed_form::PdLoop> {
    closed_form_of_plane(scene, 0).map(|(pd, _)| pd)
}

/// The closed form of bearing plane `plane`'s loop, where the law has one, with the axis it
/// closes around: the planar model's axis; on the two-plane rotor, the plane's load share as a
/// planar rotor, with the plane's design. That is the two-plane loop only where the rotor's
/// modes decouple into the plane's own (the cylindrical mode of a symmetric machine); the
/// conical mode has another modal mass, and the measured sensitivity of an axis mixes both.
pub fn closed_form_of_plane(scene: &Scene, plane: usize) -> Option<(closed_form::PdLoop, closed_form::AxisPlant)> {
    let params = scene.rotor.bearings().nth(plane)?;
    if !matches!(params.amb, crate::force::amb::AmbLaw::Linear { .. }) {
        return None;
    }
    let design = scene.plane_designs().into_iter().nth(plane)?;
    let axis = closed_form::AxisPlant::of(&design.constants);
    let c = &scene.controller;
    // A sampled law runs in the plant whatever `controller.command` says; co-simulated, the
    // built-in controller runs the registry's law, a command is a black box.
    let registry = c.mode == ControlMode::Sampled || c.cosim.command.is_none();
    let pd = if c.mode == ControlMode::Continuous {
        let g = controller::PdGains::from_design(&design.pd(), &design.constants).ok()?;
        closed_form::PdLoop::Continuous { kp: g.kp, kd: g.kd }
    } else if registry {
        // The law says whether it is a PD around levitation ([`controller::ControlLaw::linear_pd`]).
        let g = controller::build_law(&c.law, &design, &c.params).ok()?.linear_pd()?;
        closed_form::PdLoop::Sampled { kp: g.kp, kd: g.kd, period: c.period, delay: c.delay_samples }
    } else {
        return None;
    };
    Some((pd, axis))
}

fn closed_form_peak(
    plant: &closed_form::AxisPlant,
    pd: &closed_form::PdLoop,
    settings: &sensitivity::Settings,
) -> ClosedFormPeak {
    let stable = closed_form::stable(plant, pd);
    let f_hi = match pd {
        closed_form::PdLoop::Sampled { period, .. } => settings.f_max_hz.min(0.45 / period),
        _ => settings.f_max_hz,
    };
    let curve: Vec<(f64, f64)> = sensitivity::log_grid(settings.f_min_hz, f_hi, 400)
        .into_iter()
        .map(|f| (f, 20.0 * closed_form::sensitivity(plant, pd, f).norm().log10()))
        .collect();
    if !stable {
        return ClosedFormPeak { stable, f_hz: None, s_abs: None, s_db: None, zone: "unstable".into(), curve };
    }
    let (f, s) = closed_form::peak(plant, pd, settings.f_min_hz, f_hi);
    ClosedFormPeak {
        stable,
        f_hz: Some(f),
        s_abs: Some(s),
        s_db: Some(20.0 * s.log10()),
        zone: sensitivity::zone(s).into(),
        curve,
    }
}

/// The closed forms of a scene's loop beside the measured `axes`: plane A's PD (none where the
/// law is not a PD), each plane's on a two-plane rotor, and each axis' at each of `speeds` (Hz)
/// with its difference from the measured peak.
pub(super) fn closed_forms(
    scene: &Scene,
    settings: &sensitivity::Settings,
    speeds: &[f64],
    axes: &[sensitivity::AxisResult],
) -> (Option<ClosedFormPeak>, Vec<ClosedFormPeak>, Vec<AxisClosedForm>) {
    let planes = scene.rotor.bearings().count();
    let closed: Vec<Option<ClosedFormPeak>> = (0..planes)
        .map(|i| closed_form_of_plane(scene, i).map(|(pd, axis)| closed_form_peak(&axis, &pd, settings)))
        .collect();
    let closed_form = closed.first().cloned().flatten();
    let closed_form_planes = if scene.planes() > 1 { closed.into_iter().flatten().collect() } else { Vec::new() };
    // A `state_space` law's closed form on any rotor (from the matrices `plant linear` writes),
    // else the coupled one of a rotor that gives its whole open loop.
    let state_space = state_space_form::applies(scene);
    let mut closed_form_axes = if state_space {
        state_space_form::closed_form_axes(scene, settings, speeds)
    } else {
        coupled::closed_form_axes(scene, settings, speeds)
    }
    .unwrap_or_default();
    if state_space {
        state_space_form::compare(&mut closed_form_axes, axes, scene);
    } else {
        coupled::compare(&mut closed_form_axes, axes, scene);
    }
    (closed_form, closed_form_planes, closed_form_axes)
}
