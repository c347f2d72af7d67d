//! The two-plane rotor linearised about the centred, levitated rotor with the continuous PD at
//! each plane (MODEL.md §10.4): its whirl modes against spin speed (the Campbell diagram) and its
//! steady response to unbalance (the initial orbit).
//!
//! The bearings are isotropic (the same law in x and y), so the motion is written in complex
//! coordinates `ζ = x + j y` (the axis at the centre of mass's station) and `φ = a + j b` (its
//! slopes): a term `e^{λt}` with `Im λ > 0` turns from `+x` towards `+y`, the sense of the spin:
//! a forward whirl; `Im λ < 0` a backward whirl. Plane `i`'s force, with the sensor at `zs_i`
//! and the actuator at `z_i`, is
//!
//! ```text
//! F_i = −k_e,i s_i − c_i ṡ_i − k_s,i (s_i − Δ_i),   s_i = ζ + zs_i φ,   Δ_i = ζ + z_i φ
//! ```
//!
//! (`k_e` the closed-loop stiffness of the plane's PD on its own sensor, `c` its damping, `k_s`
//! the bearing's negative stiffness, which acts at the actuator), and the rotor obeys
//!
//! ```text
//! M ζ̈ = Σ F_i,        I_t φ̈ − j I_p Ω φ̇ = Σ z_i F_i
//! ```
//!
//! i.e. `M q̈ + (C − j Ω G) q̇ + K q = f` with `q = (ζ, φ)`, `M = diag(M, I_t)`,
//! `G = diag(0, I_p)` and
//!
//! ```text
//! K = | Σ k_e          Σ (k_e zs + k_s (zs − z))    |     C = | Σ c      Σ c zs   |
//!     | Σ z k_e        Σ z (k_e zs + k_s (zs − z))  |         | Σ z c    Σ z c zs |
//! ```
//!
//! For a symmetric rotor with collocated sensors (`z_B = −z_A = l`, identical planes) the two
//! rows decouple: the cylindrical pair at `λ² M + λ 2c + 2k_e = 0`, the same for both whirls,
//! and the conical pair at `I_t λ² + (2 c l² − j I_p Ω) λ + 2 k_e l² = 0`; undamped, the
//! conical frequencies are `ω = (± I_p Ω + √((I_p Ω)² + 4 I_t k_θ)) / (2 I_t)`,
//! `k_θ = 2 k_e l²`: the forward one rises with the speed, the backward one falls.

use nalgebra::{Complex, Matrix2, Matrix4, Vector2};

type C64 = Complex<f64>;

/// One plane's linearised loop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneLoop {
    /// Axial station z of the actuator (m).
    pub station: f64,
    /// Axial station zs of the sensor (m).
    pub sensor: f64,
    /// Closed-loop stiffness k_e on the sensor's displacement (N/m).
    pub stiffness: f64,
    /// Closed-loop damping c (N·s/m).
    pub damping: f64,
    /// The bearing's negative stiffness k_s (N/m), at the actuator.
    pub negative_stiffness: f64,
}

/// The linearised rotor–AMB system.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearRotor {
    /// Whole mass M (kg).
    pub mass: f64,
    /// Transverse moment of inertia I_t (kg·m²).
    pub transverse_inertia: f64,
    /// Polar moment of inertia I_p (kg·m²).
    pub polar_inertia: f64,
    /// Planes A and B.
    pub planes: [PlaneLoop; 2],
}

/// The sense of a mode's whirl.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Whirl {
    /// The same sense as the spin.
    Forward,
    /// Against the spin.
    Backward,
}

/// A mode's shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// Mostly translation (the planes move together).
    Cylindrical,
    /// Mostly tilt (the planes move against each other).
    Conical,
}

