//! Where a flexible rotor starts (issue 38 item 5): at rest, the shaft sagged under gravity on
//! its bearings, the bias currents and the levitated loop, so that with no shock and no
//! unbalance nothing moves.
//!
//! The rigid rotors start centred (the bias current carries each plane's share of the weight) or
//! sagged by `m g / k_e` ([`crate::two_plane::initial`]): a rigid body is in equilibrium there.
//! A shaft is not: gravity acts on every section and the AMBs push at two nodes, so the shaft
//! bends, and its sensors see the bend, to which the loop answers. The equilibrium is the zero
//! of the reduced model's accelerations with every rate zero: a linear solve on the reduced
//! coordinates, `J η = −a(0)`, with `J` the accelerations' Jacobian in `η`. `J` is taken from
//! the model's own derivative ([`Model::evaluate`], the levitation design's continuous PD on
//! each plane, a quiet housing, no unbalance), column by column: the derivative is affine in
//! `η` for the linear force law (the columns are exact to round-off), and a Newton step or two
//! more settle the nonlinear law. Taking it from the derivative rather than assembling it again
//! means the start is the equilibrium of exactly what the run integrates (the file's bearings,
//! the static correction, the AMB's `k_s`, the sensor nodes).

use super::machine::{ix, Model, Params, State};
use crate::model::Control;
use controller::{PdDesign, PdGains};
use nalgebra::{DMatrix, DVector};

/// Newton steps at most (the linear force law needs one; the nonlinear one settles in a few).
const NEWTON_STEPS: usize = 4;
/// Step of a Jacobian column in a reduced coordinate (mass-normalised: about 0.2 µm at a node of
/// a 20 kg rotor, where the sag is some µm; the derivative is affine, so its size hardly matters).
const COLUMN_STEP: f64 = 1e-6;

/// The reduced coordinates `η` (the basis' `r` of them) of the static equilibrium of `params`'s
/// shaft under gravity, held by each plane's levitation design `design` (its continuous PD, bias
/// currents included) with the races at rest as `rest` has them (its reduced coordinates and
/// rates are not read). `None` when the levitated shaft has no equilibrium the solve can find
/// (a singular Jacobian, or a residual that does not fall).
pub fn static_sag(params: &Params, design: &PdDesign, rest: &State) -> Option<Vec<f64>> {
    static_sag_with(params, design, [None; 2], rest)
}

/// [`static_sag`] held at rest by each plane's law of static gain `static_kp` where given: the
/// run's law at rest, `i = bias − A_a k₀ A_s d` with `k₀` its gain at zero frequency (V/V, as
/// `PdGains::kp`) in place of the design's `k_p` (issue 38 item 3); the design's PD where `None`.
/// The derivative gain plays no part at rest.
pub fn static_sag_with(
    params: &Params,
    design: &PdDesign,
    static_kp: [Option<f64>; 2],
    rest: &State,
) -> Option<Vec<f64>> {
    let r = params.reduced.size();
    // Each plane's bias in its own axes (u, v) ([`crate::axes`]): the weight shared when turned.
    let gains = |p: &crate::model::Params, kp: Option<f64>| {
        PdGains::from_design(design, &p.loop_constants).ok().map(|g| PdGains {
            bias_a: p.axes.pair_to_plane(g.bias_a),
            kp: kp.unwrap_or(g.kp),
            ..g
        })
    };
    let planes = &params.machine.planes;
    let control = [
        Control::Continuous(gains(&planes[0].params, static_kp[0])?),
        Control::Continuous(gains(&planes[1].params, static_kp[1])?),
    ];
    // No unbalance and a quiet housing: the static loads only (gravity, the bias currents).
    let mut still = params.clone();
    still.machine.rotor.eccentricity = 0.0;
    let model = Model { params: still, base: Default::default(), control, race_parked: [false; 2] };
    let mut y = *rest;
    y[..ix::TR].fill(0.0);
    y[ix::V..ix::V + r].fill(0.0);
    // Only the reduced coordinates move; the races stay where `rest` has them.
    let accel =
        |y: &State| -> DVector<f64> { DVector::from_column_slice(&model.evaluate(0.0, y).dy[ix::V..ix::V + r]) };
    let mut a = accel(&y);
    let first = a.norm();
    for _ in 0..NEWTON_STEPS {
        let mut jac = DMatrix::zeros(r, r);
        for k in 0..r {
            let mut yk = y;
            yk[k] += COLUMN_STEP;
            jac.set_column(k, &((accel(&yk) - &a) / COLUMN_STEP));
        }
        let step = jac.lu().solve(&(-&a))?;
        for k in 0..r {
            y[k] += step[k];
        }
        let before = a.norm();
        a = accel(&y);
        // Round-off: the accelerations' terms are of the order of g and ω² η.
        // Settled: no better (or not a number), or down to round-off.
        let no_better = a.norm().partial_cmp(&before) != Some(std::cmp::Ordering::Less);
        if no_better || a.norm() <= 1e-12 * first.max(1.0) {
            break;
        }
    }
    let eta: Vec<f64> = y[..r].to_vec();
    (eta.iter().all(|v| v.is_finite()) && a.norm() <= 1e-6 * first.max(1e-9)).then_some(eta)
}
