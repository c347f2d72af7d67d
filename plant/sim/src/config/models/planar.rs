//! The planar model (`rotor.model = "planar"`): one bearing plane, the study's. It has no
//! `[rotor]` keys of its own: its bearing is the shared tables' (`[touchdown]`, `[contact]`,
//! `[amb]`), its rotor the shared `[rotor]` keys.

use super::{ModelKeys, RotorParams};
use crate::config::raw::{scene_table, RawScene};
use crate::config::validate::bearing::{bearing, Keys, Share};
use crate::config::validate::two_plane_keys::refuse_plane_tables;
use crate::config::{ConfigError, RotorModel};
use crate::machine::{FailureState, Machine};
use crate::model::{Model, Params, N};
use serde::{Deserialize, Serialize};
use std::path::Path;

scene_table! {
/// `[rotor]`'s own keys of the planar model: none (a key of another model is refused).
pub struct PlanarKeys {}
}

impl ModelKeys for PlanarKeys {
    type Params = Params;

    /// The one bearing plane, from the shared tables; a two-plane rotor's per-plane tables and
    /// initial slopes are refused by name (each would be ignored otherwise).
    fn build(&self, raw: &RawScene, whole: &Share, _base_dir: &Path) -> Result<Params, ConfigError> {
        refuse_plane_tables(raw)?;
        bearing(&raw.touchdown, &raw.contact, &raw.amb, &raw.controller, &Keys { plane: None }, whole)
    }
}

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
