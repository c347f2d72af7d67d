//! `pd_delay`: a discrete PD designed for the sampling period `T` and the
//! command delay of `d` samples, so that the sampled loop has the continuous
//! design's closed-loop poles (natural frequency ω_n = √(k_e/m_r), damping
//! ratio ξ_e).
//!
//! # Why the naive PD fails
//!
//! The naive sampled PD ([`crate::pd::SampledPd`]) lags the continuous one by
//! about `ω (T/2 + d T + T/2)` at frequency ω: zero-order hold, delay and the
//! backward difference. At ω_n that lag turns part of the large proportional
//! force `(k_e + k_s)` into negative damping `(k_e + k_s)(d + 1) T`; with the
//! default magnetics, `k_e = 10⁶ N/m` and `ξ_e = 0.01`, that is ≈ 143 N·s/m
//! at 20 kHz and `d = 1`, against a design `c_e` of 68 N·s/m: the loop grows.
//!
//! # The design: exact placement of the dominant pole pair
//!
//! Per axis, the plant `m ẍ = F + k_s x` under a zero-order hold of period
//! `T` is exactly `[x, v]_{k+1} = Φ [x, v]_k + Γ F_k` with `Φ = e^{AT}`,
//! `A = [[0, 1], [λ, 0]]`, `λ = k_s/m`:
//!
//! ```text
//! Φ = [[C, S], [λ S, C]],   Γ = [G₁, S] / m,
//! C = Σ λⁿ T²ⁿ/(2n)!,   S = Σ λⁿ T²ⁿ⁺¹/(2n+1)!,   G₁ = Σ λⁿ T²ⁿ⁺²/(2n+2)!
//! ```
//!
//! (the series are cosh/sinh and hold for any sign of `k_s`), so the pulse
//! transfer from force to displacement is
//!
//! ```text
//! G(z) = ((z − Φ₂₂) Γ₁ + Φ₁₂ Γ₂) / ((z − Φ₁₁)(z − Φ₂₂) − Φ₁₂ Φ₂₁).
//! ```
//!
//! The law is a PD with a backward difference, `u = A_s x`,
//!
//! ```text
//! i_k = i_bias − A_a (a u_k + b (u_k − u_{k−1})),
//! ```
//!
//! and its command reaches the coil `d` samples later, so with
//! `L = k_i A_a A_s` the closed loop's characteristic equation is
//!
//! ```text
//! 1 + L G(z) z^{−d} (a + b (1 − z^{−1})) = 0.
//! ```
//!
//! Require it at `z₀ = e^{s₀ T}`, `s₀ = ω_n (−ξ_e + j √(1 − ξ_e²))`, the image
//! of the continuous design's pole. That is one complex equation, linear in
//! the two real unknowns:
//!
//! ```text
//! a + b w = R,   w = 1 − z₀^{−1},   R = −z₀^d / (L G(z₀))
//! b = Im R / Im w,   a = Re R − b Re w.
//! ```
//!
//! The sampled loop then has exactly the continuous design's dominant pair
//! (frequency and damping), whatever `T` and `d`; the phase lead of the
//! delay, hold and difference is compensated at ω_n by a larger `b` and a
//! slightly different `a`. The other `d + 1` closed-loop poles (delay line
//! and difference) stay near `z = 0` while `ω_n (d + 1) T ≪ 1`, and the
//! static stiffness `L a − k_s` differs from `k_e` by a small relative amount
//! of order `ω_n T (d + 1)` (reported by [`DelayPd::static_stiffness`]).
//! With `d = 0` and `T → 0`, `a → k_p` and `b/T → k_d` of the continuous PD.
//! The design needs a complex pole pair: `0 ≤ ξ_e < 1`.

use crate::law::{ControlLaw, LawError, LoopConstants, Sample};
use crate::pd::{BackwardDifference, PdDesign, PdGains};

