//! The rigid rotor on two bearing planes (`rotor.model = "two_plane"`): its `[rotor]` keys and
//! their defaults, and what the model says of itself.

use super::{Build, BuildContext, RawRotor, RotorKeys, RotorModel, RotorParams, Share};
use crate::config::checks::{finite, non_negative, positive, range};
use crate::config::scene_table::scene_table;
use crate::config::ConfigError;
use crate::machine::mechanics::{rigid, Mechanics, Signal};
use crate::machine::Linearised;
use crate::model::Params;
use crate::model::Spin;
use nalgebra::DMatrix;
use plant_physics::two_plane;
use serde::{Deserialize, Serialize};

/// `transverse_inertia_kg_m2` when none is given (kg·m²).
const TRANSVERSE_INERTIA_KG_M2: f64 = 0.414;
/// `bearing_a_mm` when none is given (mm).
const BEARING_A_MM: f64 = -180.0;
/// `bearing_b_mm` when none is given (mm).
const BEARING_B_MM: f64 = 180.0;
/// `end_a_mm` when none is given (mm).
const END_A_MM: f64 = -230.0;
/// `end_b_mm` when none is given (mm).
const END_B_MM: f64 = 230.0;

scene_table! {
/// `[rotor]`'s own keys of the two-plane rotor, each `None` unless given (the resolved scene
/// states the defaults, [`RotorParams::record_defaults`]); the shared `mass_kg`,
/// `polar_inertia_kg_m2` and drive keys are the whole rotor's.
pub struct TwoPlaneKeys {
    /// Transverse moment of inertia I_t about the centre of mass (kg·m²); none: 0.414.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub transverse_inertia_kg_m2: Option<f64> = None,
    /// Couple unbalance, the tilt χ of the principal axis of inertia from the geometric axis
    /// (µrad); none: 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub couple_unbalance_urad: Option<f64> = None,
    /// The rotor-fixed direction of that tilt, from the static unbalance's (deg); none: 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub couple_unbalance_phase_deg: Option<f64> = None,
    /// Axial position of bearing A (AMB and touchdown bearing) from the centre of mass (mm),
    /// < 0; none: −180.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bearing_a_mm: Option<f64> = None,
    /// Axial position of bearing B (mm), > 0; none: 180.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bearing_b_mm: Option<f64> = None,
    /// Axial position of plane A's displacement sensor (mm); none: `bearing_a_mm` (collocated).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sensor_a_mm: Option<f64> = None,
    /// Axial position of plane B's displacement sensor (mm); none: `bearing_b_mm`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sensor_b_mm: Option<f64> = None,
    /// Axial position of the rotor's end on plane A's side (mm); none: −230.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end_a_mm: Option<f64> = None,
    /// Axial position of the rotor's end on plane B's side (mm); none: 230.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end_b_mm: Option<f64> = None,
}
}

impl RotorParams for two_plane::Params {
    fn model(&self) -> RotorModel {
        RotorModel::TwoPlane
    }

    fn planes(&self) -> usize {
        self.planes.len()
    }

