//! Whirl modes of a linear rotor `M q̈ + (C + Ω G) q̇ + K q = 0` at a spin speed, and the
//! Campbell diagram (MODEL.md §13.4): as ROSS's `run_modal` computes them (eigenvalues of the
//! first-order system, those with `|λ| > 0.1` rad/s and `Im λ > 0`, in ascending `Im λ`), with
//! the whirl of each mode from its shape.
//!
//! Works on the full finite-element matrices and on a reduced model's alike ([`Linear`]).

use nalgebra::{Complex, DMatrix, DVector};

type C64 = Complex<f64>;

/// A linear second-order system `M q̈ + (C + Ω G) q̇ + K q = 0` and which of its coordinates
/// are the nodes' `x`, `y` (for the whirl).
#[derive(Clone, Debug)]
pub struct Linear {
    /// Mass M.
    pub mass: DMatrix<f64>,
    /// Stiffness K.
    pub stiffness: DMatrix<f64>,
    /// Damping C.
    pub damping: DMatrix<f64>,
    /// Gyroscopic G.
    pub gyroscopic: DMatrix<f64>,
    /// Rows mapping the coordinates to each node's `(x, y)`: `x_n = X_n · q`, `y_n = Y_n · q`
    /// (for the full model, unit rows; for a reduced one, the basis' rows).
    pub node_xy: Vec<(DVector<f64>, DVector<f64>)>,
}

/// The sense of a mode's whirl.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Whirl {
    /// Every node whirls with the spin.
    Forward,
    /// Every node whirls against the spin.
    Backward,
    /// Some nodes each way.
    Mixed,
}

/// One mode at a speed.
#[derive(Clone, Debug)]
pub struct Mode {
    /// Eigenvalue λ (1/s).
    pub eigenvalue: C64,
    /// Natural frequency `|λ|` (rad/s), ROSS's `wn`.
    pub wn: f64,
    /// Damped natural frequency `Im λ` (rad/s), ROSS's `wd`.
    pub wd: f64,
    /// Damping ratio `−Re λ / |λ|`.
    pub damping_ratio: f64,
    /// Whirl sense.
    pub whirl: Whirl,
}

/// Why the modes could not be computed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ModesError {
    /// The mass matrix is singular.
    #[error("the mass matrix is singular")]
    SingularMass,
    /// The eigenvalue solver did not converge.
    #[error("the eigenvalues of the rotor did not converge at {speed_rad_s} rad/s")]
    NoConvergence {
        /// The spin speed (rad/s).
        speed_rad_s: f64,
    },
}

/// A [`Linear`] system prepared for its eigenvalues: in the coordinates of the undamped modes
/// of its symmetric parts (`Φᵀ M_s Φ = I`, `Φᵀ K_s Φ = diag(ω²)`), the displacements scaled by
/// `w_i = max(ω_i, 1 rad/s)`, so that the first-order matrix is balanced (entries of the order
/// of the frequencies rather than `ω²`).
#[derive(Clone, Debug)]
pub struct Prepared {
    /// Φ.
    phi: DMatrix<f64>,
    /// `M̃⁻¹ K̃ W⁻¹` with `M̃ = Φᵀ M Φ`, `K̃ = Φᵀ K Φ`.
    stiffness: DMatrix<f64>,
    /// `M̃⁻¹ Φᵀ`: applied to `(C + Ω G) Φ`.
    minv_phi_t: DMatrix<f64>,
    /// `Φᵀ C Φ`, `Φᵀ G Φ` premultiplied by `M̃⁻¹`.
    damping: DMatrix<f64>,
    gyroscopic: DMatrix<f64>,
    /// The scale `w_i`.
    scale: DVector<f64>,
    /// The node rows in the scaled modal coordinates: `x_n = X̃_n · z₁`.
    node_xy: Vec<(DVector<f64>, DVector<f64>)>,
}

