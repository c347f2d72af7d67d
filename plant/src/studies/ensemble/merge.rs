//! The merged outputs of an ensemble sweep (or one scene's ensemble), written once every point
//! is decided.
//!
//! A sweep: `points.csv` with a sweep's columns first ([`crate::grid::outputs::SINGLE_COLUMNS`]:
//! the most frequent mode and class, the mean contact fraction, the median whirl rate, the
//! largest radius and force of the members) and then the statistics (see
//! [`ENSEMBLE_COLUMNS`]); `members.csv` (one row per counted member); `poincare.csv` (plus a
//! `member` column: the first members' Poincaré points); `sweep.json` (definition,
//! statistics, thresholds, numerically sensitive points); charts. A single scene's ensemble
//! writes `ensemble.csv` (its statistics), `members.csv`, `ensemble.json` and `members.png`
//! instead.

use crate::analysis::classify::SteadyClass;
use crate::ensemble::member::MemberResult;
use crate::ensemble::point::{point_stats, PointStats, StoppedBy};
use crate::ensemble::spec::EnsembleSpec;
use crate::ensemble::stats::{thresholds_along, Threshold};
use crate::grid::outputs::{csv_writer, e, finish, mode_plots, opt, single_fields, ModePoint, SINGLE_COLUMNS};
use crate::grid::{Grid, Kind, Mode, Spacing};
use crate::status::Status;
use anyhow::Context;
use serde::Serialize;
use std::path::Path;

crate::table::text_row! {
    /// The fields an ensemble's `points.csv` row has after the single-run ones: the point's
    /// statistics.
    pub struct EnsembleFields {
        /// Members counted.
        members,
        /// Members that recovered.
        recovered,
        /// Members in dry whirl.
        dry_whirl,
        /// Members rebounding.
        rebound,
        /// Members that diverged.
        diverged,
        /// Fraction recovered (`{:e}`).
        p_recovered,
        /// Its interval's lower end (`{:e}`).
        p_lo,
        /// Its interval's upper end (`{:e}`).
        p_hi,
        /// Median recovery time (s; empty: none).
        recovery_median_s,
        /// 90th percentile recovery time (s; empty: none).
        recovery_p90_s,
        /// Largest contact force of the members (N, `{:e}`).
        worst_contact_force_n,
        /// Members verified.
        verified,
        /// Members numerically sensitive.
        numerically_sensitive,
        /// Any member numerically sensitive.
        sensitive,
        /// Why the point's members stopped being drawn.
        stopped_by,
    }
}

/// The columns `points.csv` gets after the single-run columns for an ensemble:
/// [`EnsembleFields`]'.
pub const ENSEMBLE_COLUMNS: &[&str] = EnsembleFields::COLUMNS;

/// One row of `members.csv`.
#[derive(Serialize)]
struct MemberRow {
    point: usize,
    member: usize,
    value: Option<f64>,
    value2: Option<f64>,
    angle_deg: Option<f64>,
    drawn: String,
    mode: Mode,
    steady_class: SteadyClass,
    period_k: Option<u32>,
    recovery_s: Option<f64>,
    contact_fraction: f64,
    max_radius_m: f64,
    max_contact_force_n: f64,
    status: Status,
    verified: bool,
    first_mode: Mode,
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
    ensemble: &'a EnsembleSpec,
    points: Vec<JsonPoint<'a>>,
    /// Crossings of 0.5 by the recovery probability (1-D sweeps).
    thresholds: Vec<Threshold>,
    numerically_sensitive_points: Vec<String>,
    sensitive_share: f64,
    members_run: usize,
    members_verified: usize,
}

/// The thresholds of a 1-D ensemble sweep, in the axis's own units.
pub fn sweep_thresholds(grid: &Grid, stats: &[PointStats]) -> Vec<Threshold> {
    let Some(axis) = grid.axes.first().filter(|_| grid.axes.len() == 1) else { return Vec::new() };
    let values: Vec<f64> = (0..stats.len()).map(|i| axis.value(i)).collect();
    let column = |f: fn(&PointStats) -> f64| -> Vec<f64> { stats.iter().map(f).collect() };
    thresholds_along(
        &values,
        axis.spacing == Spacing::Log,
        &column(|s| s.tally.share.value),
        &column(|s| s.tally.share.lo),
        &column(|s| s.tally.share.hi),
    )
}

