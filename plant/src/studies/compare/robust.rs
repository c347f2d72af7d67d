//! How robust a comparison is (`plant compare --robustness N`, issue 40 item 1): each compared
//! run gets the robustness answer `plant run --robustness N` gives (its perturbed members and
//! refined-integrator run, [`crate::robustness`]), and each run's difference from the
//! comparison's reference run (the continuous run of a rate comparison, the first law of a law
//! comparison) is said to lie within their spreads or beyond them: `compare_robustness.csv`
//! ([`RobustRow`]) and `compare_robustness.json` (the rows with each run's whole answer).
//!
//! **Within the spreads.** A figure (peak contact force, largest radius) of two runs differs
//! within their spreads when the ranges the runs' answers span overlap: least to largest over
//! the run and its perturbed members, widened to the refined-integrator run's figure. Two runs
//! whose figures could swap places under a perturbation below the model's uncertainty (or under
//! a finer integrator) are not told apart by the comparison. Their outcomes (motion modes) differ
//! within the spreads when either run's answer has the other's mode among its members or its
//! refined run, beyond them when neither does.

use crate::config::Scene;
use crate::ensemble::member::Figures;
use crate::robustness::{Robustness, Spread};
use crate::summary::Summary;
use serde::Serialize;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// How a compared run's figure or outcome stands against the reference run's.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Versus {
    /// The same (the same motion mode; for a figure, the same value).
    Same,
    /// Different, but within the two runs' spreads: not a difference the comparison shows.
    WithinSpread,
    /// Different beyond both runs' spreads.
    BeyondSpread,
    /// A run without the figure (no contact, or not finished).
    Unknown,
}

impl Versus {
    /// The name in the tables.
    pub fn name(self) -> &'static str {
        match self {
            Versus::Same => "same",
            Versus::WithinSpread => "within_spread",
            Versus::BeyondSpread => "beyond_spread",
            Versus::Unknown => "unknown",
        }
    }
}

crate::table::table_row! {
/// One compared run's robustness: a row of `compare_robustness.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct RobustRow {
    /// The run, as the comparison names it (`continuous`, `sampled 20000 Hz`, `lockstep 20000 Hz`, a law).
    pub run: String,
    /// `robust`, `fragile` or `unconverged` ([`Robustness::verdict`]).
    pub verdict: &'static str,
    /// The run's own motion mode.
    pub run_mode: &'static str,
    /// Perturbed members that ended in it, of `members`.
    pub same_mode: usize,
    /// Perturbed members.
    pub members: usize,
    /// Least and largest peak contact force over the run and its members (N).
    pub force_min_n: Option<f64>,
    /// Largest of them (N).
    pub force_max_n: Option<f64>,
    /// Least largest radius over the run and its members (m).
    pub radius_min_m: Option<f64>,
    /// Largest of them (m).
    pub radius_max_m: Option<f64>,
    /// The refined integrator's motion mode (empty when not asked for).
    pub refined_mode: Option<&'static str>,
    /// The outcome against the reference run's.
    pub mode_vs_reference: &'static str,
    /// The peak contact force against the reference run's.
    pub force_vs_reference: &'static str,
    /// The largest radius against the reference run's.
    pub radius_vs_reference: &'static str,
}
}

/// Header of `compare_robustness.csv`: [`RobustRow`]'s fields.
pub const ROBUST_HEADER: &str = RobustRow::HEADER;

/// The range a run's answer spans for one figure: its spread, widened to the refined run's.
fn range(spread: &Spread, refined: Option<f64>) -> Option<(f64, f64)> {
    let (lo, hi) = (spread.min?, spread.max?);
    Some(match refined.filter(|v| v.is_finite()) {
        Some(v) => (lo.min(v), hi.max(v)),
        None => (lo, hi),
    })
}

/// A figure of two runs: the runs' own values `a`, `b` and the ranges their answers span.
fn figure(a: f64, b: f64, ra: Option<(f64, f64)>, rb: Option<(f64, f64)>) -> Versus {
    if !(a.is_finite() && b.is_finite()) {
        return Versus::Unknown;
    }
    if a == b {
        return Versus::Same;
    }
    match (ra, rb) {
        (Some((lo_a, hi_a)), Some((lo_b, hi_b))) if lo_a <= hi_b && lo_b <= hi_a => Versus::WithinSpread,
        (Some(_), Some(_)) => Versus::BeyondSpread,
        _ => Versus::Unknown,
    }
}

