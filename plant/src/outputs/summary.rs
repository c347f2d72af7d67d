//! The figures of a run, written as `summary.json`.
//!
//! They are taken as the rows come ([`FiguresBuilder`], with the analysis's
//! [`crate::analysis::Analyzer`]), so that a run of any length needs the
//! same memory. After a divergence the maxima are over the rows before the
//! failure (the row at the failure holds the state that failed, which is
//! reported on its own as `failure_state`).

use crate::analysis::tilt::TiltAnalysis;
use crate::analysis::Analysis;
use crate::config::{DragChoice, ForceLaw, RaceWhenClearChoice, ReleaseChoice, Scene, SpinChoice, SupportChoice};
pub use crate::figures::{analysis_spec, plane_analysis_spec, recovery_time, Figures, FiguresBuilder};
use crate::record::{PlaneRecorded, Recorded, Recorder};
use crate::run::{RunError, RunResult, SinkRun};
use crate::status::Status;
use serde::Serialize;

/// The name a unit enum variant serialises to (`dry_whirl`, `rk4`, …), as written in the outputs.
pub fn snake_name<T: Serialize>(v: &T) -> String {
    serde_json::to_value(v).ok().and_then(|v| v.as_str().map(str::to_owned)).unwrap_or_default()
}

pub use crate::analysis::STEADY_REVOLUTIONS;

/// Model choices of a run, for the record: the validated choices, serialised as the scene
/// file writes them.
#[derive(Clone, Debug, Serialize)]
pub struct ModelInfo {
    /// `two_plane` for the two-plane rotor (`rotor.model`; not written for the planar model).
    #[serde(skip_serializing_if = "is_planar")]
    pub rotor: crate::config::RotorModel,
    /// `held` or `free` (`rotor.spin`).
    pub spin: SpinChoice,
    /// `rotating` or `fixed`.
    pub cage: crate::model::Cage,
    /// `constant` or `palmgren` (`touchdown.drag`).
    pub race_drag: DragChoice,
    /// `balls` or `lumped` (`touchdown.support`).
    pub race_support: SupportChoice,
    /// `free` or `parked`: the race while the gap is clear (`touchdown.race_when_clear`).
    pub race_when_clear: RaceWhenClearChoice,
    /// With a parked race: `equilibrium` or `held`, the state it is released with.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub race_release: Option<ReleaseChoice>,
    /// `linear` or `nonlinear` (`amb.force_law`).
    pub amb_force: ForceLaw,
    /// Number of balls.
    pub balls: usize,
    /// Controller mode.
    pub control_mode: crate::config::ControlMode,
    /// Control law.
    pub law: String,
    /// Controller rate (Hz).
    pub controller_rate_hz: f64,
    /// Command delay (samples), sampled modes.
    pub delay_samples: u32,
    /// A flexible rotor from a ROSS file: the file's plain bearings and what became of each
    /// (`added`, `ignored`, `parallel`; `rotor.ross_bearings`); not written when there are none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub ross_bearings: Vec<plant_physics::flex::ross::UsedBearing>,
    /// A flexible rotor from a ROSS file: the file's `MagneticBearingElement`s made the planes'
    /// AMBs and what each plane took from it (`rotor.ross_ambs`); not written when there are none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub ross_ambs: Vec<plant_physics::flex::ross_amb::UsedAmb>,
    /// Each plane's axis angle θ (degrees, `amb.axis_angle_deg`): the coil pairs' and sensors'
    /// axes (u, v) the currents and the wire speak in; not written when every plane's is 0°.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub amb_axis_angle_deg: Vec<f64>,
}

impl ModelInfo {
    /// The model choices of a scene.
    pub fn new(scene: &Scene) -> Self {
        // The model choices (`[touchdown]`, `rotor.spin`) are every plane's: plane A's say them.
        let (p, c) = (scene.plane(0), &scene.controller);
        let (race_when_clear, race_release) = RaceWhenClearChoice::of(&p.race_when_clear);
        ModelInfo {
            rotor: scene.rotor.model(),
            spin: SpinChoice::of(&p.spin),
            cage: p.cage,
            race_drag: DragChoice::of(&p.drag),
            race_support: SupportChoice::of(&p.support),
            race_when_clear,
            race_release,
            amb_force: ForceLaw::of(&p.amb),
            balls: p.balls.count(),
            control_mode: c.mode,
            law: c.law.clone(),
            controller_rate_hz: 1.0 / c.period,
            delay_samples: c.delay_samples,
            ross_bearings: scene.rotor.params().file_bearings().to_vec(),
            ross_ambs: scene.rotor.params().file_ambs().to_vec(),
            amb_axis_angle_deg: if scene.rotor.bearings().any(|b| b.axes.turned()) {
                scene.rotor.bearings().map(|b| b.axes.angle().to_degrees()).collect()
            } else {
                Vec::new()
            },
        }
    }
}

