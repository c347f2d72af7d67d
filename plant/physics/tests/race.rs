//! The touchdown race on its supports, through the model's derivative: Palmgren's drag spins it
//! down by its torque at the race's speed and support load, and a fixed cage keeps its balls
//! where they were put while the race turns.

mod common;

use common::{model, study_params, BALL_STIFFNESS, CLEARANCE, PITCH_DIAMETER_MM, RACE_INERTIA, RACE_MASS};
use plant_physics::force::drag::RaceDrag;
use plant_physics::force::lumped::LumpedSupport;
use plant_physics::model::{cage_angle, ix, Cage, Support, N};
use std::f64::consts::TAU;

/// Palmgren's torque magnitude (N·m), written from the formula (N·mm, d_m in mm, n in rpm, ν_0 in
/// cSt): `M_0 = 10⁻⁷ f_0 (ν_0 n)^(2/3) d_m³` for `ν_0 n ≥ 2000`, else `160·10⁻⁷ f_0 d_m³`;
/// `M_1 = f_1 P_1 d_m`.
fn palmgren_n_m(f0: f64, nu0: f64, f1: f64, rpm: f64, load_n: f64) -> f64 {
    let dm3 = PITCH_DIAMETER_MM.powi(3);
    let m0 = if nu0 * rpm >= 2000.0 { 1e-7 * f0 * (nu0 * rpm).powf(2.0 / 3.0) * dm3 } else { 160e-7 * f0 * dm3 };
    (m0 + f1 * load_n * PITCH_DIAMETER_MM) * 1e-3
}

/// The race pressed `depth` (m) beyond the clearance onto a lumped Hertz ring of stiffness 10¹⁰
/// N/m^1.5 (one law, so the load is `K δ^1.5` in closed form), at rest in translation, spinning
/// at `rpm`; the rotor centred (no contact). Its spin decelerates at `−M(n, P)/J_b`.
#[test]
fn palmgren_drag_decelerates_the_race_by_its_torque_at_its_speed_and_support_load() {
    let (f0, nu0, f1) = (2.0, 20.0, 5e-4);
    let mut p = study_params();
    p.drag = RaceDrag::Palmgren { f0, nu0_cst: nu0, f1, pitch_diameter_mm: PITCH_DIAMETER_MM, reg_speed: 1.0 };
    let k = 1e10;
    p.support =
        Support::Lumped(LumpedSupport { clearance: CLEARANCE, stiffness: k, damping_max: 750.0, damping_depth: 1e-5 });
    let mut m = model(p);
    // (speed, depth): the viscous form without and with load, the slow constant form with load
    // (ν_0 n = 300 < 2000), a fast race on a light load, and a race turning backwards.
    for (rpm, depth) in [(3000.0_f64, 0.0_f64), (3000.0, 5e-6), (15.0, 5e-6), (30_000.0, 2e-6), (-3000.0, 5e-6)] {
        let mut y = [0.0; N];
        y[ix::YB] = -(CLEARANCE + depth);
        y[ix::WB] = rpm * TAU / 60.0;
        y[ix::WR] = m.params.speed;
        let ev = m.evaluate(0.0, &y);
        let load = k * depth.powf(1.5);
        assert_eq!(ev.contact.normal, 0.0);
        assert!((ev.balls.on_race.norm() - load).abs() <= 1e-12 * load.max(1.0), "{rpm} rpm: {:?}", ev.balls);
        let torque = -palmgren_n_m(f0, nu0, f1, rpm.abs(), load).copysign(rpm);
        let expected = torque / RACE_INERTIA;
        assert!(
            (ev.dy[ix::WB] - expected).abs() <= 1e-12 * expected.abs(),
            "{rpm} rpm, {load} N: {} rad/s² against {expected}",
            ev.dy[ix::WB]
        );
    }
    // Parked, the race's load is its weight in the housing frame (no shock: m_b g).
    m.race_parked = true;
    let mut y = [0.0; N];
    y[ix::WB] = 3000.0 * TAU / 60.0;
    let expected = -palmgren_n_m(f0, nu0, f1, 3000.0, RACE_MASS * 9.80665) / RACE_INERTIA;
    let got = m.evaluate(0.0, &y).dy[ix::WB];
    assert!((got - expected).abs() <= 1e-12 * expected.abs(), "parked: {got} against {expected}");
}

