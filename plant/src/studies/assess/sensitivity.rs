//! The sensitivity function of each control axis measured through the loop (ISO 14839-3):
//! the plant adds an excitation `E` to the sensor signal it hands the controller (the summing
//! point, [`crate::hooks::Hooks::excitation`]), one axis at a time, and correlates what the
//! controller read, `v = u + E`, with `E`: `S = v / E`, `T = u / E = S − 1`. The controller is
//! a black box: a law in the plant, the continuous PD, or a controller process over the wire.
//!
//! **One run per axis and speed.** The run starts levitated with the rotor offset by
//! `probe_um` on the axis and no shock. *Probe*: for `probe_s` the loop decays freely; the
//! envelope of the axis' signal (the rotation's unbalance response fitted and removed) gives
//! the slowest decay rate `σ` (a straight line through the logarithm of the envelope, block by
//! block). A loop whose envelope does not decay (`σ ≤ 0`), or whose rotor reaches the
//! touchdown bearing, is **unstable**: it has no margin to grade and gets no peak.
//! *Stepped sine*: then the excitation `E = a sin θ` steps through the frequencies, phase
//! continuous. At each frequency it settles for `ln(1/settle)/σ` (between two periods and
//! `max_settle_s`), then fits `v` over whole windows (at least `min_cycles` periods) by least
//! squares on `[1, cos θ, sin θ]`, plus `cos Ωt, sin Ωt` at speed (the unbalance response at the
//! rotation frequency Ω, which would otherwise leak into the estimate); frequencies within 2 %
//! of Ω are not measured at speed. Windows follow one another until two consecutive estimates
//! agree within `tolerance` (at most 6 windows; a point that never agrees is marked
//! `settled = false`).
//!
//! *Multisine* (a sampled or co-simulated loop with `auto_level`, `excitation = "multisine"`):
//! before the stepped sine, the whole log grid at once, each frequency on the nearest bin of one
//! window (`min_cycles` periods of the lowest, at speed 4 periods of each one's distance from Ω):
//! one settling, then windows fitted on every tone (the tones by their correlation sums, the
//! rotation's line by the Schur complement) until each tone agrees with its previous window;
//! a tone that does not is measured again by the stepped sine. The loop reads the sum at its
//! ticks, as it reads a single sine; the grid then costs one settling and a few windows of its
//! lowest frequency instead of a settling and two windows at each of its frequencies (over the
//! wire, each tick a round trip: the difference between minutes and seconds).
//!
//! **Level.** The amplitude `a` is at most `excitation_um` (as a displacement at the sensor,
//! `A_s · excitation_um` volts) and is lowered so that the expected response `|T| a` stays near
//! `response_um` (`|T|` from the previous point). If the rotor's displacement still passes
//! `limit` × the air gap, the amplitude is cut fourfold and the frequency starts again. With
//! `auto_level = false` the amplitude is fixed; a rotor that then reaches the touchdown bearing
//! ends the measurement with an error naming the frequency and the amplitude.
//!
//! **Frequencies and resolution near a peak.** A log grid of `points` frequencies from `f_min`
//! to `f_max` (below the Nyquist frequency of a sampled loop), then frequencies are added around
//! the largest `|S|` (at the vertex of the parabola through it and its neighbours, then one
//! `resolution` either side) until the points around the peak are at most `resolution` apart
//! (relative; 0.2 % by default); the peak is the vertex of the parabola through the three
//! points around it in (log f, dB). For a resonance of damping ratio ζ the
//! half-power width is `2ζ f`: at 0.2 % spacing the nearest point of a peak with ζ = 0.004 is
//! within 0.1 % of it, 0.3 dB below it, and the parabola's vertex closer.

mod decay;
mod multisine;
mod peak;

pub use decay::decay;
pub use peak::peak_of;

use multisine::{Multi, MULTI_WINDOWS};

