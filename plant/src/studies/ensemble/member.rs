//! One member of an ensemble: its scene (the point's scene, the members' integrator setting and
//! the member's draws, all as `--set` overrides so that `plant run SCENE --set …` reproduces
//! it), its run, and its verification at the reference setting when its outcome is close to a
//! decision.
//!
//! **Members' setting** (`ensemble.integrator = "fast"`, the default, overriding the scene's
//! integrator): the race parked while the gap is clear, RK4 with one step per controller tick,
//! and `integrator.contact_substeps` from the stability estimate at a 10 kN contact
//! ([`crate::stability::safe_contact_substeps`]). `plant bench engineering` shows it keeping the
//! reference's modes and engineering figures on the 3 G and 10 G scenes; `plant bench ensemble`
//! compares the classification of a set of members against the scene's own setting.
//!
//! **Verification**: a member is close to a decision when it is still rebounding at the end
//! with intermittent impacts (`rebound` with a contact share over the steady window below
//! `ensemble.verify_rebound`, default 0.5), when its run diverged, or when it recovered late: its
//! last contact came after `ensemble.verify_late` of the time from the shock's start to the start
//! of the steady window (the last 200 revolutions, over which the mode is decided). A sustained
//! rebound (in contact for most of the window, e.g. 58 % at r_0 = 0.16 – 0.2 mm on the 10 G
//! scene) is a regime, not a knife edge: re-running it at the reference costs 20 – 40 fast
//! members and never changed its mode in the air-gap study. It is then re-run at the
//! reference setting: DOP853 at `ensemble.verify_rtol` (default 1e-10) with absolute tolerances
//! scaled per component (r_0, 2π, r_0 Ω, Ω), the race free. The verified run counts; when its
//! mode differs from the first run's the member is `numerically_sensitive`.

use crate::analysis::classify::SteadyClass;
use crate::config::{load_scene, Scene};
use crate::ensemble::spec::{Draw, EnsembleSpec, MemberSetting};
use crate::grid::{Mode, Point};
use crate::hooks::Cancel;
use crate::integrate::Method;
use crate::run::{run, Outcome, RunResult};
use crate::status::Status;
use crate::summary::{snake_name, Summary};
use serde::{Deserialize, Serialize};
use std::sync::atomic::AtomicBool;

/// Members whose Poincaré points are kept (for the bifurcation diagrams and `poincare.csv`).
pub const POINCARE_MEMBERS: usize = 8;

/// The figures of one run of a member.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Figures {
    /// How the run ended (`completed`, `diverged`, …).
    pub status: Status,
    /// `recovered`, `dry_whirl`, `rebound`, or `diverged` when the run did not complete.
    pub mode: Mode,
    /// Steady class.
    pub steady_class: SteadyClass,
    /// Period k.
    pub period_k: Option<u32>,
    /// Time from the first shock's start to the last contact (s); `None` if still touching.
    pub recovery_s: Option<f64>,
    /// Contact share over the last 200 revolutions.
    pub contact_fraction: f64,
    /// Mean whirl rate over the steady window (Hz).
    pub whirl_hz: f64,
    /// Largest rotor radius (m).
    pub max_radius_m: f64,
    /// Largest rotor – race contact force (N).
    pub max_contact_force_n: f64,
    /// Start of the steady window (s).
    pub steady_window_start_s: f64,
    /// Wall time of the run (s): for throughput figures only, never in the merged tables.
    pub wall_time_s: f64,
}

/// A member's record, as stored in `points/NNNNN/MMMMM.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MemberResult {
    /// Point index.
    pub point: usize,
    /// Member index.
    pub member: usize,
    /// Rotor angle at the shock's arrival (deg), if drawn.
    pub angle_deg: Option<f64>,
    /// The drawn values as `--set` overrides.
    pub drawn: Vec<String>,
    /// The run at the members' setting.
    pub run: Figures,
    /// The run at the reference setting, for members close to a decision.
    pub verified: Option<Figures>,
    /// Poincaré points of the counted run's steady window (members below [`POINCARE_MEMBERS`]).
    pub poincare: Vec<(i64, f64, f64)>,
}

impl MemberResult {
    /// Member `j` of `point`: its draw, its run at the members' setting and its verification;
    /// no Poincaré points yet.
    pub fn new(
        point: &Point,
        j: usize,
        draw: &Draw,
        drawn: Vec<String>,
        run: Figures,
        verified: Option<Figures>,
    ) -> Self {
        Self { point: point.index, member: j, angle_deg: draw.angle_deg, drawn, run, verified, poincare: Vec::new() }
    }

    /// The run that counts: the verified one if there is one.
    pub fn counted(&self) -> &Figures {
        self.verified.as_ref().unwrap_or(&self.run)
    }

    /// True when verification changed the mode.
    pub fn sensitive(&self) -> bool {
        self.verified.as_ref().is_some_and(|v| v.mode != self.run.mode)
    }
}

