//! The rotor reduced to its modes below a cutoff frequency, with a static correction at the
//! force nodes, and the pure derivative of the reduced state (MODEL.md §13.5).
//!
//! **Basis.** The undamped modes of the non-spinning rotor `K φ = ω² M φ` (with whatever linear
//! bearings the [`Rotor`] has; none for a rotor on AMBs, whose forces come in at the force
//! nodes), mass-normalised (`φᵀ M φ = 1`), those with `ω < 2π f_c`. With the static correction,
//! the basis is augmented with the part of the static response to a unit force at each force
//! node's `x` and `y` that the retained modes miss (the residual flexibility,
//! `Ψ = (K + σM)⁻¹ F − Σ_r φ_r φ_rᵀ F / (ω_r² + σ)`, with `σ = 0` when the bearings hold the
//! rotor and `σ = (2π f_c)²` when it is free and `K` singular), and the augmented basis is made
//! M-orthonormal with `K` diagonal again (a Rayleigh–Ritz step: the retained modes stay as they
//! are, the corrections become pseudo-modes above the cutoff). With it, the reduced model's
//! static deflection under forces at the force nodes is the full model's exactly (for `σ = 0`).
//! With the gyroscopic correction, the loads `G φ_k` of the retained modes are treated the same
//! way: the spin couples each retained mode to the truncated ones through `Ω G φ_k`, and without
//! these vectors a rotor with heavy disks at high speed loses accuracy in its retained
//! frequencies (tests/ross.rs states by how much).
//!
//! **Equations.** With `q ≈ Φ η`, `Φᵀ M Φ = I`, `Φᵀ K Φ = Λ = diag(ω_k²)`:
//!
//! ```text
//! η̈ = −Λ η − (D + Ω Gᵣ) η̇ + Σ_j Φ_jᵀ f_j − Φᵀ M (r_x a_x + r_y a_y)
//! D = diag(2 ζ ω_k) + Φᵀ C Φ,   Gᵣ = Φᵀ G Φ
//! ```
//!
//! `f_j = (f_x, f_y)` the force on the rotor at force node `j` (`Φ_j` the basis' rows of that
//! node's `x`, `y`), `(a_x, a_y)` the acceleration of the housing frame plus gravity (`g ŷ + a_h`,
//! as for the rigid rotors: every mass feels `−m (g ŷ + a_h)`), `r_x`, `r_y` the rigid
//! translations, `ζ` the modal damping ratio (the rigid-body modes, `ω = 0`, get none).
//! The state is `[η, η̇]`, positions then rates, as [`crate::integrate`] expects.

use super::modes::Linear;
use super::rotor::{Rotor, DOF_PER_NODE};
use super::FlexError;
use nalgebra::{DMatrix, DVector};

/// How to reduce.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Reduction {
    /// Keep the modes below this frequency (Hz).
    pub cutoff_hz: f64,
    /// Nodes where forces act (AMBs, touchdown bearings, disks with unbalance), in the order
    /// the forces are given to [`Reduced::derivative`].
    pub force_nodes: Vec<usize>,
    /// Augment the modes with the residual flexibility at the force nodes.
    pub static_correction: bool,
    /// Augment the modes with the static response to each retained mode's gyroscopic force
    /// `G φ_k` (what the spin couples the retained modes to among the truncated ones).
    pub gyroscopic_correction: bool,
    /// Modal damping ratio ζ of every basis vector with `ω > 0`.
    pub modal_damping: f64,
}

/// What a basis vector is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// A rigid-body mode of a free rotor (ω = 0).
    Rigid,
    /// A mode of the full model below the cutoff.
    Mode,
    /// A static-correction pseudo-mode.
    Correction,
}

