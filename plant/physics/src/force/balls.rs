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
//!
//! The kernel works in the cage frame, turned by `R(θ_c)`, where ball `i`
//! sits at the fixed direction `u_i = (cos φ_i, sin φ_i)`, `φ_i = 2π i / z`:
//! with `ε' = R(θ_c)⁻¹ ε`, `δ_i = ε'·u_i − r_cl`, and the frame's turning
//! adds `−θ̇_c J ε'` to `ε̇'` (`J` the +90° turn). One bearing plane: the
//! kernel sees only the race centre relative to the outer ring.

use super::smooth::step;
use nalgebra::{UnitComplex, Vector2};

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
    /// Ball `i`'s direction in the cage frame, `(cos 2π i / z, sin 2π i / z)`, precomputed (the
    /// first `count` entries).
    #[serde(skip)]
    pitch: [Vector2<f64>; MAX_BALLS],
}

/// Most balls a set may have.
pub const MAX_BALLS: usize = 64;

/// Resultant of the ball contacts.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct BallForce {
    /// Force on the race (N).
    pub on_race: Vector2<f64>,
    /// Largest single ball load (N).
    pub max_load: f64,
    /// Number of loaded balls.
    pub loaded: u32,
}

impl BallSet {
    /// A set of `z` equally spaced balls, `1 ≤ z ≤ MAX_BALLS` (clamped).
    pub fn new(z: usize, clearance: f64, stiffness: f64, damping_max: f64, damping_depth: f64) -> Self {
        let count = z.clamp(1, MAX_BALLS);
        let mut pitch = [Vector2::zeros(); MAX_BALLS];
        for (i, u) in pitch[..count].iter_mut().enumerate() {
            let (s, c) = (std::f64::consts::TAU * i as f64 / count as f64).sin_cos();
            *u = Vector2::new(c, s);
        }
        Self { clearance, stiffness, damping_max, damping_depth, count, pitch }
    }

    /// Number of balls z.
    pub fn count(&self) -> usize {
        self.count
    }

    /// `(cos ψ_i, sin ψ_i)` of ball `i` for the cage turned by `cage`.
    fn direction(&self, i: usize, cage: &UnitComplex<f64>) -> Vector2<f64> {
        cage * self.pitch[i]
    }

    /// Ball forces for race position `eps` (m) and velocity `eps_dot` (m/s)
    /// relative to the housing, cage angle `cage` (rad) and cage speed
    /// `cage_rate` (rad/s).
    #[inline]
    pub fn force(&self, eps: Vector2<f64>, eps_dot: Vector2<f64>, cage: f64, cage_rate: f64) -> BallForce {
        // No ball can touch while the race is inside the clearance circle.
        if eps.norm_squared() <= self.clearance * self.clearance {
            return BallForce::default();
        }
        let cage = UnitComplex::new(cage);
        let (ab, ab_dot) = self.cage_frame(eps, eps_dot, &cage, cage_rate);
        let mut sum = Vector2::zeros();
        let mut out = BallForce::default();
        for u in &self.pitch[..self.count] {
            let Some(load) = self.load(ab, ab_dot, u) else { continue };
            sum += u * load;
            out.max_load = out.max_load.max(load);
            out.loaded += u32::from(load > 0.0);
        }
        // Back to the housing frame: −Σ F_i (cos ψ_i, sin ψ_i).
        out.on_race = -cage.transform_vector(&sum);
        out
    }

    /// Each ball's load (N), ball 0 first, for the same arguments as [`BallSet::force`]: the
    /// loads it sums (for the touchdown bearing's duty: the most loaded ball, load cycles).
    pub fn loads(&self, eps: Vector2<f64>, eps_dot: Vector2<f64>, cage: f64, cage_rate: f64, out: &mut [f64]) {
        out.iter_mut().for_each(|l| *l = 0.0);
        if eps.norm_squared() <= self.clearance * self.clearance {
            return;
        }
        let (ab, ab_dot) = self.cage_frame(eps, eps_dot, &UnitComplex::new(cage), cage_rate);
        for (u, l) in self.pitch[..self.count].iter().zip(out) {
            *l = self.load(ab, ab_dot, u).unwrap_or(0.0);
        }
    }

    /// The race's position and velocity in the cage frame, `(ε', ε̇')` (see the module doc).
    #[inline]
    fn cage_frame(
        &self,
        eps: Vector2<f64>,
        eps_dot: Vector2<f64>,
        cage: &UnitComplex<f64>,
        cage_rate: f64,
    ) -> (Vector2<f64>, Vector2<f64>) {
        // In the cage frame ball i sits at the fixed direction u_i, and ε' = R(θ_c)⁻¹ ε = (A, B),
        // so δ_i = ε'·u_i − r_cl and, with the frame turning, δ̇_i = ε̇'·u_i,
        // ε̇' = R(θ_c)⁻¹ ε̇ − θ̇_c J ε' = (… + θ̇_c B, … − θ̇_c A).
        let ab = cage.inverse_transform_vector(&eps);
        (ab, cage.inverse_transform_vector(&eps_dot) + Vector2::new(ab.y, -ab.x) * cage_rate)
    }

    /// The load of the ball at direction `u` of the cage frame (N); `None` when it does not touch.
    #[inline]
    fn load(&self, ab: Vector2<f64>, ab_dot: Vector2<f64>, u: &Vector2<f64>) -> Option<f64> {
        let delta = ab.dot(u) - self.clearance;
        if delta <= 0.0 {
            return None;
        }
        let delta_dot = ab_dot.dot(u);
        let damping = step(delta, 0.0, 0.0, self.damping_depth, self.damping_max);
        Some((self.stiffness * delta * delta.sqrt() + damping * delta_dot).max(0.0))
    }

