//! The stepped sine: one frequency at a time, its level from the response so far, settled,
//! then fitted by least squares over whole windows until two consecutive estimates agree.

use super::{Measure, MeasureError, Phase, Point};
use crate::hooks::Excitation;
use nalgebra::{Complex, SMatrix, SVector};
use std::f64::consts::TAU;

/// One frequency being measured.
pub(super) struct Step {
    pub(super) f_hz: f64,
    pub(super) omega: f64,
    pub(super) amplitude: f64,
    /// θ at the step's start and that start's time.
    pub(super) theta0: f64,
    pub(super) t0: f64,
    /// Ticks left to settle, then ticks of the current window.
    pub(super) settle_left: u64,
    pub(super) window_ticks: u64,
    pub(super) in_window: u64,
    /// The normal equations of the fit on `[1, cos θ, sin θ, cos Ωt, sin Ωt]` (the last two
    /// zero at standstill), fixed-size: no allocation per tick.
    pub(super) normal: SMatrix<f64, 5, 5>,
    pub(super) rhs: SVector<f64, 5>,
    pub(super) estimates: Vec<Complex<f64>>,
}

impl Measure<'_> {
    /// The amplitude (V) for frequency `f` from the points measured so far.
    pub(super) fn level(&self, f: f64) -> f64 {
        let max = self.settings.excitation_um * 1e-6 * self.sensor_gain;
        if !self.settings.auto_level {
            return max;
        }
        let near =
            self.points.iter().min_by(|a, b| (a.f_hz.ln() - f.ln()).abs().total_cmp(&(b.f_hz.ln() - f.ln()).abs()));
        let t = near.map_or(1.0, |p| 10f64.powf(p.t_db / 20.0)).max(1.0);
        max.min(self.settings.response_um * 1e-6 * self.sensor_gain / t)
    }

    /// The next frequency of the queue (refined around the peak once it is empty), or done.
    pub(super) fn next_step(&mut self, t: f64) {
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
    pub(super) fn settle_time(&self, f_hz: f64) -> f64 {
        let s = &self.settings;
        (s.settle.recip().ln() / self.sigma).clamp(2.0 / f_hz, s.max_settle_s.max(2.0 / f_hz))
    }

    /// Starts the stepped sine at `f_hz` (Hz), of amplitude `amplitude` (V), at `t`.
    pub(super) fn start(&mut self, f_hz: f64, amplitude: f64, t: f64) {
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

    /// One tick of the stepped sine.
    pub(super) fn tick_step(&mut self, t: f64, u: f64) -> Option<Excitation> {
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
}
