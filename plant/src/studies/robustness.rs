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
//! **Integration error.** With `[robustness] integration` (on unless set to `false`), one more
//! run repeats the scene unperturbed with its integrator refined: an adaptive method (DP5,
//! DOP853) at a tenth of its tolerances, a fixed-step one with four times its substeps (and
//! contact substeps). A contact sequence whose branch the integrator's own error picks (the
//! flexible scene under coarse RK4 did) shows there, where the perturbed members, all run with
//! the same integrator, may agree among themselves.
//!
//! **The verdict.** `robust`: every member, and the refined run, ends in the run's motion
//! mode, and the refined run's peak contact force and largest radius are the run's within
//! [`CONVERGED`]; `fragile`: at least one ends in another mode (the run's outcome is one branch
//! of several); `unconverged`: all end in the run's mode, but the refined run's figures are not
//! the run's (the integrator's setting is too coarse for them). The
//! figures' spread (least, median, largest over the run and its perturbed members) says how
//! far a single-run figure can be trusted either way; the refined run's figures stand beside
//! them.

use crate::config::{load_scene, ConfigError, ControlMode, Scene};
use crate::ensemble::member::{figures, Figures};
use crate::ensemble::stats::quantile;
use crate::grid::Mode;
use crate::hooks::Cancel;
use crate::run::{run, Outcome};
pub use crate::summary::{IntegrationCheck, Robustness, Spread};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// The most perturbed members a run may ask for.
pub const MAX_MEMBERS: usize = 256;

/// How far (relative) the refined run's peak contact force and largest radius may be from the
/// run's for its figures to count as converged in the integrator.
pub const CONVERGED: f64 = 0.01;

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

