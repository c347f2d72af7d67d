//! A bearing plane's own axes (MODEL.md §3.3): real radial AMBs put their magnet pairs at ±45°
//! from the vertical, so that both pairs share the weight. The plane's two axes are u, at the
//! angle θ from x (counter-clockwise, x horizontal, y up), and v, 90° further:
//!
//! ```text
//! û = (cos θ, sin θ),   v̂ = (−sin θ, cos θ)
//! d_uv = Rᵀ d_xy   (d_u = x cos θ + y sin θ,  d_v = −x sin θ + y cos θ)
//! F_xy = R F_uv    (F_x = F_u cos θ − F_v sin θ,  F_y = F_u sin θ + F_v cos θ)
//! ```
//!
//! ROSS's convention exactly (`rotor_assembly.py` of petrobras/ross at 631a249a, lines
//! 2716–2717 and 2731–2732, `sensor_angle` = the element's `sensors_axis_rotation`). The coil
//! pair on u pushes along u, the sensor of u reads the projection onto u; the wire, the
//! currents and the controller speak in (u, v), the rotor's motion stays in (x, y). At θ = 0
//! (the default) every function here returns its argument itself, untouched, so that a scene
//! without an angle runs the very arithmetic it ran before the axes could turn.

use nalgebra::Vector2;

/// The plane's axes: the angle θ of u from x, and its cosine and sine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Axes {
    angle: f64,
    cos: f64,
    sin: f64,
}

impl Default for Axes {
    /// The housing's own axes (θ = 0).
    fn default() -> Self {
        Self::new(0.0)
    }
}

impl Axes {
    /// The axes at `angle` (rad) from x; 0: the housing's own.
    pub fn new(angle: f64) -> Self {
        let (sin, cos) = angle.sin_cos();
        Self { angle, cos, sin }
    }

    /// θ (rad).
    pub fn angle(&self) -> f64 {
        self.angle
    }

    /// Whether these are the housing's own axes (θ = 0): what is not serialised.
    pub fn is_housings(&self) -> bool {
        !self.turned()
    }

    /// Whether the axes are turned (θ ≠ 0).
    #[inline(always)]
    pub fn turned(&self) -> bool {
        self.angle != 0.0
    }

    /// A vector of the housing's (x, y) in the plane's axes (u, v): `Rᵀ d`.
    #[inline(always)]
    pub fn to_plane(&self, d: Vector2<f64>) -> Vector2<f64> {
        if !self.turned() {
            return d;
        }
        Vector2::new(d.x * self.cos + d.y * self.sin, -d.x * self.sin + d.y * self.cos)
    }

    /// A vector of the plane's axes (u, v) in the housing's (x, y): `R f`.
    #[inline(always)]
    pub fn to_housing(&self, f: Vector2<f64>) -> Vector2<f64> {
        if !self.turned() {
            return f;
        }
        Vector2::new(f.x * self.cos - f.y * self.sin, f.x * self.sin + f.y * self.cos)
    }

    /// [`Axes::to_plane`] of a pair.
    #[inline(always)]
    pub fn pair_to_plane(&self, d: [f64; 2]) -> [f64; 2] {
        self.to_plane(Vector2::from(d)).into()
    }
}

/// Serialised as θ in degrees (the scene's `amb.axis_angle_deg`).
impl serde::Serialize for Axes {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_f64(self.angle.to_degrees())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At 0° both ways are the identity, bit for bit, even for −0 and non-finite values.
    #[test]
    fn zero_is_the_identity_bit_for_bit() {
        let a = Axes::default();
        assert_eq!(a, Axes::new(0.0));
        for v in [Vector2::new(-0.0, 1e-300), Vector2::new(f64::NAN, -3.5), Vector2::new(f64::INFINITY, 0.0)] {
            for w in [a.to_plane(v), a.to_housing(v)] {
                assert_eq!(w.x.to_bits(), v.x.to_bits());
                assert_eq!(w.y.to_bits(), v.y.to_bits());
            }
        }
    }

    /// At 45°, x̂ reads (1/√2, −1/√2), ŷ reads (1/√2, 1/√2); a push along u is (1/√2, 1/√2) in
    /// (x, y); at 90°, u is y and v is −x. Written out, not from the functions.
    #[test]
    fn the_axes_turn_counter_clockwise() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let a = Axes::new(45f64.to_radians());
        let close = |v: Vector2<f64>, x: f64, y: f64| (v.x - x).abs() < 1e-15 && (v.y - y).abs() < 1e-15;
        assert!(close(a.to_plane(Vector2::new(1.0, 0.0)), h, -h));
        assert!(close(a.to_plane(Vector2::new(0.0, 1.0)), h, h));
        assert!(close(a.to_housing(Vector2::new(1.0, 0.0)), h, h));
        assert!(close(a.to_housing(Vector2::new(0.0, 1.0)), -h, h));
        let q = Axes::new(90f64.to_radians());
        assert!(close(q.to_plane(Vector2::new(0.0, 2.0)), 2.0, 0.0));
        assert!(close(q.to_plane(Vector2::new(3.0, 0.0)), 0.0, -3.0));
        // Round trip.
        let v = Vector2::new(1.25e-5, -7.5e-6);
        let back = a.to_housing(a.to_plane(v));
        assert!((back - v).norm() < 1e-20);
    }
}
