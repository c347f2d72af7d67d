//! Active magnetic bearing force per axis (MODEL.md §3).
//!
//! Linearised (the study's): `F = k_i i + k_s Δ`.
//!
//! Nonlinear, differential driving with bias `i_0` and nominal gap `s_0`:
//! `F = k [ (i_0 + i)² / (s_0 − Δ)² − (i_0 − i)² / (s_0 + Δ)² ]`, each coil
//! current clamped at ≥ 0 (unipolar amplifiers) and each magnet's pull capped
//! at its flux-saturation force. It linearises to `k_i = 4 k i_0 / s_0²`,
//! `k_s = 4 k i_0² / s_0³`. `Δ` is the rotor position relative to the housing
//! (m), `i` the control current (A); a positive `F` pushes toward `+Δ`.
//!
//! With unipolar amplifiers each magnet's current is its own state (MODEL.md §12.3):
//! [`AmbLaw::magnet_force`] takes the two currents `i₊`, `i₋` instead of `i_0 ± i`.
//!
//! One bearing plane, x and y: a rotor with two bearings calls the kernel once per plane.

use nalgebra::Vector2;

/// The bearing's force law.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "law", rename_all = "snake_case")]
pub enum AmbLaw {
    /// `F = k_i i + k_s Δ`.
    Linear {
        /// Force-current coefficient k_i (N/A).
        ki: f64,
        /// Force-displacement coefficient k_s (N/m).
        ks: f64,
    },
    /// Two opposed magnets per axis with flux saturation.
    Nonlinear {
        /// Magnet constant k = μ_0 n² A cos η / 4 (N·m²/A²).
        k: f64,
        /// Bias current i_0 (A).
        i0: f64,
        /// Nominal air gap s_0 (m).
        s0: f64,
        /// Largest pull of one magnet (N), from flux saturation.
        force_limit: f64,
    },
}

impl AmbLaw {
    /// The nonlinear law with the same `k_i`, `k_s` at the centre as a linear
    /// one, for nominal gap `s0` (m): `i_0 = s_0 k_s / k_i`, `k = k_i s_0² / (4 i_0)`.
    pub fn nonlinear_matching(ki: f64, ks: f64, s0: f64, force_limit: f64) -> Self {
        let i0 = s0 * ks / ki;
        AmbLaw::Nonlinear { k: ki * s0 * s0 / (4.0 * i0), i0, s0, force_limit }
    }

    /// Force per axis (N) for displacement `delta` (m) and current `i` (A), x then y.
    #[inline]
    pub fn force(&self, delta: Vector2<f64>, i: Vector2<f64>) -> Vector2<f64> {
        match *self {
            AmbLaw::Linear { ki, ks } => i * ki + delta * ks,
            AmbLaw::Nonlinear { k, i0, s0, force_limit } => {
                let axis = |d: f64, i: f64| pair(k, s0, force_limit, d, i0 + i, i0 - i);
                delta.zip_map(&i, axis)
            }
        }
    }

    /// Force per axis (N) for displacement `delta` (m) with each magnet's own current (A), x
    /// then y: `plus` the magnet on the + side of each axis (gap `s_0 − Δ`, pulling toward
    /// `+Δ`), `minus` the one on the − side (gap `s_0 + Δ`). The nonlinear law without the
    /// bias: `F = k [ i₊² / (s_0 − Δ)² − i₋² / (s_0 + Δ)² ]`, the same as
    /// [`AmbLaw::force`] with `i₊ = i_0 + i`, `i₋ = i_0 − i`. Unipolar amplifiers drive the
    /// magnets this way (MODEL.md §12.3); the linear law, which has no magnets, takes the
    /// differential current `(i₊ − i₋)/2`.
    ///
    /// Out of line and cold, to keep it off the path of the derivatives of the other controls
    /// (their instruction counts: docs/results/fidelity.md, "The unipolar amplifier").
    #[cold]
    #[inline(never)]
    pub fn magnet_force(&self, delta: Vector2<f64>, plus: Vector2<f64>, minus: Vector2<f64>) -> Vector2<f64> {
        match *self {
            AmbLaw::Linear { .. } => self.force(delta, (plus - minus) * 0.5),
            AmbLaw::Nonlinear { k, s0, force_limit, .. } => Vector2::new(
                pair(k, s0, force_limit, delta.x, plus.x, minus.x),
                pair(k, s0, force_limit, delta.y, plus.y, minus.y),
            ),
        }
    }
}

