//! Housing (base) kinematics.
//!
//! A pulse prescribes the housing motion along one scalar direction `e`:
//! acceleration `a(t)`, velocity `v(t) = ∫₀ᵗ a`, displacement
//! `d(t) = ∫₀ᵗ v`, all zero before the pulse starts. A programme projects
//! each pulse onto its unit direction `e = (cos θ, sin θ)` in the x-y plane
//! (x horizontal, y up) and adds the vectors.

/// Housing kinematics along one scalar direction.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Kinematics {
    /// Acceleration, m/s².
    pub accel: f64,
    /// Velocity, m/s.
    pub vel: f64,
    /// Displacement, m.
    pub disp: f64,
}

/// Housing kinematics in the x-y plane (x horizontal, y up).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Kinematics2 {
    /// Acceleration `[a_x, a_y]`, m/s².
    pub accel: [f64; 2],
    /// Velocity `[v_x, v_y]`, m/s.
    pub vel: [f64; 2],
    /// Displacement `[d_x, d_y]`, m.
    pub disp: [f64; 2],
}

impl Kinematics2 {
    /// Add the scalar kinematics `k` acting along the unit vector `unit`
    /// (`[cos θ, sin θ]`).
    #[inline]
    pub fn add_along(&mut self, k: Kinematics, unit: [f64; 2]) {
        for (i, &e) in unit.iter().enumerate() {
            self.accel[i] += k.accel * e;
            self.vel[i] += k.vel * e;
            self.disp[i] += k.disp * e;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn add_along_projects_onto_unit_vector() {
        let mut k2 = Kinematics2::default();
        let k = Kinematics { accel: 2.0, vel: 3.0, disp: 4.0 };
        k2.add_along(k, [0.6, 0.8]);
        k2.add_along(k, [1.0, 0.0]);
        assert_eq!(k2.accel, [2.0 * 0.6 + 2.0, 2.0 * 0.8]);
        assert_eq!(k2.vel, [3.0 * 0.6 + 3.0, 3.0 * 0.8]);
        assert_eq!(k2.disp, [4.0 * 0.6 + 4.0, 4.0 * 0.8]);
    }
}
