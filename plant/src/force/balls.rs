//! Inner race – ball contacts: Hertz with radial clearance (MODEL.md §5).
//!
//! Ball `i` sits at angle `ψ_i = θ_c + 2π i / z` from +x. With the race
//! centre `ε` relative to the housing (the outer race is part of it):
//!
//! ```text
//! δ_i = ε_x cos ψ_i + ε_y sin ψ_i − r_cl
//! δ̇_i = ε̇_x cos ψ_i + ε̇_y sin ψ_i + θ̇_c (−ε_x sin ψ_i + ε_y cos ψ_i)
//! F_i = K_b δ_i^(3/2) + C_b(δ_i) δ̇_i   (δ_i > 0; clamped ≥ 0),   C_b(δ) = STEP(δ; 0, 0, δ_max, C_b,max)
//! ```
//!
//! The resultant on the race is `−Σ F_i (cos ψ_i, sin ψ_i)`: the balls push
//! the race back toward the housing centre.

use super::smooth::step;

/// The ball set of a deep-groove touchdown bearing.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BallSet {
    /// Radial clearance r_cl between race and balls (m).
    pub clearance: f64,
    /// Hertz stiffness K_b (N/m^(3/2)).
    pub stiffness: f64,
    /// Full contact damping C_b,max (N·s/m), reached at depth δ_max.
    pub damping_max: f64,
    /// Depth δ_max at which the damping is fully on (m).
    pub damping_depth: f64,
    /// Number of balls z.
    count: usize,
    /// `cos(2π i / z)` for each ball, precomputed (the first `count` entries).
    #[serde(skip)]
    pitch_cos: [f64; MAX_BALLS],
    /// `sin(2π i / z)` likewise.
    #[serde(skip)]
    pitch_sin: [f64; MAX_BALLS],
}

/// Most balls a set may have.
pub const MAX_BALLS: usize = 64;

/// Resultant of the ball contacts.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct BallForce {
    /// Force on the race (N).
    pub on_race: [f64; 2],
    /// Largest single ball load (N).
    pub max_load: f64,
    /// Number of loaded balls.
    pub loaded: u32,
}

impl BallSet {
    /// A set of `z` equally spaced balls, `1 ≤ z ≤ MAX_BALLS` (clamped).
    pub fn new(z: usize, clearance: f64, stiffness: f64, damping_max: f64, damping_depth: f64) -> Self {
        let count = z.clamp(1, MAX_BALLS);
        let mut pitch_cos = [0.0; MAX_BALLS];
        let mut pitch_sin = [0.0; MAX_BALLS];
        for i in 0..count {
            let (s, c) = (std::f64::consts::TAU * i as f64 / count as f64).sin_cos();
            pitch_cos[i] = c;
            pitch_sin[i] = s;
        }
        Self { clearance, stiffness, damping_max, damping_depth, count, pitch_cos, pitch_sin }
    }

    /// Number of balls z.
    pub fn count(&self) -> usize {
        self.count
    }

    /// `(cos ψ_i, sin ψ_i)` of ball `i` for cage angle `(sin θ_c, cos θ_c)`.
    fn direction(&self, i: usize, s0: f64, c0: f64) -> (f64, f64) {
        let (cp, sp) = (self.pitch_cos[i], self.pitch_sin[i]);
        (c0 * cp - s0 * sp, s0 * cp + c0 * sp)
    }

    /// Ball forces for race position `eps` (m) and velocity `eps_dot` (m/s)
    /// relative to the housing, cage angle `cage` (rad) and cage speed
    /// `cage_rate` (rad/s).
    #[inline]
    pub fn force(&self, eps: [f64; 2], eps_dot: [f64; 2], cage: f64, cage_rate: f64) -> BallForce {
        // No ball can touch while the race is inside the clearance circle.
        if eps[0] * eps[0] + eps[1] * eps[1] <= self.clearance * self.clearance {
            return BallForce::default();
        }
        // In the cage frame (turned by θ_c) ball i sits at the fixed angle φ_i = 2π i / z, and
        // ε = (A, B) there, so δ_i = A cos φ_i + B sin φ_i − r_cl, and with the frame turning,
        // δ̇_i = (Ȧ) cos φ_i + (Ḃ) sin φ_i, Ȧ = ε̇·(c, s) + θ̇_c B, Ḃ = ε̇·(−s, c) − θ̇_c A.
        let (s0, c0) = cage.sin_cos();
        let a = eps[0] * c0 + eps[1] * s0;
        let b = eps[1] * c0 - eps[0] * s0;
        let a_dot = eps_dot[0] * c0 + eps_dot[1] * s0 + cage_rate * b;
        let b_dot = eps_dot[1] * c0 - eps_dot[0] * s0 - cage_rate * a;
        let (mut sum_c, mut sum_s) = (0.0, 0.0);
        let mut out = BallForce::default();
        for (&cp, &sp) in self.pitch_cos[..self.count].iter().zip(&self.pitch_sin[..self.count]) {
            let delta = a * cp + b * sp - self.clearance;
            if delta <= 0.0 {
                continue;
            }
            let delta_dot = a_dot * cp + b_dot * sp;
            let damping = step(delta, 0.0, 0.0, self.damping_depth, self.damping_max);
            let load = (self.stiffness * delta * delta.sqrt() + damping * delta_dot).max(0.0);
            sum_c += load * cp;
            sum_s += load * sp;
            out.max_load = out.max_load.max(load);
            out.loaded += u32::from(load > 0.0);
        }
        // Back to the housing frame: −Σ F_i (cos ψ_i, sin ψ_i).
        out.on_race = [-(c0 * sum_c - s0 * sum_s), -(s0 * sum_c + c0 * sum_s)];
        out
    }

