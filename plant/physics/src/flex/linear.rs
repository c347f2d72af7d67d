//! The flexible machine linearised about the centred, levitated rotor (MODEL.md §13.7): its
//! open loop from the four AMB currents to the four sensor displacements (continuous, and
//! sampled under a zero-order hold), the closed loop with a continuous PD at each plane (its
//! whirl modes, labelled rigid or bending: `plant campbell`), and the closed loop with a sampled
//! law of each axis (its sensitivity `S = (I − L)⁻¹` and its poles: `plant assess`'s closed
//! form).
//!
//! **Open loop.** With the reduced coordinates `η` ([`super::reduce`]) and the AMBs' linear law
//! `F = k_i i + k_s Δ` at the AMB nodes (the nonlinear law has the same `k_i`, `k_s` at the
//! centre), the axes ordered `x_A, y_A, x_B, y_B`:
//!
//! ```text
//! η̈ + (D + Ω Gᵣ) η̇ + (Λ − Φ_aᵀ K_s Φ_a) η = Φ_aᵀ K_i i,      y = Φ_s η
//! ```
//!
//! `Φ_a`, `Φ_s` the basis' rows of each axis at its AMB node and at its sensor node, `K_s`,
//! `K_i` diagonal (each plane's `k_s`, `k_i`). The sensor reads `u = A_s y` (V).
//!
//! **Loop.** The excitation `E` enters where the sensor signal enters the controller, `v = u + E`
//! (ISO 14839-3, as [`crate`]'s planar closed form in the plant's `assess::closed_form`), and the
//! law of each axis is a transfer `i = C(·) v`: the continuous PD `C(s) = −A_a (k_p + k_d s)`, or
//! a sampled law `C(z)` (a PD with a backward difference behind an optional second-order
//! filter: `pd`, `pd_delay`, `pd_notch`) whose command is applied `d` ticks later and held. Then
//! `L = A_s P C` (4 × 4, `P` the open loop, `z^{−d}` with it when sampled) and `S = (I − L)⁻¹`;
//! the sensitivity an axis measures is `S`'s diagonal entry (the other axes' loops closed).
//! Sampled, `P(z) = C_y (zI − Φ)⁻¹ Γ` is the open loop discretised exactly (`Φ = e^{AT}`, `Γ`
//! from the matrix exponential of the augmented matrix, Van Loan).

use super::machine::Params;
use super::modes::{Linear, ModesError, Whirl};
use super::rotor::DOF_PER_NODE;
use nalgebra::{Complex, DMatrix, DVector};

type C64 = Complex<f64>;

/// Control axes: x_A, y_A, x_B, y_B.
pub const AXES: usize = 4;

/// The open loop of the flexible machine (module doc).
#[derive(Clone, Debug)]
pub struct OpenLoop {
    /// `Λ − Φ_aᵀ K_s Φ_a` (r × r).
    stiffness: DMatrix<f64>,
    /// `D` (r × r).
    damping: DMatrix<f64>,
    /// `Gᵣ` (r × r).
    gyroscopic: DMatrix<f64>,
    /// `Φ_aᵀ K_i` (r × 4).
    input: DMatrix<f64>,
    /// `Φ_s` (4 × r).
    output: DMatrix<f64>,
    /// `Φ_a` (4 × r): each axis' displacement at its AMB node (its rate, on `η̇`, is what an
    /// amplifier's back-EMF sees).
    actuator: DMatrix<f64>,
    /// Each node's `x`, `y` rows of the basis (for the whirl and the shape of a mode).
    node_xy: Vec<(DVector<f64>, DVector<f64>)>,
    /// Each node's axial position from the centre of mass (m).
    node_z: Vec<f64>,
    /// Half the AMB span (m).
    half_span: f64,
}

