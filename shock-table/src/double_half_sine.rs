//! BV043/85 double half-sine base shock.
//!
//! The shock is specified by its design acceleration `A_0` and the corner
//! frequencies `f_1 < f_2` of its shock response spectrum (displacement-
//! limited below `f_1`, velocity-limited between, acceleration-limited above
//! `f_2`). From them (MODEL.md §6):
//!
//! ```text
//! V_0 = A_0 / (2π f_2)          D_0 = V_0 / (2π f_1)
//! a_1 = A_0 / 2                 t_1 = 2π V_0 / (3 A_0) = 1 / (3 f_2)
//! t_2 = t_1 + 3 D_0 / V_0 = t_1 + 3 / (2π f_1)
//! ```
//!
//! The housing acceleration is a positive half-sine of amplitude `a_1` on
//! `[0, t_1]` and a negative half-sine of amplitude `a_2 < 0` on
//! `[t_1, t_2]` (`T = t_2 − t_1`, `τ = t − t_1`), zero before and after:
//!
//! ```text
//! 0 ≤ t < t_1:  a = a_1 sin(πt/t_1)
//!               v = (a_1 t_1/π)(1 − cos(πt/t_1))
//!               d = (a_1 t_1/π)(t − (t_1/π) sin(πt/t_1))
//! t_1 ≤ t < t_2: a = a_2 sin(πτ/T)
//!               v = v_1 + (a_2 T/π)(1 − cos(πτ/T))
//!               d = d_1 + v_1 τ + (a_2 T/π)(τ − (T/π) sin(πτ/T))
//! t ≥ t_2:      a = 0, v = v_2, d = h + v_2 (t − t_2)
//! ```
//!
//! with `v_1 = 2 a_1 t_1/π`, `d_1 = a_1 t_1²/π`. The integral of a half-sine
//! of amplitude `a` over a duration `T` is `2aT/π`, so the velocity returns
//! to zero at `t_2` (`v_2 = 0`) if and only if
//!
//! ```text
//! a_2 = −a_1 t_1 / (t_2 − t_1)
//! ```
//!
//! and the base then ends lifted by `h = d(t_2) = a_1 t_1 t_2 / π`.
//!
//! **Misprint in the study.** The study prints `a_2 = π V_0 / (t_2 − t_1)`,
//! which does not satisfy the velocity condition (for `A_0 = 20 G`, `f_1 = 10 Hz`,
//! `f_2 = 80 Hz`, it gives `+2.62 G`). Its Table 1 rows for 10 G and 20 G
//! (`a_2 = −0.87 G`, `−1.75 G`) agree with the velocity condition, but its
//! 3 G row prints `−0.44 G` where the condition gives `≈ −0.26 G`; this
//! crate derives `a_2` and pins the discrepancy in the test
//! `table1_3g_row_misprint`. The study's `h` column (2.03, 6.75, 13.51 mm)
//! is reproduced to its rounding with `G = 9.81 m/s²`; with the standard
//! `G = 9.80665 m/s²` used here the 20 G row gives 13.50 mm.

use std::f64::consts::PI;

use crate::error::{invalid, require_positive, ShockError};
use crate::half_sine::{half_sine_accel, half_sine_end, half_sine_segment};
use crate::kinematics::Kinematics;

/// BV043/85 double half-sine pulse (see the module doc for the equations).
///
/// Build it with [`from_design`](Self::from_design) or
/// [`from_peak`](Self::from_peak), which derive `a_2` from the velocity
/// returning to zero; the fields are public for inspection, and a pulse
/// built by hand with another `a_2` ends with nonzero velocity
/// ([`final_velocity`](Self::final_velocity)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DoubleHalfSine {
    /// Amplitude of the positive half-sine, m/s² (> 0); `a_1 = A_0/2`.
    pub a1: f64,
    /// Amplitude of the negative half-sine, m/s² (< 0);
    /// `a_2 = −a_1 t_1/(t_2 − t_1)`.
    pub a2: f64,
    /// End of the positive half-sine, s; `t_1 = 1/(3 f_2)`.
    pub t1: f64,
    /// End of the negative half-sine (end of the pulse), s;
    /// `t_2 = t_1 + 3/(2π f_1)`.
    pub t2: f64,
}

