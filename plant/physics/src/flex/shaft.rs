//! One Timoshenko beam element of the shaft (MODEL.md §13.2): its mass (translation and rotary
//! inertia), stiffness (bending and shear) and gyroscopic matrices on the element's eight
//! lateral degrees of freedom.
//!
//! The formulation is ROSS's `ShaftElement` (Genta's conical element, Genta & Gugliotta 1988),
//! restricted to the lateral motion: of ROSS's twelve degrees of freedom per element
//! (`x, y, z, α, β, θ` at each end) the axial `z` and torsional `θ` ones are uncoupled from the
//! others in ROSS's matrices and are left out here. The order is
//!
//! ```text
//! [x₀, y₀, α₀, β₀, x₁, y₁, α₁, β₁]
//! ```
//!
//! `x` horizontal, `y` vertical (m), `α` the rotation about `x`, `β` the rotation about `y`
//! (rad): for small slopes `β = dx/dz` and `α = −dy/dz`. The element's own matrices are the
//! lateral rows and columns of ROSS's, so the same geometry gives the same numbers; the
//! equation of motion they enter is `M q̈ + (C + Ω G) q̇ + K q = f` with the spin `Ω` about `+z`.

use nalgebra::SMatrix;

/// An 8×8 element matrix.
pub type Matrix8 = SMatrix<f64, 8, 8>;

/// A shaft material (SI).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Material {
    /// Density ρ (kg/m³).
    pub density: f64,
    /// Young's modulus E (Pa).
    pub modulus: f64,
    /// Shear modulus G (Pa).
    pub shear_modulus: f64,
}

impl Material {
    /// Poisson's ratio `ν = E / (2 G) − 1`.
    pub fn poisson(&self) -> f64 {
        self.modulus / (2.0 * self.shear_modulus) - 1.0
    }
}

/// How the shear coefficient κ of a hollow circular section is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ShearMethod {
    /// Cowper (1966), ROSS's default.
    #[default]
    Cowper,
    /// Hutchinson (2001).
    Hutchinson,
}

/// One shaft element: a (possibly conical) hollow beam between two nodes.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ShaftElement {
    /// Length L (m).
    pub length: f64,
    /// Inner diameter at the left node (m).
    pub inner_left: f64,
    /// Outer diameter at the left node (m).
    pub outer_left: f64,
    /// Inner diameter at the right node (m).
    pub inner_right: f64,
    /// Outer diameter at the right node (m).
    pub outer_right: f64,
    /// The material.
    pub material: Material,
    /// Shear deformation (Timoshenko) taken into account; Euler–Bernoulli without it.
    pub shear_effects: bool,
    /// Rotary inertia of the sections taken into account.
    pub rotary_inertia: bool,
    /// Gyroscopic coupling taken into account.
    pub gyroscopic: bool,
    /// The shear coefficient's formula.
    pub shear_method: ShearMethod,
    /// Mass-proportional damping factor α of the element (1/s): `C = α M + β K`.
    pub alpha: f64,
    /// Stiffness-proportional damping factor β of the element (s).
    pub beta: f64,
}

/// The geometric coefficients of a conical element (Genta): how area and second moment vary
/// along it, relative to the left end.
#[derive(Clone, Copy, Debug)]
struct Taper {
    a1: f64,
    a2: f64,
    b1: f64,
    b2: f64,
    gamma: f64,
    delta: f64,
}

impl ShaftElement {
    /// A cylindrical element of length `length`, inner and outer diameters `inner`, `outer`
    /// (m), with shear, rotary inertia and gyroscopic terms (ROSS's defaults).
    pub fn cylinder(length: f64, inner: f64, outer: f64, material: Material) -> Self {
        ShaftElement {
            length,
            inner_left: inner,
            outer_left: outer,
            inner_right: inner,
            outer_right: outer,
            material,
            shear_effects: true,
            rotary_inertia: true,
            gyroscopic: true,
            shear_method: ShearMethod::Cowper,
            alpha: 0.0,
            beta: 0.0,
        }
    }

