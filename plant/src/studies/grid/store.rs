//! The files of a sweep or ensemble folder and how they are checked.
//!
//! * `manifest.json`: what the folder is for: the program (`plant 0.1.0`), the kind, the sweep
//!   or ensemble definition, the resolved scene (TOML text, `set` overrides applied) and the
//!   ensemble, in clear, and the SHA-256 of all of it (`hash`). Written when a run starts; a
//!   changed manifest is reported part by part on a resume.
//! * `points/NNNNN.json` (a single run) or `points/NNNNN/MMMMM.json` (member MMMMM of point
//!   NNNNN): `{"key": …, "checksum": …, "result": {…}}`. The key is the SHA-256 of the program
//!   version, the unit's indices and the unit's resolved scene (with its draws and integrator
//!   overrides; the verification setting for members), so it changes with anything that
//!   changes the unit's result. The checksum is the SHA-256 of the `result` text as written.
//!
//! On a resume or a merge every file present is read and checked: unreadable or truncated
//! JSON, a checksum that does not match (edited by hand, damaged) or indices that differ from
//! the file's name are **corrupt**; a key that differs from the one this sweep computes is a
//! **mismatch** (made for another scene, definition, draw or program version). Neither is ever
//! used, and neither is re-run silently: a run refuses them with exit 2 unless
//! `--rerun-mismatched` is given (they are named and re-run), `--merge` lists the corrupt with
//! the missing and exits 7.

use crate::config::Scene;
use anyhow::Context;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// The program version written into manifests and unit keys.
pub const PROGRAM: &str = concat!("plant ", env!("CARGO_PKG_VERSION"));

/// SHA-256 as lowercase hex.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect()
}

/// A unit of work: a point (single runs) or one member of a point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Unit {
    /// Point index.
    pub point: usize,
    /// Member index (ensembles).
    pub member: Option<usize>,
}

impl Unit {
    /// The unit's file.
    pub fn path(&self, dir: &Path) -> PathBuf {
        let points = dir.join("points");
        match self.member {
            None => points.join(format!("{:05}.json", self.point)),
            Some(m) => points.join(format!("{:05}", self.point)).join(format!("{m:05}.json")),
        }
    }

    /// For messages: `points/00003/00017.json`.
    pub fn file(&self) -> String {
        match self.member {
            None => format!("points/{:05}.json", self.point),
            Some(m) => format!("points/{:05}/{m:05}.json", self.point),
        }
    }
}

/// The key of a unit made from `scene` (see the module doc).
pub fn unit_key(scene: &Scene, unit: Unit, verification: Option<String>) -> anyhow::Result<String> {
    let mut raw = scene.resolved()?;
    raw.ensemble = None;
    let text = toml::to_string(&raw).context("serialising a unit's scene")?;
    Ok(sha256_hex(
        format!("{PROGRAM}\npoint {}\nmember {:?}\nverification {verification:?}\n{text}", unit.point, unit.member)
            .as_bytes(),
    ))
}

#[derive(Deserialize)]
struct Stored<'a> {
    key: String,
    checksum: String,
    #[serde(borrow)]
    result: &'a serde_json::value::RawValue,
}

/// Writes a unit's result with its key and checksum, atomically.
pub fn write_unit<T: Serialize>(dir: &Path, unit: Unit, key: &str, result: &T) -> anyhow::Result<()> {
    let path = unit.path(dir);
    if let Some(parent) = path.parent() {
        crate::outfile::folder(parent)?;
    }
    let text = serde_json::to_string(result)?;
    let body = format!("{{\"key\":\"{key}\",\"checksum\":\"{}\",\"result\":{text}}}\n", sha256_hex(text.as_bytes()));
    crate::outfile::write(&path, body.as_bytes())
}

/// What was found for a unit.
#[derive(Debug)]
pub enum Found<T> {
    /// No file.
    Missing,
    /// A good file.
    Good(T),
    /// Unreadable, damaged, edited, or with wrong indices: why.
    Corrupt(String),
    /// Made for something else: why.
    Mismatch(String),
}

/// Reads a unit's file and checks it against `key`; `indices` returns what is wrong with the
/// indices inside the result, if anything.
pub fn read_unit<T: DeserializeOwned>(
    dir: &Path,
    unit: Unit,
    key: &str,
    indices: impl Fn(&T) -> Option<String>,
) -> Found<T> {
    let path = unit.path(dir);
    let text = match crate::input::read_text(&path, crate::input::MAX_JSON_BYTES) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Found::Missing,
        Err(e) => return Found::Corrupt(format!("unreadable: {e}")),
    };
    let stored: Stored = match serde_json::from_str(&text) {
        Ok(s) => s,
        Err(e) => return Found::Corrupt(format!("not a result file ({e})")),
    };
    if sha256_hex(stored.result.get().as_bytes()) != stored.checksum {
        return Found::Corrupt("checksum does not match its content (edited by hand or damaged)".into());
    }
    let result: T = match serde_json::from_str(stored.result.get()) {
        Ok(r) => r,
        Err(e) => return Found::Corrupt(format!("result unreadable ({e})")),
    };
    if let Some(why) = indices(&result) {
        return Found::Corrupt(why);
    }
    if stored.key != key {
        return Found::Mismatch(
            "made for another scene, sweep definition, draw or program version (its key differs)".into(),
        );
    }
    Found::Good(result)
}

