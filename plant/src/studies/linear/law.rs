//! The scene's law around levitation as a linear transfer of each axis (sensor volts in,
//! current command out), and the loop it closes on the linear plant: its frequency response
//! `P`, the loop `L = P C` and the sensitivity `S = (I − L)⁻¹` (ISO 14839-3's, the excitation
//! added where the sensor signal enters the controller, as `plant assess` measures it:
//! `assess::closed_form`). The arithmetic margins are computed from.
//!
//! The law: the continuous PD `C(s) = −A_a (k_p + k_d s)` of `controller.mode = "continuous"`,
//! or a registry law that is linear around levitation ([`controller::ControlLaw::linear`]: a
//! PD with a backward difference behind an optional second-order filter) sampled at the
//! controller's rate, `C(z)` (its delay is the discrete plant's: [`super::discrete`]); or a
//! law given as a linear system: `transfer_function`'s discrete transfer on every axis, and
//! `state_space`'s discrete system of every axis at once (a full matrix `C(z)`: a law may
//! couple the axes), as the law runs them (`controller::transfer_function::discrete`,
//! `controller::state_space::discrete`). A co-simulated command is a black box: no linear form.

use super::model::System;
use crate::config::{ControlMode, Scene};
use nalgebra::{Complex, DMatrix};
use plant_physics::flex::linear::{AxisLaw, PlanePd};

type C64 = Complex<f64>;

/// A law's linear form, one transfer per axis.
#[derive(Clone, Debug)]
pub enum LinearLaw {
    /// Continuous, `C(s) = −A_a (k_p + k_d s)`, one per axis.
    Continuous(Vec<PlanePd>),
    /// Sampled at `period` (s), `C(z)`, one per axis.
    Sampled {
        /// Each axis' law.
        laws: Vec<AxisLaw>,
        /// Period T (s).
        period: f64,
    },
    /// A discrete state-space law of every axis at once (`state_space`), sensor volts of every
    /// axis in, their current commands out, at `period`.
    StateSpace {
        /// `(A_d, B_d, C_d, D_d)`.
        system: System,
        /// Period T (s).
        period: f64,
    },
}

impl LinearLaw {
    /// Each axis' `C` (A/V) at frequency `f_hz` (Hz): on `s = jω`, or on `z = e^{jωT}`.
    pub fn at(&self, f_hz: f64) -> Vec<C64> {
        let w = std::f64::consts::TAU * f_hz;
        match self {
            LinearLaw::Continuous(pds) => {
                let s = C64::new(0.0, w);
                pds.iter().map(|g| -(C64::new(g.kp, 0.0) + s * g.kd) * g.amp_gain).collect()
            }
            LinearLaw::Sampled { laws, period } => {
                let z = C64::new(0.0, w * period).exp();
                laws.iter().map(|l| l.at(z)).collect()
            }
            LinearLaw::StateSpace { .. } => {
                let c = self.matrix_at(f_hz);
                (0..c.nrows()).map(|k| c[(k, k)]).collect()
            }
        }
    }

    /// The law's transfer matrix `C` (A/V, axes × axes) at `f_hz` (Hz): diagonal but for a
    /// state-space law.
    pub fn matrix_at(&self, f_hz: f64) -> DMatrix<C64> {
        match self {
            LinearLaw::StateSpace { system, period } => {
                response(system, C64::new(0.0, std::f64::consts::TAU * f_hz * period).exp())
            }
            _ => DMatrix::from_diagonal(&nalgebra::DVector::from_vec(self.at(f_hz))),
        }
    }

    /// The law's own poles outside the stability region (`|z| > 1`; a continuous PD has none):
    /// an unstable controller is allowed (some designs are), and the report says so.
    pub fn unstable_poles(&self) -> usize {
        let outside = |m: DMatrix<f64>| m.complex_eigenvalues().iter().filter(|p| p.norm() > 1.0 + 1e-12).count();
        match self {
            LinearLaw::Continuous(_) => 0,
            // Each axis' denominator `1 + d₁ z⁻¹ + …`: the eigenvalues of its companion matrix.
            LinearLaw::Sampled { laws, .. } => laws
                .iter()
                .map(|l| {
                    let n = l.den.len();
                    if n == 0 {
                        return 0;
                    }
                    outside(DMatrix::from_fn(n, n, |i, j| match i {
                        0 => -l.den[j],
                        _ if j + 1 == i => 1.0,
                        _ => 0.0,
                    }))
                })
                .sum(),
            LinearLaw::StateSpace { system, .. } => outside(system.a.clone()),
        }
    }

