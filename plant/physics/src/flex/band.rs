//! Band matrices: the finite-element rotor's global matrices stored by their band, with the
//! products and factorisations the reduction needs on them (MODEL.md §13.4, "Large shafts").
//!
//! Each shaft element couples the eight coordinates of its two nodes, so every global matrix
//! has nonzeros only within [`HALF_BAND`] = 7 of its diagonal: `O(n)` storage instead of the
//! dense `O(n²)`, products with `n × q` blocks in `O(n q)`, and a Cholesky or LU factorisation
//! in `O(n)` (the fill stays in the band without pivoting).
//!
//! Written by hand: nalgebra (the workspace's linear algebra) has no band storage or band
//! solvers, and the rest of what a crate such as LAPACK's `dpbtrf`/`dgbtrf` would bring is
//! these few loops.

use nalgebra::DMatrix;

/// The rotor matrices' half bandwidth: an element's 8 × 8 block reaches 7 off the diagonal.
pub const HALF_BAND: usize = 7;

/// A square matrix with nonzeros only where `|i − j| ≤ b`, stored row by row: row `i` holds
/// columns `i − b ..= i + b` (entries outside the matrix are zero and stay so).
#[derive(Clone, Debug, PartialEq)]
pub struct Band {
    n: usize,
    b: usize,
    data: Vec<f64>,
}

impl Band {
    /// The `n × n` zero matrix of half bandwidth `b`.
    pub fn zeros(n: usize, b: usize) -> Self {
        Band { n, b, data: vec![0.0; n * (2 * b + 1)] }
    }

    /// Its size n.
    pub fn size(&self) -> usize {
        self.n
    }

    fn at(&self, i: usize, j: usize) -> usize {
        debug_assert!(i < self.n && j < self.n && i.abs_diff(j) <= self.b, "({i}, {j}) outside the band");
        i * (2 * self.b + 1) + (j + self.b - i)
    }