fn is_planar(m: &crate::config::RotorModel) -> bool {
    *m == crate::config::RotorModel::Planar
}

/// Integrator of a run, for the record.
#[derive(Clone, Debug, Serialize)]
pub struct IntegratorInfo {
    /// Method.
    pub method: crate::integrate::Method,
    /// Relative tolerance (adaptive methods).
    pub rtol: f64,
    /// Absolute tolerances per state component (adaptive methods).
    pub atol: Vec<f64>,
    /// Substeps per controller period (fixed-step methods).
    pub substeps: u32,
    /// Substeps per controller period while the race is free (fixed-step methods, parked race).
    pub contact_substeps: u32,
    /// Macro step (s).
    pub macro_step_s: f64,
    /// Realtime runs: `fixed` (the fixed-step setting of bounded cost replaced the scene's
    /// integrator) or `scene` (`integrator.realtime`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub realtime: Option<crate::config::RealtimeSetting>,
    /// The most evaluations of the model the integrator made in one tick.
    pub max_rhs_evals_per_tick: u64,
}

/// `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// `completed`, `diverged`, `interrupted`, `peer_lost` (co-simulation: the controller was lost), … ([`Status`]).
    pub status: Status,
    /// What went wrong, with time and state.
    pub error: Option<String>,
    /// When it went wrong (s).
    pub failure_time_s: Option<f64>,
    /// The state that failed, after a divergence (the maxima below are over the rows before it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure_state: Option<FailureState>,
    /// Simulated time reached (s).
    pub simulated_s: f64,
    /// The time of the saved state the run started from (s), `plant run --from-state`; absent
    /// for a run from t = 0. Its trace and figures cover the time after it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub started_s: Option<f64>,
    /// Largest rotor radius relative to the housing (m), over the rows before a failure;
    /// `null` when there is no such row (a run that failed at its first row).
    pub max_radius_m: Option<f64>,
    /// Fraction of trace samples with rotor – race contact over the last 200 revolutions
    /// (the analysis's `steady_contact_fraction`).
    pub contact_fraction: f64,
    /// Start of the window of `contact_fraction` (s).
    pub steady_window_start_s: f64,
    /// Largest rotor – race normal force at the trace samples (N); `null` without a row.
    pub max_contact_force_n: Option<f64>,
    /// Largest race speed (rpm); `null` without a row.
    pub max_race_speed_rpm: Option<f64>,
    /// Time from the first shock's start to the last trace sample with rotor – race contact (s):
    /// 0 without contact after the shock, `null` if the rotor is still touching at the end.
    pub recovery_s: Option<f64>,
    /// A run started from a saved state: from its first row to its last sample with contact
    /// (s), 0 without contact, `null` if still touching at the end; absent for a run from t = 0.
    /// Its grading window is `takeover`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub recovery_from_start_s: Option<Option<f64>>,
    /// Time in rotor – race contact over the whole run (s), counted on the trace samples.
    pub contact_time_s: f64,
    /// Fraction of macro steps run with the race parked (0 unless `race_when_clear = "parked"`).
    pub parked_fraction: f64,
    /// Controller ticks whose command was non-finite (the last valid one was held; see
    /// `controller.max_invalid_burst`, `controller.max_invalid_fraction`).
    pub invalid_commands: u64,
    /// Time with an amplifier at its voltage limit (s), in runs with amplifiers
    /// (`amb.amplifier`); with unipolar amplifiers, any magnet's (docs/MODEL.md §12.3).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub voltage_saturation_s: Option<f64>,
    /// Accepted integrator steps.
    pub steps: u64,
    /// Rejected steps (adaptive methods).
    pub rejected_steps: u64,
    /// Right-hand-side evaluations by the integrator.
    pub rhs_evals: u64,
    /// Wall time of the simulation loop (s).
    pub wall_time_s: f64,
    /// Simulated seconds per wall-clock second.
    pub realtime_factor: f64,
    /// Model choices.
    pub model: ModelInfo,
    /// Integrator.
    pub integrator: IntegratorInfo,
    /// Spectra, Poincaré section and classification of the response.
    #[serde(flatten)]
    pub analysis: Analysis,
    /// How robust the outcome is: the run repeated with perturbations (`plant run --robustness
    /// N`, `[robustness] members`); absent unless asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub robustness: Option<Robustness>,
    /// Co-simulation figures (`lockstep`, `realtime` modes only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cosim: Option<crate::cosim::CosimReport>,
    /// A two-plane run's figures per bearing plane and its tilt (the figures above are those of
    /// the governing plane, `planes.governing`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub planes: Option<PlanesSummary>,
    /// A bending rotor's run: the rotor at mid-span, its largest radius and the shaft's largest
    /// bow there ([`crate::analysis::mid_span`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mid_span: Option<crate::analysis::mid_span::MidSpan>,
}

