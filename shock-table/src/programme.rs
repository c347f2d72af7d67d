//! Programme of shocks (a "shock table").
//!
//! Shock `j` has a pulse `p_j`, a start time `s_j` (s) and a direction
//! `θ_j` (rad from +x; `π/2` = +y, the base is lifted), unit vector
//! `e_j = (cos θ_j, sin θ_j)`. The housing kinematics in the x-y plane are
//! the vector sum
//!
//! ```text
//! a(t) = Σ_j p_j.a(t − s_j) e_j,  v(t) = Σ_j p_j.v(t − s_j) e_j,
//! d(t) = Σ_j p_j.d(t − s_j) e_j
//! ```
//!
//! (each pulse is zero before its start). Evaluation allocates nothing; the
//! unit vectors are computed once when a shock is built.

use std::f64::consts::FRAC_PI_2;

use crate::error::{require_finite, require_non_negative, ShockError};
use crate::kinematics::Kinematics2;
use crate::pulse::Pulse;

/// Default shock direction, rad: `π/2` (+y, the base is lifted).
pub const DEFAULT_DIRECTION_RAD: f64 = FRAC_PI_2;

/// A shock in a programme: a pulse, its start time and its direction.
///
/// The direction is private so that its cached unit vector cannot go stale:
/// read it with [`direction`](Self::direction), change it with
/// [`set_direction`](Self::set_direction).
#[derive(Clone, Debug, PartialEq)]
pub struct Shock {
    /// The base-motion pulse.
    pub pulse: Pulse,
    /// Start time of the pulse, s (≥ 0).
    pub start: f64,
    /// Direction, rad from +x (`π/2` = +y).
    direction: f64,
    /// `[cos θ, sin θ]`.
    unit: [f64; 2],
}

impl Shock {
    /// Shock of `pulse` starting at `start_s` (s, finite, ≥ 0) along the
    /// direction `direction_rad` (rad from +x, finite; `π/2` = +y).
    pub fn new(pulse: Pulse, start_s: f64, direction_rad: f64) -> Result<Self, ShockError> {
        require_non_negative("start_s", start_s, "s")?;
        require_finite("direction_rad", direction_rad, "rad")?;
        Ok(Self { pulse, start: start_s, direction: direction_rad, unit: unit_vector(direction_rad) })
    }

    /// Shock of `pulse` starting at `start_s` (s) along +y (the base is
    /// lifted), the default direction.
    pub fn lifting(pulse: Pulse, start_s: f64) -> Result<Self, ShockError> {
        Self::new(pulse, start_s, DEFAULT_DIRECTION_RAD)
    }

    /// Direction, rad from +x.
    pub fn direction(&self) -> f64 {
        self.direction
    }

    /// Change the direction (rad from +x, finite).
    pub fn set_direction(&mut self, direction_rad: f64) -> Result<(), ShockError> {
        require_finite("direction_rad", direction_rad, "rad")?;
        self.direction = direction_rad;
        self.unit = unit_vector(direction_rad);
        Ok(())
    }

    /// Unit vector of the direction, `[cos θ, sin θ]`.
    pub fn unit(&self) -> [f64; 2] {
        self.unit
    }

    /// Time at which the pulse's acceleration ends, s: `start + duration`.
    pub fn end_time(&self) -> f64 {
        self.start + self.pulse.duration()
    }
}

/// `[cos θ, sin θ]`, with exact zeros on the axes for the common angles
/// (`π/2` gives `[0, 1]`, not `[6e-17, 1]`).
fn unit_vector(theta: f64) -> [f64; 2] {
    let (s, c) = theta.sin_cos();
    let snap = |x: f64| if x.abs() < 1e-15 { 0.0 } else { x };
    [snap(c), snap(s)]
}

/// A programme of shocks ("shock table"); kinematics add up as vectors.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Programme {
    /// The shocks, in any order.
    pub shocks: Vec<Shock>,
}

impl Programme {
    /// Programme of the given shocks.
    pub fn new(shocks: Vec<Shock>) -> Self {
        Self { shocks }
    }

    /// Programme with one shock.
    pub fn single(shock: Shock) -> Self {
        Self { shocks: vec![shock] }
    }

    /// Housing kinematics at absolute time `t` (s). Hot path: no
    /// allocation.
    #[inline]
    pub fn eval(&self, t: f64) -> Kinematics2 {
        let mut k = Kinematics2::default();
        for s in &self.shocks {
            let tau = t - s.start;
            if tau >= 0.0 {
                k.add_along(s.pulse.eval(tau), s.unit);
            }
        }
        k
    }