/// Ball 0 sits straight down (cage phase −90°). Press the race down by `r_cl + δ`, shallow enough
/// that only a ball straight below can touch (`(r_cl + δ) cos(2π/19) < r_cl`): that ball carries
/// `K_b δ^1.5`, straight up. With a fixed cage this holds whatever angle the race has turned
/// through; with a rotating cage the balls have moved on with the race.
#[test]
fn a_fixed_cage_keeps_its_balls_where_they_were_put() {
    let delta: f64 = 1e-7;
    let hertz = BALL_STIFFNESS * delta.powf(1.5);
    let pressed = |cage: Cage, theta_b: f64| {
        let mut p = study_params();
        p.cage = cage;
        let m = model(p);
        let mut y = [0.0; N];
        y[ix::YB] = -(CLEARANCE + delta);
        y[ix::TB] = theta_b;
        y[ix::WB] = 1000.0;
        (cage_angle(&m.params, theta_b), m.evaluate(0.0, &y).balls)
    };
    for theta_b in [0.0, 1.0, -7.3, 250.0] {
        let (angle, balls) = pressed(Cage::Fixed, theta_b);
        assert_eq!(angle, -90f64.to_radians(), "θ_b = {theta_b}");
        assert_eq!(balls.loaded, 1, "θ_b = {theta_b}: {balls:?}");
        assert!((balls.on_race.y - hertz).abs() <= 1e-9 * hertz, "θ_b = {theta_b}: {balls:?}");
        assert!(balls.on_race.x.abs() <= 1e-9 * hertz, "θ_b = {theta_b}: {balls:?}");
    }
    // Rotating: the cage turns by R_in/(R_in + R_out) of the race's angle. After half a pitch of
    // cage travel the two nearest balls sit ±π/19 from straight down, (r_cl + δ) cos(π/19) < r_cl,
    // and the shallow press touches none.
    let ratio = study_params().cage_ratio;
    let half_pitch = TAU / 38.0 / ratio;
    let (angle, balls) = pressed(Cage::Rotating, half_pitch);
    assert!((angle - (-90f64.to_radians() + TAU / 38.0)).abs() < 1e-15);
    assert_eq!(balls.loaded, 0, "{balls:?}");
    // After the cage has turned by exactly one pitch, ball 1 is straight down: the Hertz load again.
    let (_, balls) = pressed(Cage::Rotating, TAU / 19.0 / ratio);
    assert_eq!(balls.loaded, 1, "{balls:?}");
    assert!((balls.on_race.y - hertz).abs() <= 1e-6 * hertz, "{balls:?}");
}

/// The race's rest position by bisection stops once its bracket no longer changes; the answer
/// is the 200-halving bisection's bit for bit (written out here), for the study's race under
/// gravity, under a 10 G shock in any direction and with the cage anywhere.
#[test]
fn the_rest_position_stops_early_with_the_full_bisections_answer() {
    use nalgebra::Vector2;
    use plant_physics::park::rest_position;
    let p = study_params();
    let full = |push: Vector2<f64>, cage: f64| {
        let g = push.x.hypot(push.y);
        let u = push / g;
        let load = p.race_mass * g;
        let resisting = |r: f64| -p.race_support(u * r, Vector2::zeros(), cage, 0.0).on_race.dot(&u);
        let (mut lo, mut hi) = (p.balls.clearance, p.balls.clearance + 1e-3);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if resisting(mid) > load {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        u * (0.5 * (lo + hi))
    };
    let mut cases = 0;
    for k in 0..24 {
        let dir = TAU * k as f64 / 24.0;
        for (push, cage) in [
            (Vector2::new(0.0, -p.gravity), 0.1 * k as f64),
            (98.1 * Vector2::new(dir.cos(), dir.sin()) - Vector2::new(0.0, p.gravity), 0.37 * k as f64),
        ] {
            let (a, b) = (rest_position(&p, push, cage), full(push, cage));
            assert_eq!((a.x.to_bits(), a.y.to_bits()), (b.x.to_bits(), b.y.to_bits()), "push {push:?}, cage {cage}");
            cases += 1;
        }
    }
    assert_eq!(cases, 48);
}
