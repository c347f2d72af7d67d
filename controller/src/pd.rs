//! The study's PD law, specified by the closed-loop stiffness and damping it
//! should give (MODEL.md §3).
//!
//! With the linearised bearing `F = k_i i + k_s Δ` and
//! `i = i_bias − A_a (k_p u + k_d u̇)`, `u = A_s Δ`, the loop acts as a spring
//! and damper:
//!
//! ```text
//! k_e = k_i k_p A_a A_s − k_s        c_e = k_i k_d A_a A_s = 2 ξ_e √(k_e m_r)
//! ```
//!
//! so `k_p = (k_e + k_s) / (k_i A_a A_s)` (V/V) and `k_d = c_e / (k_i A_a A_s)` (s).
//! The gravity bias `i_g = m_r g / k_i` on the y axis centres the levitated rotor.

pub use crate::law::PdDesign;
use crate::law::{ControlLaw, Design, LawEntry, LawError, LoopConstants, Sample};
use crate::params::Params;

/// `pd`: the naively sampled PD of the design (no parameters of its own).
pub const LAW: LawEntry =
    LawEntry { name: "pd", summary: "the design's PD, naively sampled (backward-difference derivative)", build };

fn build(design: &Design, params: &Params) -> Result<Box<dyn ControlLaw>, LawError> {
    params.reader(LAW.name).finish()?;
    let gains = PdGains::from_design(&design.pd(), &design.constants)?;
    Ok(Box::new(SampledPd::new(gains, design.period_s)))
}

/// PD gains derived from a design.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PdGains {
    /// Proportional gain k_p (V/V).
    pub kp: f64,
    /// Derivative gain k_d (s).
    pub kd: f64,
    /// Amplifier gain A_a (A/V).
    pub amp_gain_a_per_v: f64,
    /// Bias current per axis (A).
    pub bias_a: [f64; 2],
}

impl PdGains {
    /// Derives k_p, k_d and the bias from a design and the plant constants.
    ///
    /// ```
    /// use controller::{LoopConstants, PdDesign, PdGains};
    /// let c = LoopConstants { ki_n_per_a: 216.0, ks_n_per_m: 4.32e5, amp_gain_a_per_v: 1.0,
    ///     sensor_gain_v_per_m: 25_000.0, rotor_mass_kg: 11.5, gravity_m_s2: 9.80665, air_gap_m: 1.5e-4 };
    /// let g = PdGains::from_design(&PdDesign { stiffness_n_per_m: 1e6, damping_ratio: 0.01,
    ///     gravity_bias: true }, &c).unwrap();
    /// // k_e = k_i k_p A_a A_s − k_s
    /// assert!((216.0 * g.kp * 25_000.0 - 4.32e5 - 1e6).abs() < 1e-6);
    /// ```
    pub fn from_design(d: &PdDesign, c: &LoopConstants) -> Result<Self, LawError> {
        let design = |key, value, unit, why| LawError::Design { key, value, unit, why };
        if !(d.stiffness_n_per_m.is_finite() && d.stiffness_n_per_m > 0.0) {
            return Err(design("controller.stiffness_n_per_m", d.stiffness_n_per_m, "N/m", "must be > 0"));
        }
        if !(d.damping_ratio.is_finite() && d.damping_ratio >= 0.0) {
            return Err(design("controller.damping_ratio", d.damping_ratio, "", "must be >= 0"));
        }
        let loop_gain = c.ki_n_per_a * c.amp_gain_a_per_v * c.sensor_gain_v_per_m;
        let c_e = 2.0 * d.damping_ratio * (d.stiffness_n_per_m * c.rotor_mass_kg).sqrt();
        let bias_y = if d.gravity_bias { c.rotor_mass_kg * c.gravity_m_s2 / c.ki_n_per_a } else { 0.0 };
        Ok(Self {
            kp: (d.stiffness_n_per_m + c.ks_n_per_m) / loop_gain,
            kd: c_e / loop_gain,
            amp_gain_a_per_v: c.amp_gain_a_per_v,
            bias_a: [0.0, bias_y],
        })
    }

    /// Coil currents (A) from sensor voltages `u` (V) and their rates `u̇` (V/s):
    /// `i = i_bias − A_a (k_p u + k_d u̇)`, per axis, unsaturated.
    #[inline]
    pub fn current(&self, u: [f64; 2], u_dot: [f64; 2]) -> [f64; 2] {
        let axis = |k: usize| self.bias_a[k] - self.amp_gain_a_per_v * (self.kp * u[k] + self.kd * u_dot[k]);
        [axis(0), axis(1)]
    }
}

