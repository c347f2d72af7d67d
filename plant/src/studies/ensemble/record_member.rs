//! `plant ensemble SCENE --record-member J` (issue 42: "a member of an ensemble on request"):
//! member J, run again as `plant run` runs a scene, with its recording: `trace.csv`,
//! `summary.json`, `scene.toml` (`plant run` of which reproduces it) and `run.mcap` in
//! `<out>/member-J/`.
//!
//! The member's scene is the ensemble's own for that member (the point's overrides, the
//! members' integrator setting and member J's draws: [`crate::ensemble::member::member_overrides`]),
//! so its run is the ensemble's run of it, row for row. A member the ensemble re-ran at the
//! reference setting (close to a decision) is recorded at the members' setting, its first run.
//! Written here rather than in the ensemble's runner because an ensemble keeps no rows: the
//! member is run once more, after the ensemble, for its recording alone.

use crate::argument::BadArgument;
use crate::config::load_scene;
use crate::cosim::Launch;
use crate::ensemble::member::member_overrides;
use crate::ensemble::spec::EnsembleSpec;
use crate::grid::Grid;
use anyhow::Context;
use std::path::{Path, PathBuf};

/// The folder of member `j`'s recording in the ensemble's folder `dir`.
pub fn folder(dir: &Path, j: usize) -> PathBuf {
    dir.join(format!("member-{j}"))
}

/// `--record-member J` must name a member: 0 to `members` − 1. Checked before the ensemble runs.
pub fn check(j: usize, members: usize) -> Result<(), BadArgument> {
    if j >= members {
        return Err(BadArgument(format!(
            "--record-member {j}: the ensemble has {members} members, numbered 0 to {}",
            members.saturating_sub(1)
        )));
    }
    Ok(())
}

/// Runs member `j` of the ensemble `grid` (a single point) with `spec` into
/// [`folder`]`(dir, j)`, recorded; returns the folder. Stops early (Ctrl-C) as `plant run` does.
pub fn record(grid: &Grid, spec: &EnsembleSpec, j: usize, dir: &Path) -> anyhow::Result<PathBuf> {
    let point = grid.point(0)?;
    let (mut sets, _, _) = member_overrides(&point, spec, j);
    sets.push("output.mcap=true".into());
    let scene = load_scene(point.path, &sets)?;
    let out = folder(dir, j);
    let stop = crate::interrupt::stop_flag();
    let mut hooks = crate::hooks::Cancel(&stop);
    crate::output::run_to_dir_live(&out, &scene, &Launch::default(), &mut hooks, None, None)
        .with_context(|| format!("recording member {j} into {}", out.display()))?;
    Ok(out)
}
