//! Parameter sweeps for bifurcation diagrams (`plant sweep`), and the machinery that runs
//! ensembles (`plant ensemble`, [`crate::ensemble`]): points, resumable result files, shards,
//! rounds, the manifest and merging.
//!
//! A sweep file names a scene and one key to vary (and optionally a second, for a 2-D map).
//! Each point is a full run of the scene with the key set to its value — or, with an
//! `[ensemble]` table, a set of members drawn around it. Each finished unit (a point, or one
//! member of a point) is written at once, atomically, to `DIR/points/NNNNN.json` (single runs)
//! or `DIR/points/NNNNN/MMMMM.json` (members), with a key and a checksum: an interrupted sweep
//! keeps what it finished and resumes where it stopped, shards run on other machines merge by
//! copying their `points/` folders together, and a unit that was made for another scene, sweep
//! definition, draw or program version, or that was edited by hand, is refused
//! ([`store`]). Units are deterministic, so a merged sharded sweep equals an unsharded one.
//!
//! ```toml
//! scene = "../paper-10g.toml"        # relative to the sweep file
//! set = ["scene.duration_s=1.5"]     # overrides for every point (optional)
//! key = "touchdown.air_gap_mm"
//! from = 0.1
//! to = 0.4
//! points = 31
//! spacing = "linear"                 # or "log"
//!
//! [map]                              # optional second key: a 2-D map
//! key = "controller.damping_ratio"
//! from = 0.001
//! to = 0.031
//! points = 16
//!
//! [ensemble]                         # optional: members per point (crate::ensemble)
//! members = 64
//! seed = 1
//! ```
//!
//! Bounds (checked at load, exit 2): at most [`MAX_POINTS`] points in all (both keys of a map
//! together), at most [`crate::ensemble::spec::MAX_MEMBERS`] members per point and
//! [`crate::ensemble::spec::MAX_RUNS`] member runs per sweep. Every point's scene (and, for
//! ensembles, its members' scenes at the ends of every drawn range) is loaded and validated
//! before anything runs.

pub mod merge;
pub mod run;
pub mod store;

use crate::config::{load_scene, ConfigError, Scene};
use crate::ensemble::spec::{EnsembleSpec, MAX_RUNS};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

pub use run::{command, SweepArgs};

/// Most points of a sweep (both keys of a map together).
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

/// A sweep file.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepSpec {
    /// Scene file, relative to the sweep file.
    pub scene: PathBuf,
    /// Overrides applied to every point.
    #[serde(default)]
    pub set: Vec<String>,
    /// The swept key.
    #[serde(flatten)]
    pub axis: Axis,
    /// Optional second key (2-D map).
    #[serde(default)]
    pub map: Option<Axis>,
    /// Optional ensemble per point.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ensemble: Option<toml::Table>,
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

    fn check(&self, name: &str) -> Result<(), ConfigError> {
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

/// What a sweep folder holds: a sweep over one or two keys, or one scene's ensemble.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// `plant sweep`.
    Sweep,
    /// `plant ensemble`: one point, no swept key.
    Ensemble,
}

/// A loaded sweep (or single-scene ensemble): its points and where its scene is.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// Sweep or single-scene ensemble.
    pub kind: Kind,
    /// The sweep file as written (`None` for a single-scene ensemble).
    pub spec: Option<SweepSpec>,
    /// Scene path, resolved.
    pub scene_path: PathBuf,
    /// Overrides of every point.
    pub set: Vec<String>,
    /// Swept keys (none, one, or two for a map).
    pub axes: Vec<Axis>,
    /// Members per point, if an ensemble.
    pub ensemble: Option<EnsembleSpec>,
}