use crate::hooks::{Excitation, Hooks};
use crate::model::SensorSine;
use crate::run::Sink;
use nalgebra::{Complex, SMatrix, SVector};
use serde::Serialize;
use std::cell::Cell;
use std::collections::VecDeque;
use std::f64::consts::TAU;
use std::rc::Rc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Settings of the measurement (`[sensitivity]` of an assessment).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Settings {
    /// Lowest frequency (Hz).
    pub f_min_hz: f64,
    /// Highest frequency (Hz); capped below the Nyquist frequency of a sampled loop.
    pub f_max_hz: f64,
    /// Frequencies of the log grid.
    pub points: usize,
    /// Largest excitation amplitude, as a displacement at the sensor (µm).
    pub excitation_um: f64,
    /// Response amplitude the level aims at (µm).
    pub response_um: f64,
    /// Lower the level to keep the response near `response_um`.
    pub auto_level: bool,
    /// Response limit as a share of the air gap: past it the amplitude is cut.
    pub limit: f64,
    /// Share of a transient left when a window starts.
    pub settle: f64,
    /// Agreement of two consecutive windows (relative).
    pub tolerance: f64,
    /// Longest settling at one frequency (s).
    pub max_settle_s: f64,
    /// Spacing of the points around the peak (relative).
    pub resolution: f64,
    /// Initial offset of the probe (µm).
    pub probe_um: f64,
    /// Length of the probe (s).
    pub probe_s: f64,
    /// Periods per window, at least.
    pub min_cycles: f64,
    /// How the grid's frequencies are excited: all at once (a multisine, discrete loops with
    /// `auto_level`), or one after the other (a stepped sine).
    pub excitation: Signal,
}

/// How the log grid's frequencies are excited (`sensitivity.excitation`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Signal {
    /// The whole grid in one multisine (its tones on the bins of one window, Schroeder
    /// phases), settled once and fitted window by window; a tone that does not settle is
    /// measured again by the stepped sine. Used for sampled and co-simulated loops with
    /// `auto_level`; the continuous PD and a fixed level take the stepped sine.
    Multisine,
    /// One frequency after the other.
    Stepped,
}

impl Signal {
    /// The key's value as written.
    pub fn name(self) -> &'static str {
        match self {
            Signal::Multisine => "multisine",
            Signal::Stepped => "stepped",
        }
    }
}

impl Settings {
    /// The defaults for an air gap `gap_m` (m).
    pub fn for_gap(gap_m: f64) -> Self {
        Self {
            f_min_hz: 5.0,
            f_max_hz: 2000.0,
            points: 40,
            excitation_um: 1.0,
            response_um: 0.05 * gap_m * 1e6,
            auto_level: true,
            limit: 0.4,
            settle: 0.01,
            tolerance: 0.01,
            max_settle_s: 10.0,
            resolution: 0.002,
            probe_um: 0.1 * gap_m * 1e6,
            probe_s: 1.0,
            min_cycles: 8.0,
            excitation: Signal::Multisine,
        }
    }
}

/// One measured frequency.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Point {
    /// Frequency (Hz).
    pub f_hz: f64,
    /// `S` real and imaginary parts.
    pub s: [f64; 2],
    /// `|S|` (dB).
    pub s_db: f64,
    /// `|T|` (dB).
    pub t_db: f64,
    /// Excitation amplitude (V).
    pub amplitude_v: f64,
    /// Windows fitted.
    pub windows: u32,
    /// Two consecutive windows agreed within the tolerance.
    pub settled: bool,
}

/// A peak of `|S|`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Peak {
    /// Frequency (Hz).
    pub f_hz: f64,
    /// `|S|` at the peak.
    pub s_abs: f64,
    /// The same in dB.
    pub s_db: f64,
    /// Relative spacing of the points around it.
    pub spacing: f64,
}

/// The ISO 14839-3 zone of a peak sensitivity (boundaries 3, 4, 5: 9.5, 12, 14 dB).
pub fn zone(s_abs: f64) -> &'static str {
    match s_abs {
        s if s < 3.0 => "A",
        s if s < 4.0 => "B",
        s if s < 5.0 => "C",
        _ => "D",
    }
}

/// The measurement of one axis at one speed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AxisResult {
    /// Axis name.
    pub axis: String,
    /// Rotor speed (Hz).
    pub speed_hz: f64,
    /// The loop decays after the probe.
    pub stable: bool,
    /// The probe's decay rate σ (1/s; negative: growing).
    pub decay_per_s: f64,
    /// The probe's dominant frequency (Hz).
    pub probe_hz: f64,
    /// Why it is unstable, in words.
    pub note: Option<String>,
    /// Measured frequencies, ascending.
    pub points: Vec<Point>,
    /// The peak of `|S|` (stable loops only).
    pub peak: Option<Peak>,
    /// `A`, `B`, `C`, `D`, or `unstable`.
    pub zone: String,
    /// Simulated time of the measurement (s).
    pub simulated_s: f64,
}

