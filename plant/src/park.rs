//! Parking the touchdown race while the rotor is clear of it
//! (`touchdown.race_when_clear = "parked"`, a model simplification).
//!
//! While the rotor – race gap is open, the race only rests on its balls: a 48 g ring on Hertz
//! contacts that rings at ~10⁴ rad/s and costs the 19 ball kernels per evaluation, though it
//! does not act on the rotor at all. Parking holds the race in the housing frame instead
//! (translation frozen, velocity zero; the spin still runs down under the drag) and skips the
//! support and contact kernels, so the derivative is cheap and without the stiff mode.
//!
//! **When.** The run loop decides at the start of each macro step `[t₀, t₀ + H]` and keeps the
//! decision over the step (the derivative stays smooth inside it). With `d` the rotor centre
//! relative to the race centre, `w` their relative velocity and `a` the rotor's acceleration
//! relative to the housing at `t₀`, the race is parked when
//!
//! ```text
//! |d| + 2 (|w| H + ½ (|a| + Δa_h) H²) + m  ≤  r₀,      m = 2 r_cl + r₀ / 20
//! ```
//!
//! `Δa_h` bounds the change of the housing acceleration over the step (sampled at `t₀`, the
//! midpoint and the end; exact for the smooth pulses, heuristic for recorded bases with
//! features shorter than a step, which the margin absorbs). The factor 2 covers the change of
//! the rotor's own acceleration over the step (bearing force, unbalance). The margin `m` covers
//! the race itself: the free race would move inside its clearance circle (radius r_cl plus a
//! Hertz deflection of well under a micrometre), and the parked race sits somewhere in that
//! circle, so the two can be up to 2 r_cl apart; r₀/20 is the safety on top.
//!
//! **Release.** When the test fails the race is released at `t₀`: either at rest on its supports
//! under gravity and the current housing acceleration ([`Release::Equilibrium`], what the free
//! race does during a slow shock, so it does not start ringing), or where it was parked, at
//! rest ([`Release::Held`]). `plant bench models` measures both.
//!
//! While parked the trace's ball force is zero (the support kernel is not evaluated) and the
//! race's position is the held one; only the rotor's rows are the model's.

use crate::model::{ix, Model, Params, Release, State};

/// Safety margin of the gap test (m): `2 r_cl + r₀/20` (see the module doc).
pub fn margin(p: &Params) -> f64 {
    2.0 * p.balls.clearance + p.contact.gap / 20.0
}

/// Whether the rotor stays clear of the race over the macro step `[t0, t0 + h]` by the margin,
/// from the state `y` at `t0` (see the module doc).
pub fn clear(model: &Model, t0: f64, h: f64, y: &State) -> bool {
    use ix::*;
    let p = &model.params;
    let d = (y[XR] - y[XB]).hypot(y[YR] - y[YB]);
    let w = (y[VXR] - y[VXB]).hypot(y[VYR] - y[VYB]);
    let dy = model.evaluate(t0, y).dy;
    let a = dy[VXR].hypot(dy[VYR]);
    let a0 = model.base.accel(t0);
    let change = |t: f64| {
        let a1 = model.base.accel(t);
        (a1[0] - a0[0]).hypot(a1[1] - a0[1])
    };
    let da = change(t0 + 0.5 * h).max(change(t0 + h));
    let travel = 2.0 * (w * h + 0.5 * (a + da) * h * h);
    d + travel + margin(p) <= p.contact.gap
}

/// Parks the race: its translational velocity relative to the housing is set to zero.
pub fn park(y: &mut State) {
    y[ix::VXB] = 0.0;
    y[ix::VYB] = 0.0;
}

/// Releases the race at time `t` with the state `release` says (see the module doc).
pub fn release(model: &Model, t: f64, y: &mut State, release: Release) {
    y[ix::VXB] = 0.0;
    y[ix::VYB] = 0.0;
    if release == Release::Held {
        return;
    }
    let p = &model.params;
    let a_h = model.base.accel(t);
    // The race feels −m_b (g ŷ + a_h) in the housing frame: it rests along that direction.
    let push = [-a_h[0], -(p.gravity + a_h[1])];
    let cage = crate::model::cage_angle(p, y[ix::TB]);
    let eps = rest_position(p, push, cage);
    y[ix::XB] = eps[0];
    y[ix::YB] = eps[1];
}

