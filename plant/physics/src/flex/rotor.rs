//! The finite-element rotor (MODEL.md §13): shaft elements end to end, rigid disks and linear
//! bearings at nodes, and the global matrices `M`, `K`, `C`, `G` of
//! `M q̈ + (C + Ω G) q̇ + K q = f` on four degrees of freedom per node, `[x, y, α, β]`
//! (node `n`'s `x` is `q[4n]`).

use super::band::{Band, HALF_BAND};
use super::shaft::ShaftElement;
use super::FlexError;
use nalgebra::DMatrix;

/// Degrees of freedom per node: x, y, α, β.
pub const DOF_PER_NODE: usize = 4;

/// A rigid disk at a node.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Disk {
    /// The node (0 at the shaft's left end).
    pub node: usize,
    /// Mass m (kg).
    pub mass: f64,
    /// Diametral (transverse) moment of inertia I_d (kg·m²).
    pub diametral_inertia: f64,
    /// Polar moment of inertia I_p (kg·m²).
    pub polar_inertia: f64,
}

/// A linear bearing (or any linear support to the ground) at a node: force
/// `−K (x, y) − C (ẋ, ẏ) − M (ẍ, ÿ)` with 2×2 coefficient matrices, rows and columns x, y.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LinearBearing {
    /// The node.
    pub node: usize,
    /// Stiffness `[[k_xx, k_xy], [k_yx, k_yy]]` (N/m).
    pub stiffness: [[f64; 2]; 2],
    /// Damping `[[c_xx, c_xy], [c_yx, c_yy]]` (N·s/m).
    pub damping: [[f64; 2]; 2],
    /// Added mass `[[m_xx, m_xy], [m_yx, m_yy]]` (kg).
    pub mass: [[f64; 2]; 2],
}

impl LinearBearing {
    /// An isotropic spring of stiffness `k` (N/m) at `node`, no damping.
    pub fn spring(node: usize, k: f64) -> Self {
        LinearBearing { node, stiffness: [[k, 0.0], [0.0, k]], damping: [[0.0; 2]; 2], mass: [[0.0; 2]; 2] }
    }
}

/// The rotor: shaft elements in order (element `i` joins nodes `i` and `i + 1`), disks,
/// bearings, and the rotor's own proportional damping `C₀ = α M₀ + β K₀` on the shaft and disks.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Rotor {
    /// Shaft elements, left to right.
    pub elements: Vec<ShaftElement>,
    /// Rigid disks.
    pub disks: Vec<Disk>,
    /// Linear bearings.
    pub bearings: Vec<LinearBearing>,
    /// Mass-proportional damping factor of the whole rotor (1/s).
    pub alpha: f64,
    /// Stiffness-proportional damping factor of the whole rotor (s).
    pub beta: f64,
}

/// The global matrices (ndof × ndof).
#[derive(Clone, Debug, PartialEq)]
pub struct Matrices {
    /// Mass M.
    pub mass: DMatrix<f64>,
    /// Stiffness K (shaft and bearings).
    pub stiffness: DMatrix<f64>,
    /// Damping C (proportional damping and bearings).
    pub damping: DMatrix<f64>,
    /// Gyroscopic G (multiplied by the spin Ω).
    pub gyroscopic: DMatrix<f64>,
}

impl Rotor {
    /// Number of nodes (elements + 1).
    pub fn node_count(&self) -> usize {
        self.elements.len() + 1
    }

    /// Number of degrees of freedom.
    pub fn dof(&self) -> usize {
        DOF_PER_NODE * self.node_count()
    }

    /// Axial position z of each node from the left end (m).
    pub fn node_positions(&self) -> Vec<f64> {
        let mut z = Vec::with_capacity(self.node_count());
        z.push(0.0);
        for el in &self.elements {
            z.push(z.last().copied().unwrap_or(0.0) + el.length);
        }
        z
    }

    /// Whole mass (kg): shaft and disks.
    pub fn mass(&self) -> f64 {
        self.elements.iter().map(ShaftElement::mass).sum::<f64>() + self.disks.iter().map(|d| d.mass).sum::<f64>()
    }