    /// The sampling period (s) of a sampled law, `None` for a continuous one.
    pub fn period(&self) -> Option<f64> {
        match self {
            LinearLaw::Continuous(_) => None,
            LinearLaw::Sampled { period, .. } | LinearLaw::StateSpace { period, .. } => Some(*period),
        }
    }
}

/// One axis' law as a transfer function in the usual form of python-control's and MATLAB's
/// `tf(num, den)` / `tf(num, den, dt)`: coefficients in descending powers of `s` (continuous)
/// or of `z` (sampled, numerator and denominator of the same length), A/V.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Transfer {
    /// Numerator.
    pub num: Vec<f64>,
    /// Denominator.
    pub den: Vec<f64>,
}

impl LinearLaw {
    /// Each axis' transfer ([`Transfer`]).
    pub fn transfers(&self) -> Vec<Transfer> {
        match self {
            LinearLaw::Continuous(pds) => pds
                .iter()
                .map(|g| Transfer { num: vec![-g.amp_gain * g.kd, -g.amp_gain * g.kp], den: vec![1.0] })
                .collect(),
            LinearLaw::Sampled { laws, .. } => laws
                .iter()
                .map(|l| {
                    // Σ n_i z^{−i} / (1 + Σ d_i z^{−i}), times z^L over z^L.
                    let len = l.num.len().max(l.den.len() + 1);
                    let mut num = l.num.clone();
                    num.resize(len, 0.0);
                    let mut den = vec![1.0];
                    den.extend(&l.den);
                    den.resize(len, 0.0);
                    Transfer { num, den }
                })
                .collect(),
            // Not one transfer per axis: the system itself ([`LinearLaw::StateSpace`]).
            LinearLaw::StateSpace { .. } => Vec::new(),
        }
    }

    /// `continuous` or `sampled`.
    pub fn form(&self) -> &'static str {
        match self {
            LinearLaw::Continuous(_) => "continuous",
            LinearLaw::Sampled { .. } | LinearLaw::StateSpace { .. } => "sampled",
        }
    }
}

/// The scene's law as a linear form, `None` where it has none (module doc).
pub fn of(scene: &Scene) -> Option<LinearLaw> {
    let c = &scene.controller;
    let designs = scene.plane_designs();
    if c.mode == ControlMode::Continuous {
        let gains = crate::run::plane_gains(scene).ok()?;
        let pds = (0..2 * designs.len())
            .map(|k| PlanePd {
                kp: gains[k / 2].kp,
                kd: gains[k / 2].kd,
                amp_gain: gains[k / 2].amp_gain_a_per_v,
                sensor_gain: designs[k / 2].constants.sensor_gain_v_per_m,
            })
            .collect();
        return Some(LinearLaw::Continuous(pds));
    }
    if !(c.mode == ControlMode::Sampled || c.cosim.command.is_none()) {
        return None;
    }
    if c.law == controller::state_space::LAW.name {
        let ss = controller::state_space::discrete(&scene.rotor_design(), &c.params).ok()?;
        let system = System { a: ss.a, b: ss.b, c: ss.c, d: ss.d };
        return Some(LinearLaw::StateSpace { system, period: c.period });
    }
    let mut laws = Vec::with_capacity(2 * designs.len());
    for d in &designs {
        if c.law == controller::transfer_function::LAW.name {
            // `b(z)/a(z)` in descending powers of `z`, `a₀ = 1`, `b` as long as `a`: in `z⁻¹`,
            // `(b₀ + b₁ z⁻¹ + …) / (1 + a₁ z⁻¹ + …)`, the form `AxisLaw` holds.
            let tf = controller::transfer_function::discrete(d, &c.params).ok()?;
            let law = AxisLaw { num: tf.b, den: tf.a[1..].to_vec(), sensor_gain: d.constants.sensor_gain_v_per_m };
            laws.push(law.clone());
            laws.push(law);
            continue;
        }
        let linear = controller::build_law(&c.law, d, &c.params).ok()?.linear()?;
        let pd = PlanePd {
            kp: linear.pd.kp,
            kd: linear.pd.kd,
            amp_gain: d.constants.amp_gain_a_per_v,
            sensor_gain: d.constants.sensor_gain_v_per_m,
        };
        let law = AxisLaw::pd(&pd, c.period, linear.filter);
        laws.push(law.clone());
        laws.push(law);
    }
    Some(LinearLaw::Sampled { laws, period: c.period })
}

