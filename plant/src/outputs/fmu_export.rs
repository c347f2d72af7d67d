//! The FMU file of a scene (`plant fmu SCENE --out plant.fmu`, docs/guide/fmu-plant.md): the
//! model the binary answers to ([`plant_sim::fmi`], re-exported here), packed with the binary
//! and the scene's files into the archive.

pub use plant_sim::fmi::*;

use crate::config::Scene;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The file name of the FMU's binary as cargo builds it (`cargo build -p plant-fmu`).
pub const LIBRARY: &str = "libplant_fmu.so";

/// The largest binary [`package`] reads (bytes).
const MAX_LIBRARY_BYTES: u64 = 2 << 30;

/// Where `plant fmu` finds the FMU's binary: `library` if given, else [`LIBRARY`] next to
/// the running executable (where `cargo build -p plant-fmu` puts it beside `plant`).
pub fn find_library(library: Option<&Path>) -> Result<PathBuf, String> {
    if let Some(l) = library {
        return if l.is_file() { Ok(l.to_path_buf()) } else { Err(format!("--library {}: no such file", l.display())) };
    }
    let exe = std::env::current_exe().map_err(|e| format!("cannot locate the plant executable: {e}"))?;
    let dir = exe.parent().unwrap_or(Path::new("."));
    let lib = dir.join(LIBRARY);
    if lib.is_file() {
        Ok(lib)
    } else {
        let profile = if dir.ends_with("release") { " --release" } else { "" };
        Err(format!(
            "the FMU's binary {LIBRARY} is not next to {} (in {}): build it with `cargo build{profile} -p plant-fmu` \
             (or the whole workspace, `cargo build{profile}`), or name it with --library",
            exe.display(),
            dir.display()
        ))
    }
}