/// Why a measurement stopped without a result.
#[derive(Debug, Clone, thiserror::Error)]
pub enum MeasureError {
    /// The excitation drove the rotor into the touchdown bearing.
    #[error("axis {axis} at {speed_hz} Hz rotor speed: the excitation of {amplitude_um:.3} µm at {f_hz:.2} Hz drove the rotor into the touchdown bearing (t = {t_s:.3} s); lower sensitivity.excitation_um or keep sensitivity.auto_level = true")]
    Touched {
        /// Axis.
        axis: String,
        /// Speed (Hz).
        speed_hz: f64,
        /// Amplitude as displacement (µm).
        amplitude_um: f64,
        /// Frequency (Hz).
        f_hz: f64,
        /// Time (s).
        t_s: f64,
    },
    /// The level could not keep the response below the limit.
    #[error("axis {axis}: at {f_hz:.2} Hz the response to an excitation of {amplitude_um:.3} µm passed the limit of {limit_um:.1} µm (sensitivity.limit of the air gap) on its way to the touchdown bearing; lower sensitivity.excitation_um or keep sensitivity.auto_level = true")]
    Level {
        /// Axis.
        axis: String,
        /// Frequency (Hz).
        f_hz: f64,
        /// The limit (µm).
        limit_um: f64,
        /// Last amplitude (µm).
        amplitude_um: f64,
    },
    /// The multisine drove the rotor into the touchdown bearing.
    #[error("axis {axis} at {speed_hz} Hz rotor speed: the multisine of {tones} tones from {f_lo_hz:.2} to {f_hi_hz:.2} Hz, {amplitude_um:.3} µm each, drove the rotor into the touchdown bearing (t = {t_s:.3} s); lower sensitivity.response_um or set sensitivity.excitation = \"stepped\"")]
    TouchedMulti {
        /// Axis.
        axis: String,
        /// Speed (Hz).
        speed_hz: f64,
        /// Tones.
        tones: usize,
        /// Lowest tone (Hz).
        f_lo_hz: f64,
        /// Highest tone (Hz).
        f_hi_hz: f64,
        /// Each tone's amplitude as displacement (µm).
        amplitude_um: f64,
        /// Time (s).
        t_s: f64,
    },
    /// Stopped because another axis of the same part failed.
    #[error("not finished: another axis failed")]
    Abandoned,
    /// The run ended otherwise (controller lost, divergence, interruption, time cap).
    #[error("{why}")]
    Run {
        /// How.
        kind: super::failure::Failure,
        /// What happened.
        why: String,
    },
}

/// Where the measurement stands.
enum Phase {
    Probe,
    Multi(Box<Multi>),
    Step(Box<Step>),
    Done,
}

/// One tone of the multisine.
struct Tone {
    f_hz: f64,
    omega: f64,
    phase: f64,
    /// Σ cos θ·v, Σ sin θ·v over the window.
    rv: [f64; 2],
    /// Σ cos²θ, Σ sin²θ.
    d: [f64; 2],
    /// Σ cos θ·[cos Ωt, sin Ωt], Σ sin θ·[cos Ωt, sin Ωt] (at speed).
    b: [[f64; 2]; 2],
    estimates: Vec<Complex<f64>>,
    /// The estimate once two consecutive windows agreed.
    settled: Option<Complex<f64>>,
}

/// One frequency being measured.
struct Step {
    f_hz: f64,
    omega: f64,
    amplitude: f64,
    /// θ at the step's start and that start's time.
    theta0: f64,
    t0: f64,
    /// Ticks left to settle, then ticks of the current window.
    settle_left: u64,
    window_ticks: u64,
    in_window: u64,
    /// The normal equations of the fit on `[1, cos θ, sin θ, cos Ωt, sin Ωt]` (the last two
    /// zero at standstill), fixed-size: no allocation per tick.
    normal: SMatrix<f64, 5, 5>,
    rhs: SVector<f64, 5>,
    estimates: Vec<Complex<f64>>,
}

/// The measurement as run-loop hooks: drives the excitation and reads the axis' sensor.
pub struct Measure<'a> {
    settings: Settings,
    axis: usize,
    axis_name: String,
    period: f64,
    /// A sampled or co-simulated loop (the excitation is read at the ticks only).
    discrete: bool,
    sensor_gain: f64,
    gap: f64,
    speed_hz: f64,
    f_max: f64,
    stop: &'a AtomicBool,
    /// Set when another axis of the same part has failed: this one stops too.
    abandon: Option<&'a AtomicBool>,
    touched: Rc<Cell<Option<f64>>>,
    phase: Phase,
    probe: Vec<(f64, f64)>,
    sigma: f64,
    probe_hz: f64,
    queue: VecDeque<f64>,
    /// Frequencies added around the peak so far.
    refined: usize,
    coarse_left: bool,
    points: Vec<Point>,
    error: Option<MeasureError>,
    stable: Option<bool>,
    note: Option<String>,
    theta_now: f64,
    t_now: f64,
    /// After a level cut, the response is let come down until this time before it is judged again.
    grace_until: f64,
}