impl Linear {
    /// Prepares the system for [`Prepared::modes`] (the undamped modes once for all speeds).
    pub fn prepare(&self) -> Result<Prepared, ModesError> {
        let n = self.mass.nrows();
        let sym = |m: &DMatrix<f64>| (m + m.transpose()) * 0.5;
        let l = sym(&self.mass).cholesky().ok_or(ModesError::SingularMass)?.l();
        let l_inv = l.try_inverse().ok_or(ModesError::SingularMass)?;
        let s = &l_inv * sym(&self.stiffness) * l_inv.transpose();
        let eig = sym(&s).symmetric_eigen();
        let phi = l_inv.transpose() * &eig.eigenvectors;
        let scale = DVector::from_iterator(n, eig.eigenvalues.iter().map(|v| v.max(0.0).sqrt().max(1.0)));
        let mt = phi.transpose() * &self.mass * &phi;
        let mt_inv = mt.try_inverse().ok_or(ModesError::SingularMass)?;
        let mut stiffness = &mt_inv * (phi.transpose() * &self.stiffness * &phi);
        for j in 0..n {
            let w = scale[j];
            stiffness.column_mut(j).unscale_mut(w);
        }
        let minv_phi_t = &mt_inv * phi.transpose();
        let damping = &minv_phi_t * &self.damping * &phi;
        let gyroscopic = &minv_phi_t * &self.gyroscopic * &phi;
        let node_xy = self
            .node_xy
            .iter()
            .map(|(rx, ry)| {
                let f = |r: &DVector<f64>| (phi.transpose() * r).component_div(&scale);
                (f(rx), f(ry))
            })
            .collect();
        Ok(Prepared { phi, stiffness, minv_phi_t, damping, gyroscopic, scale, node_xy })
    }

    /// The lowest `count` modes at spin speed `speed` (rad/s), in ascending `wd` (fewer if the
    /// system has fewer). Prepares the system each call: for many speeds, [`Linear::prepare`]
    /// once and call [`Prepared::modes`].
    pub fn modes(&self, speed: f64, count: usize) -> Result<Vec<Mode>, ModesError> {
        self.prepare()?.modes(speed, count)
    }

    /// The Campbell diagram: the lowest `count` modes at each speed of `speeds` (rad/s).
    pub fn campbell(&self, speeds: &[f64], count: usize) -> Result<Vec<Vec<Mode>>, ModesError> {
        let p = self.prepare()?;
        speeds.iter().map(|&w| p.modes(w, count)).collect()
    }

    /// The full model of `m` (the node rows are unit rows).
    pub fn full(m: &super::rotor::Matrices) -> Self {
        let n = m.mass.nrows();
        let unit = |i: usize| {
            let mut v = DVector::zeros(n);
            v[i] = 1.0;
            v
        };
        let node_xy = (0..n / super::rotor::DOF_PER_NODE).map(|k| (unit(4 * k), unit(4 * k + 1))).collect();
        Linear {
            mass: m.mass.clone(),
            stiffness: m.stiffness.clone(),
            damping: m.damping.clone(),
            gyroscopic: m.gyroscopic.clone(),
            node_xy,
        }
    }
}

/// An eigenvalue with its first-order eigenvector, where known.
type Pair = (C64, Option<DVector<C64>>);

/// A mode with each node's orbit `(X, Y)`.
pub type ModeOrbits = (Mode, Vec<(C64, C64)>);

/// The shift of the shift-and-invert iteration (rad/s), as ROSS's (`sigma = 1`).
const SHIFT: f64 = 1.0;

impl Prepared {
    /// The first-order matrix at `speed`: state `z = (W η, η̇)`,
    /// `ż = [[0, W], [−M̃⁻¹K̃W⁻¹, −M̃⁻¹(C̃ + Ω G̃)]] z`.
    pub fn state_matrix(&self, speed: f64) -> DMatrix<f64> {
        let n = self.scale.len();
        let mut a = DMatrix::zeros(2 * n, 2 * n);
        for i in 0..n {
            a[(i, n + i)] = self.scale[i];
        }
        a.view_mut((n, 0), (n, n)).copy_from(&(-&self.stiffness));
        a.view_mut((n, n), (n, n)).copy_from(&(-(&self.damping + &self.gyroscopic * speed)));
        a
    }

