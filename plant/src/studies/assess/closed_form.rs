//! The closed-form sensitivity of one control axis with a PD law (ISO 14839-3's `S`), for
//! checking the measurement and for drawing beside it.
//!
//! One axis of the levitated rotor is `m ẍ = k_i i + k_s x` (MODEL.md §3), the sensor reads
//! `u = A_s x`, and the excitation `E` is added where the sensor signal enters the controller:
//! the controller reads `v = u + E`. With the law's transfer `i = C v` (its sign included) the
//! loop gain is `L = A_s P C`, `P` the plant from current to displacement, and
//!
//! ```text
//! S = v / E = 1 / (1 − L),     T = u / E = L / (1 − L) = S − 1
//! ```
//!
//! (`G_o = −L` is the open loop of the usual negative-feedback form, `S = 1 / (1 + G_o)`).
//!
//! * **Continuous PD** `i = −A_a (k_p v + k_d v̇)`: `L(s) = −(k_e + k_s + c_e s) / (m s² − k_s)`
//!   with `k_e + k_s = k_i A_a A_s k_p`, `c_e = k_i A_a A_s k_d`, so
//!   `S(s) = (m s² − k_s) / (m s² + c_e s + k_e)`; stable iff `k_e > 0` and `c_e > 0`.
//! * **Sampled PD** (`pd`, `pd_delay`: `i_k = −A_a (k_p v_k + k_d (v_k − v_{k−1}) / T)`), its
//!   command applied `d` ticks later and held (zero-order hold): the plant discretised exactly,
//!   `G(z) = c (zI − Φ)⁻¹ Γ` from [`controller::discrete_pd::axis_zoh`], and
//!   `L(z) = −A_s k_i A_a G(z) z^{−d} (k_p + k_d (1 − z^{−1}) / T)`, evaluated on `z = e^{jωT}`.
//!   Stable iff every root of `z^{d+1} den(z) + A (num(z)) (c₀ z − c₁)` lies inside the unit
//!   circle (`A = A_s k_i A_a`, `c₀ = k_p + k_d/T`, `c₁ = k_d/T`): the companion matrix's
//!   eigenvalues.

use nalgebra::{Complex, DMatrix};

/// One axis of the plant and its loop constants (SI).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisPlant {
    /// Rotor mass on the axis (kg).
    pub mass: f64,
    /// Negative stiffness k_s (N/m).
    pub ks: f64,
    /// Force-current coefficient k_i (N/A).
    pub ki: f64,
    /// Sensor gain A_s (V/m).
    pub sensor_gain: f64,
    /// Amplifier gain A_a (A/V).
    pub amp_gain: f64,
}

impl AxisPlant {
    /// The axis of a loop's constants.
    pub fn of(c: &controller::LoopConstants) -> Self {
        Self {
            mass: c.rotor_mass_kg,
            ks: c.ks_n_per_m,
            ki: c.ki_n_per_a,
            sensor_gain: c.sensor_gain_v_per_m,
            amp_gain: c.amp_gain_a_per_v,
        }
    }

    /// `A_s k_i A_a` (N/V · m/m: the loop's gain from the controller's input to force per metre).
    fn gain(&self) -> f64 {
        self.sensor_gain * self.ki * self.amp_gain
    }
}

/// A PD loop whose sensitivity has a closed form.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PdLoop {
    /// The continuous PD, `k_p` (V/V), `k_d` (s).
    Continuous {
        /// Proportional gain (V/V).
        kp: f64,
        /// Derivative gain (s).
        kd: f64,
    },
    /// The sampled PD with a backward difference, period `period` (s), command delay `delay`
    /// samples, zero-order hold.
    Sampled {
        /// Proportional gain (V/V).
        kp: f64,
        /// Derivative gain (s): `k_d (v_k − v_{k−1}) / T`.
        kd: f64,
        /// Sampling period T (s).
        period: f64,
        /// Command delay d (samples).
        delay: u32,
    },
}