    /// Cross-section area at the left end (m²).
    pub fn area_left(&self) -> f64 {
        std::f64::consts::PI * (self.outer_left.powi(2) - self.inner_left.powi(2)) / 4.0
    }

    /// Second moment of area at the left end (m⁴).
    pub fn second_moment_left(&self) -> f64 {
        std::f64::consts::PI * (self.outer_left.powi(4) - self.inner_left.powi(4)) / 64.0
    }

    /// Volume (m³) of the conical frustum.
    pub fn volume(&self) -> f64 {
        let outer = self.outer_left.powi(2) + self.outer_left * self.outer_right + self.outer_right.powi(2);
        let inner = self.inner_left.powi(2) + self.inner_left * self.inner_right + self.inner_right.powi(2);
        std::f64::consts::PI * self.length / 12.0 * (outer - inner)
    }

    /// Mass (kg).
    pub fn mass(&self) -> f64 {
        self.material.density * self.volume()
    }

    fn taper(&self) -> Taper {
        let (roj, rij, rok, rik) =
            (self.outer_left / 2.0, self.inner_left / 2.0, self.outer_right / 2.0, self.inner_right / 2.0);
        let (a_l, i_l) = (self.area_left(), self.second_moment_left());
        let (dro, dri) = (rok - roj, rik - rij);
        let pi = std::f64::consts::PI;
        Taper {
            a1: 2.0 * pi * (roj * dro - rij * dri) / a_l,
            a2: pi * (roj.powi(3) * dro - rij.powi(3) * dri) / i_l,
            b1: pi * (dro * dro - dri * dri) / a_l,
            b2: 3.0 * pi * (roj * roj * dro * dro - rij * rij * dri * dri) / (2.0 * i_l),
            gamma: pi * (roj * dro.powi(3) - rij * dri.powi(3)) / i_l,
            delta: pi * (dro.powi(4) - dri.powi(4)) / (4.0 * i_l),
        }
    }

    /// Area at mid-element (m²).
    fn area_mid(&self, t: &Taper) -> f64 {
        self.area_left() * (1.0 + t.a1 * 0.5 + t.b1 * 0.25)
    }

    /// Second moment of area at mid-element (m⁴).
    fn second_moment_mid(&self, t: &Taper) -> f64 {
        self.second_moment_left() * (1.0 + t.a2 * 0.5 + t.b2 * 0.25 + t.gamma * 0.125 + t.delta * 0.0625)
    }

    /// The shear coefficient κ of the mean section (Cowper or Hutchinson), or `None` without
    /// shear effects.
    pub fn shear_coefficient(&self) -> Option<f64> {
        if !self.shear_effects {
            return None;
        }
        let r = (self.inner_left + self.inner_right) / (self.outer_left + self.outer_right);
        let r2 = r * r;
        let r12 = (1.0 + r2).powi(2);
        let nu = self.material.poisson();
        Some(match self.shear_method {
            ShearMethod::Cowper => 6.0 * r12 * (1.0 + nu) / (r12 * (7.0 + 6.0 * nu) + r2 * (20.0 + 12.0 * nu)),
            ShearMethod::Hutchinson => {
                6.0 * r12 * (1.0 + nu)
                    / (r12 * (7.0 + 12.0 * nu + 4.0 * nu * nu) + 4.0 * r2 * (5.0 + 6.0 * nu + 2.0 * nu * nu))
            }
        })
    }

    /// The shear parameter `φ = 12 E I / (G κ A L²)` (0 without shear effects).
    pub fn shear_parameter(&self) -> f64 {
        let t = self.taper();
        match self.shear_coefficient() {
            None => 0.0,
            Some(kappa) => {
                12.0 * self.material.modulus * self.second_moment_mid(&t)
                    / (self.material.shear_modulus * kappa * self.area_mid(&t) * self.length.powi(2))
            }
        }
    }

