//! How robust a run's outcome is: the run repeated with perturbations far below the model's own
//! uncertainty (`plant run --robustness N`, or `[robustness] members = N` in the scene), its
//! members run in parallel, and the outcome's distribution and the spread of the headline
//! figures written beside the run's own (`summary.json`'s `robustness`, the run's last line).
//!
//! **The perturbation.** Member `k` (1 … N) turns the rotor's unbalance (its angle at t = 0) by
//! `±⌈k/2⌉ · 10⁻⁹ rad` (odd members forward, even members back), and moves the rotor's initial
//! position by `±⌈k/2⌉ · 10⁻¹²` m in x (a picometre: the sensor's noise is a thousand times
//! larger). Nothing a user could measure or set tells these runs apart: a figure or an outcome
//! that changes among them is a branch of the contact sequence that integration round-off
//! could have picked as well, not a property of the machine or the controller.
//!
//! **The verdict.** `robust`: every member ends in the run's motion mode; `fragile`: at least
//! one does not (the run's outcome is one branch of several). The figures' spread (least,
//! median, largest over the run and its members) says how far a single-run figure can be
//! trusted either way.

use crate::config::{load_scene, ConfigError, ControlMode, Scene};
use crate::ensemble::member::{figures, Figures};
use crate::ensemble::stats::quantile;
use crate::grid::Mode;
use crate::hooks::Cancel;
use crate::run::{run, Outcome};
pub use crate::summary::{Robustness, Spread};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// The most perturbed members a run may ask for.
pub const MAX_MEMBERS: usize = 256;

/// The unbalance angle's step (rad).
pub const ANGLE_STEP_RAD: f64 = 1e-9;

/// The initial position's step (m).
pub const POSITION_STEP_M: f64 = 1e-12;

/// The members a scene asks for (`[robustness] members`, 0: none), checked: bad input at load.
pub fn members(scene: &Scene) -> Result<usize, ConfigError> {
    let raw = scene.resolved()?;
    let Some(r) = raw.robustness else { return Ok(0) };
    if !(0..=MAX_MEMBERS as i64).contains(&r.members) {
        return Err(ConfigError::Range {
            key: "robustness.members".into(),
            value: r.members.to_string(),
            unit: String::new(),
            why: format!("must be 0 (none) to {MAX_MEMBERS} perturbed runs"),
        });
    }
    if r.members > 0 && scene.controller.mode == ControlMode::Realtime {
        return Err(ConfigError::Range {
            key: "robustness.members".into(),
            value: r.members.to_string(),
            unit: String::new(),
            why: "a realtime run's members would differ by their timing, not by the perturbation: ask for the \
                  robustness of the same scene in lockstep (controller.mode = \"lockstep\")"
                .into(),
        });
    }
    Ok(r.members as usize)
}

/// The overrides of member `k` (1 …): the unbalance turned and the rotor moved, both forward for
/// odd `k` and back for even `k`, by `⌈k/2⌉` steps.
pub fn perturbation(scene: &Scene, k: usize) -> Result<Vec<String>, ConfigError> {
    let raw = scene.resolved()?;
    let steps = k.div_ceil(2) as f64 * if k % 2 == 1 { 1.0 } else { -1.0 };
    let phase = raw.rotor.unbalance_phase_deg + (steps * ANGLE_STEP_RAD).to_degrees();
    let x = raw.initial.rotor_x_um + steps * POSITION_STEP_M * 1e6;
    Ok(vec![format!("rotor.unbalance_phase_deg={phase:?}"), format!("initial.rotor_x_um={x:?}")])
}

fn spread(values: &[f64]) -> Spread {
    let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    Spread {
        min: finite.iter().copied().reduce(f64::min),
        median: quantile(&finite, 0.5),
        max: finite.iter().copied().reduce(f64::max),
    }
}