    /// Checks the geometry, materials and node numbers; each error names the element or key,
    /// its value and unit.
    pub fn validate(&self) -> Result<(), FlexError> {
        if self.elements.is_empty() {
            return Err(FlexError::NoElements);
        }
        if self.elements.len() > super::MAX_ELEMENTS {
            return Err(FlexError::TooManyElements { count: self.elements.len(), limit: super::MAX_ELEMENTS });
        }
        for (i, el) in self.elements.iter().enumerate() {
            let at = |key: &'static str| (format!("shaft element {i}"), key);
            let positive = |key: &'static str, v: f64| -> Result<(), FlexError> {
                if v.is_finite() && v > 0.0 {
                    Ok(())
                } else {
                    let (element, key) = at(key);
                    Err(FlexError::NotPositive { element, key, value: v, unit: "m" })
                }
            };
            positive("length", el.length)?;
            positive("outer diameter (left)", el.outer_left)?;
            positive("outer diameter (right)", el.outer_right)?;
            for (key, inner, outer) in [
                ("inner diameter (left)", el.inner_left, el.outer_left),
                ("inner diameter (right)", el.inner_right, el.outer_right),
            ] {
                if !(inner.is_finite() && inner >= 0.0 && inner < outer) {
                    let (element, key) = at(key);
                    return Err(FlexError::InnerDiameter { element, key, value: inner, outer });
                }
            }
            let m = &el.material;
            for (key, v, unit) in [
                ("density", m.density, "kg/m³"),
                ("modulus", m.modulus, "Pa"),
                ("shear modulus", m.shear_modulus, "Pa"),
            ] {
                if !(v.is_finite() && v > 0.0) {
                    return Err(FlexError::Material { element: format!("shaft element {i}"), key, value: v, unit });
                }
            }
        }
        let nodes = self.node_count();
        for (i, d) in self.disks.iter().enumerate() {
            if d.node >= nodes {
                return Err(FlexError::NodeOutOfRange { what: format!("disk {i}"), node: d.node, nodes });
            }
            for (key, v, unit) in
                [("mass", d.mass, "kg"), ("Id", d.diametral_inertia, "kg·m²"), ("Ip", d.polar_inertia, "kg·m²")]
            {
                if !(v.is_finite() && v >= 0.0) {
                    return Err(FlexError::NotPositive { element: format!("disk {i}"), key, value: v, unit });
                }
            }
        }
        for (i, b) in self.bearings.iter().enumerate() {
            if b.node >= nodes {
                return Err(FlexError::NodeOutOfRange { what: format!("bearing {i}"), node: b.node, nodes });
            }
        }
        Ok(())
    }

    /// The global matrices, assembled element by element.
    pub fn matrices(&self) -> Matrices {
        let n = self.dof();
        let mut mass = DMatrix::zeros(n, n);
        let mut stiffness = DMatrix::zeros(n, n);
        let mut damping = DMatrix::zeros(n, n);
        let mut gyroscopic = DMatrix::zeros(n, n);
        for (i, el) in self.elements.iter().enumerate() {
            let at = DOF_PER_NODE * i;
            let add = |target: &mut DMatrix<f64>, m: super::shaft::Matrix8| {
                let mut view = target.view_mut((at, at), (8, 8));
                view += m;
            };
            add(&mut mass, el.mass_matrix());
            add(&mut stiffness, el.stiffness_matrix());
            add(&mut damping, el.damping_matrix());
            add(&mut gyroscopic, el.gyroscopic_matrix());
        }
        for d in &self.disks {
            let at = DOF_PER_NODE * d.node;
            mass[(at, at)] += d.mass;
            mass[(at + 1, at + 1)] += d.mass;
            mass[(at + 2, at + 2)] += d.diametral_inertia;
            mass[(at + 3, at + 3)] += d.diametral_inertia;
            gyroscopic[(at + 2, at + 3)] += d.polar_inertia;
            gyroscopic[(at + 3, at + 2)] -= d.polar_inertia;
        }
        if self.alpha != 0.0 || self.beta != 0.0 {
            damping += &mass * self.alpha + &stiffness * self.beta;
        }
        for b in &self.bearings {
            let at = DOF_PER_NODE * b.node;
            for r in 0..2 {
                for c in 0..2 {
                    stiffness[(at + r, at + c)] += b.stiffness[r][c];
                    damping[(at + r, at + c)] += b.damping[r][c];
                    mass[(at + r, at + c)] += b.mass[r][c];
                }
            }
        }
        Matrices { mass, stiffness, damping, gyroscopic }
    }
}

/// The global matrices by their band ([`super::band`]): what [`Rotor::matrices`] assembles,
/// entry by entry in the same order, in `O(n)` storage.
#[derive(Clone, Debug, PartialEq)]
pub struct BandMatrices {
    /// Mass M.
    pub mass: Band,
    /// Stiffness K (shaft and bearings).
    pub stiffness: Band,
    /// Damping C (proportional damping and bearings).
    pub damping: Band,
    /// Gyroscopic G (multiplied by the spin Ω).
    pub gyroscopic: Band,
}