    /// The lowest `count` modes at spin speed `speed` (rad/s), in ascending `wd`: the
    /// eigenvalues with `|λ| > 0.1` rad/s and `Im λ > 0`, found by shift-and-invert Arnoldi
    /// about 1 rad/s (as ROSS's ARPACK call), every one checked by its residual; the dense
    /// eigenvalues of the whole matrix when the iteration does not converge.
    pub fn modes(&self, speed: f64, count: usize) -> Result<Vec<Mode>, ModesError> {
        Ok(self.finish(self.pairs(speed, count)?, count))
    }

    /// [`Prepared::modes`] with each mode's node orbits: the complex amplitudes `(X, Y)` of
    /// each node's `x`, `y` (`Re((X, Y) e^{jωt})`), in the order of the system's `node_xy`
    /// (empty when the mode's vector is not known).
    pub fn modes_with_orbits(&self, speed: f64, count: usize) -> Result<Vec<ModeOrbits>, ModesError> {
        let mut pairs = self.pairs(speed, count)?;
        pairs.sort_by(|x, y| x.0.im.total_cmp(&y.0.im).then(x.0.norm().total_cmp(&y.0.norm())));
        pairs.truncate(count);
        let orbits: Vec<Vec<(C64, C64)>> =
            pairs.iter().map(|(_, v)| v.as_ref().map_or_else(Vec::new, |v| self.orbits(v))).collect();
        Ok(self.finish(pairs, count).into_iter().zip(orbits).collect())
    }

    /// The eigenpairs at `speed`: by the Krylov iteration, or the dense eigenvalues.
    fn pairs(&self, speed: f64, count: usize) -> Result<Vec<Pair>, ModesError> {
        let a = self.state_matrix(speed);
        let size = a.nrows();
        let mut dim = (3 * count + 30).min(size);
        loop {
            if let Some(pairs) = self.arnoldi(&a, dim, count) {
                return Ok(pairs);
            }
            if dim == size {
                break;
            }
            dim = (2 * dim).min(size);
        }
        self.dense_pairs(speed)
    }

    /// The same from the dense eigenvalues of the whole first-order matrix (slower; the
    /// reference the Arnoldi iteration is tested against).
    pub fn modes_dense(&self, speed: f64, count: usize) -> Result<Vec<Mode>, ModesError> {
        Ok(self.finish(self.dense_pairs(speed)?, count))
    }

    fn dense_pairs(&self, speed: f64) -> Result<Vec<Pair>, ModesError> {
        let a = self.state_matrix(speed);
        let values = a.clone().complex_eigenvalues();
        if values.iter().any(|v| !(v.re.is_finite() && v.im.is_finite())) {
            return Err(ModesError::NoConvergence { speed_rad_s: speed });
        }
        let ac = a.map(|v| C64::new(v, 0.0));
        let pairs = values
            .iter()
            .filter(|v| v.norm() > 0.1 && v.im > 0.0)
            .map(|&lambda| (lambda, null_vector(&ac, lambda)))
            .collect();
        Ok(pairs)
    }

    fn finish(&self, mut pairs: Vec<(C64, Option<DVector<C64>>)>, count: usize) -> Vec<Mode> {
        pairs.sort_by(|x, y| x.0.im.total_cmp(&y.0.im).then(x.0.norm().total_cmp(&y.0.norm())));
        pairs.truncate(count);
        pairs
            .into_iter()
            .map(|(lambda, v)| Mode {
                eigenvalue: lambda,
                wn: lambda.norm(),
                wd: lambda.im,
                damping_ratio: -lambda.re / lambda.norm(),
                whirl: v.map_or(Whirl::Mixed, |v| self.whirl(&v)),
            })
            .collect()
    }

