//! What a point computes, as the engine sees it: one trait, two implementations
//! ([`crate::sweep::single::Single`]: one run per point; [`crate::ensemble::work::Ensemble`]:
//! members drawn around the point, in rounds, with a stopping rule).

use super::{Grid, Point};
use crate::config::{ConfigError, Scene};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// Where a point stands, from the units present.
#[derive(Clone, Debug, PartialEq)]
pub enum Progress<D> {
    /// Decided: its first `counted` units count, for `decision`.
    Decided {
        /// Units counted (slots `0 .. counted`).
        counted: usize,
        /// Why it is decided (the ensembles' stopping rule; nothing for single runs).
        decision: D,
    },
    /// Round `round` is needed; `missing` lists its units (slots) not present.
    Needs {
        /// The round.
        round: usize,
        /// Slots of that round not present.
        missing: Vec<usize>,
    },
}

/// What a point computes: its units, their files' keys, when it is decided, and the merged
/// outputs. A unit's **slot** is its member index, 0 for a single run.
pub trait Work: Sync {
    /// What one unit's file holds.
    type Result: Serialize + DeserializeOwned + Send + Sync;
    /// Why a point is decided.
    type Decision: Copy + Send + Sync;

    /// Members per point: `None` when a point is one unit (`points/NNNNN.json`), else its
    /// units are `points/NNNNN/MMMMM.json`, MMMMM below this.
    fn members(&self) -> Option<usize>;
    /// Rounds of units (1 when a point's units all run at once).
    fn rounds(&self) -> usize;
    /// What the units are called on the progress bar (`points`, `members`).
    fn noun(&self) -> &'static str;
    /// What the run is called in its closing line (`sweep`, `ensemble`).
    fn what(&self) -> &'static str;

    /// Checks the grid as a whole, before any point is loaded.
    fn check(&self, _grid: &Grid) -> Result<(), ConfigError> {
        Ok(())
    }
    /// Checks one point before anything runs (its scene loaded already).
    fn check_point(&self, _point: &Point) -> Result<(), ConfigError> {
        Ok(())
    }
    /// A sentence on how units run, said before a run and kept in the manifest.
    fn describe(&self, _scene: &Scene) -> Option<String> {
        None
    }
    /// The work's own part of the manifest (an ensemble's validated table).
    fn manifest(&self) -> anyhow::Result<Option<serde_json::Value>> {
        Ok(None)
    }

    /// The key the file of unit (`point`, `member`) must have.
    fn key(&self, point: &Point, member: Option<usize>) -> anyhow::Result<String>;
    /// The (point, member) indices a result holds, checked against its file's name.
    fn indices(&self, result: &Self::Result) -> (usize, Option<usize>);
    /// Where a point stands, from its units present (by slot).
    fn progress(&self, present: &BTreeMap<usize, Self::Result>) -> Progress<Self::Decision>;
    /// Runs unit (`point`, `member`); `None` when `stop` interrupted it.
    fn run(&self, point: &Point, member: Option<usize>, stop: &AtomicBool) -> anyhow::Result<Option<Self::Result>>;
    /// Writes the merged outputs into `dir` from every point's counted units (in slot order)
    /// and its decision; returns what was written, for the closing line.
    fn merge(&self, grid: &Grid, dir: &Path, points: &[(Vec<&Self::Result>, Self::Decision)])
        -> anyhow::Result<String>;
}
