//! The multisine: the whole coarse grid excited at once, and its least-squares fit per window.

use super::Tone;
use nalgebra::Complex;

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
