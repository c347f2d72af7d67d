//! `[rotor]` as a tagged enum (issue 41 item 2): each model's key struct refuses the other
//! models' keys, naming both models; an unknown key lists the model's keys; every shipped scene
//! loads and writes its `[rotor]` back.

use super::models::RawRotor;
use super::{load_scene, parse_raw, RawScene, RotorModel};
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
                let format = toml::Value::Table(table.clone()).try_into::<RawScene>();
                let format = format.expect_err(key).to_string();
                let e = parse_raw(table, "test").expect_err(key).to_string();
                // The unit the key's name ends with.
                let unit = match key.rsplit('_').next() {
                    Some("mm") => " mm",
                    Some("hz") => " Hz",
                    Some("urad") => " µrad",
                    Some("deg") => " deg",
                    Some("m2") => " kg·m²",
                    _ => "",
                };
                for message in [&e, &format] {
                    assert!(
                        message.contains(&format!("rotor.{key} = 1{unit}: is a key of {}", owner.what())),
                        "{message}"
                    );
                    assert!(message.contains(&format!("(rotor.model = \"{}\")", owner.name())), "{message}");
                    assert!(message.contains(&format!("this scene's rotor is {}", held.is())), "{message}");
                    assert!(message.contains(&format!("(rotor.model = \"{}\")", held.name())), "{message}");
                }
                assert!(e.starts_with(&format!("rotor.{key} = 1{unit}: ")), "{e}");
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
        let file: toml::Table =
            toml::from_str(&shock_table::input::read_text(&path, shock_table::input::MAX_TOML_BYTES).unwrap()).unwrap();
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
