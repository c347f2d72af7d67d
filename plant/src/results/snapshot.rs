//! A plant's saved state (`plant run --save-state-at`, `--from-state`): the format is the
//! simulation's ([`plant_sim::snapshot`], re-exported here); writing its file is the CLI's.

pub use plant_sim::snapshot::*;

use std::path::Path;

/// Writes `snapshot` to `path`, whole or not at all.
pub fn write(snapshot: &Snapshot, path: &Path) -> Result<(), SnapshotError> {
    let fail = |message: String| SnapshotError::Write { path: path.display().to_string(), message };
    let text = snapshot.to_json().map_err(|e| fail(e.to_string()))?;
    crate::outfile::write(path, text.as_bytes()).map_err(|e| fail(format!("{e:#}")))
}