/// The open loop as a state-space system ([`OpenLoop::state_space`]).
#[derive(Clone, Debug, PartialEq)]
pub struct StateSpace {
    /// `A` (2r × 2r) on `x = [η, η̇]`.
    pub a: DMatrix<f64>,
    /// `B` (2r × 4): the AMB currents (A) in.
    pub b: DMatrix<f64>,
    /// `C` (4 × 2r): the sensor nodes' displacements (m) out.
    pub c: DMatrix<f64>,
    /// `C_a` (4 × 2r): the AMB nodes' displacements (m).
    pub actuator: DMatrix<f64>,
}

/// The PD of one bearing plane in volts: `i = −A_a (k_p v + k_d v̇)` on its sensor voltage `v`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanePd {
    /// Proportional gain (V/V).
    pub kp: f64,
    /// Derivative gain (s).
    pub kd: f64,
    /// Amplifier gain A_a (A/V).
    pub amp_gain: f64,
    /// Sensor gain A_s (V/m).
    pub sensor_gain: f64,
}

/// A sampled law of one axis around levitation, as a transfer in `q = z⁻¹` from the sensor
/// voltage to the current: `i = (n₀ + n₁ q + …) / (1 + d₁ q + …) v`.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisLaw {
    /// Numerator `n₀, n₁, …` (A/V).
    pub num: Vec<f64>,
    /// Denominator `d₁, d₂, …` (the leading 1 left out).
    pub den: Vec<f64>,
    /// Sensor gain A_s (V/m).
    pub sensor_gain: f64,
}

impl AxisLaw {
    /// The PD with a backward difference at period `period` (s): `i_k = −A_a (k_p v_k + k_d
    /// (v_k − v_{k−1}) / T)`, behind the filter `(b₀ + b₁ q + b₂ q²) / (1 + a₁ q + a₂ q²)` if any.
    pub fn pd(pd: &PlanePd, period: f64, filter: Option<([f64; 3], [f64; 2])>) -> Self {
        let a = pd.amp_gain;
        let mut num = vec![-a * (pd.kp + pd.kd / period), a * pd.kd / period];
        let mut den = Vec::new();
        if let Some((b, f)) = filter {
            let mut conv = vec![0.0; num.len() + 2];
            for (i, n) in num.iter().enumerate() {
                for (j, bj) in b.iter().enumerate() {
                    conv[i + j] += n * bj;
                }
            }
            num = conv;
            den = f.to_vec();
        }
        AxisLaw { num, den, sensor_gain: pd.sensor_gain }
    }

    /// `C(z)` at `z`.
    pub fn at(&self, z: C64) -> C64 {
        let q = z.inv();
        let poly = |c: &[f64], lead: Option<f64>| {
            let mut acc = C64::new(0.0, 0.0);
            let mut p = C64::new(1.0, 0.0);
            if let Some(l) = lead {
                acc += p * l;
                p *= q;
            }
            for v in c {
                acc += p * *v;
                p *= q;
            }
            acc
        };
        poly(&self.num, None) / poly(&self.den, Some(1.0))
    }

    /// A state-space realisation `w' = A w + B v`, `i = C w + D v` (observable canonical form,
    /// the direct form II transposed the laws run): `(A, B, C, D)` with `C = [1, 0, …]`.
    fn realisation(&self) -> (DMatrix<f64>, DVector<f64>, f64) {
        let n = self.num.len().saturating_sub(1).max(self.den.len());
        let num = |i: usize| self.num.get(i).copied().unwrap_or(0.0);
        let den = |i: usize| if i == 0 { 1.0 } else { self.den.get(i - 1).copied().unwrap_or(0.0) };
        let n0 = num(0);
        let mut a = DMatrix::zeros(n, n);
        let mut b = DVector::zeros(n);
        for i in 0..n {
            a[(i, 0)] = -den(i + 1);
            if i + 1 < n {
                a[(i, i + 1)] = 1.0;
            }
            b[i] = num(i + 1) - den(i + 1) * n0;
        }
        (a, b, n0)
    }
}

