//! The point-grid engine under `plant sweep` and `plant ensemble`: a grid of points (a scene
//! with none, one or two swept keys), what each point computes as one [`Work`] (a single run,
//! [`crate::sweep::single`], or an ensemble of members, [`crate::ensemble`]), and the
//! machinery both share ([`engine`]): unit files, the manifest, shards, rounds, resume, merge,
//! progress and cancellation.
//!
//! A **unit** is what one result file holds: a point's run (`points/NNNNN.json`) or one member
//! of a point (`points/NNNNN/MMMMM.json`). Each finished unit is written at once, atomically,
//! with a key and a checksum ([`store`]): an interrupted run keeps what it finished and resumes
//! where it stopped, shards on other machines merge by copying their `points/` folders
//! together, and a unit made for another scene, definition, draw or program version, or edited
//! by hand, is refused. Units are deterministic, so a merged sharded run equals an unsharded
//! one. A point is **decided** when its work says so from the units present ([`Progress`]):
//! a single run by its one unit, an ensemble by its stopping rule over rounds of members.
//!
//! The engine knows nothing of ensembles or of what a run computes: those depend on it, never
//! the reverse.

pub mod engine;
pub mod outputs;
pub mod store;
pub mod work;

use crate::config::{load_scene, ConfigError, Scene};
use crate::status::Status;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

pub use engine::{execute, RunArgs};
pub use work::{Progress, Work};

/// Most points of a grid (both keys of a map together).
pub const MAX_POINTS: usize = 100_000;

/// How the values of an axis are spaced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Spacing {
    /// Equal steps.
    #[default]
    Linear,
    /// Equal ratios (`from`, `to` > 0).
    Log,
}

/// One swept key.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Axis {
    /// Scene key, as for `--set` (e.g. `touchdown.air_gap_mm`, `shock[0].peak_g`).
    pub key: String,
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// Number of values (≥ 1).
    pub points: usize,
    /// Spacing (default linear).
    #[serde(default)]
    pub spacing: Spacing,
}

impl Axis {
    /// Value `j` of this axis.
    pub fn value(&self, j: usize) -> f64 {
        let n = self.points;
        let s = if n <= 1 { 0.0 } else { j as f64 / (n - 1) as f64 };
        let v = match self.spacing {
            Spacing::Linear => self.from + s * (self.to - self.from),
            Spacing::Log => self.from * (self.to / self.from).powf(s),
        };
        // 12 significant digits: 0.15, not 0.15000000000000002.
        format!("{v:.11e}").parse().unwrap_or(v)
    }

    /// The values of this axis.
    pub fn values(&self) -> Vec<f64> {
        (0..self.points).map(|j| self.value(j)).collect()
    }

    /// Checks the axis named `name` (`""` for the first key, `map` for the second).
    pub fn check(&self, name: &str) -> Result<(), ConfigError> {
        let bad = |field: &str, value: String, why: &str| ConfigError::Range {
            key: if name.is_empty() { field.to_string() } else { format!("{name}.{field}") },
            value,
            unit: String::new(),
            why: why.to_string(),
        };
        if self.points == 0 || self.points > MAX_POINTS {
            return Err(bad("points", self.points.to_string(), &format!("must be between 1 and {MAX_POINTS}")));
        }
        for (field, v) in [("from", self.from), ("to", self.to)] {
            if !v.is_finite() {
                return Err(bad(field, v.to_string(), "must be finite"));
            }
            if self.spacing == Spacing::Log && v <= 0.0 {
                return Err(bad(field, v.to_string(), "must be > 0 with spacing = \"log\""));
            }
        }
        Ok(())
    }
}

/// What a folder holds: a sweep over one or two keys, or one scene's ensemble.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// `plant sweep`.
    Sweep,
    /// `plant ensemble`: one point, no swept key.
    Ensemble,
}

/// A grid of points: a scene, the overrides of every point, and the swept keys.
#[derive(Clone, Debug)]
pub struct Grid {
    /// Sweep or single-scene ensemble.
    pub kind: Kind,
    /// What the folder was made from, for the manifest: the sweep file as read, or the single
    /// scene's path and overrides.
    pub definition: serde_json::Value,
    /// Scene path, resolved.
    pub scene_path: PathBuf,
    /// Overrides of every point.
    pub set: Vec<String>,
    /// Swept keys (none, one, or two for a map).
    pub axes: Vec<Axis>,
}

