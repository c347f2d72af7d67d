//! The discrete-time system the digital controller sees: the continuous plant under a
//! zero-order hold of the controller's period, and its command delay as extra states.
//!
//! `Φ = e^{A T}`, `Γ = ∫₀ᵀ e^{A s} ds B`, both from the exponential of the augmented matrix
//! `[[A, B], [0, 0]] T` (Van Loan; what `plant_physics::flex::linear` discretises the
//! flexible open loop with, and what python-control's `sample_system(…, 'zoh')` computes).
//! The command computed at tick `k` is applied `d = controller.delay_samples` ticks later and
//! held for one period: `d` more states per axis, `w₁ … w_d`, with `w₁⁺ = u`, `w_{j+1}⁺ = w_j`,
//! and the plant driven by `w_d`:
//!
//! ```text
//! | x⁺  |   | Φ  0 … 0  Γ | | x   |   | 0 |
//! | w₁⁺ | = | 0  0 …   0 | | w₁  | + | I | u,      y = [C 0 … 0] [x; w]
//! | w₂⁺ |   | 0  I …   0 | | …   |   | 0 |
//! ```
//!
//! (`d = 0`: `x⁺ = Φ x + Γ u`). The sensor is read at the tick, before the command: `D = 0`.

use super::model::{LinearPlant, Signal, System};
use nalgebra::DMatrix;

/// The plant discretised at `period` (s) with `delay` ticks of command delay; the states are
/// the continuous plant's, then the delay line's (newest first).
pub fn zoh(plant: &LinearPlant, period: f64, delay: u32) -> (System, Vec<Signal>) {
    let s = &plant.system;
    let (n, m, p) = (s.a.nrows(), s.b.ncols(), s.c.nrows());
    let mut aug = DMatrix::zeros(n + m, n + m);
    aug.view_mut((0, 0), (n, n)).copy_from(&(&s.a * period));
    aug.view_mut((0, n), (n, m)).copy_from(&(&s.b * period));
    let e = aug.exp();
    let (phi, gamma) = (e.view((0, 0), (n, n)).into_owned(), e.view((0, n), (n, m)).into_owned());
    let d = delay as usize;
    let size = n + m * d;
    let mut a = DMatrix::zeros(size, size);
    let mut b = DMatrix::zeros(size, m);
    a.view_mut((0, 0), (n, n)).copy_from(&phi);
    if d == 0 {
        b.copy_from(&gamma);
    } else {
        a.view_mut((0, n + m * (d - 1)), (n, m)).copy_from(&gamma);
        b.view_mut((n, 0), (m, m)).fill_with_identity();
        for j in 1..d {
            a.view_mut((n + m * j, n + m * (j - 1)), (m, m)).fill_with_identity();
        }
    }
    let mut c = DMatrix::zeros(p, size);
    c.view_mut((0, 0), (p, n)).copy_from(&s.c);
    let mut states = plant.states.clone();
    for j in 1..=d {
        for u in &plant.inputs {
            states.push(Signal {
                name: format!("{}_delay_{j}", u.name),
                unit: u.unit.clone(),
                description: format!("{}, computed {j} tick(s) before", u.description),
            });
        }
    }
    (System { a, b, c, d: DMatrix::zeros(p, m) }, states)
}