/// One whirl mode at a spin speed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mode {
    /// Eigenvalue λ of the complex system (1/s): `e^{λt}`.
    pub eigenvalue: C64,
    /// Forward or backward.
    pub whirl: Whirl,
    /// Cylindrical or conical.
    pub shape: Shape,
    /// Damped natural frequency `|Im λ| / 2π` (Hz).
    pub frequency_hz: f64,
    /// Damping ratio `−Re λ / |λ|`.
    pub damping_ratio: f64,
    /// The mode shape (ζ, φ), scaled to `|ζ|² + l² |φ|² = 1` with `l` the half span.
    pub shape_vector: [C64; 2],
}

/// Why the modes could not be computed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ModesError {
    /// The eigenvalue solver did not converge.
    #[error("the eigenvalues of the linearised rotor did not converge at {speed_rad_s} rad/s")]
    NoConvergence {
        /// The spin speed (rad/s).
        speed_rad_s: f64,
    },
}

impl LinearRotor {
    /// The rotor of `p` under the continuous PD of gains `gains` at each plane, linearised about
    /// the centre: the PD `i = i_bias − A_a (k_p A_s s + k_d A_s ṡ)` through `F = k_i i + k_s Δ`
    /// (the nonlinear bearing law has the same `k_i`, `k_s` at the centre) gives
    /// `k_e = k_i A_a A_s k_p − k_s` and `c = k_i A_a A_s k_d` on the sensor's displacement.
    pub fn from_gains(p: &super::Params, gains: &[controller::PdGains; 2]) -> Self {
        let plane = |i: usize| {
            let (pl, g) = (&p.planes[i], &gains[i]);
            let c = &pl.params.loop_constants;
            let loop_gain = c.ki_n_per_a * g.amp_gain_a_per_v * c.sensor_gain_v_per_m;
            PlaneLoop {
                station: pl.station,
                sensor: pl.sensor,
                stiffness: loop_gain * g.kp - c.ks_n_per_m,
                damping: loop_gain * g.kd,
                negative_stiffness: c.ks_n_per_m,
            }
        };
        LinearRotor {
            mass: p.rotor.mass,
            transverse_inertia: p.rotor.transverse_inertia,
            polar_inertia: p.rotor.polar_inertia,
            planes: [plane(0), plane(1)],
        }
    }

    /// The stiffness matrix K (rows ζ, φ; N/m, N, N·m).
    pub fn stiffness(&self) -> [[f64; 2]; 2] {
        let mut k = [[0.0; 2]; 2];
        for p in &self.planes {
            let on_tilt = p.stiffness * p.sensor + p.negative_stiffness * (p.sensor - p.station);
            k[0][0] += p.stiffness;
            k[0][1] += on_tilt;
            k[1][0] += p.station * p.stiffness;
            k[1][1] += p.station * on_tilt;
        }
        k
    }

    /// The damping matrix C (rows ζ, φ).
    pub fn damping(&self) -> [[f64; 2]; 2] {
        let mut c = [[0.0; 2]; 2];
        for p in &self.planes {
            c[0][0] += p.damping;
            c[0][1] += p.damping * p.sensor;
            c[1][0] += p.station * p.damping;
            c[1][1] += p.station * p.damping * p.sensor;
        }
        c
    }

    /// Half the bearing span `(z_B − z_A) / 2` (m): the length that makes a slope comparable
    /// with a displacement.
    pub fn half_span(&self) -> f64 {
        0.5 * (self.planes[1].station - self.planes[0].station)
    }

    /// The dynamic stiffness `D(λ) = λ² M + λ (C − j Ω G) + K` at spin speed `speed` (rad/s).
    pub fn dynamic(&self, speed: f64, lambda: C64) -> Matrix2<C64> {
        let (k, c) = (self.stiffness(), self.damping());
        let mass = [self.mass, self.transverse_inertia];
        let entry = |r: usize, col: usize| {
            let m = if r == col { mass[r] } else { 0.0 };
            let gyro = if r == 1 && col == 1 { C64::new(0.0, -speed * self.polar_inertia) } else { C64::new(0.0, 0.0) };
            lambda * lambda * m + lambda * (C64::new(c[r][col], 0.0) + gyro) + k[r][col]
        };
        Matrix2::new(entry(0, 0), entry(0, 1), entry(1, 0), entry(1, 1))
    }

