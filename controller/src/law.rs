//! The control-law trait, the common loop design every law is built from,
//! and why a law could not be built.

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
    /// Radial air gap r_0 between the rotor and the touchdown bearing's race (m): the radius at
    /// which the rotor touches; a law may scale thresholds from it (`relev`).
    pub air_gap_m: f64,
}

impl LoopConstants {
    /// The study's constants with the default magnetics (MODEL.md §7), as the default scene
    /// has them: for examples and tests.
    pub fn study() -> Self {
        Self {
            ki_n_per_a: 216.0,
            ks_n_per_m: 4.32e5,
            amp_gain_a_per_v: 1.0,
            sensor_gain_v_per_m: 25_000.0,
            rotor_mass_kg: 11.5,
            gravity_m_s2: 9.80665,
            air_gap_m: 150e-6,
        }
    }
}

/// The common loop design a law is built from: the closed loop asked for,
/// the sampling, the amplifier, and the plant constants. The plant converts
/// its scene into one (`Scene::design`), the wire carries it in the hello
/// (`Hello::design`), and every law of the registry is built from it and its
/// own [`crate::Params`].
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Design {
    /// Closed-loop stiffness k_e (N/m), `controller.stiffness_n_per_m`.
    pub stiffness_n_per_m: f64,
    /// Closed-loop damping ratio ξ_e, `controller.damping_ratio`.
    pub damping_ratio: f64,
    /// Controller sampling period T (s), `1 / controller.rate_hz`.
    pub period_s: f64,
    /// Add the gravity bias current on the y axis, `controller.gravity_bias`.
    pub gravity_bias: bool,
    /// Amplifier current limit i_max (A), `controller.current_limit_a` (for anti-windup).
    pub current_limit_a: f64,
    /// Command delay d (samples), `controller.delay_samples`: the command computed from sample k
    /// is applied from tick k + d.
    pub delay_samples: u32,
    /// The plant constants.
    pub constants: LoopConstants,
}

impl Design {
    /// The continuous PD design (k_e, ξ_e, gravity bias) of this loop.
    pub fn pd(&self) -> crate::PdDesign {
        crate::PdDesign {
            stiffness_n_per_m: self.stiffness_n_per_m,
            damping_ratio: self.damping_ratio,
            gravity_bias: self.gravity_bias,
        }
    }
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

/// Why a law could not be built.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum LawError {
    /// The name is not in the registry.
    #[error("unknown controller law `{name}` (known laws: {known})", known = crate::registry::law_names().join(", "))]
    Unknown {
        /// The name asked for.
        name: String,
    },
    /// A value of the common design is out of range.
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
    /// One of the law's own parameters (`[controller.params]`) is refused: wrong type or out
    /// of range.
    #[error("law {law}: controller.params.{key} = {value}{unit}: {why}", unit = unit_suffix(unit))]
    Param {
        /// The law.
        law: &'static str,
        /// The parameter's key inside `[controller.params]`.
        key: String,
        /// The value as given (TOML).
        value: String,
        /// Its unit (empty if dimensionless).
        unit: &'static str,
        /// What is wrong.
        why: String,
    },
    /// The law refuses the design it was given, for a reason of its own (a law of the C API
    /// whose `build` returned NULL, with its message).
    #[error("law {law}: {why}")]
    Refused {
        /// The law.
        law: &'static str,
        /// Its reason.
        why: String,
    },
    /// `[controller.params]` holds a key the law does not read.
    #[error("law {law}: unknown parameter controller.params.{key} = {value} (law {law} reads {known})", known = known_list(known))]
    UnknownParam {
        /// The law.
        law: &'static str,
        /// The key.
        key: String,
        /// Its value as given (TOML).
        value: String,
        /// The keys the law reads.
        known: Vec<&'static str>,
    },
}

fn unit_suffix(unit: &str) -> String {
    if unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    }
}

fn known_list(known: &[&str]) -> String {
    if known.is_empty() {
        "no parameters".to_string()
    } else {
        known.join(", ")
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
