//! The merged outputs of a sweep or ensemble, written once every point is decided.
//!
//! Single runs: `points.csv` (`value, post_shock_mode, steady_class, period_k,
//! contact_fraction, whirl_hz, max_radius_m, max_contact_force_n, status, index`, plus
//! `value2` for maps), `poincare.csv` and the diagrams.
//!
//! Ensembles: `points.csv` with the same columns first (the most frequent mode and class, the
//! mean contact fraction, the median whirl rate, the largest radius and force of the members)
//! and then the statistics (see [`ENSEMBLE_COLUMNS`]); `members.csv` (one row per counted
//! member); `poincare.csv` (plus a `member` column: the first members' Poincaré points);
//! `sweep.json` (definition, statistics, thresholds, numerically sensitive points); charts.
//! A single scene's ensemble writes `ensemble.csv` (its statistics), `members.csv`,
//! `ensemble.json` and `members.png` instead.

use super::run::PointResult;
use super::{Kind, Spacing, Sweep};
use crate::analysis::classify::MotionMode;
use crate::ensemble::member::MemberResult;
use crate::ensemble::point::{point_stats, PointStats};
use crate::ensemble::stats::{thresholds, Threshold};
use crate::plot::{self, PointGroup};
use crate::summary::snake_name as name_of;
use anyhow::Context;
use serde::Serialize;
use std::path::Path;

/// The columns `points.csv` gets after the single-run columns for an ensemble.
pub const ENSEMBLE_COLUMNS: [&str; 15] = [
    "members",
    "recovered",
    "dry_whirl",
    "rebound",
    "diverged",
    "p_recovered",
    "p_lo",
    "p_hi",
    "recovery_median_s",
    "recovery_p90_s",
    "worst_contact_force_n",
    "verified",
    "numerically_sensitive",
    "sensitive",
    "stopped_by",
];

const SINGLE_COLUMNS: [&str; 10] = [
    "value",
    "post_shock_mode",
    "steady_class",
    "period_k",
    "contact_fraction",
    "whirl_hz",
    "max_radius_m",
    "max_contact_force_n",
    "status",
    "index",
];

fn e(v: f64) -> String {
    format!("{v:e}")
}

fn opt(v: Option<f64>) -> String {
    v.map_or(String::new(), e)
}

/// A CSV table gathered in memory (its header written by hand), for [`finish`].
fn csv_writer() -> csv::Writer<Vec<u8>> {
    csv::WriterBuilder::new().has_headers(false).from_writer(Vec::new())
}

/// The leading columns of a `points.csv` row, [`SINGLE_COLUMNS`] in their order: a single
/// run's point and an ensemble point (its modal figures) write the same ones.
#[allow(clippy::too_many_arguments)]
fn single_fields(
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
    vec![
        e(value),
        post_shock_mode.to_string(),
        steady_class.to_string(),
        period_k.map_or(String::new(), |k| k.to_string()),
        e(contact_fraction),
        e(whirl_hz),
        e(max_radius_m),
        e(max_contact_force_n),
        status.to_string(),
        index.to_string(),
    ]
}

fn finish(w: csv::Writer<Vec<u8>>, path: &Path) -> anyhow::Result<()> {
    let bytes =
        w.into_inner().map_err(|e| anyhow::anyhow!("{e}")).with_context(|| format!("writing {}", path.display()))?;
    // Atomic: two shards finishing together on a shared folder may both merge.
    crate::atomic::write(path, &bytes)
}

/// Writes the outputs of a sweep of single runs.
pub fn write_single(sweep: &Sweep, dir: &Path, points: &[&PointResult]) -> anyhow::Result<()> {
    let map = sweep.axes.len() > 1;
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
            &p.post_shock_mode,
            &p.steady_class,
            p.period_k,
            p.contact_fraction,
            p.whirl_hz,
            p.max_radius_m,
            p.max_contact_force_n,
            &p.status,
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
        .map(|p| ModePoint { value: p.value, value2: p.value2, mode: &p.post_shock_mode, poincare: &p.poincare })
        .collect();
    mode_plots(sweep, dir, &owned).context("writing sweep plots")?;
    Ok(())
}

