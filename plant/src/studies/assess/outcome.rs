//! What an assessment finds: each part's outcome, each controller's report, the whole report,
//! and how a part failed.

pub use super::failure::Failure;
use super::{coupled, duty, ladder, margins, sensitivity, vibration};
use serde::Serialize;

/// An assessment that wrote its report but could not measure everything.
#[derive(Debug, thiserror::Error)]
#[error("{message}; the report in {dir} holds what was measured and says what was not")]
pub struct AssessError {
    /// The gravest failure.
    pub kind: Failure,
    /// What failed, for each part.
    pub message: String,
    /// The report's folder.
    pub dir: String,
}

/// A part's outcome.
#[derive(Clone, Debug, Serialize)]
pub struct PartOutcome<T> {
    /// `measured`, `skipped`, `failed`, or `interrupted`.
    pub status: &'static str,
    /// Why it was not measured.
    pub why: Option<String>,
    /// How it failed.
    pub failure: Option<Failure>,
    /// The result.
    pub result: Option<T>,
    /// Wall time (s).
    pub wall_s: f64,
}

impl<T> PartOutcome<T> {
    pub(super) fn measured(result: T, wall_s: f64) -> Self {
        Self { status: "measured", why: None, failure: None, result: Some(result), wall_s }
    }
    pub(super) fn skipped(why: &str) -> Self {
        Self { status: "skipped", why: Some(why.to_string()), failure: None, result: None, wall_s: 0.0 }
    }
    pub(super) fn failed(kind: Failure, why: String, wall_s: f64) -> Self {
        let status = if kind == Failure::Interrupted { "interrupted" } else { "failed" };
        Self { status, why: Some(why), failure: Some(kind), result: None, wall_s }
    }
}

/// The sensitivity part: one result per axis and speed.
#[derive(Clone, Debug, Serialize)]
pub struct SensitivityPart {
    /// Per axis and speed.
    pub axes: Vec<sensitivity::AxisResult>,
    /// The closed form of the law, where it has one (`pd`, `pd_delay` and the continuous PD on
    /// the linear bearing): per speed-independent axis, its peak and zone.
    pub closed_form: Option<ClosedFormPeak>,
    /// The two-plane rotor: each plane's closed form (its load share as a planar rotor with the
    /// plane's design, [`closed_form_of_plane`]), planes A then B; empty for the planar model.
    pub closed_form_planes: Vec<ClosedFormPeak>,
    /// A rotor whose axes couple through it (the flexible rotor): each axis' closed form at each
    /// speed, the loops of all axes closed ([`coupled`]), with its difference from the
    /// measurement; empty for the rigid rotors.
    pub closed_form_axes: Vec<coupled::AxisClosedForm>,
    /// Each measured axis' gain and phase margins, computed (the law's linear form on the
    /// linear plant, where it has one) and measured (`L = 1/S − 1`) ([`margins`]).
    pub margins: Vec<margins::AxisMargins>,
    /// Simulated time of all the measurement's runs (s).
    pub simulated_s: f64,
    /// The settings.
    pub settings: sensitivity::Settings,
}

/// The closed form's peak for comparison.
#[derive(Clone, Debug, Serialize)]
pub struct ClosedFormPeak {
    /// The closed loop is stable.
    pub stable: bool,
    /// Peak frequency (Hz).
    pub f_hz: Option<f64>,
    /// Peak `|S|`.
    pub s_abs: Option<f64>,
    /// In dB.
    pub s_db: Option<f64>,
    /// Zone.
    pub zone: String,
    /// `|S|` in dB at each measured frequency of the first axis, for the chart.
    pub curve: Vec<(f64, f64)>,
}

/// One controller's assessment.
#[derive(Clone, Debug, Serialize)]
pub struct ControllerReport {
    /// Label.
    pub label: String,
    /// Its overrides of the scene.
    pub set: Vec<String>,
    /// Law, mode, rate.
    pub law: String,
    /// Controller mode.
    pub mode: String,
    /// Rate (Hz).
    pub rate_hz: f64,
    /// Stability margin.
    pub sensitivity: PartOutcome<SensitivityPart>,
    /// Vibration.
    pub vibration: PartOutcome<vibration::Vibration>,
    /// Shock ladder with the duty.
    pub ladder: PartOutcome<ladder::LadderResult>,
    /// The verdict line.
    pub verdict: String,
    /// Wall time of the whole (s).
    pub wall_s: f64,
}

/// The whole report.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Program and version.
    pub program: String,
    /// The assessment file or scene.
    pub file: String,
    /// The scene every controller runs.
    pub scene: String,
    /// The report's folder.
    pub out: String,
    /// The parts asked for.
    pub parts: Vec<String>,
    /// The bearing's basis (materials, static capacity, cycle threshold).
    pub bearing: Option<duty::Bearing>,
    /// The ladder's settings.
    pub ladder_settings: ladder::Settings,
    /// What the settings cannot answer (a ladder whose members cannot reach `min_p`), said at
    /// load time on the terminal too.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// One per controller.
    pub controllers: Vec<ControllerReport>,
    /// True when interrupted: the parts not measured say so.
    pub interrupted: bool,
    /// Wall time (s).
    pub wall_s: f64,
    /// Absolute folders and how the report shows them (relative to where the command ran): every
    /// text of the report is written with them replaced ([`report::write`]).
    #[serde(skip)]
    pub roots: Vec<(String, String)>,
}