/// One bearing plane's figures in a two-plane run's `summary.json` (the planar summary's, for
/// this plane).
#[derive(Clone, Debug, Serialize)]
pub struct PlaneSummary {
    /// Largest rotor radius at the bearing relative to the housing (m); `null` over no row.
    pub max_radius_m: Option<f64>,
    /// Fraction of samples with contact over the steady window.
    pub contact_fraction: f64,
    /// Largest rotor – race normal force (N); `null` over no row.
    pub max_contact_force_n: Option<f64>,
    /// Largest race speed (rpm); `null` over no row.
    pub max_race_speed_rpm: Option<f64>,
    /// From the first shock's start to the last sample in contact (s); `null` if still touching.
    pub recovery_s: Option<f64>,
    /// Time in contact over the run (s).
    pub contact_time_s: f64,
    /// Time of the first sample with rotor – race contact (s); `null` if the plane never touched.
    pub first_contact_s: Option<f64>,
    /// The plane's analysis (spectra, Poincaré section, classification).
    #[serde(flatten)]
    pub analysis: Analysis,
}

/// A two-plane run's per-plane figures and tilt.
#[derive(Clone, Debug, Serialize)]
pub struct PlanesSummary {
    /// The plane whose figures the summary's top level holds: `a` or `b`, the one with the
    /// larger steady contact fraction, then the larger peak contact force, then `a`.
    pub governing: &'static str,
    /// Bearing plane A.
    pub a: PlaneSummary,
    /// Bearing plane B.
    pub b: PlaneSummary,
    /// The rotor's tilt.
    pub tilt: TiltAnalysis,
}

impl PlaneSummary {
    fn new(p: &PlaneRecorded, simulated: f64) -> Self {
        Self {
            max_radius_m: p.figures.max_radius_m,
            contact_fraction: p.analysis.steady_contact_fraction,
            max_contact_force_n: p.figures.max_contact_force_n,
            max_race_speed_rpm: p.figures.max_race_speed_rpm,
            recovery_s: p.figures.recovery_s,
            contact_time_s: p.figures.contact_share() * simulated,
            first_contact_s: p.figures.first_contact_s,
            analysis: p.analysis.clone(),
        }
    }
}

impl Summary {
    /// One line of what the run did: status, time, speed, largest radius and force.
    pub fn headline(&self) -> String {
        let or_none = |v: Option<f64>, scale: f64, decimals: usize, unit: &str| match v {
            Some(v) => format!("{:.*} {unit}", decimals, v * scale),
            None => "none (no row before the failure)".to_string(),
        };
        format!(
            "{} {} s simulated in {:.2} s ({:.2}x real time); max radius {}, max contact force {}",
            self.status,
            crate::argument::shown(self.simulated_s),
            self.wall_time_s,
            self.realtime_factor,
            or_none(self.max_radius_m, 1e6, 1, "µm"),
            or_none(self.max_contact_force_n, 1.0, 0, "N"),
        ) + &self.takeover_words()
    }

    /// A run from a saved state: what its grade covers (empty for a run from t = 0).
    fn takeover_words(&self) -> String {
        match &self.analysis.takeover {
            None => String::new(),
            Some(t) if t.settled => format!(
                "; {} graded over {:.0} revolutions from {:.4} s, after {:.3} s of settling from the first row at {:.4} s",
                self.analysis.post_shock_mode.name(),
                t.window_revolutions,
                t.window_s[0],
                t.settle_s,
                t.first_row_s
            ),
            Some(t) => format!(
                "; {} graded over every row from {:.4} s: the run ended within its {:.3} s of settling \
                 after the state (run it longer to grade the takeover)",
                self.analysis.post_shock_mode.name(),
                t.first_row_s,
                t.settle_s
            ),
        }
    }

    /// Figures of a run whose trace is in memory.
    pub fn new(scene: &Scene, result: &RunResult) -> Self {
        let mut recorder = Recorder::new(scene, false);
        result.trace.records().for_each(|r| recorder.push(&r));
        Self::from_parts(scene, &result.run, recorder.finish(result.run.outcome.failure_time()))
    }

