//! The planar model (`rotor.model = "planar"`): one bearing plane, the study's.

use super::RotorParams;
use crate::config::RotorModel;
use crate::machine::{FailureState, Machine};
use crate::model::{Model, Params, N};

impl RotorParams for Params {
    fn model(&self) -> RotorModel {
        RotorModel::Planar
    }

    fn planes(&self) -> usize {
        1
    }

    fn plane(&self, i: usize) -> &Params {
        assert_eq!(i, 0, "the planar rotor has one bearing plane");
        self
    }

    fn plane_mut(&mut self, i: usize) -> &mut Params {
        assert_eq!(i, 0, "the planar rotor has one bearing plane");
        self
    }

    fn atol(&self, groups: [f64; 4]) -> Vec<f64> {
        Model::atol(groups).to_vec()
    }

    fn failure(&self, t: f64, y: &[f64]) -> Option<FailureState> {
        Some(Model::failure(t, y.get(..N)?.try_into().ok()?))
    }
}
