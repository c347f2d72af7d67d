//! One base-motion pulse along a scalar direction.
//!
//! Time is measured from the pulse's own start; every pulse is zero for
//! `t < 0`. Velocity and displacement are the exact integrals of the
//! acceleration from rest, `v = ∫₀ᵗ a`, `d = ∫₀ᵗ v` (see each kind's
//! module for its closed forms and for what happens after its end).

use crate::double_half_sine::DoubleHalfSine;
use crate::half_sine::HalfSine;
use crate::kinematics::Kinematics;
use crate::recorded::Recorded;
use crate::sine::SineVibration;

/// One base-motion pulse, time measured from its own start (`t = 0`); zero
/// for `t < 0`.
#[derive(Clone, Debug, PartialEq)]
pub enum Pulse {
    /// BV043/85 double half-sine: ends at rest, lifted by `h`.
    DoubleHalfSine(DoubleHalfSine),
    /// Single positive half-sine: ends with velocity `2PT/π`.
    HalfSine(HalfSine),
    /// Sinusoidal vibration over whole cycles: ends at rest at zero.
    Sine(SineVibration),
    /// Measured acceleration record: ends with the record's final velocity.
    Recorded(Recorded),
}

impl Pulse {
    /// Kinematics at time `t` (s) from the pulse start: acceleration (m/s²),
    /// velocity (m/s), displacement (m).
    #[inline]
    pub fn eval(&self, t: f64) -> Kinematics {
        match self {
            Pulse::DoubleHalfSine(p) => p.eval(t),
            Pulse::HalfSine(p) => p.eval(t),
            Pulse::Sine(p) => p.eval(t),
            Pulse::Recorded(p) => p.eval(t),
        }
    }

    /// Acceleration at time `t` (s) from the pulse start, m/s².
    #[inline]
    pub fn accel(&self, t: f64) -> f64 {
        match self {
            Pulse::DoubleHalfSine(p) => p.accel(t),
            Pulse::HalfSine(p) => p.accel(t),
            Pulse::Sine(p) => p.accel(t),
            Pulse::Recorded(p) => p.accel(t),
        }
    }

    /// Times from the pulse start (s) where the acceleration or its slope
    /// jumps: an integrator should end a step there rather than step across.
    /// Ascending. A recorded pulse lists every sample (its acceleration is
    /// piecewise linear).
    pub fn breakpoints(&self) -> Vec<f64> {
        match self {
            Pulse::DoubleHalfSine(p) => vec![0.0, p.t1, p.t2],
            Pulse::HalfSine(p) => vec![0.0, p.duration],
            Pulse::Sine(p) => vec![0.0, p.duration()],
            Pulse::Recorded(p) => p.times().to_vec(),
        }
    }

    /// Time after which the acceleration is zero, s.
    pub fn duration(&self) -> f64 {
        match self {
            Pulse::DoubleHalfSine(p) => p.duration(),
            Pulse::HalfSine(p) => p.duration,
            Pulse::Sine(p) => p.duration(),
            Pulse::Recorded(p) => p.duration(),
        }
    }
}

impl From<DoubleHalfSine> for Pulse {
    fn from(p: DoubleHalfSine) -> Self {
        Pulse::DoubleHalfSine(p)
    }
}

impl From<HalfSine> for Pulse {
    fn from(p: HalfSine) -> Self {
        Pulse::HalfSine(p)
    }
}

impl From<SineVibration> for Pulse {
    fn from(p: SineVibration) -> Self {
        Pulse::Sine(p)
    }
}

impl From<Recorded> for Pulse {
    fn from(p: Recorded) -> Self {
        Pulse::Recorded(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accel_agrees_with_eval_for_every_kind() {
        let pulses: [Pulse; 4] = [
            DoubleHalfSine::from_peak(98.0, 10.0, 80.0).unwrap().into(),
            HalfSine::new(49.0, 0.011).unwrap().into(),
            SineVibration::new(9.8, 20.0, 3).unwrap().into(),
            Recorded::from_samples(vec![0.0, 0.01, 0.03], vec![1.0, -4.0, 2.0]).unwrap().into(),
        ];
        for p in &pulses {
            let d = p.duration();
            for i in -2..=30 {
                let t = d * i as f64 / 25.0;
                assert_eq!(p.accel(t), p.eval(t).accel, "{p:?} at {t}");
            }
            assert_eq!(p.eval(-1e-9), Kinematics::default());
        }
    }
}