impl Sweep {
    /// Reads and checks a sweep file, and loads every point's scene (and, for an ensemble,
    /// its members' scenes at the ends of the drawn ranges) so that bad input fails with exit 2
    /// before anything runs.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = shock_table::input::read_text(path, shock_table::input::MAX_TOML_BYTES)
            .map_err(|source| ConfigError::Read { path: path.to_path_buf(), source })?;
        let spec: SweepSpec = toml::from_str(&text)
            .map_err(|e| ConfigError::Parse { path: path.display().to_string(), message: e.to_string() })?;
        spec.axis.check("")?;
        if let Some(m) = &spec.map {
            m.check("map")?;
            let n = spec.axis.points.saturating_mul(m.points);
            if n > MAX_POINTS {
                return Err(ConfigError::Range {
                    key: "points × map.points".into(),
                    value: format!("{} × {} = {n}", spec.axis.points, m.points),
                    unit: " points".into(),
                    why: format!("must be at most {MAX_POINTS} in all"),
                });
            }
        }
        let ensemble = spec.ensemble.as_ref().map(EnsembleSpec::from_table).transpose()?;
        let scene_path = path.parent().unwrap_or(Path::new(".")).join(&spec.scene);
        let axes = std::iter::once(spec.axis.clone()).chain(spec.map.clone()).collect();
        let sweep = Sweep { kind: Kind::Sweep, set: spec.set.clone(), spec: Some(spec), scene_path, axes, ensemble };
        sweep.validate()?;
        Ok(sweep)
    }

    /// A single scene's ensemble (`plant ensemble`): one point, the scene's `[ensemble]` table.
    pub fn single(scene_path: &Path, set: &[String]) -> Result<Self, ConfigError> {
        let scene = load_scene(scene_path, set)?;
        let table = crate::ensemble::resolved(&scene)?.ensemble.unwrap_or_default();
        let ensemble = EnsembleSpec::from_table(&table)?;
        let sweep = Sweep {
            kind: Kind::Ensemble,
            spec: None,
            scene_path: scene_path.to_path_buf(),
            set: set.to_vec(),
            axes: Vec::new(),
            ensemble: Some(ensemble),
        };
        sweep.validate()?;
        Ok(sweep)
    }

    /// Checks every point (see [`Sweep::load`]).
    fn validate(&self) -> Result<(), ConfigError> {
        if let Some(e) = &self.ensemble {
            let runs = self.len().saturating_mul(e.members);
            if runs > MAX_RUNS {
                return Err(ConfigError::Range {
                    key: "ensemble.members".into(),
                    value: format!("{} (× {} points = {runs})", e.members, self.len()),
                    unit: " member runs".into(),
                    why: format!("a sweep may run at most {MAX_RUNS} members in all"),
                });
            }
            for a in &self.axes {
                let clash = e.vary.iter().any(|v| v.key == a.key) || (e.angle && a.key == "rotor.unbalance_phase_deg");
                if clash {
                    return Err(ConfigError::Range {
                        key: "ensemble".into(),
                        value: format!("\"{}\"", a.key),
                        unit: String::new(),
                        why: "is both swept and drawn: draw it relatively, or sweep another key".into(),
                    });
                }
            }
        }
        for i in 0..self.len() {
            let scene = self.scene_for(i)?;
            if let Some(e) = &self.ensemble {
                let sets = self.point_sets(i);
                let mut member_sets = sets.clone();
                member_sets.extend(crate::ensemble::member::setting_overrides(&scene, e.integrator));
                for draw in e.extremes() {
                    let mut s = member_sets.clone();
                    s.extend(crate::ensemble::member::draw_overrides(&scene, e, &draw));
                    let member = load_scene(&self.scene_path, &s)?;
                    if let crate::stability::StepVerdict::Refuse(why) = crate::stability::check(&member) {
                        return Err(ConfigError::Range {
                            key: "ensemble.integrator".into(),
                            value: format!("{:?}", e.integrator),
                            unit: String::new(),
                            why,
                        });
                    }
                }
            }
        }
        Ok(())
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.axes.iter().map(|a| a.points).product()
    }

    /// True for a sweep without points (never, once loaded).
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
    /// The whole sweep.
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

/// Why a sweep or ensemble stopped short; [`SweepError::exit_code`] gives its exit code.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
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

impl SweepError {
    /// The exit code of this error (README, exit codes).
    pub fn exit_code(&self) -> u8 {
        match self {
            SweepError::Mismatch { .. } => 2,
            SweepError::Failed { .. } => 3,
            SweepError::Incomplete { .. } => 7,
            SweepError::Interrupted => 130,
        }
    }
}

/// The exit code of an error from `plant sweep` / `plant ensemble`: 2 for bad input
/// ([`ConfigError`]), the [`SweepError`]'s own, else `None` (an output could not be written: 1).
pub fn exit_code(e: &anyhow::Error) -> Option<u8> {
    if e.downcast_ref::<ConfigError>().is_some() {
        return Some(2);
    }
    e.downcast_ref::<SweepError>().map(SweepError::exit_code)
}