    /// The summary of a run from what its [`Recorder`] made of it as its rows came.
    pub fn from_parts(scene: &Scene, run: &SinkRun, recorded: Recorded) -> Self {
        let governing = recorded.governing();
        let planes = match (&recorded.tilt, recorded.planes.as_slice()) {
            (Some(tilt), [a, b]) => Some(PlanesSummary {
                governing: ["a", "b"][governing],
                a: PlaneSummary::new(a, run.span()),
                b: PlaneSummary::new(b, run.span()),
                tilt: tilt.clone(),
            }),
            _ => None,
        };
        let mid_span = recorded.mid_span;
        let lead = recorded.planes.into_iter().nth(governing).expect("a recorded run has a plane");
        let (figures, analysis) = (lead.figures, lead.analysis);
        let c = &scene.controller;
        let failure = match &run.outcome {
            crate::run::Outcome::Diverged(e) => Some(e),
            _ => None,
        };
        Summary {
            scene: scene.name.clone(),
            status: run.outcome.status(),
            error: run.outcome.error(),
            failure_time_s: run.outcome.failure_time(),
            failure_state: failure.and_then(|e| failure_state(scene, e)),
            simulated_s: run.clock.simulated,
            started_s: (run.clock.started > 0.0).then_some(run.clock.started),
            max_radius_m: figures.max_radius_m,
            contact_fraction: analysis.steady_contact_fraction,
            steady_window_start_s: analysis.steady_window_s[0],
            max_contact_force_n: figures.max_contact_force_n,
            max_race_speed_rpm: figures.max_race_speed_rpm,
            recovery_s: figures.recovery_s,
            recovery_from_start_s: analysis
                .takeover
                .map(|t| figures.recovery_s.map(|r| (scene.first_shock_start() + r - t.first_row_s).max(0.0))),
            contact_time_s: figures.contact_share() * run.span(),
            parked_fraction: {
                let ticks = (run.span() / c.period).round() * run.planes as f64;
                if ticks > 0.0 {
                    run.parked_steps as f64 / ticks
                } else {
                    0.0
                }
            },
            invalid_commands: run.invalid_commands,
            voltage_saturation_s: run.voltage_saturation_s,
            steps: run.stats.steps,
            rejected_steps: run.stats.rejected,
            rhs_evals: run.stats.rhs_evals,
            wall_time_s: run.clock.wall_time,
            realtime_factor: if run.clock.wall_time > 0.0 { run.span() / run.clock.wall_time } else { f64::INFINITY },
            model: ModelInfo::new(scene),
            integrator: IntegratorInfo {
                method: scene.integrator.method,
                rtol: scene.integrator.rtol,
                atol: scene.rotor.atol(scene.integrator.atol_groups),
                substeps: scene.integrator.substeps,
                contact_substeps: scene.integrator.contact_substeps,
                macro_step_s: c.period,
                realtime: (c.mode == crate::config::ControlMode::Realtime).then_some(scene.integrator.realtime),
                max_rhs_evals_per_tick: run.ticks.max_rhs_evals,
            },
            analysis,
            robustness: None,
            cosim: run.cosim.clone(),
            planes,
            mid_span,
        }
    }
}

pub use crate::config::FailureState;
pub use crate::machine::{PlanarFailure, RaceFailure, TwoPlaneFailure};

/// The failing state of a divergence of a run of `scene` ([`crate::config::Rotor::failure`]):
/// the rotor model's part of the state (the hardware's states of a run with amplifiers or a
/// sensor front end follow it, [`crate::hardware`]); `None` if the error holds less than the
/// model's state.
pub fn failure_state(scene: &Scene, e: &RunError) -> Option<FailureState> {
    scene.rotor.failure(e.time(), e.state())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stepper::{Command, Plant};

    /// Every state layout a run can fail in (bare, with amplifiers or a sensor front end, with
    /// unipolar amplifiers; planar and two-plane) gives its failing state: the model's part of
    /// the state, whatever follows it (the length check gave none with hardware).
    #[test]
    fn every_layout_of_the_state_gives_its_failure_state() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("config");
        let hw = ["amb.amplifier=true"];
        let uni = ["amb.amplifier=true", "amb.amplifier_topology=\"unipolar\"", "amb.force_law=\"nonlinear\""];
        let front = ["sensor.bandwidth_hz=5000.0"];
        let cases: [(&str, &[&str], bool); 7] = [
            ("paper-10g.toml", &[], false),
            ("realistic-10g.toml", &[], false),
            ("paper-10g.toml", &front, false),
            ("realistic-10g.toml", &uni, false),
            ("two-plane-asymmetric-10g.toml", &[], true),
            ("two-plane-asymmetric-10g.toml", &hw, true),
            ("two-plane-asymmetric-10g.toml", &uni, true),
        ];
        let mut lengths = Vec::new();
        for (file, sets, two) in cases {
            let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
            let scene =
                crate::config::load_scene(&root.join(file), &sets).unwrap_or_else(|e| panic!("{file} {sets:?}: {e}"));
            let plant = Plant::new(&scene, &Command::Continuous(None)).unwrap();
            let state = plant.state().to_vec();
            lengths.push(state.len());
            let e = RunError::RadiusGuard { t: 0.25, what: "rotor radius", value_m: 1.0, limit_m: 0.5, state };
            match (failure_state(&scene, &e), two) {
                (Some(FailureState::Planar(f)), false) => assert_eq!(f.t_s, 0.25),
                (Some(FailureState::TwoPlane(f)), true) => assert_eq!(f.t_s, 0.25),
                (other, _) => panic!("{file} {sets:?}: {other:?}"),
            }
        }
        lengths.sort_unstable();
        lengths.dedup();
        assert!(lengths.len() >= 5, "the cases cover the layouts: {lengths:?}");
    }
}

