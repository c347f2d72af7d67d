//! Sinusoidal base vibration (shaker test) over whole cycles.
//!
//! Amplitude `A`, frequency `f`, `ω = 2πf`, `n` whole cycles, so the
//! duration is `T = n/f`. Starting from rest, on `0 ≤ t < T`:
//!
//! ```text
//! a(t) = A cos(ωt)
//! v(t) = (A/ω) sin(ωt)
//! d(t) = (A/ω²)(1 − cos ωt)
//! ```
//!
//! The cosine start makes the velocity zero-mean over each cycle, so the
//! base does not drift: it oscillates between `0` and `2A/ω²` about the mean
//! offset `A/ω²`, and after the last cycle (`t ≥ T`) acceleration,
//! velocity and displacement are all exactly zero (the formulas give zero
//! there up to rounding; the pulse returns exact zeros). The acceleration
//! steps from 0 to `A` at `t = 0` and from `A` to 0 at `t = T`. Zero for
//! `t < 0`.

use std::f64::consts::PI;

use crate::error::{invalid, require_positive, ShockError};
use crate::kinematics::Kinematics;

/// Sinusoidal base vibration over a whole number of cycles (see the module
/// doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SineVibration {
    /// Acceleration amplitude `A`, m/s² (> 0).
    pub amplitude: f64,
    /// Frequency `f`, Hz (> 0).
    pub freq_hz: f64,
    /// Number of whole cycles `n` (≥ 1).
    pub cycles: u32,
}

impl SineVibration {
    /// Vibration of amplitude `amplitude_m_s2` (m/s², > 0) at `freq_hz`
    /// (Hz, > 0) for `cycles` (≥ 1) whole cycles.
    ///
    /// ```
    /// let s = shock_table::SineVibration::new(9.80665, 20.0, 40).unwrap();
    /// assert_eq!(s.duration(), 2.0);
    /// assert_eq!(s.eval(2.5).disp, 0.0);
    /// ```
    pub fn new(amplitude_m_s2: f64, freq_hz: f64, cycles: u32) -> Result<Self, ShockError> {
        require_positive("amplitude_m_s2", amplitude_m_s2, "m/s²")?;
        require_positive("freq_hz", freq_hz, "Hz")?;
        if cycles == 0 {
            return Err(invalid("cycles", 0.0, "", "must be >= 1"));
        }
        Ok(Self { amplitude: amplitude_m_s2, freq_hz, cycles })
    }

    /// Duration `n/f`, s.
    pub fn duration(&self) -> f64 {
        f64::from(self.cycles) / self.freq_hz
    }

    /// Kinematics at time `t` (s) from the start.
    #[inline]
    pub fn eval(&self, t: f64) -> Kinematics {
        if t < 0.0 || t >= self.duration() {
            return Kinematics::default();
        }
        let w = 2.0 * PI * self.freq_hz;
        let (s, c) = (w * t).sin_cos();
        let a = self.amplitude;
        Kinematics { accel: a * c, vel: a / w * s, disp: a / (w * w) * (1.0 - c) }
    }

    /// Acceleration at `t` (s), m/s².
    #[inline]
    pub fn accel(&self, t: f64) -> f64 {
        if t < 0.0 || t >= self.duration() {
            0.0
        } else {
            self.amplitude * (2.0 * PI * self.freq_hz * t).cos()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numeric::{displacement_by_nested_simpson, simpson_piecewise};

    #[test]
    fn exact_integrals_match_numerical() {
        let s = SineVibration::new(9.80665, 20.0, 3).unwrap();
        let a = |t: f64| s.accel(t);
        let w = 2.0 * PI * 20.0;
        let vmax = s.amplitude / w;
        let dmax = 2.0 * s.amplitude / (w * w);
        for t in [0.01, 0.0625, 0.1, 0.149] {
            let k = s.eval(t);
            let v = simpson_piecewise(&a, &[], t, 4000);
            assert!((k.vel - v).abs() < 1e-10 * vmax, "v at {t}: {} vs {v}", k.vel);
            let d = displacement_by_nested_simpson(a, &[], t, 1500);
            assert!((k.disp - d).abs() < 1e-9 * dmax, "d at {t}: {} vs {d}", k.disp);
        }
    }

    #[test]
    fn ends_at_rest_with_zero_displacement() {
        let s = SineVibration::new(3.0, 33.0, 7).unwrap();
        let t_end = s.duration();
        let w = 2.0 * PI * 33.0;
        let before = s.eval(t_end * (1.0 - 1e-12));
        assert!(before.vel.abs() < 1e-9 * s.amplitude / w);
        assert!(before.disp.abs() < 1e-9 * s.amplitude / (w * w));
        assert_eq!(s.eval(t_end), Kinematics::default());
        assert_eq!(s.eval(10.0), Kinematics::default());
        // zero-mean velocity over the run: the displacement at the end is 0
        let v_mean = simpson_piecewise(&|t| s.eval(t).vel, &[], t_end, 7 * 200) / t_end;
        assert!(v_mean.abs() < 1e-12 * s.amplitude / w);
    }

    #[test]
    fn starts_from_rest() {
        let s = SineVibration::new(3.0, 4.0, 1).unwrap();
        let k = s.eval(0.0);
        assert_eq!((k.accel, k.vel, k.disp), (3.0, 0.0, 0.0));
        assert_eq!(s.eval(-1e-3), Kinematics::default());
    }

    #[test]
    fn rejects_zero_cycles_and_bad_numbers() {
        assert_eq!(SineVibration::new(1.0, 1.0, 0).unwrap_err().to_string(), "cycles = 0: must be >= 1");
        assert_eq!(SineVibration::new(1.0, 0.0, 3).unwrap_err().to_string(), "freq_hz = 0 Hz: must be > 0");
        assert!(SineVibration::new(-1.0, 1.0, 3).is_err());
    }
}
