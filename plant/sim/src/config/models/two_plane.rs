//! The rigid rotor on two bearing planes (`rotor.model = "two_plane"`): its `[rotor]` keys and
//! their defaults, and what the model says of itself.

use super::{RawRotor, RotorKeys, RotorModel, RotorParams};
use crate::config::scene_table::scene_table;
use crate::machine::Linearised;
use crate::model::Params;
use plant_physics::two_plane;
use serde::{Deserialize, Serialize};

/// `transverse_inertia_kg_m2` when none is given (kg·m²).
pub(in crate::config) const TRANSVERSE_INERTIA_KG_M2: f64 = 0.414;
/// `bearing_a_mm` when none is given (mm).
pub(in crate::config) const BEARING_A_MM: f64 = -180.0;
/// `bearing_b_mm` when none is given (mm).
pub(in crate::config) const BEARING_B_MM: f64 = 180.0;
/// `end_a_mm` when none is given (mm).
pub(in crate::config) const END_A_MM: f64 = -230.0;
/// `end_b_mm` when none is given (mm).
pub(in crate::config) const END_B_MM: f64 = 230.0;

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
