//! `soak.json`: the soak's figures, its resident memory and its criteria, judged.

use super::monitor::ShockFigures;
use super::programme::{Criteria, Programme};
use super::sink::RssSample;
use crate::cosim::CosimReport;
use crate::run::{Outcome, SinkRun};
use crate::status::Status;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// Resident-memory figures of one process (KiB; growth in MiB).
#[derive(Clone, Debug, Default, Serialize)]
pub struct ProcessRss {
    /// First sample.
    pub start_kib: u64,
    /// Last sample.
    pub end_kib: u64,
    /// Largest sample.
    pub max_kib: u64,
    /// Last less first (MiB).
    pub growth_mib: f64,
}

/// The `rss` object of `soak.json`.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RssReport {
    /// Rows of `rss.csv`.
    pub samples: usize,
    /// Sampling period (simulated s).
    pub every_s: f64,
    /// The plant (this process); null without `/proc`.
    pub plant: Option<ProcessRss>,
    /// The controller process; null if never sampled.
    pub controller: Option<ProcessRss>,
}

/// Recovery times of the recovered shocks (s); null when none recovered.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Spread {
    /// Smallest.
    pub min: Option<f64>,
    /// Median.
    pub median: Option<f64>,
    /// Mean.
    pub mean: Option<f64>,
    /// Largest.
    pub max: Option<f64>,
}

/// One criterion of the programme, judged.
#[derive(Clone, Debug, Serialize)]
pub struct CriterionResult {
    /// Key in `[criteria]`.
    pub criterion: &'static str,
    /// The limit.
    pub limit: f64,
    /// What was measured (null: not measured, which fails).
    pub measured: Option<f64>,
    /// Unit of both.
    pub unit: &'static str,
    /// Met.
    pub passed: bool,
}

impl std::fmt::Display for CriterionResult {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let unit = if self.unit.is_empty() { String::new() } else { format!(" {}", self.unit) };
        let measured = self.measured.map_or("not measured".to_string(), |m| format!("{m}{unit}"));
        let op = if self.criterion.starts_with("min_") { ">=" } else { "<=" };
        write!(f, "{}: measured {measured}, limit {op} {}{unit}", self.criterion, self.limit)
    }
}

/// `soak.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Programme name.
    pub programme: String,
    /// Programme file.
    pub programme_file: String,
    /// `completed`, `diverged`, `interrupted`, `peer_lost`, … ([`Status`]).
    pub status: Status,
    /// What stopped the run early.
    pub error: Option<String>,
    /// Simulated time reached (s).
    pub simulated_s: f64,
    /// Simulated time planned (s).
    pub planned_s: f64,
    /// A soak continued from its checkpoint (`plant soak --resume`): the simulated time it
    /// continued from (s). Its figures per shock cover the whole soak; `sequence_gaps`,
    /// `deadline_misses`, `realtime_factor` and `cosim` cover the part after this time.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resumed_from_s: Option<f64>,
    /// Wall time of the whole soak, start-up and outputs included (s).
    pub wall_time_s: f64,
    /// Simulated over loop wall time.
    pub realtime_factor: f64,
    /// Shocks in the programme.
    pub shocks: usize,
    /// Windows that ran to their end.
    pub shocks_completed: usize,
    /// Shocks recovered.
    pub recovered: usize,
    /// `recovered / shocks`.
    pub recovered_fraction: f64,
    /// Recovery times of the recovered shocks.
    pub recovery_s: Spread,
    /// Largest contact force over the soak (N).
    pub max_contact_force_n: f64,
    /// Total time in contact (s).
    pub contact_time_s: f64,
    /// Sequence gaps: messages lost.
    pub sequence_gaps: u64,
    /// Deadline misses (realtime).
    pub deadline_misses: u64,
    /// Their share of the ticks with a reply due.
    pub deadline_miss_fraction: f64,
    /// Resident memory.
    pub rss: RssReport,
    /// The recovery rule: hold (s).
    pub recovery_hold_s: f64,
    /// The recovery rule: clear radius (m) (bearing plane A's, of a two-plane rotor).
    pub recovery_clear_radius_m: f64,
    /// Each bearing plane's clear radius (m), A then B: a two-plane rotor's planes each have
    /// their own air gap.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub recovery_clear_radius_per_plane_m: Option<Vec<f64>>,
    /// The programme's criteria, judged (only those given).
    pub criteria: Vec<CriterionResult>,
    /// All criteria met and the run completed.
    pub passed: bool,
    /// The co-simulation's own figures.
    pub cosim: Option<CosimReport>,
}

impl Report {
    /// One line of what the soak did: status, time, recoveries, force, messages, memory.
    pub fn headline(&self) -> String {
        let fmt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3}"));
        let rss = |p: &Option<ProcessRss>| {
            p.as_ref().map_or("not measured".to_string(), |p| {
                format!(
                    "{:.1} -> {:.1} MiB (max {:.1})",
                    p.start_kib as f64 / 1024.0,
                    p.end_kib as f64 / 1024.0,
                    p.max_kib as f64 / 1024.0
                )
            })
        };
        format!(
            "{} {:.3} of {:.3} s simulated in {:.1} s; recovered {}/{} shocks (recovery s: min {}, median {}, max {}); \
             max contact force {:.0} N; sequence gaps {}, deadline misses {} ({:.2e}); RSS plant {}, controller {}",
            self.status,
            self.simulated_s,
            self.planned_s,
            self.wall_time_s,
            self.recovered,
            self.shocks,
            fmt(self.recovery_s.min),
            fmt(self.recovery_s.median),
            fmt(self.recovery_s.max),
            self.max_contact_force_n,
            self.sequence_gaps,
            self.deadline_misses,
            self.deadline_miss_fraction,
            rss(&self.rss.plant),
            rss(&self.rss.controller),
        )
    }
}