    /// The four whirl modes at spin speed `speed` (rad/s): forward and backward, cylindrical
    /// and conical, in that order (forward cylindrical, backward cylindrical, forward conical,
    /// backward conical). Of the two modes whirling one way, the one with more translation
    /// relative to tilt (`|ζ|` against `l |φ|`) is called cylindrical.
    pub fn modes(&self, speed: f64) -> Result<[Mode; 4], ModesError> {
        let (k, c) = (self.stiffness(), self.damping());
        let (m, it) = (self.mass, self.transverse_inertia);
        let re = |v: f64| C64::new(v, 0.0);
        let gyro = C64::new(0.0, -speed * self.polar_inertia);
        // First order in (ζ, φ, ζ̇, φ̇): q̈ = −M⁻¹ K q − M⁻¹ (C − jΩG) q̇.
        #[rustfmt::skip]
        let a = Matrix4::new(
            re(0.0), re(0.0), re(1.0), re(0.0),
            re(0.0), re(0.0), re(0.0), re(1.0),
            re(-k[0][0] / m), re(-k[0][1] / m), re(-c[0][0] / m), re(-c[0][1] / m),
            re(-k[1][0] / it), re(-k[1][1] / it), re(-c[1][0] / it), (re(-c[1][1]) - gyro) / it,
        );
        let values = a.eigenvalues().ok_or(ModesError::NoConvergence { speed_rad_s: speed })?;
        if values.iter().any(|v| !(v.re.is_finite() && v.im.is_finite())) {
            return Err(ModesError::NoConvergence { speed_rad_s: speed });
        }
        let l = self.half_span();
        let mut modes: Vec<Mode> = values
            .iter()
            .map(|&lambda| {
                let shape_vector = self.null_vector(speed, lambda, l);
                Mode {
                    eigenvalue: lambda,
                    whirl: if lambda.im >= 0.0 { Whirl::Forward } else { Whirl::Backward },
                    shape: Shape::Cylindrical,
                    frequency_hz: lambda.im.abs() / std::f64::consts::TAU,
                    damping_ratio: if lambda.norm() > 0.0 { -lambda.re / lambda.norm() } else { 0.0 },
                    shape_vector,
                }
            })
            .collect();
        // Two each way: of a pair, the more translational is cylindrical. An overdamped or
        // degenerate set (not two each way) is split by the sign of the frequency as found.
        modes.sort_by(|x, y| y.eigenvalue.im.total_cmp(&x.eigenvalue.im));
        let (fw, bw) = modes.split_at_mut(2);
        for pair in [fw, bw] {
            let ratio = |md: &Mode| md.shape_vector[0].norm() / (l * md.shape_vector[1].norm()).max(f64::MIN_POSITIVE);
            if ratio(&pair[1]) > ratio(&pair[0]) {
                pair.swap(0, 1);
            }
            pair[0].shape = Shape::Cylindrical;
            pair[1].shape = Shape::Conical;
            let whirl =
                if pair[0].eigenvalue.im + pair[1].eigenvalue.im >= 0.0 { Whirl::Forward } else { Whirl::Backward };
            pair[0].whirl = whirl;
            pair[1].whirl = whirl;
        }
        Ok([modes[0], modes[2], modes[1], modes[3]])
    }

    /// A null vector `(ζ, φ)` of `D(λ)`, scaled to `|ζ|² + l² |φ|² = 1`.
    fn null_vector(&self, speed: f64, lambda: C64, l: f64) -> [C64; 2] {
        let d = self.dynamic(speed, lambda);
        // From the row with the larger entries: (−d01, d00) or (d11, −d10).
        let row0 = d[(0, 0)].norm() + d[(0, 1)].norm();
        let row1 = d[(1, 0)].norm() + d[(1, 1)].norm();
        let v = if row0 >= row1 { [-d[(0, 1)], d[(0, 0)]] } else { [d[(1, 1)], -d[(1, 0)]] };
        let norm = (v[0].norm_sqr() + l * l * v[1].norm_sqr()).sqrt();
        if norm > 0.0 {
            [v[0] / norm, v[1] / norm]
        } else {
            [C64::new(1.0, 0.0), C64::new(0.0, 0.0)]
        }
    }