/// A sampled loop: the law of each axis, the period and the command delay.
#[derive(Clone, Debug)]
pub struct SampledLoop {
    /// Each axis' law, x_A, y_A, x_B, y_B.
    pub laws: [AxisLaw; AXES],
    /// Period T (s).
    pub period: f64,
    /// Command delay d (ticks).
    pub delay: u32,
}

/// A transfer `C (wI − A)⁻¹ B` (4 × 4) of the open loop: continuous (`A` the first-order
/// matrix, `w = s`) or sampled (`A = Φ`, `B = Γ`, `w = z`), with `A` reduced once to Hessenberg
/// form `A = Q H Qᵀ` so that each frequency costs a Hessenberg solve.
#[derive(Clone, Debug)]
pub struct Response {
    phi: DMatrix<f64>,
    gamma: DMatrix<f64>,
    out: DMatrix<f64>,
    h: DMatrix<f64>,
    qt_b: DMatrix<f64>,
    c_q: DMatrix<f64>,
}

/// What a mode is, from its shape: a rigid-body mode of the rotor on its bearings (cylindrical:
/// mostly translation; conical: mostly tilt) or a bending mode (its number, counted up the
/// frequencies in forward–backward pairs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeKind {
    /// Mostly translation.
    Cylindrical,
    /// Mostly tilt.
    Conical,
    /// The shaft bends: the n-th bending mode (1, 2, …).
    Bending(u32),
}

/// A whirl mode of the closed loop at a speed.
#[derive(Clone, Debug)]
pub struct LoopMode {
    /// What it is.
    pub kind: ModeKind,
    /// Its whirl.
    pub whirl: Whirl,
    /// Damped natural frequency (Hz).
    pub frequency_hz: f64,
    /// Damping ratio.
    pub damping_ratio: f64,
    /// Share of the mode's displacement (over the nodes) not on a straight line.
    pub bending_share: f64,
}

impl OpenLoop {
    /// The open loop of `p` (module doc).
    pub fn of(p: &Params) -> Self {
        let red = &*p.reduced;
        let r = red.size();
        let row = |node: usize, axis: usize| red.basis.row(DOF_PER_NODE * node + axis).transpose();
        let mut amb = DMatrix::zeros(AXES, r);
        let mut output = DMatrix::zeros(AXES, r);
        let (mut ks, mut ki) = ([0.0; AXES], [0.0; AXES]);
        for (i, plane) in p.machine.planes.iter().enumerate() {
            let c = &plane.params.loop_constants;
            for axis in 0..2 {
                let k = 2 * i + axis;
                amb.row_mut(k).copy_from(&row(p.nodes[i].amb, axis).transpose());
                output.row_mut(k).copy_from(&row(p.nodes[i].sensor, axis).transpose());
                ks[k] = c.ks_n_per_m;
                ki[k] = c.ki_n_per_a;
            }
        }
        let ks = DMatrix::from_diagonal(&DVector::from_row_slice(&ks));
        let stiffness = DMatrix::from_diagonal(&red.omega_sq) - amb.transpose() * ks * &amb;
        let input = amb.transpose() * DMatrix::from_diagonal(&DVector::from_row_slice(&ki));
        let nodes = p.z.len();
        let node_xy = (0..nodes).map(|k| (row(k, 0), row(k, 1))).collect();
        let [za, zb] = [0, 1].map(|i| p.z[p.nodes[i].amb]);
        OpenLoop {
            stiffness,
            damping: red.damping.clone(),
            gyroscopic: red.gyroscopic.clone(),
            input,
            output,
            actuator: amb,
            node_xy,
            node_z: p.z.clone(),
            half_span: 0.5 * (zb - za).abs(),
        }
    }

    /// Reduced coordinates r.
    pub fn size(&self) -> usize {
        self.stiffness.nrows()
    }

