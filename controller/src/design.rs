//! What a law is built from: the plant constants of a bearing plane ([`LoopConstants`]), the
//! loop asked of that plane ([`Design`]), and for a two-plane rotor both planes' designs with
//! the rotor's geometry ([`RotorDesign`], [`Geometry`]). All SI. The plant converts its scene
//! into these, the wire carries them in the hello, and every law is built from them and its
//! own `[controller.params]`. (Re-exported from [`crate::law`] and the crate root.)
//!
//! # Planes, axes and signs (issue 17)
//!
//! z is the rotor axis, from bearing plane A towards plane B, origin at the rotor's centre of
//! mass; x horizontal, y up, spin Ω about +z. The axes are listed x_A, y_A, x_B, y_B wherever
//! axes are listed (wire, laws, currents); the planar model's x, y is plane A's pair. The
//! planar model is one bearing plane's share of a symmetric machine: its `rotor_mass_kg` is
//! the mass that bearing carries.

use crate::error::LawError;

/// Axes of the two-plane rotor (x_A, y_A, x_B, y_B): the most a law drives.
pub const ROTOR_AXES: usize = 4;

/// The plant constants of one bearing plane that a law needs for its design (SI units).
///
/// ```
/// use controller::LoopConstants;
/// let c = LoopConstants::study();
/// // The loop gain from sensor volts back to newtons: k_i A_a A_s (N per V of command per V).
/// let loop_gain = c.ki_n_per_a * c.amp_gain_a_per_v * c.sensor_gain_v_per_m;
/// assert_eq!(loop_gain, 5.4e6);
/// // The gravity bias current of this plane's mass share (A).
/// assert!((c.rotor_mass_kg * c.gravity_m_s2 / c.ki_n_per_a - 0.5221).abs() < 1e-4);
/// ```
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
    /// The rotor mass this bearing carries m_r (kg), for the damping design and the gravity
    /// bias: the whole rotor's mass in the planar model (one bearing's share of a symmetric
    /// machine), and the plane's static share of the mass on a two-plane rotor.
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

/// The loop design of one bearing plane a law is built from: the closed loop asked for, the
/// sampling, the amplifier, and the plane's plant constants. The plant converts its scene into
/// one (`Scene::design`), the wire carries it in the hello (`Hello::design`; plane B's in the
/// v4 fields), and every law of the registry is built from it and its own [`crate::Params`].
/// On a two-plane rotor a per-plane (decentralised) law is built once per plane, each from
/// its plane's design.
///
/// ```
/// use controller::{build_law, Design, Params, Sample};
/// let design = Design::study(); // k_e = 1e6 N/m, ξ_e = 0.01, 20 kHz, i_max = 2 A, d = 1
/// assert_eq!(design.period_s, 1.0 / 20_000.0);
/// let mut pd = build_law("pd", &design, &Params::default()).unwrap();
/// // 10 µm off centre on x: a restoring current on x, the gravity bias on y.
/// let u = design.constants.sensor_gain_v_per_m * 10e-6;
/// let i = pd.update(&Sample { seq: 0, t_s: 0.0, sensor_v: [u, 0.0], ..Default::default() });
/// assert!(i[0] < 0.0 && i[1] > 0.5);
/// ```
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
    pub fn pd(&self) -> PdDesign {
        PdDesign {
            stiffness_n_per_m: self.stiffness_n_per_m,
            damping_ratio: self.damping_ratio,
            gravity_bias: self.gravity_bias,
        }
    }

    /// The study's reference design (the default scene's): k_e = 10⁶ N/m, ξ_e = 0.01 at
    /// 20 kHz, gravity bias on, i_max = 2 A, one sample of delay, [`LoopConstants::study`].
    pub fn study() -> Self {
        Self {
            stiffness_n_per_m: 1e6,
            damping_ratio: 0.01,
            period_s: 1.0 / 20_000.0,
            gravity_bias: true,
            current_limit_a: 2.0,
            delay_samples: 1,
            constants: LoopConstants::study(),
        }
    }
}

/// A PD design: the closed-loop behaviour asked for (the part of a [`Design`] the PD-type
/// laws are specified by; [`Design::pd`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PdDesign {
    /// Closed-loop stiffness k_e (N/m), > 0.
    pub stiffness_n_per_m: f64,
    /// Closed-loop damping ratio ξ_e, ≥ 0.
    pub damping_ratio: f64,
    /// Add the gravity bias current on the y axis.
    pub gravity_bias: bool,
}

/// The geometry and inertia of a two-plane rotor (SI), as the hello carries it for 4 axes.
/// Stations are axial positions from the centre of mass along +z (plane A's side negative).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Geometry {
    /// The whole rotor's mass M (kg).
    pub mass_kg: f64,
    /// Transverse moment of inertia I_t about the centre of mass (kg m²).
    pub transverse_inertia_kg_m2: f64,
    /// Polar moment of inertia I_p (kg m²).
    pub polar_inertia_kg_m2: f64,
    /// Rated (commanded) spin speed (rad/s); the measured speed is in every sample.
    pub rated_speed_rad_s: f64,
    /// Stations of the bearing (actuator) planes A and B (m): z_A < z_B.
    pub bearing_z_m: [f64; 2],
    /// Stations of the sensor planes A and B (m); equal to the bearings' when collocated.
    pub sensor_z_m: [f64; 2],
}

