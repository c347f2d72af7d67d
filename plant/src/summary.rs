//! The figures of a run, written as `summary.json`.
//!
//! They are taken as the rows come ([`FiguresBuilder`], with the analysis's
//! [`crate::analysis::Analyzer`]), so that a run of any length needs the
//! same memory. After a divergence the maxima are over the rows before the
//! failure (the row at the failure holds the state that failed, which is
//! reported on its own as `failure_state`).

use crate::analysis::{Analysis, AnalysisSpec, Analyzer};
use crate::config::{DragChoice, ForceLaw, RaceWhenClearChoice, ReleaseChoice, Scene, SpinChoice, SupportChoice};
use crate::run::{RunError, RunResult, SinkRun};
use crate::status::Status;
use crate::trace::{col, Row, Trace};
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
}

impl ModelInfo {
    /// The model choices of a scene.
    pub fn new(scene: &Scene) -> Self {
        let (p, c) = (&scene.params, &scene.controller);
        let (race_when_clear, race_release) = RaceWhenClearChoice::of(&p.race_when_clear);
        ModelInfo {
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
        }
    }
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
    /// Time in rotor – race contact over the whole run (s), counted on the trace samples.
    pub contact_time_s: f64,
    /// Fraction of macro steps run with the race parked (0 unless `race_when_clear = "parked"`).
    pub parked_fraction: f64,
    /// Controller ticks whose command was non-finite (the last valid one was held; see
    /// `controller.max_invalid_burst`, `controller.max_invalid_fraction`).
    pub invalid_commands: u64,
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
    /// Co-simulation figures (`lockstep`, `realtime` modes only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cosim: Option<crate::cosim::CosimReport>,
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
            self.simulated_s,
            self.wall_time_s,
            self.realtime_factor,
            or_none(self.max_radius_m, 1e6, 1, "µm"),
            or_none(self.max_contact_force_n, 1.0, 0, "N"),
        )
    }

    /// Figures of a run whose trace is in memory.
    pub fn new(scene: &Scene, result: &RunResult) -> Self {
        let mut figures = FiguresBuilder::new(scene.first_shock_start());
        let mut analyzer = Analyzer::new(analysis_spec(scene), None);
        for r in result.trace.rows() {
            figures.push(&r);
            analyzer.push(&r);
        }
        let (analysis, _) = analyzer.finish();
        Self::from_parts(scene, &result.run, figures.finish(result.run.outcome.failure_time()), analysis)
    }

    /// The summary of a run from its figures and analysis, taken as its rows came.
    pub fn from_parts(scene: &Scene, run: &SinkRun, figures: Figures, analysis: Analysis) -> Self {
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
            failure_state: failure.and_then(FailureState::of),
            simulated_s: run.simulated,
            max_radius_m: figures.max_radius_m,
            contact_fraction: analysis.steady_contact_fraction,
            steady_window_start_s: analysis.steady_window_s[0],
            max_contact_force_n: figures.max_contact_force_n,
            max_race_speed_rpm: figures.max_race_speed_rpm,
            recovery_s: figures.recovery_s,
            contact_time_s: figures.contact_share() * run.simulated,
            parked_fraction: {
                let ticks = (run.simulated / c.period).round();
                if ticks > 0.0 {
                    run.parked_steps as f64 / ticks
                } else {
                    0.0
                }
            },
            invalid_commands: run.invalid_commands,
            steps: run.stats.steps,
            rejected_steps: run.stats.rejected,
            rhs_evals: run.stats.rhs_evals,
            wall_time_s: run.wall_time,
            realtime_factor: if run.wall_time > 0.0 { run.simulated / run.wall_time } else { f64::INFINITY },
            model: ModelInfo::new(scene),
            integrator: IntegratorInfo {
                method: scene.integrator.method,
                rtol: scene.integrator.rtol,
                atol: scene.integrator.atol.to_vec(),
                substeps: scene.integrator.substeps,
                contact_substeps: scene.integrator.contact_substeps,
                macro_step_s: c.period,
            },
            analysis,
            cosim: run.cosim.clone(),
        }
    }
}

