//! The planar model (`rotor.model = "planar"`): one bearing plane, the study's. It has no
//! `[rotor]` keys of its own: its bearing is the shared tables' (`[touchdown]`, `[contact]`,
//! `[amb]`), its rotor the shared `[rotor]` keys.

use super::{Build, BuildContext, RotorModel, RotorParams};
use crate::config::scene_table::scene_table;
use crate::config::ConfigError;
use crate::machine::mechanics::{rigid, Mechanics, Signal};
use crate::model::Params;
use nalgebra::DMatrix;
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

    /// `m ẍ = k_i i_x + k_s x`, the same in y.
    fn mechanics(&self, _omega: f64) -> Mechanics {
        let lc = &self.loop_constants;
        let mass = DMatrix::from_diagonal_element(2, 2, self.rotor_mass);
        let gyro = DMatrix::zeros(2, 2);
        let ident = DMatrix::identity(2, 2);
        let states = ["x", "y"]
            .iter()
            .map(|a| Signal::new(*a, "m", format!("rotor {a}, relative to the housing")))
            .chain(["x", "y"].iter().map(|a| Signal::new(format!("v{a}"), "m/s", format!("rotor {a} velocity"))))
            .collect();
        let what = "planar rotor: mass, AMB negative stiffness k_s and current gain k_i".to_string();
        rigid(&mass, &gyro, &ident, &ident, [lc.ks_n_per_m; 4], [lc.ki_n_per_a; 4], states, what)
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