/// Whether run `r` reached motion mode `mode` in any of its members or its refined run.
fn reaches(r: &Robustness, mode: &str) -> bool {
    r.run_mode == mode
        || r.modes.get(mode).is_some_and(|&n| n > 0)
        || r.integration.as_ref().is_some_and(|i| i.mode == mode)
}

/// How `run` stands against `reference` (each with its own figures: peak contact force and
/// largest radius, those its answer's spreads were formed around): `(mode, force, radius)` (pure).
pub fn versus(reference: (&Robustness, f64, f64), run: (&Robustness, f64, f64)) -> (Versus, Versus, Versus) {
    let ((ra, fa, xa), (rb, fb, xb)) = (reference, run);
    let mode = if ra.run_mode == rb.run_mode {
        Versus::Same
    } else if reaches(ra, rb.run_mode) || reaches(rb, ra.run_mode) {
        Versus::WithinSpread
    } else {
        Versus::BeyondSpread
    };
    let force = |r: &Robustness| range(&r.max_contact_force_n, r.integration.as_ref().map(|i| i.max_contact_force_n));
    let radius = |r: &Robustness| range(&r.max_radius_m, r.integration.as_ref().map(|i| i.max_radius_m));
    (mode, figure(fa, fb, force(ra), force(rb)), figure(xa, xb, radius(ra), radius(rb)))
}

/// One compared run with its own figures and its answer.
#[derive(Clone, Debug, Serialize)]
pub struct Answered {
    /// The run's name in the comparison.
    pub run: String,
    /// Its peak contact force (N).
    pub max_contact_force_n: f64,
    /// Its largest radius (m).
    pub max_radius_m: f64,
    /// Its robustness answer.
    pub robustness: Robustness,
}

/// The rows of `compare_robustness.csv`, each run against the first (the reference) (pure).
pub fn rows(runs: &[Answered]) -> Vec<RobustRow> {
    let Some(reference) = runs.first() else { return Vec::new() };
    fn of(a: &Answered) -> (&Robustness, f64, f64) {
        (&a.robustness, a.max_contact_force_n, a.max_radius_m)
    }
    runs.iter()
        .map(|a| {
            let r = &a.robustness;
            let (mode, force, radius) = versus(of(reference), of(a));
            RobustRow {
                run: a.run.clone(),
                verdict: r.verdict,
                run_mode: r.run_mode,
                same_mode: r.same_mode,
                members: r.members,
                force_min_n: r.max_contact_force_n.min,
                force_max_n: r.max_contact_force_n.max,
                radius_min_m: r.max_radius_m.min,
                radius_max_m: r.max_radius_m.max,
                refined_mode: r.integration.as_ref().map(|i| i.mode),
                mode_vs_reference: mode.name(),
                force_vs_reference: force.name(),
                radius_vs_reference: radius.name(),
            }
        })
        .collect()
}

/// The answer of the compared run `name` (its scene made from `scene_path` with `sets`, its
/// summary `summary`), when its scene asks for robustness members (`--robustness N`, or
/// `robustness.members`): the run's perturbed members and refined run, as `plant run
/// --robustness N` runs them ([`crate::robustness::assess`]). `None` when not asked for or
/// interrupted (the caller reads the stop flag).
pub fn answer(
    scene_path: &Path,
    sets: &[String],
    scene: &Scene,
    summary: &Summary,
    name: &str,
    log: &mut dyn FnMut(&str),
    stop: &AtomicBool,
) -> anyhow::Result<Option<Answered>> {
    let n = crate::robustness::members(scene)?;
    if n == 0 {
        return Ok(None);
    }
    let own = Figures::of_summary(summary);
    let Some(r) = crate::robustness::assess(scene_path, sets, scene, &own, n, stop)? else { return Ok(None) };
    log(&format!("{name}: robustness: {}", r.headline()));
    Ok(Some(Answered {
        run: name.to_owned(),
        max_contact_force_n: own.max_contact_force_n,
        max_radius_m: own.max_radius_m,
        robustness: r,
    }))
}

/// A run of `compare_robustness.json`: its row and its whole answer.
#[derive(Serialize)]
struct JsonRun<'a> {
    #[serde(flatten)]
    row: &'a RobustRow,
    max_contact_force_n: f64,
    max_radius_m: f64,
    robustness: &'a Robustness,
}