impl DoubleHalfSine {
    /// From the design acceleration `A_0` (m/s²) and SRS corner frequencies
    /// `f_1 < f_2` (Hz) (MODEL.md §6).
    ///
    /// `f_2 > f_1` is required: the design spectrum is displacement-limited
    /// below `f_1` and acceleration-limited above `f_2`, with the velocity
    /// plateau `V_0` between them.
    ///
    /// ```
    /// use shock_table::{DoubleHalfSine, G0_M_S2};
    /// let p = DoubleHalfSine::from_design(20.0 * G0_M_S2, 10.0, 80.0).unwrap();
    /// assert!((p.a1 / G0_M_S2 - 10.0).abs() < 1e-12);
    /// assert!(p.eval(p.t2).vel.abs() < 1e-12);
    /// ```
    pub fn from_design(a0_m_s2: f64, f1_hz: f64, f2_hz: f64) -> Result<Self, ShockError> {
        check_design(("design_accel_m_s2", a0_m_s2, "m/s²"), f1_hz, f2_hz)?;
        Ok(Self::derive(a0_m_s2, f1_hz, f2_hz))
    }

    /// From the peak acceleration `a_1` (m/s²) of the pulse (`= A_0/2`), as
    /// the study's Table 1 lists it, and the corner frequencies (Hz).
    ///
    /// ```
    /// use shock_table::{DoubleHalfSine, G0_M_S2};
    /// let p = DoubleHalfSine::from_peak(10.0 * G0_M_S2, 10.0, 80.0).unwrap();
    /// assert!((p.lift() * 1e3 - 6.75).abs() < 0.005); // h, mm
    /// ```
    pub fn from_peak(a1_m_s2: f64, f1_hz: f64, f2_hz: f64) -> Result<Self, ShockError> {
        check_design(("peak_m_s2", a1_m_s2, "m/s²"), f1_hz, f2_hz)?;
        Ok(Self::derive(2.0 * a1_m_s2, f1_hz, f2_hz))
    }

    fn derive(a0: f64, f1: f64, f2: f64) -> Self {
        let v0 = a0 / (2.0 * PI * f2);
        let d0 = v0 / (2.0 * PI * f1);
        let a1 = a0 / 2.0;
        let t1 = 2.0 * PI * v0 / (3.0 * a0);
        let t2 = t1 + 3.0 * d0 / v0;
        let a2 = -a1 * t1 / (t2 - t1);
        Self { a1, a2, t1, t2 }
    }

    /// Design acceleration `A_0 = 2 a_1`, m/s².
    pub fn design_accel(&self) -> f64 {
        2.0 * self.a1
    }

    /// Design velocity `V_0 = A_0/(2π f_2) = 3 a_1 t_1/π`, m/s.
    pub fn design_velocity(&self) -> f64 {
        3.0 * self.a1 * self.t1 / PI
    }

    /// Design displacement `D_0 = V_0/(2π f_1) = V_0 (t_2 − t_1)/3`, m.
    pub fn design_displacement(&self) -> f64 {
        self.design_velocity() * (self.t2 - self.t1) / 3.0
    }

    /// Peak velocity of the base, reached at `t_1`: `v_1 = 2 a_1 t_1/π`, m/s.
    pub fn peak_velocity(&self) -> f64 {
        2.0 * self.a1 * self.t1 / PI
    }

    /// Velocity after the pulse, `v_1 + 2 a_2 (t_2 − t_1)/π`, m/s; zero (to
    /// rounding) for a pulse from [`from_design`](Self::from_design) or
    /// [`from_peak`](Self::from_peak).
    pub fn final_velocity(&self) -> f64 {
        self.end().vel
    }

    /// Lift `h`: displacement of the base at the end of the pulse `t_2`, m.
    /// For a derived `a_2`, `h = a_1 t_1 t_2/π`.
    pub fn lift(&self) -> f64 {
        self.end().disp
    }