/// The loop gain `L` at frequency `f` (Hz).
pub fn loop_gain(plant: &AxisPlant, pd: &PdLoop, f_hz: f64) -> Complex<f64> {
    let w = std::f64::consts::TAU * f_hz;
    match *pd {
        PdLoop::Continuous { kp, kd } => {
            let s = Complex::new(0.0, w);
            -(Complex::new(plant.gain() * kp, 0.0) + s * (plant.gain() * kd)) / (s * s * plant.mass - plant.ks)
        }
        PdLoop::Sampled { kp, kd, period, delay } => {
            let z = Complex::new(0.0, w * period).exp();
            let (num, den) = pulse_transfer(plant, period);
            let g = (num[0] * z + num[1]) / (z * z + den[0] * z + den[1]);
            let c = Complex::new(kp, 0.0) + (Complex::new(1.0, 0.0) - z.inv()) * (kd / period);
            -(g * c * z.powi(-(delay as i32))) * plant.gain()
        }
    }
}

/// `S = 1 / (1 − L)` at frequency `f` (Hz).
pub fn sensitivity(plant: &AxisPlant, pd: &PdLoop, f_hz: f64) -> Complex<f64> {
    Complex::new(1.0, 0.0) / (Complex::new(1.0, 0.0) - loop_gain(plant, pd, f_hz))
}

/// The pulse transfer from force to displacement under a zero-order hold of period `t`:
/// `G(z) = (n₁ z + n₀) / (z² + a₁ z + a₀)`, returned as `([n₁, n₀], [a₁, a₀])`.
fn pulse_transfer(plant: &AxisPlant, t: f64) -> ([f64; 2], [f64; 2]) {
    let (phi, gamma) = controller::discrete_pd::axis_zoh(plant.mass, plant.ks, t);
    let num = [gamma[0], phi[0][1] * gamma[1] - phi[1][1] * gamma[0]];
    let den = [-(phi[0][0] + phi[1][1]), phi[0][0] * phi[1][1] - phi[0][1] * phi[1][0]];
    (num, den)
}

/// The closed loop's poles: `s` for the continuous loop, `z` for the sampled one.
pub fn poles(plant: &AxisPlant, pd: &PdLoop) -> Vec<Complex<f64>> {
    match *pd {
        PdLoop::Continuous { kp, kd } => {
            // m s² + c s + k = 0 with k = A kp − k_s, c = A kd.
            let (k, c) = (plant.gain() * kp - plant.ks, plant.gain() * kd);
            let disc = Complex::new(c * c - 4.0 * plant.mass * k, 0.0).sqrt();
            vec![(-c + disc) / (2.0 * plant.mass), (-c - disc) / (2.0 * plant.mass)]
        }
        PdLoop::Sampled { kp, kd, period, delay } => {
            let (num, den) = pulse_transfer(plant, period);
            let d = delay as usize;
            let degree = d + 3;
            // Coefficients by power: z^{d+1} (z² + a₁ z + a₀) + A (n₁ z + n₀)(c₀ z − c₁).
            let mut p = vec![0.0; degree + 1];
            p[d + 3] += 1.0;
            p[d + 2] += den[0];
            p[d + 1] += den[1];
            let (a, c0, c1) = (plant.gain(), kp + kd / period, kd / period);
            p[2] += a * num[0] * c0;
            p[1] += a * (num[1] * c0 - num[0] * c1);
            p[0] -= a * num[1] * c1;
            let mut companion = DMatrix::<f64>::zeros(degree, degree);
            for i in 0..degree {
                companion[(0, i)] = -p[degree - 1 - i];
                if i + 1 < degree {
                    companion[(i + 1, i)] = 1.0;
                }
            }
            companion.complex_eigenvalues().iter().copied().collect()
        }
    }
}

/// True when every closed-loop pole is stable (left half-plane; inside the unit circle).
pub fn stable(plant: &AxisPlant, pd: &PdLoop) -> bool {
    let p = poles(plant, pd);
    match pd {
        PdLoop::Continuous { .. } => p.iter().all(|s| s.re < 0.0),
        PdLoop::Sampled { .. } => p.iter().all(|z| z.norm() < 1.0),
    }
}

