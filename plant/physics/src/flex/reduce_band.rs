//! The reduction of [`super::reduce`] for a large shaft (more than [`super::DENSE_ELEMENTS`]
//! elements): the same basis and reduced matrices, computed on the band matrices
//! ([`super::band`]) without a dense full-size matrix anywhere. The retained modes come from
//! subspace iteration ([`super::subspace`]), their number from the Sturm count of
//! `K − (2π f_c)² M`; the static and gyroscopic corrections are band solves; every projection
//! `Φᵀ A Φ` is a band product on the `r` basis vectors. Time and memory grow as the element
//! count (for a given number of retained modes), where the dense path's grow as its cube and
//! square.
//!
//! The steps are the dense path's, in its order (read [`super::reduce`]'s module doc for what
//! each one is); only the kernels differ, so the two agree to rounding (tested to 1e-10 on the
//! retained frequencies).

use super::band::Band;
use super::reduce::{append_corrections, unit_loads, Kind, Parts, Reduction, RIGID_MODES};
use super::rotor::{Rotor, DOF_PER_NODE};
use super::FlexError;
use nalgebra::{DMatrix, DVector};

/// The reduction's parts by the band path.
pub(crate) fn parts(rotor: &Rotor, spec: &Reduction) -> Result<Parts, FlexError> {
    let m = rotor.band_matrices();
    let wc = std::f64::consts::TAU * spec.cutoff_hz;
    let n = rotor.dof();
    let below = if spec.cutoff_hz.is_finite() && spec.cutoff_hz > 0.0 {
        m.stiffness.symmetric_part().plus(-wc * wc, &m.mass.symmetric_part()).negative_eigenvalues()
    } else {
        0
    };
    if below > super::BAND_MAX_MODES {
        return Err(FlexError::TooManyModes {
            cutoff_hz: spec.cutoff_hz,
            count: below,
            limit: super::BAND_MAX_MODES,
            dense: super::DENSE_ELEMENTS,
        });
    }
    let shift = if wc.is_finite() && wc > 0.0 { wc * wc } else { 1.0 };
    // A rotor without a bearing's stiffness is free: its rigid-body motions are K's null space
    // exactly (no element resists them), and are taken as they are, at ω = 0 exactly, rather
    // than from the iteration, whose rounding leaves them at |λ| ~ ε ‖K‖ / ‖M‖, far from zero
    // for short elements (1.2·10³ rad²/s² at 2,000 elements of 0.25 mm). The dense path finds
    // them numerically zero against the cutoff; the same vectors up to a rotation among them.
    let free = rotor.bearings.iter().all(|b| b.stiffness.iter().flatten().all(|&k| k == 0.0));
    let rigid = if free { Some(rigid_modes(rotor, &m.mass)?) } else { None };
    let fixed = if free { RIGID_MODES } else { 0 };
    // At least the rigid-body modes, to name them when the cutoff leaves some out.
    let wanted = below.max(RIGID_MODES).min(n) - fixed;
    let (flexible, shapes) = super::subspace::lowest_modes(&m.mass, &m.stiffness, wanted, shift, rigid.as_ref())?;
    let w2: Vec<f64> = std::iter::repeat_n(0.0, fixed).chain(flexible.iter().copied()).collect();
    let phi = match &rigid {
        Some(r) => {
            let mut cols: Vec<DVector<f64>> = r.column_iter().map(|c| c.into_owned()).collect();
            cols.extend(shapes.column_iter().map(|c| c.into_owned()));
            DMatrix::from_columns(&cols)
        }
        None => shapes,
    };
    let kept = w2.iter().take_while(|&&v| v < wc * wc).count();
    if !(spec.cutoff_hz.is_finite() && spec.cutoff_hz > 0.0) || kept < RIGID_MODES {
        let lowest: Vec<f64> = w2.iter().take(RIGID_MODES).map(|v| v.max(0.0).sqrt() / std::f64::consts::TAU).collect();
        return Err(FlexError::CutoffBelowRigidModes { cutoff_hz: spec.cutoff_hz, rigid_hz: lowest });
    }
    let mut kinds: Vec<Kind> = (0..kept).map(|k| if k < fixed { Kind::Rigid } else { Kind::Mode }).collect();
    let mut omega_sq: Vec<f64> = w2[..kept].to_vec();
    let modes = phi.columns(0, kept).into_owned();
    let mut basis = modes.clone();

    let mut loads = if spec.static_correction { unit_loads(n, &spec.force_nodes) } else { Vec::new() };
    if spec.gyroscopic_correction {
        let g = m.gyroscopic.mul(&modes);
        for k in 0..kept {
            let gk = g.column(k).into_owned();
            if gk.norm() > 0.0 {
                loads.push(gk);
            }
        }
    }
    if !loads.is_empty() {
        let f = DMatrix::from_columns(&loads);
        let sigma = if kinds.contains(&Kind::Rigid) { wc * wc } else { 0.0 };
        let shifted: Band = m.stiffness.plus(sigma, &m.mass);
        let mut psi = shifted.lu().ok_or(FlexError::SingularStiffness)?.solve(&f);
        if psi.iter().any(|v| !v.is_finite()) {
            return Err(FlexError::SingularStiffness);
        }
        // Remove what the retained modes already carry: Ψ −= Φ diag(1 / (ω² + σ)) Φᵀ F.
        let mut coef = modes.transpose() * &f;
        for (k, w2k) in omega_sq.iter().enumerate().take(kept) {
            coef.row_mut(k).unscale_mut(w2k + sigma);
        }
        psi -= &modes * coef;
        append_corrections(
            &mut basis,
            &mut omega_sq,
            &mut kinds,
            &psi,
            |x| m.mass.project(x, x),
            |x| m.stiffness.project(x, x),
        );
    }
    let r = basis.ncols();
    let mut damping = m.damping.project(&basis, &basis);
    for k in 0..r {
        damping[(k, k)] += 2.0 * spec.modal_damping * omega_sq[k].sqrt();
    }
    let gyroscopic = m.gyroscopic.project(&basis, &basis);
    let rigid = DMatrix::from_fn(n, 2, |i, axis| if i % DOF_PER_NODE == axis { 1.0 } else { 0.0 });
    let mr = m.mass.mul(&rigid);
    let frame = [basis.transpose() * mr.column(0), basis.transpose() * mr.column(1)];
    Ok(Parts { basis, omega_sq, kinds, damping, gyroscopic, frame })
}

