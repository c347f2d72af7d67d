//! The inductive displacement sensor as the digital controller reads it:
//! gain `A_s` (V/m), optional seeded white noise, optional ADC quantisation.
//!
//! ```text
//! u = Q( A_s Δ + n ),   n ~ N(0, σ²) per axis and sample,   Q(v) = q · round(v / q) clamped to ±V_range
//! ```
//!
//! with `q = 2 V_range / 2^bits`. The noise comes from a seeded generator
//! ([`crate::rng::SplitMix64`], Box–Muller), so a run is reproducible bit for bit.

use crate::rng::SplitMix64;

/// One runout harmonic of one sensor axis (MODEL.md §12.2): a signal locked to the rotor's
/// angle θ that the sensor reads as displacement, `a cos(k θ + φ)`. Mechanical runout (the
/// target surface's out-of-roundness) and electrical runout (the target's varying conductivity
/// and permeability) add the same way; `kind` only labels it.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Harmonic {
    /// The axis: 0 = x, 1 = y (plane A's for a two-plane rotor), 2 = x_B, 3 = y_B.
    pub axis: usize,
    /// The order k ≥ 1 (1 = once per revolution).
    pub order: u32,
    /// Amplitude a (m).
    pub amplitude: f64,
    /// Phase φ (rad), from the keyphasor's angle 0.
    pub phase: f64,
    /// Mechanical or electrical.
    pub kind: RunoutKind,
}

/// What causes a runout harmonic (both add to the signal alike).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RunoutKind {
    /// The target surface's out-of-roundness.
    Mechanical,
    /// The target material's non-uniformity (eddy-current and inductive sensors).
    Electrical,
}

/// The runout of `axis` at rotor angle `angle` (rad): the sum of its harmonics (m).
#[inline]
pub fn runout(harmonics: &[Harmonic], axis: usize, angle: f64) -> f64 {
    harmonics
        .iter()
        .filter(|h| h.axis == axis)
        .map(|h| h.amplitude * (f64::from(h.order) * angle + h.phase).cos())
        .sum()
}

/// The rate of [`runout`] (m/s) of `axis` at rotor angle `angle` (rad) turning at `speed`
/// (rad/s): `−Σ a k θ̇ sin(k θ + φ)`.
#[inline]
pub fn runout_rate(harmonics: &[Harmonic], axis: usize, angle: f64, speed: f64) -> f64 {
    harmonics
        .iter()
        .filter(|h| h.axis == axis)
        .map(|h| {
            let k = f64::from(h.order);
            -h.amplitude * k * speed * (k * angle + h.phase).sin()
        })
        .sum()
}

/// The sensor's low-pass (its bandwidth), on the displacement it measures.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "order", rename_all = "snake_case")]
pub enum LowPass {
    /// First order, `H(s) = ω / (s + ω)`.
    First {
        /// Corner ω (rad/s).
        corner: f64,
    },
    /// Second order Butterworth, `H(s) = ω² / (s² + √2 ω s + ω²)`.
    Second {
        /// Corner ω (rad/s).
        corner: f64,
    },
}

impl LowPass {
    /// The states' rates for input `u` and states `z` (the output `z[0]`, and its rate for the
    /// second order): `ż₀ = ω (u − z₀)`, or `ż₀ = z₁`, `ż₁ = ω² (u − z₀) − √2 ω z₁`.
    #[inline]
    pub fn rates(&self, u: f64, z: [f64; 2]) -> [f64; 2] {
        match *self {
            LowPass::First { corner } => [corner * (u - z[0]), 0.0],
            LowPass::Second { corner } => {
                [z[1], corner * corner * (u - z[0]) - std::f64::consts::SQRT_2 * corner * z[1]]
            }
        }
    }

    /// The frequency response `H(jω)` at `omega` (rad/s): (magnitude, phase in rad).
    pub fn response(&self, omega: f64) -> (f64, f64) {
        match *self {
            LowPass::First { corner } => {
                let r = omega / corner;
                (1.0 / (1.0 + r * r).sqrt(), -r.atan())
            }
            LowPass::Second { corner } => {
                let r = omega / corner;
                let (re, im) = (1.0 - r * r, std::f64::consts::SQRT_2 * r);
                (1.0 / re.hypot(im), -im.atan2(re))
            }
        }
    }

