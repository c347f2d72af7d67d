//! `modal`: a centralised law of the two-plane rotor in translation and tilt coordinates,
//! with its own stiffness and damping for the cylindrical and the conical modes and an
//! optional cross-feedback of the tilt rates against the gyroscopic coupling `I_p Ω`.
//!
//! # The rotor it is designed on (issue 17's coordinates)
//!
//! z along the rotor axis from plane A to plane B, origin at the centre of mass; the rotor's
//! axis at the centre of mass is displaced (x, y) and sloped a = dx/dz, b = dy/dz, so a
//! station z moves by (x + a z, y + b z). A rigid rotor of mass M, transverse inertia I_t and
//! polar inertia I_p spinning at Ω about +z obeys, for small tilts,
//!
//! ```text
//! M ẍ = F_xA + F_xB                      I_t ä + I_p Ω ḃ = z_A F_xA + z_B F_xB
//! M ÿ = F_yA + F_yB (− M g)              I_t b̈ − I_p Ω ȧ = z_A F_yA + z_B F_yB
//! ```
//!
//! (the angular momentum `I_t (−ḃ, ȧ) + I_p Ω (a, b)` about x and y; with `a + j b = e^{jωt}`
//! and no bearing, `I_t ω² − I_p Ω ω − k_θ = 0`: the forward whirl, in the sense of the spin,
//! stiffens with speed), and each bearing's linearised force is `F_j = k_ij i_j + k_sj Δ_j`
//! with `Δ_j` the displacement at the actuator station z_j.
//!
//! # The law
//!
//! From the sensor voltages at the sensor stations z_sA ≠ z_sB (`d_j = u_j / A_sj`):
//!
//! ```text
//! a = (d_B − d_A) / (z_sB − z_sA)        x = (z_sB d_A − z_sA d_B) / (z_sB − z_sA)      (b, y alike)
//! ```
//!
//! and their rates by the backward difference (0 at the first sample, as `pd`). The modal
//! forces asked for, with `K_c, C_c` for translation (the cylindrical modes), `K_t, C_t` for
//! tilt (the conical modes) and `κ` the cross-feedback (Ω is the keyphasor's speed):
//!
//! ```text
//! F_x = −K_c x − C_c ẋ                   M_a = −K_t a − C_t ȧ + κ I_p Ω ḃ
//! F_y = −K_c y − C_c ẏ (+ M g)           M_b = −K_t b − C_t ḃ − κ I_p Ω ȧ
//! ```
//!
//! are shared between the bearings by statics (`F_A = (z_B F − M) / (z_B − z_A)`,
//! `F_B = (M − z_A F) / (z_B − z_A)`), and each bearing's current cancels its negative
//! stiffness at the estimated actuator displacement: `i_j = (F_j − k_sj (x + a z_j)) / k_ij`
//! (the law commands currents; the amplifier gain plays no part). On the linearised rotor the
//! closed loop is then exactly
//!
//! ```text
//! M ẍ + C_c ẋ + K_c x = 0                I_t φ̈ + (C_t − j (1 − κ) I_p Ω) φ̇ + K_t φ = 0,   φ = a + j b
//! ```
//!
//! cylindrical modes at `ω_c = √(K_c / M)` with damping ratio `C_c / (2 √(K_c M))`, conical
//! modes at `√(K_t / I_t)` at standstill, split into forward and backward whirl by
//! `(1 − κ) I_p Ω` (κ = 1 removes the split: the gyroscopic coupling is fed back away). The
//! gravity bias (`gravity_bias`) carries `M g` shared by statics, so each bearing carries its
//! static share. The design is for the continuous loop; sampling at `T` with `d` samples of
//! delay adds the naive PD's lag (as `pd`, not `pd_delay`).
//!
//! # Parameters (`[controller.params]`)
//!
//! | key | unit | default | meaning |
//! |---|---|---|---|
//! | `cylindrical_stiffness_n_per_m` | N/m | k_eA + k_eB | K_c, the translational stiffness of the whole rotor (> 0) |
//! | `cylindrical_damping_ratio` | – | ξ_e (plane A's) | damping ratio of the cylindrical modes (≥ 0) |
//! | `conical_stiffness_n_m_per_rad` | N m/rad | k_eA z_A² + k_eB z_B² | K_t, the tilt stiffness (> 0) |
//! | `conical_damping_ratio` | – | ξ_e (plane A's) | damping ratio of the conical modes at standstill (≥ 0) |
//! | `gyroscopic_cross_feedback` | – | 0 | κ, the part of I_p Ω fed back (0 none … 1 all) |
//!
//! The defaults give the cylindrical mode of the decentralised design (the per-bearing k_e
//! summed) and the conical stiffness that bearings of stiffness k_e at their stations give.

