//! The flexible shaft on two bearing planes (`rotor.model = "flexible"`).

use super::RotorParams;
use crate::config::raw::RawScene;
use crate::config::RotorModel;
use crate::machine::{mid_span_weight, FailureState, FlexibleLinear, Linearised, Machine};
use crate::model::Params;
use plant_physics::flex::linear::OpenLoop;
use plant_physics::flex::machine::{self as flexible, Model, N};
use plant_physics::flex::ross::UsedBearing;
use plant_physics::flex::ross_amb::UsedAmb;
use plant_physics::two_plane;

/// Cutoff when none is given (Hz).
pub(in crate::config) const CUTOFF_HZ: f64 = 2000.0;
/// Modal damping ratio when none is given.
pub(in crate::config) const MODAL_DAMPING: f64 = 0.005;

impl RotorParams for flexible::Params {
    fn model(&self) -> RotorModel {
        RotorModel::Flexible
    }

    fn planes(&self) -> usize {
        self.machine.planes.len()
    }

    fn plane(&self, i: usize) -> &Params {
        &self.machine.planes[i].params
    }

    fn plane_mut(&mut self, i: usize) -> &mut Params {
        &mut self.machine.planes[i].params
    }

    fn atol(&self, groups: [f64; 4]) -> Vec<f64> {
        Model::atol(groups).to_vec()
    }

    fn failure(&self, t: f64, y: &[f64]) -> Option<FailureState> {
        Some(Model::failure(t, y.get(..N)?.try_into().ok()?))
    }

    fn record_defaults(&self, raw: &mut RawScene) {
        record_flexible(raw, self);
    }

    /// The rigid body of the shaft, its AMBs and sensors at their nodes.
    fn rigid_body(&self) -> Option<&two_plane::Params> {
        Some(&self.machine)
    }

    fn non_collocated_plane(&self) -> Option<usize> {
        self.nodes.iter().position(|n| n.sensor != n.amb)
    }

    fn mid_span_weight(&self) -> Option<f64> {
        Some(mid_span_weight(self))
    }

    fn linearised(&self, gains: &[controller::PdGains]) -> Option<Box<dyn Linearised>> {
        Some(Box::new(FlexibleLinear::new(self, gains)))
    }

    fn file_bearings(&self) -> &[UsedBearing] {
        &self.file_bearings
    }

    fn file_ambs(&self) -> &[UsedAmb] {
        &self.file_ambs
    }

    fn open_loop(&self) -> Option<OpenLoop> {
        Some(OpenLoop::of(self))
    }
}

/// Writes the flexible rotor's defaults into the raw scene, and the mass and polar inertia its
/// shaft has (what the scene's `mass_kg` and `polar_inertia_kg_m2` are replaced by), so that the
/// resolved `scene.toml` states them.
fn record_flexible(raw: &mut RawScene, params: &flexible::Params) {
    let r = &mut raw.rotor;
    r.mass_kg = params.machine.rotor.mass;
    r.polar_inertia_kg_m2 = params.machine.rotor.polar_inertia;
    r.sensor_a_node.get_or_insert(params.nodes[0].sensor);
    r.sensor_b_node.get_or_insert(params.nodes[1].sensor);
    r.touchdown_a_node.get_or_insert(params.nodes[0].touchdown);
    r.touchdown_b_node.get_or_insert(params.nodes[1].touchdown);
    r.cutoff_hz.get_or_insert(CUTOFF_HZ);
    r.modal_damping.get_or_insert(MODAL_DAMPING);
}
