//! Analysis of a run (MODEL.md §9): spectra with whirl direction, the
//! spectrogram through the transient, the Poincaré section, and the
//! classification of the steady response and of the post-shock motion mode.
//!
//! The **steady window** is the last [`STEADY_REVOLUTIONS`] revolutions of
//! the trace (from its last row), computed once here ([`steady_window`]);
//! `summary.json`'s `contact_fraction` is the window's contact share.
//!
//! The analysis is made as the rows come ([`Analyzer`]), in memory bounded by
//! the window: it keeps the window's rows, its Poincaré points, at most
//! [`MAX_TRANSIENT_POINTS`] points of the transient (evenly decimated), and
//! a bounded spectrogram ([`spectrum::StftBuilder`]).

pub mod classify;
pub mod mid_span;
pub mod poincare;
pub mod spectrum;
pub mod tilt;

use crate::bounded::Strided;
use crate::plot::{self, PointGroup, Scale, Series};
use crate::trace::{Row, Trace};
use classify::{MotionMode, SteadyClass};
use poincare::{SectionBuilder, SectionPoint, SectionSample};
use serde::Serialize;
use std::collections::VecDeque;
use std::path::Path;

/// Revolutions at the end of a run over which steady figures are taken.
pub const STEADY_REVOLUTIONS: f64 = 200.0;

/// Most Poincaré points of the transient (before the steady window) kept for the map.
pub const MAX_TRANSIENT_POINTS: usize = 20_000;

/// What the analysis needs to know of the scene.
#[derive(Clone, Copy, Debug)]
pub struct AnalysisSpec {
    /// Air gap r_0 (m): the scale of the orbit.
    pub gap: f64,
    /// Rotor speed (rad/s): the revolution period.
    pub speed: f64,
    /// Spin phase of the Poincaré section (rad).
    pub phase: f64,
    /// Tolerance of the periodicity test, as a fraction of the gap.
    pub tolerance: f64,
}

impl AnalysisSpec {
    /// Length of the steady window (s): [`STEADY_REVOLUTIONS`] revolutions (0 without spin).
    pub fn window_length(&self) -> f64 {
        let revolution = if self.speed > 0.0 { std::f64::consts::TAU / self.speed } else { 0.0 };
        STEADY_REVOLUTIONS * revolution
    }
}

/// The steady window `[start, end]` (s) of a trace whose last row is at `end`.
pub fn steady_window(end: f64, spec: &AnalysisSpec) -> [f64; 2] {
    [(end - spec.window_length()).max(0.0), end]
}

/// Revolutions a run started from a saved state (a takeover) settles for before its grading
/// window may open: the new controller's own transient is not graded as the shock's.
pub const TAKEOVER_SETTLE_REVOLUTIONS: f64 = 50.0;

/// How a run that started from a saved state was graded (`summary.json`'s `takeover`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Takeover {
    /// The first row's time (s): the first output after the saved state's time.
    pub first_row_s: f64,
    /// The settling allowed after it before the grading window may open (s):
    /// [`TAKEOVER_SETTLE_REVOLUTIONS`] revolutions.
    pub settle_s: f64,
    /// The grading window `[start, end]` (s).
    pub window_s: [f64; 2],
    /// Its length in revolutions (a run from t = 0 is graded on its last 200).
    pub window_revolutions: f64,
    /// The run lasted past its settling, and the window lies after it; `false`: it ended within
    /// its settling and is graded on every row after its start, the takeover's transient
    /// included (run it longer to grade the takeover).
    pub settled: bool,
}

/// The grading window of a trace whose first row is at `first` and last at `end`: the steady
/// window, which for a run started from a saved state (`first > 0`) opens no earlier than the
/// settling after its start ([`Takeover`]). A run from t = 0 keeps its steady window.
pub fn graded_window(first: f64, end: f64, spec: &AnalysisSpec) -> ([f64; 2], Option<Takeover>) {
    let steady = steady_window(end, spec);
    if first.is_nan() || first <= 0.0 {
        return (steady, None);
    }
    let revolution = if spec.speed > 0.0 { std::f64::consts::TAU / spec.speed } else { 0.0 };
    let settle_s = TAKEOVER_SETTLE_REVOLUTIONS * revolution;
    let settled = first + settle_s < end;
    let start = if settled { steady[0].max(first + settle_s) } else { steady[0] };
    let window_revolutions = if revolution > 0.0 { (end - start.max(first)) / revolution } else { 0.0 };
    let takeover = Takeover { first_row_s: first, settle_s, window_s: [start, end], window_revolutions, settled };
    ([start, end], Some(takeover))
}

