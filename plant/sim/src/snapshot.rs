//! A plant's whole evolving state as a value, and as a file.
//!
//! [`crate::stepper::Plant::snapshot`] returns a [`Snapshot`]: the tick and time, the state,
//! the integrator's step-size memory, substeps and counters, the output rows' clock, each race's
//! parking and the sensor noise generator; the run loop adds the commands in flight in its delay
//! line. [`crate::stepper::Plant::restore`] continues from it bit for bit.
//!
//! A snapshot carries the [`Fingerprint`] of the scene it was taken in: what another scene must
//! share for the state to mean the same there (the rotor model and its `[rotor]` keys, the
//! state's layout, the integrator, the controller's and the output's rates). The controller,
//! its law, gains and parameters, the shock programme and the duration may differ: that is what
//! `plant run --from-state` is for. A law with memory of its own (an integrator, a filter)
//! starts afresh; the commands in flight do not.
//!
//! The file (`state-T.json` in a run folder) is JSON with a format version ([`FORMAT`]); its
//! numbers read back to the same bits.

use crate::config::Scene;
use controller::ROTOR_AXES;
use plant_physics::integrate::AdaptiveState;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The snapshot file's format version.
pub const FORMAT: u32 = 1;

/// The largest snapshot file read (bytes): far above any real one (a few kB), so that a wrong
/// file (a device, a trace) is refused before it is read whole.
pub const MAX_FILE_BYTES: u64 = 16 << 20;

/// What a scene must share with the one a snapshot was taken in: `(key, value)` pairs in a fixed
/// order, the values as written in the scene (numbers in full).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fingerprint(pub Vec<(String, String)>);

impl Fingerprint {
    /// The fingerprint of `scene` for a plant of `state_len` state numbers.
    pub fn of(scene: &Scene, state_len: usize) -> Self {
        // The rotor model first, so that a snapshot of another model is named as such.
        let mut entries = vec![
            ("rotor.model".to_owned(), scene.rotor.model().name().to_owned()),
            ("state.length".to_owned(), state_len.to_string()),
        ];
        entries.extend(scene.state_fingerprint().into_iter().filter(|(k, _)| k != "rotor.model"));
        Self(entries)
    }

    /// The first entry where `other` differs from this one, in words.
    pub fn first_difference(&self, other: &Fingerprint) -> Option<String> {
        let find = |f: &Fingerprint, key: &str| f.0.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone());
        for (key, value) in &self.0 {
            match find(other, key) {
                Some(v) if &v == value => {}
                Some(v) => return Some(format!("{key} is {value} in the snapshot, {v} in the scene")),
                None => return Some(format!("{key} = {value} in the snapshot is not in the scene")),
            }
        }
        other
            .0
            .iter()
            .find(|(k, _)| find(self, k).is_none())
            .map(|(k, v)| format!("{k} = {v} in the scene is not in the snapshot"))
    }
}

/// A plant's evolving state (module doc).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// [`FORMAT`].
    pub format: u32,
    /// The scene it belongs to.
    pub fingerprint: Fingerprint,
    /// Ticks done.
    pub tick: u64,
    /// Simulated time (s): the end of tick `tick − 1`.
    pub t_s: f64,
    /// The state (the model's, the hardware's after it).
    pub state: Vec<f64>,
    /// The adaptive integrator's step-size memory.
    pub adaptive: AdaptiveState,
    /// The fixed-step integrator's substeps now (those of a free race or of parked ones).
    pub substeps: u32,
    /// Accepted steps so far.
    pub steps: u64,
    /// Rejected step attempts so far.
    pub rejected: u64,
    /// Evaluations of the derivative so far.
    pub rhs_evals: u64,
    /// The most evaluations in one tick so far.
    pub max_rhs_evals: u64,
    /// The next output row's number (row `n` at `n` output intervals).
    pub next_output: u64,
    /// Each plane's race parked.
    pub parked: Vec<bool>,
    /// Macro steps with a race parked so far.
    pub parked_steps: u64,
    /// The sensor noise generator's state before the sample of tick `tick` was read.
    pub sensor_rng: u64,
    /// The run's digital loop: the commands in flight.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub digital: Option<DigitalState>,
    /// The seal ([`Snapshot::seal_for`]): SHA-256 of the scene's fingerprint and every other
    /// field, hex. A saved state carries it; an in-memory one (an FMU's) has none (empty).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub seal: String,
}