    /// The mass matrix: translational inertia, plus rotary inertia when enabled (kg, kg·m, kg·m²).
    #[rustfmt::skip]
    pub fn mass_matrix(&self) -> Matrix8 {
        let t = self.taper();
        let (phi, l) = (self.shear_parameter(), self.length);
        let p2 = phi * phi;
        let (a1, b1) = (t.a1, t.b1);
        let m1 = (468.0 + 882.0 * phi + 420.0 * p2) + a1 * (108.0 + 210.0 * phi + 105.0 * p2) + b1 * (38.0 + 78.0 * phi + 42.0 * p2);
        let m2 = ((66.0 + 115.5 * phi + 52.5 * p2) + a1 * (21.0 + 40.5 * phi + 21.0 * p2) + b1 * (8.5 + 18.0 * phi + 10.5 * p2)) * l;
        let m3 = (162.0 + 378.0 * phi + 210.0 * p2) + a1 * (81.0 + 189.0 * phi + 105.0 * p2) + b1 * (46.0 + 111.0 * phi + 63.0 * p2);
        let m4 = ((39.0 + 94.5 * phi + 52.5 * p2) + a1 * (18.0 + 40.5 * phi + 21.0 * p2) + b1 * (9.5 + 21.0 * phi + 10.5 * p2)) * l;
        let m5 = ((12.0 + 21.0 * phi + 10.5 * p2) + a1 * (4.5 + 9.0 * phi + 5.25 * p2) + b1 * (2.0 + 4.5 * phi + 3.0 * p2)) * l * l;
        let m6 = ((39.0 + 94.5 * phi + 52.5 * p2) + a1 * (21.0 + 54.0 * phi + 31.5 * p2) + b1 * (12.5 + 34.5 * phi + 21.0 * p2)) * l;
        let m7 = ((9.0 + 21.0 * phi + 10.5 * p2) + a1 * (4.5 + 10.5 * phi + 5.25 * p2) + b1 * (2.5 + 6.0 * phi + 3.0 * p2)) * l * l;
        let m8 = (468.0 + 882.0 * phi + 420.0 * p2) + a1 * (360.0 + 672.0 * phi + 315.0 * p2) + b1 * (290.0 + 540.0 * phi + 252.0 * p2);
        let m9 = ((66.0 + 115.5 * phi + 52.5 * p2) + a1 * (45.0 + 75.0 * phi + 31.5 * p2) + b1 * (32.5 + 52.5 * phi + 21.0 * p2)) * l;
        let m10 = ((12.0 + 21.0 * phi + 10.5 * p2) + a1 * (7.5 + 12.0 * phi + 5.25 * p2) + b1 * (5.0 + 7.5 * phi + 3.0 * p2)) * l * l;
        let mt = Matrix8::from_row_slice(&[
             m1, 0.0, 0.0,  m2,  m3, 0.0, 0.0, -m4,
            0.0,  m1, -m2, 0.0, 0.0,  m3,  m4, 0.0,
            0.0, -m2,  m5, 0.0, 0.0, -m6, -m7, 0.0,
             m2, 0.0, 0.0,  m5,  m6, 0.0, 0.0, -m7,
             m3, 0.0, 0.0,  m6,  m8, 0.0, 0.0, -m9,
            0.0,  m3, -m6, 0.0, 0.0,  m8,  m9, 0.0,
            0.0,  m4, -m7, 0.0, 0.0,  m9, m10, 0.0,
            -m4, 0.0, 0.0, -m7, -m9, 0.0, 0.0, m10,
        ]) * (self.material.density * self.area_left() * l / (1260.0 * (1.0 + phi).powi(2)));
        if !self.rotary_inertia {
            return mt;
        }
        let (r11, r12, r13, r14, r15, r16) = self.rotary_coefficients(&t, phi);
        let mr = Matrix8::from_row_slice(&[
             r11,  0.0,  0.0,  r12, -r11,  0.0,  0.0,  r13,
             0.0,  r11, -r12,  0.0,  0.0, -r11, -r13,  0.0,
             0.0, -r12,  r14,  0.0,  0.0,  r12, -r15,  0.0,
             r12,  0.0,  0.0,  r14, -r12,  0.0,  0.0, -r15,
            -r11,  0.0,  0.0, -r12,  r11,  0.0,  0.0, -r13,
             0.0, -r11,  r12,  0.0,  0.0,  r11,  r13,  0.0,
             0.0, -r13, -r15,  0.0,  0.0,  r13,  r16,  0.0,
             r13,  0.0,  0.0, -r15, -r13,  0.0,  0.0,  r16,
        ]) * (self.material.density * self.second_moment_left() / (210.0 * l * (1.0 + phi).powi(2)));
        mt + mr
    }