/// The largest peaks of the complex orbit spectrum over the steady window, largest first.
#[derive(Clone, Debug, Serialize)]
pub struct DominantPeaks {
    /// Their frequencies (Hz, negative = backward whirl).
    pub dominant_frequencies_hz: Vec<f64>,
    /// Their amplitudes (m).
    pub dominant_amplitudes_m: Vec<f64>,
}

/// The analysis of one run, as it goes into `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Analysis {
    /// `recovered`, `dry_whirl` or `rebound`.
    pub post_shock_mode: MotionMode,
    /// `periodic`, `kt_periodic`, `quasi_periodic`, `irregular` (or `unknown` with too few revolutions).
    pub steady_class: SteadyClass,
    /// k of a kT-periodic (or periodic: 1) response.
    pub period_k: Option<u32>,
    /// True when the steady window still shows a transient dying away onto that orbit.
    pub steady_converging: bool,
    /// Largest peaks of the complex orbit spectrum over the steady window.
    #[serde(flatten)]
    pub dominant: DominantPeaks,
    /// Mean whirl rate of the orbit over the steady window (Hz, negative = backward).
    pub whirl_hz: f64,
    /// Share of samples in contact over the steady window.
    pub steady_contact_fraction: f64,
    /// Separate contact episodes in the steady window.
    pub steady_contact_episodes: usize,
    /// Largest rotor radius over the steady window (m).
    pub steady_max_radius_m: f64,
    /// Steady window (s).
    pub steady_window_s: [f64; 2],
    /// A run started from a saved state: how its window was chosen ([`graded_window`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub takeover: Option<Takeover>,
    /// Poincaré points in the steady window.
    pub poincare_points: usize,
    /// The Poincaré section (not serialised): every point of the steady window, and the
    /// transient's evenly decimated to at most [`MAX_TRANSIENT_POINTS`].
    #[serde(skip)]
    pub section: Vec<SectionPoint>,
}

/// One row of the steady window.
#[derive(Clone, Copy, Debug)]
struct WindowRow {
    t: f64,
    x: f64,
    y: f64,
    contact: f64,
}

/// What a finished analysis keeps for its charts: the steady window's orbit
/// and the spectrogram through the run.
#[derive(Clone, Debug, Default)]
pub struct AnalysisData {
    /// Times of the window's rows (s).
    pub t_s: Vec<f64>,
    /// Rotor x of the window's rows (m).
    pub x_m: Vec<f64>,
    /// Rotor y of the window's rows (m).
    pub y_m: Vec<f64>,
    /// The spectrogram of `dx + j·dy` through the run, if one was asked for.
    pub spectrogram: Option<spectrum::Spectrogram>,
}

/// The analysis, made as the rows come (see the module docs).
#[derive(Clone, Debug)]
pub struct Analyzer {
    spec: AnalysisSpec,
    span: f64,
    window: VecDeque<WindowRow>,
    section: SectionBuilder,
    recent: VecDeque<SectionPoint>,
    transient: Strided<SectionPoint>,
    stft: Option<spectrum::StftBuilder>,
    /// The first row's time.
    first: Option<f64>,
}

impl Analyzer {
    /// An analysis; with `spectrogram_dt = Some(dt)` (the output interval, s) it also
    /// builds the spectrogram: ~0.05 s Hann windows, 4× overlap, |f| ≤ 1500 Hz.
    pub fn new(spec: AnalysisSpec, spectrogram_dt: Option<f64>) -> Self {
        let stft = spectrogram_dt.filter(|dt| *dt > 0.0 && dt.is_finite()).map(|dt| {
            let f_max = (0.5 / dt).min(2500.0);
            let window = ((0.05 / dt) as usize).next_power_of_two().clamp(64, 8192);
            spectrum::StftBuilder::new(dt, window, window / 4, f_max.min(1500.0))
        });
        Self {
            spec,
            span: spec.window_length(),
            window: VecDeque::new(),
            section: SectionBuilder::new(spec.phase),
            recent: VecDeque::new(),
            transient: Strided::new(MAX_TRANSIENT_POINTS),
            stft,
            first: None,
        }
    }