/// The peak of `|S|` over `[f_lo, f_hi]` (Hz): `(f_peak, |S|_peak)`, from a log grid of 4000
/// points refined by golden-section search around the largest.
pub fn peak(plant: &AxisPlant, pd: &PdLoop, f_lo: f64, f_hi: f64) -> (f64, f64) {
    let mag = |lf: f64| sensitivity(plant, pd, lf.exp()).norm();
    let (a, b) = (f_lo.ln(), f_hi.ln());
    let n = 4000;
    let x = |i: usize| a + (b - a) * i as f64 / n as f64;
    let best = (0..=n).max_by(|&i, &j| mag(x(i)).total_cmp(&mag(x(j)))).unwrap_or(0);
    let (mut lo, mut hi) = (x(best.saturating_sub(1)), x((best + 1).min(n)));
    let g = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..100 {
        let (c, d) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if mag(c) > mag(d) {
            hi = d;
        } else {
            lo = c;
        }
    }
    let lf = 0.5 * (lo + hi);
    (lf.exp(), mag(lf))
}

#[cfg(test)]
mod tests {
    use super::*;
    use controller::{LoopConstants, PdDesign, PdGains};

    fn plant() -> AxisPlant {
        AxisPlant::of(&LoopConstants::study())
    }

    fn pd(xi: f64) -> PdGains {
        let d = PdDesign { stiffness_n_per_m: 1e6, damping_ratio: xi, gravity_bias: false };
        PdGains::from_design(&d, &LoopConstants::study()).expect("design")
    }

    #[test]
    fn continuous_pd_is_the_spring_damper_formula() {
        // S(s) = (m s² − k_s) / (m s² + c_e s + k_e), the note's form.
        let g = pd(0.05);
        let (m, ks, ke): (f64, f64, f64) = (11.5, 4.32e5, 1e6);
        let ce = 2.0 * 0.05 * (ke * m).sqrt();
        for f in [3.0, 47.0, 300.0] {
            let s = Complex::new(0.0, std::f64::consts::TAU * f);
            let expected = (s * s * m - ks) / (s * s * m + s * ce + ke);
            let got = sensitivity(&plant(), &PdLoop::Continuous { kp: g.kp, kd: g.kd }, f);
            assert!((got - expected).norm() < 1e-9 * expected.norm(), "{f} Hz: {got} against {expected}");
        }
        // Near the rigid mode the peak is about (k_e + k_s) / (2 ξ k_e).
        let (f, s) = peak(&plant(), &PdLoop::Continuous { kp: g.kp, kd: g.kd }, 1.0, 1000.0);
        let wn = (ke / m).sqrt() / std::f64::consts::TAU;
        assert!((f / wn - 1.0).abs() < 0.05 && (s / ((ke + ks) / (0.1 * ke)) - 1.0).abs() < 0.05, "{f} {s}");
    }

    #[test]
    fn a_fast_sampled_pd_without_delay_tends_to_the_continuous_one() {
        let g = pd(0.1);
        let c = PdLoop::Continuous { kp: g.kp, kd: g.kd };
        let s = PdLoop::Sampled { kp: g.kp, kd: g.kd, period: 1e-7, delay: 0 };
        for f in [10.0, 47.0, 200.0] {
            let (a, b) = (sensitivity(&plant(), &c, f), sensitivity(&plant(), &s, f));
            assert!((a - b).norm() < 1e-3 * a.norm(), "{f} Hz: {a} against {b}");
        }
    }

    #[test]
    fn stability_follows_the_measured_damping_of_the_naive_pd() {
        // docs/results/sampled-vs-continuous.md: the naive pd at ξ_e = 0.01 with one sample of
        // delay is unstable at 10 and 20 kHz, stable at 50 kHz; continuous, stable.
        let g = pd(0.01);
        let at = |rate: f64| PdLoop::Sampled { kp: g.kp, kd: g.kd, period: 1.0 / rate, delay: 1 };
        assert!(!stable(&plant(), &at(10e3)));
        assert!(!stable(&plant(), &at(20e3)));
        assert!(stable(&plant(), &at(50e3)));
        assert!(stable(&plant(), &PdLoop::Continuous { kp: g.kp, kd: g.kd }));
        // The dominant pole's damping at 50 kHz is the measured +0.004 (the free decay's).
        let z = poles(&plant(), &at(50e3)).into_iter().max_by(|a, b| a.norm().total_cmp(&b.norm())).expect("pole");
        let s = z.ln() * 50e3;
        let xi = -s.re / s.norm();
        assert!((xi - 0.004).abs() < 0.0015, "ξ = {xi}");
    }
}