    /// The first-order matrix `A` of `[η, η̇]` at spin speed `speed` (rad/s), the loop open.
    fn state_matrix(&self, speed: f64) -> DMatrix<f64> {
        let r = self.size();
        let mut a = DMatrix::zeros(2 * r, 2 * r);
        a.view_mut((0, r), (r, r)).fill_with_identity();
        a.view_mut((r, 0), (r, r)).copy_from(&(-&self.stiffness));
        a.view_mut((r, r), (r, r)).copy_from(&(-(&self.damping + &self.gyroscopic * speed)));
        a
    }

    /// The open loop `P(s)` (m/A, 4 × 4) at spin speed `speed` (rad/s), ready for many `s`:
    /// [`OpenLoop::state_space`]'s matrices.
    pub fn continuous(&self, speed: f64) -> Response {
        let ss = self.state_space(speed);
        Response::new(ss.a, ss.b, ss.c)
    }

    /// The open loop at spin speed `speed` (rad/s) as a state-space system on `x = [η, η̇]`:
    /// `ẋ = A x + B i`, `y = C x` (the four AMB currents in A, the four sensor displacements in
    /// m), with the AMB nodes' displacements `C_a x` beside it. The one source of the continuous
    /// [`Response`] and of `plant linear`'s export.
    pub fn state_space(&self, speed: f64) -> StateSpace {
        let r = self.size();
        let mut b = DMatrix::zeros(2 * r, AXES);
        b.view_mut((r, 0), (r, AXES)).copy_from(&self.input);
        let mut c = DMatrix::zeros(AXES, 2 * r);
        c.view_mut((0, 0), (AXES, r)).copy_from(&self.output);
        let mut actuator = DMatrix::zeros(AXES, 2 * r);
        actuator.view_mut((0, 0), (AXES, r)).copy_from(&self.actuator);
        StateSpace { a: self.state_matrix(speed), b, c, actuator }
    }

    /// The open loop discretised under a zero-order hold of period `period` (s) at spin speed
    /// `speed` (rad/s): the exponential of `[[A, B], [0, 0]] T`.
    pub fn discretise(&self, speed: f64, period: f64) -> Response {
        let r = self.size();
        let n = 2 * r;
        let mut aug = DMatrix::zeros(n + AXES, n + AXES);
        aug.view_mut((0, 0), (n, n)).copy_from(&(self.state_matrix(speed) * period));
        aug.view_mut((r, n), (r, AXES)).copy_from(&(&self.input * period));
        let e = aug.exp();
        let mut out = DMatrix::zeros(AXES, n);
        out.view_mut((0, 0), (AXES, r)).copy_from(&self.output);
        Response::new(e.view((0, 0), (n, n)).into_owned(), e.view((0, n), (n, AXES)).into_owned(), out)
    }

    /// The closed loop with the continuous PD `pd` at each plane, as a linear second-order system
    /// `η̈ + (C + Ω G) η̇ + K η = 0` (its whirl modes through [`Linear`]).
    pub fn with_pd(&self, pd: &[PlanePd; 2]) -> Linear {
        let (p, d) = self.pd_matrices(pd);
        let r = self.size();
        Linear {
            mass: DMatrix::identity(r, r),
            stiffness: &self.stiffness + &self.input * p * &self.output,
            damping: &self.damping + &self.input * d * &self.output,
            gyroscopic: self.gyroscopic.clone(),
            node_xy: self.node_xy.clone(),
        }
    }

    /// `diag(A_a k_p A_s)`, `diag(A_a k_d A_s)` per axis.
    fn pd_matrices(&self, pd: &[PlanePd; 2]) -> (DMatrix<f64>, DMatrix<f64>) {
        let axis = |f: &dyn Fn(&PlanePd) -> f64| {
            DMatrix::from_diagonal(&DVector::from_fn(AXES, |k, _| {
                f(&pd[k / 2]) * pd[k / 2].amp_gain * pd[k / 2].sensor_gain
            }))
        };
        (axis(&|g| g.kp), axis(&|g| g.kd))
    }

