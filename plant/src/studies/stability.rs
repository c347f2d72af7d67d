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

/// Derivative evaluations past which a run's cost is said before it starts (about two minutes
/// at 1 µs per evaluation).
pub const COSTLY_EVALUATIONS: f64 = 1e8;

/// The fastest pole of the scene's hardware (rad/s) and the key that sets it: the sensor's
/// low-pass corner, a current loop's bandwidth (or its coil's R/L); `None` without hardware.
fn fastest_hardware_pole(scene: &Scene) -> Option<(f64, &'static str)> {
    use crate::sensor::LowPass;
    let sensor = scene.hardware.front_end.low_pass.map(|lp| match lp {
        LowPass::First { corner } | LowPass::Second { corner } => (corner, "sensor.bandwidth_hz"),
    });
    let coils = scene
        .hardware
        .amplifiers
        .iter()
        .flatten()
        .map(|a| (a.bandwidth.max(a.resistance / a.inductance), "amb.current_loop_hz"));
    sensor.into_iter().chain(coils).max_by(|a, b| a.0.total_cmp(&b.0))
}

/// What an adaptive method costs on a scene whose hardware has a fast pole (issue 31 item 11:
/// `sensor.bandwidth_hz = 1e9` with `dp5` took about 3 h for a 1.5 s scene): an explicit
/// method's step stays within its stability bound on the negative real axis, `ω h ≤ c`
/// (DP5 about 3.3, DOP853 about 6.0), whatever the tolerances, so the run takes at least
/// `duration · ω / c` steps. `Some(warning)` with that estimate when it passes
/// [`COSTLY_EVALUATIONS`] evaluations of the derivative.
pub fn hardware_cost(scene: &Scene) -> Option<String> {
    let m = scene.integrator.method;
    let (c, stages) = match m {
        Method::Dp5 => (3.3, 6.0),
        Method::Dop853 => (6.0, 12.0),
        _ => return None,
    };
    let (omega, key) = fastest_hardware_pole(scene)?;
    let h = c / omega;
    let steps = scene.duration / h;
    let evaluations = steps * stages;
    if evaluations.is_nan() || evaluations <= COSTLY_EVALUATIONS {
        return None;
    }
    let hours = evaluations * 1e-6 / 3600.0;
    Some(format!(
        "{key} puts a pole at {omega:.3e} rad/s that integrator.method = \"{}\" must resolve: its step stays \
         below {h:.2e} s, at least {steps:.2e} steps ({evaluations:.2e} evaluations of the derivative) for \
         scene.duration_s = {} s, about {hours:.1} h at 1 µs per evaluation; the run goes on (Ctrl-C keeps \
         what it computed): a {key} near the real hardware's keeps it short",
        crate::summary::snake_name(&m),
        scene.duration
    ))
}

/// Checks a fixed-step scene's step against the estimated limits, and an adaptive one's cost
/// on fast hardware ([`hardware_cost`]).
pub fn check(scene: &Scene) -> StepVerdict {
    let m = scene.integrator.method;
    if let Some(w) = hardware_cost(scene) {
        return StepVerdict::Warn(w);
    }
    if !matches!(m, Method::ExplicitEuler | Method::SymplecticEuler | Method::Rk4) {
        return StepVerdict::Fine;
    }
    // The stiff modes exist only while the race is free: with a parked race that is the step of
    // `contact_substeps`.
    let (key, steps) = match scene.plane(0).race_when_clear {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(sets: &[&str]) -> Scene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/paper-10g.toml");
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        crate::config::load_scene(&path, &sets).unwrap()
    }

    /// Issue 31 item 11: a legal sensor bandwidth (1 GHz) with an adaptive method ran for
    /// hours without a word. The cost is said before the run, with the estimate, for either
    /// adaptive method and either fast pole (the sensor's corner, a current loop); a bandwidth
    /// a real sensor has says nothing.
    #[test]
    fn a_fast_hardware_pole_under_an_adaptive_method_is_warned_with_its_cost() {
        for method in ["dp5", "dop853"] {
            let m = format!("integrator.method=\"{method}\"");
            let w = hardware_cost(&scene(&[&m, "sensor.bandwidth_hz=1e9"])).expect("a warning");
            assert!(w.contains("sensor.bandwidth_hz") && w.contains("steps") && w.contains(" h at 1 µs"), "{w}");
            assert!(matches!(check(&scene(&[&m, "sensor.bandwidth_hz=1e9"])), StepVerdict::Warn(_)));
            let w = hardware_cost(&scene(&[&m, "amb.amplifier=true", "amb.current_loop_hz=1e9"])).expect("a warning");
            assert!(w.contains("amb.current_loop_hz"), "{w}");
            assert_eq!(hardware_cost(&scene(&[&m, "sensor.bandwidth_hz=5000"])), None);
            assert_eq!(hardware_cost(&scene(&[&m])), None);
        }
    }
}