    /// Shift-and-invert block Krylov iteration (two start vectors, so that a double eigenvalue,
    /// as an isotropic rotor's at rest, shows both copies) of dimension `dim` on `a`, with a
    /// Rayleigh–Ritz step: the wanted eigenpairs (`|λ| > 0.1`, `Im λ > 0`) whose residual
    /// `‖(A − σ)⁻¹ x − θ x‖ < 10⁻⁸ |θ|` (the balanced matrix of an undamped rotor is
    /// skew-symmetric, so its eigenvalues are as accurate as that), none beyond the nearest unconverged one; `None` unless
    /// at least `count`. The loops are on plain slices: this runs in the tests' unoptimised builds
    /// too.
    fn arnoldi(&self, a: &DMatrix<f64>, dim: usize, count: usize) -> Option<Vec<(C64, Option<DVector<C64>>)>> {
        let size = a.nrows();
        let mut shifted: Vec<f64> = (0..size * size).map(|k| a[(k / size, k % size)]).collect();
        for i in 0..size {
            shifted[i * size + i] -= SHIFT;
        }
        let lu = DenseLu::new(shifted, size)?;
        let mut basis: Vec<Vec<f64>> = Vec::with_capacity(dim);
        let mut images: Vec<Vec<f64>> = Vec::with_capacity(dim);
        let push = |basis: &mut Vec<Vec<f64>>, mut w: Vec<f64>| {
            let before = dot(&w, &w).sqrt();
            for _ in 0..2 {
                for v in basis.iter() {
                    let c = dot(v, &w);
                    for (wk, vk) in w.iter_mut().zip(v) {
                        *wk -= c * vk;
                    }
                }
            }
            let norm = dot(&w, &w).sqrt();
            if norm > 1e-12 * before {
                basis.push(w.iter().map(|x| x / norm).collect());
            }
        };
        push(&mut basis, (0..size).map(|i| 1.0 + 0.5 * ((i as f64) * 0.731).sin()).collect());
        push(&mut basis, (0..size).map(|i| ((i as f64) * 1.913 + 0.3).cos()).collect());
        let mut j = 0;
        while j < basis.len() {
            let w = lu.solve(&basis[j]);
            if basis.len() < dim {
                push(&mut basis, w.clone());
            }
            images.push(w);
            j += 1;
        }
        let m = basis.len();
        // Block Hessenberg: the image of basis vector k lies in the span of the first k + 3 (two
        // start vectors), so the entries below that band are zero but for round-off.
        let h = DMatrix::from_fn(m, m, |i, k| if i > k + 2 { 0.0 } else { dot(&basis[i], &images[k]) });
        let thetas = h.clone().complex_eigenvalues();
        let shift = C64::new(SHIFT, 0.0);
        let mut found = Vec::new();
        let mut converged_radius = f64::INFINITY;
        for theta in thetas.iter() {
            if theta.norm() <= 1e-300 || theta.norm().is_nan() {
                continue;
            }
            let lambda = shift + C64::new(1.0, 0.0) / theta;
            let y = dense_null_vector(&h, *theta)?;
            // x = V y and the residual W y − θ V y.
            let mut x = vec![C64::new(0.0, 0.0); size];
            let mut r = vec![C64::new(0.0, 0.0); size];
            for k in 0..m {
                for i in 0..size {
                    x[i] += y[k] * basis[k][i];
                    r[i] += y[k] * images[k][i];
                }
            }
            let residual =
                x.iter().zip(&r).map(|(xi, ri)| (*ri - *theta * *xi).norm_sqr()).sum::<f64>().sqrt() / theta.norm();
            if m < size && residual > 1e-8 {
                converged_radius = converged_radius.min((lambda - shift).norm());
                continue;
            }
            if lambda.norm() > 0.1 && lambda.im > 0.0 {
                found.push((lambda, Some(DVector::from_vec(x))));
            }
        }
        found.retain(|(l, _)| (l - shift).norm() < converged_radius);
        found.sort_by(|x, y| x.0.im.total_cmp(&y.0.im));
        if found.len() < count && m < size {
            return None;
        }
        Some(found)
    }

