//! The control-law trait, the plant constants a law designs itself from, and
//! the registry that builds a law by name.

use crate::discrete_pd::{DelayPd, DelayPdGains};
use crate::pd::{PdDesign, PdGains, SampledPd};
use crate::pid::{PidDesign, PidGains, SampledPid};
use crate::relev::{Relev, RelevSpec};

/// Plant constants a law needs for its design (SI units).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LoopConstants {
    /// Force-current coefficient k_i (N/A).
    pub ki_n_per_a: f64,
    /// Force-displacement (negative stiffness) coefficient k_s (N/m).
    pub ks_n_per_m: f64,
    /// Amplifier gain A_a (A/V).
    pub amp_gain_a_per_v: f64,
    /// Sensor gain A_s (V/m).
    pub sensor_gain_v_per_m: f64,
    /// Rotor mass m_r (kg), for the damping design and the gravity bias.
    pub rotor_mass_kg: f64,
    /// Gravity (m/s²); the gravity bias current is `m_r g / k_i` on the y axis.
    pub gravity_m_s2: f64,
}

/// One controller input: what the digital controller reads at a tick.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Sample {
    /// Sample index k (the tick it was taken at).
    pub seq: u64,
    /// Simulated time of the sample (s).
    pub t_s: f64,
    /// Sensor voltages `A_s·Δ` per axis (V), x then y.
    pub sensor_v: [f64; 2],
}

/// A sampled control law: one call per controller tick.
///
/// State lives in `self`, so a law is deterministic given its sample sequence;
/// the caller owns time (it is in the sample), never the law.
pub trait ControlLaw: Send {
    /// The law's registry name (`controller.law`).
    fn name(&self) -> &'static str;
    /// One tick: coil currents per axis (A), before the amplifier limit.
    fn update(&mut self, sample: &Sample) -> [f64; 2];
    /// Forget all memory (back to the state before the first sample).
    fn reset(&mut self);
}

/// What selects and parameterises a law (the scene's `[controller]` keys).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LawSpec<'a> {
    /// Law name, one of [`LAW_NAMES`].
    pub law: &'a str,
    /// Design stiffness k_e (N/m).
    pub stiffness_n_per_m: f64,
    /// Design damping ratio ξ_e.
    pub damping_ratio: f64,
    /// Controller sampling period (s).
    pub period_s: f64,
    /// Add the gravity bias current on the y axis.
    pub gravity_bias: bool,
    /// Amplifier current limit i_max (A), for anti-windup.
    pub current_limit_a: f64,
    /// Command delay d (samples): the command computed from sample k is applied from tick k + d.
    pub delay_samples: u32,
    /// The switching rule of `relev` (ignored by the other laws).
    pub relev: RelevSpec,
}

/// Laws the registry knows.
pub const LAW_NAMES: &[&str] = &["pd", "pid", "pd_delay", "relev"];

/// Why a law could not be built.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum LawError {
    /// The name is not in [`LAW_NAMES`].
    #[error("unknown controller law `{0}` (known laws: {known})", known = LAW_NAMES.join(", "))]
    Unknown(String),
    /// A design value is out of range.
    #[error("{key} = {value} {unit}: {why}")]
    Design {
        /// Config key.
        key: &'static str,
        /// Offending value.
        value: f64,
        /// Unit of the value.
        unit: &'static str,
        /// What is wrong.
        why: &'static str,
    },
}

/// Builds the sampled law a spec names.
pub fn build_law(spec: &LawSpec, c: &LoopConstants) -> Result<Box<dyn ControlLaw>, LawError> {
    let design = PdDesign {
        stiffness_n_per_m: spec.stiffness_n_per_m,
        damping_ratio: spec.damping_ratio,
        gravity_bias: spec.gravity_bias,
    };
    match spec.law {
        "pd" => {
            let gains = PdGains::from_design(&design, c)?;
            Ok(Box::new(SampledPd::new(gains, spec.period_s)))
        }
        "pid" => {
            let gains = PidGains::from_design(&PidDesign { pd: design, integral_time_s: None }, c)?;
            Ok(Box::new(SampledPid::new(gains, spec.period_s, spec.current_limit_a)))
        }
        "pd_delay" => {
            let gains = DelayPdGains::from_design(&design, c, spec.period_s, spec.delay_samples)?;
            Ok(Box::new(DelayPd::new(gains, spec.period_s)))
        }
        "relev" => Ok(Box::new(Relev::new(&design, &spec.relev, c, spec.period_s, spec.delay_samples)?)),
        other => Err(LawError::Unknown(other.to_string())),
    }
}

/// Clamps each axis current to `|i| ≤ limit` (A).
///
/// ```
/// assert_eq!(controller::saturate([3.0, -0.5], 2.0), [2.0, -0.5]);
/// ```
#[inline]
pub fn saturate(i: [f64; 2], limit: f64) -> [f64; 2] {
    [i[0].clamp(-limit, limit), i[1].clamp(-limit, limit)]
}