use crate::design::{Design, Geometry, RotorDesign, ROTOR_AXES};
use crate::error::LawError;
use crate::law::{RotorLaw, RotorLawEntry, RotorSample};
use crate::params::{Check, Params};

/// `modal` and its parameters (the module doc's table).
pub const LAW: RotorLawEntry = RotorLawEntry {
    name: "modal",
    summary: "two-plane rotor only: centralised law in translation and tilt, stiffness and damping per mode, \
              gyroscopic cross-feedback (params cylindrical_stiffness_n_per_m, cylindrical_damping_ratio, \
              conical_stiffness_n_m_per_rad, conical_damping_ratio, gyroscopic_cross_feedback)",
    build,
};

fn build(design: &RotorDesign, params: &Params) -> Result<Box<dyn RotorLaw>, LawError> {
    let spec = ModalSpec::from_params(params, design)?;
    Ok(Box::new(Modal::new(design, &spec)?))
}

/// The modal design asked for (SI), from `modal`'s parameters.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ModalSpec {
    /// K_c (N/m).
    pub cylindrical_stiffness_n_per_m: f64,
    /// ζ_c.
    pub cylindrical_damping_ratio: f64,
    /// K_t (N m/rad).
    pub conical_stiffness_n_m_per_rad: f64,
    /// ζ_t (at standstill).
    pub conical_damping_ratio: f64,
    /// κ in [0, 1].
    pub gyroscopic_cross_feedback: f64,
}

impl ModalSpec {
    /// Reads the parameters; the defaults come from the rotor's design (the module doc). A
    /// planar design is refused ([`LawError::Axes`]).
    pub fn from_params(params: &Params, design: &RotorDesign) -> Result<Self, LawError> {
        let (planes, g) = two_plane(design)?;
        let [a, b] = planes;
        let [za, zb] = g.bearing_z_m;
        let mut p = params.reader(LAW.name);
        let kc = p.number(
            "cylindrical_stiffness_n_per_m",
            "N/m",
            a.stiffness_n_per_m + b.stiffness_n_per_m,
            Check::Positive,
        )?;
        let zc = p.number("cylindrical_damping_ratio", "", a.damping_ratio, Check::NonNegative)?;
        let kt = p.number(
            "conical_stiffness_n_m_per_rad",
            "N m/rad",
            a.stiffness_n_per_m * za * za + b.stiffness_n_per_m * zb * zb,
            Check::Positive,
        )?;
        let zt = p.number("conical_damping_ratio", "", a.damping_ratio, Check::NonNegative)?;
        let kappa = p.number("gyroscopic_cross_feedback", "", 0.0, Check::NonNegative)?;
        if kappa > 1.0 {
            return Err(p.error(
                "gyroscopic_cross_feedback",
                kappa,
                "",
                "must be between 0 (none) and 1 (the whole gyroscopic coupling I_p Ω fed back)",
            ));
        }
        p.finish()?;
        Ok(Self {
            cylindrical_stiffness_n_per_m: kc,
            cylindrical_damping_ratio: zc,
            conical_stiffness_n_m_per_rad: kt,
            conical_damping_ratio: zt,
            gyroscopic_cross_feedback: kappa,
        })
    }
}

/// The two planes and the geometry, or the refusal of a planar rotor.
fn two_plane(design: &RotorDesign) -> Result<([Design; 2], Geometry), LawError> {
    match design {
        RotorDesign::TwoPlane { planes, geometry } => Ok((*planes, *geometry)),
        RotorDesign::Planar(_) => {
            Err(LawError::Axes { law: LAW.name, axes: design.axes(), drives: "a two-plane rotor (4 axes) only" })
        }
    }
}