impl<'a> Measure<'a> {
    /// A measurement on axis `axis` (its name `axis_name`) of a loop with controller period
    /// `period` (s; the continuous PD: the plant's macro step), sensor gain (V/m), air gap (m),
    /// rotor speed (Hz); `sampled`: cap `f_max` below the Nyquist frequency.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        settings: Settings,
        axis: usize,
        axis_name: &str,
        period: f64,
        sampled: bool,
        sensor_gain: f64,
        gap: f64,
        speed_hz: f64,
        stop: &'a AtomicBool,
        touched: Rc<Cell<Option<f64>>>,
    ) -> Self {
        let f_max = if sampled { settings.f_max_hz.min(0.45 / period) } else { settings.f_max_hz };
        let grid = log_grid(settings.f_min_hz, f_max, settings.points)
            .into_iter()
            .filter(|f| !near_rotation(*f, speed_hz))
            .collect();
        Self {
            settings,
            axis,
            axis_name: axis_name.to_string(),
            period,
            discrete: sampled,
            sensor_gain,
            gap,
            speed_hz,
            f_max,
            stop,
            abandon: None,
            touched,
            phase: Phase::Probe,
            probe: Vec::new(),
            sigma: f64::NAN,
            probe_hz: f64::NAN,
            queue: grid,
            refined: 0,
            coarse_left: true,
            points: Vec::new(),
            error: None,
            stable: None,
            note: None,
            theta_now: 0.0,
            t_now: 0.0,
            grace_until: 0.0,
        }
    }

    /// Stops the measurement, too, once `flag` is set (another axis of the part has failed).
    pub fn abandon_on(mut self, flag: &'a AtomicBool) -> Self {
        self.abandon = Some(flag);
        self
    }

    /// The result, once the run has ended (`simulated_s`: how far it ran).
    pub fn result(mut self, simulated_s: f64) -> Result<AxisResult, MeasureError> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        if self.stable.is_none() {
            if let Some(t) = self.touched.get() {
                self.stable = Some(false);
                self.sigma = decay(&self.probe, self.speed_hz).0;
                self.note = Some(format!(
                    "the rotor reached the touchdown bearing {t:.3} s into the free decay from {:.1} µm",
                    self.settings.probe_um
                ));
            }
        }
        let Some(stable) = self.stable else {
            let why = "the measurement did not get past its probe".into();
            return Err(MeasureError::Run { kind: super::failure::Failure::Other, why });
        };
        if stable && !matches!(self.phase, Phase::Done) {
            let why = format!("the measurement stopped at t = {simulated_s:.3} s before its last frequency");
            return Err(MeasureError::Run { kind: super::failure::Failure::Other, why });
        }
        self.points.sort_by(|a, b| a.f_hz.total_cmp(&b.f_hz));
        let peak = if stable { peak_of(&self.points) } else { None };
        let zone = match (&peak, stable) {
            (Some(p), true) => zone(p.s_abs).to_string(),
            (None, true) => "none".to_string(),
            _ => "unstable".to_string(),
        };
        Ok(AxisResult {
            axis: self.axis_name,
            speed_hz: self.speed_hz,
            stable,
            decay_per_s: self.sigma,
            probe_hz: self.probe_hz,
            note: self.note,
            points: self.points,
            peak,
            zone,
            simulated_s,
        })
    }

    fn finish_probe(&mut self, t: f64) {
        let (sigma, f_d) = decay(&self.probe, self.speed_hz);
        self.sigma = sigma;
        self.probe_hz = f_d;
        if sigma.is_nan() || sigma <= 0.0 {
            self.stable = Some(false);
            self.note = Some(format!(
                "the free decay from {:.1} µm does not decay: its envelope grows at {:.3} 1/s (about {:.1} Hz)",
                self.settings.probe_um, -sigma, f_d
            ));
            self.phase = Phase::Done;
            return;
        }
        self.stable = Some(true);
        self.t_now = t;
        let multi = self.discrete && self.settings.auto_level && self.settings.excitation == Signal::Multisine;
        if multi && self.queue.len() >= 2 {
            let tones: Vec<f64> = self.queue.drain(..).collect();
            let a = self.settings.excitation_um.min(self.settings.response_um) * 1e-6 * self.sensor_gain
                / (tones.len() as f64).sqrt();
            self.start_multi(tones, a, t);
        } else {
            self.next_step(t);
        }
    }

    /// Starts the multisine of `tones` (Hz, ascending), each of amplitude `amplitude` (V), at
    /// `t`: the window holds `min_cycles` periods of the lowest tone (at speed also 4 periods of
    /// each tone's distance from the rotation), and each tone moves to the nearest free bin of
    /// that window (a whole number of periods in it).
    fn start_multi(&mut self, tones: Vec<f64>, amplitude: f64, t: f64) {
        let s = &self.settings;
        let lowest = tones[0];
        let mut window = s.min_cycles / lowest;
        if self.speed_hz > 0.0 {
            for f in &tones {
                window = window.max(4.0 / (f - self.speed_hz).abs());
            }
        }
        let ticks = (window / self.period).ceil().max(8.0) as u64;
        let bin = 1.0 / (ticks as f64 * self.period);
        let mut bins: Vec<u64> = Vec::with_capacity(tones.len());
        for f in &tones {
            let k = ((f / bin).round() as u64).max(1).max(bins.last().map_or(1, |b| b + 1));
            let f_k = k as f64 * bin;
            if 2 * k < ticks && !near_rotation(f_k, self.speed_hz) && f_k <= self.f_max {
                bins.push(k);
            }
        }
        let n = bins.len();
        let tones: Vec<Tone> = bins
            .iter()
            .enumerate()
            .map(|(j, k)| Tone {
                f_hz: *k as f64 * bin,
                omega: TAU * *k as f64 * bin,
                // Schroeder's phases: a low crest factor.
                phase: -std::f64::consts::PI * (j * (j + 1)) as f64 / n as f64,
                rv: [0.0; 2],
                d: [0.0; 2],
                b: [[0.0; 2]; 2],
                estimates: Vec::with_capacity(MULTI_WINDOWS as usize),
                settled: None,
            })
            .collect();
        let settle = self.settle_time(lowest);
        self.phase = Phase::Multi(Box::new(Multi {
            tones,
            amplitude,
            t0: t,
            settle_left: (settle / self.period).ceil() as u64,
            window_ticks: ticks,
            in_window: 0,
            windows: 0,
            n: 0.0,
            sv: 0.0,
            su: [0.0; 2],
            uv: [0.0; 2],
            uu: [0.0; 3],
            e_now: 0.0,
            e_at: f64::NAN,
        }));
    }

    /// One tick of the multisine.
    fn tick_multi(&mut self, t: f64, u: f64) -> Option<Excitation> {
        let limit_v = self.settings.limit * self.gap * self.sensor_gain;
        let tolerance = self.settings.tolerance;
        let at_speed = self.speed_hz > 0.0;
        let Phase::Multi(m) = &mut self.phase else { return None };
        let e = m.value(t);
        if u.abs() > limit_v && t >= self.grace_until {
            // Too strong a response: a quarter of the level, twice at most; then the stepped
            // sine, frequency by frequency, with its own levels.
            let floor = self.settings.excitation_um.min(self.settings.response_um) * 1e-6 * self.sensor_gain / 20.0;
            let tones: Vec<f64> = m.tones.iter().map(|k| k.f_hz).collect();
            let a = m.amplitude / 4.0;
            self.grace_until = t + (self.settle_time(tones[0]) * 0.5).min(2.0);
            if a >= floor / (tones.len() as f64).sqrt() {
                self.start_multi(tones, a, t);
                return self.sine();
            }
            self.queue.extend(tones);
            self.theta_now = 0.0;
            self.next_step(t);
            return self.sine();
        }
        if m.settle_left > 0 {
            m.settle_left -= 1;
            return self.sine();
        }
        let rot = if at_speed {
            let (sn, cs) = (TAU * self.speed_hz * t).sin_cos();
            [cs, sn]
        } else {
            [0.0; 2]
        };
        m.add(t, u + e, rot);
        if m.in_window < m.window_ticks {
            return self.sine();
        }
        let fit = m.fit(at_speed);
        m.clear();
        m.windows += 1;
        for (k, s_est) in m.tones.iter_mut().zip(fit) {
            if k.settled.is_some() {
                continue;
            }
            k.estimates.push(s_est);
            let n = k.estimates.len();
            if n >= 2 && (k.estimates[n - 1] - k.estimates[n - 2]).norm() <= tolerance * s_est.norm() {
                k.settled = Some(s_est);
            }
        }
        if m.tones.iter().all(|k| k.settled.is_some()) || m.windows >= MULTI_WINDOWS {
            let amplitude = m.amplitude;
            let tones = std::mem::take(&mut m.tones);
            for k in tones {
                match k.settled {
                    Some(s_est) => {
                        let tt = s_est - 1.0;
                        self.points.push(Point {
                            f_hz: k.f_hz,
                            s: [s_est.re, s_est.im],
                            s_db: 20.0 * s_est.norm().log10(),
                            t_db: 20.0 * tt.norm().log10(),
                            amplitude_v: amplitude,
                            windows: k.estimates.len() as u32,
                            settled: true,
                        });
                    }
                    // Not settled in the multisine's windows: measured again on its own.
                    None => self.queue.push_back(k.f_hz),
                }
            }
            self.theta_now = 0.0;
            self.next_step(t);
        }
        self.sine()
    }

    /// The amplitude (V) for frequency `f` from the points measured so far.
    fn level(&self, f: f64) -> f64 {
        let max = self.settings.excitation_um * 1e-6 * self.sensor_gain;
        if !self.settings.auto_level {
            return max;
        }
        let near =
            self.points.iter().min_by(|a, b| (a.f_hz.ln() - f.ln()).abs().total_cmp(&(b.f_hz.ln() - f.ln()).abs()));
        let t = near.map_or(1.0, |p| 10f64.powf(p.t_db / 20.0)).max(1.0);
        max.min(self.settings.response_um * 1e-6 * self.sensor_gain / t)
    }

    fn next_step(&mut self, t: f64) {
        if self.queue.is_empty() && self.coarse_left {
            self.coarse_left = false;
        }
        if self.queue.is_empty() {
            self.refine();
        }
        match self.queue.pop_front() {
            Some(f) => {
                let a = self.level(f);
                self.start(f, a, t);
            }
            None => self.phase = Phase::Done,
        }
    }

    /// The settling time at frequency `f_hz` (s).
    fn settle_time(&self, f_hz: f64) -> f64 {
        let s = &self.settings;
        (s.settle.recip().ln() / self.sigma).clamp(2.0 / f_hz, s.max_settle_s.max(2.0 / f_hz))
    }

    fn start(&mut self, f_hz: f64, amplitude: f64, t: f64) {
        let omega = TAU * f_hz;
        let s = &self.settings;
        let settle = self.settle_time(f_hz);
        let mut window = s.min_cycles / f_hz;
        if self.speed_hz > 0.0 {
            window = window.max(4.0 / (f_hz - self.speed_hz).abs());
        }
        // A whole number of excitation periods, and whole ticks.
        let window = (window * f_hz).ceil() / f_hz;
        self.phase = Phase::Step(Box::new(Step {
            f_hz,
            omega,
            amplitude,
            theta0: self.theta_now,
            t0: t,
            settle_left: (settle / self.period).ceil() as u64,
            window_ticks: ((window / self.period).round() as u64).max(4),
            in_window: 0,
            normal: SMatrix::zeros(),
            rhs: SVector::zeros(),
            estimates: Vec::with_capacity(6),
        }));
    }

    /// Adds a frequency near the largest `|S|` until its neighbours are within the resolution:
    /// the vertex of the parabola through it and its neighbours (in ln f, dB) while that lies
    /// half a resolution or more from it, then the points one resolution either side of it. At
    /// an end of the grid, the interval beside it is halved.
    fn refine(&mut self) {
        let mut pts: Vec<(f64, f64)> = self.points.iter().map(|p| (p.f_hz.ln(), p.s_db)).collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let Some(i) = (0..pts.len()).max_by(|&a, &b| pts[a].1.total_cmp(&pts[b].1)) else { return };
        let res = self.settings.resolution;
        // Points added around one peak, at most: a guard, the rule ends long before.
        if self.refined >= 64 {
            return;
        }
        let add = |x: f64, me: &mut Self| {
            let f = x.exp();
            let clear = pts.iter().all(|p| (p.0 - x).abs() > 0.25 * res);
            let ok = clear && !near_rotation(f, me.speed_hz) && f <= me.f_max;
            if ok {
                me.queue.push_back(f);
            }
            ok
        };
        if i == 0 || i + 1 == pts.len() {
            let j = if i == 0 { 1 } else { i - 1 };
            if let Some(n) = pts.get(j) {
                if (n.0 - pts[i].0).abs() > res {
                    add(0.5 * (n.0 + pts[i].0), self);
                }
            }
            self.refined += self.queue.len();
            return;
        }
        let ((x0, y0), (x1, y1), (x2, y2)) = (pts[i - 1], pts[i], pts[i + 1]);
        let (left, right) = (x1 - x0, x2 - x1);
        if left <= res * (1.0 + 1e-9) && right <= res * (1.0 + 1e-9) {
            return;
        }
        let d0 = (y1 - y0) / left;
        let d1 = (y2 - y1) / right;
        let curv = (d1 - d0) / (x2 - x0);
        let vertex = (curv < 0.0).then(|| (0.5 * (x0 + x1) - d0 / (2.0 * curv)).clamp(x0, x2));
        let at_vertex = vertex.is_some_and(|xv| (xv - x1).abs() >= 0.5 * res && add(xv, self));
        if !at_vertex {
            if left > res * (1.0 + 1e-9) {
                add(x1 - res.min(0.5 * left), self);
            }
            if right > res * (1.0 + 1e-9) {
                add(x1 + res.min(0.5 * right), self);
            }
        }
        self.refined += self.queue.len();
    }

    fn tick(&mut self, t: f64, u: f64) -> Option<Excitation> {
        self.t_now = t;
        if let Phase::Probe = self.phase {
            self.probe.push((t, u));
            if t + 0.5 * self.period >= self.settings.probe_s {
                self.finish_probe(t);
            } else {
                return None;
            }
            // The excitation starts at the next tick.
            if let Phase::Multi(_) = self.phase {
                return self.sine();
            }
        }
        if let Phase::Multi(_) = self.phase {
            return self.tick_multi(t, u);
        }
        let speed = self.speed_hz;
        let limit_v = self.settings.limit * self.gap * self.sensor_gain;
        let tolerance = self.settings.tolerance;
        let Phase::Step(step) = &mut self.phase else { return None };
        let theta = step.theta0 + step.omega * (t - step.t0);
        self.theta_now = theta;
        self.t_now = t;
        let e = step.amplitude * theta.sin();
        if u.abs() > limit_v && t >= self.grace_until {
            // Too strong a response: a quarter of the level, and this frequency again.
            let (f, a, was) = (step.f_hz, step.amplitude / 4.0, step.amplitude);
            let floor = 1e-6 * self.settings.excitation_um * 1e-6 * self.sensor_gain;
            if !self.settings.auto_level || a < floor {
                self.error = Some(MeasureError::Level {
                    axis: self.axis_name.clone(),
                    f_hz: f,
                    limit_um: limit_v / self.sensor_gain * 1e6,
                    amplitude_um: was / self.sensor_gain * 1e6,
                });
                self.phase = Phase::Done;
                return None;
            }
            self.start(f, a, t);
            // The response decays at σ: judge it again once it has had time to come down.
            self.grace_until = t + (self.settle_time(f) * 0.5).min(2.0);
            return self.sine();
        }
        let mut done = None;
        if step.settle_left > 0 {
            step.settle_left -= 1;
        } else {
            let (w_sin, w_cos) = if speed > 0.0 { (TAU * speed * t).sin_cos() } else { (0.0, 0.0) };
            let phi = SVector::<f64, 5>::new(1.0, theta.cos(), theta.sin(), w_cos, w_sin);
            step.normal += phi * phi.transpose();
            step.rhs += phi * (u + e);
            step.in_window += 1;
            if step.in_window >= step.window_ticks {
                let mut normal = step.normal;
                if speed <= 0.0 {
                    normal[(3, 3)] = 1.0;
                    normal[(4, 4)] = 1.0;
                }
                let fit = normal.lu().solve(&step.rhs);
                let v = fit.map_or(Complex::new(f64::NAN, f64::NAN), |c| Complex::new(c[1], -c[2]));
                let s_est = v / Complex::new(0.0, -step.amplitude);
                step.estimates.push(s_est);
                step.normal.fill(0.0);
                step.rhs.fill(0.0);
                step.in_window = 0;
                let n = step.estimates.len();
                let agreed =
                    n >= 2 && (step.estimates[n - 1] - step.estimates[n - 2]).norm() <= tolerance * s_est.norm();
                if agreed || n >= 6 {
                    let tt = s_est - 1.0;
                    done = Some(Point {
                        f_hz: step.f_hz,
                        s: [s_est.re, s_est.im],
                        s_db: 20.0 * s_est.norm().log10(),
                        t_db: 20.0 * tt.norm().log10(),
                        amplitude_v: step.amplitude,
                        windows: n as u32,
                        settled: agreed,
                    });
                }
            }
        }
        if let Some(point) = done {
            self.points.push(point);
            self.next_step(t);
        }
        self.sine()
    }

    /// The sine in force now, on the axis' plane (axes 0, 1: plane A's x, y; 2, 3: plane B's).
    fn sine(&mut self) -> Option<Excitation> {
        let t_now = self.t_now;
        if let Phase::Multi(m) = &mut self.phase {
            // The multisine's value at this tick, held: the loop adds it to the tick's sample
            // (a sampled or co-simulated law reads the sensor at the ticks only).
            let mut amplitude_v = [0.0; 2];
            amplitude_v[self.axis % 2] = m.value(t_now);
            let held = SensorSine { amplitude_v, omega_rad_s: 0.0, phase_rad: std::f64::consts::FRAC_PI_2 };
            return Some(Excitation { plane: self.axis / 2, sine: held });
        }
        let Phase::Step(step) = &self.phase else { return None };
        let mut amplitude_v = [0.0; 2];
        amplitude_v[self.axis % 2] = step.amplitude;
        let sine = SensorSine { amplitude_v, omega_rad_s: step.omega, phase_rad: step.theta0 - step.omega * step.t0 };
        Some(Excitation { plane: self.axis / 2, sine })
    }
}