/// Where the race rests on its supports (m, relative to the housing) under the specific force
/// `push` (m/s², the acceleration the loads would give the free race), with the cage at `cage`
/// (rad): found by bisection along `push` on the support's force along it. With discrete balls
/// the force also has a small component across `push`, which is ignored.
pub fn rest_position(p: &Params, push: [f64; 2], cage: f64) -> [f64; 2] {
    let g = push[0].hypot(push[1]);
    let load = p.race_mass * g;
    if load == 0.0 {
        return [0.0; 2];
    }
    let u = [push[0] / g, push[1] / g];
    let resisting = |r: f64| {
        let f = p.race_support([r * u[0], r * u[1]], [0.0; 2], cage, 0.0).on_race;
        -(f[0] * u[0] + f[1] * u[1])
    };
    let (mut lo, mut hi) = (p.balls.clearance, p.balls.clearance + 1e-3);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if resisting(mid) > load {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let r = 0.5 * (lo + hi);
    [r * u[0], r * u[1]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::load_scene;
    use crate::model::{Control, N};
    use std::path::Path;

    fn model() -> Model {
        let scene = load_scene(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/paper-3g.toml"), &[]).unwrap();
        let gains = crate::run::design_gains(&scene).unwrap();
        Model { params: scene.params, base: scene.base, control: Control::Continuous(gains), race_parked: false }
    }

    /// Under gravity alone the rest position is the initial state's sag, straight down.
    #[test]
    fn rest_position_under_gravity_is_the_sag() {
        let m = model();
        let p = &m.params;
        let eps = rest_position(p, [0.0, -p.gravity], p.cage_phase);
        let sag = crate::initial::race_sag(p);
        assert!(eps[0].abs() < 1e-15, "{eps:?}");
        assert!((eps[1] - sag).abs() < 1e-12, "{} against {sag}", eps[1]);
    }

    /// A centred rotor at rest is clear; one a margin short of the race is not; a rotor moving
    /// fast towards the race is not clear even though it is far from it now.
    #[test]
    fn clear_bounds_the_closing_over_the_step() {
        let m = model();
        let h = 5e-5;
        let mut y: State = [0.0; N];
        y[ix::YB] = crate::initial::race_sag(&m.params);
        assert!(clear(&m, 0.0, h, &y));
        let gap = m.params.contact.gap;
        y[ix::YR] = y[ix::YB] + gap - 0.5 * margin(&m.params);
        assert!(!clear(&m, 0.0, h, &y));
        y[ix::YR] = y[ix::YB] + 0.5 * gap;
        assert!(clear(&m, 0.0, h, &y));
        y[ix::VYR] = 0.5 * gap / h; // would cross the rest of the gap within the step
        assert!(!clear(&m, 0.0, h, &y));
    }

    /// With the race parked the derivative freezes its translation and matches the full model
    /// for the rotor wherever the gap is open.
    #[test]
    fn parked_derivative_matches_the_rotor_rows_and_freezes_the_race() {
        let mut m = model();
        let mut y: State = [0.0; N];
        y[ix::YB] = crate::initial::race_sag(&m.params);
        y[ix::XR] = 3e-5;
        y[ix::VYR] = 0.01;
        y[ix::WR] = m.params.speed;
        y[ix::WB] = 50.0;
        let full = m.evaluate(0.0, &y).dy;
        m.race_parked = true;
        let parked = m.evaluate(0.0, &y).dy;
        for i in [ix::XR, ix::YR, ix::TR, ix::VXR, ix::VYR, ix::WR, ix::TB, ix::WB] {
            assert_eq!(parked[i], full[i], "component {i}");
        }
        for i in [ix::XB, ix::YB, ix::VXB, ix::VYB] {
            assert_eq!(parked[i], 0.0, "component {i}");
        }
    }
}