    /// `q = (x, y, a, b)` at the centre of mass: `M q̈ + Ω G q̇ = Φ_aᵀ (K_i i + K_s Φ_a q)` with
    /// `M = diag(M, M, I_t, I_t)`, `G`'s `(a, b)` rows `(+I_p ḃ, −I_p ȧ)`, `Φ_a` the axes' rows
    /// at the actuators' stations (`x + z_i a`), the sensors read `Φ_s q` at theirs.
    fn mechanics(&self, omega: f64) -> Mechanics {
        let r = &self.rotor;
        let mass = DMatrix::from_diagonal(&nalgebra::DVector::from_row_slice(&[
            r.mass,
            r.mass,
            r.transverse_inertia,
            r.transverse_inertia,
        ]));
        let mut gyro = DMatrix::zeros(4, 4);
        // I_t ä + I_p Ω ḃ = …,  I_t b̈ − I_p Ω ȧ = …
        gyro[(2, 3)] = r.polar_inertia * omega;
        gyro[(3, 2)] = -r.polar_inertia * omega;
        let rows = |station: &dyn Fn(usize) -> f64| {
            DMatrix::from_fn(4, 4, |k, col| {
                let dir = k % 2;
                if col == dir {
                    1.0
                } else if col == 2 + dir {
                    station(k / 2)
                } else {
                    0.0
                }
            })
        };
        let actuator = rows(&|i| self.planes[i].station);
        let sensor = rows(&|i| self.planes[i].sensor);
        let lc = |k: usize| self.planes[k / 2].params.loop_constants;
        let ks = std::array::from_fn(|k| lc(k).ks_n_per_m);
        let ki = std::array::from_fn(|k| lc(k).ki_n_per_a);
        let q = [
            ("x", "m", "rotor axis x at the centre of mass's station"),
            ("y", "m", "rotor axis y at the centre of mass's station"),
            ("a", "rad", "slope dx/dz of the rotor axis"),
            ("b", "rad", "slope dy/dz of the rotor axis"),
        ];
        let states = q
            .iter()
            .map(|(n, u, d)| Signal::new(*n, u, *d))
            .chain(q.iter().map(|(n, u, d)| Signal::new(format!("{n}dot"), &format!("{u}/s"), format!("rate of {d}"))))
            .collect();
        let what = "rigid two-plane rotor: mass, transverse and polar inertia (gyroscopics at the speed), each \
                    plane's AMB k_s and k_i at its station, its sensor at its own"
            .to_string();
        rigid(&mass, &gyro, &actuator, &sensor, ks, ki, states, what)
    }

    fn plane(&self, i: usize) -> &Params {
        &self.planes[i].params
    }

    fn plane_mut(&mut self, i: usize) -> &mut Params {
        &mut self.planes[i].params
    }

    fn record_defaults(&self, rotor: &mut RawRotor) {
        if let RotorKeys::TwoPlane(keys) = &mut rotor.model {
            record_two_plane(keys);
        }
    }

    fn rigid_body(&self) -> Option<&two_plane::Params> {
        Some(self)
    }

    fn non_collocated_plane(&self) -> Option<usize> {
        self.planes.iter().position(|p| p.sensor != p.station)
    }

    fn linearised(&self, gains: &[controller::PdGains]) -> Option<Box<dyn Linearised>> {
        Some(Box::new(two_plane::linear::LinearRotor::from_gains(self, &[gains[0], gains[1]])))
    }
}

/// Writes the two-plane rotor's defaults into its keys (as the user would have written them, in
/// the file's units), so that the resolved `scene.toml` states them.
fn record_two_plane(r: &mut TwoPlaneKeys) {
    r.transverse_inertia_kg_m2.get_or_insert(TRANSVERSE_INERTIA_KG_M2);
    r.couple_unbalance_urad.get_or_insert(0.0);
    r.couple_unbalance_phase_deg.get_or_insert(0.0);
    let a = *r.bearing_a_mm.get_or_insert(BEARING_A_MM);
    let b = *r.bearing_b_mm.get_or_insert(BEARING_B_MM);
    r.sensor_a_mm.get_or_insert(a);
    r.sensor_b_mm.get_or_insert(b);
    r.end_a_mm.get_or_insert(END_A_MM);
    r.end_b_mm.get_or_insert(END_B_MM);
}

impl Build for TwoPlaneKeys {
    type Params = two_plane::Params;

    fn build(&self, ctx: &dyn BuildContext) -> Result<two_plane::Params, ConfigError> {
        two_plane_params(ctx, self, ctx.whole())
    }
}

