//! `[rotor]` as written: the keys every model reads ([`RotorShared`]) and the model's own, the
//! tagged enum [`RotorKeys`] on `model` (`planar` when absent), whose key struct refuses every
//! key that is not its model's.
//!
//! Read and written by hand rather than derived, because serde cannot do either as the file
//! is: an internally tagged enum has no default for a missing tag, and `flatten` (the shared
//! keys beside the model's) turns `deny_unknown_fields` off. So the table is split by the key
//! lists: the shared keys to [`RotorShared`], the rest to the model's key struct, which refuses
//! what is not its own; a refused key that another model has is worded from the same lists
//! ([`RawRotor::foreign_key`]): no model writes another's keys out by hand.

use super::{RotorKeys, RotorModel};
use crate::config::scene_table::scene_table;
use crate::config::ConfigError;
use serde::{de::Error as _, Deserialize, Deserializer, Serialize, Serializer};
use std::sync::OnceLock;

scene_table! {
/// `[rotor]`'s keys that every model reads (the `model` key and each model's own keys are the
/// model's key struct's, `config/models/<model>.rs`; [`RawRotor`] is the whole table).
///
/// The planar model has one bearing plane, the study's: `mass_kg` and `polar_inertia_kg_m2` are
/// the share one bearing carries; the two-plane rotor is the whole rotor on two bearings with its
/// tilt: they are the whole rotor's (the study's symmetric machine has 23 kg and
/// 11.62e-3 kg·m², docs/MODEL.md §10.1).
pub struct RotorShared {
    /// m_r (kg); two-plane: the whole rotor's mass M.
    pub mass_kg: f64 = 11.5,
    /// e (µm): the centre of mass's offset from the geometric axis (static unbalance).
    pub eccentricity_um: f64 = 2.0,
    /// J_r (kg·m²); two-plane: the whole rotor's I_p.
    pub polar_inertia_kg_m2: f64 = 5.81e-3,
    /// r_r (mm).
    pub radius_mm: f64 = 19.85,
    /// Rated speed (Hz).
    pub speed_hz: f64 = 500.0,
    /// Angle of the unbalance at t = 0 (deg).
    pub unbalance_phase_deg: f64 = 0.0,
    /// `held` or `free`.
    pub spin: SpinChoice = SpinChoice::Held,
    /// Speed-loop gain for `free` spin (N·m·s/rad); two-plane: on the whole rotor.
    pub drive_gain_n_m_s: f64 = 0.05,
    /// Drive torque limit for `free` spin (N·m); two-plane: on the whole rotor.
    pub drive_torque_limit_n_m: f64 = 2.0,
}
}

/// `rotor.spin`: how the rotor's speed is driven.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpinChoice {
    /// The drive holds the speed exactly.
    Held,
    /// A speed loop with a gain and a torque limit drives it.
    Free,
}

/// `[rotor]` as written.
#[derive(Clone, Debug, Default)]
pub struct RawRotor {
    /// `model` and the model's own keys.
    pub model: RotorKeys,
    /// The keys every model reads.
    pub shared: RotorShared,
}

/// `raw.rotor.speed_hz` reads a shared key as the file writes it, whichever the model.
impl std::ops::Deref for RawRotor {
    type Target = RotorShared;

    fn deref(&self) -> &RotorShared {
        &self.shared
    }
}

impl std::ops::DerefMut for RawRotor {
    fn deref_mut(&mut self) -> &mut RotorShared {
        &mut self.shared
    }
}