    /// Entry `(i, j)` (zero outside the band).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        if i.abs_diff(j) > self.b {
            0.0
        } else {
            self.data[self.at(i, j)]
        }
    }

    /// Adds `v` to entry `(i, j)`, which must lie in the band.
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        assert!(i.abs_diff(j) <= self.b, "({i}, {j}) outside the half bandwidth {}", self.b);
        let k = self.at(i, j);
        self.data[k] += v;
    }

    /// The columns of row `i` inside the matrix and the band, with its stored entries.
    fn row(&self, i: usize) -> (usize, &[f64]) {
        let lo = i.saturating_sub(self.b);
        let hi = (i + self.b).min(self.n - 1);
        let start = i * (2 * self.b + 1) + (lo + self.b - i);
        (lo, &self.data[start..start + (hi - lo + 1)])
    }

    /// `self + factor · other` (same size and band).
    pub fn plus(&self, factor: f64, other: &Band) -> Band {
        assert_eq!((self.n, self.b), (other.n, other.b), "same size and band");
        let data = self.data.iter().zip(&other.data).map(|(a, b)| a + factor * b).collect();
        Band { n: self.n, b: self.b, data }
    }

    /// The symmetric part `(A + Aᵀ) / 2`.
    pub fn symmetric_part(&self) -> Band {
        let mut s = self.clone();
        for i in 0..self.n {
            for j in i.saturating_sub(self.b)..i {
                let v = 0.5 * (self.get(i, j) + self.get(j, i));
                let (a, b) = (s.at(i, j), s.at(j, i));
                s.data[a] = v;
                s.data[b] = v;
            }
        }
        s
    }

    /// `A X` for a block `X` of `n` rows.
    pub fn mul(&self, x: &DMatrix<f64>) -> DMatrix<f64> {
        assert_eq!(x.nrows(), self.n, "rows");
        let mut y = DMatrix::zeros(self.n, x.ncols());
        for c in 0..x.ncols() {
            let xc = x.column(c);
            let xc = xc.as_slice();
            let mut yc = y.column_mut(c);
            for i in 0..self.n {
                let (lo, row) = self.row(i);
                yc[i] = row.iter().zip(&xc[lo..]).map(|(a, v)| a * v).sum();
            }
        }
        y
    }

    /// `Xᵀ A Y` (`q × p`).
    pub fn project(&self, x: &DMatrix<f64>, y: &DMatrix<f64>) -> DMatrix<f64> {
        x.transpose() * self.mul(y)
    }

    /// The dense matrix (for tests and small comparisons).
    pub fn to_dense(&self) -> DMatrix<f64> {
        DMatrix::from_fn(self.n, self.n, |i, j| self.get(i, j))
    }

    /// The Cholesky factor `A = L Lᵀ` of a symmetric positive definite band (its lower half is
    /// read); `None` when a pivot is not positive.
    pub fn cholesky(&self) -> Option<BandCholesky> {
        let (n, b) = (self.n, self.b);
        // l[i][k] holds L(i, i − b + k), k = 0..=b.
        let w = b + 1;
        let mut l = vec![0.0; n * w];
        for i in 0..n {
            let lo = i.saturating_sub(b);
            for j in lo..=i {
                let mut s = self.get(i, j);
                for k in lo.max(j.saturating_sub(b))..j {
                    s -= l[i * w + (k + b - i)] * l[j * w + (k + b - j)];
                }
                if j == i {
                    if !(s > 0.0 && s.is_finite()) {
                        return None;
                    }
                    l[i * w + b] = s.sqrt();
                } else {
                    l[i * w + (j + b - i)] = s / l[j * w + b];
                }
            }
        }
        Some(BandCholesky { n, b, l })
    }

    /// How many eigenvalues of the symmetric band are negative (Sylvester's law of inertia: the
    /// negative pivots of `A = L D Lᵀ`), the Sturm count of finite-element eigensolvers (Bathe,
    /// *Finite Element Procedures*, §11.4.3). A zero pivot (the matrix singular) is nudged by a
    /// relative 1e-14, counting that eigenvalue as not negative.
    pub fn negative_eigenvalues(&self) -> usize {
        let (n, b) = (self.n, self.b);
        let w = b + 1;
        let scale = self.data.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
        // u[i][k] holds L(i, i − b + k) D(j) (the unscaled elimination), d the pivots.
        let mut lw = vec![0.0; n * w];
        let mut d = vec![0.0; n];
        let mut negative = 0;
        for i in 0..n {
            let lo = i.saturating_sub(b);
            for j in lo..i {
                // (L D)(i, j) = A(i, j) − Σ_k L(i, k) D(k) L(j, k)
                let mut s = self.get(i, j);
                for k in lo.max(j.saturating_sub(b))..j {
                    s -= lw[i * w + (k + b - i)] * lw[j * w + (k + b - j)] / d[k];
                }
                lw[i * w + (j + b - i)] = s;
            }
            let mut s = self.get(i, i);
            for k in lo..i {
                let v = lw[i * w + (k + b - i)];
                s -= v * v / d[k];
            }
            if s == 0.0 || !s.is_finite() {
                s = 1e-14 * scale;
            }
            if s < 0.0 {
                negative += 1;
            }
            d[i] = s;
            lw[i * w + b] = s;
        }
        negative
    }

    /// The LU factors of a band without pivoting (`None` on a zero or non-finite pivot).
    ///
    /// No pivoting keeps the fill in the band. It is safe for what it solves here, `K + σ M`:
    /// the symmetric part of `K` is positive semidefinite and `M`'s definite (or `K` definite
    /// when `σ = 0`), and a matrix whose symmetric part is positive definite is factored
    /// without pivoting with no breakdown (Golub & Van Loan, §4.2); the bearings' cross
    /// coupling makes `K` unsymmetric but leaves its symmetric part as it was.
    pub fn lu(&self) -> Option<BandLu> {
        let (n, b) = (self.n, self.b);
        let mut a = self.clone();
        for k in 0..n {
            let pivot = a.data[a.at(k, k)];
            if pivot == 0.0 || !pivot.is_finite() {
                return None;
            }
            let hi = (k + b).min(n - 1);
            for i in k + 1..=hi {
                let f = a.data[a.at(i, k)] / pivot;
                let ik = a.at(i, k);
                a.data[ik] = f;
                for j in k + 1..=hi {
                    let (ij, kj) = (a.at(i, j), a.at(k, j));
                    a.data[ij] -= f * a.data[kj];
                }
            }
        }
        Some(BandLu { a })
    }
}

/// The Cholesky factor of a band ([`Band::cholesky`]).
#[derive(Clone, Debug)]
pub struct BandCholesky {
    n: usize,
    b: usize,
    l: Vec<f64>,
}