/// The reduced rotor.
#[derive(Clone, Debug)]
pub struct Reduced {
    /// The basis Φ (ndof × r), M-orthonormal.
    pub basis: DMatrix<f64>,
    /// `ω_k²` of each basis vector (rad²/s²).
    pub omega_sq: DVector<f64>,
    /// What each basis vector is.
    pub kinds: Vec<Kind>,
    /// `D = diag(2 ζ ω_k) + Φᵀ C Φ` (1/s).
    pub damping: DMatrix<f64>,
    /// `Gᵣ = Φᵀ G Φ`.
    pub gyroscopic: DMatrix<f64>,
    /// The force nodes.
    pub force_nodes: Vec<usize>,
    /// `Φᵀ M r_x` and `Φᵀ M r_y`.
    frame: [DVector<f64>; 2],
    /// The basis' rows of each force node's x and y: r × (2 × force nodes).
    input: DMatrix<f64>,
    /// The shaft's node count.
    nodes: usize,
    /// The basis laid out row by row, a copy of `basis` for the node readers.
    ///
    /// Written by hand, not a nalgebra view, because of the hot loop: `DMatrix` is
    /// column-major, so a node's row of it is strided (one cache line per element at 16 nodes ×
    /// 4 DOF) and bounds-checked element by element; the node readers walk such rows several
    /// times per evaluation, up to 271 evaluations per controller tick in contact.
    basis_rows: Vec<f64>,
    /// `D + ω Gᵣ` at one spin speed ω (rad/s), column-major like `damping`: the rates' matrix
    /// of a rotor whose spin is held there, formed once instead of in every evaluation
    /// ([`Reduced::hold_speed`]). Each entry is `d + ω g` as the evaluation forms it, so the
    /// derivative is the same to the bit with or without it.
    held: Option<(f64, Vec<f64>)>,
}

/// The lowest modes of `K φ = ω² M φ`: `(ω², Φ)` ascending, Φ mass-normalised.
fn undamped_modes(mass: &DMatrix<f64>, stiffness: &DMatrix<f64>) -> Result<(DVector<f64>, DMatrix<f64>), FlexError> {
    let chol = mass.clone().cholesky().ok_or(FlexError::MassNotPositive)?;
    let l = chol.l();
    let l_inv = l.clone().try_inverse().ok_or(FlexError::MassNotPositive)?;
    let s = &l_inv * stiffness * l_inv.transpose();
    let s = (&s + s.transpose()) * 0.5;
    let eig = s.symmetric_eigen();
    let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let values = DVector::from_iterator(order.len(), order.iter().map(|&i| eig.eigenvalues[i]));
    let u = DMatrix::from_columns(&order.iter().map(|&i| eig.eigenvectors.column(i).into_owned()).collect::<Vec<_>>());
    Ok((values, l_inv.transpose() * u))
}

/// The modes of the full model's undamped, non-spinning rotor (Hz), ascending: all of them up
/// to [`super::DENSE_ELEMENTS`] elements, the lowest [`LOWEST_LARGE`] above.
pub fn undamped_frequencies_hz(rotor: &Rotor) -> Result<Vec<f64>, FlexError> {
    if !super::dense_model(rotor) {
        return super::reduce_band::lowest_frequencies_hz(rotor, LOWEST_LARGE);
    }
    let m = rotor.matrices();
    let (w2, _) = undamped_modes(&m.mass, &m.stiffness)?;
    Ok(w2.iter().map(|v| v.max(0.0).sqrt() / std::f64::consts::TAU).collect())
}

/// What a reduction makes of a rotor, before the node readers' layouts.
pub(crate) struct Parts {
    /// Φ.
    pub basis: DMatrix<f64>,
    /// `ω_k²`.
    pub omega_sq: Vec<f64>,
    /// What each basis vector is.
    pub kinds: Vec<Kind>,
    /// `D`.
    pub damping: DMatrix<f64>,
    /// `Gᵣ`.
    pub gyroscopic: DMatrix<f64>,
    /// `Φᵀ M r_x`, `Φᵀ M r_y`.
    pub frame: [DVector<f64>; 2],
}