/// The continuous modal gains the law applies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModalGains {
    /// K_c (N/m).
    pub kc: f64,
    /// C_c = 2 ζ_c √(K_c M) (N s/m).
    pub cc: f64,
    /// K_t (N m/rad).
    pub kt: f64,
    /// C_t = 2 ζ_t √(K_t I_t) (N m s/rad).
    pub ct: f64,
    /// κ I_p (kg m²): the moment per unit of Ω times the other tilt rate.
    pub gyro: f64,
}

/// The `modal` law.
#[derive(Clone, Debug)]
pub struct Modal {
    gains: ModalGains,
    /// Sensor gains A_s per plane (V/m).
    sensor_gain: [f64; 2],
    /// Sensor stations (m).
    sensor_z: [f64; 2],
    /// Bearing stations (m).
    bearing_z: [f64; 2],
    /// k_i per plane (N/A).
    ki: [f64; 2],
    /// k_s per plane (N/m).
    ks: [f64; 2],
    /// The vertical force carried by the bias (N): M g, or 0.
    weight_n: f64,
    period_s: f64,
    /// The previous sample's modal coordinates (x, a, y, b).
    prev: Option<[f64; 4]>,
}

impl Modal {
    /// The law for a two-plane rotor's design and a modal spec; refuses a planar design and a
    /// geometry it cannot be built on, naming the hello's field.
    pub fn new(design: &RotorDesign, spec: &ModalSpec) -> Result<Self, LawError> {
        design.check()?;
        let ([a, b], g) = two_plane(design)?;
        let bad = |key, value, unit, why| Err(LawError::Design { key, value, unit, why });
        if !(g.mass_kg.is_finite() && g.mass_kg > 0.0) {
            return bad("Hello.total_mass_kg", g.mass_kg, "kg", "must be > 0 (law modal)");
        }
        if !(g.transverse_inertia_kg_m2.is_finite() && g.transverse_inertia_kg_m2 > 0.0) {
            return bad(
                "Hello.transverse_inertia_kg_m2",
                g.transverse_inertia_kg_m2,
                "kg m²",
                "must be > 0 (law modal)",
            );
        }
        if !(g.polar_inertia_kg_m2.is_finite() && g.polar_inertia_kg_m2 >= 0.0) {
            return bad("Hello.polar_inertia_kg_m2", g.polar_inertia_kg_m2, "kg m²", "must be >= 0 (law modal)");
        }
        let [zsa, zsb] = g.sensor_z_m;
        if !(zsa.is_finite() && zsb.is_finite() && zsa != zsb) {
            return bad(
                "Hello.sensor_b_z_m",
                zsb,
                "m",
                "must be finite and differ from sensor_a_z_m (law modal tells tilt from translation by it)",
            );
        }
        for (plane, d) in [("Hello.ki_n_per_a (plane A)", &a), ("Hello.b_ki_n_per_a", &b)] {
            let ki = d.constants.ki_n_per_a;
            if !(ki.is_finite() && ki != 0.0) {
                return bad(plane, ki, "N/A", "must be finite and non-zero (law modal)");
            }
        }
        for (plane, d) in [("Hello.sensor_gain_v_per_m (plane A)", &a), ("Hello.b_sensor_gain_v_per_m", &b)] {
            let s = d.constants.sensor_gain_v_per_m;
            if !(s.is_finite() && s != 0.0) {
                return bad(plane, s, "V/m", "must be finite and non-zero (law modal)");
            }
        }
        let gains = ModalGains {
            kc: spec.cylindrical_stiffness_n_per_m,
            cc: 2.0 * spec.cylindrical_damping_ratio * (spec.cylindrical_stiffness_n_per_m * g.mass_kg).sqrt(),
            kt: spec.conical_stiffness_n_m_per_rad,
            ct: 2.0
                * spec.conical_damping_ratio
                * (spec.conical_stiffness_n_m_per_rad * g.transverse_inertia_kg_m2).sqrt(),
            gyro: spec.gyroscopic_cross_feedback * g.polar_inertia_kg_m2,
        };
        Ok(Self {
            gains,
            sensor_gain: [a.constants.sensor_gain_v_per_m, b.constants.sensor_gain_v_per_m],
            sensor_z: g.sensor_z_m,
            bearing_z: g.bearing_z_m,
            ki: [a.constants.ki_n_per_a, b.constants.ki_n_per_a],
            ks: [a.constants.ks_n_per_m, b.constants.ks_n_per_m],
            weight_n: if a.gravity_bias { g.mass_kg * a.constants.gravity_m_s2 } else { 0.0 },
            period_s: a.period_s,
            prev: None,
        })
    }

