//! Classification of the steady response (from its Poincaré points) and of
//! the post-shock motion mode (from contact and orbit).
//!
//! Steady class, with `d_k(n) = |p_{n+k} − p_n|` scaled by the air gap r_0:
//!
//! * `periodic` (k = 1) or `kt_periodic` (k > 1): the smallest k ≤ 16 with
//!   `d_k < tol` over the last quarter of the points, or with `d_k` falling by
//!   more than 3× from the first to the last quarter (a transient still dying
//!   away onto a k-periodic orbit);
//! * otherwise `quasi_periodic` when the points lie on a curve: their
//!   correlation dimension (slope of the pair count `C(r) ∝ r^D` between 5 %
//!   and 20 % of the cloud's diameter) is below 1.45;
//! * otherwise `irregular`.
//!
//! Motion mode over the same window: `recovered` with no rotor – race
//! contact, `dry_whirl` with contact in at least 95 % of the samples
//! (continuous rubbing; its whirl frequency and direction come from the mean
//! angular rate of the orbit), `rebound` otherwise (repeated impacts).

use serde::{Deserialize, Serialize};

/// How the steady response repeats.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SteadyClass {
    /// One Poincaré point.
    Periodic,
    /// k Poincaré points, visited in turn.
    KtPeriodic,
    /// Points on a closed curve.
    QuasiPeriodic,
    /// None of the above.
    Irregular,
    /// Too few points to say.
    Unknown,
}

impl SteadyClass {
    /// Every class.
    pub const ALL: [SteadyClass; 5] = [
        SteadyClass::Periodic,
        SteadyClass::KtPeriodic,
        SteadyClass::QuasiPeriodic,
        SteadyClass::Irregular,
        SteadyClass::Unknown,
    ];

    /// The name written in the outputs (`kt_periodic`, …).
    pub fn name(self) -> &'static str {
        match self {
            SteadyClass::Periodic => "periodic",
            SteadyClass::KtPeriodic => "kt_periodic",
            SteadyClass::QuasiPeriodic => "quasi_periodic",
            SteadyClass::Irregular => "irregular",
            SteadyClass::Unknown => "unknown",
        }
    }
}

/// What the rotor does after the shock.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MotionMode {
    /// Back on its small unbalance orbit, no contact.
    Recovered,
    /// Continuous contact, whirling around the clearance circle.
    DryWhirl,
    /// Repeated impacts.
    Rebound,
}

impl MotionMode {
    /// The name written in the outputs (`recovered`, `dry_whirl`, `rebound`).
    pub fn name(self) -> &'static str {
        match self {
            MotionMode::Recovered => "recovered",
            MotionMode::DryWhirl => "dry_whirl",
            MotionMode::Rebound => "rebound",
        }
    }
}

impl std::fmt::Display for MotionMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::fmt::Display for SteadyClass {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Largest period tested.
pub const MAX_K: usize = 16;

/// A steady classification.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Steady {
    /// The class.
    pub class: SteadyClass,
    /// k for (kT-)periodic responses.
    pub k: Option<u32>,
    /// True when the response is still settling geometrically onto that orbit.
    pub converging: bool,
}

/// Fits `ln d = a + b n`; returns `(b, R²)`.
fn log_fit(d: &[f64]) -> (f64, f64) {
    let pts: Vec<(f64, f64)> =
        d.iter().enumerate().filter(|(_, v)| **v > 0.0).map(|(i, v)| (i as f64, v.ln())).collect();
    let n = pts.len() as f64;
    if n < 3.0 {
        return (0.0, 0.0);
    }
    let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / n, pts.iter().map(|p| p.1).sum::<f64>() / n);
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let syy: f64 = pts.iter().map(|p| (p.1 - my).powi(2)).sum();
    if sxx == 0.0 || syy == 0.0 {
        return (0.0, 0.0);
    }
    (sxy / sxx, sxy * sxy / (sxx * syy))
}

