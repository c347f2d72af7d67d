//! The rigid rotor on two bearing planes (`rotor.model = "two_plane"`).

use super::RotorParams;
use crate::config::raw::RawScene;
use crate::config::RotorModel;
use crate::machine::{FailureState, Linearised, Machine};
use crate::model::Params;
use plant_physics::two_plane::{self, Model, N};

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

    fn atol(&self, groups: [f64; 4]) -> Vec<f64> {
        Model::atol(groups).to_vec()
    }

    fn failure(&self, t: f64, y: &[f64]) -> Option<FailureState> {
        Some(Model::failure(t, y.get(..N)?.try_into().ok()?))
    }

    fn record_defaults(&self, raw: &mut RawScene) {
        record_two_plane(raw);
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

/// Writes the two-plane rotor's defaults into the raw scene (as the user would have written
/// them, in the file's units), so that the resolved `scene.toml` states them.
fn record_two_plane(raw: &mut RawScene) {
    let r = &mut raw.rotor;
    r.transverse_inertia_kg_m2.get_or_insert(0.414);
    r.couple_unbalance_urad.get_or_insert(0.0);
    r.couple_unbalance_phase_deg.get_or_insert(0.0);
    let a = *r.bearing_a_mm.get_or_insert(-180.0);
    let b = *r.bearing_b_mm.get_or_insert(180.0);
    r.sensor_a_mm.get_or_insert(a);
    r.sensor_b_mm.get_or_insert(b);
    r.end_a_mm.get_or_insert(-230.0);
    r.end_b_mm.get_or_insert(230.0);
}