/// One point of a grid, loaded: its scene file, its overrides, its scene.
#[derive(Clone, Debug)]
pub struct Point<'a> {
    /// Scene file.
    pub path: &'a Path,
    /// The point's overrides (the grid's `set`, `output.plots=false`, the swept values).
    pub sets: Vec<String>,
    /// The point's scene.
    pub scene: Scene,
    /// Point index.
    pub index: usize,
    /// The swept keys' values at the point (none for a single scene).
    pub values: Vec<f64>,
}

impl Grid {
    /// Checks every point before anything runs: its scene loads, and `work` accepts the grid
    /// and each point (an ensemble also loads its members' scenes at the ends of every drawn
    /// range), so that bad input fails with exit 2 before anything runs.
    pub fn validate<W: Work>(&self, work: &W) -> Result<(), ConfigError> {
        work.check(self)?;
        for i in 0..self.len() {
            work.check_point(&self.point(i)?)?;
        }
        Ok(())
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.axes.iter().map(|a| a.points).product()
    }

    /// True for a grid without points (never, once loaded).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Values of point `i` (one per axis). The first key varies fastest.
    pub fn point_values(&self, i: usize) -> Vec<f64> {
        match self.axes.as_slice() {
            [] => Vec::new(),
            [a] => vec![a.value(i % a.points)],
            [a, b, ..] => vec![a.value(i % a.points), b.value(i / a.points)],
        }
    }

    /// Values of point `i` (the second is NaN without a map).
    pub fn values(&self, i: usize) -> (f64, f64) {
        let v = self.point_values(i);
        (v.first().copied().unwrap_or(f64::NAN), v.get(1).copied().unwrap_or(f64::NAN))
    }

    /// The overrides of point `i`.
    pub fn point_sets(&self, i: usize) -> Vec<String> {
        let mut set = self.set.clone();
        set.push("output.plots=false".into());
        for (a, v) in self.axes.iter().zip(self.point_values(i)) {
            set.push(format!("{}={v:?}", a.key));
        }
        set
    }

    /// The scene of point `i`.
    pub fn scene_for(&self, i: usize) -> Result<Scene, ConfigError> {
        load_scene(&self.scene_path, &self.point_sets(i))
    }

    /// Point `i`, loaded.
    pub fn point(&self, i: usize) -> Result<Point<'_>, ConfigError> {
        let sets = self.point_sets(i);
        let scene = load_scene(&self.scene_path, &sets)?;
        Ok(Point { path: &self.scene_path, sets, scene, index: i, values: self.point_values(i) })
    }

    /// The scene every point starts from: the grid's `set` applied, before the swept keys.
    pub fn base_scene(&self) -> Result<Scene, ConfigError> {
        load_scene(&self.scene_path, &self.set)
    }

    /// A point's name for messages: `point 3 (touchdown.air_gap_mm = 0.13)`.
    pub fn point_name(&self, i: usize) -> String {
        let values: Vec<String> =
            self.axes.iter().zip(self.point_values(i)).map(|(a, v)| format!("{} = {v}", a.key)).collect();
        if values.is_empty() {
            format!("point {i}")
        } else {
            format!("point {i} ({})", values.join(", "))
        }
    }

    /// Short name of the scene, for chart titles.
    pub fn scene_name(&self) -> String {
        self.scene_path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
    }
}

/// Which share of the work a process runs: `index / count`, as `--shard I/N`. Single runs go
/// by point (`i % N == I`); ensemble members by point and member (`(i + j) % N == I`), so that
/// the members of one point spread over the shards too.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// This shard, 0-based.
    pub index: usize,
    /// Number of shards.
    pub count: usize,
}

