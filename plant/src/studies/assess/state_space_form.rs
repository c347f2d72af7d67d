//! The closed form of a `state_space` law (every axis at once; a law may couple the axes), on
//! any rotor: the law's discrete system closed on the very matrices `plant linear` writes
//! ([`crate::linear::build`]: the plant at the speed, held and delayed as the controller sees
//! it), per axis and speed as [`super::coupled`]'s for the flexible rotor: `S = (I − P C)⁻¹`'s
//! diagonal on a log grid ([`crate::linear::law::sensitivity`]), stability from the closed
//! loop's poles (their largest modulus, [`crate::linear::law::closed_loop`]), the peaks refined.

use super::coupled::{every_axis, AxisClosedForm};
use super::sensitivity::{self, Settings};
use crate::config::Scene;
use crate::linear::law::{self, LinearLaw};

/// Whether the scene's law is a `state_space` law this closed form is for.
pub fn applies(scene: &Scene) -> bool {
    scene.controller.law == controller::state_space::LAW.name
        && matches!(law::of(scene), Some(LinearLaw::StateSpace { .. }))
}

/// The linear loop at `speed_hz` (Hz): the law, the plant (continuous, discrete).
fn loop_at(scene: &Scene, speed_hz: f64) -> Option<(LinearLaw, crate::linear::Built)> {
    let law = law::of(scene)?;
    let built = crate::linear::build(scene, speed_hz).ok()?;
    Some((law, built))
}

/// Every axis' closed form at each speed of `speeds_hz` (Hz); `None` where the law has no
/// linear form or the plant no linear model.
pub fn closed_form_axes(scene: &Scene, settings: &Settings, speeds_hz: &[f64]) -> Option<Vec<AxisClosedForm>> {
    every_axis(&super::axis_names(scene), speeds_hz, settings, |speed_hz| {
        let (law, built) = loop_at(scene, speed_hz)?;
        let LinearLaw::StateSpace { system, period } = &law else { return None };
        let a = law::closed_loop(&built.discrete.0, system)?;
        let largest_pole = a.complex_eigenvalues().iter().map(|p| p.norm()).fold(0.0, f64::max);
        let f_hi = settings.f_max_hz.min(0.45 / period);
        let s_at = move |f: f64| law::sensitivity(&law, &built.plant.system, &built.discrete.0, f);
        Some((largest_pole < 1.0, largest_pole, f_hi, s_at))
    })
}

/// Fills each closed form's `measured_difference_db` from the measured axes.
pub fn compare(forms: &mut [AxisClosedForm], measured: &[sensitivity::AxisResult], scene: &Scene) {
    let names = super::axis_names(scene);
    for form in forms.iter_mut() {
        let Some(axis) = measured.iter().find(|a| a.axis == form.axis && a.speed_hz == form.speed_hz) else {
            continue;
        };
        if axis.points.is_empty() || !form.stable {
            continue;
        }
        let Some((law, built)) = loop_at(scene, form.speed_hz) else { continue };
        let k = names.iter().position(|n| *n == form.axis).unwrap_or(0);
        let worst = axis
            .points
            .iter()
            .map(|p| {
                let s = law::sensitivity(&law, &built.plant.system, &built.discrete.0, p.f_hz)[(k, k)].norm();
                (p.s_db - 20.0 * s.log10()).abs()
            })
            .fold(0.0, f64::max);
        form.measured_difference_db = Some(worst);
    }
}