impl BandCholesky {
    /// `A⁻¹ Y`.
    // The index runs over the band's storage and the vector at once: clearer as an index.
    #[allow(clippy::needless_range_loop)]
    pub fn solve(&self, y: &DMatrix<f64>) -> DMatrix<f64> {
        let (n, b, w) = (self.n, self.b, self.b + 1);
        assert_eq!(y.nrows(), n, "rows");
        let mut x = y.clone();
        for c in 0..x.ncols() {
            let mut col = x.column_mut(c);
            let v = col.as_mut_slice();
            // L z = y
            for i in 0..n {
                let lo = i.saturating_sub(b);
                let mut s = v[i];
                for k in lo..i {
                    s -= self.l[i * w + (k + b - i)] * v[k];
                }
                v[i] = s / self.l[i * w + b];
            }
            // Lᵀ x = z
            for i in (0..n).rev() {
                let hi = (i + b).min(n - 1);
                let mut s = v[i];
                for k in i + 1..=hi {
                    s -= self.l[k * w + (i + b - k)] * v[k];
                }
                v[i] = s / self.l[i * w + b];
            }
        }
        x
    }
}

/// The LU factors of a band ([`Band::lu`]): `L` unit lower (below the diagonal), `U` upper.
#[derive(Clone, Debug)]
pub struct BandLu {
    a: Band,
}

impl BandLu {
    /// `A⁻¹ Y`.
    pub fn solve(&self, y: &DMatrix<f64>) -> DMatrix<f64> {
        let (n, b) = (self.a.n, self.a.b);
        let mut x = y.clone();
        for c in 0..x.ncols() {
            let mut col = x.column_mut(c);
            let v = col.as_mut_slice();
            for i in 0..n {
                for k in i.saturating_sub(b)..i {
                    v[i] -= self.a.get(i, k) * v[k];
                }
            }
            for i in (0..n).rev() {
                for k in i + 1..=(i + b).min(n - 1) {
                    v[i] -= self.a.get(i, k) * v[k];
                }
                v[i] /= self.a.get(i, i);
            }
        }
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A symmetric positive definite band of size 30, half bandwidth 3, and an unsymmetric one.
    fn sample(unsym: f64) -> Band {
        let (n, b) = (30, 3);
        let mut a = Band::zeros(n, b);
        for i in 0..n {
            a.add(i, i, 10.0 + (i as f64 * 0.37).sin());
            for j in i.saturating_sub(b)..i {
                let v = ((i * 7 + j * 3) as f64 * 0.91).cos();
                a.add(i, j, v + unsym * (j as f64 * 0.2).sin());
                a.add(j, i, v);
            }
        }
        a
    }

    fn block(n: usize, q: usize) -> DMatrix<f64> {
        DMatrix::from_fn(n, q, |i, j| ((i * 5 + j * 11) as f64 * 0.53).sin())
    }

    #[test]
    fn products_and_solves_match_the_dense_ones() {
        let a = sample(0.0);
        let dense = a.to_dense();
        let x = block(30, 4);
        assert!((a.mul(&x) - &dense * &x).abs().max() < 1e-12);
        let chol = a.cholesky().expect("positive definite");
        assert!((&dense * chol.solve(&x) - &x).abs().max() < 1e-12);
        let u = sample(0.4);
        let lu = u.lu().expect("factors");
        assert!((u.to_dense() * lu.solve(&x) - &x).abs().max() < 1e-12);
        assert!((u.symmetric_part().to_dense() - (u.to_dense() + u.to_dense().transpose()) * 0.5).abs().max() < 1e-15);
    }

    /// The Sturm count of `A − μ I` is the number of dense eigenvalues below μ.
    #[test]
    fn the_negative_pivots_count_the_eigenvalues_below_a_shift() {
        let a = sample(0.0);
        let values = a.to_dense().symmetric_eigen().eigenvalues;
        let mut identity = Band::zeros(30, 3);
        for i in 0..30 {
            identity.add(i, i, 1.0);
        }
        for mu in [0.0, 7.5, 9.0, 10.0, 11.3, 14.0] {
            let below = values.iter().filter(|&&v| v < mu).count();
            assert_eq!(a.plus(-mu, &identity).negative_eigenvalues(), below, "μ = {mu}: {values}");
        }
        assert!(Band::zeros(3, 1).cholesky().is_none());
    }
}
