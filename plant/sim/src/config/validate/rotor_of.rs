//! The scene's rotor built from `[rotor]` by the model `rotor.model` names: one arm per model,
//! each calling its keys' builder (`two_plane_keys.rs`, `flexible_keys.rs`; the planar model's are
//! the shared bearing tables', `bearing.rs`).

use super::bearing::{bearing, Keys, Share};
use super::flexible_keys::{flexible_params, refuse_flexible_keys};
use super::two_plane_keys::{refuse_two_plane_keys, two_plane_params};
use crate::config::raw::RawScene;
use crate::config::{ConfigError, Rotor, RotorModel};
use std::path::Path;

/// The rotor model `rotor.model` names, built from the raw scene (its keys validated, each
/// error naming the key, value and unit): its bearing planes from `[touchdown]`,
/// `[contact]` and `[amb]` with `whole`, the rotor's values from `[rotor]`. The keys of the
/// other models are refused by name. `base_dir` resolves a model's files.
pub(super) fn rotor_from_raw(raw: &RawScene, whole: &Share, base_dir: &Path) -> Result<Rotor, ConfigError> {
    Ok(match raw.rotor.model {
        RotorModel::Planar => {
            refuse_two_plane_keys(raw)?;
            refuse_flexible_keys(raw)?;
            let keys = Keys { plane: None };
            Rotor::Planar(bearing(&raw.touchdown, &raw.contact, &raw.amb, &raw.controller, &keys, whole)?)
        }
        RotorModel::TwoPlane => {
            refuse_flexible_keys(raw)?;
            Rotor::TwoPlane(two_plane_params(raw, whole)?)
        }
        RotorModel::Flexible => Rotor::Flexible(flexible_params(raw, whole, base_dir)?),
    })
}