/// One axis's two opposed magnets (N): currents `plus`, `minus` (A; a negative one is read as
/// 0: no coil current reverses), displacement `d` (m), each pull capped at `force_limit`.
#[inline(always)]
fn pair(k: f64, s0: f64, force_limit: f64, d: f64, plus: f64, minus: f64) -> f64 {
    let plus = plus.max(0.0);
    let minus = minus.max(0.0);
    // The rotor never reaches a pole (the touchdown gap is far
    // smaller than s0); the guard keeps a diverging run finite.
    let gap_plus = (s0 - d).max(1e-3 * s0);
    let gap_minus = (s0 + d).max(1e-3 * s0);
    let pull_plus = (k * plus * plus / (gap_plus * gap_plus)).min(force_limit);
    let pull_minus = (k * minus * minus / (gap_minus * gap_minus)).min(force_limit);
    pull_plus - pull_minus
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> Vector2<f64> {
        Vector2::new(x, y)
    }

    #[test]
    fn nonlinear_linearises_to_ki_ks() {
        let law = AmbLaw::nonlinear_matching(216.0, 4.32e5, 1e-3, 1e6);
        let (h, hi) = (1e-8, 1e-6);
        let zero = Vector2::zeros();
        let ks = (law.force(v(h, 0.0), zero).x - law.force(v(-h, 0.0), zero).x) / (2.0 * h);
        let ki = (law.force(zero, v(hi, 0.0)).x - law.force(zero, v(-hi, 0.0)).x) / (2.0 * hi);
        assert!((ks - 4.32e5).abs() < 1e-4 * 4.32e5, "ks = {ks}");
        assert!((ki - 216.0).abs() < 1e-4 * 216.0, "ki = {ki}");
    }

    #[test]
    fn saturation_caps_each_magnet() {
        let law = AmbLaw::nonlinear_matching(216.0, 4.32e5, 1e-3, 300.0);
        let f = law.force(Vector2::zeros(), v(2.0, 0.0));
        assert_eq!(f.x, 300.0);
    }

    #[test]
    fn magnets_at_the_bias_give_the_biased_law() {
        // i₊ = i_0 + i, i₋ = i_0 − i gives the biased law's force, bit for bit (i_0 ≈ 2 A).
        let law = AmbLaw::nonlinear_matching(216.0, 4.32e5, 1e-3, 1000.0);
        let AmbLaw::Nonlinear { i0, .. } = law else { unreachable!("nonlinear") };
        let d = v(3e-5, -1.2e-4);
        let i = v(0.375, -1.5);
        let magnets = law.magnet_force(d, i.map(|i| i0 + i), i.map(|i| i0 - i));
        assert_eq!(law.force(d, i), magnets);
        // One magnet off: only the other pulls, k i² / gap².
        let (k, s0) = (216.0 * 1e-6 / 8.0, 1e-3);
        let f = law.magnet_force(d, v(0.0, 1.0), v(1.0, 0.0));
        assert!((f.x + k / ((s0 + d.x) * (s0 + d.x))).abs() < 1e-12);
        assert!((f.y - k / ((s0 - d.y) * (s0 - d.y))).abs() < 1e-12);
        // The linear law takes the differential current.
        let linear = AmbLaw::Linear { ki: 216.0, ks: 4.32e5 };
        assert_eq!(linear.magnet_force(d, v(2.375, 0.5), v(1.625, 3.5)), linear.force(d, i));
    }

    #[test]
    fn linear_is_linear() {
        let law = AmbLaw::Linear { ki: 216.0, ks: 4.32e5 };
        assert_eq!(law.force(v(1e-5, -1e-5), v(0.5, 0.0)), v(108.0 + 4.32, -4.32));
    }
}