/// Runs the `n` perturbed members of the scene at `path` (with the overrides `set` that made
/// `scene`) in parallel and judges them against the run's own `own` figures; `None` when
/// interrupted.
pub fn assess(
    path: &Path,
    set: &[String],
    scene: &Scene,
    own: &Figures,
    n: usize,
    stop: &AtomicBool,
) -> anyhow::Result<Option<Robustness>> {
    let mut scenes = Vec::with_capacity(n);
    for k in 1..=n {
        let mut sets = set.to_vec();
        sets.extend(perturbation(scene, k)?);
        scenes.push(load_scene(path, &sets)?);
    }
    let results: Vec<anyhow::Result<Option<Figures>>> = crate::assess::jobs_for(scene, || {
        scenes
            .par_iter()
            .map(|s| {
                let result = run(s, &mut Cancel(stop))?;
                if result.run.outcome == Outcome::Interrupted {
                    return Ok(None);
                }
                Ok(Some(figures(s, &result).0))
            })
            .collect()
    });
    let mut members = Vec::with_capacity(n);
    for r in results {
        match r? {
            Some(f) => members.push(f),
            None => return Ok(None),
        }
    }
    Ok(Some(judge(own, &members)))
}

/// The verdict and spreads of the run `own` among its `members` (pure).
pub fn judge(own: &Figures, members: &[Figures]) -> Robustness {
    let mut modes: BTreeMap<&'static str, usize> = Mode::ALL.iter().map(|m| (m.name(), 0)).collect();
    for m in members {
        *modes.entry(m.mode.name()).or_default() += 1;
    }
    let same_mode = members.iter().filter(|m| m.mode == own.mode).count();
    let all: Vec<&Figures> = std::iter::once(own).chain(members).collect();
    let recoveries: Vec<f64> = all.iter().filter_map(|f| f.recovery_s).collect();
    Robustness {
        members: members.len(),
        perturbation: format!(
            "the unbalance's angle by ±k·{ANGLE_STEP_RAD:e} rad and the rotor's initial x by ±k·{POSITION_STEP_M:e} m, \
             k = 1 … {}",
            members.len().div_ceil(2)
        ),
        verdict: if same_mode == members.len() { "robust" } else { "fragile" },
        run_mode: own.mode.name(),
        same_mode,
        modes,
        max_contact_force_n: spread(&all.iter().map(|f| f.max_contact_force_n).collect::<Vec<_>>()),
        max_radius_m: spread(&all.iter().map(|f| f.max_radius_m).collect::<Vec<_>>()),
        recovery_s: spread(&recoveries),
        still_touching: all.len() - recoveries.len(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::classify::SteadyClass;
    use crate::status::Status;

    fn run(mode: Mode, force: f64, recovery_s: Option<f64>) -> Figures {
        Figures {
            status: Status::Completed,
            mode,
            steady_class: SteadyClass::Periodic,
            period_k: Some(1),
            recovery_s,
            contact_fraction: 0.0,
            whirl_hz: 0.0,
            max_radius_m: force * 1e-8,
            max_contact_force_n: force,
            steady_window_start_s: 1.1,
            wall_time_s: 0.0,
        }
    }

    /// One member in another mode makes the run fragile; the spreads cover the run and its
    /// members; a member still touching has no recovery time and is counted.
    #[test]
    fn a_run_is_fragile_when_a_member_ends_otherwise() {
        let own = run(Mode::Recovered, 5000.0, Some(0.2));
        let same = [run(Mode::Recovered, 5100.0, Some(0.25)), run(Mode::Recovered, 4900.0, Some(0.1))];
        let r = judge(&own, &same);
        assert_eq!((r.verdict, r.same_mode, r.members, r.still_touching), ("robust", 2, 2, 0));
        assert_eq!(r.max_contact_force_n, Spread { min: Some(4900.0), median: Some(5000.0), max: Some(5100.0) });
        assert_eq!((r.recovery_s.min, r.recovery_s.max), (Some(0.1), Some(0.25)));
        let mixed = [run(Mode::Recovered, 5100.0, Some(0.25)), run(Mode::Rebound, 6600.0, None)];
        let r = judge(&own, &mixed);
        assert_eq!((r.verdict, r.same_mode, r.still_touching), ("fragile", 1, 1));
        assert_eq!((r.modes["recovered"], r.modes["rebound"], r.modes["dry_whirl"]), (1, 1, 0));
        assert!(r.headline().contains("1 of 2 perturbed runs recovered as this one (FRAGILE)"), "{}", r.headline());
        assert!(r.headline().contains("peak contact force 5000–6600 N"), "{}", r.headline());
    }
}