impl Hooks for Measure<'_> {
    fn cancelled(&self) -> bool {
        matches!(self.phase, Phase::Done)
            || self.touched.get().is_some()
            || self.stop.load(Ordering::Relaxed)
            || self.abandon.is_some_and(|a| a.load(Ordering::Relaxed))
    }

    fn excitation(&mut self, _k: u64, t: f64, sensor_v: &[f64]) -> Option<Excitation> {
        if let Some(t_touch) = self.touched.get() {
            if self.error.is_none() {
                match &self.phase {
                    Phase::Step(step) => {
                        self.error = Some(MeasureError::Touched {
                            axis: self.axis_name.clone(),
                            speed_hz: self.speed_hz,
                            amplitude_um: step.amplitude / self.sensor_gain * 1e6,
                            f_hz: step.f_hz,
                            t_s: t_touch,
                        });
                    }
                    Phase::Multi(m) => {
                        self.error = Some(MeasureError::TouchedMulti {
                            axis: self.axis_name.clone(),
                            speed_hz: self.speed_hz,
                            tones: m.tones.len(),
                            f_lo_hz: m.tones.first().map_or(f64::NAN, |k| k.f_hz),
                            f_hi_hz: m.tones.last().map_or(f64::NAN, |k| k.f_hz),
                            amplitude_um: m.amplitude / self.sensor_gain * 1e6,
                            t_s: t_touch,
                        });
                    }
                    Phase::Probe => {
                        self.stable = Some(false);
                        self.note = Some(format!(
                            "the rotor reached the touchdown bearing {t_touch:.3} s into the free decay from {:.1} µm",
                            self.settings.probe_um
                        ));
                    }
                    Phase::Done => {}
                }
                self.phase = Phase::Done;
            }
            return None;
        }
        let u = sensor_v.get(self.axis).copied().unwrap_or(0.0);
        self.tick(t, u)
    }
}

