//! Analysis of a run (MODEL.md §9): spectra with whirl direction, the
//! spectrogram through the transient, the Poincaré section, and the
//! classification of the steady response and of the post-shock motion mode.
//!
//! The steady window is the last [`crate::summary::STEADY_REVOLUTIONS`]
//! revolutions of the run.

pub mod classify;
pub mod poincare;
pub mod spectrum;

use crate::plot::{self, PointGroup, Scale, Series};
use crate::trace::Trace;
use classify::{MotionMode, SteadyClass};
use poincare::SectionPoint;
use serde::Serialize;
use std::path::Path;

/// What the analysis needs to know of the scene.
#[derive(Clone, Copy, Debug)]
pub struct Setting {
    /// Air gap r_0 (m): the scale of the orbit.
    pub gap: f64,
    /// Rotor speed (rad/s): the revolution period.
    pub speed: f64,
    /// Spin phase of the Poincaré section (rad).
    pub phase: f64,
    /// Tolerance of the periodicity test, as a fraction of the gap.
    pub tolerance: f64,
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
    /// Largest peaks of the complex orbit spectrum over the steady window (Hz, negative = backward whirl), largest first.
    pub dominant_frequencies_hz: Vec<f64>,
    /// Their amplitudes (m).
    pub dominant_amplitudes_m: Vec<f64>,
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
    /// Poincaré points in the steady window.
    pub poincare_points: usize,
    /// The Poincaré section over the whole run (not serialised).
    #[serde(skip)]
    pub section: Vec<SectionPoint>,
}

/// Index of the first row at or after `t`.
fn first_at(t: &[f64], at: f64) -> usize {
    t.partition_point(|x| *x < at)
}

/// Analyses a trace.
pub fn analyze(trace: &Trace, s: &Setting) -> Analysis {
    let end = trace.t_s.last().copied().unwrap_or(0.0);
    let revolution = if s.speed > 0.0 { std::f64::consts::TAU / s.speed } else { 0.0 };
    let start = (end - crate::summary::STEADY_REVOLUTIONS * revolution).max(0.0);
    let i0 = first_at(&trace.t_s, start);
    let (t, x, y) = (&trace.t_s[i0..], &trace.dx_m[i0..], &trace.dy_m[i0..]);
    let dt = if t.len() > 1 { (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64 } else { 0.0 };

    let section = poincare::section(trace, s.phase);
    let steady: Vec<[f64; 2]> = section.iter().filter(|p| p.t_s >= start).map(|p| [p.x_m, p.y_m]).collect();
    let class = classify::steady_class(&steady, s.gap, s.tolerance);

    let peaks = if dt > 0.0 {
        spectrum::peaks(&spectrum::whirl_spectrum(x, y, dt), 5, 0.02, 3.0 / (t.len() as f64 * dt))
    } else {
        Vec::new()
    };
    let contact = &trace.contact_force_n[i0..];
    let fraction = crate::summary::contact_fraction(trace, start);
    Analysis {
        post_shock_mode: classify::motion_mode(fraction),
        steady_class: class.class,
        period_k: class.k,
        steady_converging: class.converging,
        dominant_frequencies_hz: peaks.iter().map(|p| p.freq_hz).collect(),
        dominant_amplitudes_m: peaks.iter().map(|p| p.amplitude).collect(),
        whirl_hz: classify::mean_whirl_hz(t, x, y),
        steady_contact_fraction: fraction,
        steady_contact_episodes: classify::contact_episodes(contact),
        steady_max_radius_m: x.iter().zip(y).map(|(a, b)| a.hypot(*b)).fold(0.0, f64::max),
        steady_window_s: [start, end],
        poincare_points: steady.len(),
        section,
    }
}

/// Writes `spectrum.png`, `whirl_spectrum.png`, `spectrogram.png` and `poincare.png`.
pub fn write_plots(dir: &Path, name: &str, trace: &Trace, a: &Analysis, gap: f64) -> Result<(), plot::PlotError> {
    let i0 = first_at(&trace.t_s, a.steady_window_s[0]);
    let (t, x, y) = (&trace.t_s[i0..], &trace.dx_m[i0..], &trace.dy_m[i0..]);
    if t.len() < 8 {
        return Ok(());
    }
    let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    let f_max = (0.5 / dt).min(2500.0);
    let um = |v: &[f64]| v.iter().map(|a| a * 1e6).collect::<Vec<f64>>();
    let title = |what: &str| format!("{name} — {what}");

    let (sx, sy) = (spectrum::amplitude_spectrum(x, dt), spectrum::amplitude_spectrum(y, dt));
    let keep = sx.freq_hz.partition_point(|f| *f <= f_max);
    let (ax, ay) = (um(&sx.amplitude[..keep]), um(&sy.amplitude[..keep]));
    plot::lines(
        &dir.join("spectrum.png"),
        &title(&format!("amplitude spectrum, steady window {:.2}–{:.2} s", a.steady_window_s[0], a.steady_window_s[1])),
        "frequency (Hz)",
        "amplitude (µm)",
        &[
            Series { label: "dx", x: &sx.freq_hz[..keep], y: &ax },
            Series { label: "dy", x: &sy.freq_hz[..keep], y: &ay },
        ],
        Scale::Log10,
    )?;

    let w = spectrum::whirl_spectrum(x, y, dt);
    let (lo, hi) = (w.freq_hz.partition_point(|f| *f < -f_max), w.freq_hz.partition_point(|f| *f <= f_max));
    let aw = um(&w.amplitude[lo..hi]);
    plot::lines(
        &dir.join("whirl_spectrum.png"),
        &title("spectrum of dx + j·dy (f > 0 forward, f < 0 backward whirl)"),
        "frequency (Hz)",
        "amplitude (µm)",
        &[Series { label: "dx + j·dy", x: &w.freq_hz[lo..hi], y: &aw }],
        Scale::Log10,
    )?;

    // Spectrogram over the whole run: ~0.05 s windows, 4× overlap.
    let window = ((0.05 / dt) as usize).next_power_of_two().clamp(64, 8192);
    let mut sg = spectrum::stft(&trace.dx_m, &trace.dy_m, trace.t_s[0], dt, window, window / 4, f_max.min(1500.0));
    if !sg.time_s.is_empty() {
        // 100 dB of dynamic range below the loudest cell.
        let top = sg.db.iter().flatten().copied().fold(f64::NEG_INFINITY, f64::max);
        sg.db.iter_mut().flatten().for_each(|v| *v = v.max(top - 100.0));
        plot::heatmap(
            &dir.join("spectrogram.png"),
            &title("spectrogram of dx + j·dy (f < 0: backward whirl)"),
            "time (s)",
            "frequency (Hz)",
            &sg.time_s,
            &sg.freq_hz,
            &sg.db,
            "amplitude (dB re 1 m)",
        )?;
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
    plot::scatter(
        &dir.join("poincare.png"),
        &title(&format!(
            "Poincaré map: {}{}",
            crate::summary::snake_name(&a.steady_class),
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
    )
}