impl Shard {
    /// The whole grid.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// True when unit (point `i`, member `j`) belongs to this shard.
    pub fn owns(&self, i: usize, j: Option<usize>) -> bool {
        (i + j.unwrap_or(0)) % self.count == self.index
    }
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (i, n) = s.split_once('/').ok_or_else(|| format!("--shard {s}: expected I/N, e.g. 0/4"))?;
        let index: usize = i.trim().parse().map_err(|_| format!("--shard {s}: I is not a number"))?;
        let count: usize = n.trim().parse().map_err(|_| format!("--shard {s}: N is not a number"))?;
        if count == 0 || index >= count {
            return Err(format!("--shard {s}: need 0 <= I < N"));
        }
        Ok(Shard { index, count })
    }
}

/// What a run of a study counts as: its post-shock motion mode, or `diverged` when it did not
/// complete (an ensemble's members; a single run's point keeps its analysed mode,
/// [`crate::analysis::classify::MotionMode`]). Serialised as `recovered`, `dry_whirl`,
/// `rebound`, `diverged`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Back on its small unbalance orbit, no contact.
    Recovered,
    /// Continuous contact, whirling around the clearance circle.
    DryWhirl,
    /// Repeated impacts.
    Rebound,
    /// The run did not complete.
    Diverged,
}

impl Mode {
    /// Every mode, in the order ties are broken and charts list them.
    pub const ALL: [Mode; 4] = [Mode::Recovered, Mode::DryWhirl, Mode::Rebound, Mode::Diverged];

    /// The mode a run counts as: its motion mode if it completed, else `diverged`.
    pub fn of_run(status: Status, mode: crate::analysis::classify::MotionMode) -> Mode {
        if status == Status::Completed {
            Mode::from(mode)
        } else {
            Mode::Diverged
        }
    }

    /// The name written in the outputs.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Recovered => "recovered",
            Mode::DryWhirl => "dry_whirl",
            Mode::Rebound => "rebound",
            Mode::Diverged => "diverged",
        }
    }
}

impl From<crate::analysis::classify::MotionMode> for Mode {
    fn from(m: crate::analysis::classify::MotionMode) -> Mode {
        use crate::analysis::classify::MotionMode;
        match m {
            MotionMode::Recovered => Mode::Recovered,
            MotionMode::DryWhirl => Mode::DryWhirl,
            MotionMode::Rebound => Mode::Rebound,
        }
    }
}

/// Why a sweep or ensemble stopped short (its exit code: [`crate::exit`]).
#[derive(Debug, thiserror::Error)]
pub enum GridError {
    /// Units made for another scene, definition, draw or program version, or damaged/edited
    /// ones, found on a resume (exit 2): re-run them with `--rerun-mismatched`.
    #[error("{} result file(s) in {dir} do not match this sweep (re-run them with --rerun-mismatched):\n  {}", units.len(), list(units))]
    Mismatch {
        /// The output folder.
        dir: PathBuf,
        /// Each unit with what is wrong.
        units: Vec<String>,
    },
    /// `--merge` (or `--round`) with units missing or corrupt (exit 7).
    #[error("incomplete: {} missing, {} corrupt in {dir}:\n  {}", missing.len(), corrupt.len(), list(&[missing.as_slice(), corrupt.as_slice()].concat()))]
    Incomplete {
        /// The output folder.
        dir: PathBuf,
        /// Missing units.
        missing: Vec<String>,
        /// Corrupt units, with why.
        corrupt: Vec<String>,
    },
    /// Units whose run failed (exit 3).
    #[error("{} unit(s) failed:\n  {}", failed.len(), list(failed))]
    Failed {
        /// Each unit with its error.
        failed: Vec<String>,
    },
    /// Interrupted by SIGINT/SIGTERM (exit 130); finished units are kept.
    #[error("interrupted; finished units are kept, run the same command again to resume")]
    Interrupted,
}

fn list(items: &[String]) -> String {
    const SHOWN: usize = 20;
    let mut s = items.iter().take(SHOWN).cloned().collect::<Vec<_>>().join("\n  ");
    if items.len() > SHOWN {
        s.push_str(&format!("\n  … and {} more", items.len() - SHOWN));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mode_names_are_the_serialised_names() {
        for m in Mode::ALL {
            assert_eq!(serde_json::to_value(m).unwrap(), m.name());
        }
    }
}