/// What the mode diagrams draw of a point.
struct ModePoint<'a> {
    value: f64,
    value2: Option<f64>,
    mode: &'a str,
    poincare: &'a [(i64, f64, f64)],
}

const MODES: [MotionMode; 3] = [MotionMode::Recovered, MotionMode::DryWhirl, MotionMode::Rebound];

/// Bifurcation diagrams coloured by mode (and the mode map of a 2-D sweep) from
/// (value, value2, mode, Poincaré points).
fn mode_plots(sweep: &Sweep, dir: &Path, points: &[ModePoint]) -> Result<(), plot::PlotError> {
    let Some(axis) = sweep.axes.first() else { return Ok(()) };
    let key = &axis.key;
    let log = axis.spacing == Spacing::Log;
    let axis_value = |v: f64| if log { v.log10() } else { v };
    let axis_label = if log { format!("log10({key})") } else { key.clone() };
    let scene = sweep.scene_name();
    for (coord, file) in [(0usize, "bifurcation_x.png"), (1, "bifurcation_y.png")] {
        let mut groups: Vec<(String, Vec<f64>, Vec<f64>)> = Vec::new();
        for mode in MODES {
            let name = name_of(&mode);
            let (mut xs, mut ys) = (Vec::new(), Vec::new());
            for p in points.iter().filter(|p| p.mode == name) {
                for (_, x, y) in p.poincare {
                    xs.push(axis_value(p.value));
                    ys.push(if coord == 0 { *x } else { *y } * 1e6);
                }
            }
            groups.push((name, xs, ys));
        }
        let pg: Vec<PointGroup> =
            groups.iter().filter(|g| !g.1.is_empty()).map(|g| PointGroup { label: &g.0, x: &g.1, y: &g.2 }).collect();
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
    if let Some(m) = sweep.axes.get(1) {
        let log2 = m.spacing == Spacing::Log;
        let mut groups: Vec<(String, Vec<f64>, Vec<f64>)> = Vec::new();
        for mode in MODES {
            let name = name_of(&mode);
            let sel: Vec<_> = points.iter().filter(|p| p.mode == name).collect();
            let xs = sel.iter().map(|p| axis_value(p.value)).collect();
            let ys = sel.iter().map(|p| p.value2.map_or(f64::NAN, |v| if log2 { v.log10() } else { v })).collect();
            groups.push((name, xs, ys));
        }
        let pg: Vec<PointGroup> =
            groups.iter().filter(|g| !g.1.is_empty()).map(|g| PointGroup { label: &g.0, x: &g.1, y: &g.2 }).collect();
        if !pg.is_empty() {
            let file = if sweep.ensemble.is_some() { "map_modes.png" } else { "map.png" };
            plot::scatter(
                &dir.join(file),
                &format!(
                    "{scene}: {}post-shock mode over {key} × {}",
                    if sweep.ensemble.is_some() { "most frequent " } else { "" },
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

/// One row of `members.csv`.
#[derive(Serialize)]
struct MemberRow<'a> {
    point: usize,
    member: usize,
    value: Option<f64>,
    value2: Option<f64>,
    angle_deg: Option<f64>,
    drawn: String,
    mode: &'a str,
    steady_class: &'a str,
    period_k: Option<u32>,
    recovery_s: Option<f64>,
    contact_fraction: f64,
    max_radius_m: f64,
    max_contact_force_n: f64,
    status: &'a str,
    verified: bool,
    first_mode: &'a str,
    numerically_sensitive: bool,
}

/// A point's entry in `sweep.json`.
#[derive(Serialize)]
struct JsonPoint<'a> {
    value: Option<f64>,
    value2: Option<f64>,
    #[serde(flatten)]
    stats: &'a PointStats,
}

/// `sweep.json` / `ensemble.json`.
#[derive(Serialize)]
struct JsonSummary<'a> {
    program: &'static str,
    kind: Kind,
    scene: String,
    keys: Vec<&'a str>,
    member_setting: String,
    ensemble: &'a crate::ensemble::spec::EnsembleSpec,
    points: Vec<JsonPoint<'a>>,
    /// Crossings of 0.5 by the recovery probability (1-D sweeps).
    thresholds: Vec<Threshold>,
    numerically_sensitive_points: Vec<String>,
    sensitive_share: f64,
    members_run: usize,
    members_verified: usize,
}

/// The thresholds of a 1-D ensemble sweep, in the axis's own units.
pub fn sweep_thresholds(sweep: &Sweep, stats: &[PointStats]) -> Vec<Threshold> {
    let Some(axis) = sweep.axes.first().filter(|_| sweep.axes.len() == 1) else { return Vec::new() };
    let log = axis.spacing == Spacing::Log;
    let mut order: Vec<usize> = (0..stats.len()).collect();
    let x_of = |i: usize| {
        let v = axis.value(i);
        if log {
            v.log10()
        } else {
            v
        }
    };
    order.sort_by(|a, b| x_of(*a).total_cmp(&x_of(*b)));
    let x: Vec<f64> = order.iter().map(|&i| x_of(i)).collect();
    let p: Vec<f64> = order.iter().map(|&i| stats[i].p_recovered).collect();
    let lo: Vec<f64> = order.iter().map(|&i| stats[i].p_lo).collect();
    let hi: Vec<f64> = order.iter().map(|&i| stats[i].p_hi).collect();
    let back = |v: f64| if log { 10f64.powf(v) } else { v };
    thresholds(&x, &p, &lo, &hi)
        .into_iter()
        .map(|t| Threshold { value: back(t.value), interval: [back(t.interval[0]), back(t.interval[1])], ..t })
        .collect()
}

/// Writes the outputs of an ensemble sweep (or a single scene's ensemble) from each point's
/// counted members and the rule that stopped it. Returns what was written.
pub fn write_ensemble(
    sweep: &Sweep,
    dir: &Path,
    counted: &[(Vec<&MemberResult>, &'static str)],
) -> anyhow::Result<String> {
    let spec = sweep.ensemble.as_ref().context("not an ensemble")?;
    let stats: Vec<PointStats> =
        counted.iter().enumerate().map(|(i, (m, stopped))| point_stats(i, m, stopped)).collect();
    let values: Vec<(Option<f64>, Option<f64>)> = (0..sweep.len())
        .map(|i| {
            let v = sweep.point_values(i);
            (v.first().copied(), v.get(1).copied())
        })
        .collect();

    // members.csv
    let mut mw = csv::Writer::from_writer(Vec::new());
    for (i, (members, _)) in counted.iter().enumerate() {
        for m in members {
            let c = m.counted();
            mw.serialize(MemberRow {
                point: i,
                member: m.member,
                value: values[i].0,
                value2: values[i].1,
                angle_deg: m.angle_deg,
                drawn: m.drawn.join(" "),
                mode: &c.mode,
                steady_class: &c.steady_class,
                period_k: c.period_k,
                recovery_s: c.recovery_s,
                contact_fraction: c.contact_fraction,
                max_radius_m: c.max_radius_m,
                max_contact_force_n: c.max_contact_force_n,
                status: &c.status,
                verified: m.verified.is_some(),
                first_mode: &m.run.mode,
                numerically_sensitive: m.sensitive(),
            })?;
        }
    }
    finish(mw, &dir.join("members.csv"))?;

    let base = sweep.scene_for(0)?;
    let thresholds = sweep_thresholds(sweep, &stats);
    let sensitive: Vec<String> =
        stats.iter().filter(|s| s.numerically_sensitive > 0).map(|s| sweep.point_name(s.index)).collect();
    let summary = JsonSummary {
        program: super::store::PROGRAM,
        kind: sweep.kind,
        scene: sweep.scene_path.display().to_string(),
        keys: sweep.axes.iter().map(|a| a.key.as_str()).collect(),
        member_setting: crate::ensemble::member::setting_description(&base, spec),
        ensemble: spec,
        points: stats.iter().zip(&values).map(|(s, v)| JsonPoint { value: v.0, value2: v.1, stats: s }).collect(),
        thresholds,
        sensitive_share: sensitive.len() as f64 / stats.len().max(1) as f64,
        numerically_sensitive_points: sensitive,
        members_run: stats.iter().map(|s| s.members).sum(),
        members_verified: stats.iter().map(|s| s.verified).sum(),
    };
    let json_name = if sweep.kind == Kind::Ensemble { "ensemble.json" } else { "sweep.json" };
    crate::atomic::write(&dir.join(json_name), (serde_json::to_string_pretty(&summary)? + "\n").as_bytes())?;

    if sweep.kind == Kind::Ensemble {
        let mut w = csv::Writer::from_writer(Vec::new());
        for s in &stats {
            w.serialize(s)?;
        }
        finish(w, &dir.join("ensemble.csv"))?;
        crate::ensemble::charts::members_chart(sweep, dir, counted.first().map_or(&[][..], |c| &c.0[..]))
            .context("writing members.png")?;
        return Ok("ensemble.csv, members.csv, ensemble.json and members.png".into());
    }

    // points.csv: the single-run columns, then the statistics.
    let map = sweep.axes.len() > 1;
    let mut w = csv_writer();
    let mut header: Vec<&str> = SINGLE_COLUMNS.to_vec();
    if map {
        header.push("value2");
    }
    header.extend(ENSEMBLE_COLUMNS);
    w.write_record(&header)?;
    let mut pw = csv_writer();
    let mut pheader = vec!["value", "n", "x_m", "y_m"];
    if map {
        pheader.push("value2");
    }
    pheader.push("member");
    pw.write_record(&pheader)?;
    for (s, (members, _)) in stats.iter().zip(counted) {
        let (v1, v2) = values[s.index];
        let v1 = v1.unwrap_or(f64::NAN);
        let mut row = single_fields(
            v1,
            &s.post_shock_mode,
            &s.steady_class,
            s.period_k,
            s.contact_fraction,
            s.whirl_hz,
            s.max_radius_m,
            s.worst_contact_force_n,
            &s.status,
            s.index,
        );
        if map {
            row.push(opt(v2));
        }
        row.extend([
            s.members.to_string(),
            s.recovered.to_string(),
            s.dry_whirl.to_string(),
            s.rebound.to_string(),
            s.diverged.to_string(),
            e(s.p_recovered),
            e(s.p_lo),
            e(s.p_hi),
            opt(s.recovery_median_s),
            opt(s.recovery_p90_s),
            e(s.worst_contact_force_n),
            s.verified.to_string(),
            s.numerically_sensitive.to_string(),
            (s.numerically_sensitive > 0).to_string(),
            s.stopped_by.clone(),
        ]);
        w.write_record(&row)?;
        for m in members.iter().filter(|m| !m.poincare.is_empty()) {
            for (n, x, y) in &m.poincare {
                let mut r = vec![e(v1), n.to_string(), e(*x), e(*y)];
                if map {
                    r.push(opt(v2));
                }
                r.push(m.member.to_string());
                pw.write_record(&r)?;
            }
        }
    }
    finish(w, &dir.join("points.csv"))?;
    finish(pw, &dir.join("poincare.csv"))?;

    // Charts: bifurcation diagrams with the probability band (1-D) or the probability map.
    crate::ensemble::charts::sweep_charts(sweep, dir, &stats, counted, &summary.thresholds)
        .context("writing ensemble charts")?;
    if map {
        let pts: Vec<ModePoint> = stats
            .iter()
            .map(|s| ModePoint {
                value: values[s.index].0.unwrap_or(f64::NAN),
                value2: values[s.index].1,
                mode: &s.post_shock_mode,
                poincare: &[],
            })
            .collect();
        mode_plots(sweep, dir, &pts).context("writing the mode map")?;
        Ok("points.csv, members.csv, poincare.csv, sweep.json, map.png and map_modes.png".into())
    } else {
        Ok("points.csv, members.csv, poincare.csv, sweep.json, recovery_probability.png and the bifurcation diagrams"
            .into())
    }
}