/// Classifies Poincaré points `p` (m), scaled by `gap` (m), with tolerance `tol` (fraction of the gap).
///
/// A k-periodic orbit is recognised when `d_k < tol` over the last quarter, or when the
/// envelope of `d_k` (maxima over blocks of 16 points) decays geometrically over the window
/// (log-linear fit with R² > 0.8, falling by at least 25 %): a transient dying away onto the
/// orbit (`converging`). The smallest such k wins.
pub fn steady_class(p: &[[f64; 2]], gap: f64, tol: f64) -> Steady {
    let n = p.len();
    if n < 8 {
        return Steady { class: SteadyClass::Unknown, k: None, converging: false };
    }
    let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) / gap;
    for k in 1..=MAX_K.min(n / 4) {
        let d: Vec<f64> = (0..n - k).map(|i| dist(p[i + k], p[i])).collect();
        let last = &d[d.len() - d.len() / 4..];
        let class = if k == 1 { SteadyClass::Periodic } else { SteadyClass::KtPeriodic };
        if last.iter().all(|v| *v < tol) {
            return Steady { class, k: Some(k as u32), converging: false };
        }
        // The envelope of d_k (maxima over blocks of 16 revolutions, which spans the beat of a
        // slow free vibration seen once per revolution) decaying geometrically.
        let envelope: Vec<f64> =
            d.chunks(16).filter(|c| c.len() == 16).map(|c| c.iter().copied().fold(0.0, f64::max)).collect();
        let (slope, r2) = log_fit(&envelope);
        if envelope.len() >= 6 && slope < 0.0 && r2 > 0.8 && (slope * envelope.len() as f64).exp() < 0.75 {
            return Steady { class, k: Some(k as u32), converging: true };
        }
    }
    let class = if correlation_dimension(p) < 1.45 { SteadyClass::QuasiPeriodic } else { SteadyClass::Irregular };
    Steady { class, k: None, converging: false }
}

/// Correlation dimension of a point cloud: slope of log C(r) against log r
/// between 5 % and 20 % of its diameter.
pub fn correlation_dimension(p: &[[f64; 2]]) -> f64 {
    let mut d2: Vec<f64> = Vec::with_capacity(p.len() * p.len() / 2);
    for i in 0..p.len() {
        for j in i + 1..p.len() {
            d2.push((p[i][0] - p[j][0]).powi(2) + (p[i][1] - p[j][1]).powi(2));
        }
    }
    let diam2 = d2.iter().copied().fold(0.0, f64::max);
    if diam2 == 0.0 {
        return 0.0;
    }
    let count = |r: f64| d2.iter().filter(|&&x| x < r * r * diam2).count().max(1) as f64;
    let (r1, r2) = (0.05, 0.2);
    (count(r2).ln() - count(r1).ln()) / (r2 / r1).ln()
}

/// Post-shock motion mode from the contact share of the window.
pub fn motion_mode(contact_fraction: f64) -> MotionMode {
    if contact_fraction <= 0.0 {
        MotionMode::Recovered
    } else if contact_fraction >= 0.95 {
        MotionMode::DryWhirl
    } else {
        MotionMode::Rebound
    }
}

/// Mean angular rate of an orbit (Hz, signed: negative = backward), from the
/// unwrapped angle of `(x, y)` between the first and last sample.
pub fn mean_whirl_hz(t: &[f64], x: &[f64], y: &[f64]) -> f64 {
    let n = t.len().min(x.len()).min(y.len());
    if n < 2 {
        return 0.0;
    }
    let tau = std::f64::consts::TAU;
    let mut total = 0.0;
    let mut prev = y[0].atan2(x[0]);
    for i in 1..n {
        let a = y[i].atan2(x[i]);
        let mut d = a - prev;
        d -= tau * (d / tau).round();
        total += d;
        prev = a;
    }
    total / tau / (t[n - 1] - t[0])
}