/// The rigid-body motions of a free rotor, mass-normalised (`Rᵀ M R = I`): translations along
/// x and y, tilts in the x–z plane (`x = z`, `β = 1`) and the y–z plane (`y = z`, `α = −1`).
fn rigid_modes(rotor: &Rotor, mass: &Band) -> Result<DMatrix<f64>, FlexError> {
    let z = rotor.node_positions();
    let n = rotor.dof();
    let r = DMatrix::from_fn(n, RIGID_MODES, |i, j| {
        let (node, dof) = (i / DOF_PER_NODE, i % DOF_PER_NODE);
        match (j, dof) {
            (0, 0) | (1, 1) | (2, 3) => 1.0,
            (2, 0) | (3, 1) => z[node],
            (3, 2) => -1.0,
            _ => 0.0,
        }
    });
    let gram = mass.project(&r, &r);
    let gram = (&gram + gram.transpose()) * 0.5;
    let l = gram.cholesky().ok_or(FlexError::MassNotPositive)?.l();
    let l_inv = l.try_inverse().ok_or(FlexError::MassNotPositive)?;
    Ok(r * l_inv.transpose())
}

/// The lowest `count` modes of the full model's undamped, non-spinning rotor (Hz), ascending,
/// by the band path.
pub(crate) fn lowest_frequencies_hz(rotor: &Rotor, count: usize) -> Result<Vec<f64>, FlexError> {
    let m = rotor.band_matrices();
    let (w2, _) = super::subspace::lowest_modes(&m.mass, &m.stiffness, count, 1.0, None)?;
    Ok(w2.iter().map(|v| v.max(0.0).sqrt() / std::f64::consts::TAU).collect())
}

#[cfg(test)]
mod tests {
    use super::super::reduce::Reduced;
    use super::super::shaft::{Material, ShaftElement};
    use super::super::{Disk, LinearBearing};
    use super::*;

    fn steel() -> Material {
        Material { density: 7810.0, modulus: 211e9, shear_modulus: 81.2e9 }
    }