impl Geometry {
    /// The symmetric two-plane machine equivalent to the study's planar scene (docs/MODEL.md,
    /// issue 17): M = 23 kg, I_t = 0.414 kg m², I_p = 11.62e-3 kg m², 500 Hz rated, bearings and
    /// sensors at ∓0.18 m.
    pub fn symmetric_study() -> Self {
        Self {
            mass_kg: 23.0,
            transverse_inertia_kg_m2: 0.414,
            polar_inertia_kg_m2: 11.62e-3,
            rated_speed_rad_s: std::f64::consts::TAU * 500.0,
            bearing_z_m: [-0.18, 0.18],
            sensor_z_m: [-0.18, 0.18],
        }
    }
}

/// Everything a law of the whole rotor is built from: one [`Design`] per bearing plane and,
/// for a two-plane rotor, its [`Geometry`]. A per-plane law runs on it as one law per plane
/// (each built from its plane's design); a law of all axes at once (`modal`) reads it whole.
///
/// ```
/// use controller::{Design, Geometry, RotorDesign};
/// let planar = RotorDesign::Planar(Design::study());
/// assert_eq!((planar.axes(), planar.planes().len()), (2, 1));
/// assert!(planar.geometry().is_none());
///
/// let two = RotorDesign::symmetric_study();
/// assert_eq!((two.axes(), two.planes().len()), (4, 2));
/// // Each plane carries its share of the 23 kg rotor.
/// assert_eq!(two.planes()[1].constants.rotor_mass_kg, 11.5);
/// assert_eq!(two.geometry().unwrap().mass_kg, 23.0);
/// assert_eq!(two.current_limits(), [2.0; 4]);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "rotor", rename_all = "snake_case")]
pub enum RotorDesign {
    /// The planar model (2 axes: x, y): one bearing plane's share of a symmetric machine.
    Planar(Design),
    /// A two-plane rotor (4 axes: x_A, y_A, x_B, y_B).
    TwoPlane {
        /// Plane A's and plane B's designs. They share the sampling period, the delay, the
        /// gravity bias switch and gravity (the hello carries them once; [`RotorDesign::check`]).
        planes: [Design; 2],
        /// The rotor's geometry.
        geometry: Geometry,
    },
}

impl RotorDesign {
    /// The study's symmetric two-plane machine: [`Design::study`] at each plane (k_e = 10⁶ N/m
    /// per bearing, 11.5 kg each) and [`Geometry::symmetric_study`].
    pub fn symmetric_study() -> Self {
        RotorDesign::TwoPlane { planes: [Design::study(); 2], geometry: Geometry::symmetric_study() }
    }

    /// The number of controlled axes: 2 or 4.
    pub fn axes(&self) -> u32 {
        2 * self.planes().len() as u32
    }

    /// The bearing planes' designs: A, then B on a two-plane rotor.
    pub fn planes(&self) -> &[Design] {
        match self {
            RotorDesign::Planar(d) => std::slice::from_ref(d),
            RotorDesign::TwoPlane { planes, .. } => planes,
        }
    }

    /// The rotor's geometry (two-plane rotors only).
    pub fn geometry(&self) -> Option<&Geometry> {
        match self {
            RotorDesign::Planar(_) => None,
            RotorDesign::TwoPlane { geometry, .. } => Some(geometry),
        }
    }

    /// Plane A's design (the planar design of a planar rotor).
    pub fn plane_a(&self) -> &Design {
        &self.planes()[0]
    }

    /// Each axis's current limit (A), in axis order; axes past [`RotorDesign::axes`] repeat
    /// plane A's (they are never used).
    pub fn current_limits(&self) -> [f64; ROTOR_AXES] {
        let p = self.planes();
        let b = p.get(1).unwrap_or(&p[0]);
        [p[0].current_limit_a, p[0].current_limit_a, b.current_limit_a, b.current_limit_a]
    }

    /// Checks what a two-plane design must hold for every law: the planes share the period,
    /// the delay, the gravity bias switch and gravity; the bearing stations are finite and
    /// distinct (z_A < z_B). What a particular law needs beyond this (inertias, distinct sensor
    /// stations) it checks itself. The keys named are the hello's fields.
    pub fn check(&self) -> Result<(), LawError> {
        let RotorDesign::TwoPlane { planes: [a, b], geometry: g } = self else { return Ok(()) };
        let design = |key, value, unit, why| LawError::Design { key, value, unit, why };
        if a.period_s.to_bits() != b.period_s.to_bits() || a.delay_samples != b.delay_samples {
            return Err(design("plane B period_s", b.period_s, "s", "the planes share the period and the delay"));
        }
        if a.gravity_bias != b.gravity_bias || a.constants.gravity_m_s2.to_bits() != b.constants.gravity_m_s2.to_bits()
        {
            return Err(design(
                "plane B gravity_m_s2",
                b.constants.gravity_m_s2,
                "m/s²",
                "the planes share gravity and the gravity bias switch",
            ));
        }
        let [za, zb] = g.bearing_z_m;
        if !(za.is_finite() && zb.is_finite() && za < zb) {
            return Err(design("Hello.bearing_b_z_m", zb, "m", "must be finite and beyond bearing_a_z_m (z_A < z_B)"));
        }
        Ok(())
    }
}

impl From<Design> for RotorDesign {
    fn from(d: Design) -> Self {
        RotorDesign::Planar(d)
    }
}