/// The closed loop's state matrix of a discrete plant (current command in, sensor volts out,
/// its hold and delay states in) and a discrete law of every axis (volts in, command out), the
/// law's output fed to the plant as it is (`i = C_k x_k + D_k v`, the sign in the law, as
/// [`sensitivity`]'s `S = (I − P C)⁻¹`): the plant's states then the law's. `None` where the
/// loop has no solution for its commands (`I − D_k D_p` singular) or the sizes disagree.
pub fn closed_loop(plant: &System, law: &System) -> Option<DMatrix<f64>> {
    let (n, nk, m) = (plant.a.nrows(), law.a.nrows(), plant.b.ncols());
    if law.b.ncols() != plant.c.nrows() || law.c.nrows() != m {
        return None;
    }
    // i = M (D_k C_p x + C_k x_k), M = (I − D_k D_p)⁻¹; v = C_p x + D_p i.
    let inv = (DMatrix::<f64>::identity(m, m) - &law.d * &plant.d).try_inverse()?;
    let i_x = &inv * &law.d * &plant.c;
    let i_k = &inv * &law.c;
    let v_x = &plant.c + &plant.d * &i_x;
    let v_k = &plant.d * &i_k;
    let mut a = DMatrix::zeros(n + nk, n + nk);
    a.view_mut((0, 0), (n, n)).copy_from(&(&plant.a + &plant.b * &i_x));
    a.view_mut((0, n), (n, nk)).copy_from(&(&plant.b * &i_k));
    a.view_mut((n, 0), (nk, n)).copy_from(&(&law.b * &v_x));
    a.view_mut((n, n), (nk, nk)).copy_from(&(&law.a + &law.b * &v_k));
    Some(a)
}

/// `C (wI − A)⁻¹ B + D` at the complex frequency `w` (`s`, or `z` of a discrete system).
pub fn response(sys: &System, w: C64) -> DMatrix<C64> {
    let n = sys.a.nrows();
    let m =
        DMatrix::<C64>::from_fn(n, n, |i, j| if i == j { w - sys.a[(i, j)] } else { C64::new(-sys.a[(i, j)], 0.0) });
    let b = sys.b.map(|v| C64::new(v, 0.0));
    let nan = || DMatrix::from_element(n, b.ncols(), C64::new(f64::NAN, 0.0));
    let lu = m.clone().lu();
    let mut x = lu.solve(&b).unwrap_or_else(nan);
    // Two steps of iterative refinement: the LU's back substitution cancels where the position
    // follows from the velocity (`x = v / s` far above a mode: the planar axis loses 3e-12 at
    // 2.8 kHz); refined, the response is the exact rational arithmetic's to 1e-15.
    for _ in 0..2 {
        let r = &b - &m * &x;
        x += lu.solve(&r).unwrap_or_else(nan);
    }
    sys.c.map(|v| C64::new(v, 0.0)) * x + sys.d.map(|v| C64::new(v, 0.0))
}

/// The plant's response at `f_hz` (Hz) as the law sees it: the continuous system on `s = jω`
/// for a continuous law, the discrete one (its delay states in) on `z = e^{jωT}` for a sampled.
pub fn plant_at(law: &LinearLaw, continuous: &System, discrete: &System, f_hz: f64) -> DMatrix<C64> {
    let w = std::f64::consts::TAU * f_hz;
    match law.period() {
        None => response(continuous, C64::new(0.0, w)),
        Some(period) => response(discrete, C64::new(0.0, w * period).exp()),
    }
}

/// `S = (I − P C)⁻¹` at `f_hz` (Hz): `P` the plant's response (V/A), `C` the law's (A/V,
/// [`LinearLaw::matrix_at`]). Each axis' sensitivity is its diagonal entry.
pub fn sensitivity(law: &LinearLaw, continuous: &System, discrete: &System, f_hz: f64) -> DMatrix<C64> {
    let p = plant_at(law, continuous, discrete, f_hz);
    let m = p.nrows();
    let l = match law {
        LinearLaw::StateSpace { .. } => &p * law.matrix_at(f_hz),
        _ => {
            // Diagonal: each column scaled, as the product would but without its zero terms
            // (the same figures as before a law could couple the axes).
            let c = law.at(f_hz);
            DMatrix::from_fn(m, m, |i, j| p[(i, j)] * c[j])
        }
    };
    let i_minus_l = DMatrix::<C64>::identity(m, m) - l;
    i_minus_l.try_inverse().unwrap_or_else(|| DMatrix::from_element(m, m, C64::new(f64::NAN, 0.0)))
}