/// A complex number as (re, im); just what the design needs.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Cx(f64, f64);

impl Cx {
    fn mul(self, o: Cx) -> Cx {
        Cx(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
    }
    fn div(self, o: Cx) -> Cx {
        let n = o.0 * o.0 + o.1 * o.1;
        Cx((self.0 * o.0 + self.1 * o.1) / n, (self.1 * o.0 - self.0 * o.1) / n)
    }
    fn add(self, o: Cx) -> Cx {
        Cx(self.0 + o.0, self.1 + o.1)
    }
    fn scale(self, k: f64) -> Cx {
        Cx(self.0 * k, self.1 * k)
    }
    fn exp(self) -> Cx {
        let m = self.0.exp();
        Cx(m * self.1.cos(), m * self.1.sin())
    }
}

/// Exact zero-order-hold discretisation of `m ẍ = F + k_s x` over `t`:
/// `(Φ, Γ)` (see the module doc).
pub fn axis_zoh(mass: f64, ks: f64, t: f64) -> ([[f64; 2]; 2], [f64; 2]) {
    let lambda = ks / mass;
    let (mut c, mut s, mut g1) = (0.0, 0.0, 0.0);
    // term_n = λⁿ T^n' / n'! for n' = 2n, 2n+1, 2n+2.
    let (mut tc, mut ts, mut tg) = (1.0, t, t * t / 2.0);
    for n in 0..60 {
        c += tc;
        s += ts;
        g1 += tg;
        let k = 2.0 * n as f64;
        tc *= lambda * t * t / ((k + 1.0) * (k + 2.0));
        ts *= lambda * t * t / ((k + 2.0) * (k + 3.0));
        tg *= lambda * t * t / ((k + 3.0) * (k + 4.0));
        if tc.abs() < 1e-18 * c.abs() && ts.abs() < 1e-18 * s.abs() && tg.abs() < 1e-18 * g1.abs() {
            break;
        }
    }
    ([[c, s], [lambda * s, c]], [g1 / mass, s / mass])
}

/// Gains of the delay-aware PD.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DelayPdGains {
    /// Gains in [`PdGains`] form: `kp = a` (V/V), `kd = b T` (s), so that
    /// [`PdGains::current`] with the backward difference `(u_k − u_{k−1})/T`
    /// gives the law; the bias is the PD design's.
    pub pd: PdGains,
    /// Static closed-loop stiffness `L a − k_s` (N/m) the design gives.
    pub static_stiffness_n_per_m: f64,
}

impl DelayPdGains {
    /// Places the sampled loop's dominant poles at `e^{s₀ T}` (module doc).
    pub fn from_design(d: &PdDesign, c: &LoopConstants, period_s: f64, delay_samples: u32) -> Result<Self, LawError> {
        let design = |key, value, unit, why| LawError::Design { key, value, unit, why };
        let base = PdGains::from_design(d, c)?;
        if d.damping_ratio >= 1.0 {
            return Err(design(
                "controller.damping_ratio",
                d.damping_ratio,
                "",
                "pd_delay places a complex pole pair: must be < 1",
            ));
        }
        if !(period_s.is_finite() && period_s > 0.0) {
            return Err(design("controller.period", period_s, "s", "must be > 0"));
        }
        let wn = (d.stiffness_n_per_m / c.rotor_mass_kg).sqrt();
        let xi = d.damping_ratio;
        let z0 = Cx(-xi * wn * period_s, wn * (1.0 - xi * xi).sqrt() * period_s).exp();
        let (phi, gamma) = axis_zoh(c.rotor_mass_kg, c.ks_n_per_m, period_s);
        let num = Cx(z0.0 - phi[1][1], z0.1).scale(gamma[0]).add(Cx(phi[0][1] * gamma[1], 0.0));
        let den = Cx(z0.0 - phi[0][0], z0.1).mul(Cx(z0.0 - phi[1][1], z0.1)).add(Cx(-phi[0][1] * phi[1][0], 0.0));
        let g = num.div(den);
        let l = c.ki_n_per_a * c.amp_gain_a_per_v * c.sensor_gain_v_per_m;
        let mut zd = Cx(1.0, 0.0);
        for _ in 0..delay_samples {
            zd = zd.mul(z0);
        }
        let r = zd.div(g.scale(l)).scale(-1.0);
        let w = Cx(1.0, 0.0).add(Cx(1.0, 0.0).div(z0).scale(-1.0));
        let b = r.1 / w.1;
        let a = r.0 - b * w.0;
        if !(a.is_finite() && b.is_finite()) {
            return Err(design("controller.period", period_s, "s", "pd_delay design is singular at this period"));
        }
        Ok(Self { pd: PdGains { kp: a, kd: b * period_s, ..base }, static_stiffness_n_per_m: l * a - c.ks_n_per_m })
    }
}

