//! The multisine: the whole coarse grid excited at once, and its least-squares fit per window.

use super::{near_rotation, Measure, Phase, Point};
use crate::hooks::Excitation;
use nalgebra::Complex;
use std::f64::consts::TAU;

/// The whole coarse grid at once: `E = a Σ sin(ω_j (t − t0) + φ_j)`, each `ω_j` a whole number
/// of periods in the window (the tones are orthogonal over it), fitted per window on
/// `[1, cos θ_j, sin θ_j, cos Ωt, sin Ωt]`, the tones and the constant by their correlation
/// sums and the rotation's line by the Schur complement (it is not on the window's bins).
pub(super) struct Multi {
    pub(super) tones: Vec<Tone>,
    /// Each tone's amplitude (V).
    pub(super) amplitude: f64,
    pub(super) t0: f64,
    pub(super) settle_left: u64,
    pub(super) window_ticks: u64,
    pub(super) in_window: u64,
    pub(super) windows: u32,
    /// Σ 1, Σ v, Σ [cos Ωt, sin Ωt], Σ v [cos Ωt, sin Ωt], Σ cos²Ωt, Σ cos Ωt sin Ωt, Σ sin²Ωt.
    pub(super) n: f64,
    pub(super) sv: f64,
    pub(super) su: [f64; 2],
    pub(super) uv: [f64; 2],
    pub(super) uu: [f64; 3],
    /// The last `E(t)` and its time.
    pub(super) e_now: f64,
    pub(super) e_at: f64,
}

/// Windows of a multisine before its unsettled tones go to the stepped sine.
pub(super) const MULTI_WINDOWS: u32 = 6;

impl Multi {
    /// `E(t)` (V), kept for the tick: the fit and the loop read the same value.
    pub(super) fn value(&mut self, t: f64) -> f64 {
        if self.e_at != t {
            self.e_now =
                self.amplitude * self.tones.iter().map(|k| (k.omega * (t - self.t0) + k.phase).sin()).sum::<f64>();
            self.e_at = t;
        }
        self.e_now
    }

    pub(super) fn clear(&mut self) {
        for k in &mut self.tones {
            k.rv = [0.0; 2];
            k.d = [0.0; 2];
            k.b = [[0.0; 2]; 2];
        }
        self.in_window = 0;
        self.n = 0.0;
        self.sv = 0.0;
        self.su = [0.0; 2];
        self.uv = [0.0; 2];
        self.uu = [0.0; 3];
    }

    /// Adds one tick: `v` what the controller read, `rot` `[cos Ωt, sin Ωt]` (zero at standstill).
    pub(super) fn add(&mut self, t: f64, v: f64, rot: [f64; 2]) {
        for k in &mut self.tones {
            let (sn, cs) = (k.omega * (t - self.t0) + k.phase).sin_cos();
            k.rv[0] += cs * v;
            k.rv[1] += sn * v;
            k.d[0] += cs * cs;
            k.d[1] += sn * sn;
            k.b[0][0] += cs * rot[0];
            k.b[0][1] += cs * rot[1];
            k.b[1][0] += sn * rot[0];
            k.b[1][1] += sn * rot[1];
        }
        self.n += 1.0;
        self.sv += v;
        self.su[0] += rot[0];
        self.su[1] += rot[1];
        self.uv[0] += rot[0] * v;
        self.uv[1] += rot[1] * v;
        self.uu[0] += rot[0] * rot[0];
        self.uu[1] += rot[0] * rot[1];
        self.uu[2] += rot[1] * rot[1];
        self.in_window += 1;
    }

    /// Each tone's `S` over the window just ended (`at_speed`: with the rotation's line).
    pub(super) fn fit(&self, at_speed: bool) -> Vec<Complex<f64>> {
        // The rotation's line [p, q] from the Schur complement of the orthogonal block.
        let y = if at_speed {
            let mut m = [self.uu[0], self.uu[1], self.uu[2]];
            let mut w = self.uv;
            let mut eliminate = |b: [f64; 2], d: f64, r: f64| {
                if d > 0.0 {
                    m[0] -= b[0] * b[0] / d;
                    m[1] -= b[0] * b[1] / d;
                    m[2] -= b[1] * b[1] / d;
                    w[0] -= b[0] * r / d;
                    w[1] -= b[1] * r / d;
                }
            };
            eliminate(self.su, self.n, self.sv);
            for k in &self.tones {
                eliminate(k.b[0], k.d[0], k.rv[0]);
                eliminate(k.b[1], k.d[1], k.rv[1]);
            }
            let det = m[0] * m[2] - m[1] * m[1];
            if det.abs() > 0.0 {
                [(m[2] * w[0] - m[1] * w[1]) / det, (m[0] * w[1] - m[1] * w[0]) / det]
            } else {
                [0.0; 2]
            }
        } else {
            [0.0; 2]
        };
        self.tones
            .iter()
            .map(|k| {
                let c = (k.rv[0] - k.b[0][0] * y[0] - k.b[0][1] * y[1]) / k.d[0];
                let s = (k.rv[1] - k.b[1][0] * y[0] - k.b[1][1] * y[1]) / k.d[1];
                // v = c cos θ + s sin θ = Re((c − i s) e^{iθ}); E = a sin θ = Re(−i a e^{iθ}).
                Complex::new(c, -s) / Complex::new(0.0, -self.amplitude)
            })
            .collect()
    }
}

/// One tone of the multisine.
pub(super) struct Tone {
    pub(super) f_hz: f64,
    pub(super) omega: f64,
    pub(super) phase: f64,
    /// Σ cos θ·v, Σ sin θ·v over the window.
    pub(super) rv: [f64; 2],
    /// Σ cos²θ, Σ sin²θ.
    pub(super) d: [f64; 2],
    /// Σ cos θ·[cos Ωt, sin Ωt], Σ sin θ·[cos Ωt, sin Ωt] (at speed).
    pub(super) b: [[f64; 2]; 2],
    pub(super) estimates: Vec<Complex<f64>>,
    /// The estimate once two consecutive windows agreed.
    pub(super) settled: Option<Complex<f64>>,
}

impl Measure<'_> {
    /// Starts the multisine of `tones` (Hz, ascending), each of amplitude `amplitude` (V), at
    /// `t`: the window holds `min_cycles` periods of the lowest tone (at speed also 4 periods of
    /// each tone's distance from the rotation), and each tone moves to the nearest free bin of
    /// that window (a whole number of periods in it).
    pub(super) fn start_multi(&mut self, tones: Vec<f64>, amplitude: f64, t: f64) {
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
    pub(super) fn tick_multi(&mut self, t: f64, u: f64) -> Option<Excitation> {
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
}