    /// The whirl of the mode with first-order eigenvector `z = (W η, η̇)`: a node whirls forward
    /// when `Im(X̄ Y) < 0` (its orbit `Re((X, Y) e^{jωt})` turns from +x towards +y, the spin's
    /// sense). Nodes with less than 1 % of the largest amplitude do not vote.
    fn whirl(&self, z: &DVector<C64>) -> Whirl {
        let orbits = self.orbits(z);
        let largest = orbits.iter().map(|(x, y)| x.norm_sqr() + y.norm_sqr()).fold(0.0, f64::max);
        let (mut fw, mut bw) = (0, 0);
        for (x, y) in &orbits {
            if x.norm_sqr() + y.norm_sqr() < 1e-4 * largest {
                continue;
            }
            if (x.conj() * y).im < 0.0 {
                fw += 1;
            } else {
                bw += 1;
            }
        }
        match (fw, bw) {
            (_, 0) => Whirl::Forward,
            (0, _) => Whirl::Backward,
            _ => Whirl::Mixed,
        }
    }

    /// Each node's `(X, Y)` in the mode of first-order eigenvector `z = (W η, η̇)`.
    fn orbits(&self, z: &DVector<C64>) -> Vec<(C64, C64)> {
        let n = self.scale.len();
        let top = z.rows(0, n);
        self.node_xy
            .iter()
            .map(|(rx, ry)| {
                let dot = |r: &DVector<f64>| r.iter().zip(top.iter()).map(|(a, b)| *b * *a).sum::<C64>();
                (dot(rx), dot(ry))
            })
            .collect()
    }

    /// The modal matrix Φ the prepared coordinates are built on.
    pub fn basis(&self) -> &DMatrix<f64> {
        &self.phi
    }

    /// `M̃⁻¹ Φᵀ`.
    pub fn projection(&self) -> &DMatrix<f64> {
        &self.minv_phi_t
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// A dense real LU factorisation with partial pivoting, row-major, on a plain vector.
struct DenseLu {
    n: usize,
    a: Vec<f64>,
    pivots: Vec<usize>,
}

impl DenseLu {
    fn new(mut a: Vec<f64>, n: usize) -> Option<Self> {
        let mut pivots = Vec::with_capacity(n);
        for k in 0..n {
            let p = (k..n).max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs()))?;
            if a[p * n + k] == 0.0 {
                return None;
            }
            if p != k {
                for c in 0..n {
                    a.swap(k * n + c, p * n + c);
                }
            }
            pivots.push(p);
            let pivot = a[k * n + k];
            let (top, rest) = a.split_at_mut((k + 1) * n);
            let row_k = &top[k * n..];
            for i in 0..n - k - 1 {
                let row = &mut rest[i * n..(i + 1) * n];
                let f = row[k] / pivot;
                row[k] = f;
                if f != 0.0 {
                    for c in k + 1..n {
                        row[c] -= f * row_k[c];
                    }
                }
            }
        }
        Some(DenseLu { n, a, pivots })
    }

    fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut x = b.to_vec();
        for (k, &p) in self.pivots.iter().enumerate() {
            x.swap(k, p);
        }
        for i in 0..n {
            let row = &self.a[i * n..i * n + i];
            let s: f64 = row.iter().zip(&x[..i]).map(|(a, b)| a * b).sum();
            x[i] -= s;
        }
        for i in (0..n).rev() {
            let row = &self.a[i * n + i + 1..(i + 1) * n];
            let s: f64 = row.iter().zip(&x[i + 1..]).map(|(a, b)| a * b).sum();
            x[i] = (x[i] - s) / self.a[i * n + i];
        }
        x
    }
}