    /// The corner ω (rad/s).
    pub fn corner(&self) -> f64 {
        match *self {
            LowPass::First { corner } | LowPass::Second { corner } => corner,
        }
    }
}

/// What lies between the rotor and the sensor's voltage besides the gain, noise and ADC: its
/// bandwidth, runout, and measurement range (the scene's `[sensor]`; all off by default).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct FrontEnd {
    /// The low-pass; `None`: ideal.
    pub low_pass: Option<LowPass>,
    /// The runout harmonics.
    pub runout: Vec<Harmonic>,
    /// The measurement range ±r (m); `None`: unlimited.
    pub range: Option<f64>,
}

impl FrontEnd {
    /// Whether any part is on.
    pub fn is_on(&self) -> bool {
        self.low_pass.is_some() || !self.runout.is_empty() || self.range.is_some()
    }

    /// The measured displacement `d` (m) clipped to the range.
    #[inline]
    pub fn clip(&self, d: f64) -> f64 {
        match self.range {
            Some(r) => d.clamp(-r, r),
            None => d,
        }
    }

    /// The rate (m/s) of what the sensor reads, the range's [`FrontEnd::clip`] of the filter's
    /// output `z[0]` (of its input `u`, m, without a filter): the filter's output rate, or the
    /// input's rate `u_rate` (m/s) without one; 0 while the range clips. What an analog
    /// controller differentiates (MODEL.md §12.2).
    #[inline]
    pub fn rate(&self, u: f64, u_rate: f64, z: [f64; 2]) -> f64 {
        let (d, rate) = match self.low_pass {
            Some(lp) => (z[0], lp.rates(u, z)[0]),
            None => (u, u_rate),
        };
        match self.range {
            Some(r) if d.abs() > r => 0.0,
            _ => rate,
        }
    }
}

/// Sensor settings (the scene's `[sensor]` table).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SensorSettings {
    /// Gain A_s (V/m).
    pub gain: f64,
    /// Noise standard deviation (V); 0 = none.
    pub noise_v: f64,
    /// Noise seed.
    pub seed: u64,
    /// ADC resolution (bits); 0 = ideal (no quantisation).
    pub adc_bits: u32,
    /// ADC input range ±V_range (V).
    pub adc_range_v: f64,
}

/// A sensor with its noise generator state.
#[derive(Clone, Debug)]
pub struct Sensor {
    settings: SensorSettings,
    rng: SplitMix64,
}

impl Sensor {
    /// A sensor at the start of a run.
    pub fn new(settings: SensorSettings) -> Self {
        Self { settings, rng: SplitMix64::new(settings.seed) }
    }

    /// The noise generator's state (a snapshot's).
    pub fn rng_state(&self) -> u64 {
        self.rng.state()
    }

    /// Puts the noise generator at `state` ([`Sensor::rng_state`]).
    pub fn set_rng_state(&mut self, state: u64) {
        self.rng = SplitMix64::new(state);
    }

    /// The voltages the controller reads for displacement `delta` (m), x then y.
    pub fn read(&mut self, delta: [f64; 2]) -> [f64; 2] {
        self.read_with_gain(delta, self.settings.gain)
    }

