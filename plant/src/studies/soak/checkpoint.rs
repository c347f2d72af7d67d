//! A soak's checkpoint (`soak-state.json`): what `plant soak --resume` needs to continue a soak
//! that was killed or interrupted, so that the continued soak writes what the uninterrupted one
//! would have.
//!
//! The soak takes one at the start of each shock: the plant's [`Snapshot`] (with the digital
//! loop's commands in flight), the per-shock tracker and the envelope bin under way, the
//! figures of the shocks already closed, the number of output rows seen, and how many bytes of
//! `soak.csv` and `envelope.csv` were written then. It is written whole or not at all (a
//! temporary, then a rename), by the sink once it has taken every row up to the snapshot's
//! time, so that all of its parts describe one instant.
//!
//! Its `programme` is the resolved programme (scene, shocks, recovery, RSS period, criteria):
//! a resume under a programme that differs anywhere is refused, naming the first difference.

use super::monitor::{Envelope, ShockFigures, ShockTracker};
use super::programme::Programme;
use crate::snapshot::Snapshot;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The checkpoint's file name in a soak's folder.
pub const FILE: &str = "soak-state.json";

/// The checkpoint file's format version.
pub const FORMAT: u32 = 1;

/// The largest checkpoint read (bytes): a few shocks' figures and a plant snapshot are a few
/// kB; 100 000 shocks' figures stay far below this.
const MAX_FILE_BYTES: u64 = 256 << 20;

/// A soak's state at a shock's start (module doc).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Checkpoint {
    /// [`FORMAT`].
    pub format: u32,
    /// The resolved programme ([`fingerprint`]).
    pub programme: serde_json::Value,
    /// The plant, the digital loop's commands in flight included.
    pub plant: Snapshot,
    /// Output rows the soak had taken (row `n` is at `n` output intervals).
    pub rows: u64,
    /// The per-shock tracker.
    pub tracker: ShockTracker,
    /// The envelope bin under way.
    pub envelope: Envelope,
    /// The shocks already closed (their `soak.csv` rows are written).
    pub figures: Vec<ShockFigures>,
    /// Bytes of `soak.csv` written.
    pub soak_csv_bytes: u64,
    /// Bytes of `envelope.csv` written.
    pub envelope_csv_bytes: u64,
    /// The seal ([`Checkpoint::seal_for`]), hex.
    #[serde(default)]
    pub seal: String,
}

/// Why a soak cannot be resumed from its folder.
#[derive(Debug, thiserror::Error)]
pub enum ResumeError {
    /// No checkpoint, or one that cannot be read.
    #[error("{path}: {message}")]
    File {
        /// The checkpoint file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// A checkpoint of another programme.
    #[error(
        "{path}: the soak in this folder ran another programme: {difference}; run it without --resume to start afresh"
    )]
    Programme {
        /// The checkpoint file.
        path: String,
        /// The first difference, in words.
        difference: String,
    },
}

/// The resolved programme as a value: the scene (as written into `scene.toml`), its shocks, the
/// recovery settings, the RSS period and the criteria.
pub fn fingerprint(prog: &Programme) -> anyhow::Result<serde_json::Value> {
    let scene: toml::Value = toml::from_str(&prog.scene.to_toml()?)?;
    Ok(serde_json::json!({
        "scene": scene,
        "shocks": prog.shocks,
        "recovery": { "hold_s": prog.hold, "clear_radius_m": prog.clear_radius },
        "rss_every_s": prog.rss_every,
        "criteria": prog.criteria,
    }))
}

/// The checkpoint's path in `dir`.
pub fn path(dir: &Path) -> PathBuf {
    dir.join(FILE)
}

impl Checkpoint {
    /// The seal of this checkpoint under a programme of value `programme` ([`fingerprint`]):
    /// SHA-256 (hex) of the checkpoint as JSON with `programme` in place of its own and no
    /// seal. Recomputed from the programme on `--resume`, not read: a checkpoint with any field
    /// edited has another seal. It catches edits, not forgeries (an editor may recompute it):
    /// the fields are also checked against the programme, the plant and the files
    /// ([`super::run`]'s resume).
    pub fn seal_for(&self, programme: &serde_json::Value) -> String {
        use sha2::{Digest, Sha256};
        let unsealed = Checkpoint { programme: programme.clone(), seal: String::new(), ..self.clone() };
        // Plain data: serialising it cannot fail; an empty text only makes a seal no file carries.
        let text = serde_json::to_string(&unsealed).unwrap_or_default();
        format!("{:x}", Sha256::digest(text.as_bytes()))
    }

    /// Seals the checkpoint for its own programme.
    pub fn seal(&mut self) {
        self.seal = self.seal_for(&self.programme);
    }

