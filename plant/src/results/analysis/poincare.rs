//! The Poincaré section: one point per revolution, taken when the rotor's
//! spin angle passes a fixed phase (`θ_r = φ + 2π n`).
//!
//! Crossing times are found by linear interpolation of the (smooth,
//! monotonic) spin angle between trace rows, and the position there by cubic
//! Hermite interpolation with the recorded velocities, which is accurate to
//! fourth order in the trace interval.

use crate::trace::Trace;

/// One point of the section.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SectionPoint {
    /// Revolution index n (counted from θ_r = φ at or after the first row).
    pub n: i64,
    /// Crossing time (s).
    pub t_s: f64,
    /// Rotor x relative to the housing (m).
    pub x_m: f64,
    /// Rotor y relative to the housing (m).
    pub y_m: f64,
}

/// Cubic Hermite interpolation of a quantity `p` with derivative `v` between
/// `(t0, p0, v0)` and `(t1, p1, v1)` at `t`.
fn hermite(t0: f64, t1: f64, p0: f64, p1: f64, v0: f64, v1: f64, t: f64) -> f64 {
    let h = t1 - t0;
    let s = (t - t0) / h;
    let (s2, s3) = (s * s, s * s * s);
    (2.0 * s3 - 3.0 * s2 + 1.0) * p0 + (s3 - 2.0 * s2 + s) * h * v0 + (-2.0 * s3 + 3.0 * s2) * p1 + (s3 - s2) * h * v1
}

/// What the section needs of one trace row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SectionSample {
    /// Time (s).
    pub t_s: f64,
    /// Rotor spin angle (rad).
    pub angle_rad: f64,
    /// Rotor x, y relative to the housing (m).
    pub pos_m: [f64; 2],
    /// Rotor x, y velocity relative to the housing (m/s).
    pub vel_m_s: [f64; 2],
}

/// The section built row by row: each crossing between the previous row and
/// the new one is found as the rows come, so nothing but one row is kept.
#[derive(Clone, Debug)]
pub struct SectionBuilder {
    phase_rad: f64,
    previous: Option<SectionSample>,
}

impl SectionBuilder {
    /// A section at spin phase `phase_rad`.
    pub fn new(phase_rad: f64) -> Self {
        Self { phase_rad, previous: None }
    }

    /// The next row; each crossing since the previous row goes to `point`.
    pub fn push(&mut self, row: SectionSample, point: &mut impl FnMut(SectionPoint)) {
        let tau = std::f64::consts::TAU;
        if let Some(p) = self.previous.replace(row) {
            let (a, b) = (p.angle_rad - self.phase_rad, row.angle_rad - self.phase_rad);
            if !(a.is_finite() && b.is_finite()) || b <= a {
                return;
            }
            // Revolutions n with a ≤ 2πn < b (the first row counts if it sits on the phase).
            // Crossing n belongs to the interval with a ≤ n·2π < b, compared as n·2π throughout
            // (a/2π and n·2π round differently), so the intervals share no crossing and miss none.
            let mut n = (a / tau).floor() as i64 - 1;
            while (n as f64) * tau < a {
                n += 1;
            }
            while (n as f64) * tau < b {
                let target = n as f64 * tau;
                let (t0, t1) = (p.t_s, row.t_s);
                let t = t0 + (target - a) / (b - a) * (t1 - t0);
                point(SectionPoint {
                    n,
                    t_s: t,
                    x_m: hermite(t0, t1, p.pos_m[0], row.pos_m[0], p.vel_m_s[0], row.vel_m_s[0], t),
                    y_m: hermite(t0, t1, p.pos_m[1], row.pos_m[1], p.vel_m_s[1], row.vel_m_s[1], t),
                });
                n += 1;
            }
        }
    }
}

/// The section of a trace at spin phase `phase_rad`.
pub fn section(trace: &Trace, phase_rad: f64) -> Vec<SectionPoint> {
    let mut out = Vec::new();
    let mut builder = SectionBuilder::new(phase_rad);
    for i in 0..trace.len() {
        let row = SectionSample {
            t_s: trace.t_s[i],
            angle_rad: trace.spin.rotor_angle_rad[i],
            pos_m: [trace.motion.dx_m[i], trace.motion.dy_m[i]],
            vel_m_s: [trace.motion.vx_m_s[i], trace.motion.vy_m_s[i]],
        };
        builder.push(row, &mut |p| out.push(p));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_at_the_fixed_phase_with_hermite_accuracy() {
        // Rotor at 500 Hz; orbit = forward whirl at 500 Hz (radius 2 µm, phase lag 30°) plus a
        // 47 Hz whirl (radius 10 µm). At θ_r = φ + 2πn the synchronous part is frozen.
        let (f, w2) = (500.0, 47.0);
        let dt = 5e-5;
        let mut tr = Trace::default();
        let tau = std::f64::consts::TAU;
        for i in 0..4000 {
            let t = i as f64 * dt;
            let (a1, a2) = (tau * f * t - std::f64::consts::FRAC_PI_6, tau * w2 * t);
            tr.t_s.push(t);
            tr.spin.rotor_angle_rad.push(tau * f * t + 0.1);
            tr.motion.dx_m.push(2e-6 * a1.cos() + 10e-6 * a2.cos());
            tr.motion.dy_m.push(2e-6 * a1.sin() + 10e-6 * a2.sin());
            tr.motion.vx_m_s.push(-2e-6 * tau * f * a1.sin() - 10e-6 * tau * w2 * a2.sin());
            tr.motion.vy_m_s.push(2e-6 * tau * f * a1.cos() + 10e-6 * tau * w2 * a2.cos());
        }
        let phase = 1.0;
        let s = section(&tr, phase);
        // One point per revolution: 0.2 s at 500 Hz.
        assert!((s.len() as i64 - 100).abs() <= 1, "{}", s.len());
        for p in &s {
            // θ_r(t) = φ + 2π n exactly at the crossing time.
            let t_exact = (phase + tau * p.n as f64 - 0.1) / (tau * f);
            assert!((p.t_s - t_exact).abs() < 1e-12, "{} vs {t_exact}", p.t_s);
            let (a1, a2) = (tau * f * t_exact - std::f64::consts::FRAC_PI_6, tau * w2 * t_exact);
            let x = 2e-6 * a1.cos() + 10e-6 * a2.cos();
            let y = 2e-6 * a1.sin() + 10e-6 * a2.sin();
            assert!((p.x_m - x).abs() < 1e-8 && (p.y_m - y).abs() < 1e-8, "{p:?} vs ({x}, {y})");
        }
        // Consecutive n.
        assert!(s.windows(2).all(|w| w[1].n == w[0].n + 1));
    }

    #[test]
    fn crossing_on_a_row_is_counted_once() {
        // Regression: rows exactly at θ = 2πn (a held speed with 40 rows per revolution).
        let mut tr = Trace::default();
        let w = std::f64::consts::TAU * 500.0;
        for i in 0..=2000 {
            let t = i as f64 * 5e-5;
            tr.t_s.push(t);
            tr.spin.rotor_angle_rad.push(w * t);
            for c in [&mut tr.motion.dx_m, &mut tr.motion.dy_m, &mut tr.motion.vx_m_s, &mut tr.motion.vy_m_s] {
                c.push(0.0);
            }
        }
        let s = section(&tr, 0.0);
        let ns: Vec<i64> = s.iter().map(|p| p.n).collect();
        assert_eq!(ns, (0..50).collect::<Vec<i64>>());
    }
}