    /// Pulse duration `t_2`, s.
    pub fn duration(&self) -> f64 {
        self.t2
    }

    /// State at `t_1`.
    #[inline]
    fn mid(&self) -> Kinematics {
        half_sine_end(self.a1, self.t1, 0.0, 0.0)
    }

    /// State at `t_2`.
    #[inline]
    fn end(&self) -> Kinematics {
        let m = self.mid();
        half_sine_end(self.a2, self.t2 - self.t1, m.vel, m.disp)
    }

    /// Kinematics at time `t` (s) from the pulse start: acceleration (m/s²),
    /// velocity (m/s) and displacement (m), exact closed forms.
    #[inline]
    pub fn eval(&self, t: f64) -> Kinematics {
        if t < 0.0 {
            Kinematics::default()
        } else if t < self.t1 {
            half_sine_segment(self.a1, self.t1, t, 0.0, 0.0)
        } else if t < self.t2 {
            let m = self.mid();
            half_sine_segment(self.a2, self.t2 - self.t1, t - self.t1, m.vel, m.disp)
        } else {
            let e = self.end();
            Kinematics { accel: 0.0, vel: e.vel, disp: e.disp + e.vel * (t - self.t2) }
        }
    }

    /// Acceleration at `t` (s), m/s².
    #[inline]
    pub fn accel(&self, t: f64) -> f64 {
        if t < 0.0 || t >= self.t2 {
            0.0
        } else if t < self.t1 {
            half_sine_accel(self.a1, self.t1, t)
        } else {
            half_sine_accel(self.a2, self.t2 - self.t1, t - self.t1)
        }
    }
}

