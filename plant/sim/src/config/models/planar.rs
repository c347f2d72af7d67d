//! The planar model (`rotor.model = "planar"`): one bearing plane, the study's. It has no
//! `[rotor]` keys of its own: its bearing is the shared tables' (`[touchdown]`, `[contact]`,
//! `[amb]`), its rotor the shared `[rotor]` keys.

use super::{Build, BuildContext, RotorModel, RotorParams};
use crate::config::scene_table::scene_table;
use crate::config::ConfigError;
use crate::model::Params;
use serde::{Deserialize, Serialize};

scene_table! {
/// `[rotor]`'s own keys of the planar model: none (a key of another model is refused).
pub struct PlanarKeys {}
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
}

/// The planar model: its one bearing plane from the shared tables; a two-plane rotor's per-plane
/// tables and initial slopes are refused by name (each would be ignored otherwise).
impl Build for PlanarKeys {
    type Params = Params;

    fn build(&self, ctx: &dyn BuildContext) -> Result<Params, ConfigError> {
        ctx.single_plane(ctx.whole())
    }
}
