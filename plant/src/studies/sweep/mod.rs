//! Parameter sweeps for bifurcation diagrams (`plant sweep`): the sweep file, and the command
//! that runs it on the grid engine ([`crate::grid`]): each point a single run ([`single`]), or,
//! with an `[ensemble]` table, an ensemble of members ([`crate::ensemble`]).
//!
//! A sweep file names a scene and one key to vary (and optionally a second, for a 2-D map).
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

pub mod overlay;
pub mod single;

use crate::config::ConfigError;
use crate::ensemble::spec::EnsembleSpec;
use crate::ensemble::work::Ensemble;
use crate::grid::{execute, Axis, Grid, Kind, RunArgs, Spacing, MAX_POINTS};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A sweep file.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(from = "SweepFile")]
pub struct SweepSpec {
    /// Scene file, relative to the sweep file.
    pub scene: PathBuf,
    /// Overrides applied to every point.
    pub set: Vec<String>,
    /// The swept key.
    #[serde(flatten)]
    pub axis: Axis,
    /// Optional second key (2-D map).
    pub map: Option<Axis>,
    /// Optional ensemble per point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ensemble: Option<toml::Table>,
}

/// The sweep file as read: the swept key's fields at the top level, read directly (not through
/// `#[serde(flatten)]`, which loses the TOML position and the key of a type error: it reported
/// line 1, column 1).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SweepFile {
    scene: PathBuf,
    #[serde(default)]
    set: Vec<String>,
    key: String,
    from: f64,
    to: f64,
    points: usize,
    #[serde(default)]
    spacing: Spacing,
    #[serde(default)]
    map: Option<Axis>,
    #[serde(default)]
    ensemble: Option<toml::Table>,
}

impl From<SweepFile> for SweepSpec {
    fn from(f: SweepFile) -> Self {
        SweepSpec {
            scene: f.scene,
            set: f.set,
            axis: Axis { key: f.key, from: f.from, to: f.to, points: f.points, spacing: f.spacing },
            map: f.map,
            ensemble: f.ensemble,
        }
    }
}

/// Reads and checks a sweep file: its grid, and its `[ensemble]` if it has one. The points are
/// checked by [`Grid::validate`] with the work that runs them.
pub fn load(path: &Path) -> Result<(Grid, Option<EnsembleSpec>), ConfigError> {
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
    let definition = serde_json::to_value(&spec)
        .map_err(|e| ConfigError::Parse { path: path.display().to_string(), message: e.to_string() })?;
    let grid = Grid {
        kind: Kind::Sweep,
        definition,
        scene_path: path.parent().unwrap_or(Path::new(".")).join(&spec.scene),
        set: spec.set.clone(),
        axes: std::iter::once(spec.axis).chain(spec.map).collect(),
    };
    Ok((grid, ensemble))
}

/// `plant sweep` arguments.
#[derive(clap::Args, Debug, Clone)]
pub struct SweepArgs {
    /// Sweep file (TOML).
    pub sweep: PathBuf,
    /// Common options.
    #[command(flatten)]
    pub run: RunArgs,
}

/// `plant sweep`: loads the sweep file and checks every point (exit 2 on bad input), then
/// runs or merges it into `--out` (default `runs/sweep-<file stem>`).
pub fn command(args: &SweepArgs) -> anyhow::Result<()> {
    let (grid, ensemble) = load(&args.sweep)?;
    let stem = args.sweep.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let dir = args.run.out.clone().unwrap_or_else(|| PathBuf::from("runs").join(format!("sweep-{stem}")));
    match ensemble {
        None => {
            grid.validate(&single::Single)?;
            execute(&grid, &single::Single, &dir, &args.run)
        }
        Some(spec) => {
            let work = Ensemble { spec };
            grid.validate(&work)?;
            execute(&grid, &work, &dir, &args.run)
        }
    }
}