/// The reduction with the dense matrices and nalgebra's dense eigensolver (up to
/// [`super::DENSE_ELEMENTS`]: the shipped scenes' arithmetic).
fn dense_parts(rotor: &Rotor, spec: &Reduction) -> Result<Parts, FlexError> {
    let m = rotor.matrices();
    let (w2, phi) = undamped_modes(&m.mass, &m.stiffness)?;
    let wc = std::f64::consts::TAU * spec.cutoff_hz;
    // A free rotor's rigid-body modes: numerically zero against the cutoff.
    let rigid_tol = 1e-8 * wc * wc;
    let kept = w2.iter().take_while(|&&v| v < wc * wc).count();
    if !(spec.cutoff_hz.is_finite() && spec.cutoff_hz > 0.0) || kept < RIGID_MODES {
        let lowest: Vec<f64> = w2.iter().take(RIGID_MODES).map(|v| v.max(0.0).sqrt() / std::f64::consts::TAU).collect();
        return Err(FlexError::CutoffBelowRigidModes { cutoff_hz: spec.cutoff_hz, rigid_hz: lowest });
    }
    let mut kinds: Vec<Kind> =
        w2.iter().take(kept).map(|&v| if v.abs() <= rigid_tol { Kind::Rigid } else { Kind::Mode }).collect();
    let mut omega_sq: Vec<f64> = w2.iter().take(kept).map(|&v| if v.abs() <= rigid_tol { 0.0 } else { v }).collect();
    let mut basis = phi.columns(0, kept).into_owned();

    let n = rotor.dof();
    let mut loads = if spec.static_correction { unit_loads(n, &spec.force_nodes) } else { Vec::new() };
    if spec.gyroscopic_correction {
        for k in 0..kept {
            let g = &m.gyroscopic * phi.column(k);
            if g.norm() > 0.0 {
                loads.push(g);
            }
        }
    }
    if !loads.is_empty() {
        let f = DMatrix::from_columns(&loads);
        let sigma = if kinds.contains(&Kind::Rigid) { wc * wc } else { 0.0 };
        let shifted = &m.stiffness + &m.mass * sigma;
        let mut psi = shifted.lu().solve(&f).ok_or(FlexError::SingularStiffness)?;
        // Remove what the retained modes already carry.
        for (k, w2k) in omega_sq.iter().enumerate().take(kept) {
            let p = phi.column(k);
            let coef = (p.transpose() * &f) / (w2k + sigma);
            psi -= p * coef;
        }
        append_corrections(
            &mut basis,
            &mut omega_sq,
            &mut kinds,
            &psi,
            |x| x.transpose() * &m.mass * x,
            |x| x.transpose() * &m.stiffness * x,
        );
    }
    let r = basis.ncols();
    let mut damping = basis.transpose() * &m.damping * &basis;
    for k in 0..r {
        damping[(k, k)] += 2.0 * spec.modal_damping * omega_sq[k].sqrt();
    }
    let gyroscopic = basis.transpose() * &m.gyroscopic * &basis;
    let rigid = |axis: usize| DVector::from_fn(rotor.dof(), |i, _| if i % DOF_PER_NODE == axis { 1.0 } else { 0.0 });
    let frame = [basis.transpose() * (&m.mass * rigid(0)), basis.transpose() * (&m.mass * rigid(1))];
    Ok(Parts { basis, omega_sq, kinds, damping, gyroscopic, frame })
}

/// The unit loads on the two axes of each node in `nodes` (the static correction's right-hand
/// sides), on a shaft of `n` degrees of freedom.
pub(super) fn unit_loads(n: usize, nodes: &[usize]) -> Vec<DVector<f64>> {
    let mut loads = Vec::with_capacity(2 * nodes.len());
    for &node in nodes {
        for axis in 0..2 {
            let mut e = DVector::zeros(n);
            e[DOF_PER_NODE * node + axis] = 1.0;
            loads.push(e);
        }
    }
    loads
}

