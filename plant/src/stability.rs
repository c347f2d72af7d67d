//! Stability of the fixed-step integrators on the contact problem, checked before a run, so
//! that the plant can warn about (or refuse) settings that are known to blow up. The estimate
//! is [`plant_physics::stability`]'s; `plant bench accuracy` measures the real limits and
//! prints them next to these estimates (docs/results/speed-accuracy.md).
//!
//! With `touchdown.race_when_clear = "parked"` the race rests in the housing frame while the gap
//! is clear, and the stiff race-on-balls mode is gone: the fixed step then only has to resolve
//! the rotor on its bearing (hundreds of rad/s). The limits below apply to the step taken while
//! the race is free, `integrator.contact_substeps`.

use crate::config::Scene;
use crate::integrate::Method;
use crate::model::RaceWhenClear;
pub use plant_physics::stability::REFERENCE_CONTACT_FORCE;

/// [`plant_physics::stability::estimate`] for a scene's parameters.
pub fn estimate(scene: &Scene, method: Method, peak_contact_force: f64) -> f64 {
    // The stiffer bearing plane of a two-plane rotor.
    (0..scene.planes())
        .map(|i| plant_physics::stability::estimate(scene.plane(i), method, peak_contact_force))
        .fold(f64::INFINITY, f64::min)
}

/// Substeps per controller period that keep `method` within the estimated limit under a
/// [`REFERENCE_CONTACT_FORCE`] contact (1 for the adaptive methods and explicit Euler, which has no
/// limit to meet).
pub fn safe_contact_substeps(scene: &Scene, method: Method) -> u32 {
    (0..scene.planes())
        .map(|i| plant_physics::stability::safe_contact_substeps(scene.plane(i), method, scene.controller.period))
        .max()
        .unwrap_or(1)
}

/// What the plant says about a scene's integrator before running it.
#[derive(Clone, Debug, PartialEq)]
pub enum StepVerdict {
    /// Adaptive, or a fixed step within the estimate.
    Fine,
    /// Stable while levitated, but a contact will likely blow up.
    Warn(String),
    /// Unstable even without contact.
    Refuse(String),
}

/// Checks a fixed-step scene's step against the estimated limits.
pub fn check(scene: &Scene) -> StepVerdict {
    let m = scene.integrator.method;
    if !matches!(m, Method::ExplicitEuler | Method::SymplecticEuler | Method::Rk4) {
        return StepVerdict::Fine;
    }
    // The stiff modes exist only while the race is free: with a parked race that is the step of
    // `contact_substeps`.
    let (key, steps) = match scene.params.race_when_clear {
        RaceWhenClear::Free => ("integrator.substeps", scene.integrator.substeps),
        RaceWhenClear::Parked(_) => ("integrator.contact_substeps", scene.integrator.contact_substeps),
    };
    let h = scene.controller.period / f64::from(steps);
    let name = crate::summary::snake_name(&m);
    let free = estimate(scene, m, 0.0);
    let contact = estimate(scene, m, REFERENCE_CONTACT_FORCE);
    let substeps = |limit: f64| (scene.controller.period / limit).ceil();
    if m == Method::ExplicitEuler {
        return StepVerdict::Warn(
            "integrator.method = \"explicit_euler\" has no stability on the imaginary axis: the undamped race \
             modes grow at any step (the bench found 1.5 µs needed in the 10 G rub); prefer rk4 or dp5"
                .to_string(),
        );
    }
    if h > free {
        return StepVerdict::Refuse(format!(
            "{key} = {steps} gives a step of {h:.3e} s, beyond the estimated stability limit {free:.3e} s of \
             {name} for the race resting on its balls: the run would blow up before any contact; use \
             {key} >= {} or method \"dp5\"",
            substeps(free)
        ));
    }
    if h > contact {
        return StepVerdict::Warn(format!(
            "a step of {h:.3e} s exceeds the estimated stability limit {contact:.3e} s of {name} under a {:.0} kN \
             contact: a hard impact will likely blow up ({key} >= {} is safe)",
            REFERENCE_CONTACT_FORCE / 1e3,
            substeps(contact)
        ));
    }
    StepVerdict::Fine
}