    /// Elastic energy stored in the ball contacts (J): `Σ (2/5) K_b δ_i^(5/2)`.
    pub fn potential(&self, eps: Vector2<f64>, cage: f64) -> f64 {
        let cage = UnitComplex::new(cage);
        (0..self.count)
            .map(|i| {
                let delta = eps.dot(&self.direction(i, &cage)) - self.clearance;
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

    fn v(x: f64, y: f64) -> Vector2<f64> {
        Vector2::new(x, y)
    }

    fn balls() -> BallSet {
        BallSet::new(19, 1e-5, 7.81e9, 750.0, 1e-5)
    }

    #[test]
    fn loads_are_the_ones_the_resultant_sums() {
        let b = balls();
        let (eps, eps_dot, cage, rate) = (v(3e-6, -1.4e-5), v(0.01, -0.02), 0.3, 50.0);
        let f = b.force(eps, eps_dot, cage, rate);
        let mut loads = [0.0; 19];
        b.loads(eps, eps_dot, cage, rate, &mut loads);
        let sum: Vector2<f64> = loads
            .iter()
            .enumerate()
            .map(|(i, l)| {
                let psi = cage + std::f64::consts::TAU * i as f64 / 19.0;
                -Vector2::new(psi.cos(), psi.sin()) * *l
            })
            .sum();
        assert!((sum - f.on_race).norm() < 1e-9 * f.on_race.norm(), "{sum:?} {:?}", f.on_race);
        assert_eq!(loads.iter().copied().fold(0.0, f64::max), f.max_load);
        assert_eq!(loads.iter().filter(|l| **l > 0.0).count() as u32, f.loaded);
    }

    #[test]
    fn inside_clearance_no_force() {
        assert_eq!(balls().force(v(0.0, -0.9e-5), v(0.0, -1.0), 0.3, 10.0), BallForce::default());
    }

    #[test]
    fn single_ball_below_carries_hertz_load() {
        let b = balls();
        // Cage turned so ball 0 is straight down; race pressed down by r_cl + δ, shallow enough
        // that the neighbours at ±2π/19 stay clear: (r_cl + δ) cos(2π/19) < r_cl.
        let delta = 1e-7;
        let f = b.force(v(0.0, -(1e-5 + delta)), Vector2::zeros(), -std::f64::consts::FRAC_PI_2, 0.0);
        let expected = 7.81e9 * delta.powf(1.5);
        assert_eq!(f.loaded, 1);
        assert!((f.on_race.y - expected).abs() < 1e-9 * expected, "{f:?}");
        assert!(f.on_race.x.abs() < 1e-9 * expected);
    }

    #[test]
    fn load_shared_symmetrically_between_two_balls() {
        let b = balls();
        let half = std::f64::consts::PI / 19.0;
        // Two balls at −90° ± half a pitch: the x components cancel; the next pair, at ±3/2
        // pitch, stays clear: 10.2 µm · cos(3π/19) < r_cl.
        let f = b.force(v(0.0, -1.02e-5), Vector2::zeros(), -std::f64::consts::FRAC_PI_2 - half, 0.0);
        assert_eq!(f.loaded, 2);
        assert!(f.on_race.x.abs() < 1e-9 * f.on_race.y);
    }

    #[test]
    fn resultant_matches_potential_gradient() {
        let b = balls();
        let eps = v(3e-6, -1.3e-5);
        let (hx, hy) = (v(1e-11, 0.0), v(0.0, 1e-11));
        let f = b.force(eps, Vector2::zeros(), 0.2, 0.0);
        let dx = (b.potential(eps + hx, 0.2) - b.potential(eps - hx, 0.2)) / (2.0 * hx.x);
        let dy = (b.potential(eps + hy, 0.2) - b.potential(eps - hy, 0.2)) / (2.0 * hy.y);
        assert!((f.on_race.x + dx).abs() < 1e-5 * f.on_race.y.abs());
        assert!((f.on_race.y + dy).abs() < 1e-5 * f.on_race.y.abs());
    }

    #[test]
    fn overlap_rate_includes_the_cage_rotation() {
        // The damping force follows δ̇_i = d/dt δ_i(ε(t), θ_c(t)): compare with a finite
        // difference of the ball overlaps along a motion with a turning cage.
        let b = BallSet::new(19, 1e-5, 0.0, 750.0, 1e-5);
        let (eps, eps_dot, cage, rate) = ([2e-6, -1.15e-5], [0.01, -0.02], 0.1, 300.0);
        let f = b.force(eps.into(), eps_dot.into(), cage, rate);
        let h = 1e-9;
        let expected = (0..19).fold([0.0; 2], |acc, i| {
            // Ball i at ψ_i = θ_c(t) + 2π i / 19.
            let at = |t: f64| {
                let (s, c) = (cage + rate * t + std::f64::consts::TAU * i as f64 / 19.0).sin_cos();
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
        assert!((f.on_race.x - expected[0]).abs() < 1e-6 * expected[1].abs().max(1e-3), "{f:?} vs {expected:?}");
        assert!((f.on_race.y - expected[1]).abs() < 1e-6 * expected[1].abs().max(1e-3), "{f:?} vs {expected:?}");
    }
}