    /// A stepped free shaft of `n` elements with two disks, or on two anisotropic,
    /// cross-coupled bearings.
    fn shaft(n: usize, bearings: bool) -> Rotor {
        let elements = (0..n)
            .map(|i| {
                let d = if i < n / 3 { 0.04 } else { 0.05 };
                let mut e = ShaftElement::cylinder(0.6 / n as f64, 0.01, d, steel());
                e.alpha = 0.3;
                e
            })
            .collect();
        let bearings = if bearings {
            let mut a = LinearBearing::spring(1, 3e7);
            a.stiffness[0][1] = 2e6;
            a.damping = [[400.0, 10.0], [0.0, 500.0]];
            vec![a, LinearBearing::spring(n - 1, 5e7)]
        } else {
            vec![]
        };
        Rotor {
            elements,
            disks: vec![
                Disk { node: n / 2, mass: 4.0, diametral_inertia: 6e-3, polar_inertia: 1e-2 },
                Disk { node: n - 2, mass: 1.5, diametral_inertia: 2e-3, polar_inertia: 3e-3 },
            ],
            bearings,
            alpha: 0.1,
            beta: 1e-6,
        }
    }

    fn spec(n: usize, gyro: bool) -> Reduction {
        Reduction {
            cutoff_hz: 6000.0,
            force_nodes: vec![2, n - 3, 1, n - 1],
            static_correction: true,
            gyroscopic_correction: gyro,
            modal_damping: 0.01,
        }
    }

    /// The band path gives the dense path's retained frequencies to 1e-10 (relative; the
    /// rigid-body modes exactly 0), the same kinds of basis vector, and reduced models with the
    /// same response: the same static deflection at the force nodes under a load, and the same
    /// frame and input terms up to the basis' signs (compared through products that do not
    /// depend on them). Free and on bearings, with and without the gyroscopic correction.
    #[test]
    fn the_band_path_matches_the_dense_one_on_small_shafts() {
        for (n, bearings, gyro) in [(24, false, true), (30, true, false), (40, true, true), (17, false, false)] {
            let rotor = shaft(n, bearings);
            let s = spec(n, gyro);
            let dense = dense_reduced(&rotor, &s);
            let band = Reduced::from_parts(&rotor, &s, parts(&rotor, &s).expect("band path")).expect("builds");
            assert_eq!(band.kinds, dense.kinds, "n = {n}");
            let (fd, fb) = (dense.frequencies_hz(), band.frequencies_hz());
            for (k, (a, b)) in fd.iter().zip(&fb).enumerate() {
                if dense.kinds[k] == Kind::Mode {
                    assert!((a - b).abs() <= 1e-10 * a, "n = {n}, mode {k}: {a} Hz dense, {b} Hz band");
                } else if dense.kinds[k] == Kind::Rigid {
                    assert_eq!((*a, *b), (0.0, 0.0), "n = {n}, mode {k}");
                }
            }
            // The static deflection at every force node under forces at all of them (with the
            // static correction the reduced model's is the full model's: both must agree).
            let deflection = |red: &Reduced| {
                let r = red.size();
                let forces: Vec<[f64; 2]> = (0..s.force_nodes.len()).map(|j| [100.0 + j as f64, -50.0]).collect();
                let mut q = vec![0.0; r];
                let mut rhs = vec![0.0; r];
                red.accelerations(&vec![0.0; r], &vec![0.0; r], 0.0, &forces, [0.0, 0.0], &mut rhs);
                for k in 0..r {
                    if red.omega_sq[k] > 0.0 {
                        q[k] = rhs[k] / red.omega_sq[k];
                    }
                }
                let mut state = q.clone();
                state.extend(vec![0.0; r]);
                s.force_nodes.iter().map(|&node| red.displacement(&state, node)).collect::<Vec<_>>()
            };
            if bearings {
                for (a, b) in deflection(&dense).iter().zip(deflection(&band)) {
                    for i in 0..2 {
                        assert!((a[i] - b[i]).abs() <= 1e-8 * a[i].abs().max(1e-12), "n = {n}: {a:?} {b:?}");
                    }
                }
            }
        }
    }

    fn dense_reduced(rotor: &Rotor, s: &Reduction) -> Reduced {
        assert!(super::super::dense_model(rotor));
        Reduced::new(rotor, s).expect("dense path")
    }

    /// The lowest frequencies by the band path are the dense eigensolver's.
    #[test]
    fn the_lowest_frequencies_match_the_dense_ones() {
        let rotor = shaft(30, true);
        let dense = super::super::reduce::undamped_frequencies_hz(&rotor).unwrap();
        let band = lowest_frequencies_hz(&rotor, 8).unwrap();
        for (a, b) in dense.iter().zip(&band) {
            assert!((a - b).abs() <= 1e-10 * a, "{a} Hz dense, {b} Hz band");
        }
    }
}