    /// Writes the checkpoint into `dir`, whole or not at all, sealed.
    pub fn write(&self, dir: &Path) -> anyhow::Result<()> {
        let mut sealed = self.clone();
        sealed.seal();
        let text = serde_json::to_string(&sealed)?;
        crate::outfile::write(&path(dir), text.as_bytes())
    }

    /// Reads `dir`'s checkpoint and checks that it belongs to `prog`.
    pub fn read(dir: &Path, prog: &Programme) -> Result<Checkpoint, ResumeError> {
        let file = path(dir);
        let shown = file.display().to_string();
        let fail = |message: String| ResumeError::File { path: shown.clone(), message };
        if std::fs::symlink_metadata(&file).is_err() {
            return Err(fail(
                "no checkpoint to resume from: the soak in this folder completed (its checkpoint is removed then), \
                 never reached its first shock, or never ran here"
                    .into(),
            ));
        }
        let text = crate::input::read_text(&file, MAX_FILE_BYTES).map_err(|e| fail(format!("{e:#}")))?;
        #[derive(Deserialize)]
        struct Version {
            format: u32,
        }
        let version: Version = serde_json::from_str(&text)
            .map_err(|e| fail(format!("not a soak checkpoint (no format version: {e}); truncated or another file?")))?;
        if version.format != FORMAT {
            return Err(fail(format!(
                "a soak checkpoint of format {}; this plant reads format {FORMAT}",
                version.format
            )));
        }
        let checkpoint: Checkpoint = serde_json::from_str(&text)
            .map_err(|e| fail(format!("not a whole soak checkpoint of format {FORMAT}: {e}")))?;
        let ours = fingerprint(prog).map_err(|e| fail(format!("the programme as a value: {e:#}")))?;
        if let Some(difference) = first_difference("", &checkpoint.programme, &ours) {
            return Err(ResumeError::Programme { path: shown, difference });
        }
        let expected = checkpoint.seal_for(&ours);
        if checkpoint.seal != expected {
            return Err(fail(format!(
                "the checkpoint's seal = {:?} is not {expected}, that of this programme and the checkpoint's fields: \
                 the file was edited; run without --resume to start afresh",
                checkpoint.seal
            )));
        }
        Ok(checkpoint)
    }
}

/// The first place, as a dotted key, where `saved` and `now` differ, in words.
pub fn first_difference(at: &str, saved: &serde_json::Value, now: &serde_json::Value) -> Option<String> {
    use serde_json::Value;
    let key = |k: &str| if at.is_empty() { k.to_owned() } else { format!("{at}.{k}") };
    match (saved, now) {
        (Value::Object(a), Value::Object(b)) => {
            for (k, va) in a {
                match b.get(k) {
                    Some(vb) => {
                        if let Some(d) = first_difference(&key(k), va, vb) {
                            return Some(d);
                        }
                    }
                    None => return Some(format!("{} = {va} in the saved soak is not in this programme", key(k))),
                }
            }
            b.iter()
                .find(|(k, _)| !a.contains_key(*k))
                .map(|(k, v)| format!("{} = {v} in this programme is not in the saved soak", key(k)))
        }
        (Value::Array(a), Value::Array(b)) if a.len() == b.len() => {
            a.iter().zip(b).enumerate().find_map(|(i, (va, vb))| first_difference(&format!("{at}[{i}]"), va, vb))
        }
        (Value::Array(a), Value::Array(b)) => {
            Some(format!("{at} has {} entries in the saved soak, {} in this programme", a.len(), b.len()))
        }
        _ if saved == now => None,
        _ => Some(format!("{at} is {saved} in the saved soak, {now} in this programme")),
    }
}

#[cfg(test)]
mod tests {
    use super::first_difference;
    use serde_json::json;

    #[test]
    fn the_first_difference_is_named_by_its_key() {
        let a = json!({"scene": {"shock": [{"peak_g": 2.0}, {"peak_g": 10.0}]}, "rss_every_s": 0.05});
        assert_eq!(first_difference("", &a, &a), None);
        let b = json!({"scene": {"shock": [{"peak_g": 2.0}, {"peak_g": 12.0}]}, "rss_every_s": 0.05});
        assert_eq!(
            first_difference("", &a, &b).as_deref(),
            Some("scene.shock[1].peak_g is 10.0 in the saved soak, 12.0 in this programme")
        );
        let c = json!({"scene": {"shock": [{"peak_g": 2.0}]}, "rss_every_s": 0.05});
        assert_eq!(
            first_difference("", &a, &c).as_deref(),
            Some("scene.shock has 2 entries in the saved soak, 1 in this programme")
        );
        let d = json!({"scene": {"shock": [{"peak_g": 2.0}, {"peak_g": 10.0}]}, "rss_every_s": 0.05, "x": 1});
        assert_eq!(first_difference("", &a, &d).as_deref(), Some("x = 1 in this programme is not in the saved soak"));
    }
}