    /// Elastic energy stored in the ball contacts (J): `Σ (2/5) K_b δ_i^(5/2)`.
    pub fn potential(&self, eps: [f64; 2], cage: f64) -> f64 {
        let (s0, c0) = cage.sin_cos();
        (0..self.count)
            .map(|i| {
                let (c, s) = self.direction(i, s0, c0);
                let delta = eps[0] * c + eps[1] * s - self.clearance;
                if delta > 0.0 {
                    0.4 * self.stiffness * delta.powf(2.5)
                } else {
                    0.0
                }
            })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn balls() -> BallSet {
        BallSet::new(19, 1e-5, 7.81e9, 750.0, 1e-5)
    }

    #[test]
    fn inside_clearance_no_force() {
        assert_eq!(balls().force([0.0, -0.9e-5], [0.0, -1.0], 0.3, 10.0), BallForce::default());
    }

    #[test]
    fn single_ball_below_carries_hertz_load() {
        let b = balls();
        // Cage turned so ball 0 is straight down; race pressed down by r_cl + δ, shallow enough
        // that the neighbours at ±2π/19 stay clear: (r_cl + δ) cos(2π/19) < r_cl.
        let delta = 1e-7;
        let f = b.force([0.0, -(1e-5 + delta)], [0.0; 2], -std::f64::consts::FRAC_PI_2, 0.0);
        let expected = 7.81e9 * delta.powf(1.5);
        assert_eq!(f.loaded, 1);
        assert!((f.on_race[1] - expected).abs() < 1e-9 * expected, "{f:?}");
        assert!(f.on_race[0].abs() < 1e-9 * expected);
    }

    #[test]
    fn load_shared_symmetrically_between_two_balls() {
        let b = balls();
        let half = std::f64::consts::PI / 19.0;
        // Two balls at −90° ± half a pitch: the x components cancel; the next pair, at ±3/2
        // pitch, stays clear: 10.2 µm · cos(3π/19) < r_cl.
        let f = b.force([0.0, -1.02e-5], [0.0; 2], -std::f64::consts::FRAC_PI_2 - half, 0.0);
        assert_eq!(f.loaded, 2);
        assert!(f.on_race[0].abs() < 1e-9 * f.on_race[1]);
    }

    #[test]
    fn resultant_matches_potential_gradient() {
        let b = balls();
        let eps = [3e-6, -1.3e-5];
        let h = 1e-11;
        let f = b.force(eps, [0.0; 2], 0.2, 0.0);
        let dx = (b.potential([eps[0] + h, eps[1]], 0.2) - b.potential([eps[0] - h, eps[1]], 0.2)) / (2.0 * h);
        let dy = (b.potential([eps[0], eps[1] + h], 0.2) - b.potential([eps[0], eps[1] - h], 0.2)) / (2.0 * h);
        assert!((f.on_race[0] + dx).abs() < 1e-5 * f.on_race[1].abs());
        assert!((f.on_race[1] + dy).abs() < 1e-5 * f.on_race[1].abs());
    }

    #[test]
    fn overlap_rate_includes_the_cage_rotation() {
        // The damping force follows δ̇_i = d/dt δ_i(ε(t), θ_c(t)): compare with a finite
        // difference of the ball overlaps along a motion with a turning cage.
        let b = BallSet::new(19, 1e-5, 0.0, 750.0, 1e-5);
        let (eps, eps_dot, cage, rate) = ([2e-6, -1.15e-5], [0.01, -0.02], 0.1, 300.0);
        let f = b.force(eps, eps_dot, cage, rate);
        let h = 1e-9;
        let expected = (0..19).fold([0.0; 2], |acc, i| {
            let at = |t: f64| {
                let (s0, c0) = (cage + rate * t).sin_cos();
                let (c, s) = b.direction(i, s0, c0);
                ((eps[0] + eps_dot[0] * t) * c + (eps[1] + eps_dot[1] * t) * s - 1e-5, c, s)
            };
            let (d, c, s) = at(0.0);
            if d <= 0.0 {
                return acc;
            }
            let rate_fd = (at(h).0 - at(-h).0) / (2.0 * h);
            let load = (step(d, 0.0, 0.0, 1e-5, 750.0) * rate_fd).max(0.0);
            [acc[0] - load * c, acc[1] - load * s]
        });
        assert!((f.on_race[0] - expected[0]).abs() < 1e-6 * expected[1].abs().max(1e-3), "{f:?} vs {expected:?}");
        assert!((f.on_race[1] - expected[1]).abs() < 1e-6 * expected[1].abs().max(1e-3), "{f:?} vs {expected:?}");
    }
}