    /// [`Sensor::read`] through a sensor of gain `gain` (V/m): a bearing plane's own, with the
    /// noise and the ADC of the settings (one noise sequence for all the planes' sensors, read
    /// in plane order).
    pub fn read_with_gain(&mut self, delta: [f64; 2], gain: f64) -> [f64; 2] {
        let s = self.settings;
        let mut u = [gain * delta[0], gain * delta[1]];
        if s.noise_v > 0.0 {
            let n = self.rng.normal_pair();
            u = [u[0] + s.noise_v * n[0], u[1] + s.noise_v * n[1]];
        }
        if s.adc_bits > 0 {
            let q = 2.0 * s.adc_range_v / 2f64.powi(s.adc_bits as i32);
            for v in &mut u {
                *v = (q * (*v / q).round()).clamp(-s.adc_range_v, s.adc_range_v);
            }
        }
        u
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ideal() -> SensorSettings {
        SensorSettings { gain: 25_000.0, noise_v: 0.0, seed: 1, adc_bits: 0, adc_range_v: 10.0 }
    }

    /// A sine of `omega` (rad/s) through `lp` (RK4, fine step), after the transient: the
    /// amplitude and phase of the output's fundamental against the input's.
    fn measured_response(lp: LowPass, omega: f64) -> (f64, f64) {
        let period = std::f64::consts::TAU / omega;
        let h = period / 2000.0;
        let mut z = [0.0; 2];
        let mut t = 0.0;
        let settle = 40.0 * period;
        let (mut c, mut s) = (0.0, 0.0);
        let step = |t: f64, z: [f64; 2]| {
            let f = |t: f64, z: [f64; 2]| lp.rates((omega * t).sin(), z);
            let k1 = f(t, z);
            let k2 = f(t + h / 2.0, [z[0] + h / 2.0 * k1[0], z[1] + h / 2.0 * k1[1]]);
            let k3 = f(t + h / 2.0, [z[0] + h / 2.0 * k2[0], z[1] + h / 2.0 * k2[1]]);
            let k4 = f(t + h, [z[0] + h * k3[0], z[1] + h * k3[1]]);
            [
                z[0] + h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
                z[1] + h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
            ]
        };
        let n = (settle / h).round() as usize;
        for _ in 0..n {
            z = step(t, z);
            t += h;
        }
        // One whole period more: the output's Fourier coefficients at omega (rectangle rule).
        for _ in 0..2000 {
            z = step(t, z);
            t += h;
            c += z[0] * (omega * t).cos() * h;
            s += z[0] * (omega * t).sin() * h;
        }
        let (c, s) = (2.0 * c / period, 2.0 * s / period);
        // z = A sin(ω t + φ) = A (sin cos φ + cos sin φ): s = A cos φ, c = A sin φ.
        (c.hypot(s), c.atan2(s))
    }

    #[test]
    fn a_low_pass_lags_as_its_transfer_function() {
        for lp in [
            LowPass::First { corner: 2.0 * std::f64::consts::PI * 5000.0 },
            LowPass::Second { corner: 2.0 * std::f64::consts::PI * 5000.0 },
        ] {
            for f in [500.0, 3000.0, 5000.0] {
                let omega = std::f64::consts::TAU * f;
                let (mag, phase) = measured_response(lp, omega);
                let (emag, ephase) = lp.response(omega);
                assert!((mag - emag).abs() < 1e-4, "{lp:?} at {f} Hz: |H| {mag} against {emag}");
                assert!((phase - ephase).abs() < 1e-3, "{lp:?} at {f} Hz: phase {phase} against {ephase}");
            }
        }
        // The first order's lag at its corner is 45°, the second's 90°.
        let w = 1000.0;
        assert!((LowPass::First { corner: w }.response(w).1 + std::f64::consts::FRAC_PI_4).abs() < 1e-12);
        assert!((LowPass::Second { corner: w }.response(w).1 + std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }

    #[test]
    fn runout_sums_its_harmonics_per_axis() {
        let h =
            |axis, order, amplitude, phase| Harmonic { axis, order, amplitude, phase, kind: RunoutKind::Mechanical };
        let list = [h(0, 1, 2e-6, 0.3), h(0, 2, 1e-6, -1.0), h(1, 1, 3e-6, 0.0)];
        let theta = 0.7;
        let x = 2e-6 * (theta + 0.3f64).cos() + 1e-6 * (2.0 * theta - 1.0f64).cos();
        assert_eq!(runout(&list, 0, theta), x);
        assert_eq!(runout(&list, 1, theta), 3e-6 * theta.cos());
        assert_eq!(runout(&list, 2, theta), 0.0);
    }

    /// The runout's rate is the derivative of the runout along a turning rotor (central
    /// differences).
    #[test]
    fn runout_rate_is_the_runouts_derivative() {
        let h =
            |axis, order, amplitude, phase| Harmonic { axis, order, amplitude, phase, kind: RunoutKind::Electrical };
        let list = [h(0, 1, 2e-6, 0.3), h(0, 3, 1e-6, -1.0), h(1, 2, 3e-6, 0.5)];
        let speed = std::f64::consts::TAU * 500.0;
        let dt = 1e-9;
        for k in 0..50 {
            let theta = 0.13 * k as f64;
            for axis in 0..3 {
                let numeric =
                    (runout(&list, axis, theta + speed * dt) - runout(&list, axis, theta - speed * dt)) / (2.0 * dt);
                let exact = runout_rate(&list, axis, theta, speed);
                assert!(
                    (numeric - exact).abs() < 1e-6 * (1.0 + exact.abs()),
                    "axis {axis}, θ = {theta}: {numeric} against {exact}"
                );
            }
        }
        assert_eq!(runout_rate(&list, 2, 1.0, speed), 0.0);
    }

    /// What an analog controller differentiates: the input's rate, the filter's output rate, 0
    /// while the range clips.
    #[test]
    fn the_front_ends_rate_is_the_filters_or_the_inputs_and_zero_when_clipped() {
        let ideal = FrontEnd::default();
        assert_eq!(ideal.rate(1e-4, 0.02, [0.0; 2]), 0.02);
        let ranged = FrontEnd { range: Some(1.5e-4), ..FrontEnd::default() };
        assert_eq!(ranged.rate(1e-4, 0.02, [0.0; 2]), 0.02);
        assert_eq!(ranged.rate(1.6e-4, 0.02, [0.0; 2]), 0.0);
        assert_eq!(ranged.rate(-1.6e-4, -0.02, [0.0; 2]), 0.0);
        let w = 2.0 * std::f64::consts::PI * 5000.0;
        let second = FrontEnd { low_pass: Some(LowPass::Second { corner: w }), ..FrontEnd::default() };
        // The Butterworth's output rate is its second state, whatever the input.
        assert_eq!(second.rate(1e-4, 0.02, [5e-5, 0.3]), 0.3);
        let first =
            FrontEnd { low_pass: Some(LowPass::First { corner: w }), range: Some(1.5e-4), ..FrontEnd::default() };
        assert_eq!(first.rate(1e-4, 0.02, [5e-5, 0.0]), w * (1e-4 - 5e-5));
        // Clipped on the filter's output, not the input.
        assert_eq!(first.rate(2e-4, 0.02, [1.4e-4, 0.0]), w * (2e-4 - 1.4e-4));
        assert_eq!(first.rate(2e-4, 0.02, [1.6e-4, 0.0]), 0.0);
    }

    #[test]
    fn ideal_sensor_is_the_gain() {
        assert_eq!(Sensor::new(ideal()).read([1e-5, -2e-5]), [0.25, -0.5]);
    }

    #[test]
    fn quantisation_rounds_to_the_lsb_and_clips() {
        let mut s = Sensor::new(SensorSettings { adc_bits: 12, ..ideal() });
        let q: f64 = 20.0 / 4096.0;
        let u = s.read([1.234e-5, 1.0]);
        assert!((u[0] - q * (0.3085 / q).round()).abs() < 1e-15 && (u[0] - 0.3085).abs() <= q / 2.0);
        assert_eq!(u[1], 10.0);
    }

    #[test]
    fn noise_has_the_set_deviation_and_is_reproducible() {
        let set = SensorSettings { noise_v: 0.01, ..ideal() };
        let (mut a, mut b) = (Sensor::new(set), Sensor::new(set));
        let xs: Vec<f64> = (0..20_000).map(|_| a.read([0.0; 2])[0]).collect();
        let ys: Vec<f64> = (0..20_000).map(|_| b.read([0.0; 2])[0]).collect();
        assert_eq!(xs, ys);
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let sd = (xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / xs.len() as f64).sqrt();
        assert!(mean.abs() < 3e-4 && (sd - 0.01).abs() < 3e-4, "mean {mean}, sd {sd}");
        let other: Vec<f64> = (0..10)
            .map(|_| 0.0)
            .scan(Sensor::new(SensorSettings { seed: 2, ..set }), |s, _| Some(s.read([0.0; 2])[0]))
            .collect();
        assert_ne!(other, xs[..10].to_vec());
    }
}
