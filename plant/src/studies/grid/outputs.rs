//! What every grid's merged outputs share: the leading columns of `points.csv` (a single run's
//! point and an ensemble point write the same ones), the CSV writing, and the diagrams
//! coloured by post-shock mode.

use super::{Grid, Mode, Spacing};
use crate::analysis::classify::MotionMode;
use crate::plot::{self, PointGroup};
use anyhow::Context;
use std::path::Path;

crate::table::text_row! {
    /// The leading fields of a `points.csv` row, for single runs and ensembles alike.
    pub struct SingleFields {
        /// The swept value (`{:e}`).
        value,
        /// The post-shock mode's name.
        post_shock_mode,
        /// The steady class's name.
        steady_class,
        /// The period in revolutions (empty: none).
        period_k,
        /// Contact fraction (`{:e}`).
        contact_fraction,
        /// Whirl frequency (Hz, `{:e}`).
        whirl_hz,
        /// Largest radius (m, `{:e}`).
        max_radius_m,
        /// Largest contact force (N, `{:e}`).
        max_contact_force_n,
        /// The run's status.
        status,
        /// The point's index.
        index,
    }
}

/// The leading columns of `points.csv`, for single runs and ensembles alike (`value2` follows
/// them for maps): [`SingleFields`]'.
pub const SINGLE_COLUMNS: &[&str] = SingleFields::COLUMNS;

/// A number as the tables write it (`{:e}`).
pub fn e(v: f64) -> String {
    format!("{v:e}")
}

/// An optional number: empty when there is none.
pub fn opt(v: Option<f64>) -> String {
    v.map_or(String::new(), e)
}

/// A CSV table gathered in memory (its header written by hand), for [`finish`].
pub fn csv_writer() -> csv::Writer<Vec<u8>> {
    csv::WriterBuilder::new().has_headers(false).from_writer(Vec::new())
}

/// Writes a table gathered by a [`csv_writer`] (or any in-memory writer) to `path`, atomically:
/// two shards finishing together on a shared folder may both merge.
pub fn finish(w: csv::Writer<Vec<u8>>, path: &Path) -> anyhow::Result<()> {
    let bytes =
        w.into_inner().map_err(|e| anyhow::anyhow!("{e}")).with_context(|| format!("writing {}", path.display()))?;
    crate::outfile::write(path, &bytes)
}

/// The leading columns of a `points.csv` row, [`SINGLE_COLUMNS`] in their order: a single
/// run's point and an ensemble point (its modal figures) write the same ones.
#[allow(clippy::too_many_arguments)]
pub fn single_fields(
    value: f64,
    post_shock_mode: &str,
    steady_class: &str,
    period_k: Option<u32>,
    contact_fraction: f64,
    whirl_hz: f64,
    max_radius_m: f64,
    max_contact_force_n: f64,
    status: &str,
    index: usize,
) -> Vec<String> {
    SingleFields {
        value: e(value),
        post_shock_mode: post_shock_mode.to_string(),
        steady_class: steady_class.to_string(),
        period_k: period_k.map_or(String::new(), |k| k.to_string()),
        contact_fraction: e(contact_fraction),
        whirl_hz: e(whirl_hz),
        max_radius_m: e(max_radius_m),
        max_contact_force_n: e(max_contact_force_n),
        status: status.to_string(),
        index: index.to_string(),
    }
    .into_fields()
}

/// What the mode diagrams draw of a point.
pub struct ModePoint<'a> {
    /// Value of the first key.
    pub value: f64,
    /// Value of the second key (maps).
    pub value2: Option<f64>,
    /// The point's mode (an ensemble's most frequent).
    pub mode: Option<Mode>,
    /// Poincaré points (n, x, y).
    pub poincare: &'a [(i64, f64, f64)],
}

const MODES: [MotionMode; 3] = [MotionMode::Recovered, MotionMode::DryWhirl, MotionMode::Rebound];

/// Bifurcation diagrams coloured by mode (and the mode map of a 2-D grid): `map.png` for single
/// runs, `map_modes.png` ("most frequent") for ensembles, whose `map.png` is the probability.
pub fn mode_plots(grid: &Grid, dir: &Path, points: &[ModePoint], of_ensembles: bool) -> Result<(), plot::PlotError> {
    let Some(axis) = grid.axes.first() else { return Ok(()) };
    let key = &axis.key;
    let log = axis.spacing == Spacing::Log;
    let axis_value = |v: f64| if log { v.log10() } else { v };
    let axis_label = if log { format!("log10({key})") } else { key.clone() };
    let scene = grid.scene_name();
    for (coord, file) in [(0usize, "bifurcation_x.png"), (1, "bifurcation_y.png")] {
        let mut groups: Vec<(&str, Vec<f64>, Vec<f64>)> = Vec::new();
        for mode in MODES {
            let (mut xs, mut ys) = (Vec::new(), Vec::new());
            for p in points.iter().filter(|p| p.mode == Some(Mode::from(mode))) {
                for (_, x, y) in p.poincare {
                    xs.push(axis_value(p.value));
                    ys.push(if coord == 0 { *x } else { *y } * 1e6);
                }
            }
            groups.push((Mode::from(mode).name(), xs, ys));
        }
        let pg: Vec<PointGroup> =
            groups.iter().filter(|g| !g.1.is_empty()).map(|g| PointGroup { label: g.0, x: &g.1, y: &g.2 }).collect();
        if pg.is_empty() {
            continue;
        }
        let c = if coord == 0 { "x" } else { "y" };
        plot::scatter(
            &dir.join(file),
            &format!("{scene}: bifurcation diagram, {c}(nT) against {key}"),
            &axis_label,
            &format!("{c}(nT) (µm)"),
            &pg,
            false,
        )?;
    }
    if let Some(m) = grid.axes.get(1) {
        let log2 = m.spacing == Spacing::Log;
        let mut groups: Vec<(&str, Vec<f64>, Vec<f64>)> = Vec::new();
        for mode in MODES {
            let sel: Vec<_> = points.iter().filter(|p| p.mode == Some(Mode::from(mode))).collect();
            let xs = sel.iter().map(|p| axis_value(p.value)).collect();
            let ys = sel.iter().map(|p| p.value2.map_or(f64::NAN, |v| if log2 { v.log10() } else { v })).collect();
            groups.push((Mode::from(mode).name(), xs, ys));
        }
        let pg: Vec<PointGroup> =
            groups.iter().filter(|g| !g.1.is_empty()).map(|g| PointGroup { label: g.0, x: &g.1, y: &g.2 }).collect();
        if !pg.is_empty() {
            let file = if of_ensembles { "map_modes.png" } else { "map.png" };
            plot::scatter(
                &dir.join(file),
                &format!(
                    "{scene}: {}post-shock mode over {key} × {}",
                    if of_ensembles { "most frequent " } else { "" },
                    m.key
                ),
                &axis_label,
                &if log2 { format!("log10({})", m.key) } else { m.key.clone() },
                &pg,
                false,
            )?;
        }
    }
    Ok(())
}