/// Writes the FMU of `scene` to `out` (FMI `fmi`): `modelDescription.xml`, `binaries/<platform>/<id>.so`
/// (`library`), `resources/scene.toml` (the scene as resolved; each file it reads, a recorded
/// shock's or `rotor.ross_file`, beside it). Returns the model it describes.
pub fn package(scene: &Scene, library: &Path, out: &Path, fmi: Fmi) -> anyhow::Result<Model> {
    use anyhow::Context;
    let mut raw: toml::Table = toml::from_str(&scene.to_toml()?).context("the resolved scene")?;
    // Each file the scene reads (a recorded shock's, the ROSS machine) goes into resources/ and
    // the scene names it there.
    let mut extra = Vec::new();
    for (keys, file) in files_read(&raw) {
        let bytes = crate::input::read_bytes(Path::new(&file), MAX_FILE_BYTES)
            .with_context(|| format!("{} {file}", keys.join(".")))?;
        let name = match keys[0].as_str() {
            "shock" => format!("shock-{}.csv", keys[1]),
            _ => "rotor-ross.toml".to_string(),
        };
        set_at(&mut raw, &keys, name.clone());
        extra.push((name, bytes));
    }
    let text = toml::to_string(&raw).context("writing the scene")?;
    // The model as the binary will see it: from the scene read back from the text written.
    let dir = std::env::temp_dir().join(format!("plant-fmu-{}-{}", std::process::id(), identifier_of(&scene.name)));
    crate::outfile::folder(&dir)?;
    let staged = (|| -> anyhow::Result<Model> {
        crate::outfile::write(&dir.join("scene.toml"), text.as_bytes())?;
        for (name, bytes) in &extra {
            crate::outfile::write(&dir.join(name), bytes)?;
        }
        let back = load_fmu_scene(&dir, &[]).context("the scene written into the FMU")?;
        Model::of(&back).map_err(|e| anyhow::anyhow!("the scene written into the FMU: {e}"))
    })();
    let _ = std::fs::remove_dir_all(&dir);
    let model = staged?;
    let binary = crate::input::read_bytes(library, MAX_LIBRARY_BYTES)
        .with_context(|| format!("reading the FMU's binary {}", library.display()))?;
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .unix_permissions(0o644);
    let mut add = |name: &str, bytes: &[u8], options: zip::write::SimpleFileOptions| -> anyhow::Result<()> {
        zip.start_file(name, options)?;
        zip.write_all(bytes)?;
        Ok(())
    };
    let description = match fmi {
        Fmi::V2 => model.xml(),
        Fmi::V3 => model.xml3(),
    };
    add("modelDescription.xml", description.as_bytes(), options)?;
    // The binary is stored as it is: compressing a debug build's (over 100 MB) takes a minute.
    let stored = options.compression_method(zip::CompressionMethod::Stored).unix_permissions(0o755);
    add(&format!("binaries/{}/{}.so", fmi.platform(), model.identifier), &binary, stored)?;
    add("resources/scene.toml", text.as_bytes(), options)?;
    for (name, bytes) in &extra {
        add(&format!("resources/{name}"), bytes, options)?;
    }
    let bytes = zip.finish()?.into_inner();
    crate::outfile::write(out, &bytes)?;
    Ok(model)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::load_scene;

    /// The files `names` of the FMU `fmu`'s `resources/` unpacked into the folder `into`.
    fn unpack(fmu: &Path, names: &[&str], into: &Path) -> std::path::PathBuf {
        std::fs::create_dir_all(into).unwrap();
        let mut zip = zip::ZipArchive::new(std::fs::File::open(fmu).unwrap()).unwrap();
        for name in names {
            let mut bytes = Vec::new();
            std::io::Read::read_to_end(&mut zip.by_name(&format!("resources/{name}")).unwrap(), &mut bytes).unwrap();
            std::fs::write(into.join(name), bytes).unwrap();
        }
        into.to_path_buf()
    }

    /// An FMU whose scene reads files (a recorded shock, a ROSS machine) carries them in
    /// `resources/`, and the scene unpacked anywhere makes the GUID written into it (it once
    /// held the staging folder's paths, and every such FMU was refused at instantiation); an
    /// edited file in `resources/` makes another GUID.
    #[test]
    fn an_fmu_with_files_is_the_same_model_wherever_it_is_unpacked() {
        let dir = crate::util::scratch("fmu-files-test");
        let csv: String = std::iter::once("t_s,accel_m_s2\n".to_string())
            .chain((0..50).map(|i| format!("{},{}\n", i as f64 * 1e-4, (i as f64 * 0.1).sin() * 50.0)))
            .collect();
        std::fs::write(dir.join("rec.csv"), &csv).unwrap();
        let mut table: toml::Table =
            std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/cosim-10g.toml"))
                .unwrap()
                .parse()
                .unwrap();
        let mut shock = toml::Table::new();
        shock.insert("kind".into(), "recorded".into());
        shock.insert("file".into(), "rec.csv".into());
        table.insert("shock".into(), toml::Value::Array(vec![toml::Value::Table(shock)]));
        std::fs::write(dir.join("scene.toml"), toml::to_string(&table).unwrap()).unwrap();
        let scene = load_scene(&dir.join("scene.toml"), &[]).unwrap();
        let library = dir.join("lib.so");
        std::fs::write(&library, b"not a library: package only copies it").unwrap();
        let model = package(&scene, &library, &dir.join("x.fmu"), Fmi::V2).unwrap();
        let unpacked = unpack(&dir.join("x.fmu"), &["scene.toml", "shock-0.csv"], &dir.join("unpacked"));
        let back = Model::of(&load_fmu_scene(&unpacked, &[]).unwrap()).unwrap();
        assert_eq!(back.guid, model.guid);
        std::fs::write(unpacked.join("shock-0.csv"), csv.replace(",0\n", ",1\n")).unwrap();
        let edited = Model::of(&load_fmu_scene(&unpacked, &[]).unwrap()).unwrap();
        assert_ne!(edited.guid, model.guid);

        // The flexible scene on a ROSS file: the machine goes in as resources/rotor-ross.toml.
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        std::fs::copy(root.join("plant/physics/tests/fixtures/ross/amb_machine.toml"), dir.join("m.toml")).unwrap();
        let mut table: toml::Table =
            std::fs::read_to_string(root.join("config/flexible-10g.toml")).unwrap().parse().unwrap();
        let rotor = table["rotor"].as_table_mut().unwrap();
        rotor.remove("shaft");
        rotor.insert("ross_file".into(), "m.toml".into());
        rotor.insert("ross_bearings".into(), "ignore".into());
        std::fs::write(dir.join("flex.toml"), toml::to_string(&table).unwrap()).unwrap();
        let model =
            package(&load_scene(&dir.join("flex.toml"), &[]).unwrap(), &library, &dir.join("f.fmu"), Fmi::V2).unwrap();
        let flex = unpack(&dir.join("f.fmu"), &["scene.toml", "rotor-ross.toml"], &dir.join("flex"));
        std::fs::remove_file(dir.join("m.toml")).unwrap();
        let back = Model::of(&load_fmu_scene(&flex, &[]).unwrap()).unwrap();
        assert_eq!(back.guid, model.guid);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
