//! The vibration of the levitated rotor before any shock, graded as ISO 14839-2 does: the
//! peak of the orbit at the sensor (the largest distance of the rotor's centre from the
//! housing's) relative to the minimum radial clearance `C_min` (the touchdown bearing's air gap
//! `r_0`), zone boundaries at 0.3, 0.4 and 0.5 `C_min`; with the coil current it takes (its
//! mean, the largest swing about the mean and the RMS of the swing, per axis).
//!
//! The run: the scene at its rotor speed with the shocks moved past its end, on the members'
//! fast setting; the first `settle_s` are left out (the start from the continuous design's
//! unbalance orbit settles under a sampled law), the figures come from the following `window_s`.
//! A rotor that touches a touchdown bearing in this run is **not levitated**. The two-plane
//! rotor is graded at each bearing plane against its own clearance; the worst plane governs.

use crate::run::Sink;
use crate::trace::Record;
use serde::Serialize;

/// The ISO 14839-2 zone of a displacement ratio `d / C_min`.
pub fn zone(ratio: f64) -> &'static str {
    super::iso_zone::grade(ratio, [0.3, 0.4, 0.5])
}

/// The vibration figures: the governing plane's (the largest `peak / C_min`) at the top,
/// each bearing plane's in `planes` (one for the planar model).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Vibration {
    /// Rotor speed (Hz).
    pub speed_hz: f64,
    /// Peak of the orbit over the window (µm), at the governing plane.
    pub peak_um: f64,
    /// Minimum radial clearance C_min (µm) of the governing plane.
    pub clearance_um: f64,
    /// `peak / C_min` of the governing plane.
    pub ratio: f64,
    /// `A` … `D`: the governing plane's, the worst.
    pub zone: String,
    /// The coil currents over the window and the amplifier's limit.
    #[serde(flatten)]
    pub coil: Currents,
    /// Settling left out and window (s).
    pub settle_s: f64,
    /// Window (s).
    pub window_s: f64,
    /// The governing plane (`A` or `B`; the planar model: `A`).
    pub plane: String,
    /// Each plane's peak, clearance, ratio and zone.
    pub planes: Vec<PlaneVibration>,
}

/// The coil currents over the window, per axis (x, y of each plane in order), against the
/// amplifier's limit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Currents {
    /// Mean coil current per axis (A).
    pub current_mean_a: Vec<f64>,
    /// Largest swing of the coil current about its mean per axis (A).
    pub current_swing_a: Vec<f64>,
    /// RMS of the swing per axis (A).
    pub current_rms_a: Vec<f64>,
    /// The amplifier's current limit (A).
    pub current_limit_a: f64,
}

/// One bearing plane's vibration.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlaneVibration {
    /// `A` or `B`.
    pub plane: String,
    /// Peak of the orbit at the bearing over the window (µm).
    pub peak_um: f64,
    /// The plane's minimum radial clearance C_min (µm).
    pub clearance_um: f64,
    /// `peak / C_min`.
    pub ratio: f64,
    /// `A` … `D`.
    pub zone: String,
}

/// Whether the rotor at any plane's bearing is farther from the race's centre than that plane's
/// air gap `gaps[i]` (m) in `record`.
pub fn touching(record: &Record, gaps: &[f64]) -> bool {
    (0..record.planes()).any(|i| {
        let r = record.plane(i);
        let d = (r.motion.dx_m - r.motion.xb_m).hypot(r.motion.dy_m - r.motion.yb_m);
        gaps.get(i).is_some_and(|g| d > *g)
    })
}

/// Takes the figures over `[from, ∞)` and notes the first contact.
pub struct VibrationSink {
    from: f64,
    gaps: Vec<f64>,
    /// First contact (s).
    pub touched: Option<f64>,
    peak: Vec<f64>,
    n: f64,
    sum: Vec<f64>,
    sum2: Vec<f64>,
    min: Vec<f64>,
    max: Vec<f64>,
}

impl VibrationSink {
    /// Figures from time `from` (s), for planes of air gaps `gaps` (m).
    pub fn new(from: f64, gaps: Vec<f64>) -> Self {
        let axes = 2 * gaps.len();
        Self {
            from,
            peak: vec![0.0; gaps.len()],
            gaps,
            touched: None,
            n: 0.0,
            sum: vec![0.0; axes],
            sum2: vec![0.0; axes],
            min: vec![f64::INFINITY; axes],
            max: vec![f64::NEG_INFINITY; axes],
        }
    }

    /// The figures; current `limit` (A), speed (Hz), settle and window (s).
    pub fn figures(&self, limit: f64, speed_hz: f64, settle_s: f64, window_s: f64) -> Vibration {
        let n = self.n.max(1.0);
        let axes = self.sum.len();
        let mean: Vec<f64> = self.sum.iter().map(|s| s / n).collect();
        let rms = (0..axes).map(|k| (self.sum2[k] / n - mean[k] * mean[k]).max(0.0).sqrt()).collect();
        let swing = (0..axes).map(|k| (self.max[k] - mean[k]).max(mean[k] - self.min[k])).collect();
        let planes: Vec<PlaneVibration> = self
            .peak
            .iter()
            .zip(&self.gaps)
            .enumerate()
            .map(|(i, (peak, gap))| PlaneVibration {
                plane: ["A", "B"][i.min(1)].into(),
                peak_um: peak * 1e6,
                clearance_um: gap * 1e6,
                ratio: peak / gap,
                zone: zone(peak / gap).into(),
            })
            .collect();
        let worst = planes.iter().max_by(|a, b| a.ratio.total_cmp(&b.ratio)).cloned().unwrap_or(PlaneVibration {
            plane: "A".into(),
            peak_um: 0.0,
            clearance_um: 0.0,
            ratio: f64::NAN,
            zone: "none".into(),
        });
        Vibration {
            speed_hz,
            peak_um: worst.peak_um,
            clearance_um: worst.clearance_um,
            ratio: worst.ratio,
            zone: worst.zone,
            coil: Currents { current_mean_a: mean, current_swing_a: swing, current_rms_a: rms, current_limit_a: limit },
            settle_s,
            window_s,
            plane: worst.plane,
            planes,
        }
    }
}

impl Sink for VibrationSink {
    fn sample(&mut self, record: &Record) {
        let t = record.a.t_s;
        if self.touched.is_none() && touching(record, &self.gaps) {
            self.touched = Some(t);
        }
        if t < self.from {
            return;
        }
        self.n += 1.0;
        for i in 0..record.planes().min(self.gaps.len()) {
            let r = record.plane(i);
            self.peak[i] = self.peak[i].max(r.motion.dx_m.hypot(r.motion.dy_m));
            for (j, a) in [r.loads.ix_a, r.loads.iy_a].into_iter().enumerate() {
                let k = 2 * i + j;
                self.sum[k] += a;
                self.sum2[k] += a * a;
                self.min[k] = self.min[k].min(a);
                self.max[k] = self.max[k].max(a);
            }
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