/// Writes `compare_robustness.csv` and `compare_robustness.json` into `out` (nothing when no
/// run was answered).
pub fn write(out: &Path, runs: &[Answered]) -> anyhow::Result<()> {
    if runs.is_empty() {
        return Ok(());
    }
    let table = rows(runs);
    crate::table::write_with_header(&out.join("compare_robustness.csv"), ROBUST_HEADER, &table)?;
    let json: Vec<JsonRun> = table
        .iter()
        .zip(runs)
        .map(|(row, a)| JsonRun {
            row,
            max_contact_force_n: a.max_contact_force_n,
            max_radius_m: a.max_radius_m,
            robustness: &a.robustness,
        })
        .collect();
    crate::output::write_json(
        &out.join("compare_robustness.json"),
        &serde_json::json!({ "reference": runs[0].run, "runs": json }),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ensemble::member::Figures;
    use crate::grid::Mode;
    use crate::robustness::judge;

    fn run(mode: Mode, force: f64) -> Figures {
        Figures::fixture(mode, if mode == Mode::Recovered { Some(0.1) } else { None }, 0.0, force)
    }

    fn answered(name: &str, own: Figures, members: &[Figures], refined: Option<Figures>) -> Answered {
        let r = judge(&own, members, refined.map(|f| (f, "rk4 with 64 substeps".to_string())));
        Answered {
            run: name.into(),
            max_contact_force_n: own.max_contact_force_n,
            max_radius_m: own.max_radius_m,
            robustness: r,
        }
    }

    /// Two runs whose force ranges overlap differ within their spreads; disjoint ranges differ
    /// beyond them; the refined run widens a range (the flexible scene's two branches, 5 119 N
    /// and 6 636 N: a run at 5 119 N whose refined run gives 6 636 N is not told apart from a run
    /// at 6 636 N); the outcome differs within the spreads when a member reached the other's.
    #[test]
    fn differences_within_and_beyond_the_spreads() {
        let reference = answered(
            "continuous",
            run(Mode::Recovered, 5000.0),
            &[run(Mode::Recovered, 5100.0), run(Mode::Recovered, 4900.0)],
            None,
        );
        let near = answered(
            "sampled 20000 Hz",
            run(Mode::Recovered, 5200.0),
            &[run(Mode::Recovered, 5050.0), run(Mode::Recovered, 5300.0)],
            None,
        );
        let far = answered(
            "sampled 5000 Hz",
            run(Mode::Rebound, 9000.0),
            &[run(Mode::Rebound, 8800.0), run(Mode::Rebound, 9100.0)],
            None,
        );
        let branch = answered(
            "lockstep 5000 Hz",
            run(Mode::Rebound, 6636.0),
            &[run(Mode::Rebound, 6600.0), run(Mode::Recovered, 6700.0)],
            None,
        );
        let refined = answered(
            "sampled 50000 Hz",
            run(Mode::Recovered, 4000.0),
            &[run(Mode::Recovered, 4010.0), run(Mode::Recovered, 3990.0)],
            Some(run(Mode::Recovered, 4950.0)),
        );
        let rows = rows(&[reference, near, far, branch, refined]);
        let got: Vec<(&str, &str, &str)> =
            rows.iter().map(|r| (r.mode_vs_reference, r.force_vs_reference, r.radius_vs_reference)).collect();
        assert_eq!(
            got,
            [
                ("same", "same", "same"),
                ("same", "within_spread", "within_spread"),
                ("beyond_spread", "beyond_spread", "beyond_spread"),
                ("within_spread", "beyond_spread", "beyond_spread"),
                ("same", "within_spread", "within_spread"),
            ]
        );
        assert_eq!((rows[3].verdict, rows[3].same_mode, rows[3].members), ("fragile", 1, 2));
        assert_eq!((rows[1].force_min_n, rows[1].force_max_n), (Some(5050.0), Some(5300.0)));
        assert_eq!(rows[4].refined_mode, Some("recovered"));
    }

    /// A run without contact has no peak force: its difference is unknown, not within.
    #[test]
    fn a_missing_figure_is_unknown() {
        let a = answered("a", run(Mode::Recovered, 5000.0), &[run(Mode::Recovered, 5000.0)], None);
        let b = answered("b", run(Mode::Recovered, f64::NAN), &[run(Mode::Recovered, f64::NAN)], None);
        let rows = rows(&[a, b]);
        assert_eq!(rows[1].force_vs_reference, "unknown");
    }
}