/// Number of separate contact episodes (runs of positive force) in a series.
pub fn contact_episodes(force: &[f64]) -> usize {
    force.windows(2).filter(|w| w[0] <= 0.0 && w[1] > 0.0).count()
        + usize::from(force.first().is_some_and(|f| *f > 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    const GAP: f64 = 150e-6;

    #[test]
    fn single_frequency_is_periodic() {
        let p = vec![[1e-6, -2e-6]; 200];
        assert_eq!(steady_class(&p, GAP, 1e-3), Steady { class: SteadyClass::Periodic, k: Some(1), converging: false });
    }

    #[test]
    fn three_points_in_turn_are_3t_periodic() {
        let pts = [[10e-6, 0.0], [-5e-6, 8e-6], [-5e-6, -8e-6]];
        let p: Vec<[f64; 2]> = (0..200).map(|n| pts[n % 3]).collect();
        assert_eq!(
            steady_class(&p, GAP, 1e-3),
            Steady { class: SteadyClass::KtPeriodic, k: Some(3), converging: false }
        );
    }

    #[test]
    fn decaying_transient_onto_a_2t_orbit_counts_as_2t() {
        let p: Vec<[f64; 2]> = (0..200)
            .map(|n| {
                let s = if n % 2 == 0 { 1.0 } else { -1.0 };
                let decay = 20e-6 * (-(n as f64) / 30.0).exp();
                [s * 30e-6 + decay * (0.7 * n as f64).cos(), decay * (0.7 * n as f64).sin()]
            })
            .collect();
        assert_eq!(
            steady_class(&p, GAP, 1e-3),
            Steady { class: SteadyClass::KtPeriodic, k: Some(2), converging: true }
        );
    }

    #[test]
    fn two_incommensurate_frequencies_are_quasi_periodic() {
        // Sampled once per revolution, a second frequency at an irrational ratio draws a circle.
        let ratio = (5.0_f64.sqrt() - 1.0) / 2.0;
        let p: Vec<[f64; 2]> = (0..200)
            .map(|n| {
                let a = TAU * ratio * n as f64;
                [2e-6 + 40e-6 * a.cos(), 25e-6 * a.sin() + 5e-6 * (2.0 * a).sin()]
            })
            .collect();
        assert_eq!(steady_class(&p, GAP, 1e-3).class, SteadyClass::QuasiPeriodic);
    }

    #[test]
    fn noise_is_irregular() {
        let mut rng = crate::rng::SplitMix64::new(7);
        let p: Vec<[f64; 2]> = (0..200).map(|_| [60e-6 * rng.unit(), 60e-6 * rng.unit()]).collect();
        assert_eq!(steady_class(&p, GAP, 1e-3).class, SteadyClass::Irregular);
    }

    #[test]
    fn small_noise_on_a_fixed_point_is_still_periodic() {
        let mut rng = crate::rng::SplitMix64::new(3);
        let p: Vec<[f64; 2]> = (0..200).map(|_| [1e-6 + 1e-9 * rng.unit(), 1e-9 * rng.unit()]).collect();
        assert_eq!(steady_class(&p, GAP, 1e-3), Steady { class: SteadyClass::Periodic, k: Some(1), converging: false });
    }

    #[test]
    fn lightly_damped_ring_down_is_a_converging_fixed_point() {
        // A 47 Hz free vibration (ξ = 0.01) seen once per 500 Hz revolution, on top of the
        // unbalance orbit: the points fall on a shrinking line, not a closed curve.
        let p: Vec<[f64; 2]> = (0..200)
            .map(|n| {
                let t = n as f64 / 500.0;
                let a = 25e-6 * (-0.01 * 295.0 * t).exp() * (TAU * 46.9 * t).cos();
                [1.9e-6 + 0.3 * a, -0.2e-6 + a]
            })
            .collect();
        assert_eq!(steady_class(&p, GAP, 1e-3), Steady { class: SteadyClass::Periodic, k: Some(1), converging: true });
    }

    #[test]
    fn whirl_direction_and_rate() {
        let t: Vec<f64> = (0..2000).map(|i| i as f64 * 1e-4).collect();
        let x: Vec<f64> = t.iter().map(|t| (TAU * 65.0 * t).cos()).collect();
        let y: Vec<f64> = t.iter().map(|t| -(TAU * 65.0 * t).sin()).collect();
        assert!((mean_whirl_hz(&t, &x, &y) + 65.0).abs() < 0.1);
    }

    #[test]
    fn names_are_the_serialised_names() {
        for c in SteadyClass::ALL {
            assert_eq!(serde_json::to_value(c).unwrap(), c.name());
        }
        for m in [MotionMode::Recovered, MotionMode::DryWhirl, MotionMode::Rebound] {
            assert_eq!(serde_json::to_value(m).unwrap(), m.name());
        }
    }

    #[test]
    fn modes_and_episodes() {
        assert_eq!(motion_mode(0.0), MotionMode::Recovered);
        assert_eq!(motion_mode(0.99), MotionMode::DryWhirl);
        assert_eq!(motion_mode(0.3), MotionMode::Rebound);
        assert_eq!(contact_episodes(&[0.0, 1.0, 2.0, 0.0, 0.0, 3.0, 0.0]), 2);
        assert_eq!(contact_episodes(&[1.0, 0.0, 3.0]), 2);
    }
}