/// Least, median and largest of a figure over the run and its members.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Spread {
    /// Least.
    pub min: Option<f64>,
    /// Median.
    pub median: Option<f64>,
    /// Largest.
    pub max: Option<f64>,
}

/// `summary.json`'s `robustness`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Robustness {
    /// Perturbed runs beside the run.
    pub members: usize,
    /// What was perturbed, in words.
    pub perturbation: String,
    /// `robust` (every member and the refined run in the run's mode, the refined run's figures
    /// the run's), `fragile` (a member or the refined run in another mode) or `unconverged`
    /// (all in the run's mode, but the refined run's figures are not the run's).
    pub verdict: &'static str,
    /// The run's own motion mode.
    pub run_mode: &'static str,
    /// Members that ended in it.
    pub same_mode: usize,
    /// Members per motion mode (`recovered`, `dry_whirl`, `rebound`, `diverged`).
    pub modes: std::collections::BTreeMap<&'static str, usize>,
    /// Peak contact force over the run and its members (N).
    pub max_contact_force_n: Spread,
    /// Largest radius over the run and its members (m).
    pub max_radius_m: Spread,
    /// Recovery time over the run and the members that recovered from contact (s).
    pub recovery_s: Spread,
    /// Members (and the run) still touching at the end: no recovery time.
    pub still_touching: usize,
    /// The run repeated with the integrator refined (`[robustness] integration`); absent when
    /// not asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub integration: Option<IntegrationCheck>,
}

/// `summary.json`'s `robustness.integration`: the run with its integrator refined.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IntegrationCheck {
    /// The refined setting, in words.
    pub setting: String,
    /// Its motion mode.
    pub mode: &'static str,
    /// Whether it ends in the run's motion mode.
    pub same_mode: bool,
    /// Whether its peak contact force and largest radius are the run's within
    /// `robustness::CONVERGED` (relative): the run's figures are converged in the integrator.
    pub converged: bool,
    /// Its peak contact force (N).
    pub max_contact_force_n: f64,
    /// Its largest radius (m).
    pub max_radius_m: f64,
    /// Its recovery time (s); none while still touching.
    pub recovery_s: Option<f64>,
}

impl Robustness {
    /// The words for the run's last line.
    pub fn headline(&self) -> String {
        let range = |s: &Spread, scale: f64, digits: usize, unit: &str| match (s.min, s.max) {
            (Some(a), Some(b)) => format!("{:.*}–{:.*} {unit}", digits, a * scale, digits, b * scale),
            _ => "none".into(),
        };
        let integration = match &self.integration {
            Some(i) => format!(
                "; integrator refined ({}): {}, peak contact force {:.0} N",
                i.setting,
                match (i.same_mode, i.converged) {
                    (true, true) => format!("{} as this one", i.mode),
                    (true, false) => format!("{} as this one but with other figures", i.mode),
                    (false, _) => format!("{} (another mode)", i.mode),
                },
                i.max_contact_force_n
            ),
            None => String::new(),
        };
        format!(
            "robustness: {} of {} perturbed runs {} as this one ({}); peak contact force {}, max radius {}{integration}",
            self.same_mode,
            self.members,
            self.run_mode,
            self.verdict.to_uppercase(),
            range(&self.max_contact_force_n, 1.0, 0, "N"),
            range(&self.max_radius_m, 1e6, 1, "µm"),
        )
    }
}