    /// The closed loop's whirl modes with the continuous PD `pd` at spin speed `speed` (rad/s),
    /// those below `f_max_hz`, ascending, each labelled by its shape ([`ModeKind`]): the mode's
    /// node displacements fitted by a straight line, a mode with more than half of its
    /// displacement off the line bends; of the others, the two of each whirl with more
    /// translation at the centre of mass against tilt over the half span are cylindrical.
    pub fn whirl_modes(&self, pd: &[PlanePd; 2], speed: f64, f_max_hz: f64) -> Result<Vec<LoopMode>, ModesError> {
        let prepared = self.with_pd(pd).prepare()?;
        let mut count = 8;
        let pairs = loop {
            let pairs = prepared.modes_with_orbits(speed, count)?;
            let top = pairs.last().map_or(0.0, |(m, _)| m.wd / std::f64::consts::TAU);
            if pairs.len() < count || top > f_max_hz || count >= 2 * self.size() {
                break pairs;
            }
            count *= 2;
        };
        let mut modes: Vec<(LoopMode, f64)> = pairs
            .into_iter()
            .filter(|(m, _)| m.wd / std::f64::consts::TAU <= f_max_hz)
            .map(|(m, orbits)| {
                let (bending, translation) = self.shape(&orbits);
                let mode = LoopMode {
                    kind: ModeKind::Bending(0),
                    whirl: m.whirl,
                    frequency_hz: m.wd / std::f64::consts::TAU,
                    damping_ratio: m.damping_ratio,
                    bending_share: bending,
                };
                (mode, translation)
            })
            .collect();
        // Rigid-body modes: the four with the least bending (two of each whirl at speed).
        let mut order: Vec<usize> = (0..modes.len()).collect();
        order.sort_by(|&a, &b| modes[a].0.bending_share.total_cmp(&modes[b].0.bending_share));
        let rigid: Vec<usize> = order.iter().copied().filter(|&i| modes[i].0.bending_share < 0.5).take(4).collect();
        let mut by_translation = rigid.clone();
        by_translation.sort_by(|&a, &b| modes[b].1.total_cmp(&modes[a].1));
        for (rank, &i) in by_translation.iter().enumerate() {
            modes[i].0.kind = if rank < 2 { ModeKind::Cylindrical } else { ModeKind::Conical };
        }
        let mut n = 0;
        for (i, m) in modes.iter_mut().enumerate() {
            if !rigid.contains(&i) {
                m.0.kind = ModeKind::Bending(n / 2 + 1);
                n += 1;
            }
        }
        Ok(modes.into_iter().map(|(m, _)| m).collect())
    }

    /// A mode's bending share and its translation against tilt, from its node orbits.
    fn shape(&self, orbits: &[(C64, C64)]) -> (f64, f64) {
        // Least squares of each axis' amplitudes on [1, z].
        let n = self.node_z.len() as f64;
        let (sz, szz) = self.node_z.iter().fold((0.0, 0.0), |(a, b), z| (a + z, b + z * z));
        let det = n * szz - sz * sz;
        let (mut total, mut residual, mut translation, mut tilt) = (0.0, 0.0, 0.0, 0.0);
        for axis in 0..2 {
            let v: Vec<C64> = orbits.iter().map(|o| if axis == 0 { o.0 } else { o.1 }).collect();
            let s1: C64 = v.iter().sum();
            let s2: C64 = v.iter().zip(&self.node_z).map(|(x, z)| x * *z).sum();
            let c0 = (s1 * szz - s2 * sz) / det;
            let c1 = (s2 * n - s1 * sz) / det;
            for (x, z) in v.iter().zip(&self.node_z) {
                total += x.norm_sqr();
                residual += (x - c0 - c1 * *z).norm_sqr();
            }
            translation += c0.norm_sqr();
            tilt += (c1 * self.half_span).norm_sqr();
        }
        let bending = if total > 0.0 { residual / total } else { 0.0 };
        (bending, translation / tilt.max(1e-300))
    }

