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
