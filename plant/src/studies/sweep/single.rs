//! A sweep's point as a single run: its result file, its run, and the merged outputs
//! (`points.csv`: `value, post_shock_mode, steady_class, period_k, contact_fraction, whirl_hz,
//! max_radius_m, max_contact_force_n, status, index`, plus `value2` for maps; `poincare.csv`
//! and the diagrams).

use crate::analysis::classify::{MotionMode, SteadyClass};
use crate::grid::outputs::{csv_writer, e, finish, mode_plots, opt, single_fields, ModePoint, SINGLE_COLUMNS};
use crate::grid::store::{unit_key, Unit};
use crate::grid::{Grid, Mode, Point, Progress, Work};
use crate::hooks::Cancel;
use crate::run::{run, Outcome};
use crate::status::Status;
use crate::summary::Summary;
use anyhow::Context;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// The result of one point, as stored in `points/NNNNN.json`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PointResult {
    /// Point index.
    pub index: usize,
    /// Value of the swept key.
    pub value: f64,
    /// Value of the second key (maps), else null.
    pub value2: Option<f64>,
    /// How the run ended (`completed`, `diverged`, …).
    pub status: Status,
    /// Post-shock motion mode.
    pub post_shock_mode: MotionMode,
    /// Steady class.
    pub steady_class: SteadyClass,
    /// Period k.
    pub period_k: Option<u32>,
    /// Contact share over the last 200 revolutions.
    pub contact_fraction: f64,
    /// Mean whirl rate over the steady window (Hz, negative = backward).
    pub whirl_hz: f64,
    /// Largest rotor radius (m).
    pub max_radius_m: f64,
    /// Largest contact force (N).
    pub max_contact_force_n: f64,
    /// Poincaré points of the steady window: (n, x_m, y_m).
    pub poincare: Vec<(i64, f64, f64)>,
}

/// Each point one run of its scene.
pub struct Single;

/// Runs a point; `None` when it was interrupted.
pub fn run_point(point: &Point, stop: &AtomicBool) -> anyhow::Result<Option<PointResult>> {
    let scene = &point.scene;
    let result = run(scene, &mut Cancel(stop))?;
    if result.run.outcome == Outcome::Interrupted {
        return Ok(None);
    }
    let s = Summary::new(scene, &result);
    let a = &s.analysis;
    Ok(Some(PointResult {
        index: point.index,
        value: point.values.first().copied().unwrap_or(f64::NAN),
        value2: point.values.get(1).copied(),
        status: s.status,
        post_shock_mode: a.post_shock_mode,
        steady_class: a.steady_class,
        period_k: a.period_k,
        contact_fraction: s.contact_fraction,
        whirl_hz: a.whirl_hz,
        max_radius_m: s.max_radius_m.unwrap_or(0.0), // stored as a number (null would not read back)
        max_contact_force_n: s.max_contact_force_n.unwrap_or(0.0),
        poincare: a.section.iter().filter(|p| p.t_s >= a.steady_window_s[0]).map(|p| (p.n, p.x_m, p.y_m)).collect(),
    }))
}

impl Work for Single {
    type Result = PointResult;
    type Decision = ();

    fn members(&self) -> Option<usize> {
        None
    }

    fn rounds(&self) -> usize {
        1
    }

    fn noun(&self) -> &'static str {
        "points"
    }

    fn what(&self) -> &'static str {
        "sweep"
    }

    fn key(&self, point: &Point, member: Option<usize>) -> anyhow::Result<String> {
        unit_key(&point.scene, Unit { point: point.index, member }, None)
    }

    fn indices(&self, result: &PointResult) -> (usize, Option<usize>) {
        (result.index, None)
    }

    fn progress(&self, present: &BTreeMap<usize, PointResult>) -> Progress<()> {
        if present.contains_key(&0) {
            Progress::Decided { counted: 1, decision: () }
        } else {
            Progress::Needs { round: 0, missing: vec![0] }
        }
    }

    fn run(&self, point: &Point, _member: Option<usize>, stop: &AtomicBool) -> anyhow::Result<Option<PointResult>> {
        run_point(point, stop)
    }

    fn merge(&self, grid: &Grid, dir: &Path, points: &[(Vec<&PointResult>, ())]) -> anyhow::Result<String> {
        let points: Vec<&PointResult> = points.iter().flat_map(|(p, _)| p.iter().copied()).collect();
        write_single(grid, dir, &points)?;
        Ok("points.csv, poincare.csv and the diagrams".into())
    }
}

/// Writes the outputs of a sweep of single runs.
fn write_single(grid: &Grid, dir: &Path, points: &[&PointResult]) -> anyhow::Result<()> {
    let map = grid.axes.len() > 1;
    let second = |v: Option<f64>| if map { vec![opt(v)] } else { Vec::new() };
    let mut w = csv_writer();
    let mut header: Vec<&str> = SINGLE_COLUMNS.to_vec();
    let mut pw = csv_writer();
    let mut pheader = vec!["value", "n", "x_m", "y_m"];
    if map {
        header.push("value2");
        pheader.push("value2");
    }
    w.write_record(&header)?;
    pw.write_record(&pheader)?;
    for p in points {
        let mut row = single_fields(
            p.value,
            Mode::from(p.post_shock_mode).name(),
            p.steady_class.name(),
            p.period_k,
            p.contact_fraction,
            p.whirl_hz,
            p.max_radius_m,
            p.max_contact_force_n,
            p.status.name(),
            p.index,
        );
        row.extend(second(p.value2));
        w.write_record(&row)?;
        for (n, x, y) in &p.poincare {
            let mut r = vec![e(p.value), n.to_string(), e(*x), e(*y)];
            r.extend(second(p.value2));
            pw.write_record(&r)?;
        }
    }
    finish(w, &dir.join("points.csv"))?;
    finish(pw, &dir.join("poincare.csv"))?;
    let owned: Vec<ModePoint> = points
        .iter()
        .map(|p| ModePoint {
            value: p.value,
            value2: p.value2,
            mode: Some(Mode::from(p.post_shock_mode)),
            poincare: &p.poincare,
        })
        .collect();
    mode_plots(grid, dir, &owned, false).context("writing sweep plots")?;
    Ok(())
}