    /// Housing acceleration `[a_x, a_y]` at absolute time `t` (s), m/s².
    /// Hot path: no allocation.
    #[inline]
    pub fn accel(&self, t: f64) -> [f64; 2] {
        let mut a = [0.0; 2];
        for s in &self.shocks {
            let tau = t - s.start;
            if tau >= 0.0 {
                let ai = s.pulse.accel(tau);
                a[0] += ai * s.unit[0];
                a[1] += ai * s.unit[1];
            }
        }
        a
    }

    /// Time after which all accelerations are zero, s: the latest
    /// `start + duration` (0 for an empty programme).
    pub fn end_time(&self) -> f64 {
        self.shocks.iter().map(Shock::end_time).fold(0.0, f64::max)
    }

    /// Absolute times (s) where the housing acceleration or its slope jumps,
    /// ascending and without repeats (see [`crate::Pulse::breakpoints`]).
    ///
    /// ```
    /// use shock_table::{DoubleHalfSine, Programme, Shock};
    /// let p = DoubleHalfSine::from_peak(10.0 * 9.80665, 10.0, 80.0).unwrap();
    /// let prog = Programme::single(Shock::lifting(p.clone().into(), 0.02).unwrap());
    /// assert_eq!(prog.breakpoints(), vec![0.02, 0.02 + p.t1, 0.02 + p.t2]);
    /// ```
    pub fn breakpoints(&self) -> Vec<f64> {
        let mut b: Vec<f64> =
            self.shocks.iter().flat_map(|s| s.pulse.breakpoints().into_iter().map(move |t| s.start + t)).collect();
        b.sort_by(f64::total_cmp);
        b.dedup();
        b
    }

    /// `true` if the programme has no shocks.
    pub fn is_empty(&self) -> bool {
        self.shocks.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{DoubleHalfSine, HalfSine, G0_M_S2};
    use std::f64::consts::PI;

    fn dhs(peak_g: f64) -> Pulse {
        DoubleHalfSine::from_peak(peak_g * G0_M_S2, 10.0, 80.0).unwrap().into()
    }

    #[test]
    fn two_shocks_in_different_directions_add_as_vectors() {
        let p1 = dhs(10.0);
        let p2: Pulse = HalfSine::new(3.0 * G0_M_S2, 0.011).unwrap().into();
        let (th1, th2) = (PI / 2.0, PI / 6.0);
        let prog = Programme::new(vec![
            Shock::new(p1.clone(), 0.02, th1).unwrap(),
            Shock::new(p2.clone(), 0.03, th2).unwrap(),
        ]);
        for &t in &[0.0, 0.025, 0.031, 0.04, 0.06, 0.2] {
            let k = prog.eval(t);
            let k1 = p1.eval(t - 0.02);
            let k2 = p2.eval(t - 0.03);
            let e1 = [th1.cos(), th1.sin()];
            let e2 = [th2.cos(), th2.sin()];
            for i in 0..2 {
                let want_a = k1.accel * e1[i] + k2.accel * e2[i];
                let want_v = k1.vel * e1[i] + k2.vel * e2[i];
                let want_d = k1.disp * e1[i] + k2.disp * e2[i];
                assert!((k.accel[i] - want_a).abs() < 1e-12, "a[{i}] at {t}");
                assert!((k.vel[i] - want_v).abs() < 1e-14, "v[{i}] at {t}");
                assert!((k.disp[i] - want_d).abs() < 1e-15, "d[{i}] at {t}");
                assert_eq!(prog.accel(t)[i], k.accel[i]);
            }
        }
        assert!((prog.end_time() - (0.02 + p1.duration()).max(0.041)).abs() < 1e-15);
    }

    #[test]
    fn default_direction_lifts_with_exact_zero_x() {
        let prog = Programme::single(Shock::lifting(dhs(20.0), 0.0).unwrap());
        let k = prog.eval(1.0);
        assert_eq!(k.disp[0], 0.0);
        assert!((k.disp[1] * 1e3 - 13.504).abs() < 1e-3);
    }

    #[test]
    fn empty_programme_is_still() {
        let p = Programme::default();
        assert!(p.is_empty());
        assert_eq!(p.end_time(), 0.0);
        assert_eq!(p.eval(1.0), Kinematics2::default());
    }

    #[test]
    fn set_direction_updates_unit_vector() {
        let mut s = Shock::lifting(dhs(3.0), 0.0).unwrap();
        s.set_direction(0.0).unwrap();
        assert_eq!(s.unit(), [1.0, 0.0]);
        assert!(s.set_direction(f64::NAN).is_err());
        assert_eq!(Shock::new(dhs(3.0), -1.0, 0.0).unwrap_err().to_string(), "start_s = -1 s: must be >= 0");
    }
}