/// The figures of a run: the one place that reads [`Summary`] for ensembles.
pub fn figures(scene: &Scene, result: &RunResult) -> (Figures, Vec<(i64, f64, f64)>) {
    let s = Summary::new(scene, result);
    let a = &s.analysis;
    let f = Figures::of_summary(&s);
    let poincare = a.section.iter().filter(|p| p.t_s >= a.steady_window_s[0]).map(|p| (p.n, p.x_m, p.y_m)).collect();
    (f, poincare)
}

impl Figures {
    /// The figures a run's [`Summary`] gives.
    pub fn of_summary(s: &Summary) -> Self {
        let a = &s.analysis;
        Figures {
            status: s.status,
            mode: Mode::of_run(s.status, a.post_shock_mode),
            steady_class: a.steady_class,
            period_k: a.period_k,
            recovery_s: s.recovery_s,
            contact_fraction: s.contact_fraction,
            whirl_hz: a.whirl_hz,
            max_radius_m: s.max_radius_m.unwrap_or(0.0), // stored as a number (null would not read back)
            max_contact_force_n: s.max_contact_force_n.unwrap_or(0.0),
            steady_window_start_s: s.steady_window_start_s,
            wall_time_s: s.wall_time_s,
        }
    }
}

#[cfg(test)]
impl Figures {
    /// A completed, periodic (k = 1) member in `mode` for the tests: its recovery time, contact
    /// fraction and peak contact force (N) as given, its largest radius `force` × 1e-8 m.
    pub(crate) fn fixture(mode: Mode, recovery_s: Option<f64>, contact_fraction: f64, force: f64) -> Self {
        Figures {
            status: Status::Completed,
            mode,
            steady_class: SteadyClass::Periodic,
            period_k: Some(1),
            recovery_s,
            contact_fraction,
            whirl_hz: 0.0,
            max_radius_m: force * 1e-8,
            max_contact_force_n: force,
            steady_window_start_s: 1.1,
            wall_time_s: 0.0,
        }
    }
}

/// `--set` overrides of the members' setting for a point's scene (empty for `scene`).
pub fn setting_overrides(scene: &Scene, setting: MemberSetting) -> Vec<String> {
    match setting {
        MemberSetting::Scene => Vec::new(),
        MemberSetting::Fast => scene.fixed_step_overrides(),
    }
}

/// A sentence on the members' setting, for the outputs.
pub fn setting_description(scene: &Scene, spec: &EnsembleSpec) -> String {
    let own = match scene.integrator.method {
        m if m.is_adaptive() => format!("{} rtol {:e}", snake_name(&m), scene.integrator.rtol),
        m => format!("{} with {} substeps", snake_name(&m), scene.integrator.substeps),
    };
    let members = match spec.integrator {
        MemberSetting::Fast => format!(
            "members run on the fast setting, overriding the scene's integrator ({own}): race parked while the gap is \
             clear, rk4 with 1 step per tick, contact_substeps = {}",
            crate::stability::safe_contact_substeps(scene, Method::Rk4).max(1)
        ),
        MemberSetting::Scene => format!("members run on the scene's own integrator ({own})"),
    };
    if spec.verify {
        format!(
            "{members}; members close to a decision (rebound in contact for less than {} of the steady window, \
             diverged, or recovered after {} of the time from the shock to the steady window) are re-run on dop853 \
             rtol {:e} with scaled atol, race free",
            spec.verify_rebound, spec.verify_late, spec.verify_rtol
        )
    } else {
        format!("{members}; no verification")
    }
}

/// `--set` overrides of the reference setting that verifies a member.
pub fn verify_overrides(scene: &Scene, rtol: f64) -> Vec<String> {
    let [p, v, a, w] = scene.atol_scale_groups();
    vec![
        "integrator.method=\"dop853\"".into(),
        format!("integrator.rtol={rtol:?}"),
        format!("integrator.atol_position_m={:?}", rtol * p),
        format!("integrator.atol_angle_rad={:?}", rtol * a),
        format!("integrator.atol_velocity_m_s={:?}", rtol * v),
        format!("integrator.atol_angular_speed_rad_s={:?}", rtol * w),
        "touchdown.race_when_clear=\"free\"".into(),
    ]
}

/// The overrides of a member's verification run: the point's, the reference setting's, then the
/// member's draws (`drawn`).
pub fn verification_overrides(point: &Point, spec: &EnsembleSpec, drawn: &[String]) -> Vec<String> {
    let mut sets = point.sets.to_vec();
    sets.extend(verify_overrides(&point.scene, spec.verify_rtol));
    sets.extend(drawn.iter().cloned());
    sets
}

