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
//!
//! By job: this file holds the settings, the results and the measurement's state machine (the
//! run loop's hooks); `probe` the free decay, `multisine` and `stepped` the two excitations,
//! `peak` the refinement around the peak and the peak itself.

mod multisine;
mod peak;
mod probe;
mod stepped;

pub use peak::peak_of;
pub use probe::decay;

use multisine::Multi;
use stepped::Step;

use crate::hooks::{Excitation, Hooks};
use crate::model::SensorSine;
use crate::run::Sink;
use serde::Serialize;
use std::cell::Cell;
use std::collections::VecDeque;
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

/// The ISO 14839-3 zone boundaries of the peak `|S|`: A/B, B/C, C/D (9.5, 12, 14 dB).
pub const ZONE_LIMITS: [f64; 3] = [3.0, 4.0, 5.0];

/// The ISO 14839-3 zone of a peak sensitivity ([`ZONE_LIMITS`]).
pub fn zone(s_abs: f64) -> &'static str {
    super::iso_zone::grade(s_abs, ZONE_LIMITS)
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
        self.tick_step(t, u)
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