    /// The next row of the trace (times increasing).
    pub fn push(&mut self, r: &Row) {
        let t = r.t_s;
        self.first.get_or_insert(t);
        let (x, y) = (r.motion.dx_m, r.motion.dy_m);
        let sample = SectionSample {
            t_s: t,
            angle_rad: r.spin.rotor_angle_rad,
            pos_m: [x, y],
            vel_m_s: [r.motion.vx_m_s, r.motion.vy_m_s],
        };
        let recent = &mut self.recent;
        self.section.push(sample, &mut |p| recent.push_back(p));
        if let Some(stft) = &mut self.stft {
            stft.push(t, x, y);
        }
        self.window.push_back(WindowRow { t, x, y, contact: r.loads.contact_force_n });
        // Rows and points before `t − span` are before the final window, whose start is
        // `end − span` with `end ≥ t`.
        let cutoff = t - self.span;
        while self.window.front().is_some_and(|w| w.t < cutoff) {
            self.window.pop_front();
        }
        while self.recent.front().is_some_and(|p| p.t_s < cutoff) {
            if let Some(p) = self.recent.pop_front() {
                self.transient.push(p);
            }
        }
    }

    /// The analysis of the rows pushed, and what its charts need.
    pub fn finish(self) -> (Analysis, AnalysisData) {
        let s = &self.spec;
        let end = self.window.back().map_or(0.0, |w| w.t);
        let ([start, end], takeover) = graded_window(self.first.unwrap_or(0.0), end, s);
        let rows: Vec<WindowRow> = self.window.into_iter().filter(|w| w.t >= start).collect();
        let t: Vec<f64> = rows.iter().map(|w| w.t).collect();
        let x: Vec<f64> = rows.iter().map(|w| w.x).collect();
        let y: Vec<f64> = rows.iter().map(|w| w.y).collect();
        let contact: Vec<f64> = rows.iter().map(|w| w.contact).collect();
        let dt = if t.len() > 1 { (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64 } else { 0.0 };

        let mut section = self.transient.into_items();
        section.extend(self.recent.iter().copied().filter(|p| p.t_s < start));
        let first_steady = section.len();
        section.extend(self.recent.iter().copied().filter(|p| p.t_s >= start));
        let steady: Vec<[f64; 2]> = section[first_steady..].iter().map(|p| [p.x_m, p.y_m]).collect();
        let class = classify::steady_class(&steady, s.gap, s.tolerance);

        let peaks = if dt > 0.0 {
            spectrum::peaks(&spectrum::whirl_spectrum(&x, &y, dt), 5, 0.02, 3.0 / (t.len() as f64 * dt))
        } else {
            Vec::new()
        };
        let hits = contact.iter().filter(|f| **f > 0.0).count();
        let fraction = if contact.is_empty() { 0.0 } else { hits as f64 / contact.len() as f64 };
        let analysis = Analysis {
            post_shock_mode: classify::motion_mode(fraction),
            steady_class: class.class,
            period_k: class.k,
            steady_converging: class.converging,
            dominant: DominantPeaks {
                dominant_frequencies_hz: peaks.iter().map(|p| p.freq_hz).collect(),
                dominant_amplitudes_m: peaks.iter().map(|p| p.amplitude).collect(),
            },
            whirl_hz: classify::mean_whirl_hz(&t, &x, &y),
            steady_contact_fraction: fraction,
            steady_contact_episodes: classify::contact_episodes(&contact),
            steady_max_radius_m: x.iter().zip(&y).map(|(a, b)| a.hypot(*b)).fold(0.0, f64::max),
            steady_window_s: [start, end],
            takeover,
            poincare_points: steady.len(),
            section,
        };
        let data = AnalysisData { t_s: t, x_m: x, y_m: y, spectrogram: self.stft.map(spectrum::StftBuilder::finish) };
        (analysis, data)
    }
}

/// Analyses a trace in memory (no spectrogram; plane A of a two-plane trace).
pub fn analyze(trace: &Trace, spec: &AnalysisSpec) -> Analysis {
    let mut a = Analyzer::new(*spec, None);
    trace.rows().for_each(|r| a.push(&r));
    a.finish().0
}

/// The analysis charts' files, without a tag (the planar model) and with the tags `_a`, `_b`
/// (a two-plane run's planes).
pub const PLOT_FILES: [[&str; 4]; 3] = [
    ["spectrum.png", "whirl_spectrum.png", "spectrogram.png", "poincare.png"],
    ["spectrum_a.png", "whirl_spectrum_a.png", "spectrogram_a.png", "poincare_a.png"],
    ["spectrum_b.png", "whirl_spectrum_b.png", "spectrogram_b.png", "poincare_b.png"],
];

/// Writes `spectrum.png`, `whirl_spectrum.png`, `spectrogram.png` and `poincare.png`, with
/// `tag` (`""`, `"_a"` or `"_b"`) before the extension ([`PLOT_FILES`]); a chart with nothing
/// to draw (a run stopped within a few samples) is not written. Returns the charts written.
pub fn write_plots(
    dir: &Path,
    name: &str,
    tag: &str,
    a: &Analysis,
    data: &AnalysisData,
    gap: f64,
) -> Result<Vec<&'static str>, plot::PlotError> {
    let [f_spectrum, f_whirl, f_spectrogram, f_poincare] = PLOT_FILES[match tag {
        "_a" => 1,
        "_b" => 2,
        _ => 0,
    }];
    let mut written = Vec::new();
    let (t, x, y) = (&data.t_s[..], &data.x_m[..], &data.y_m[..]);
    if t.len() < 8 {
        return Ok(written);
    }
    let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    let f_max = (0.5 / dt).min(2500.0);
    let um = |v: &[f64]| v.iter().map(|a| a * 1e6).collect::<Vec<f64>>();
    let title = |what: &str| format!("{name} — {what}");
    let skip_empty = |r: Result<(), plot::PlotError>, file: &'static str, written: &mut Vec<&'static str>| match r {
        Ok(()) => {
            written.push(file);
            Ok(())
        }
        Err(plot::PlotError::NoData { .. }) => Ok(()),
        Err(e) => Err(e),
    };