impl RawRotor {
    /// Every key `[rotor]` may hold, whichever the model: `model`, the shared keys, each model's
    /// own (the guide's key table lists them all).
    pub fn keys() -> &'static [&'static str] {
        static KEYS: OnceLock<Vec<&'static str>> = OnceLock::new();
        KEYS.get_or_init(|| {
            let own = RotorModel::ALL.iter().flat_map(|m| m.own_keys());
            let mut keys: Vec<&'static str> = ["model"].iter().chain(RotorShared::KEYS).chain(own).copied().collect();
            let mut seen = std::collections::HashSet::new();
            keys.retain(|k| seen.insert(*k));
            keys
        })
    }

    /// The keys a scene holding `model` may write: `model`, the shared keys, the model's own.
    pub fn keys_of(model: RotorModel) -> &'static [&'static str] {
        static KEYS: OnceLock<Vec<Vec<&'static str>>> = OnceLock::new();
        let lists = KEYS.get_or_init(|| {
            let of = |m: &RotorModel| ["model"].iter().chain(RotorShared::KEYS).chain(m.own_keys()).copied().collect();
            RotorModel::ALL.iter().map(of).collect()
        });
        let i = RotorModel::ALL.iter().position(|m| *m == model).unwrap_or_default();
        &lists[i]
    }

    /// The first key of `rotor` (a `[rotor]` table as written) that the scene's model does not
    /// have and another model does, refused naming the key, its value, the model that has it and
    /// the scene's; `None` when there is none (or `model` is not a model's name: that is
    /// refused as a bad value).
    pub fn foreign_key(rotor: &toml::Table) -> Option<ConfigError> {
        let held = match rotor.get("model") {
            None => RotorModel::default(),
            Some(v) => v.clone().try_into::<RotorModel>().ok()?,
        };
        let ours = Self::keys_of(held);
        rotor.iter().filter(|(k, _)| !ours.contains(&k.as_str())).find_map(|(key, value)| {
            let owner = RotorModel::ALL.iter().find(|m| m.own_keys().contains(&key.as_str()))?;
            let (value, unit) = match value {
                toml::Value::Table(_) => ("a table".to_string(), String::new()),
                v => (v.to_string(), unit_of(key).map_or(String::new(), |u| format!(" {u}"))),
            };
            Some(ConfigError::Range {
                key: format!("rotor.{key}"),
                value,
                unit,
                why: format!(
                    "is a key of {} (rotor.model = \"{}\") and this scene's rotor is {} (rotor.model = \"{}\"): set \
                     rotor.model = \"{}\" or remove the key",
                    owner.what(),
                    owner.name(),
                    held.is(),
                    held.name(),
                    owner.name()
                ),
            })
        })
    }
}

/// The unit a `[rotor]` key's name ends with (the scene format writes units in the key names), as
/// a message writes it; `None` for a key without one (a node, a ratio, a choice). Read from the
/// name because the key structs' fields carry no unit of their own.
fn unit_of(key: &str) -> Option<&'static str> {
    const SUFFIXES: [(&str, &str); 9] = [
        ("_kg_m2", "kg·m²"),
        ("_kg", "kg"),
        ("_mm", "mm"),
        ("_um", "µm"),
        ("_urad", "µrad"),
        ("_deg", "deg"),
        ("_hz", "Hz"),
        ("_n_m_s", "N·m·s/rad"),
        ("_n_m", "N·m"),
    ];
    SUFFIXES.iter().find(|(suffix, _)| key.ends_with(suffix)).map(|(_, unit)| *unit)
}

/// The file's order: `model`, the shared keys, the model's own (those it has).
impl Serialize for RawRotor {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct Written<'a> {
            model: RotorModel,
            #[serde(flatten)]
            shared: &'a RotorShared,
            #[serde(flatten)]
            keys: &'a RotorKeys,
        }
        Written { model: self.model.model(), shared: &self.shared, keys: &self.model }.serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for RawRotor {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        /// `model` alone, read as serde reads a tag (its error names the key and the models).
        #[derive(Deserialize)]
        struct Tag {
            #[serde(default)]
            model: RotorModel,
        }
        let mut table = toml::Table::deserialize(deserializer)?;
        let tag = toml::Table::from_iter(table.remove("model").map(|m| ("model".to_string(), m)));
        let model = toml::Value::Table(tag).try_into::<Tag>().map_err(D::Error::custom)?.model;
        let (shared, own): (toml::Table, toml::Table) =
            table.into_iter().partition(|(k, _)| RotorShared::KEYS.contains(&k.as_str()));
        let shared = toml::Value::Table(shared).try_into::<RotorShared>().map_err(D::Error::custom)?;
        let keys = RotorKeys::from_table(model, own.clone()).map_err(|e| {
            // The key struct refused: a key that is not the model's is named with the keys a
            // scene of the model may write (all of them, not the key struct's alone).
            let ours = RawRotor::keys_of(model);
            let mut with_model = own.clone();
            with_model.insert("model".into(), toml::Value::String(model.name().into()));
            match (RawRotor::foreign_key(&with_model), own.keys().find(|k| !ours.contains(&k.as_str()))) {
                (Some(foreign), _) => D::Error::custom(foreign),
                (None, Some(unknown)) => D::Error::unknown_field(unknown, ours),
                (None, None) => D::Error::custom(e),
            }
        })?;
        Ok(RawRotor { model: keys, shared })
    }
}