impl Rotor {
    /// The global matrices as bands, assembled as [`Rotor::matrices`] assembles the dense ones.
    pub fn band_matrices(&self) -> BandMatrices {
        let n = self.dof();
        let zero = || Band::zeros(n, HALF_BAND);
        let (mut mass, mut stiffness, mut damping, mut gyroscopic) = (zero(), zero(), zero(), zero());
        for (i, el) in self.elements.iter().enumerate() {
            let at = DOF_PER_NODE * i;
            let add = |target: &mut Band, m: super::shaft::Matrix8| {
                for r in 0..8 {
                    for c in 0..8 {
                        target.add(at + r, at + c, m[(r, c)]);
                    }
                }
            };
            add(&mut mass, el.mass_matrix());
            add(&mut stiffness, el.stiffness_matrix());
            add(&mut damping, el.damping_matrix());
            add(&mut gyroscopic, el.gyroscopic_matrix());
        }
        for d in &self.disks {
            let at = DOF_PER_NODE * d.node;
            mass.add(at, at, d.mass);
            mass.add(at + 1, at + 1, d.mass);
            mass.add(at + 2, at + 2, d.diametral_inertia);
            mass.add(at + 3, at + 3, d.diametral_inertia);
            gyroscopic.add(at + 2, at + 3, d.polar_inertia);
            gyroscopic.add(at + 3, at + 2, -d.polar_inertia);
        }
        if self.alpha != 0.0 || self.beta != 0.0 {
            damping = damping.plus(self.alpha, &mass).plus(self.beta, &stiffness);
        }
        for b in &self.bearings {
            let at = DOF_PER_NODE * b.node;
            for r in 0..2 {
                for c in 0..2 {
                    stiffness.add(at + r, at + c, b.stiffness[r][c]);
                    damping.add(at + r, at + c, b.damping[r][c]);
                    mass.add(at + r, at + c, b.mass[r][c]);
                }
            }
        }
        BandMatrices { mass, stiffness, damping, gyroscopic }
    }
}

/// The rotor as a rigid body (from its mass and gyroscopic matrices, so the shaft's distributed
/// mass and rotary inertia count as the finite elements have them).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct RigidBody {
    /// Mass M (kg).
    pub mass: f64,
    /// Axial position of the centre of mass from the left end (m).
    pub centre: f64,
    /// Transverse moment of inertia about the centre of mass I_t (kg·m²).
    pub transverse_inertia: f64,
    /// Polar moment of inertia I_p (kg·m²).
    pub polar_inertia: f64,
}

impl Rotor {
    /// The rigid-body properties: with `r_x` the rigid translation along x and `t_β`, `t_α` the
    /// rigid tilts about the centre of mass (`x = z − z_G, β = 1` and `y = −(z − z_G), α = 1`),
    /// `M = r_xᵀ M r_x`, `z_G M = r_xᵀ M (x = z, β = 1)`, `I_t = t_βᵀ M t_β`, `I_p = t_αᵀ G t_β`.
    /// The bearings' added masses are left out.
    pub fn rigid_body(&self) -> RigidBody {
        let mut without = self.clone();
        without.bearings.clear();
        // `uᵀ M v` and `uᵀ G v`: from the dense matrices up to the dense limit (the shipped
        // scenes' figures as they were), from the bands above it.
        let (dense, band) = if super::dense_model(self) {
            (Some(without.matrices()), None)
        } else {
            (None, Some(without.band_matrices()))
        };
        let form = |gyro: bool, u: &nalgebra::DVector<f64>, v: &nalgebra::DVector<f64>| -> f64 {
            match (&dense, &band) {
                (Some(m), _) => (u.transpose() * if gyro { &m.gyroscopic } else { &m.mass } * v)[0],
                (_, Some(m)) => {
                    let a = if gyro { &m.gyroscopic } else { &m.mass };
                    let v = nalgebra::DMatrix::from_column_slice(v.len(), 1, v.as_slice());
                    u.dot(&a.mul(&v).column(0))
                }
                _ => unreachable!("one of the two"),
            }
        };
        let z = self.node_positions();
        let n = self.dof();
        let vector = |f: &dyn Fn(usize, f64) -> [f64; 4]| {
            let mut v = nalgebra::DVector::zeros(n);
            for (k, &zk) in z.iter().enumerate() {
                let e = f(k, zk);
                for (i, value) in e.iter().enumerate() {
                    v[DOF_PER_NODE * k + i] = *value;
                }
            }
            v
        };
        let rx = vector(&|_, _| [1.0, 0.0, 0.0, 0.0]);
        let mass = form(false, &rx, &rx);
        let tilt0 = vector(&|_, zk| [zk, 0.0, 0.0, 1.0]);
        let centre = form(false, &rx, &tilt0) / mass;
        let t_beta = vector(&|_, zk| [zk - centre, 0.0, 0.0, 1.0]);
        let t_alpha = vector(&|_, zk| [0.0, -(zk - centre), 1.0, 0.0]);
        RigidBody {
            mass,
            centre,
            transverse_inertia: form(false, &t_beta, &t_beta),
            polar_inertia: form(true, &t_alpha, &t_beta),
        }
    }
}