/// The delay-aware discrete PD (`pd_delay`).
#[derive(Clone, Debug)]
pub struct DelayPd {
    gains: DelayPdGains,
    rate: BackwardDifference,
}

impl DelayPd {
    /// A delay-aware PD with the given gains and sampling period (s).
    pub fn new(gains: DelayPdGains, period_s: f64) -> Self {
        Self { gains, rate: BackwardDifference::new(period_s) }
    }

    /// The static closed-loop stiffness (N/m) of this design.
    pub fn static_stiffness(&self) -> f64 {
        self.gains.static_stiffness_n_per_m
    }
}

impl ControlLaw for DelayPd {
    fn name(&self) -> &'static str {
        "pd_delay"
    }

    fn update(&mut self, s: &Sample) -> [f64; 2] {
        let u_dot = self.rate.rate(s.sensor_v);
        self.gains.pd.current(s.sensor_v, u_dot)
    }

    fn reset(&mut self) {
        self.rate.reset();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pd::SampledPd;
    use crate::test_plant::{decay_measure, simulate, AxisZoh, Rig};

    use crate::test_plant::constants;

    const KE: f64 = 1e6;
    const XI: f64 = 0.01;

    fn design() -> PdDesign {
        PdDesign { stiffness_n_per_m: KE, damping_ratio: XI, gravity_bias: false }
    }

    /// Free decay from 10 µm on x; peak amplitude ratio last/first and the
    /// measured (ξ, ω_d).
    fn free_decay(law: &mut dyn ControlLaw, rate_hz: f64, delay: usize) -> (f64, (f64, f64)) {
        let c = constants();
        let period = 1.0 / rate_hz;
        let ticks = (0.6 / period) as usize; // ≈ 28 cycles at 47 Hz
        let (xs, _) = simulate(law, &c, Rig { period, delay, limit: 1e9 }, [[1e-5, 0.0], [0.0; 2]], [0.0; 2], ticks);
        let x: Vec<f64> = xs.iter().map(|p| p[0]).collect();
        let head = x[..x.len() / 5].iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let tail = x[4 * x.len() / 5..].iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        (tail / head, decay_measure(&x, period, 0.02))
    }

    #[test]
    fn series_zoh_matches_rk4() {
        let c = constants();
        for t in [5e-5, 1e-4, 1e-3] {
            let (phi, gamma) = axis_zoh(c.rotor_mass_kg, c.ks_n_per_m, t);
            let rk = AxisZoh::new(c.rotor_mass_kg, c.ks_n_per_m, t, 2000);
            for (i, row) in phi.iter().enumerate() {
                assert!((gamma[i] - rk.gamma[i]).abs() <= 1e-9 * rk.gamma[i].abs(), "{t}");
                for (j, v) in row.iter().enumerate() {
                    assert!((v - rk.phi[i][j]).abs() <= 1e-9 * rk.phi[i][j].abs().max(1.0), "{t}");
                }
            }
        }
    }

    #[test]
    fn tends_to_the_continuous_pd() {
        let c = constants();
        let pd = PdGains::from_design(&design(), &c).unwrap();
        let g = DelayPdGains::from_design(&design(), &c, 1e-7, 0).unwrap();
        assert!((g.pd.kp / pd.kp - 1.0).abs() < 1e-3, "{} vs {}", g.pd.kp, pd.kp);
        assert!((g.pd.kd / pd.kd - 1.0).abs() < 1e-2, "{} vs {}", g.pd.kd, pd.kd);
    }

    #[test]
    fn naive_pd_grows_and_pd_delay_holds_the_design() {
        let c = constants();
        let wd = (KE / c.rotor_mass_kg).sqrt() * (1.0 - XI * XI).sqrt();
        for rate in [20_000.0, 10_000.0] {
            let period = 1.0 / rate;
            let mut naive = SampledPd::new(PdGains::from_design(&design(), &c).unwrap(), period);
            let (ratio, (xi_naive, _)) = free_decay(&mut naive, rate, 1);
            eprintln!("{rate} Hz naive pd: amplitude ratio {ratio:.3}, xi {xi_naive:.5}");
            assert!(ratio > 1.5 && xi_naive < 0.0, "naive pd at {rate} Hz should grow: ratio {ratio}, xi {xi_naive}");

            let g = DelayPdGains::from_design(&design(), &c, period, 1).unwrap();
            let mut law = DelayPd::new(g, period);
            let (ratio, (xi, w)) = free_decay(&mut law, rate, 1);
            eprintln!(
                "{rate} Hz pd_delay: ratio {ratio:.3}, xi {xi:.5} (design {XI}), w_d {w:.3} rad/s (design {wd:.3}), \
                 static stiffness {:.4e} N/m, kp {:.5} (pd {:.5}), kd {:.4e} s (pd {:.4e})",
                g.static_stiffness_n_per_m,
                g.pd.kp,
                PdGains::from_design(&design(), &c).unwrap().kp,
                g.pd.kd,
                PdGains::from_design(&design(), &c).unwrap().kd,
            );
            assert!(ratio < 1.0, "pd_delay at {rate} Hz should decay: ratio {ratio}");
            assert!((xi / XI - 1.0).abs() < 0.3, "pd_delay at {rate} Hz: xi {xi} vs {XI}");
            assert!((w / wd - 1.0).abs() < 0.02, "pd_delay at {rate} Hz: w_d {w} vs {wd}");
        }
    }

    #[test]
    fn pd_delay_without_delay_also_holds_the_design() {
        let c = constants();
        let period = 1.0 / 5_000.0;
        let mut law = DelayPd::new(DelayPdGains::from_design(&design(), &c, period, 0).unwrap(), period);
        let (_, (xi, _)) = free_decay(&mut law, 5_000.0, 0);
        assert!((xi / XI - 1.0).abs() < 0.3, "xi {xi}");
    }

    #[test]
    fn reset_and_name() {
        let c = constants();
        let mut law = DelayPd::new(DelayPdGains::from_design(&design(), &c, 5e-5, 1).unwrap(), 5e-5);
        assert_eq!(law.name(), "pd_delay");
        let s0 = Sample { seq: 0, t_s: 0.0, sensor_v: [0.1, -0.2] };
        let first = law.update(&s0);
        law.update(&Sample { seq: 1, t_s: 5e-5, sensor_v: [0.3, 0.0] });
        law.reset();
        assert_eq!(law.update(&s0), first);
    }

    #[test]
    fn overdamped_design_is_refused() {
        let d = PdDesign { stiffness_n_per_m: KE, damping_ratio: 1.2, gravity_bias: false };
        let e = DelayPdGains::from_design(&d, &constants(), 5e-5, 1).unwrap_err().to_string();
        assert!(e.contains("controller.damping_ratio"), "{e}");
    }
}
