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
use crate::config::raw::RotorShared;
use crate::config::ConfigError;
use serde::{de::Error as _, Deserialize, Deserializer, Serialize, Serializer};
use std::sync::OnceLock;

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
            let value = match value {
                toml::Value::Table(_) => "a table".to_string(),
                v => v.to_string(),
            };
            Some(ConfigError::Range {
                key: format!("rotor.{key}"),
                value,
                unit: String::new(),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{load_scene, parse_raw};
    use std::path::Path;

    /// A scene whose `[rotor]` holds `model` and `key = 1`.
    fn with_key(model: RotorModel, key: &str) -> toml::Table {
        let text = format!("[rotor]\nmodel = \"{}\"\n{key} = 1\n", model.name());
        toml::from_str(&text).unwrap()
    }

    /// Every model's key struct refuses every key of every other model that is not its own (the
    /// pairs from the key structs' lists, not written here), by name: the key, its value, the
    /// model that has it and the model the scene holds; the file format's own error says so too.
    #[test]
    fn every_models_key_struct_refuses_every_other_models_keys() {
        let mut pairs = 0;
        for held in RotorModel::ALL {
            for owner in RotorModel::ALL.iter().filter(|m| *m != held) {
                for key in owner.own_keys().iter().filter(|k| !RawRotor::keys_of(*held).contains(k)) {
                    let table = with_key(*held, key);
                    let format = toml::Value::Table(table.clone()).try_into::<crate::config::RawScene>();
                    let format = format.expect_err(key).to_string();
                    let e = parse_raw(table, "test").expect_err(key).to_string();
                    for message in [&e, &format] {
                        assert!(
                            message.contains(&format!("rotor.{key} = 1: is a key of {}", owner.what())),
                            "{message}"
                        );
                        assert!(message.contains(&format!("(rotor.model = \"{}\")", owner.name())), "{message}");
                        assert!(message.contains(&format!("this scene's rotor is {}", held.is())), "{message}");
                        assert!(message.contains(&format!("(rotor.model = \"{}\")", held.name())), "{message}");
                    }
                    assert!(e.starts_with(&format!("rotor.{key} = 1: ")), "{e}");
                    pairs += 1;
                }
            }
        }
        // The two-plane rotor's 9 keys in the planar and the flexible scenes, the flexible
        // rotor's 13 in the planar and the two-plane ones.
        assert_eq!(pairs, 2 * 9 + 2 * 13);
    }

    /// A key no model has is refused as unknown, listing every key a scene of its model may
    /// write: `model`, the shared keys and the model's own; `model` absent is the planar model.
    #[test]
    fn an_unknown_key_is_refused_with_the_keys_of_the_scenes_model() {
        for model in RotorModel::ALL {
            let e = parse_raw(with_key(*model, "bogus"), "test").unwrap_err().to_string();
            assert!(e.contains("unknown field `bogus`, expected one of `model`, `mass_kg`"), "{e}");
            let last = RawRotor::keys_of(*model).last().unwrap();
            assert!(e.contains(&format!("`{last}`")), "{model:?}: {e}");
        }
        let e = parse_raw(toml::from_str("[rotor]\nmodel = \"rigid\"\n").unwrap(), "t").unwrap_err().to_string();
        assert!(e.contains("unknown variant `rigid`, expected one of `planar`, `two_plane`, `flexible`"), "{e}");
        let absent = parse_raw(toml::from_str("[rotor]\nmass_kg = 3.0\n").unwrap(), "t").unwrap();
        assert_eq!((absent.rotor.model.model(), absent.rotor.mass_kg), (RotorModel::Planar, 3.0));
    }

    /// Every shipped scene (`config/*.toml`) loads, holds the model its file names, and its
    /// resolved scene states every `[rotor]` key the file wrote (the rotor's table is read and
    /// written back whole) and reads back into the same resolved scene.
    #[test]
    fn every_shipped_scene_loads_and_writes_back_its_rotor_keys() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../config");
        let mut scenes: Vec<_> = std::fs::read_dir(&dir).unwrap().flatten().map(|e| e.path()).collect();
        scenes.retain(|p| p.extension().is_some_and(|e| e == "toml"));
        scenes.sort();
        assert!(scenes.len() >= 14, "{scenes:?}");
        for path in scenes {
            let scene = load_scene(&path, &[]).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let file: toml::Table = toml::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
            let written = file.get("rotor").and_then(toml::Value::as_table).cloned().unwrap_or_default();
            let model = written.get("model").and_then(toml::Value::as_str).unwrap_or("planar");
            assert_eq!(scene.rotor.model().name(), model, "{}", path.display());
            let text = scene.to_toml().unwrap();
            let resolved: toml::Table = toml::from_str(&text).unwrap();
            let rotor = resolved["rotor"].as_table().unwrap();
            for key in written.keys() {
                assert!(rotor.contains_key(key), "{}: rotor.{key} not written back", path.display());
            }
            assert_eq!(scene.resolved().unwrap().rotor.model.model(), scene.rotor.model(), "{}", path.display());
            assert!(text.contains(&format!("[rotor]\nmodel = \"{model}\"\n")), "{}: {text}", path.display());
        }
    }
}