/// The integration-error run's overrides and their description: an adaptive method at a tenth of
/// its tolerances, a fixed-step method with four times its substeps (at most the 100 000 the
/// scene allows).
pub fn refinement(scene: &Scene) -> Result<(Vec<String>, String), ConfigError> {
    let i = scene.resolved()?.integrator;
    let method = serde_json::to_value(i.method).ok().and_then(|v| v.as_str().map(str::to_owned)).unwrap_or_default();
    if i.method.is_adaptive() {
        let mut sets =
            vec![format!("integrator.rtol={:?}", i.rtol / 10.0), format!("integrator.atol={:?}", i.atol / 10.0)];
        let overrides = [
            ("atol_position_m", i.atol_position_m),
            ("atol_velocity_m_s", i.atol_velocity_m_s),
            ("atol_angle_rad", i.atol_angle_rad),
            ("atol_angular_speed_rad_s", i.atol_angular_speed_rad_s),
        ];
        sets.extend(overrides.iter().filter_map(|(k, v)| v.map(|v| format!("integrator.{k}={:?}", v / 10.0))));
        Ok((sets, format!("{method} at rtol {:e}, atol {:e}", i.rtol / 10.0, i.atol / 10.0)))
    } else {
        let four = |n: u32| n.saturating_mul(4).min(100_000);
        let sets = vec![
            format!("integrator.substeps={}", four(i.substeps)),
            format!("integrator.contact_substeps={}", four(i.contact_substeps)),
        ];
        Ok((sets, format!("{method} with {} substeps", four(i.substeps))))
    }
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
    let mut scenes = Vec::with_capacity(n + 1);
    for k in 1..=n {
        let mut sets = set.to_vec();
        sets.extend(perturbation(scene, k)?);
        scenes.push(load_scene(path, &sets)?);
    }
    let refined = match scene.resolved()?.robustness.is_some_and(|r| r.integration) {
        true => {
            let (extra, setting) = refinement(scene)?;
            let mut sets = set.to_vec();
            sets.extend(extra);
            scenes.push(load_scene(path, &sets)?);
            Some(setting)
        }
        false => None,
    };
    let results: Vec<anyhow::Result<Option<Figures>>> = crate::run::jobs::jobs_for(scene, || {
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
    let mut members = Vec::with_capacity(n + 1);
    for r in results {
        match r? {
            Some(f) => members.push(f),
            None => return Ok(None),
        }
    }
    let refined = refined.map(|setting| (members.pop().expect("the refined run is the last"), setting));
    Ok(Some(judge(own, &members, refined)))
}

/// The verdict and spreads of the run `own` among its perturbed `members`, and beside the run
/// `refined` with its integrator refined (and that setting, in words) (pure).
pub fn judge(own: &Figures, members: &[Figures], refined: Option<(Figures, String)>) -> Robustness {
    let mut modes: BTreeMap<&'static str, usize> = Mode::ALL.iter().map(|m| (m.name(), 0)).collect();
    for m in members {
        *modes.entry(m.mode.name()).or_default() += 1;
    }
    let same_mode = members.iter().filter(|m| m.mode == own.mode).count();
    let all: Vec<&Figures> = std::iter::once(own).chain(members).collect();
    let recoveries: Vec<f64> = all.iter().filter_map(|f| f.recovery_s).collect();
    let integration = refined.map(|(f, setting)| IntegrationCheck {
        setting,
        mode: f.mode.name(),
        same_mode: f.mode == own.mode,
        converged: [(f.max_contact_force_n, own.max_contact_force_n), (f.max_radius_m, own.max_radius_m)]
            .iter()
            .all(|&(a, b)| (a - b).abs() <= CONVERGED * a.abs().max(b.abs())),
        max_contact_force_n: f.max_contact_force_n,
        max_radius_m: f.max_radius_m,
        recovery_s: f.recovery_s,
    });
    let agrees = same_mode == members.len() && integration.as_ref().is_none_or(|i| i.same_mode);
    let converged = integration.as_ref().is_none_or(|i| i.converged);
    Robustness {
        members: members.len(),
        perturbation: format!(
            "the unbalance's angle by ±k·{ANGLE_STEP_RAD:e} rad and the rotor's initial x by ±k·{POSITION_STEP_M:e} m, \
             k = 1 … {}",
            members.len().div_ceil(2)
        ),
        verdict: match (agrees, converged) {
            (false, _) => "fragile",
            (true, false) => "unconverged",
            (true, true) => "robust",
        },
        run_mode: own.mode.name(),
        same_mode,
        modes,
        max_contact_force_n: spread(&all.iter().map(|f| f.max_contact_force_n).collect::<Vec<_>>()),
        max_radius_m: spread(&all.iter().map(|f| f.max_radius_m).collect::<Vec<_>>()),
        recovery_s: spread(&recoveries),
        still_touching: all.len() - recoveries.len(),
        integration,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(mode: Mode, force: f64, recovery_s: Option<f64>) -> Figures {
        Figures::fixture(mode, recovery_s, 0.0, force)
    }

    /// One member in another mode makes the run fragile; the spreads cover the run and its
    /// members; a member still touching has no recovery time and is counted.
    #[test]
    fn a_run_is_fragile_when_a_member_ends_otherwise() {
        let own = run(Mode::Recovered, 5000.0, Some(0.2));
        let same = [run(Mode::Recovered, 5100.0, Some(0.25)), run(Mode::Recovered, 4900.0, Some(0.1))];
        let r = judge(&own, &same, None);
        assert_eq!((r.verdict, r.same_mode, r.members, r.still_touching), ("robust", 2, 2, 0));
        assert_eq!(r.max_contact_force_n, Spread { min: Some(4900.0), median: Some(5000.0), max: Some(5100.0) });
        assert_eq!((r.recovery_s.min, r.recovery_s.max), (Some(0.1), Some(0.25)));
        let mixed = [run(Mode::Recovered, 5100.0, Some(0.25)), run(Mode::Rebound, 6600.0, None)];
        let r = judge(&own, &mixed, None);
        assert_eq!((r.verdict, r.same_mode, r.still_touching), ("fragile", 1, 1));
        assert_eq!((r.modes["recovered"], r.modes["rebound"], r.modes["dry_whirl"]), (1, 1, 0));
        assert!(r.headline().contains("1 of 2 perturbed runs recovered as this one (FRAGILE)"), "{}", r.headline());
        assert!(r.headline().contains("peak contact force 5000–6600 N"), "{}", r.headline());
    }

    /// A refined integrator that ends in another mode makes the run fragile though every
    /// perturbed member agrees; the headline says which setting and what it gave.
    #[test]
    fn a_run_is_fragile_when_the_refined_integrator_ends_otherwise() {
        let own = run(Mode::Recovered, 5000.0, Some(0.2));
        let same = [run(Mode::Recovered, 5100.0, Some(0.25)), run(Mode::Recovered, 4900.0, Some(0.1))];
        let agreeing = judge(&own, &same, Some((run(Mode::Recovered, 5050.0, Some(0.2)), "dp5 at rtol 1e-7".into())));
        assert_eq!(agreeing.verdict, "robust");
        assert!(agreeing.headline().contains("integrator refined (dp5 at rtol 1e-7): recovered as this one"));
        let r = judge(&own, &same, Some((run(Mode::Rebound, 6636.0, None), "rk4 with 64 substeps".into())));
        assert_eq!((r.verdict, r.same_mode), ("fragile", 2));
        let i = r.integration.as_ref().expect("the refined run");
        assert_eq!((i.mode, i.same_mode, i.max_contact_force_n, i.recovery_s), ("rebound", false, 6636.0, None));
        // The spreads stay those of the perturbed members and the run.
        assert_eq!(r.max_contact_force_n.max, Some(5100.0));
        assert!(
            r.headline().contains("rk4 with 64 substeps): rebound (another mode), peak contact force 6636 N"),
            "{}",
            r.headline()
        );
        // The same mode with another peak (the flexible scene at RK4 with 2 substeps: 35 343 N,
        // refined 5 102 N): the run's figures are not converged in the integrator.
        let own = run(Mode::Rebound, 35_343.0, None);
        let r =
            judge(&own, &[run(Mode::Rebound, 35_343.0, None)], Some((run(Mode::Rebound, 5102.0, None), "rk4".into())));
        assert_eq!(r.verdict, "unconverged");
        assert!(r.headline().contains("rebound as this one but with other figures"), "{}", r.headline());
        // Within 1 %: converged.
        let r = judge(&own, &[], Some((run(Mode::Rebound, 35_343.0 * 1.009, None), "rk4".into())));
        assert_eq!(r.verdict, "robust");
    }
}
