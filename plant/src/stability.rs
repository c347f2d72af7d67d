//! Stability of the fixed-step integrators on the contact problem, estimated
//! before a run, so that the plant can warn about (or refuse) settings that are
//! known to blow up. `plant bench accuracy` measures the real limits and
//! prints them next to these estimates (README, "Speed against accuracy").

//!
//! With `touchdown.race_when_clear = "parked"` the race rests in the housing frame while the gap
//! is clear, and the stiff race-on-balls mode is gone: the fixed step then only has to resolve
//! the rotor on its bearing (hundreds of rad/s). The limits below apply to the step taken while
//! the race is free, `integrator.contact_substeps`.

use crate::config::Scene;
use crate::integrate::Method;
use crate::model::RaceWhenClear;

/// Stability estimate of a fixed-step method: the largest step `c / ω_max`, with `ω_max` the
/// race's frequency on its contacts linearised at the reference's peak contact force (or on
/// one ball under the race's weight without contact) and `c` the method's stability bound on
/// the imaginary axis (symplectic Euler 2, RK4 2√2; explicit Euler has none: 0).
pub fn estimate(scene: &Scene, method: Method, peak_contact_force: f64) -> f64 {
    let p = &scene.params;
    let weight = p.race_mass * p.gravity;
    let load = peak_contact_force.max(weight);
    // Rotor – race: k = (10/9) K_r δ^(1/9) at δ = (F/K_r)^(9/10).
    let k_r = if peak_contact_force > 0.0 {
        let d = (load / p.contact.stiffness).powf(0.9);
        10.0 / 9.0 * p.contact.stiffness * d.powf(1.0 / 9.0)
    } else {
        0.0
    };
    // Balls: the load on about two balls, k = 2 · 1.5 K_b δ^(1/2), δ = (F / 2K_b)^(2/3).
    let share = if peak_contact_force > 0.0 { 2.0 } else { 1.0 };
    let d = (load / (share * p.balls.stiffness)).powf(2.0 / 3.0);
    let k_b = share * 1.5 * p.balls.stiffness * d.sqrt();
    let omega = ((k_r + k_b) / p.race_mass).sqrt();
    let c = match method {
        Method::SymplecticEuler => 2.0,
        Method::Rk4 => 2.0 * std::f64::consts::SQRT_2,
        _ => 0.0,
    };
    c / omega
}

/// Contact force at which the warning is judged (N): the peak rotor – race forces of the
/// study's 10 – 20 G scenes are 8 – 11 kN.
pub const REFERENCE_CONTACT_FORCE: f64 = 1e4;

/// Substeps per controller period that keep `method` within the estimated limit under a
/// [`REFERENCE_CONTACT_FORCE`] contact (1 for the adaptive methods and explicit Euler, which has no
/// limit to meet).
pub fn safe_contact_substeps(scene: &Scene, method: Method) -> u32 {
    let limit = estimate(scene, method, REFERENCE_CONTACT_FORCE);
    if limit > 0.0 && !method.is_adaptive() {
        (scene.controller.period / limit).ceil().max(1.0) as u32
    } else {
        1
    }
}

/// What the plant says about a scene's integrator before running it.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    /// Adaptive, or a fixed step within the estimate.
    Fine,
    /// Stable while levitated, but a contact will likely blow up.
    Warn(String),
    /// Unstable even without contact.
    Refuse(String),
}

/// Checks a fixed-step scene's step against the estimated limits.
pub fn check(scene: &Scene) -> Verdict {
    let m = scene.integrator.method;
    if !matches!(m, Method::ExplicitEuler | Method::SymplecticEuler | Method::Rk4) {
        return Verdict::Fine;
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
        return Verdict::Warn(
            "integrator.method = \"explicit_euler\" has no stability on the imaginary axis: the undamped race \
             modes grow at any step (the bench found 1.5 µs needed in the 10 G rub); prefer rk4 or dp5"
                .to_string(),
        );
    }
    if h > free {
        return Verdict::Refuse(format!(
            "{key} = {steps} gives a step of {h:.3e} s, beyond the estimated stability limit {free:.3e} s of \
             {name} for the race resting on its balls: the run would blow up before any contact; use \
             {key} >= {} or method \"dp5\"",
            substeps(free)
        ));
    }
    if h > contact {
        return Verdict::Warn(format!(
            "a step of {h:.3e} s exceeds the estimated stability limit {contact:.3e} s of {name} under a {:.0} kN \
             contact: a hard impact will likely blow up ({key} >= {} is safe)",
            REFERENCE_CONTACT_FORCE / 1e3,
            substeps(contact)
        ));
    }
    Verdict::Fine
}