    /// The six coefficients of the rotary-inertia and gyroscopic matrices (Genta), with their
    /// powers of L.
    fn rotary_coefficients(&self, t: &Taper, phi: f64) -> (f64, f64, f64, f64, f64, f64) {
        let (a2, b2, g, d, l) = (t.a2, t.b2, t.gamma, t.delta, self.length);
        let p2 = phi * phi;
        let c1 = 252.0 + 126.0 * a2 + 72.0 * b2 + 45.0 * g + 30.0 * d;
        let c2 = (21.0 - 105.0 * phi
            + a2 * (21.0 - 42.0 * phi)
            + b2 * (15.0 - 21.0 * phi)
            + g * (10.5 - 12.0 * phi)
            + d * (7.5 - 7.5 * phi))
            * l;
        let c3 = (21.0
            - 105.0 * phi
            - 63.0 * a2 * phi
            - b2 * (6.0 + 42.0 * phi)
            - g * (7.5 + 30.0 * phi)
            - d * (7.5 + 22.5 * phi))
            * l;
        let c4 = (28.0
            + 35.0 * phi
            + 70.0 * p2
            + a2 * (7.0 - 7.0 * phi + 17.5 * p2)
            + b2 * (4.0 - 7.0 * phi + 7.0 * p2)
            + g * (2.75 - 5.0 * phi + 3.5 * p2)
            + d * (2.0 - 3.5 * phi + 2.0 * p2))
            * l
            * l;
        let c5 = (7.0 + 35.0 * phi - 35.0 * p2
            + a2 * (3.5 + 17.5 * phi - 17.5 * p2)
            + b2 * (3.0 + 10.5 * phi - 10.5 * p2)
            + g * (2.75 + 7.0 * phi - 7.0 * p2)
            + d * (2.5 + 5.0 * phi - 5.0 * p2))
            * l
            * l;
        let c6 = (28.0
            + 35.0 * phi
            + 70.0 * p2
            + a2 * (21.0 + 42.0 * phi + 52.5 * p2)
            + b2 * (18.0 + 42.0 * phi + 42.0 * p2)
            + g * (16.25 + 40.0 * phi + 35.0 * p2)
            + d * (15.0 + 37.5 * phi + 30.0 * p2))
            * l
            * l;
        (c1, c2, c3, c4, c5, c6)
    }