/// Appends the corrections `psi` to `basis`: M-orthonormalised among themselves (dropping
/// dependent ones), K diagonalised on them (Rayleigh–Ritz), each with its `ω²` and kind.
/// `mass` and `stiffness` give `Xᵀ A X` of a block `X`: the dense path's products or the band
/// path's, each with its own arithmetic.
pub(super) fn append_corrections(
    basis: &mut DMatrix<f64>,
    omega_sq: &mut Vec<f64>,
    kinds: &mut Vec<Kind>,
    psi: &DMatrix<f64>,
    mass: impl Fn(&DMatrix<f64>) -> DMatrix<f64>,
    stiffness: impl Fn(&DMatrix<f64>) -> DMatrix<f64>,
) {
    let gram = mass(psi);
    let gram = (&gram + gram.transpose()) * 0.5;
    let ge = gram.symmetric_eigen();
    let top = ge.eigenvalues.iter().copied().fold(0.0, f64::max);
    let cols: Vec<DVector<f64>> = (0..ge.eigenvalues.len())
        .filter(|&i| ge.eigenvalues[i] > 1e-10 * top)
        .map(|i| psi * ge.eigenvectors.column(i) / ge.eigenvalues[i].sqrt())
        .collect();
    if cols.is_empty() {
        return;
    }
    let q = DMatrix::from_columns(&cols);
    let kq = stiffness(&q);
    let kq = (&kq + kq.transpose()) * 0.5;
    let ke = kq.symmetric_eigen();
    let mut order: Vec<usize> = (0..ke.eigenvalues.len()).collect();
    order.sort_by(|&a, &b| ke.eigenvalues[a].total_cmp(&ke.eigenvalues[b]));
    let extra =
        q * DMatrix::from_columns(&order.iter().map(|&i| ke.eigenvectors.column(i).into_owned()).collect::<Vec<_>>());
    let mut all: Vec<DVector<f64>> = basis.column_iter().map(|c| c.into_owned()).collect();
    all.extend(extra.column_iter().map(|c| c.into_owned()));
    *basis = DMatrix::from_columns(&all);
    for &i in &order {
        omega_sq.push(ke.eigenvalues[i].max(0.0));
        kinds.push(Kind::Correction);
    }
}

/// Rows `k .. k + L` of each column of `m` (column-major, `r` rows), as arrays.
fn columns<const L: usize>(m: &[f64], r: usize, k: usize) -> impl Iterator<Item = &[f64; L]> {
    m.chunks_exact(r).map(move |c| <&[f64; L]>::try_from(&c[k..k + L]).expect("k + L <= r"))
}

/// Rows of the derivative computed side by side ([`Reduced::rate_rows`]).
const ROWS: usize = 4;

/// How many of a large shaft's lowest frequencies [`undamped_frequencies_hz`] gives.
pub const LOWEST_LARGE: usize = 12;

/// Rigid-body modes of a rotor in the plane: two translations and two tilts.
pub const RIGID_MODES: usize = 4;

impl Reduced {
    /// Reduces `rotor` as `spec` says.
    pub fn new(rotor: &Rotor, spec: &Reduction) -> Result<Self, FlexError> {
        rotor.validate()?;
        let nodes = rotor.node_count();
        for &n in &spec.force_nodes {
            if n >= nodes {
                return Err(FlexError::NodeOutOfRange { what: "force node".into(), node: n, nodes });
            }
        }
        if !(spec.modal_damping.is_finite() && spec.modal_damping >= 0.0) {
            return Err(FlexError::Value { key: "modal damping ratio", value: spec.modal_damping, unit: "" });
        }
        let parts =
            if super::dense_model(rotor) { dense_parts(rotor, spec)? } else { super::reduce_band::parts(rotor, spec)? };
        Self::from_parts(rotor, spec, parts)
    }

    /// The reduced rotor from a reduction's parts.
    pub(crate) fn from_parts(rotor: &Rotor, spec: &Reduction, parts: Parts) -> Result<Self, FlexError> {
        let Parts { basis, omega_sq, kinds, damping, gyroscopic, frame } = parts;
        let nodes = rotor.node_count();
        let r = basis.ncols();
        let mut input = DMatrix::zeros(r, 2 * spec.force_nodes.len());
        for (j, &node) in spec.force_nodes.iter().enumerate() {
            for axis in 0..2 {
                input.column_mut(2 * j + axis).copy_from(&basis.row(DOF_PER_NODE * node + axis).transpose());
            }
        }
        Ok(Reduced {
            basis_rows: basis.transpose().as_slice().to_vec(),
            basis,
            omega_sq: DVector::from_vec(omega_sq),
            kinds,
            damping,
            gyroscopic,
            force_nodes: spec.force_nodes.clone(),
            frame,
            input,
            nodes,
            held: None,
        })
    }

    /// Forms the rates' matrix `D + speed Gᵣ` once, for a rotor whose spin stays at `speed`
    /// (rad/s): an evaluation at exactly that speed uses it, any other forms its terms as before.
    pub fn hold_speed(mut self, speed: f64) -> Self {
        let matrix =
            self.damping.as_slice().iter().zip(self.gyroscopic.as_slice()).map(|(d, g)| d + speed * g).collect();
        self.held = Some((speed, matrix));
        self
    }