/// A sink that notes the first rotor – race contact on any bearing plane (the rotor at the
/// bearing and the race's centre farther apart than the plane's air gap, `gaps[i]`).
pub struct ContactWatch {
    /// When the rotor first touched (s).
    pub touched: Rc<Cell<Option<f64>>>,
    /// Each plane's air gap (m).
    pub gaps: Vec<f64>,
}

impl Sink for ContactWatch {
    fn sample(&mut self, record: &crate::trace::Record) {
        if self.touched.get().is_none() && super::vibration::touching(record, &self.gaps) {
            self.touched.set(Some(record.a.t_s));
        }
    }
}

/// The longest a measurement run may simulate (s): one that has not reached its last frequency
/// by then fails.
pub const RUN_CAP_S: f64 = 3000.0;

/// The least simulated time a measurement of `settings` takes (s): the probe, then at each
/// frequency of the grid two periods of settling and two windows of `min_cycles` periods. Above
/// [`RUN_CAP_S`] it cannot finish, and is refused before anything runs.
pub fn least_simulated_s(settings: &Settings) -> f64 {
    let per_frequency = 2.0 + 2.0 * settings.min_cycles;
    settings.probe_s
        + log_grid(settings.f_min_hz, settings.f_max_hz, settings.points).iter().map(|f| per_frequency / f).sum::<f64>()
}

/// `n` frequencies log-spaced from `lo` to `hi` (Hz).
pub fn log_grid(lo: f64, hi: f64, n: usize) -> VecDeque<f64> {
    let n = n.max(2);
    (0..n).map(|i| (lo.ln() + (hi.ln() - lo.ln()) * i as f64 / (n - 1) as f64).exp()).collect()
}

fn near_rotation(f: f64, speed_hz: f64) -> bool {
    speed_hz > 0.0 && (f / speed_hz - 1.0).abs() < 0.02
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zones_by_the_peak_sensitivity() {
        assert_eq!(zone(2.9), "A");
        assert_eq!(zone(3.5), "B");
        assert_eq!(zone(4.5), "C");
        assert_eq!(zone(5.0), "D");
    }
}