/// The state a diverged run failed in (`failure_state` in `summary.json`); non-finite
/// values are written as `null`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FailureState {
    /// Time of the failure (s).
    pub t_s: f64,
    /// Rotor radius relative to the housing (m).
    pub rotor_radius_m: f64,
    /// Race radius relative to the housing (m).
    pub race_radius_m: f64,
    /// Rotor x, y relative to the housing (m).
    pub rotor_m: [f64; 2],
    /// Rotor velocity relative to the housing (m/s).
    pub rotor_velocity_m_s: [f64; 2],
    /// Race x, y relative to the housing (m).
    pub race_m: [f64; 2],
    /// Race velocity relative to the housing (m/s).
    pub race_velocity_m_s: [f64; 2],
    /// Rotor spin angle (rad) and speed (rad/s).
    pub rotor_spin: [f64; 2],
    /// Race angle (rad) and speed (rad/s).
    pub race_spin: [f64; 2],
}

impl FailureState {
    /// The failing state of a divergence, if the error holds a whole state.
    pub fn of(e: &RunError) -> Option<Self> {
        use crate::model::ix;
        let y = e.state();
        if y.len() != crate::model::N {
            return None;
        }
        Some(Self {
            t_s: e.time(),
            rotor_radius_m: y[ix::XR].hypot(y[ix::YR]),
            race_radius_m: y[ix::XB].hypot(y[ix::YB]),
            rotor_m: [y[ix::XR], y[ix::YR]],
            rotor_velocity_m_s: [y[ix::VXR], y[ix::VYR]],
            race_m: [y[ix::XB], y[ix::YB]],
            race_velocity_m_s: [y[ix::VXB], y[ix::VYB]],
            rotor_spin: [y[ix::TR], y[ix::WR]],
            race_spin: [y[ix::TB], y[ix::WB]],
        })
    }
}

/// The analysis setting of a scene: Poincaré section at spin phase 0, periodicity tolerance 1e-3 r_0.
pub fn analysis_spec(scene: &Scene) -> AnalysisSpec {
    AnalysisSpec { gap: scene.params.contact.gap, speed: scene.params.speed, phase: 0.0, tolerance: 1e-3 }
}

/// The summary's figures of a whole run, taken row by row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Figures {
    /// Largest rotor radius (m); `None` when no row counts (a failure at the first row).
    pub max_radius_m: Option<f64>,
    /// Largest contact force (N); `None` when no row counts.
    pub max_contact_force_n: Option<f64>,
    /// Largest race speed (rpm); `None` when no row counts.
    pub max_race_speed_rpm: Option<f64>,
    /// See [`Summary::recovery_s`].
    pub recovery_s: Option<f64>,
    /// Rows.
    pub rows: u64,
    /// Rows with a positive contact force.
    pub contact_rows: u64,
}

impl Figures {
    /// Share of the rows in contact (0 without rows).
    pub fn contact_share(&self) -> f64 {
        if self.rows == 0 {
            0.0
        } else {
            self.contact_rows as f64 / self.rows as f64
        }
    }
}

/// Takes [`Figures`] as the rows come. The maxima lag one row behind, so that
/// the row of a failure can be left out at the end.
#[derive(Clone, Debug)]
pub struct FiguresBuilder {
    shock_start: f64,
    max_radius: f64,
    max_force: f64,
    max_rpm: f64,
    /// The last row's time and its radius, force and race speed (rpm), not yet in the maxima.
    pending: Option<[f64; 4]>,
    last_contact: Option<f64>,
    last_row_in_contact: bool,
    rows: u64,
    contact_rows: u64,
    /// Rows taken into the maxima.
    counted: u64,
}

impl FiguresBuilder {
    /// Figures with recovery counted from `shock_start` (s).
    pub fn new(shock_start: f64) -> Self {
        Self {
            shock_start,
            max_radius: 0.0,
            max_force: 0.0,
            max_rpm: 0.0,
            pending: None,
            last_contact: None,
            last_row_in_contact: false,
            rows: 0,
            contact_rows: 0,
            counted: 0,
        }
    }

    /// The next row.
    pub fn push(&mut self, r: &Row) {
        self.commit();
        let (t, force) = (r[col::T_S], r[col::CONTACT_FORCE_N]);
        let rpm = r[col::RACE_SPEED_RAD_S].abs() * 60.0 / std::f64::consts::TAU;
        self.pending = Some([t, r[col::DX_M].hypot(r[col::DY_M]), force, rpm]);
        self.rows += 1;
        self.contact_rows += u64::from(force > 0.0);
        self.last_row_in_contact = t >= self.shock_start && force > 0.0;
        if self.last_row_in_contact {
            self.last_contact = Some(t);
        }
    }

