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
use nalgebra::Vector2;
use shock_table::Programme;

/// Safety margin of the gap test (m): `2 r_cl + r₀/20` (see the module doc).
pub fn margin(p: &Params) -> f64 {
    2.0 * p.balls.clearance + p.contact.gap / 20.0
}

/// `(y[i], y[i + 1])` as a vector.
fn pair(y: &State, i: usize) -> Vector2<f64> {
    Vector2::new(y[i], y[i + 1])
}

/// `|v|` by `hypot` (as before: the decisions below are thresholds, kept bit for bit).
fn length(v: Vector2<f64>) -> f64 {
    v.x.hypot(v.y)
}

/// Whether the rotor stays clear of the race over the macro step `[t0, t0 + h]` by the margin,
/// from the state `y` at `t0` (see the module doc).
pub fn clear(model: &Model, t0: f64, h: f64, y: &State) -> bool {
    use ix::*;
    let dy = model.evaluate(t0, y).dy;
    let motion = GapMotion {
        distance: length(pair(y, XR) - pair(y, XB)),
        speed: length(pair(y, VXR) - pair(y, VXB)),
        accel: length(pair(&dy, VXR)),
    };
    stays_open(&model.params, &model.base, t0, h, motion)
}

/// The rotor's motion relative to one race at the start of a macro step, in that bearing plane.
#[derive(Clone, Copy, Debug)]
pub struct GapMotion {
    /// `|d|`, the distance between the rotor's and the race's centres (m).
    pub distance: f64,
    /// `|w|`, their relative speed (m/s).
    pub speed: f64,
    /// `|a|`, the rotor's acceleration relative to the housing (m/s²).
    pub accel: f64,
}

/// The test of the module doc for one bearing plane of parameters `p`, the housing moved by
/// `base`: whether the gap stays open by the margin over `[t0, t0 + h]`.
pub fn stays_open(p: &Params, base: &Programme, t0: f64, h: f64, m: GapMotion) -> bool {
    let a0 = Vector2::from(base.accel(t0));
    let change = |t: f64| length(Vector2::from(base.accel(t)) - a0);
    let da = change(t0 + 0.5 * h).max(change(t0 + h));
    let travel = 2.0 * (m.speed * h + 0.5 * (m.accel + da) * h * h);
    m.distance + travel + margin(p) <= p.contact.gap
}

/// Parks the race: its translational velocity relative to the housing is set to zero.
pub fn park(y: &mut State) {
    park_race(y, ix::XB);
}

/// Parks the race whose position pair starts at `x` in a `[positions; velocities]` state.
pub fn park_race<const M: usize>(y: &mut [f64; M], x: usize) {
    y[x + M / 2] = 0.0;
    y[x + 1 + M / 2] = 0.0;
}

/// Releases the race at time `t` with the state `release` says (see the module doc).
pub fn release(model: &Model, t: f64, y: &mut State, release: Release) {
    release_race(&model.params, &model.base, t, y, ix::XB, release);
}

/// Releases the race of parameters `p` whose position pair starts at `x` (its angle at `x + 2`)
/// in a `[positions; velocities]` state, at time `t`, as `release` says.
pub fn release_race<const M: usize>(
    p: &Params,
    base: &Programme,
    t: f64,
    y: &mut [f64; M],
    x: usize,
    release: Release,
) {
    park_race(y, x);
    if release == Release::Held {
        return;
    }
    let a_h = Vector2::from(base.accel(t));
    // The race feels −m_b (g ŷ + a_h) in the housing frame: it rests along that direction.
    let push = -a_h - Vector2::new(0.0, p.gravity);
    let cage = crate::model::cage_angle(p, y[x + 2]);
    let eps = rest_position(p, push, cage);
    y[x] = eps.x;
    y[x + 1] = eps.y;
}

/// Where the race rests on its supports (m, relative to the housing) under the specific force
/// `push` (m/s², the acceleration the loads would give the free race), with the cage at `cage`
/// (rad): found by bisection along `push` on the support's force along it. With discrete balls
/// the force also has a small component across `push`, which is ignored.
pub fn rest_position(p: &Params, push: Vector2<f64>, cage: f64) -> Vector2<f64> {
    let g = length(push);
    let load = p.race_mass * g;
    if load == 0.0 {
        return Vector2::zeros();
    }
    let u = push / g;
    let resisting = |r: f64| -p.race_support(u * r, Vector2::zeros(), cage, 0.0).on_race.dot(&u);
    let (mut lo, mut hi) = (p.balls.clearance, p.balls.clearance + 1e-3);
    // At most 200 halvings, but a 1 mm bracket around a rest position of ~10 µm reaches
    // adjacent floating-point numbers after about 58 (1e-3 / ulp(1e-5) ≈ 2^58): an iteration
    // that changes neither end is a fixed point that every later one repeats, so stopping
    // there gives the 200-halving answer bit for bit (tests/race.rs) with less than a third
    // of the support evaluations, which a realtime tick that releases its race pays.
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        let (l, h) = if resisting(mid) > load { (lo, mid) } else { (mid, hi) };
        if (l, h) == (lo, hi) {
            break;
        }
        (lo, hi) = (l, h);
    }
    u * (0.5 * (lo + hi))
}