    /// The continuous modal gains.
    pub fn gains(&self) -> ModalGains {
        self.gains
    }

    /// The modal coordinates (x, a) of one direction from its two sensor displacements (m).
    #[inline]
    fn modal(&self, d_a: f64, d_b: f64) -> (f64, f64) {
        let [zsa, zsb] = self.sensor_z;
        let span = zsb - zsa;
        ((zsb * d_a - zsa * d_b) / span, (d_b - d_a) / span)
    }

    /// The two bearings' currents for a total force `f` (N) and moment `m` (N m) about the
    /// centre of mass in one direction, at the estimated position `x` and slope `a`.
    #[inline]
    fn currents(&self, f: f64, m: f64, x: f64, a: f64) -> [f64; 2] {
        let [za, zb] = self.bearing_z;
        let span = zb - za;
        let forces = [(zb * f - m) / span, (m - za * f) / span];
        [(forces[0] - self.ks[0] * (x + a * za)) / self.ki[0], (forces[1] - self.ks[1] * (x + a * zb)) / self.ki[1]]
    }
}

impl RotorLaw for Modal {
    fn name(&self) -> &'static str {
        LAW.name
    }

    fn update(&mut self, s: &RotorSample) -> [f64; ROTOR_AXES] {
        let u = s.sensor_v;
        let [ga, gb] = self.sensor_gain;
        let (x, a) = self.modal(u[0] / ga, u[2] / gb);
        let (y, b) = self.modal(u[1] / ga, u[3] / gb);
        let q = [x, a, y, b];
        let rate = match self.prev {
            Some(p) => std::array::from_fn(|k| (q[k] - p[k]) / self.period_s),
            None => [0.0; 4],
        };
        self.prev = Some(q);
        let [xd, ad, yd, bd] = rate;
        let g = self.gains;
        let omega = s.speed_rad_s;
        let fx = -g.kc * x - g.cc * xd;
        let ma = -g.kt * a - g.ct * ad + g.gyro * omega * bd;
        let fy = self.weight_n - g.kc * y - g.cc * yd;
        let mb = -g.kt * b - g.ct * bd - g.gyro * omega * ad;
        let [ixa, ixb] = self.currents(fx, ma, x, a);
        let [iya, iyb] = self.currents(fy, mb, y, b);
        [ixa, iya, ixb, iyb]
    }

    fn reset(&mut self) {
        self.prev = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::LoopConstants;
    use nalgebra::{SMatrix, SVector};
    use num_complex::Complex64;

    type M4 = SMatrix<f64, 4, 4>;

    /// An asymmetric two-plane rotor: centre of mass off mid-span, sensors not collocated,
    /// each plane with its own magnetics and sensor.
    fn asymmetric() -> RotorDesign {
        let a = Design {
            constants: LoopConstants {
                ki_n_per_a: 216.0,
                ks_n_per_m: 4.32e5,
                sensor_gain_v_per_m: 25_000.0,
                rotor_mass_kg: 14.0,
                ..LoopConstants::study()
            },
            ..Design::study()
        };
        let b = Design {
            stiffness_n_per_m: 1.4e6,
            constants: LoopConstants {
                ki_n_per_a: 180.0,
                ks_n_per_m: 3.1e5,
                sensor_gain_v_per_m: 20_000.0,
                rotor_mass_kg: 9.0,
                ..LoopConstants::study()
            },
            current_limit_a: 3.0,
            ..Design::study()
        };
        RotorDesign::TwoPlane {
            planes: [a, b],
            geometry: Geometry {
                mass_kg: 23.0,
                transverse_inertia_kg_m2: 0.414,
                polar_inertia_kg_m2: 11.62e-3,
                rated_speed_rad_s: std::f64::consts::TAU * 500.0,
                bearing_z_m: [-0.14, 0.22],
                sensor_z_m: [-0.17, 0.25],
            },
        }
    }

    fn spec(design: &RotorDesign, extra: &str) -> ModalSpec {
        ModalSpec::from_params(&Params::parse(extra).unwrap(), design).unwrap()
    }

    /// The linear two-plane rigid rotor of the module doc, with the bearings' linearised
    /// forces, written independently of the law: the generalised forces (F_x, M_a, F_y, M_b)
    /// that the law's currents give at positions `q` = (x, a, y, b) moving at `qd`.
    struct Rotor {
        design: RotorDesign,
    }

    impl Rotor {
        fn geometry(&self) -> Geometry {
            *self.design.geometry().unwrap()
        }

        fn sensors(&self, q: &[f64; 4]) -> [f64; 4] {
            let g = self.geometry();
            let p = self.design.planes();
            let at = |plane: usize, pos: f64, slope: f64| {
                p[plane].constants.sensor_gain_v_per_m * (pos + slope * g.sensor_z_m[plane])
            };
            [at(0, q[0], q[1]), at(0, q[2], q[3]), at(1, q[0], q[1]), at(1, q[2], q[3])]
        }

        fn forces(&self, i: [f64; 4], q: &[f64; 4]) -> [f64; 4] {
            let g = self.geometry();
            let p = self.design.planes();
            let bearing = |plane: usize, current: f64, pos: f64, slope: f64| {
                let c = p[plane].constants;
                c.ki_n_per_a * current + c.ks_n_per_m * (pos + slope * g.bearing_z_m[plane])
            };
            let (fxa, fya) = (bearing(0, i[0], q[0], q[1]), bearing(0, i[1], q[2], q[3]));
            let (fxb, fyb) = (bearing(1, i[2], q[0], q[1]), bearing(1, i[3], q[2], q[3]));
            let [za, zb] = g.bearing_z_m;
            [fxa + fxb, za * fxa + zb * fxb, fya + fyb, za * fya + zb * fyb]
        }

        /// The generalised force at `q` moving at `qd`, the law fed two samples one period
        /// apart (its backward difference then reads `qd`), at spin speed `omega`.
        fn probe(&self, law: &mut Modal, q: [f64; 4], qd: [f64; 4], omega: f64) -> [f64; 4] {
            law.reset();
            let t = law.period_s;
            let before: [f64; 4] = std::array::from_fn(|k| q[k] - qd[k] * t);
            let sample = |seq, q: &[f64; 4]| RotorSample {
                seq,
                t_s: seq as f64 * t,
                axes: 4,
                sensor_v: self.sensors(q),
                speed_rad_s: omega,
                angle_rad: 0.0,
            };
            law.update(&sample(0, &before));
            let i = law.update(&sample(1, &q));
            self.forces(i, &q)
        }

        /// The law's stiffness and damping matrices on this rotor (Q = bias − K q − C q̇),
        /// measured by probing each coordinate.
        fn matrices(&self, law: &mut Modal, omega: f64) -> (M4, M4) {
            let bias = self.probe(law, [0.0; 4], [0.0; 4], omega);
            let (mut k, mut c) = (M4::zeros(), M4::zeros());
            let (dq, dv) = ([1e-5, 1e-4, 1e-5, 1e-4], [1e-3, 1e-2, 1e-3, 1e-2]);
            for j in 0..4 {
                let mut e = [0.0; 4];
                e[j] = dq[j];
                let f = self.probe(law, e, [0.0; 4], omega);
                let mut v = [0.0; 4];
                v[j] = dv[j];
                let g = self.probe(law, [0.0; 4], v, omega);
                for r in 0..4 {
                    k[(r, j)] = -(f[r] - bias[r]) / dq[j];
                    c[(r, j)] = -(g[r] - bias[r]) / dv[j];
                }
            }
            (k, c)
        }

        /// The closed loop's eigenvalues: M q̈ + G q̇ = −K q − C q̇ with the gyroscopic G.
        fn eigenvalues(&self, k: &M4, c: &M4, omega: f64) -> Vec<Complex64> {
            let g = self.geometry();
            let m =
                SVector::<f64, 4>::new(g.mass_kg, g.transverse_inertia_kg_m2, g.mass_kg, g.transverse_inertia_kg_m2);
            let mut gyro = M4::zeros();
            gyro[(1, 3)] = g.polar_inertia_kg_m2 * omega;
            gyro[(3, 1)] = -g.polar_inertia_kg_m2 * omega;
            let mut a = SMatrix::<f64, 8, 8>::zeros();
            for r in 0..4 {
                a[(r, r + 4)] = 1.0;
                for j in 0..4 {
                    a[(r + 4, j)] = -k[(r, j)] / m[r];
                    a[(r + 4, j + 4)] = -(c[(r, j)] + gyro[(r, j)]) / m[r];
                }
            }
            a.complex_eigenvalues().iter().copied().collect()
        }
    }

    /// The closed-form roots: the cylindrical pair twice (x and y), the conical roots of
    /// `I_t s² + (C_t − j γ) s + K_t = 0`, γ = (1 − κ) I_p Ω, and their conjugates.
    fn closed_form(g: &Geometry, s: &ModalSpec, omega: f64) -> Vec<Complex64> {
        let wc = (s.cylindrical_stiffness_n_per_m / g.mass_kg).sqrt();
        let zc = s.cylindrical_damping_ratio;
        let cyl = Complex64::new(-zc * wc, wc * (1.0 - zc * zc).sqrt());
        let it = g.transverse_inertia_kg_m2;
        let kt = s.conical_stiffness_n_m_per_rad;
        let ct = 2.0 * s.conical_damping_ratio * (kt * it).sqrt();
        let gamma = (1.0 - s.gyroscopic_cross_feedback) * g.polar_inertia_kg_m2 * omega;
        let b = Complex64::new(ct, -gamma);
        let root = (b * b - 4.0 * it * kt).sqrt();
        let (r1, r2) = ((-b + root) / (2.0 * it), (-b - root) / (2.0 * it));
        vec![cyl, cyl, cyl.conj(), cyl.conj(), r1, r2, r1.conj(), r2.conj()]
    }

    fn assert_same_roots(mut got: Vec<Complex64>, mut want: Vec<Complex64>, what: &str) {
        let key = |z: &Complex64| (z.im, z.re);
        got.sort_by(|a, b| key(a).partial_cmp(&key(b)).unwrap());
        want.sort_by(|a, b| key(a).partial_cmp(&key(b)).unwrap());
        for (g, w) in got.iter().zip(&want) {
            assert!(
                (g - w).norm() < 1e-6 * w.norm(),
                "{what}: eigenvalue {g} against the closed form {w}\n{got:?}\n{want:?}"
            );
        }
    }

    #[test]
    fn the_closed_loop_has_the_modal_stiffness_and_damping_asked_for() {
        let design = asymmetric();
        let rotor = Rotor { design };
        let g = rotor.geometry();
        let s = spec(
            &design,
            "cylindrical_damping_ratio = 0.2\nconical_damping_ratio = 0.1\nconical_stiffness_n_m_per_rad = 6e4",
        );
        let mut law = Modal::new(&design, &s).unwrap();
        let (k, c) = rotor.matrices(&mut law, 0.0);
        let gains = law.gains();
        // Through the rotor's physics (non-collocated sensors, the negative stiffnesses, two
        // different bearings): the stiffness and damping are modal, diagonal, as asked.
        let want_k = M4::from_diagonal(&SVector::<f64, 4>::new(gains.kc, gains.kt, gains.kc, gains.kt));
        let want_c = M4::from_diagonal(&SVector::<f64, 4>::new(gains.cc, gains.ct, gains.cc, gains.ct));
        for r in 0..4 {
            for j in 0..4 {
                let scale = want_k[(r, r)].max(want_k[(j, j)]);
                assert!(
                    (k[(r, j)] - want_k[(r, j)]).abs() < 1e-6 * scale,
                    "K[{r},{j}] = {} against {}",
                    k[(r, j)],
                    want_k[(r, j)]
                );
                let scale = want_c[(r, r)].max(want_c[(j, j)]);
                assert!(
                    (c[(r, j)] - want_c[(r, j)]).abs() < 1e-5 * scale,
                    "C[{r},{j}] = {} against {}",
                    c[(r, j)],
                    want_c[(r, j)]
                );
            }
        }
        assert_eq!(gains.kc, 1e6 + 1.4e6, "the default K_c is the bearings' k_e summed");
        assert_eq!(gains.kt, 6e4);
        // The modal damping ratios, from the measured C.
        assert!((c[(0, 0)] / (2.0 * (k[(0, 0)] * g.mass_kg).sqrt()) - 0.2).abs() < 1e-6);
        assert!((c[(1, 1)] / (2.0 * (k[(1, 1)] * g.transverse_inertia_kg_m2).sqrt()) - 0.1).abs() < 1e-6);
        // The eigenvalues of the closed loop are the closed form's, at standstill.
        assert_same_roots(rotor.eigenvalues(&k, &c, 0.0), closed_form(&g, &s, 0.0), "standstill");
    }

    #[test]
    fn at_speed_the_conical_modes_split_unless_the_coupling_is_fed_back() {
        let design = asymmetric();
        let rotor = Rotor { design };
        let g = rotor.geometry();
        let omega = g.rated_speed_rad_s;
        for kappa in [0.0, 0.5, 1.0] {
            let s = spec(&design, &format!("conical_damping_ratio = 0.05\ngyroscopic_cross_feedback = {kappa:?}"));
            let mut law = Modal::new(&design, &s).unwrap();
            let (k, c) = rotor.matrices(&mut law, omega);
            // The cross-feedback is a skew term between the tilt rates: + κ I_p Ω on M_a from ḃ.
            let want = kappa * g.polar_inertia_kg_m2 * omega;
            assert!((-c[(1, 3)] - want).abs() < 1e-6 * (want.abs() + 1.0), "κ = {kappa}: C[a, b] = {}", c[(1, 3)]);
            assert!((c[(3, 1)] - want).abs() < 1e-6 * (want.abs() + 1.0), "κ = {kappa}: C[b, a] = {}", c[(3, 1)]);
            let roots = rotor.eigenvalues(&k, &c, omega);
            assert_same_roots(roots.clone(), closed_form(&g, &s, omega), &format!("κ = {kappa}"));
            // Forward (Im > 0 of the φ = a + j b roots) and backward conical frequencies.
            let conical: Vec<f64> = closed_form(&g, &s, omega)[4..6].iter().map(|r| r.im.abs()).collect();
            let split = (conical[0] - conical[1]).abs();
            let standstill = (s.conical_stiffness_n_m_per_rad / g.transverse_inertia_kg_m2).sqrt();
            if kappa == 1.0 {
                assert!(split < 1e-9 * standstill, "fed back whole: no split ({split})");
            } else {
                // (1 − κ) I_p Ω / I_t, the split of the undamped gyroscopic pair.
                let expected = (1.0 - kappa) * g.polar_inertia_kg_m2 * omega / g.transverse_inertia_kg_m2;
                assert!((split / expected - 1.0).abs() < 1e-2, "κ = {kappa}: split {split} rad/s, expected {expected}");
            }
        }
    }

    #[test]
    fn on_the_symmetric_machine_the_defaults_give_the_planar_rigid_mode() {
        let design = RotorDesign::symmetric_study();
        let s = spec(&design, "");
        let law = Modal::new(&design, &s).unwrap();
        let g = Geometry::symmetric_study();
        // √(2 k_e / M) = √(k_e / m): the planar model's rigid mode, 46.9 Hz.
        let f = (law.gains().kc / g.mass_kg).sqrt() / std::f64::consts::TAU;
        assert!((f - 46.9).abs() < 0.05, "{f} Hz");
        assert_eq!(law.gains().kt, 2.0 * 1e6 * 0.18 * 0.18);
        let f_conical = (law.gains().kt / g.transverse_inertia_kg_m2).sqrt() / std::f64::consts::TAU;
        assert!((f_conical - 63.0).abs() < 0.1, "{f_conical} Hz");
        assert_eq!(
            (s.cylindrical_damping_ratio, s.conical_damping_ratio, s.gyroscopic_cross_feedback),
            (0.01, 0.01, 0.0)
        );
    }

    #[test]
    fn the_gravity_bias_gives_each_bearing_its_static_share() {
        let design = asymmetric();
        let mut law = Modal::new(&design, &spec(&design, "")).unwrap();
        let i = law.update(&RotorSample { axes: 4, ..Default::default() });
        let g = design.geometry().unwrap();
        let [za, zb] = g.bearing_z_m;
        let weight = g.mass_kg * 9.80665;
        let (share_a, share_b) = (weight * zb / (zb - za), -weight * za / (zb - za));
        let p = design.planes();
        assert_eq!((i[0], i[2]), (0.0, 0.0));
        assert!((i[1] * p[0].constants.ki_n_per_a - share_a).abs() < 1e-9 * weight, "{i:?}");
        assert!((i[3] * p[1].constants.ki_n_per_a - share_b).abs() < 1e-9 * weight, "{i:?}");
        // The first sample's derivative is 0 (a second sample at the same place gives the
        // same currents); another place has a rate; reset forgets the previous sample.
        let at = |v: f64| RotorSample { axes: 4, sensor_v: [v, 0.0, v, 0.0], ..Default::default() };
        law.reset();
        let first = law.update(&at(0.1));
        assert_eq!(law.update(&at(0.1)), first);
        let moving = law.update(&at(0.2));
        law.reset();
        let still = law.update(&at(0.2));
        assert!(moving[0] < still[0] && moving[2] < still[2], "the rate damps: {moving:?} against {still:?}");
        law.reset();
        assert_eq!(law.update(&at(0.1)), first);
    }

    #[test]
    fn a_planar_rotor_and_bad_parameters_are_refused_naming_law_key_value_and_unit() {
        let e = build(&RotorDesign::Planar(Design::study()), &Params::default()).err().unwrap();
        assert!(matches!(e, LawError::Axes { law: "modal", axes: 2, .. }), "{e:?}");
        assert!(e.to_string().contains("two-plane rotor (4 axes)") && e.to_string().contains("2 axes"), "{e}");
        let design = asymmetric();
        for (doc, needles) in [
            (
                "cylindrical_stiffness_n_per_m = -5.0",
                &["law modal", "controller.params.cylindrical_stiffness_n_per_m = -5.0 N/m", "> 0"][..],
            ),
            (
                "conical_stiffness_n_m_per_rad = \"stiff\"",
                &["law modal", "conical_stiffness_n_m_per_rad = \"stiff\" N m/rad", "expected a number"][..],
            ),
            (
                "conical_damping_ratio = -0.1",
                &["law modal", "controller.params.conical_damping_ratio = -0.1", ">= 0"][..],
            ),
            (
                "gyroscopic_cross_feedback = 1.5",
                &["law modal", "controller.params.gyroscopic_cross_feedback = 1.5", "between 0"][..],
            ),
            (
                "stiffness = 1.0",
                &[
                    "law modal",
                    "unknown parameter controller.params.stiffness",
                    "cylindrical_stiffness_n_per_m, cylindrical_damping_ratio",
                ][..],
            ),
        ] {
            let e = build(&design, &Params::parse(doc).unwrap()).err().unwrap().to_string();
            for n in needles {
                assert!(e.contains(n), "{doc}: no {n:?} in {e}");
            }
        }
        let RotorDesign::TwoPlane { planes, geometry } = design else { unreachable!() };
        for (g, key) in [
            (Geometry { sensor_z_m: [0.1, 0.1], ..geometry }, "Hello.sensor_b_z_m"),
            (Geometry { transverse_inertia_kg_m2: 0.0, ..geometry }, "Hello.transverse_inertia_kg_m2"),
            (Geometry { mass_kg: f64::NAN, ..geometry }, "Hello.total_mass_kg"),
            (Geometry { bearing_z_m: [0.2, 0.1], ..geometry }, "Hello.bearing_b_z_m"),
        ] {
            let e =
                build(&RotorDesign::TwoPlane { planes, geometry: g }, &Params::default()).err().unwrap().to_string();
            assert!(e.contains(key), "{e}");
        }
    }
}