    /// The continuous PD's closed loop is stable at spin speed `speed`: the largest real part
    /// of its eigenvalues (1/s), negative when stable.
    pub fn abscissa_continuous(&self, pd: &[PlanePd; 2], speed: f64) -> f64 {
        let lin = self.with_pd(pd);
        let r = self.size();
        let mut a = DMatrix::zeros(2 * r, 2 * r);
        a.view_mut((0, r), (r, r)).fill_with_identity();
        a.view_mut((r, 0), (r, r)).copy_from(&(-&lin.stiffness));
        a.view_mut((r, r), (r, r)).copy_from(&(-(&lin.damping + &lin.gyroscopic * speed)));
        a.complex_eigenvalues().iter().map(|l| l.re).fold(f64::NEG_INFINITY, f64::max)
    }
}

/// `S = (I − L)⁻¹` with `L = diag(A_s) P diag(C)`.
fn sensitivity_of(p: &DMatrix<C64>, sensor: &DVector<C64>, law: &DVector<C64>) -> DMatrix<C64> {
    let mut l = p.clone();
    for i in 0..AXES {
        for j in 0..AXES {
            l[(i, j)] = sensor[i] * p[(i, j)] * law[j];
        }
    }
    let m = DMatrix::<C64>::identity(AXES, AXES) - l;
    m.try_inverse().unwrap_or_else(|| DMatrix::from_element(AXES, AXES, C64::new(f64::NAN, 0.0)))
}

impl Response {
    fn new(a: DMatrix<f64>, b: DMatrix<f64>, c: DMatrix<f64>) -> Self {
        let (q, h) = a.clone().hessenberg().unpack();
        let qt_b = q.transpose() * &b;
        let c_q = &c * &q;
        Response { phi: a, gamma: b, out: c, h, qt_b, c_q }
    }

    /// `P(w)` (m/A, 4 × 4): `C Q (wI − H)⁻¹ Qᵀ B`, by Gaussian elimination on the Hessenberg
    /// matrix (pivoting between neighbouring rows).
    pub fn at(&self, w: C64) -> DMatrix<C64> {
        let n = self.h.nrows();
        let mut m: Vec<C64> = (0..n * n)
            .map(|k| {
                let (i, j) = (k / n, k % n);
                C64::new(-self.h[(i, j)], 0.0) + if i == j { w } else { C64::new(0.0, 0.0) }
            })
            .collect();
        let mut x: Vec<C64> = (0..n * AXES).map(|k| C64::new(self.qt_b[(k / AXES, k % AXES)], 0.0)).collect();
        for k in 0..n {
            if k + 1 < n && m[(k + 1) * n + k].norm() > m[k * n + k].norm() {
                for c in k..n {
                    m.swap(k * n + c, (k + 1) * n + c);
                }
                for c in 0..AXES {
                    x.swap(k * AXES + c, (k + 1) * AXES + c);
                }
            }
            if k + 1 < n {
                let f = m[(k + 1) * n + k] / m[k * n + k];
                if f.norm() != 0.0 {
                    for c in k..n {
                        let v = m[k * n + c];
                        m[(k + 1) * n + c] -= f * v;
                    }
                    for c in 0..AXES {
                        let v = x[k * AXES + c];
                        x[(k + 1) * AXES + c] -= f * v;
                    }
                }
            }
        }
        for i in (0..n).rev() {
            for c in 0..AXES {
                let mut acc = x[i * AXES + c];
                for j in i + 1..n {
                    acc -= m[i * n + j] * x[j * AXES + c];
                }
                x[i * AXES + c] = acc / m[i * n + i];
            }
        }
        DMatrix::from_fn(AXES, AXES, |i, c| (0..n).map(|k| x[k * AXES + c] * self.c_q[(i, k)]).sum())
    }

    /// The continuous PD's `S` (4 × 4) at `f_hz` (Hz), on a continuous response.
    pub fn sensitivity_continuous(&self, pd: &[PlanePd; 2], f_hz: f64) -> DMatrix<C64> {
        let s = C64::new(0.0, std::f64::consts::TAU * f_hz);
        let p = self.at(s);
        let law = DVector::from_fn(AXES, |k, _| {
            let g = &pd[k / 2];
            -(C64::new(g.kp, 0.0) + s * g.kd) * g.amp_gain
        });
        let gains = DVector::from_fn(AXES, |k, _| C64::new(pd[k / 2].sensor_gain, 0.0));
        sensitivity_of(&p, &gains, &law)
    }