/// Writes the outputs of an ensemble sweep (or a single scene's ensemble) from each point's
/// counted members and the rule that stopped it. Returns what was written.
pub fn write_ensemble(
    grid: &Grid,
    spec: &EnsembleSpec,
    dir: &Path,
    counted: &[(Vec<&MemberResult>, StoppedBy)],
) -> anyhow::Result<String> {
    let stats: Vec<PointStats> =
        counted.iter().enumerate().map(|(i, (m, stopped))| point_stats(i, m, *stopped)).collect();
    let values: Vec<(Option<f64>, Option<f64>)> = (0..grid.len())
        .map(|i| {
            let v = grid.point_values(i);
            (v.first().copied(), v.get(1).copied())
        })
        .collect();

    write_members(counted, &values, dir)?;

    let base = grid.scene_for(0)?;
    let thresholds = sweep_thresholds(grid, &stats);
    let sensitive: Vec<String> =
        stats.iter().filter(|s| s.verification.numerically_sensitive > 0).map(|s| grid.point_name(s.index)).collect();
    let summary = JsonSummary {
        program: crate::grid::store::PROGRAM,
        kind: grid.kind,
        scene: grid.scene_path.display().to_string(),
        keys: grid.axes.iter().map(|a| a.key.as_str()).collect(),
        member_setting: crate::ensemble::member::setting_description(&base, spec),
        ensemble: spec,
        points: stats.iter().zip(&values).map(|(s, v)| JsonPoint { value: v.0, value2: v.1, stats: s }).collect(),
        thresholds,
        sensitive_share: sensitive.len() as f64 / stats.len().max(1) as f64,
        numerically_sensitive_points: sensitive,
        members_run: stats.iter().map(|s| s.tally.members).sum(),
        members_verified: stats.iter().map(|s| s.verification.verified).sum(),
    };
    let json_name = if grid.kind == Kind::Ensemble { "ensemble.json" } else { "sweep.json" };
    crate::outfile::write(&dir.join(json_name), (serde_json::to_string_pretty(&summary)? + "\n").as_bytes())?;

    if grid.kind == Kind::Ensemble {
        let mut w = csv::Writer::from_writer(Vec::new());
        for s in &stats {
            w.serialize(s)?;
        }
        finish(w, &dir.join("ensemble.csv"))?;
        crate::ensemble::charts::members_chart(grid, dir, counted.first().map_or(&[][..], |c| &c.0[..]))
            .context("writing members.png")?;
        return Ok("ensemble.csv, members.csv, ensemble.json and members.png".into());
    }

    let map = grid.axes.len() > 1;
    write_points(&stats, counted, &values, map, dir)?;

    // Charts: bifurcation diagrams with the probability band (1-D) or the probability map.
    crate::ensemble::charts::sweep_charts(grid, dir, &stats, counted, &summary.thresholds)
        .context("writing ensemble charts")?;
    if map {
        let pts: Vec<ModePoint> = stats
            .iter()
            .map(|s| ModePoint {
                value: values[s.index].0.unwrap_or(f64::NAN),
                value2: values[s.index].1,
                mode: s.typical.post_shock_mode,
                poincare: &[],
            })
            .collect();
        mode_plots(grid, dir, &pts, true).context("writing the mode map")?;
        Ok("points.csv, members.csv, poincare.csv, sweep.json, map.png and map_modes.png".into())
    } else {
        Ok("points.csv, members.csv, poincare.csv, sweep.json, recovery_probability.png and the bifurcation diagrams"
            .into())
    }
}

/// `members.csv`: a row per counted member of every point.
fn write_members(
    counted: &[(Vec<&MemberResult>, StoppedBy)],
    values: &[(Option<f64>, Option<f64>)],
    dir: &Path,
) -> anyhow::Result<()> {
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
                mode: c.mode,
                steady_class: c.steady_class,
                period_k: c.period_k,
                recovery_s: c.recovery_s,
                contact_fraction: c.contact_fraction,
                max_radius_m: c.max_radius_m,
                max_contact_force_n: c.max_contact_force_n,
                status: c.status,
                verified: m.verified.is_some(),
                first_mode: m.run.mode,
                numerically_sensitive: m.sensitive(),
            })?;
        }
    }
    finish(mw, &dir.join("members.csv"))?;
    Ok(())
}

/// `points.csv` (the single-run columns, then the statistics; `map`: a second swept value) and
/// `poincare.csv` (the kept members' Poincaré points).
fn write_points(
    stats: &[PointStats],
    counted: &[(Vec<&MemberResult>, StoppedBy)],
    values: &[(Option<f64>, Option<f64>)],
    map: bool,
    dir: &Path,
) -> anyhow::Result<()> {
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
            s.typical.post_shock_mode.map_or("", Mode::name),
            s.typical.steady_class.map_or("", SteadyClass::name),
            s.typical.period_k,
            s.contact_fraction,
            s.whirl_hz,
            s.max_radius_m,
            s.worst_contact_force_n,
            s.status.name(),
            s.index,
        );
        if map {
            row.push(opt(v2));
        }
        row.extend(
            EnsembleFields {
                members: s.tally.members.to_string(),
                recovered: s.tally.recovered.to_string(),
                dry_whirl: s.tally.dry_whirl.to_string(),
                rebound: s.tally.rebound.to_string(),
                diverged: s.tally.diverged.to_string(),
                p_recovered: e(s.tally.share.value),
                p_lo: e(s.tally.share.lo),
                p_hi: e(s.tally.share.hi),
                recovery_median_s: opt(s.tally.recovery.median_s),
                recovery_p90_s: opt(s.tally.recovery.p90_s),
                worst_contact_force_n: e(s.worst_contact_force_n),
                verified: s.verification.verified.to_string(),
                numerically_sensitive: s.verification.numerically_sensitive.to_string(),
                sensitive: (s.verification.numerically_sensitive > 0).to_string(),
                stopped_by: crate::summary::snake_name(&s.stopped_by),
            }
            .into_fields(),
        );
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
    Ok(())
}
