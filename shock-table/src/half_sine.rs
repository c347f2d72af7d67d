//! Single positive half-sine pulse.
//!
//! On `0 ≤ t ≤ T` (peak `P`, duration `T`, `ω = π/T`):
//!
//! ```text
//! a(t) = P sin(ωt)
//! v(t) = (P/ω) (1 − cos ωt)
//! d(t) = (P/ω) (t − sin(ωt)/ω)
//! ```
//!
//! Zero for `t < 0`. The pulse does **not** return the base to rest: after
//! `T` the acceleration is zero, the velocity stays at `v_T = 2PT/π` and the
//! displacement grows linearly, `d(t) = PT²/π + v_T (t − T)`. It is the
//! textbook drop-table pulse; for a shock that leaves the base at rest use
//! [`DoubleHalfSine`](crate::DoubleHalfSine).

use std::f64::consts::PI;

use crate::error::{require_positive, ShockError};
use crate::kinematics::Kinematics;

/// Single positive half-sine of acceleration (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfSine {
    /// Peak acceleration `P`, m/s² (> 0).
    pub peak: f64,
    /// Duration `T`, s (> 0).
    pub duration: f64,
}

impl HalfSine {
    /// Half-sine of peak `peak_m_s2` (m/s²) lasting `duration_s` (s); both
    /// finite and > 0.
    ///
    /// ```
    /// let p = shock_table::HalfSine::new(50.0, 0.011).unwrap();
    /// assert_eq!(p.eval(0.0055).accel, 50.0);
    /// ```
    pub fn new(peak_m_s2: f64, duration_s: f64) -> Result<Self, ShockError> {
        require_positive("peak_m_s2", peak_m_s2, "m/s²")?;
        require_positive("duration_s", duration_s, "s")?;
        Ok(Self { peak: peak_m_s2, duration: duration_s })
    }

    /// Velocity at the end of the pulse, `2PT/π`, m/s (kept afterwards).
    pub fn final_velocity(&self) -> f64 {
        2.0 * self.peak * self.duration / PI
    }

    /// Kinematics at time `t` (s) from the pulse start.
    #[inline]
    pub fn eval(&self, t: f64) -> Kinematics {
        if t < 0.0 {
            return Kinematics::default();
        }
        let t_end = self.duration;
        if t < t_end {
            return half_sine_segment(self.peak, t_end, t, 0.0, 0.0);
        }
        let end = half_sine_end(self.peak, t_end, 0.0, 0.0);
        Kinematics { accel: 0.0, vel: end.vel, disp: end.disp + end.vel * (t - t_end) }
    }

    /// Acceleration at `t` (s), m/s².
    #[inline]
    pub fn accel(&self, t: f64) -> f64 {
        if t < 0.0 || t >= self.duration {
            0.0
        } else {
            half_sine_accel(self.peak, self.duration, t)
        }
    }
}

/// Acceleration `p sin(π τ/T)` of a half-sine segment at local time `tau`
/// (same rounding as [`half_sine_segment`]).
#[inline]
pub(crate) fn half_sine_accel(p: f64, t_seg: f64, tau: f64) -> f64 {
    p * (PI / t_seg * tau).sin()
}

/// Kinematics at local time `tau ∈ [0, T]` of a half-sine segment
/// `a = p sin(π τ/T)` that starts with velocity `v0` (m/s) and displacement
/// `d0` (m):
///
/// `v = v0 + (p/ω)(1 − cos ωτ)`, `d = d0 + v0 τ + (p/ω)(τ − sin(ωτ)/ω)`,
/// `ω = π/T`.
#[inline]
pub(crate) fn half_sine_segment(p: f64, t_seg: f64, tau: f64, v0: f64, d0: f64) -> Kinematics {
    let w = PI / t_seg;
    let (s, c) = (w * tau).sin_cos();
    let pw = p / w;
    Kinematics { accel: p * s, vel: v0 + pw * (1.0 - c), disp: d0 + v0 * tau + pw * (tau - s / w) }
}

/// Kinematics at the end `tau = T` of a half-sine segment, in closed form
/// (no trigonometric rounding): `v = v0 + 2pT/π`, `d = d0 + v0 T + pT²/π`,
/// acceleration 0.
#[inline]
pub(crate) fn half_sine_end(p: f64, t_seg: f64, v0: f64, d0: f64) -> Kinematics {
    Kinematics { accel: 0.0, vel: v0 + 2.0 * p * t_seg / PI, disp: d0 + v0 * t_seg + p * t_seg * t_seg / PI }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numeric::{displacement_by_nested_simpson, simpson};

    fn pulse() -> HalfSine {
        HalfSine::new(5.0 * crate::G0_M_S2, 0.011).unwrap()
    }

    #[test]
    fn zero_before_start() {
        assert_eq!(pulse().eval(-1e-9), Kinematics::default());
        assert_eq!(pulse().accel(-1e-9), 0.0);
    }

    #[test]
    fn velocity_is_exact_integral_of_accel() {
        let p = pulse();
        for t in [0.002f64, 0.0055, 0.0109, 0.011, 0.02] {
            let v_num = simpson(|s| p.accel(s), 0.0, t.min(p.duration), 2000);
            let v = p.eval(t).vel;
            assert!((v - v_num).abs() < 1e-10 * p.final_velocity(), "{t}: {v} vs {v_num}");
        }
    }

    #[test]
    fn displacement_is_exact_double_integral() {
        let p = pulse();
        for &t in &[0.004, 0.011, 0.03] {
            let d_num = displacement_by_nested_simpson(|s| p.accel(s), &[p.duration], t, 400);
            let d = p.eval(t).disp;
            assert!((d - d_num).abs() < 1e-10 * d.abs(), "{t}: {d} vs {d_num}");
        }
    }

    #[test]
    fn after_end_velocity_held_displacement_linear() {
        let p = pulse();
        let v_t = p.final_velocity();
        let a = p.eval(0.1);
        let b = p.eval(0.2);
        assert_eq!(a.accel, 0.0);
        assert_eq!(a.vel, v_t);
        assert!(((b.disp - a.disp) - v_t * 0.1).abs() < 1e-14);
        // continuity at T
        let before = p.eval(p.duration * (1.0 - 1e-12));
        let at = p.eval(p.duration);
        assert!((before.vel - at.vel).abs() < 1e-9 * v_t);
        assert!((before.disp - at.disp).abs() < 1e-9 * at.disp);
    }

    #[test]
    fn rejects_bad_parameters() {
        let e = HalfSine::new(-1.0, 0.01).unwrap_err();
        assert_eq!(e.to_string(), "peak_m_s2 = -1 m/s²: must be > 0");
        let e = HalfSine::new(1.0, f64::INFINITY).unwrap_err();
        assert_eq!(e.to_string(), "duration_s = inf s: must be finite");
    }
}