    /// The sampled loop's `S` (4 × 4) at `f_hz` (Hz).
    pub fn sensitivity(&self, lp: &SampledLoop, f_hz: f64) -> DMatrix<C64> {
        let z = C64::new(0.0, std::f64::consts::TAU * f_hz * lp.period).exp();
        let p = self.at(z);
        let delay = z.powi(-(lp.delay as i32));
        let law = DVector::from_fn(AXES, |k, _| lp.laws[k].at(z) * delay);
        let gains = DVector::from_fn(AXES, |k, _| C64::new(lp.laws[k].sensor_gain, 0.0));
        sensitivity_of(&p, &gains, &law)
    }

    /// The sampled closed loop's spectral radius: the largest `|z|` of its poles (plant, law
    /// states, delay line), below 1 when stable.
    pub fn spectral_radius(&self, lp: &SampledLoop) -> f64 {
        self.poles(lp).iter().map(|z| z.norm()).fold(0.0, f64::max)
    }

    /// The least stable pole of the sampled closed loop as `(|z|, its frequency arg z / 2πT in
    /// Hz)`.
    pub fn least_stable(&self, lp: &SampledLoop) -> (f64, f64) {
        let z = self.poles(lp).into_iter().max_by(|a, b| a.norm().total_cmp(&b.norm())).unwrap_or_default();
        (z.norm(), z.arg().abs() / (std::f64::consts::TAU * lp.period))
    }

    /// The sampled closed loop's poles (plant, law states, delay line).
    pub fn poles(&self, lp: &SampledLoop) -> Vec<C64> {
        let n = self.phi.nrows();
        let real: Vec<_> = lp.laws.iter().map(AxisLaw::realisation).collect();
        let law_states: usize = real.iter().map(|(a, _, _)| a.nrows()).sum();
        let d = lp.delay as usize;
        let size = n + law_states + AXES * d;
        let mut m = DMatrix::<f64>::zeros(size, size);
        // The command c = Cw w + Dv v, v = A_s C_y x: rows of c over the state.
        let mut command = DMatrix::<f64>::zeros(AXES, size);
        let mut offset = n;
        for (k, ((a, b, d0), law)) in real.iter().zip(&lp.laws).enumerate() {
            let ns = a.nrows();
            // The sensor voltage of axis k: A_s (C_y x)_k.
            let v_row = self.out.row(k) * law.sensor_gain;
            // w' = A w + B v
            m.view_mut((offset, offset), (ns, ns)).copy_from(a);
            for i in 0..ns {
                for c in 0..n {
                    m[(offset + i, c)] += b[i] * v_row[c];
                }
            }
            // c = w[0] + D v
            if ns > 0 {
                command[(k, offset)] = 1.0;
            }
            for c in 0..n {
                command[(k, c)] += d0 * v_row[c];
            }
            offset += ns;
        }
        // The plant: x' = Φ x + Γ i, i = c (d = 0) or the delay line's last.
        m.view_mut((0, 0), (n, n)).copy_from(&self.phi);
        if d == 0 {
            let add = &self.gamma * &command;
            m.view_mut((0, 0), (n, size)).zip_apply(&add, |a, b| *a += b);
        } else {
            let q = |j: usize| offset + AXES * j;
            m.view_mut((0, q(d - 1)), (n, AXES)).copy_from(&self.gamma);
            m.view_mut((q(0), 0), (AXES, size)).copy_from(&command);
            for j in 1..d {
                m.view_mut((q(j), q(j - 1)), (AXES, AXES)).fill_with_identity();
            }
        }
        m.complex_eigenvalues().iter().copied().collect()
    }
}