/// Removes the temporaries of unit and output writes killed half-way (a SIGKILL during an
/// atomic write) from the folder, its `points/` and each point's member folder, leaving those
/// of live writers (another shard's); returns what it removed.
pub fn remove_temporaries(dir: &Path) -> Vec<PathBuf> {
    let points = dir.join("points");
    let members = std::fs::read_dir(&points).into_iter().flatten().flatten().map(|e| e.path()).filter(|p| p.is_dir());
    let folders: Vec<PathBuf> = [dir.to_path_buf(), points.clone()].into_iter().chain(members).collect();
    folders.iter().flat_map(|f| crate::atomic::remove_stale(f)).collect()
}

/// The unit files present in a folder (temporary files of atomic writes are skipped), and
/// the other files found under `points/`.
pub fn present(dir: &Path) -> (Vec<Unit>, Vec<PathBuf>) {
    let (mut units, mut strays) = (Vec::new(), Vec::new());
    let index = |name: &str, ext: bool| -> Option<usize> {
        let stem = if ext { name.strip_suffix(".json")? } else { name };
        (stem.len() >= 5 && stem.bytes().all(|b| b.is_ascii_digit())).then(|| stem.parse().ok()).flatten()
    };
    let Ok(entries) = std::fs::read_dir(dir.join("points")) else {
        return (units, strays);
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue;
        }
        let path = e.path();
        if path.is_dir() {
            let Some(point) = index(&name, false) else {
                strays.push(path);
                continue;
            };
            for m in std::fs::read_dir(&path).into_iter().flatten().flatten() {
                let mname = m.file_name().to_string_lossy().into_owned();
                if mname.starts_with('.') {
                    continue;
                }
                match index(&mname, true) {
                    Some(member) => units.push(Unit { point, member: Some(member) }),
                    None => strays.push(m.path()),
                }
            }
        } else {
            match index(&name, true) {
                Some(point) => units.push(Unit { point, member: None }),
                None => strays.push(path),
            }
        }
    }
    units.sort();
    (units, strays)
}

/// `manifest.json`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Manifest {
    /// Program and version.
    pub program: String,
    /// `sweep` or `ensemble`.
    pub kind: String,
    /// The sweep file (or the single scene's path and overrides), as JSON.
    pub definition: serde_json::Value,
    /// The resolved scene (the sweep's `set` applied, before the swept keys), TOML.
    pub scene: String,
    /// The ensemble, validated, with its defaults.
    pub ensemble: Option<serde_json::Value>,
    /// What the members run on.
    pub member_setting: Option<String>,
    /// SHA-256 of the fields above.
    pub hash: String,
}

impl Manifest {
    /// The manifest of a grid run by `work`.
    pub fn of<W: super::Work>(grid: &super::Grid, work: &W) -> anyhow::Result<Self> {
        let base = grid.base_scene()?;
        let mut raw = base.resolved()?;
        raw.ensemble = None;
        let mut m = Manifest {
            program: PROGRAM.to_string(),
            kind: crate::summary::snake_name(&grid.kind),
            definition: grid.definition.clone(),
            scene: toml::to_string(&raw)?,
            ensemble: work.manifest()?,
            member_setting: work.describe(&base),
            hash: String::new(),
        };
        m.hash = sha256_hex(serde_json::to_string(&m)?.as_bytes());
        Ok(m)
    }

    /// The parts that differ from `other`.
    pub fn differences(&self, other: &Manifest) -> Vec<&'static str> {
        let mut d = Vec::new();
        if self.program != other.program {
            d.push("program version");
        }
        if self.kind != other.kind || self.definition != other.definition {
            d.push("sweep definition");
        }
        if self.scene != other.scene {
            d.push("scene");
        }
        if self.ensemble != other.ensemble || self.member_setting != other.member_setting {
            d.push("ensemble");
        }
        d
    }

    /// Reads `DIR/manifest.json`: `Ok(None)` if there is none, `Err` text if unreadable.
    pub fn read(dir: &Path) -> Result<Option<Manifest>, String> {
        match crate::input::read_text(&dir.join("manifest.json"), crate::input::MAX_JSON_BYTES) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(e.to_string()),
            Ok(t) => serde_json::from_str(&t).map(Some).map_err(|e| e.to_string()),
        }
    }

    /// Writes `DIR/manifest.json`.
    pub fn write(&self, dir: &Path) -> anyhow::Result<()> {
        crate::outfile::write(&dir.join("manifest.json"), (serde_json::to_string_pretty(self)? + "\n").as_bytes())
    }
}
