//! A rotor model's linear mechanics about the centre (`plant linear`'s first block): `ẋ = A x +
//! B i` on `x = [q, q̇]`, the sensors' displacements `C_s x` and the actuators' `C_a x`, one row
//! per axis, with its states named. Each model gives its own ([`crate::config::RotorParams::mechanics`]);
//! the rigid ones through [`rigid`].

use nalgebra::DMatrix;
use serde::Serialize;

/// A named signal or state with its unit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Signal {
    /// Name (an identifier: letters, digits, `_`).
    pub name: String,
    /// SI unit.
    pub unit: String,
    /// What it is.
    pub description: String,
}

impl Signal {
    /// A signal named `name` in `unit`, described by `description`.
    pub fn new(name: impl Into<String>, unit: &str, description: impl Into<String>) -> Self {
        Signal { name: name.into(), unit: unit.into(), description: description.into() }
    }
}

/// The mechanical part of a rotor's linear plant.
#[derive(Clone, Debug)]
pub struct Mechanics {
    /// `A` on `x = [q, q̇]`.
    pub a: DMatrix<f64>,
    /// `B` from the axes' currents.
    pub b: DMatrix<f64>,
    /// The sensors' displacements `C_s` (a row per axis).
    pub sensor: DMatrix<f64>,
    /// The actuators' displacements `C_a` (a row per axis).
    pub actuator: DMatrix<f64>,
    /// The states, in `x`'s order.
    pub states: Vec<Signal>,
    /// What the mechanics hold, in words (the linear plant's first part).
    pub what: String,
}

/// A rigid rotor's mechanics: `M q̈ + G q̇ = Φ_aᵀ (K_i i + K_s Φ_a q)`, sensors `Φ_s q`
/// (`Φ_a`, `Φ_s` one row per axis; `ks`, `ki` per axis, the first `Φ_a.nrows()` used).
#[allow(clippy::too_many_arguments)]
pub fn rigid(
    mass: &DMatrix<f64>,
    gyro: &DMatrix<f64>,
    actuator: &DMatrix<f64>,
    sensor: &DMatrix<f64>,
    ks: [f64; 4],
    ki: [f64; 4],
    states: Vec<Signal>,
    what: String,
) -> Mechanics {
    let (dof, axes) = (mass.nrows(), actuator.nrows());
    let inv = DMatrix::from_diagonal(&mass.diagonal().map(|m| 1.0 / m));
    let ks = DMatrix::from_diagonal(&nalgebra::DVector::from_fn(axes, |k, _| ks[k]));
    let ki = DMatrix::from_diagonal(&nalgebra::DVector::from_fn(axes, |k, _| ki[k]));
    let mut a = DMatrix::zeros(2 * dof, 2 * dof);
    a.view_mut((0, dof), (dof, dof)).fill_with_identity();
    a.view_mut((dof, 0), (dof, dof)).copy_from(&(&inv * actuator.transpose() * ks * actuator));
    a.view_mut((dof, dof), (dof, dof)).copy_from(&(-(&inv * gyro)));
    let mut b = DMatrix::zeros(2 * dof, axes);
    b.view_mut((dof, 0), (dof, axes)).copy_from(&(&inv * actuator.transpose() * ki));
    let pad = |rows: &DMatrix<f64>| {
        let mut m = DMatrix::zeros(axes, 2 * dof);
        m.view_mut((0, 0), (axes, dof)).copy_from(rows);
        m
    };
    Mechanics { a, b, sensor: pad(sensor), actuator: pad(actuator), states, what }
}