    /// The steady response `(ζ, φ)` to a forcing `(force, moment) e^{jΩt}` at spin speed `speed`
    /// (rad/s): `D(jΩ) q = f`. When the coupling terms of `D` are zero (a symmetric rotor) each
    /// row is solved on its own, `ζ = force / D_00`, the planar model's formula.
    pub fn forced_response(&self, speed: f64, force: C64, moment: C64) -> [C64; 2] {
        let d = self.dynamic_at_spin(speed);
        if d[(0, 1)] == C64::new(0.0, 0.0) && d[(1, 0)] == C64::new(0.0, 0.0) {
            return [force / d[(0, 0)], moment / d[(1, 1)]];
        }
        let det = d[(0, 0)] * d[(1, 1)] - d[(0, 1)] * d[(1, 0)];
        [(force * d[(1, 1)] - d[(0, 1)] * moment) / det, (d[(0, 0)] * moment - d[(1, 0)] * force) / det]
    }

    /// `D(jΩ)` at the spin speed, written out as the planar model writes its denominator
    /// (`k_e − m ω² + j c_e ω`), so that a decoupled row gives the planar orbit bit for bit.
    fn dynamic_at_spin(&self, speed: f64) -> Matrix2<C64> {
        let (k, c) = (self.stiffness(), self.damping());
        let w = speed;
        let (m, it, ip) = (self.mass, self.transverse_inertia, self.polar_inertia);
        Matrix2::new(
            C64::new(k[0][0] - m * w * w, c[0][0] * w),
            C64::new(k[0][1], c[0][1] * w),
            C64::new(k[1][0], c[1][0] * w),
            // −I_t Ω² + I_p Ω² (the gyroscopic term at a forward synchronous whirl) + K + jΩC.
            C64::new(k[1][1] - it * w * w + ip * w * w, c[1][1] * w),
        )
    }

