//! The lowest modes of `K φ = λ M φ` for band matrices (MODEL.md §13.4, "Large shafts"):
//! subspace iteration with the shift-inverted operator and a Rayleigh–Ritz step each sweep
//! (Bathe, *Finite Element Procedures*, §11.6), the count of wanted modes fixed beforehand by the
//! Sturm count of `K − λ_c M` ([`Band::negative_eigenvalues`]), so that none below the cutoff
//! is missed.
//!
//! Each sweep costs a band solve and band products on `q` vectors (`O(n q)`) and a dense
//! `q × q` eigenproblem: the cost grows as the shaft's element count `n` for a fixed number
//! of retained modes, where the dense eigensolver's grows as `n³`. Written by hand: nalgebra
//! has no band or sparse eigensolver (see [`super::band`]).

use super::band::Band;
use super::FlexError;
use nalgebra::{DMatrix, DVector};

/// The sweeps allowed before the iteration is declared not converged.
const MAX_SWEEPS: usize = 500;

/// Converged when no wanted `λ + σ` changes by more than this times the largest of them in a
/// sweep.
const TOLERANCE: f64 = 1e-14;

/// The `count` lowest eigenpairs `(λ, Φ)` of `K φ = λ M φ`, λ ascending, Φ mass-normalised
/// (`Φᵀ M Φ = I`), from the symmetric parts of the bands `mass` and `stiffness`; `shift` a
/// positive σ of the order of the wanted λ (it is raised when `K + σ M` is not definite).
/// With `known`, M-orthonormal eigenvectors already known (a free rotor's rigid-body modes),
/// the modes are sought among the vectors M-orthogonal to them.
pub fn lowest_modes(
    mass: &Band,
    stiffness: &Band,
    count: usize,
    shift: f64,
    known: Option<&DMatrix<f64>>,
) -> Result<(DVector<f64>, DMatrix<f64>), FlexError> {
    let n = mass.size();
    let (m, k) = (mass.symmetric_part(), stiffness.symmetric_part());
    m.cholesky().ok_or(FlexError::MassNotPositive)?;
    let count = count.min(n - known.map_or(0, |r| r.ncols()));
    if count == 0 {
        return Ok((DVector::zeros(0), DMatrix::zeros(n, 0)));
    }
    // X −= R Rᵀ M X: what the known vectors carry, removed.
    let deflate = |x: &mut DMatrix<f64>| {
        if let Some(r) = known {
            let c = r.transpose() * m.mul(x);
            *x -= r * c;
        }
    };
    // Bathe's size of the subspace, at least twice the wanted count so that the convergence
    // rate (λ_count + σ) / (λ_q+1 + σ) is small.
    let q = (2 * count).max(count + 8).min(n - known.map_or(0, |r| r.ncols()));
    let mut sigma = shift.max(f64::MIN_POSITIVE);
    let factor = loop {
        if let Some(f) = k.plus(sigma, &m).cholesky() {
            break f;
        }
        sigma *= 10.0;
        if !sigma.is_finite() {
            return Err(FlexError::SingularStiffness);
        }
    };
    // Start vectors with every coordinate in play, of different shapes (deterministic, so that
    // a model is built the same every time).
    let mut x = DMatrix::from_fn(n, q, |i, j| {
        if j == 0 {
            1.0
        } else {
            ((i as f64 + 1.0) * (0.618_034 * j as f64 + 0.1) + 0.37 * j as f64).sin()
        }
    });
    deflate(&mut x);
    let mut previous: Option<DVector<f64>> = None;
    for _ in 0..MAX_SWEEPS {
        let y = m.mul(&x);
        let mut y = y;
        let mut xb = factor.solve(&y);
        // The operator keeps the known vectors' M-orthogonal complement; this removes what
        // rounding brings back of them (`X̄ᵀ (K + σM) X̄ = X̄ᵀ M X` still holds, K R = 0).
        deflate(&mut xb);
        // Columns of unit length (and `M X` scaled alike, so that `(K + σM) X̄ = M X` holds
        // on): the pencil below is then as well conditioned as the vectors are independent,
        // whatever the spread of the shifted eigenvalues.
        for c in 0..q {
            let norm = xb.column(c).norm();
            if norm > 0.0 {
                xb.column_mut(c).unscale_mut(norm);
                y.column_mut(c).unscale_mut(norm);
            }
        }
        // (K + σM) X̄ = M X, so X̄ᵀ (K + σM) X̄ = X̄ᵀ M X: no product with K needed.
        let a = xb.transpose() * &y;
        let b = m.project(&xb, &xb);
        let (mu, z) = small_pencil(&a, &b).ok_or(FlexError::MassNotPositive)?;
        x = xb * z;
        // Measured against the largest wanted value: a rigid-body mode's `λ + σ` is `σ`, and
        // its change is rounding of the order of the others'.
        let top = mu[count - 1].abs().max(f64::MIN_POSITIVE);
        let converged = previous.as_ref().is_some_and(|p| (0..count).all(|i| (mu[i] - p[i]).abs() <= TOLERANCE * top));
        previous = Some(mu);
        if converged {
            let mu = previous.expect("set above");
            let values = DVector::from_iterator(count, mu.iter().take(count).map(|v| v - sigma));
            return Ok((values, x.columns(0, count).into_owned()));
        }
    }
    Err(FlexError::NoConvergence { sweeps: MAX_SWEEPS })
}

/// The eigenpairs of the small symmetric pencil `A z = μ B z`, `B` positive definite: μ
/// ascending, `Zᵀ B Z = I`.
fn small_pencil(a: &DMatrix<f64>, b: &DMatrix<f64>) -> Option<(DVector<f64>, DMatrix<f64>)> {
    let sym = |m: &DMatrix<f64>| (m + m.transpose()) * 0.5;
    let l = sym(b).cholesky()?.l();
    let l_inv = l.try_inverse()?;
    let s = sym(&(&l_inv * sym(a) * l_inv.transpose()));
    let eig = s.symmetric_eigen();
    let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let values = DVector::from_iterator(order.len(), order.iter().map(|&i| eig.eigenvalues[i]));
    let u = DMatrix::from_columns(&order.iter().map(|&i| eig.eigenvectors.column(i).into_owned()).collect::<Vec<_>>());
    Some((values, l_inv.transpose() * u))
}