    fn commit(&mut self) {
        if let Some([_, radius, force, rpm]) = self.pending.take() {
            let keep = |m: &mut f64, v: f64| {
                if v.is_finite() {
                    *m = m.max(v);
                }
            };
            keep(&mut self.max_radius, radius);
            keep(&mut self.max_force, force);
            keep(&mut self.max_rpm, rpm);
            self.counted += 1;
        }
    }

    /// The figures; rows at or after `failure_time` (s) are left out of the maxima.
    pub fn finish(mut self, failure_time: Option<f64>) -> Figures {
        if self.pending.is_some_and(|p| failure_time.is_none_or(|tf| p[0] < tf)) {
            self.commit();
        }
        let counted = |m: f64| (self.counted > 0).then_some(m);
        Figures {
            max_radius_m: counted(self.max_radius),
            max_contact_force_n: counted(self.max_force),
            max_race_speed_rpm: counted(self.max_rpm),
            // From the shock's start to the last row in contact: 0 if none, `None` if the last
            // row is in contact (the rotor never left).
            recovery_s: match self.last_contact {
                None => Some(0.0),
                Some(_) if self.last_row_in_contact => None,
                Some(t) => Some(t - self.shock_start),
            },
            rows: self.rows,
            contact_rows: self.contact_rows,
        }
    }
}

/// Time from `start` (s) to the last trace sample with a positive contact force: 0 if there
/// is none after `start`, `None` if the last sample is in contact (the rotor never left).
pub fn recovery_time(trace: &Trace, start: f64) -> Option<f64> {
    let mut f = FiguresBuilder::new(start);
    trace.rows().for_each(|r| f.push(&r));
    f.finish(None).recovery_s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(t: f64, dx: f64, force: f64) -> Row {
        let mut r = [0.0; crate::trace::WIDTH];
        r[col::T_S] = t;
        r[col::DX_M] = dx;
        r[col::CONTACT_FORCE_N] = force;
        r
    }

    #[test]
    fn maxima_leave_out_the_row_of_the_failure() {
        let mut f = FiguresBuilder::new(0.0);
        for r in [row(0.0, 1e-6, 0.0), row(1e-4, 628e-6, 10.0), row(2e-4, 793e-6, 2e5)] {
            f.push(&r);
        }
        let diverged = f.clone().finish(Some(2e-4));
        assert_eq!((diverged.max_radius_m, diverged.max_contact_force_n), (Some(628e-6), Some(10.0)));
        let completed = f.finish(None);
        assert_eq!((completed.max_radius_m, completed.max_contact_force_n), (Some(793e-6), Some(2e5)));
    }

    /// Issue 21 item 7: a run that failed at its first row reported `max_radius_m = 0.0`, a
    /// radius it never had: without a row before the failure the maxima are `None` (null).
    #[test]
    fn maxima_over_no_row_are_none() {
        let mut f = FiguresBuilder::new(0.0);
        f.push(&row(0.0, f64::NAN, f64::NAN));
        let failed = f.finish(Some(0.0));
        assert_eq!((failed.max_radius_m, failed.max_contact_force_n, failed.max_race_speed_rpm), (None, None, None));
        assert_eq!(FiguresBuilder::new(0.0).finish(None).max_radius_m, None);
    }

    #[test]
    fn recovery_is_from_the_shock_to_the_last_contact() {
        let mut tr = Trace::default();
        for (t, force) in [(0.0, 1.0), (0.1, 0.0), (0.2, 5.0), (0.3, 0.0), (0.4, 0.0)] {
            tr.push_row(&row(t, 0.0, force));
        }
        // Contact before the shock does not count.
        assert_eq!(recovery_time(&tr, 0.05), Some(0.2 - 0.05));
        assert_eq!(recovery_time(&tr, 0.25), Some(0.0));
        tr.push_row(&row(0.5, 0.0, 1.0));
        assert_eq!(recovery_time(&tr, 0.05), None);
    }
}
