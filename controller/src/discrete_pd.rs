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
//! `A = [[0, 1], [λ, 0]]`, `λ = k_s/m`, `Γ = ∫₀ᵀ e^{As} ds [0, 1/m]`:
//!
//! ```text
//! Φ = [[C, S], [λ S, C]],   Γ = [G₁, S] / m,
//! C = cosh(√λ T),   S = sinh(√λ T)/√λ,   G₁ = (C − 1)/λ
//! ```
//!
//! (for `λ < 0` the hyperbolic functions become circular ones). [`axis_zoh`]
//! takes both from one matrix exponential (nalgebra's Padé with scaling and
//! squaring) of the augmented matrix `[[A, B], [0, 0]] T` (Van Loan), in the
//! time unit `T` so that its entries are of order one. The pulse transfer
//! from force to displacement is
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
use nalgebra::Matrix3;
use num_complex::Complex64;

/// Exact zero-order-hold discretisation of `m ẍ = F + k_s x` over `t`:
/// `(Φ, Γ)` (see the module doc), with `mass` (kg), `ks` (N/m), `t` (s).
///
/// ```
/// // A free mass (k_s = 0): Φ = [[1, T], [0, 1]], Γ = [T²/2, T] / m.
/// let (phi, gamma) = controller::discrete_pd::axis_zoh(2.0, 0.0, 0.1);
/// assert!((phi[0][1] - 0.1).abs() < 1e-15 && (phi[0][0] - 1.0).abs() < 1e-15);
/// assert!((gamma[0] - 0.0025).abs() < 1e-15 && (gamma[1] - 0.05).abs() < 1e-15);
/// ```
pub fn axis_zoh(mass: f64, ks: f64, t: f64) -> ([[f64; 2]; 2], [f64; 2]) {
    // In the time unit T, with the state (x, T v) and the input T² F / m, the augmented matrix is
    // [[0, 1, 0], [λ T², 0, 1], [0, 0, 0]], and its exponential holds Φ and Γ in that unit:
    // e = [[C, S/T, G₁/T²], [λ T S, C, S/T], [0, 0, 1]].
    let lambda = ks / mass;
    let e = Matrix3::new(0.0, 1.0, 0.0, lambda * t * t, 0.0, 1.0, 0.0, 0.0, 0.0).exp();
    let phi = [[e[(0, 0)], e[(0, 1)] * t], [e[(1, 0)] / t, e[(1, 1)]]];
    let gamma = [e[(0, 2)] * t * t / mass, e[(1, 2)] * t / mass];
    (phi, gamma)
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
        let z0 = Complex64::new(-xi * wn * period_s, wn * (1.0 - xi * xi).sqrt() * period_s).exp();
        let (phi, gamma) = axis_zoh(c.rotor_mass_kg, c.ks_n_per_m, period_s);
        let num = (z0 - phi[1][1]) * gamma[0] + phi[0][1] * gamma[1];
        let den = (z0 - phi[0][0]) * (z0 - phi[1][1]) - phi[0][1] * phi[1][0];
        let g = num / den;
        let l = c.ki_n_per_a * c.amp_gain_a_per_v * c.sensor_gain_v_per_m;
        let r = -(z0.powu(delay_samples) / (g * l));
        let w = 1.0 - z0.inv();
        let b = r.im / w.im;
        let a = r.re - b * w.re;
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

    fn linear_pd(&self) -> Option<crate::law::LinearPd> {
        Some(crate::law::LinearPd { kp: self.gains.pd.kp, kd: self.gains.pd.kd })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pd::SampledPd;
    use crate::test_plant::{decay_measure, simulate, AxisZoh, Rig};

    const KE: f64 = 1e6;
    const XI: f64 = 0.01;

    fn design() -> PdDesign {
        PdDesign { stiffness_n_per_m: KE, damping_ratio: XI, gravity_bias: false }
    }

    /// Free decay from 10 µm on x; peak amplitude ratio last/first and the
    /// measured (ξ, ω_d).
    fn free_decay(law: &mut dyn ControlLaw, rate_hz: f64, delay: usize) -> (f64, (f64, f64)) {
        let c = LoopConstants::study();
        let period = 1.0 / rate_hz;
        let ticks = (0.6 / period) as usize; // ≈ 28 cycles at 47 Hz
        let (xs, _) = simulate(law, &c, Rig { period, delay, limit: 1e9 }, [[1e-5, 0.0], [0.0; 2]], [0.0; 2], ticks);
        let x: Vec<f64> = xs.iter().map(|p| p[0]).collect();
        let head = x[..x.len() / 5].iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let tail = x[4 * x.len() / 5..].iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        (tail / head, decay_measure(&x, period, 0.02))
    }

    /// Against the closed forms of the module doc, for a negative stiffness (the magnets' pull,
    /// hyperbolic) and a positive one (circular), from 50 µs to 1 ms.
    #[test]
    fn zoh_matches_the_closed_forms() {
        for (mass, ks) in [(11.5, 4.32e5), (11.5, -4.32e5), (3.0, 2e6)] {
            for t in [5e-5, 1e-4, 1e-3] {
                let lambda: f64 = ks / mass;
                // G₁ = (C − 1)/λ, written without the cancellation: 2 sinh²(r T/2)/r² (λ = r²) or
                // 2 sin²(r T/2)/r² (λ = −r²).
                let (c, s, g1) = if lambda >= 0.0 {
                    let r = lambda.sqrt();
                    ((r * t).cosh(), (r * t).sinh() / r, 2.0 * (0.5 * r * t).sinh().powi(2) / lambda)
                } else {
                    let r = (-lambda).sqrt();
                    ((r * t).cos(), (r * t).sin() / r, 2.0 * (0.5 * r * t).sin().powi(2) / -lambda)
                };
                let (phi, gamma) = axis_zoh(mass, ks, t);
                let close = |got: f64, want: f64| (got - want).abs() <= 1e-13 * want.abs();
                assert!(close(phi[0][0], c) && close(phi[1][1], c), "{t}: {phi:?} vs C = {c}");
                assert!(close(phi[0][1], s) && close(phi[1][0], lambda * s), "{t}: {phi:?} vs S = {s}");
                assert!(close(gamma[0], g1 / mass) && close(gamma[1], s / mass), "{t}: {gamma:?} vs {g1}, {s}");
            }
        }
    }

    #[test]
    fn zoh_matches_rk4() {
        let c = LoopConstants::study();
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
        let c = LoopConstants::study();
        let pd = PdGains::from_design(&design(), &c).unwrap();
        let g = DelayPdGains::from_design(&design(), &c, 1e-7, 0).unwrap();
        assert!((g.pd.kp / pd.kp - 1.0).abs() < 1e-3, "{} vs {}", g.pd.kp, pd.kp);
        assert!((g.pd.kd / pd.kd - 1.0).abs() < 1e-2, "{} vs {}", g.pd.kd, pd.kd);
    }

    #[test]
    fn naive_pd_grows_and_pd_delay_holds_the_design() {
        let c = LoopConstants::study();
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
        let c = LoopConstants::study();
        let period = 1.0 / 5_000.0;
        let mut law = DelayPd::new(DelayPdGains::from_design(&design(), &c, period, 0).unwrap(), period);
        let (_, (xi, _)) = free_decay(&mut law, 5_000.0, 0);
        assert!((xi / XI - 1.0).abs() < 0.3, "xi {xi}");
    }

    #[test]
    fn reset_and_name() {
        let c = LoopConstants::study();
        let mut law = DelayPd::new(DelayPdGains::from_design(&design(), &c, 5e-5, 1).unwrap(), 5e-5);
        assert_eq!(law.name(), "pd_delay");
        let s0 = Sample { seq: 0, t_s: 0.0, sensor_v: [0.1, -0.2], ..Default::default() };
        let first = law.update(&s0);
        law.update(&Sample { seq: 1, t_s: 5e-5, sensor_v: [0.3, 0.0], ..Default::default() });
        law.reset();
        assert_eq!(law.update(&s0), first);
    }

    #[test]
    fn overdamped_design_is_refused() {
        let d = PdDesign { stiffness_n_per_m: KE, damping_ratio: 1.2, gravity_bias: false };
        let e = DelayPdGains::from_design(&d, &LoopConstants::study(), 5e-5, 1).unwrap_err().to_string();
        assert!(e.contains("controller.damping_ratio"), "{e}");
    }
}