/// A soak's outcome: how the run ended and the report written.
pub struct Finished {
    /// How the run ended.
    pub outcome: Outcome,
    /// What `soak.json` holds.
    pub report: Report,
    /// What the live view served (`plant soak --live`).
    pub live: Option<crate::live::Served>,
}

fn process_rss(samples: impl Iterator<Item = Option<u64>>) -> Option<ProcessRss> {
    let v: Vec<u64> = samples.flatten().collect();
    let (first, last) = (*v.first()?, *v.last()?);
    Some(ProcessRss {
        start_kib: first,
        end_kib: last,
        max_kib: v.iter().copied().max().unwrap_or(0),
        growth_mib: (last as f64 - first as f64) / 1024.0,
    })
}

pub(crate) fn report(
    prog: &Programme,
    programme_file: &Path,
    result: &SinkRun,
    figures: &[ShockFigures],
    rss: &[RssSample],
    started: Instant,
) -> Report {
    let (status, error) = (result.outcome.status(), result.outcome.error());
    let mut times: Vec<f64> = figures.iter().filter(|f| f.recovered).map(|f| f.recovery_s).collect();
    times.sort_by(f64::total_cmp);
    let spread = if times.is_empty() {
        Spread::default()
    } else {
        let n = times.len();
        let median = if n % 2 == 1 { times[n / 2] } else { 0.5 * (times[n / 2 - 1] + times[n / 2]) };
        Spread {
            min: Some(times[0]),
            median: Some(median),
            mean: Some(times.iter().sum::<f64>() / n as f64),
            max: Some(times[n - 1]),
        }
    };
    let recovered = times.len();
    let shocks = prog.shocks.len();
    let cosim = result.cosim.clone();
    let (gaps, misses, miss_fraction) =
        cosim.as_ref().map_or((0, 0, 0.0), |c| (c.sequence_gaps, c.deadline_misses, c.deadline_miss_fraction));
    let rss = RssReport {
        samples: rss.len(),
        every_s: prog.rss_every,
        plant: process_rss(rss.iter().map(|s| s.plant_kib)),
        controller: process_rss(rss.iter().map(|s| s.controller_kib)),
    };
    let max_force = figures.iter().map(|f| f.max_contact_force_n).fold(0.0, f64::max);
    let mut report = Report {
        programme: prog.name.clone(),
        programme_file: programme_file.display().to_string(),
        status,
        error,
        simulated_s: result.clock.simulated,
        planned_s: prog.scene.duration,
        resumed_from_s: (result.clock.started > 0.0).then_some(result.clock.started),
        wall_time_s: started.elapsed().as_secs_f64(),
        realtime_factor: (result.clock.simulated - result.clock.started) / result.clock.wall_time.max(1e-12),
        shocks,
        shocks_completed: figures.iter().filter(|f| f.complete).count(),
        recovered,
        recovered_fraction: recovered as f64 / shocks.max(1) as f64,
        recovery_s: spread,
        max_contact_force_n: max_force,
        contact_time_s: figures.iter().map(|f| f.contact_time_s).sum(),
        sequence_gaps: gaps,
        deadline_misses: misses,
        deadline_miss_fraction: miss_fraction,
        rss,
        recovery_hold_s: prog.hold,
        recovery_clear_radius_m: prog.clear_radius[0],
        recovery_clear_radius_per_plane_m: (prog.clear_radius.len() > 1).then(|| prog.clear_radius.clone()),
        criteria: Vec::new(),
        passed: false,
        cosim,
    };
    report.criteria = judge(&prog.criteria, &report);
    report.passed = report.status == Status::Completed && report.criteria.iter().all(|v| v.passed);
    report
}

/// Judges each given criterion against the report's figures.
pub fn judge(c: &Criteria, r: &Report) -> Vec<CriterionResult> {
    let mut out = Vec::new();
    let mut check = |criterion, limit: Option<f64>, measured: Option<f64>, unit, at_least: bool| {
        if let Some(limit) = limit {
            let passed = measured.is_some_and(|m| if at_least { m >= limit } else { m <= limit });
            out.push(CriterionResult { criterion, limit, measured, unit, passed });
        }
    };
    check("min_recovered_fraction", c.min_recovered_fraction, Some(r.recovered_fraction), "", true);
    // Over the recovered shocks; with none recovered there is nothing over the limit.
    check("max_recovery_s", c.max_recovery_s, Some(r.recovery_s.max.unwrap_or(0.0)), "s", false);
    check("max_sequence_gaps", c.max_sequence_gaps.map(|g| g as f64), Some(r.sequence_gaps as f64), "", false);
    check("max_deadline_miss_fraction", c.max_deadline_miss_fraction, Some(r.deadline_miss_fraction), "", false);
    let growth = match (&r.rss.plant, &r.rss.controller) {
        (Some(p), Some(c)) => Some(p.growth_mib.max(c.growth_mib)),
        _ => None,
    };
    check("max_rss_growth_mib", c.max_rss_growth_mib, growth, "MiB", false);
    check("max_contact_force_n", c.max_contact_force_n, Some(r.max_contact_force_n), "N", false);
    out
}