/// `--set` overrides of a draw on a point's scene.
///
/// The angle at the shock's arrival θ sets the unbalance phase at t = 0: with the spin held,
/// θ = φ_0 + Ω t_shock, so φ_0 = θ − Ω t_shock (mod 360°). With `rotor.spin = "free"` the speed
/// before the shock is held by the drive, so the same holds to within the drive's error.
pub fn draw_overrides(scene: &Scene, spec: &EnsembleSpec, draw: &Draw) -> Vec<String> {
    // The scene loaded once already: reading it back cannot fail but for a bug; then no draw.
    let Ok(raw) = scene.resolved() else { return Vec::new() };
    let mut out = Vec::new();
    if let Some(angle) = draw.angle_deg {
        let turned = raw.rotor.speed_hz * 360.0 * scene.first_shock_start();
        out.push(format!("rotor.unbalance_phase_deg={:?}", (angle - turned).rem_euclid(360.0)));
    }
    for (k, shock) in raw.shock.iter().enumerate() {
        if spec.direction_deg > 0.0 {
            out.push(format!("shock[{k}].direction_deg={:?}", shock.direction_deg() + draw.direction_offset_deg));
        }
        if spec.peak_rel > 0.0 {
            if let Some((field, v)) = shock.size() {
                out.push(format!("shock[{k}].{field}={:?}", v * draw.peak_factor));
            }
        }
    }
    if spec.eccentricity_rel > 0.0 {
        out.push(format!("rotor.eccentricity_um={:?}", raw.rotor.eccentricity_um * draw.eccentricity_factor));
    }
    for (v, x) in spec.vary.iter().zip(&draw.vary) {
        out.push(format!("{}={x:?}", v.key));
    }
    out
}

/// The overrides of member `j`'s first run, and its draw.
pub fn member_overrides(point: &Point, spec: &EnsembleSpec, j: usize) -> (Vec<String>, Draw, Vec<String>) {
    let draw = spec.draw(j);
    let drawn = draw_overrides(&point.scene, spec, &draw);
    let mut sets = point.sets.clone();
    sets.extend(setting_overrides(&point.scene, spec.integrator));
    sets.extend(drawn.iter().cloned());
    (sets, draw, drawn)
}

/// True when a run's outcome is close to a decision (see the module doc).
pub fn close_to_decision(f: &Figures, shock_start: f64, spec: &EnsembleSpec) -> bool {
    let late = spec.verify_late;
    match f.mode {
        Mode::Diverged => true,
        Mode::Rebound => f.contact_fraction < spec.verify_rebound,
        Mode::Recovered => {
            let span = f.steady_window_start_s - shock_start;
            f.recovery_s.is_some_and(|r| span > 0.0 && r > late * span)
        }
        Mode::DryWhirl => false,
    }
}

/// Runs member `j` of a point; `None` when interrupted.
pub fn run_member(
    point: &Point,
    spec: &EnsembleSpec,
    j: usize,
    stop: &AtomicBool,
) -> anyhow::Result<Option<MemberResult>> {
    let (sets, draw, drawn) = member_overrides(point, spec, j);
    let scene = load_scene(point.path, &sets)?;
    let result = run(&scene, &mut Cancel(stop))?;
    if result.run.outcome == Outcome::Interrupted {
        return Ok(None);
    }
    let (first, mut poincare) = figures(&scene, &result);
    drop(result);
    let mut verified = None;
    if spec.verify && close_to_decision(&first, scene.first_shock_start(), spec) {
        let reference = load_scene(point.path, &verification_overrides(point, spec, &drawn))?;
        let result = run(&reference, &mut Cancel(stop))?;
        if result.run.outcome == Outcome::Interrupted {
            return Ok(None);
        }
        let (f, p) = figures(&reference, &result);
        verified = Some(f);
        poincare = p;
    }
    if j >= POINCARE_MEMBERS {
        poincare.clear();
    }
    Ok(Some(MemberResult { poincare, ..MemberResult::new(point, j, &draw, drawn, first, verified) }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figures(mode: Mode, recovery_s: Option<f64>, contact_fraction: f64) -> Figures {
        Figures::fixture(mode, recovery_s, contact_fraction, 0.0)
    }

    #[test]
    fn close_calls_are_late_recoveries_intermittent_rebounds_and_divergences() {
        let spec = EnsembleSpec::default();
        // Shock at 0.02 s, window from 1.1 s: "late" is after 0.75 × 1.08 = 0.81 s.
        assert!(!close_to_decision(&figures(Mode::Recovered, Some(0.55), 0.0), 0.02, &spec));
        assert!(close_to_decision(&figures(Mode::Recovered, Some(0.9), 0.0), 0.02, &spec));
        assert!(close_to_decision(&figures(Mode::Rebound, None, 0.17), 0.02, &spec));
        assert!(!close_to_decision(&figures(Mode::Rebound, None, 0.58), 0.02, &spec));
        assert!(!close_to_decision(&figures(Mode::DryWhirl, None, 1.0), 0.02, &spec));
        assert!(close_to_decision(&figures(Mode::Diverged, None, 0.0), 0.02, &spec));
    }
}