/// The two-plane rotor of a scene (`rotor.model = "two_plane"`), validated: its geometry and
/// inertia from `[rotor]`, each plane's bearing from the shared tables and its own.
pub(in crate::config) fn two_plane_params(
    ctx: &dyn BuildContext,
    r: &TwoPlaneKeys,
    whole: &Share,
) -> Result<two_plane::Params, ConfigError> {
    let mm = |key: &str, value: f64| finite(key, value, "mm");
    let za = mm("rotor.bearing_a_mm", r.bearing_a_mm.unwrap_or(BEARING_A_MM))?;
    let zb = mm("rotor.bearing_b_mm", r.bearing_b_mm.unwrap_or(BEARING_B_MM))?;
    const SIDES: &str = "bearing A lies on the −z side of the centre of mass (the origin of z) and bearing B on \
                         the +z side: the centre of mass is between the bearings";
    if za >= 0.0 {
        return Err(range("rotor.bearing_a_mm", za, "mm", &format!("must be < 0: {SIDES}")));
    }
    if zb <= 0.0 {
        return Err(range("rotor.bearing_b_mm", zb, "mm", &format!("must be > 0: {SIDES}")));
    }
    let ea = mm("rotor.end_a_mm", r.end_a_mm.unwrap_or(END_A_MM))?;
    let eb = mm("rotor.end_b_mm", r.end_b_mm.unwrap_or(END_B_MM))?;
    if ea > za {
        return Err(range(
            "rotor.end_a_mm",
            ea,
            "mm",
            &format!("must be <= rotor.bearing_a_mm = {za} mm: the bearing sits on the rotor"),
        ));
    }
    if eb < zb {
        return Err(range(
            "rotor.end_b_mm",
            eb,
            "mm",
            &format!("must be >= rotor.bearing_b_mm = {zb} mm: the bearing sits on the rotor"),
        ));
    }
    let sensor = |key: &str, value: f64| -> Result<f64, ConfigError> {
        let v = mm(key, value)?;
        if !(ea..=eb).contains(&v) {
            return Err(range(
                key,
                v,
                "mm",
                &format!("must lie on the rotor, between rotor.end_a_mm = {ea} mm and rotor.end_b_mm = {eb} mm"),
            ));
        }
        Ok(v)
    };
    let sa = sensor("rotor.sensor_a_mm", r.sensor_a_mm.unwrap_or(za))?;
    let sb = sensor("rotor.sensor_b_mm", r.sensor_b_mm.unwrap_or(zb))?;
    let transverse = positive(
        "rotor.transverse_inertia_kg_m2",
        r.transverse_inertia_kg_m2.unwrap_or(TRANSVERSE_INERTIA_KG_M2),
        "kg·m²",
    )?;
    let couple = non_negative("rotor.couple_unbalance_urad", r.couple_unbalance_urad.unwrap_or(0.0), "µrad")? * 1e-6;
    let couple_phase =
        finite("rotor.couple_unbalance_phase_deg", r.couple_unbalance_phase_deg.unwrap_or(0.0), "deg")?.to_radians();
    let stations = [za * 1e-3, zb * 1e-3];
    let sensors = [sa * 1e-3, sb * 1e-3];
    let plane = |i: usize| -> Result<two_plane::Plane, ConfigError> {
        let mass = two_plane::load_share(whole.mass, stations, i);
        let fraction = mass / whole.mass;
        let spin = match whole.spin {
            Spin::Held => Spin::Held,
            Spin::Free { drive_gain, torque_limit } => {
                Spin::Free { drive_gain: drive_gain * fraction, torque_limit: torque_limit * fraction }
            }
        };
        let share = Share { mass, inertia: whole.inertia * fraction, spin, ..*whole };
        let params = ctx.plane(i, &share)?;
        Ok(two_plane::Plane { station: stations[i], sensor: sensors[i], params })
    };
    Ok(two_plane::Params {
        gravity: whole.gravity,
        rotor: two_plane::Rotor {
            mass: whole.mass,
            transverse_inertia: transverse,
            polar_inertia: whole.inertia,
            eccentricity: whole.eccentricity,
            couple,
            couple_phase,
            speed: whole.speed,
            spin: whole.spin,
        },
        planes: [plane(0)?, plane(1)?],
    })
}