    /// Number of basis vectors r (the state has 2r entries).
    pub fn size(&self) -> usize {
        self.basis.ncols()
    }

    /// Frequencies `ω_k / 2π` of the basis vectors (Hz).
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.omega_sq.iter().map(|v| v.sqrt() / std::f64::consts::TAU).collect()
    }

    /// The derivative of the state `[η, η̇]` (length 2r) at spin speed `speed` (rad/s), under
    /// the forces `forces[j] = (f_x, f_y)` (N) on the rotor at force node `j`, with the housing
    /// frame accelerating at `frame_accel = g ŷ + a_h` (m/s²); written into `dstate`.
    pub fn derivative(
        &self,
        state: &[f64],
        speed: f64,
        forces: &[[f64; 2]],
        frame_accel: [f64; 2],
        dstate: &mut [f64],
    ) {
        let r = self.size();
        let (eta, rate) = state.split_at(r);
        let (d_eta, d_rate) = dstate.split_at_mut(r);
        d_eta.copy_from_slice(rate);
        self.accelerations(eta, rate, speed, forces, frame_accel, d_rate);
    }

    /// The rate part of [`Reduced::derivative`], `η̈` (length r) into `out`, from the
    /// coordinates `eta` and their rates `rate` given apart (the plant's state keeps them in
    /// two halves).
    pub fn accelerations(
        &self,
        eta: &[f64],
        rate: &[f64],
        speed: f64,
        forces: &[[f64; 2]],
        frame_accel: [f64; 2],
        out: &mut [f64],
    ) {
        let r = self.size();
        assert_eq!(forces.len(), self.force_nodes.len(), "one force per force node");
        let (eta, rate, out) = (&eta[..r], &rate[..r], &mut out[..r]);
        let mut k = 0;
        while k + ROWS <= r {
            self.rate_rows::<ROWS>(k, eta, rate, speed, forces, frame_accel, out);
            k += ROWS;
        }
        for k in k..r {
            self.rate_rows::<1>(k, eta, rate, speed, forces, frame_accel, out);
        }
    }

    /// Rows `k .. k + L` of the derivative's rate part, `η̈_k`, computed side by side.
    ///
    /// Written by hand for the hot loop: each row is a chain of `r + 2 × force nodes` dependent
    /// additions, so one row at a time waits on the adder's latency; `L` rows at once keep `L`
    /// chains in flight, read the column-major matrices along their columns, and let the
    /// compiler pair the lanes. Each row's terms are added in the same order as a row-by-row
    /// sum (`−ω²η − frame`, then the rates in order, then the forces in order), so the result
    /// is the same to the bit; only the rows are interleaved.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn rate_rows<'a, const L: usize>(
        &'a self,
        k: usize,
        eta: &[f64],
        rate: &[f64],
        speed: f64,
        forces: &[[f64; 2]],
        frame_accel: [f64; 2],
        d_rate: &mut [f64],
    ) {
        let r = self.size();
        let (w2, fx, fy) = (
            &self.omega_sq.as_slice()[k..][..L],
            &self.frame[0].as_slice()[k..][..L],
            &self.frame[1].as_slice()[k..][..L],
        );
        let eta = &eta[k..][..L];
        let mut acc = [0.0; L];
        for j in 0..L {
            acc[j] = -w2[j] * eta[j] - fx[j] * frame_accel[0] - fy[j] * frame_accel[1];
        }
        assert!(k + L <= r, "rows {k}..{} of {r}", k + L);
        let of = |m: &'a DMatrix<f64>| columns::<L>(m.as_slice(), r, k);
        match &self.held {
            Some((held, c)) if held.to_bits() == speed.to_bits() => {
                for (c, v) in columns::<L>(c, r, k).zip(rate) {
                    for j in 0..L {
                        acc[j] -= c[j] * v;
                    }
                }
            }
            _ => {
                for ((d, g), v) in of(&self.damping).zip(of(&self.gyroscopic)).zip(rate) {
                    for j in 0..L {
                        acc[j] -= (d[j] + speed * g[j]) * v;
                    }
                }
            }
        }
        let mut input = of(&self.input);
        for f in forces {
            let (Some(bx), Some(by)) = (input.next(), input.next()) else {
                unreachable!("two input columns per force node")
            };
            for j in 0..L {
                acc[j] += bx[j] * f[0] + by[j] * f[1];
            }
        }
        d_rate[k..k + L].copy_from_slice(&acc);
    }

    /// Node `node`'s basis rows `first` and `first + 1` (x and y, or the two rotations).
    fn node_rows(&self, node: usize, first: usize) -> [&[f64]; 2] {
        assert!(node < self.nodes, "node {node} of {}", self.nodes);
        let r = self.size();
        let row = DOF_PER_NODE * node + first;
        [&self.basis_rows[row * r..][..r], &self.basis_rows[(row + 1) * r..][..r]]
    }

    /// Node `node`'s rows `first`, `first + 1` dotted with the first r entries of `v`.
    ///
    /// The sums run side by side (see [`Reduced::rate_rows`] for why), each over the basis row
    /// in order from −0.0, as `Iterator::sum` adds, so the result is the same to the bit as
    /// separate sums.
    fn node_pair(&self, node: usize, first: usize, v: &[f64]) -> [f64; 2] {
        let [bx, by] = self.node_rows(node, first);
        let mut acc = [-0.0; 2];
        for ((x, y), v) in bx.iter().zip(by).zip(&v[..bx.len()]) {
            acc[0] += x * v;
            acc[1] += y * v;
        }
        acc
    }

    /// Displacement and velocity `((x, y), (ẋ, ẏ))` (m, m/s) of node `node` in state `state`
    /// (`[η, η̇]`).
    pub fn motion(&self, state: &[f64], node: usize) -> [[f64; 2]; 2] {
        let (q, v) = state.split_at(self.size());
        self.motion_of(q, v, node)
    }

    /// [`Reduced::motion`] from the coordinates and their rates given apart.
    /// Its four sums in one pass over the node's rows, as [`Reduced::node_pair`] adds them (the
    /// evaluation reads every plane's node so: the flexible 10 G scene takes 2.69·10⁹
    /// instructions, against 2.83·10⁹ with two passes, callgrind).
    pub fn motion_of(&self, eta: &[f64], rate: &[f64], node: usize) -> [[f64; 2]; 2] {
        let [bx, by] = self.node_rows(node, 0);
        let r = bx.len();
        let mut acc = [[-0.0; 2]; 2];
        for (((x, y), q), v) in bx.iter().zip(by).zip(&eta[..r]).zip(&rate[..r]) {
            acc[0][0] += x * q;
            acc[0][1] += y * q;
            acc[1][0] += x * v;
            acc[1][1] += y * v;
        }
        acc
    }

    /// Displacement `(x, y)` (m) of node `node` in state `state`.
    pub fn displacement(&self, state: &[f64], node: usize) -> [f64; 2] {
        self.node_pair(node, 0, state)
    }

    /// Velocity `(ẋ, ẏ)` (m/s) of node `node`.
    pub fn velocity(&self, state: &[f64], node: usize) -> [f64; 2] {
        self.node_pair(node, 0, &state[self.size()..])
    }

    /// Rotations `(α, β)` (rad) of node `node` (`β = dx/dz`, `α = −dy/dz`).
    pub fn rotation(&self, state: &[f64], node: usize) -> [f64; 2] {
        self.node_pair(node, 2, state)
    }

    /// The full model's coordinates `q = Φ η` of a state.
    pub fn expand(&self, state: &[f64]) -> DVector<f64> {
        &self.basis * DVector::from_column_slice(&state[..self.size()])
    }

    /// The reduced model as a linear system (for its whirl modes and Campbell diagram).
    pub fn linear(&self) -> Linear {
        let r = self.size();
        let node_xy = (0..self.nodes)
            .map(|k| (self.basis.row(DOF_PER_NODE * k).transpose(), self.basis.row(DOF_PER_NODE * k + 1).transpose()))
            .collect();
        Linear {
            mass: DMatrix::identity(r, r),
            stiffness: DMatrix::from_diagonal(&self.omega_sq),
            damping: self.damping.clone(),
            gyroscopic: self.gyroscopic.clone(),
            node_xy,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flex::shaft::{Material, ShaftElement};

    /// The largest shaft the model takes (`MAX_ELEMENTS`, by the band path) builds and reduces,
    /// and its first bending frequencies are the Euler–Bernoulli free–free beam's,
    /// `(β_k L)² √(E I / (ρ A L⁴)) / 2π` with `β_k L` = 4.730041, 7.853205, 10.995608 (the
    /// roots of `cos βL cosh βL = 1`), for Euler–Bernoulli elements (no shear, no rotary
    /// inertia): a steel shaft of 0.5 m and 40 mm, each frequency twice (x and y), after the
    /// four rigid-body modes at 0 Hz. To 1e-4: the discretisation error is far below that at
    /// 2,000 elements, and what remains is the assembly's rounding (element stiffnesses of
    /// 2·10¹⁶ N/m at 0.25 mm summed into a matrix whose rigid motions they cancel: a relative
    /// error of the order of n³ ε in the lowest eigenvalue, 3·10⁻⁵ in the first frequency here).
    /// Its cost: `cargo bench -p plant-physics --bench shaft`.
    #[test]
    fn the_largest_allowed_shaft_builds_with_the_beams_frequencies() {
        let steel = Material { density: 7810.0, modulus: 211e9, shear_modulus: 81.2e9 };
        let (length, d, n) = (0.5, 0.04, crate::flex::MAX_ELEMENTS);
        let element = |_| {
            let mut e = ShaftElement::cylinder(length / n as f64, 0.0, d, steel);
            (e.shear_effects, e.rotary_inertia, e.gyroscopic) = (false, false, false);
            e
        };
        let rotor =
            Rotor { elements: (0..n).map(element).collect(), disks: vec![], bearings: vec![], alpha: 0.0, beta: 0.0 };
        assert!(!crate::flex::dense_model(&rotor), "the band path");
        let spec = Reduction {
            cutoff_hz: 5000.0,
            force_nodes: vec![n / 10, n - n / 10],
            static_correction: true,
            gyroscopic_correction: true,
            modal_damping: 0.0,
        };
        let reduced = Reduced::new(&rotor, &spec).expect("reduces");
        let f = reduced.frequencies_hz();
        assert!(f[..RIGID_MODES].iter().all(|&v| v == 0.0), "{f:?}");
        assert_eq!(reduced.kinds.iter().filter(|k| **k == Kind::Mode).count(), 6, "{f:?}");
        let (area, inertia) = (std::f64::consts::PI * d * d / 4.0, std::f64::consts::PI * d.powi(4) / 64.0);
        let scale = (211e9 * inertia / (7810.0 * area * length.powi(4))).sqrt() / std::f64::consts::TAU;
        for (k, beta_l) in [4.730_040_745, 7.853_204_624, 10.995_607_838].iter().enumerate() {
            let euler = beta_l * beta_l * scale;
            for f in [f[4 + 2 * k], f[5 + 2 * k]] {
                assert!((f - euler).abs() < 1e-4 * euler, "mode {k}: {f} Hz against Euler–Bernoulli's {euler} Hz");
            }
        }
        // One more element is refused, naming the count and the limit.
        let mut over = rotor.clone();
        over.elements.push(over.elements[0].clone());
        assert_eq!(Reduced::new(&over, &spec).unwrap_err(), FlexError::TooManyElements { count: n + 1, limit: n });
    }

    /// A free steel shaft, 0.4 m in 8 elements, with a disk at node 3.
    fn free_rotor() -> Rotor {
        let steel = Material { density: 7810.0, modulus: 211e9, shear_modulus: 81.2e9 };
        Rotor {
            elements: (0..8).map(|_| ShaftElement::cylinder(0.05, 0.0, 0.04, steel)).collect(),
            disks: vec![crate::flex::Disk { node: 3, mass: 3.0, diametral_inertia: 4e-3, polar_inertia: 7e-3 }],
            bearings: vec![],
            alpha: 0.0,
            beta: 0.0,
        }
    }

    fn spec(zeta: f64) -> Reduction {
        Reduction {
            cutoff_hz: 3000.0,
            force_nodes: vec![1, 7],
            static_correction: true,
            gyroscopic_correction: true,
            modal_damping: zeta,
        }
    }

    /// A free rotor keeps its four rigid-body modes at 0 Hz; in a frame accelerating at g it
    /// falls as a body, every node at −g; a force at a node accelerates the centre of mass by
    /// F/M (the rigid-body modes span the rigid motion exactly).
    #[test]
    fn a_free_rotor_falls_and_is_pushed_as_a_body() {
        let rotor = free_rotor();
        let reduced = Reduced::new(&rotor, &spec(0.02)).unwrap();
        assert_eq!(reduced.kinds.iter().filter(|k| **k == Kind::Rigid).count(), RIGID_MODES);
        let r = reduced.size();
        let mut d = vec![0.0; 2 * r];
        reduced.derivative(&vec![0.0; 2 * r], 300.0, &[[0.0; 2], [0.0; 2]], [0.0, 9.81], &mut d);
        let acc = &reduced.basis * DVector::from_column_slice(&d[r..]);
        for node in 0..rotor.node_count() {
            assert!((acc[4 * node + 1] + 9.81).abs() < 1e-9, "node {node}: {}", acc[4 * node + 1]);
            assert!(acc[4 * node].abs() < 1e-9, "node {node}: {}", acc[4 * node]);
        }
        reduced.derivative(&vec![0.0; 2 * r], 300.0, &[[5.0, 0.0], [0.0, 0.0]], [0.0, 0.0], &mut d);
        let acc = &reduced.basis * DVector::from_column_slice(&d[r..]);
        let m = rotor.matrices().mass;
        let rx = DVector::from_fn(rotor.dof(), |i, _| if i % 4 == 0 { 1.0 } else { 0.0 });
        let centre = (rx.transpose() * &m * &acc)[0] / rotor.mass();
        assert!((centre - 5.0 / rotor.mass()).abs() < 1e-9 * centre.abs(), "{centre}");
    }

    /// The modal damping ratio is each flexible mode's at rest; the accessors read the expanded
    /// state at a node.
    #[test]
    fn modal_damping_is_the_modes_damping_ratio_and_accessors_read_the_nodes() {
        let rotor = free_rotor();
        let reduced = Reduced::new(&rotor, &spec(0.02)).unwrap();
        let modes = reduced.linear().modes(0.0, 4).unwrap();
        for m in &modes {
            assert!((m.damping_ratio - 0.02).abs() < 1e-9, "{m:?}");
        }
        let r = reduced.size();
        let state: Vec<f64> = (0..2 * r).map(|k| (k as f64 * 0.37).sin() * 1e-6).collect();
        let q = reduced.expand(&state);
        let v = &reduced.basis * DVector::from_column_slice(&state[r..]);
        let [x, y] = reduced.displacement(&state, 5);
        let [vx, vy] = reduced.velocity(&state, 5);
        let [a, b] = reduced.rotation(&state, 5);
        assert_eq!([x, y, a, b], [q[20], q[21], q[22], q[23]]);
        assert_eq!([vx, vy], [v[20], v[21]]);
    }

    /// The rates' matrix formed once at a held speed gives the derivative the terms formed at
    /// each evaluation give, to the bit, at that speed; at any other speed the held matrix is
    /// not used (the derivative is the unheld one's, and differs from the held speed's).
    #[test]
    fn a_held_speed_gives_the_same_derivative_to_the_bit() {
        let rotor = free_rotor();
        let plain = Reduced::new(&rotor, &spec(0.02)).unwrap();
        let speed = 2.0 * std::f64::consts::PI * 300.0;
        let held = plain.clone().hold_speed(speed);
        let r = plain.size();
        let state: Vec<f64> = (0..2 * r).map(|k| (k as f64 * 0.61).cos() * 1e-5).collect();
        let forces = [[12.0, -3.0], [-7.5, 40.0]];
        let run = |red: &Reduced, w: f64| {
            let mut d = vec![0.0; 2 * r];
            red.derivative(&state, w, &forces, [0.3, 9.81], &mut d);
            d.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        };
        assert_eq!(run(&held, speed), run(&plain, speed));
        assert_eq!(run(&held, 0.5 * speed), run(&plain, 0.5 * speed));
        assert_ne!(run(&held, 0.5 * speed), run(&held, speed), "the speed changes the rates' terms");
    }
}
