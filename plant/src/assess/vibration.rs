//! The vibration of the levitated rotor before any shock, graded as ISO 14839-2 does: the
//! peak of the orbit at the sensor (the largest distance of the rotor's centre from the
//! housing's) relative to the minimum radial clearance `C_min` (the touchdown bearing's air gap
//! `r_0`), zone boundaries at 0.3, 0.4 and 0.5 `C_min`; with the coil current it takes (its
//! mean, the largest swing about the mean and the RMS of the swing, per axis).
//!
//! The run: the scene at its rotor speed with the shocks moved past its end, on the members'
//! fast setting; the first `settle_s` are left out (the start from the continuous design's
//! unbalance orbit settles under a sampled law), the figures come from the following `window_s`.
//! A rotor that touches the touchdown bearing in this run is **not levitated**.

use crate::model::{ix, Model, State};
use crate::run::Sink;
use serde::Serialize;

/// The ISO 14839-2 zone of a displacement ratio `d / C_min`.
pub fn zone(ratio: f64) -> &'static str {
    match ratio {
        r if r < 0.3 => "A",
        r if r < 0.4 => "B",
        r if r < 0.5 => "C",
        _ => "D",
    }
}

/// The vibration figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Vibration {
    /// Rotor speed (Hz).
    pub speed_hz: f64,
    /// Peak of the orbit over the window (µm).
    pub peak_um: f64,
    /// Minimum radial clearance C_min (µm).
    pub clearance_um: f64,
    /// `peak / C_min`.
    pub ratio: f64,
    /// `A` … `D`.
    pub zone: String,
    /// Mean coil current per axis (A).
    pub current_mean_a: Vec<f64>,
    /// Largest swing of the coil current about its mean per axis (A).
    pub current_swing_a: Vec<f64>,
    /// RMS of the swing per axis (A).
    pub current_rms_a: Vec<f64>,
    /// The amplifier's current limit (A).
    pub current_limit_a: f64,
    /// Settling left out and window (s).
    pub settle_s: f64,
    /// Window (s).
    pub window_s: f64,
}

/// Takes the figures over `[from, ∞)` and notes the first contact.
pub struct VibrationSink {
    from: f64,
    /// First contact (s).
    pub touched: Option<f64>,
    peak: f64,
    n: f64,
    sum: [f64; 2],
    sum2: [f64; 2],
    min: [f64; 2],
    max: [f64; 2],
}

impl VibrationSink {
    /// Figures from time `from` (s).
    pub fn new(from: f64) -> Self {
        Self {
            from,
            touched: None,
            peak: 0.0,
            n: 0.0,
            sum: [0.0; 2],
            sum2: [0.0; 2],
            min: [f64::INFINITY; 2],
            max: [f64::NEG_INFINITY; 2],
        }
    }

    /// The figures; `clearance` (m), `limit` (A), speed (Hz), settle and window (s).
    pub fn figures(&self, clearance: f64, limit: f64, speed_hz: f64, settle_s: f64, window_s: f64) -> Vibration {
        let mean: Vec<f64> = self.sum.iter().map(|s| s / self.n.max(1.0)).collect();
        let rms = (0..2).map(|k| (self.sum2[k] / self.n.max(1.0) - mean[k] * mean[k]).max(0.0).sqrt()).collect();
        let swing = (0..2).map(|k| (self.max[k] - mean[k]).max(mean[k] - self.min[k])).collect();
        let ratio = self.peak / clearance;
        Vibration {
            speed_hz,
            peak_um: self.peak * 1e6,
            clearance_um: clearance * 1e6,
            ratio,
            zone: zone(ratio).to_string(),
            current_mean_a: mean,
            current_swing_a: swing,
            current_rms_a: rms,
            current_limit_a: limit,
            settle_s,
            window_s,
        }
    }
}

impl Sink for VibrationSink {
    fn sample(&mut self, _record: &crate::trace::Record) {}

    fn planar_state(&mut self, model: &Model, t: f64, y: &State) {
        let d = (y[ix::XR] - y[ix::XB]).hypot(y[ix::YR] - y[ix::YB]);
        if d > model.params.contact.gap && self.touched.is_none() {
            self.touched = Some(t);
        }
        if t < self.from {
            return;
        }
        self.peak = self.peak.max(y[ix::XR].hypot(y[ix::YR]));
        let i = model.evaluate(t, y).current;
        self.n += 1.0;
        for (k, &a) in i.iter().enumerate() {
            self.sum[k] += a;
            self.sum2[k] += a * a;
            self.min[k] = self.min[k].min(a);
            self.max[k] = self.max[k].max(a);
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn zones_at_the_standards_boundaries() {
        assert_eq!(super::zone(0.29), "A");
        assert_eq!(super::zone(0.3), "B");
        assert_eq!(super::zone(0.45), "C");
        assert_eq!(super::zone(0.5), "D");
    }
}