/// The digital loop's part of a snapshot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DigitalState {
    /// The commands in the delay line, oldest first (A, per axis).
    pub in_flight: Vec<[f64; ROTOR_AXES]>,
    /// The samples the law read last, oldest first ([`crate::digital::RECENT`] at most): a law
    /// started from the snapshot reads them first ([`crate::digital::DigitalLoop::prime`]).
    #[serde(default)]
    pub recent: Vec<controller::RotorSample>,
}

/// Why a snapshot cannot be read or restored.
#[derive(Debug, thiserror::Error)]
pub enum SnapshotError {
    /// The file could not be read.
    #[error("{path}: {message}")]
    Read {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// The file could not be written.
    #[error("{path}: {message}")]
    Write {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
    /// Another format version.
    #[error("a snapshot of format {found}; this plant reads format {expected}")]
    Format {
        /// The file's.
        found: u32,
        /// This build's, [`FORMAT`].
        expected: u32,
    },
    /// Taken in a scene that differs from this one where it matters.
    #[error("a snapshot of another scene: {0}")]
    Scene(String),
    /// A length that does not fit the plant.
    #[error("the snapshot's {what} has {found} numbers; this plant has {expected}")]
    Layout {
        /// Which part.
        what: &'static str,
        /// The plant's.
        expected: usize,
        /// The snapshot's.
        found: usize,
    },
    /// A state number that is not finite.
    #[error("the snapshot's state number {index} is {value}")]
    NonFinite {
        /// Its index.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A time that is not the tick's.
    #[error("the snapshot's time t_s = {t_s} s is not tick {tick} of a period of {period_s} s")]
    Time {
        /// The tick.
        tick: u64,
        /// The time (s).
        t_s: f64,
        /// The period (s).
        period_s: f64,
    },
    /// Integrator settings out of range.
    #[error("the snapshot's integrator memory is out of range: {0}")]
    Integrator(String),
    /// A field whose value this scene's plant could not have written.
    #[error("the snapshot's {field} = {value}: {expected}")]
    Field {
        /// The field, as in the file.
        field: String,
        /// Its value, as read.
        value: String,
        /// What it must be, in words.
        expected: String,
    },
    /// No seal, or one that is not that of this scene and the snapshot's fields.
    #[error("{0}")]
    Seal(String),
}

impl SnapshotError {
    /// A [`SnapshotError::Field`].
    pub fn field(field: impl Into<String>, value: impl std::fmt::Display, expected: impl Into<String>) -> Self {
        Self::Field { field: field.into(), value: value.to_string(), expected: expected.into() }
    }
}

impl Snapshot {
    /// Refuses a snapshot of another format or of a scene with another fingerprint.
    pub fn check_against(&self, fingerprint: &Fingerprint) -> Result<(), SnapshotError> {
        if self.format != FORMAT {
            return Err(SnapshotError::Format { found: self.format, expected: FORMAT });
        }
        match self.fingerprint.first_difference(fingerprint) {
            Some(why) => Err(SnapshotError::Scene(why)),
            None => Ok(()),
        }
    }

    /// The seal of this snapshot in a scene of `fingerprint`: SHA-256 (hex) of the snapshot as
    /// JSON with `fingerprint` in place of its own and no seal. Computed from the scene, not read
    /// from the file: a state whose fingerprint or any other field was edited, or that belongs to
    /// another scene, has another seal. It catches edits and foreign states, not forgeries (an
    /// editor may recompute it): the fields are also checked against the scene and the physics
    /// ([`crate::run::check_start`]).
    pub fn seal_for(&self, fingerprint: &Fingerprint) -> String {
        use sha2::{Digest, Sha256};
        let unsealed = Snapshot { fingerprint: fingerprint.clone(), seal: String::new(), ..self.clone() };
        // Plain data (strings, numbers, booleans): serialising it cannot fail; an empty text
        // would only make a seal no file carries.
        let text = serde_json::to_string(&unsealed).unwrap_or_default();
        format!("{:x}", Sha256::digest(text.as_bytes()))
    }

    /// Seals the snapshot for its own scene ([`Snapshot::seal_for`]): what a saved state carries.
    pub fn seal(&mut self) {
        self.seal = self.seal_for(&self.fingerprint);
    }

    /// Refuses a snapshot without a seal or whose seal is not that of `fingerprint` (the scene
    /// it is to continue in) and its fields: a saved state edited, or of another scene.
    pub fn check_seal(&self, fingerprint: &Fingerprint) -> Result<(), SnapshotError> {
        if self.seal.is_empty() {
            return Err(SnapshotError::Seal(
                "the snapshot has no seal: written by hand or by an older plant; save the state again".into(),
            ));
        }
        let expected = self.seal_for(fingerprint);
        if self.seal != expected {
            return Err(SnapshotError::Seal(format!(
                "the snapshot's seal = {} is not {expected}, that of this scene and the snapshot's fields: \
                 the file was edited (or belongs to another scene); a state is used as saved",
                self.seal
            )));
        }
        Ok(())
    }

    /// The snapshot as the text of its file (pretty JSON); the CLI writes it whole or not at
    /// all (`plant::snapshot::write`).
    pub fn to_json(&self) -> Result<String, serde_json::Error> {
        serde_json::to_string_pretty(self)
    }

    /// Reads a snapshot file: a regular file of at most [`MAX_FILE_BYTES`], of this format.
    pub fn read(path: &Path) -> Result<Snapshot, SnapshotError> {
        let fail = |message: String| SnapshotError::Read { path: path.display().to_string(), message };
        // A regular file of at most MAX_FILE_BYTES (a device, a FIFO or a folder refused at once).
        let text = shock_table::input::read_text(path, MAX_FILE_BYTES).map_err(|e| fail(format!("{e:#}")))?;
        // The format first, so that another version is named as such rather than as a field
        // this build does not know.
        #[derive(Deserialize)]
        struct Version {
            format: u32,
        }
        let version: Version = serde_json::from_str(&text)
            .map_err(|e| fail(format!("not a snapshot (no format version: {e}); truncated or another file?")))?;
        if version.format != FORMAT {
            return Err(fail(SnapshotError::Format { found: version.format, expected: FORMAT }.to_string()));
        }
        serde_json::from_str(&text).map_err(|e| fail(format!("not a whole snapshot of format {FORMAT}: {e}")))
    }

    /// The file name, in a run folder, of the snapshot asked for at `t_s` (`--save-state-at`):
    /// `state-0.5.json` (the time in the fewest digits that read back to it, in plain or in
    /// exponent form, whichever is shorter: `1e-300` made a name of 300 zeros, too long for the
    /// file system).
    pub fn file_name(t_s: f64) -> String {
        let (plain, exponent) = (format!("{t_s}"), format!("{t_s:e}"));
        let t = if exponent.len() < plain.len() { exponent } else { plain };
        format!("state-{t}.json")
    }
}

/// True for a name [`Snapshot::file_name`] makes: `state-T.json` with a number `T`.
pub fn is_file_name(name: &str) -> bool {
    name.strip_prefix("state-").and_then(|s| s.strip_suffix(".json")).is_some_and(|t| t.parse::<f64>().is_ok())
}

#[cfg(test)]
mod name_tests {
    use super::*;

    /// Every time a run takes has a short name that reads back to it (`is_file_name`).
    #[test]
    fn a_snapshot_name_is_short_and_reads_back() {
        for (t, name) in [(0.5, "state-0.5.json"), (0.0301, "state-0.0301.json"), (1e-300, "state-1e-300.json")] {
            assert_eq!(Snapshot::file_name(t), name);
            assert!(is_file_name(name));
        }
        for t in [1e-300, 5e-324, 0.1 + 0.2, 1.5, 1e15, 123456.789] {
            let name = Snapshot::file_name(t);
            assert!(name.len() <= 40 && is_file_name(&name), "{name}");
            let back: f64 = name["state-".len()..name.len() - ".json".len()].parse().expect("a number");
            assert_eq!(back, t);
        }
    }
}