/// The derivative of a sampled signal as the backward difference
/// `u̇_k ≈ (u_k − u_{k−1}) / T` (zero at the first sample), per axis.
#[derive(Clone, Debug)]
pub struct BackwardDifference {
    period_s: f64,
    prev: Option<[f64; 2]>,
}

impl BackwardDifference {
    /// A differencer for sampling period `period_s` (s).
    pub fn new(period_s: f64) -> Self {
        Self { period_s, prev: None }
    }

    /// The rate of `u` at this sample; remembers `u` for the next.
    #[inline]
    pub fn rate(&mut self, u: [f64; 2]) -> [f64; 2] {
        let r = match self.prev {
            Some(p) => [(u[0] - p[0]) / self.period_s, (u[1] - p[1]) / self.period_s],
            None => [0.0; 2],
        };
        self.prev = Some(u);
        r
    }

    /// Forgets the previous sample.
    pub fn reset(&mut self) {
        self.prev = None;
    }
}

/// The PD law naively sampled: the derivative is the backward difference of
/// the sampled sensor voltage (see [`BackwardDifference`]).
#[derive(Clone, Debug)]
pub struct SampledPd {
    gains: PdGains,
    rate: BackwardDifference,
}

impl SampledPd {
    /// A sampled PD with the given gains and sampling period (s).
    pub fn new(gains: PdGains, period_s: f64) -> Self {
        Self { gains, rate: BackwardDifference::new(period_s) }
    }
}

impl ControlLaw for SampledPd {
    fn name(&self) -> &'static str {
        LAW.name
    }

    fn update(&mut self, s: &Sample) -> [f64; 2] {
        let u_dot = self.rate.rate(s.sensor_v);
        self.gains.current(s.sensor_v, u_dot)
    }

    fn reset(&mut self) {
        self.rate.reset();
    }

    fn linear_pd(&self) -> Option<crate::law::LinearPd> {
        Some(crate::law::LinearPd { kp: self.gains.kp, kd: self.gains.kd })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gains_reproduce_stiffness_damping_and_bias() {
        let c = LoopConstants::study();
        let d = PdDesign { stiffness_n_per_m: 1e6, damping_ratio: 0.01, gravity_bias: true };
        let g = PdGains::from_design(&d, &c).unwrap();
        // A static offset Δ gives F = k_i i + k_s Δ = k_i i_bias − k_e Δ.
        let delta = 1e-5;
        let i = g.current([0.0, c.sensor_gain_v_per_m * delta], [0.0; 2]);
        let f = c.ki_n_per_a * i[1] + c.ks_n_per_m * delta;
        assert!((f - (c.rotor_mass_kg * c.gravity_m_s2 - 1e6 * delta)).abs() < 1e-6);
        // A velocity gives F = −c_e v with c_e = 2 ξ √(k m).
        let v = 0.01;
        let i = g.current([0.0; 2], [c.sensor_gain_v_per_m * v, 0.0]);
        let c_e = 2.0 * 0.01 * (1e6_f64 * 11.5).sqrt();
        assert!((c.ki_n_per_a * i[0] + c_e * v).abs() < 1e-9);
    }

    #[test]
    fn sampled_pd_uses_backward_difference() {
        let c = LoopConstants::study();
        let d = PdDesign { stiffness_n_per_m: 1e6, damping_ratio: 0.01, gravity_bias: false };
        let g = PdGains::from_design(&d, &c).unwrap();
        let mut law = SampledPd::new(g, 1e-4);
        let first = law.update(&Sample { seq: 0, t_s: 0.0, sensor_v: [0.1, 0.0], ..Default::default() });
        assert_eq!(first, g.current([0.1, 0.0], [0.0; 2]));
        let second = law.update(&Sample { seq: 1, t_s: 1e-4, sensor_v: [0.2, 0.0], ..Default::default() });
        assert_eq!(second, g.current([0.2, 0.0], [1000.0, 0.0]));
        law.reset();
        assert_eq!(law.update(&Sample { seq: 0, t_s: 0.0, sensor_v: [0.1, 0.0], ..Default::default() }), first);
    }

    #[test]
    fn bad_design_names_key_value_unit() {
        let d = PdDesign { stiffness_n_per_m: -1.0, damping_ratio: 0.01, gravity_bias: true };
        let e = PdGains::from_design(&d, &LoopConstants::study()).unwrap_err().to_string();
        assert!(e.contains("controller.stiffness_n_per_m") && e.contains("-1") && e.contains("N/m"), "{e}");
    }
}