    /// The stiffness matrix: bending plus shear (N/m, N, N·m).
    #[rustfmt::skip]
    pub fn stiffness_matrix(&self) -> Matrix8 {
        let t = self.taper();
        let (phi, l) = (self.shear_parameter(), self.length);
        let p2 = phi * phi;
        let (a1, a2, b1, b2, g, d) = (t.a1, t.a2, t.b1, t.b2, t.gamma, t.delta);
        let k1 = 1260.0 + 630.0 * a2 + 504.0 * b2 + 441.0 * g + 396.0 * d;
        let shear = phi * (105.0 * a2 + 105.0 * b2 + 94.5 * g + 84.0 * d);
        let k2 = (630.0 + 210.0 * a2 + 147.0 * b2 + 126.0 * g + 114.0 * d - shear) * l;
        let k3 = (630.0 + 420.0 * a2 + 357.0 * b2 + 315.0 * g + 282.0 * d + shear) * l;
        let k4 = (420.0 + 210.0 * phi + 105.0 * p2
            + a2 * (105.0 + 52.5 * p2)
            + b2 * (56.0 - 35.0 * phi + 35.0 * p2)
            + g * (42.0 - 42.0 * phi + 26.25 * p2)
            + d * (36.0 - 42.0 * phi + 21.0 * p2)) * l * l;
        let k5 = (210.0 - 210.0 * phi - 105.0 * p2
            + a2 * (105.0 - 105.0 * phi - 52.5 * p2)
            + b2 * (91.0 - 70.0 * phi - 35.0 * p2)
            + g * (84.0 - 52.5 * phi - 26.25 * p2)
            + d * (78.0 - 42.0 * phi - 21.0 * p2)) * l * l;
        let k6 = (420.0 + 210.0 * phi + 105.0 * p2
            + a2 * (315.0 + 210.0 * phi + 52.5 * p2)
            + b2 * (266.0 + 175.0 * phi + 35.0 * p2)
            + g * (231.0 + 147.0 * phi + 26.25 * p2)
            + d * (204.0 + 126.0 * phi + 21.0 * p2)) * l * l;
        let k7 = 12.0 + 6.0 * a1 + 4.0 * b1;
        let k8 = (6.0 + 3.0 * a1 + 2.0 * b1) * l;
        let k9 = (3.0 + 1.5 * a1 + b1) * l * l;
        let pattern = |p: f64, q: f64, r: f64, s: f64, u: f64, v: f64| Matrix8::from_row_slice(&[
              p, 0.0, 0.0,   q,  -p, 0.0, 0.0,   r,
            0.0,   p,  -q, 0.0, 0.0,  -p,  -r, 0.0,
            0.0,  -q,   s, 0.0, 0.0,   q,   u, 0.0,
              q, 0.0, 0.0,   s,  -q, 0.0, 0.0,   u,
             -p, 0.0, 0.0,  -q,   p, 0.0, 0.0,  -r,
            0.0,  -p,   q, 0.0, 0.0,   p,   r, 0.0,
            0.0,  -r,   u, 0.0, 0.0,   r,   v, 0.0,
              r, 0.0, 0.0,   u,  -r, 0.0, 0.0,   v,
        ]);
        let bending = pattern(k1, k2, k3, k4, k5, k6) * (self.second_moment_left() / 105.0);
        let shear_part = pattern(k7, k8, k8, k9, k9, k9)
            * (self.second_moment_mid(&t) * phi * self.area_left() / self.area_mid(&t));
        (bending + shear_part) * (self.material.modulus / (l.powi(3) * (1.0 + phi).powi(2)))
    }

    /// The gyroscopic matrix G (kg·m²/m² units of the rotary terms): enters as `Ω G q̇`; zero
    /// when the gyroscopic terms are off.
    #[rustfmt::skip]
    pub fn gyroscopic_matrix(&self) -> Matrix8 {
        if !self.gyroscopic {
            return Matrix8::zeros();
        }
        let t = self.taper();
        let phi = self.shear_parameter();
        let (g1, g2, g3, g4, g5, g6) = self.rotary_coefficients(&t, phi);
        Matrix8::from_row_slice(&[
            0.0,  g1, -g2, 0.0, 0.0, -g1, -g3, 0.0,
            -g1, 0.0, 0.0, -g2,  g1, 0.0, 0.0, -g3,
             g2, 0.0, 0.0,  g4, -g2, 0.0, 0.0, -g5,
            0.0,  g2, -g4, 0.0, 0.0, -g2,  g5, 0.0,
            0.0, -g1,  g2, 0.0, 0.0,  g1,  g3, 0.0,
             g1, 0.0, 0.0,  g2, -g1, 0.0, 0.0,  g3,
             g3, 0.0, 0.0, -g5, -g3, 0.0, 0.0,  g6,
            0.0,  g3,  g5, 0.0, 0.0, -g3, -g6, 0.0,
        ]) * (self.material.density * self.second_moment_left() * 2.0 / (210.0 * self.length * (1.0 + phi).powi(2)))
    }