    let (sx, sy) = (spectrum::amplitude_spectrum(x, dt), spectrum::amplitude_spectrum(y, dt));
    let keep = sx.freq_hz.partition_point(|f| *f <= f_max);
    let (ax, ay) = (um(&sx.amplitude[..keep]), um(&sy.amplitude[..keep]));
    let r = plot::lines(
        &dir.join(f_spectrum),
        &title(&format!("amplitude spectrum, steady window {:.2}–{:.2} s", a.steady_window_s[0], a.steady_window_s[1])),
        "frequency (Hz)",
        "amplitude (µm)",
        &[
            Series { label: "dx", x: &sx.freq_hz[..keep], y: &ax },
            Series { label: "dy", x: &sy.freq_hz[..keep], y: &ay },
        ],
        Scale::Log10,
    );
    skip_empty(r, f_spectrum, &mut written)?;

    let w = spectrum::whirl_spectrum(x, y, dt);
    let (lo, hi) = (w.freq_hz.partition_point(|f| *f < -f_max), w.freq_hz.partition_point(|f| *f <= f_max));
    let aw = um(&w.amplitude[lo..hi]);
    let r = plot::lines(
        &dir.join(f_whirl),
        &title("spectrum of dx + j·dy (f > 0 forward, f < 0 backward whirl)"),
        "frequency (Hz)",
        "amplitude (µm)",
        &[Series { label: "dx + j·dy", x: &w.freq_hz[lo..hi], y: &aw }],
        Scale::Log10,
    );
    skip_empty(r, f_whirl, &mut written)?;

    if let Some(sg) = data.spectrogram.as_ref().filter(|sg| !sg.time_s.is_empty()) {
        // 100 dB of dynamic range below the loudest cell.
        let mut db = sg.db.clone();
        let top = db.iter().flatten().copied().fold(f64::NEG_INFINITY, f64::max);
        db.iter_mut().flatten().for_each(|v| *v = v.max(top - 100.0));
        let r = plot::heatmap(
            &dir.join(f_spectrogram),
            &title("spectrogram of dx + j·dy (f < 0: backward whirl)"),
            "time (s)",
            "frequency (Hz)",
            &sg.time_s,
            &sg.freq_hz,
            &db,
            "amplitude (dB re 1 m)",
        );
        skip_empty(r, f_spectrogram, &mut written)?;
    }