/// Validate an amplitude `(key, value, unit)` and the corner frequencies.
fn check_design(amplitude: (&str, f64, &'static str), f1_hz: f64, f2_hz: f64) -> Result<(), ShockError> {
    let (key, value, unit) = amplitude;
    require_positive(key, value, unit)?;
    check_corners(f1_hz, f2_hz)
}

/// Validate SRS corner frequencies: finite, > 0, `f_2 > f_1`.
pub(crate) fn check_corners(f1_hz: f64, f2_hz: f64) -> Result<(), ShockError> {
    require_positive("f1_hz", f1_hz, "Hz")?;
    require_positive("f2_hz", f2_hz, "Hz")?;
    if f2_hz <= f1_hz {
        return Err(invalid(
            "f2_hz",
            f2_hz,
            "Hz",
            format!(
                "must be > f1_hz = {f1_hz} Hz (the shock response spectrum is displacement-limited \
                 below f1 and acceleration-limited above f2, with the velocity plateau V_0 between)"
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numeric::{displacement_by_nested_simpson, simpson_piecewise};
    use crate::G0_M_S2;
    use proptest::prelude::*;

    fn table1(peak_g: f64) -> DoubleHalfSine {
        DoubleHalfSine::from_peak(peak_g * G0_M_S2, 10.0, 80.0).unwrap()
    }

    /// `|x − printed| ≤ half a unit of the printed last digit` (+ rounding slack).
    fn assert_printed(x: f64, printed: f64, decimals: i32, what: &str) {
        let half = 0.5 * 10f64.powi(-decimals) * (1.0 + 1e-9);
        assert!((x - printed).abs() <= half, "{what}: computed {x}, study prints {printed}");
    }

    // Physics: the velocity integral of a_1 over [0,t_1] is 2 a_1 t_1/π and
    // must be cancelled by that of a_2 over [t_1,t_2]: v(t_2) = 0, and with
    // no acceleration afterwards v stays 0.
    #[test]
    fn velocity_returns_to_zero_at_t2_and_stays() {
        for g in [3.0, 10.0, 20.0, 57.0] {
            let p = table1(g);
            let scale = p.peak_velocity();
            assert!(p.eval(p.t2).vel.abs() <= 1e-12 * scale);
            assert!(p.final_velocity().abs() <= 1e-12 * scale);
            for t in [p.t2 * 1.5, 1.0, 100.0] {
                let k = p.eval(t);
                assert_eq!(k.accel, 0.0);
                assert!(k.vel.abs() <= 1e-12 * scale);
                assert!((k.disp - p.lift()).abs() <= 1e-12 * p.lift().max(1.0) * t.max(1.0));
            }
            // just before t_2 the velocity is also (nearly) zero: continuity
            let before = p.eval(p.t2 * (1.0 - 1e-10));
            assert!(before.vel.abs() <= 1e-9 * scale);
        }
    }

    #[test]
    fn lift_equals_numerical_double_integral() {
        for g in [3.0, 20.0] {
            let p = table1(g);
            let d_num = displacement_by_nested_simpson(|t| p.accel(t), &[p.t1, p.t2], p.t2, 400);
            assert!((p.lift() - d_num).abs() < 1e-10 * p.lift(), "lift {} vs Simpson-twice {d_num}", p.lift());
            let closed = p.a1 * p.t1 * p.t2 / PI;
            assert!((p.lift() - closed).abs() < 1e-14 * closed);
        }
    }

    #[test]
    fn velocity_and_displacement_match_numerical_integrals_inside() {
        let p = table1(10.0);
        let a = |t: f64| p.accel(t);
        for frac in [0.1, 0.5, 0.99] {
            for t in [frac * p.t1, p.t1 + frac * (p.t2 - p.t1)] {
                let k = p.eval(t);
                let v = simpson_piecewise(&a, &[p.t1, p.t2], t, 2000);
                assert!((k.vel - v).abs() < 1e-10 * p.peak_velocity(), "v at {t}");
                let d = displacement_by_nested_simpson(a, &[p.t1, p.t2], t, 600);
                assert!((k.disp - d).abs() < 1e-10 * p.lift(), "d at {t}: {} vs {d}", k.disp);
            }
        }
    }

    #[test]
    fn kinematics_continuous_at_t1_and_t2() {
        let p = table1(20.0);
        for tk in [p.t1, p.t2] {
            let eps = 1e-12 * tk;
            let l = p.eval(tk - eps);
            let r = p.eval(tk);
            assert!((l.accel - r.accel).abs() < 1e-9 * p.a1, "a at {tk}");
            assert!((l.vel - r.vel).abs() < 1e-9 * p.peak_velocity(), "v at {tk}");
            assert!((l.disp - r.disp).abs() < 1e-9 * p.lift(), "d at {tk}");
        }
    }

    #[test]
    fn zero_before_start() {
        let p = table1(10.0);
        assert_eq!(p.eval(-1e-6), Kinematics::default());
        assert_eq!(p.accel(-1e-6), 0.0);
        assert_eq!(p.eval(0.0), Kinematics::default());
    }

    // Study's Table 1: f_1 = 10 Hz, f_2 = 80 Hz. Expected values are the
    // printed ones; tolerance is half a unit of the printed last digit.
    #[test]
    fn table1_times() {
        for g in [3.0, 10.0, 20.0] {
            let p = table1(g);
            assert_printed(p.t1, 0.0042, 4, "t_1");
            assert_printed(p.t2, 0.0519, 4, "t_2");
        }
    }

    #[test]
    fn table1_a2_10g_and_20g() {
        assert_printed(table1(10.0).a2 / G0_M_S2, -0.87, 2, "a_2 (10 G)");
        assert_printed(table1(20.0).a2 / G0_M_S2, -1.75, 2, "a_2 (20 G)");
    }

    #[test]
    fn table1_lift() {
        assert_printed(table1(3.0).lift() * 1e3, 2.03, 2, "h (3 G)");
        assert_printed(table1(10.0).lift() * 1e3, 6.75, 2, "h (10 G)");
        // With G = 9.80665 m/s² the 20 G row is 13.504 mm; the study prints
        // 13.51 (it used G = 9.81, see `table1_lift_with_g_9_81`). Within one
        // unit of the last printed digit.
        let h20 = table1(20.0).lift() * 1e3;
        assert!((h20 - 13.51).abs() <= 0.01, "h (20 G) = {h20}");
        assert!((h20 - 13.504).abs() < 5e-4);
    }

    /// The study's h column is reproduced exactly to its rounding with
    /// G = 9.81 m/s².
    #[test]
    fn table1_lift_with_g_9_81() {
        for (g, h) in [(3.0, 2.03), (10.0, 6.75), (20.0, 13.51)] {
            let p = DoubleHalfSine::from_peak(g * 9.81, 10.0, 80.0).unwrap();
            assert_printed(p.lift() * 1e3, h, 2, "h (G = 9.81)");
        }
    }

    /// Regression pin: the study's 3 G row prints a_2 = −0.44 G, but the
    /// velocity returning to zero at t_2 requires a_2 = −a_1 t_1/(t_2 − t_1)
    /// ≈ −0.26 G (and the printed formula π V_0/(t_2 − t_1) is positive).
    #[test]
    fn table1_3g_row_misprint() {
        let p = table1(3.0);
        let a2_g = p.a2 / G0_M_S2;
        assert_printed(a2_g, -0.26, 2, "a_2 (3 G) from the velocity condition");
        assert!((a2_g - -0.44).abs() > 0.1, "the printed −0.44 G is not reproduced");
        // With the printed −0.44 G the base would not come to rest.
        let printed = DoubleHalfSine { a2: -0.44 * G0_M_S2, ..p };
        assert!(printed.final_velocity() < -0.2 * p.peak_velocity());
        // The printed formula a_2 = π V_0/(t_2 − t_1) has the wrong sign and size.
        let misprint_formula = PI * p.design_velocity() / (p.t2 - p.t1) / G0_M_S2;
        assert!(misprint_formula > 0.0);
        assert!((misprint_formula - 0.785).abs() < 0.01);
    }

    #[test]
    fn from_design_is_from_peak_of_half() {
        let a = DoubleHalfSine::from_design(40.0, 12.0, 90.0).unwrap();
        let b = DoubleHalfSine::from_peak(20.0, 12.0, 90.0).unwrap();
        assert_eq!(a, b);
        assert!((a.design_velocity() - 40.0 / (2.0 * PI * 90.0)).abs() < 1e-15);
        assert!((a.design_displacement() - a.design_velocity() / (2.0 * PI * 12.0)).abs() < 1e-15);
        assert_eq!(a.design_accel(), 40.0);
    }

    #[test]
    fn rejects_bad_design() {
        let msg = |r: Result<DoubleHalfSine, ShockError>| r.unwrap_err().to_string();
        assert_eq!(msg(DoubleHalfSine::from_peak(1.0, 10.0, -3.0)), "f2_hz = -3 Hz: must be > 0");
        assert_eq!(msg(DoubleHalfSine::from_design(0.0, 10.0, 80.0)), "design_accel_m_s2 = 0 m/s²: must be > 0");
        assert_eq!(msg(DoubleHalfSine::from_peak(f64::NAN, 10.0, 80.0)), "peak_m_s2 = NaN m/s²: must be finite");
        let m = msg(DoubleHalfSine::from_peak(1.0, 80.0, 10.0));
        assert!(m.starts_with("f2_hz = 10 Hz: must be > f1_hz = 80 Hz"), "{m}");
        assert!(m.contains("displacement-limited"), "{m}");
    }

    proptest! {
        // Identities for any admissible design: v(t_2) = 0, a_2 < 0,
        // h = a_1 t_1 t_2/π, and the base never moves down (d ≥ 0).
        #[test]
        fn identities(a1 in 0.1f64..2000.0, f1 in 0.5f64..100.0, ratio in 1.01f64..50.0) {
            let p = DoubleHalfSine::from_peak(a1, f1, f1 * ratio).unwrap();
            prop_assert!(p.a2 < 0.0);
            prop_assert!(p.final_velocity().abs() <= 1e-12 * p.peak_velocity());
            let h = p.a1 * p.t1 * p.t2 / PI;
            prop_assert!((p.lift() - h).abs() <= 1e-12 * h);
            for i in 0..=20 {
                let t = p.t2 * i as f64 / 20.0;
                prop_assert!(p.eval(t).disp >= -1e-15 * h);
                prop_assert!(p.eval(t).vel >= -1e-12 * p.peak_velocity());
            }
        }
    }
}
