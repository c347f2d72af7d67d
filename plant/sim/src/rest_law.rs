//! The run's law at rest (issue 38 item 3): the gain at zero frequency of each plane's law, for
//! the flexible rotor's rest equilibrium ([`plant_physics::flex::initial::static_sag_with`]), so
//! that the shaft starts where the law the run uses holds it, not where the scene's PD design
//! would.
//!
//! A law that states its linear form around levitation ([`controller::ControlLaw::linear`]:
//! `i = bias − A_a k_p F(z) u`, `F` a filter of the sensor voltage) has the static gain
//! `k₀ = k_p F(1)`, `F(1) = (b₀ + b₁ + b₂)/(1 + a₁ + a₂)`. A law with an integrator (`F` with a
//! pole at z = 1: `pid`, `ross_pid` with `ki_pid ≠ 0`) has none: at rest it drives the sensors to
//! zero with an integral state the plant cannot set in it (the law starts from zero, in the plant
//! or in the controller process), so its start stays the design's (docs/MODEL.md §13.6). A law
//! without a linear form, a law of the whole rotor, or a co-simulated command the plant cannot
//! build: the design's too.

use crate::config::{ControlMode, Scene};

/// Each plane's static gain `k₀` (V/V, as `PdGains::kp`) of the run's law, where it has one and
/// it is not the design's `k_p` (within 10⁻⁹, so that a PD's start is the one of before, bit
/// for bit); `None` elsewhere, and in continuous mode (the run's law is the design's PD).
pub fn static_gains(scene: &Scene) -> [Option<f64>; 2] {
    let c = &scene.controller;
    let registry = c.mode == ControlMode::Sampled || (c.mode != ControlMode::Continuous && c.cosim.command.is_none());
    let mut out = [None; 2];
    if !registry {
        return out;
    }
    for (i, design) in scene.plane_designs().iter().enumerate().take(2) {
        let Ok(law) = controller::build_law(&c.law, design, &c.params) else { continue };
        let Some(linear) = law.linear() else { continue };
        let Some(k0) = static_gain(&linear) else { continue };
        let Ok(pd) = controller::PdGains::from_design(&design.pd(), &design.constants) else { continue };
        if (k0 - pd.kp).abs() > 1e-9 * pd.kp.abs() {
            out[i] = Some(k0);
        }
    }
    out
}

/// Whether every plane's law of the run holds its plane's weight itself from the start
/// ([`controller::ControlLaw::holds_weight_at_rest`]: `ross_pid`'s integral without the gravity
/// bias). Its rest is then where the sensors read zero with each plane's share of the weight
/// carried, which is the design's rest with the gravity bias (the bias and the preloaded
/// integral give the same current at a zero reading): the flexible rotor's start is solved so
/// (the flexible rotor's `machine::Builds::initial_state`). `false` in continuous mode and for a command the
/// plant cannot build.
pub fn holds_weight(scene: &Scene) -> bool {
    let c = &scene.controller;
    let registry = c.mode == ControlMode::Sampled || (c.mode != ControlMode::Continuous && c.cosim.command.is_none());
    let designs = scene.plane_designs();
    registry
        && !designs.is_empty()
        && designs
            .iter()
            .all(|design| controller::build_law(&c.law, design, &c.params).is_ok_and(|law| law.holds_weight_at_rest()))
}

/// `k_p F(1)` of a linear law, `None` with a pole at z = 1 (an integrator) or not finite.
pub fn static_gain(law: &controller::LinearLaw) -> Option<f64> {
    let Some((b, a)) = law.filter else { return Some(law.pd.kp) };
    let den = 1.0 + a[0] + a[1];
    // A pole at z = 1 to rounding: the integrator's (1 − z⁻¹) factor.
    if den.abs() <= 1e-12 * (1.0 + a[0].abs() + a[1].abs()) {
        return None;
    }
    let k0 = law.pd.kp * (b[0] + b[1] + b[2]) / den;
    k0.is_finite().then_some(k0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use controller::ross_pid::RossPidGains;

    /// ROSS's PID by Tustin at 20 kHz: without the integral its static gain is `kp` (the
    /// derivative's filter passes nothing at rest), with it none; a plain PD's is its `k_p`.
    #[test]
    fn the_static_gain_of_rosss_pid_is_kp_without_its_integral() {
        let build = |ki: f64| {
            let gains = RossPidGains { kp: 7000.0, ki, kd: 3.325, n_f: 5000.0 };
            controller::ross_pid::RossPid::new(gains, 1.0, [0.0; 2], 5e-5, 2.0)
        };
        use controller::ControlLaw;
        let k0 = static_gain(&build(0.0).linear().unwrap()).unwrap();
        assert!((k0 - 7000.0).abs() < 1e-9 * 7000.0, "{k0}");
        assert_eq!(static_gain(&build(70000.0).linear().unwrap()), None);
        let pd = controller::LinearLaw { pd: controller::LinearPd { kp: 2.5, kd: 1e-3 }, filter: None };
        assert_eq!(static_gain(&pd), Some(2.5));
    }
}