    /// The static deflection `(ζ, φ)` (real) under a force `force` (N) at the centre of mass
    /// and no moment: `K q = (force, 0)`; each row on its own when K is diagonal.
    pub fn static_deflection(&self, force: f64) -> Vector2<f64> {
        let k = self.stiffness();
        if k[0][1] == 0.0 && k[1][0] == 0.0 {
            return Vector2::new(force / k[0][0], 0.0);
        }
        let det = k[0][0] * k[1][1] - k[0][1] * k[1][0];
        Vector2::new(force * k[1][1] / det, -k[1][0] * force / det)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// The default two-plane machine: M = 23 kg, I_t = 0.414, I_p = 11.62e-3, bearings at
    /// ±0.18 m, k_e = 1e6 N/m per bearing.
    fn symmetric(damping: f64) -> LinearRotor {
        let plane = |z: f64| PlaneLoop { station: z, sensor: z, stiffness: 1e6, damping, negative_stiffness: 4.32e5 };
        LinearRotor {
            mass: 23.0,
            transverse_inertia: 0.414,
            polar_inertia: 11.62e-3,
            planes: [plane(-0.18), plane(0.18)],
        }
    }

    /// Undamped symmetric rotor: the four frequencies against the closed forms, at rest and at
    /// 250 and 500 Hz; the forward conical rises, the backward falls, the cylindrical stays.
    #[test]
    fn undamped_symmetric_modes_match_the_closed_forms() {
        let r = symmetric(0.0);
        let (m, it, ip, k, l): (f64, f64, f64, f64, f64) = (23.0, 0.414, 11.62e-3, 1e6, 0.18);
        let cylindrical = (2.0 * k / m).sqrt() / TAU;
        let mut previous: Option<[Mode; 4]> = None;
        for hz in [0.0, 250.0, 500.0] {
            let w = hz * TAU;
            let k_theta = 2.0 * k * l * l;
            let root = ((ip * w).powi(2) + 4.0 * it * k_theta).sqrt();
            let (fw, bw) = ((ip * w + root) / (2.0 * it) / TAU, (-ip * w + root) / (2.0 * it) / TAU);
            let modes = r.modes(w).unwrap();
            let expect = [
                (Whirl::Forward, Shape::Cylindrical, cylindrical),
                (Whirl::Backward, Shape::Cylindrical, cylindrical),
                (Whirl::Forward, Shape::Conical, fw),
                (Whirl::Backward, Shape::Conical, bw),
            ];
            for (md, (whirl, shape, f)) in modes.iter().zip(expect) {
                assert_eq!((md.whirl, md.shape), (whirl, shape), "{hz} Hz: {md:?}");
                assert!(
                    (md.frequency_hz - f).abs() < 1e-9 * f,
                    "{hz} Hz {whirl:?} {shape:?}: {} against {f}",
                    md.frequency_hz
                );
                assert!(md.damping_ratio.abs() < 1e-9, "{md:?}");
            }
            if let Some(prev) = previous {
                assert!(modes[2].frequency_hz > prev[2].frequency_hz && modes[3].frequency_hz < prev[3].frequency_hz);
            }
            previous = Some(modes);
        }
        // The standstill values the scene comments state: 46.9 Hz and about 63 Hz.
        assert!((cylindrical - 46.9).abs() < 0.05, "{cylindrical}");
        let conical = (2.0 * k * l * l / it).sqrt() / TAU;
        assert!((conical - 62.9).abs() < 0.1, "{conical}");
    }

    /// Damped: the cylindrical row is the oscillator `M ζ̈ + 2c ζ̇ + 2k_e ζ = 0`,
    /// `λ = −ξω_n ± jω_n√(1 − ξ²)` with `ξ = 2c / (2 √(2k_e M))`: the design's ξ_e per bearing
    /// on its mass share (`c = 2 ξ_e √(k_e M/2)`) is the mode's.
    #[test]
    fn damped_cylindrical_mode_matches_the_oscillator() {
        let c = 2.0 * 0.01 * (1e6_f64 * 11.5).sqrt();
        let r = symmetric(c);
        let wn = (2e6_f64 / 23.0).sqrt();
        let zeta = 2.0 * c / (2.0 * (2e6_f64 * 23.0).sqrt());
        let modes = r.modes(500.0 * TAU).unwrap();
        for md in &modes[..2] {
            assert!((md.damping_ratio - zeta).abs() < 1e-9, "{md:?}");
            assert!((md.eigenvalue.im.abs() - wn * (1.0 - zeta * zeta).sqrt()).abs() < 1e-6, "{md:?}");
        }
        assert!((zeta - 0.01).abs() < 1e-12, "the design's ξ_e per bearing is the mode's: {zeta}");
    }

    /// The forced response solves D(jΩ) q = f, coupled or not; decoupled, it is the planar formula.
    #[test]
    fn forced_response_solves_the_dynamic_stiffness() {
        let mut r = symmetric(300.0);
        r.planes[1].station = 0.25;
        r.planes[0].sensor = -0.2;
        let w = 300.0 * TAU;
        let f = [C64::new(2.0, -1.0), C64::new(0.3, 0.5)];
        let q = r.forced_response(w, f[0], f[1]);
        let d = r.dynamic(w, C64::new(0.0, w));
        let back = d * nalgebra::Vector2::new(q[0], q[1]);
        for i in 0..2 {
            assert!((back[i] - f[i]).norm() < 1e-9 * f[i].norm(), "{back:?} against {f:?}");
        }
        let s = symmetric(300.0);
        let q = s.forced_response(w, f[0], C64::new(0.0, 0.0));
        let planar = f[0] / C64::new(2e6 - 23.0 * w * w, 600.0 * w);
        assert_eq!(q[0], planar);
    }
}
