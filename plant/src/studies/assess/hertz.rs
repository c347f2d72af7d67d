//! Hertzian contact pressures of the touchdown bearing, from a contact force and the geometry
//! (the basis of the duty's pressures; docs/MODEL.md §11 states them with their assumptions).
//!
//! **Rotor – inner race**: a shaft of radius `r_r` inside a bore of radius `r_i = r_r + r_0`,
//! touching along a line of length `B` (the race's width, aligned, no edge loading). Hertz's line
//! contact of two cylinders, the bore concave:
//!
//! ```text
//! 1/R = 1/r_r − 1/r_i,   E* = E / (2 (1 − ν²)) (both steel),   p_max = √(F E* / (π B R)),   b = √(4 F R / (π B E*))
//! ```
//!
//! With the study's 0.15 mm gap the contact is very conformal (R ≈ 2.6 m): the half-width `b`
//! is then not small against the radius, and the figure is Hertz's estimate outside its strict
//! validity (stated in the report with `b`).
//!
//! **Ball – inner raceway** (point contact, radial bearing, contact angle 0): ball diameter
//! `D`, pitch diameter `d_m`, groove radius `f_i D` (conformity `f_i`, 0.52 unless told). In the
//! rolling direction `1/R_x = 2/D + 2/(d_m − D)`, across it `1/R_y = 2/D − 1/(f_i D)`; with
//! `α = R_y / R_x`, Brewe and Hamrock's approximations of the ellipse (ellipticity
//! `k = α^(2/π)`, elliptic integral `ℰ = 1 + (π/2 − 1)/α`) give, with `E' = E / (1 − ν²)`,
//! `R = (1/R_x + 1/R_y)⁻¹` and the ball load `Q`:
//!
//! ```text
//! a = (6 k² ℰ Q R / (π E'))^(1/3),   b = (6 ℰ Q R / (π k E'))^(1/3),   p_max = 3 Q / (2 π a b)
//! ```
//!
//! **Static capacity** (ISO 76's basis for radial ball bearings): the ball load `Q₀` that gives
//! 4200 MPa at the most loaded ball's inner-raceway contact. From `p_max ∝ Q^(1/3)`,
//! `Q₀ = Q (4200 MPa / p_max(Q))³`. ISO 76 relates it to the bearing's static rating by
//! `C₀ = Z Q₀ / 5`; for the study's bearing (Z = 19, D = 5.5 mm, d_m = 51 mm, f_i = 0.52) this
//! gives Q₀ ≈ 2.35 kN and C₀ ≈ 8.9 kN, the rating ISO 76's factor `f₀ ≈ 15.6` gives for its
//! `D / d_m` (`C₀ = f₀ Z D²`).

use std::f64::consts::PI;

/// Materials and the geometry not in the scene (SI): both bodies of one steel.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Materials {
    /// Young's modulus E (Pa).
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio ν.
    pub poisson: f64,
    /// Inner groove radius over ball diameter, f_i.
    pub groove_conformity: f64,
    /// The contact pressure that defines the static capacity (Pa): 4200 MPa (ISO 76).
    pub static_pressure_pa: f64,
}

impl Default for Materials {
    fn default() -> Self {
        Self { youngs_modulus_pa: 208e9, poisson: 0.3, groove_conformity: 0.52, static_pressure_pa: 4.2e9 }
    }
}

/// A contact's peak pressure and its half-width.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Pressure {
    /// Peak (Hertz) pressure (Pa).
    pub p_max_pa: f64,
    /// Half-width of the contact across the rolling direction (m): the line contact's `b`, the
    /// ellipse's semi-major axis `a`.
    pub half_width_m: f64,
}

/// The rotor – inner race line contact for normal force `force` (N): shaft radius
/// `rotor_radius`, bore radius `bore_radius`, contact length `length` (m).
pub fn rotor_race(m: &Materials, force: f64, rotor_radius: f64, bore_radius: f64, length: f64) -> Pressure {
    let r = 1.0 / (1.0 / rotor_radius - 1.0 / bore_radius);
    let e_star = m.youngs_modulus_pa / (2.0 * (1.0 - m.poisson * m.poisson));
    let f = force.max(0.0);
    Pressure {
        p_max_pa: (f * e_star / (PI * length * r)).sqrt(),
        half_width_m: (4.0 * f * r / (PI * length * e_star)).sqrt(),
    }
}

/// The ball – inner raceway contact for ball load `load` (N): ball diameter `ball`, pitch
/// diameter `pitch` (m).
pub fn ball_inner(m: &Materials, load: f64, ball: f64, pitch: f64) -> Pressure {
    let rx = 1.0 / (2.0 / ball + 2.0 / (pitch - ball));
    let ry = 1.0 / (2.0 / ball - 1.0 / (m.groove_conformity * ball));
    let alpha = ry / rx;
    let k = alpha.powf(2.0 / PI);
    let ell = 1.0 + (PI / 2.0 - 1.0) / alpha;
    let r = 1.0 / (1.0 / rx + 1.0 / ry);
    let e_prime = m.youngs_modulus_pa / (1.0 - m.poisson * m.poisson);
    let q = load.max(0.0);
    let a = (6.0 * k * k * ell * q * r / (PI * e_prime)).cbrt();
    let b = (6.0 * ell * q * r / (PI * k * e_prime)).cbrt();
    let p = if q > 0.0 { 3.0 * q / (2.0 * PI * a * b) } else { 0.0 };
    Pressure { p_max_pa: p, half_width_m: a }
}

/// The static capacity of one ball, `Q₀` (N): the load giving `m.static_pressure_pa` at the
/// ball – inner raceway contact (see the module doc).
pub fn ball_static_load(m: &Materials, ball: f64, pitch: f64) -> f64 {
    let q = 1000.0;
    q * (m.static_pressure_pa / ball_inner(m, q, ball, pitch).p_max_pa).powi(3)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_study_bearing_static_capacity_is_iso_76s() {
        // C₀ = f₀ Z D² with f₀ ≈ 15.6 at D cos α / d_m = 0.108 (ISO 76, table 1, interpolated):
        // 15.6 × 19 × 5.5² = 8966 N, and Q₀ = 5 C₀ / Z.
        let m = Materials::default();
        let q0 = ball_static_load(&m, 5.5e-3, 51e-3);
        let c0 = 19.0 * q0 / 5.0;
        assert!((c0 / 8966.0 - 1.0).abs() < 0.05, "C0 = {c0} N, Q0 = {q0} N");
        // Pressure grows as the cube root of the load.
        let (p1, p8) = (ball_inner(&m, 100.0, 5.5e-3, 51e-3), ball_inner(&m, 800.0, 5.5e-3, 51e-3));
        assert!((p8.p_max_pa / p1.p_max_pa - 2.0).abs() < 1e-12);
    }

    #[test]
    fn line_contact_against_a_hand_computation() {
        // A steel cylinder of 10 mm radius on a flat (bore radius infinite): R = 10 mm;
        // F = 1000 N over 10 mm, E* = 114.3 GPa:
        // p = √(1000 · 114.3e9 / (π · 0.01 · 0.01)) = 603 MPa.
        let m = Materials::default();
        let p = rotor_race(&m, 1000.0, 0.01, f64::INFINITY, 0.01);
        assert!((p.p_max_pa / 603.14e6 - 1.0).abs() < 1e-3, "{}", p.p_max_pa);
        assert_eq!(rotor_race(&m, 0.0, 0.01, 0.0101, 0.01).p_max_pa, 0.0);
    }
}