    /// The element's damping matrix `α M + β K`.
    pub fn damping_matrix(&self) -> Matrix8 {
        if self.alpha == 0.0 && self.beta == 0.0 {
            return Matrix8::zeros();
        }
        self.mass_matrix() * self.alpha + self.stiffness_matrix() * self.beta
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steel() -> Material {
        Material { density: 7810.0, modulus: 211e9, shear_modulus: 81.2e9 }
    }

    /// ROSS's docstring example (L = 0.5, idl = 0.05, odl = 0.1, odr = 0.15, steel): the
    /// printed entries of its M, K and G, lateral rows and columns.
    #[test]
    fn conical_element_reproduces_the_ross_docstring_entries() {
        let mut el = ShaftElement::cylinder(0.5, 0.05, 0.1, steel());
        el.outer_right = 0.15;
        let (m, k, g) = (el.mass_matrix(), el.stiffness_matrix(), el.gyroscopic_matrix());
        let close = |a: f64, b: f64, tol: f64| (a - b).abs() <= tol;
        // ROSS rows/cols x0, y0, α0, β0 are ours 0, 1, 2, 3.
        assert!(close(m[(0, 0)], 11.369864, 1e-6), "{}", m[(0, 0)]);
        assert!(close(m[(0, 3)], 0.861976, 1e-6), "{}", m[(0, 3)]);
        assert!(close(m[(1, 2)], -0.861976, 1e-6), "{}", m[(1, 2)]);
        assert!(close(m[(2, 2)], 0.086675, 1e-6), "{}", m[(2, 2)]);
        assert!(close(k[(0, 0)] / 1e6, 219.9614, 1e-4), "{}", k[(0, 0)]);
        assert!(close(k[(0, 3)] / 1e6, 41.2975, 1e-4), "{}", k[(0, 3)]);
        assert!(close(k[(2, 2)] / 1e6, 12.2353, 1e-4), "{}", k[(2, 2)]);
        assert!(close(g[(0, 1)], 0.309408, 1e-6), "{}", g[(0, 1)]);
        assert!(close(g[(0, 2)], -0.010859, 1e-6), "{}", g[(0, 2)]);
        assert!(close(g[(2, 3)], 0.006721, 1e-6), "{}", g[(2, 3)]);
    }

    /// M and K symmetric, G skew; a rigid translation stores no strain energy and carries the
    /// element's mass.
    #[test]
    fn matrices_have_their_symmetries_and_rigid_body_properties() {
        let mut el = ShaftElement::cylinder(0.3, 0.01, 0.06, steel());
        el.outer_right = 0.08;
        let (m, k, g) = (el.mass_matrix(), el.stiffness_matrix(), el.gyroscopic_matrix());
        assert!((m - m.transpose()).abs().max() < 1e-12 * m.abs().max());
        assert!((k - k.transpose()).abs().max() < 1e-9 * k.abs().max());
        assert!((g + g.transpose()).abs().max() < 1e-15);
        let mut ux = nalgebra::SVector::<f64, 8>::zeros();
        ux[0] = 1.0;
        ux[4] = 1.0;
        assert!((k * ux).abs().max() < 1e-9 * k.abs().max());
        let mass = (ux.transpose() * m * ux)[0];
        assert!((mass - el.mass()).abs() < 1e-9 * el.mass(), "{mass} against {}", el.mass());
        // A rigid tilt in the x–z plane (β = dx/dz = s, x = s z) stores no energy either.
        let s = 1e-3;
        let tilt = nalgebra::SVector::<f64, 8>::from_row_slice(&[0.0, 0.0, 0.0, s, s * el.length, 0.0, 0.0, s]);
        assert!((k * tilt).abs().max() < 1e-6 * k.abs().max() * s);
        // …and in the y–z plane (α = −dy/dz).
        let tilt_y = nalgebra::SVector::<f64, 8>::from_row_slice(&[0.0, 0.0, -s, 0.0, 0.0, s * el.length, -s, 0.0]);
        assert!((k * tilt_y).abs().max() < 1e-6 * k.abs().max() * s);
    }
}