/// A null vector of `H − θ I` for a small real `h`, zero below its second subdiagonal (block
/// Hessenberg): one step of inverse iteration from a full vector (Gaussian elimination with
/// partial pivoting within the band, O(m²), on plain vectors), normalised.
fn dense_null_vector(h: &DMatrix<f64>, theta: C64) -> Option<Vec<C64>> {
    let m = h.nrows();
    let mu = theta * C64::new(1.0 + 1e-12, 1e-12);
    let mut a: Vec<C64> = (0..m * m)
        .map(|k| {
            let (i, j) = (k / m, k % m);
            C64::new(h[(i, j)], 0.0) - if i == j { mu } else { C64::new(0.0, 0.0) }
        })
        .collect();
    let mut b = vec![C64::new(1.0, 0.0); m];
    for k in 0..m {
        let last = (k + 3).min(m);
        let p = (k..last).max_by(|&i, &j| a[i * m + k].norm().total_cmp(&a[j * m + k].norm()))?;
        if p != k {
            for c in 0..m {
                a.swap(k * m + c, p * m + c);
            }
            b.swap(k, p);
        }
        let pivot = a[k * m + k];
        if pivot.norm() == 0.0 {
            continue;
        }
        for i in k + 1..last {
            let f = a[i * m + k] / pivot;
            if f.norm() != 0.0 {
                for c in k..m {
                    let v = a[k * m + c];
                    a[i * m + c] -= f * v;
                }
                let v = b[k];
                b[i] -= f * v;
            }
        }
    }
    let mut x = vec![C64::new(0.0, 0.0); m];
    for i in (0..m).rev() {
        let mut s = b[i];
        for c in i + 1..m {
            s -= a[i * m + c] * x[c];
        }
        let d = if a[i * m + i].norm() > 0.0 { a[i * m + i] } else { C64::new(1e-300, 0.0) };
        x[i] = s / d;
    }
    let norm = x.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt();
    if !(norm.is_finite() && norm > 0.0) {
        return None;
    }
    Some(x.into_iter().map(|v| v / norm).collect())
}

/// A null vector of `a − λ I` by inverse iteration (shifted a little off λ).
fn null_vector(a: &DMatrix<C64>, lambda: C64) -> Option<DVector<C64>> {
    let n = a.nrows();
    let mu = lambda * C64::new(1.0 + 1e-10, 1e-10) + C64::new(1e-12, 0.0);
    let mut d = a.clone();
    for i in 0..n {
        d[(i, i)] -= mu;
    }
    let lu = d.lu();
    let mut v = DVector::from_fn(n, |i, _| C64::new(1.0 + (i as f64 * 0.37).sin(), 0.3 * (i as f64).cos()));
    for _ in 0..3 {
        let w = lu.solve(&v)?;
        let norm = w.norm();
        if !(norm.is_finite() && norm > 0.0) {
            return None;
        }
        v = w / C64::new(norm, 0.0);
    }
    Some(v)
}

#[cfg(test)]
mod tests {
    use crate::flex::shaft::{Material, ShaftElement};
    use crate::flex::{Disk, Linear, LinearBearing, Rotor};

    /// The Krylov iteration against the dense eigenvalues of the whole matrix, on a rotor with
    /// anisotropic, damped bearings and a heavy disk, at rest and spinning.
    #[test]
    fn krylov_modes_match_the_dense_eigenvalues() {
        let steel = Material { density: 7810.0, modulus: 211e9, shear_modulus: 81.2e9 };
        let mut bearings = vec![LinearBearing::spring(0, 1e6), LinearBearing::spring(4, 1e6)];
        bearings[1].stiffness[1][1] = 7e5;
        bearings[0].damping = [[300.0, 0.0], [0.0, 200.0]];
        let rotor = Rotor {
            elements: (0..4).map(|_| ShaftElement::cylinder(0.15, 0.0, 0.03, steel)).collect(),
            disks: vec![Disk { node: 3, mass: 8.0, diametral_inertia: 0.03, polar_inertia: 0.05 }],
            bearings,
            alpha: 0.0,
            beta: 0.0,
        };
        let p = Linear::full(&rotor.matrices()).prepare().unwrap();
        for speed in [0.0, 3000.0] {
            let (fast, dense) = (p.modes(speed, 6).unwrap(), p.modes_dense(speed, 6).unwrap());
            assert_eq!(fast.len(), 6);
            for (a, b) in fast.iter().zip(&dense) {
                assert!((a.eigenvalue - b.eigenvalue).norm() < 1e-8 * b.wn, "{speed}: {a:?} against {b:?}");
                if speed > 0.0 {
                    assert_eq!(a.whirl, b.whirl, "{speed}: {a:?} against {b:?}");
                }
            }
        }
    }
}