    let (mut tx, mut ty, mut sx_, mut sy_) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for p in &a.section {
        if p.t_s >= a.steady_window_s[0] {
            sx_.push(p.x_m * 1e6);
            sy_.push(p.y_m * 1e6);
        } else {
            tx.push(p.x_m * 1e6);
            ty.push(p.y_m * 1e6);
        }
    }
    let circle: Vec<[f64; 2]> =
        (0..=360).map(|d| (d as f64).to_radians()).map(|a| [gap * 1e6 * a.cos(), gap * 1e6 * a.sin()]).collect();
    let (cx, cy): (Vec<f64>, Vec<f64>) = circle.iter().map(|p| (p[0], p[1])).unzip();
    let r = plot::scatter(
        &dir.join(f_poincare),
        &title(&format!(
            "Poincaré map: {}{}",
            a.steady_class.name(),
            a.period_k.map(|k| format!(", k = {k}")).unwrap_or_default()
        )),
        "x (µm)",
        "y (µm)",
        &[
            PointGroup { label: "air gap", x: &cx, y: &cy },
            PointGroup { label: "transient", x: &tx, y: &ty },
            PointGroup { label: "last 200 revolutions", x: &sx_, y: &sy_ },
        ],
        true,
    );
    skip_empty(r, f_poincare, &mut written)?;
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows at 10 kHz from `t0` to `t0 + 0.4` s of a rotor at 500 Hz on a 150 µm gap, touching
    /// the race (5 N) for the first millisecond only.
    fn graded(t0: f64) -> Analysis {
        let spec = AnalysisSpec { gap: 1.5e-4, speed: std::f64::consts::TAU * 500.0, phase: 0.0, tolerance: 1e-3 };
        let mut a = Analyzer::new(spec, None);
        for k in 0..=4000 {
            let t = t0 + k as f64 * 1e-4;
            let mut r = Row { t_s: t, ..Row::default() };
            r.spin.rotor_angle_rad = spec.speed * t;
            r.motion.dx_m = 2e-6 * (spec.speed * t).cos();
            r.motion.dy_m = 2e-6 * (spec.speed * t).sin();
            r.loads.contact_force_n = if k < 10 { 5.0 } else { 0.0 };
            a.push(&r);
        }
        a.finish().0
    }

    /// A controller that takes over from a state saved at 1.1 s and lifts the rotor off within
    /// 1 ms is graded on what follows its settling (50 revolutions, 0.1 s at 500 Hz):
    /// `recovered`, over the 150 revolutions from 1.2 s; graded from its first row, as before, it
    /// was `rebound`. A run from t = 0 keeps its steady window (the last 200 revolutions), so the
    /// same contact at its start still counts there.
    #[test]
    fn a_takeover_is_graded_after_its_settling() {
        let from_state = graded(1.1);
        assert_eq!(from_state.post_shock_mode, classify::MotionMode::Recovered);
        let t = from_state.takeover.expect("a run from a state says how it was graded");
        assert!(t.settled && (t.first_row_s - 1.1).abs() < 1e-12 && (t.settle_s - 0.1).abs() < 1e-12, "{t:?}");
        assert!((t.window_s[0] - 1.2).abs() < 1e-9 && (t.window_revolutions - 150.0).abs() < 1e-6, "{t:?}");
        assert_eq!(from_state.steady_window_s, t.window_s);
        let from_zero = graded(0.0);
        assert_eq!(from_zero.post_shock_mode, classify::MotionMode::Rebound);
        assert_eq!((from_zero.takeover, from_zero.steady_window_s[0]), (None, 0.0));
    }

    /// A run from a state that ends within its settling is graded on every row after its start
    /// and says so (`settled: false`), rather than on an empty window (which would read as
    /// `recovered`).
    #[test]
    fn a_takeover_that_ends_within_its_settling_says_so() {
        let spec = AnalysisSpec { gap: 1.5e-4, speed: std::f64::consts::TAU * 500.0, phase: 0.0, tolerance: 1e-3 };
        let (w, t) = graded_window(0.02, 0.04, &spec);
        let t = t.expect("from a state");
        assert!(!t.settled && w == steady_window(0.04, &spec) && w == t.window_s, "{t:?}");
        assert!((t.window_revolutions - 10.0).abs() < 1e-9, "{t:?}");
    }
}
