//! The two-plane rotor against the planar model and against closed forms: the symmetric machine's
//! derivative is the planar one, bit for bit, in and out of contact; the model linearised by
//! finite differences is the linear rotor of `two_plane::linear`; without bearings, contact,
//! drive, gravity or shock the rotor keeps its energy and angular momentum; started on its
//! linear unbalance response (static and couple) it stays there.

mod common;

use common::{study_params, symmetric_two_plane};
use controller::{PdDesign, PdGains};
use plant_physics::force::amb::AmbLaw;
use plant_physics::integrate::{Integrator, Method, Settings};
use plant_physics::model::{self, Control, Spin};
use plant_physics::two_plane::initial::{design_loops, initial_state, InitialConditions};
use plant_physics::two_plane::{self as tp, invariants, ix};
use shock_table::Programme;
use std::f64::consts::TAU;

fn planar_model(p: model::Params, control: Control) -> model::Model {
    model::Model { params: p, base: Programme::default(), control, race_parked: false }
}

fn two_plane_model(p: tp::Params, control: Control) -> tp::Model {
    tp::Model { params: p, base: Programme::default(), control: [control; 2], race_parked: [false; 2] }
}

/// The two-plane state of a planar state: the axis at the planar rotor's place, no tilt, both
/// races the planar race.
fn lift(y: &model::State) -> tp::State {
    use model::ix as p;
    let mut z = [0.0; tp::N];
    let v = ix::V;
    for (from, to) in [(p::XR, ix::X), (p::YR, ix::Y), (p::TR, ix::TR)] {
        z[to] = y[from];
        z[to + v] = y[from + 6];
    }
    for race in ix::RACE {
        for k in 0..3 {
            z[race + k] = y[p::XB + k];
            z[race + k + v] = y[p::XB + k + 6];
        }
    }
    z
}

fn gains() -> PdGains {
    let design = PdDesign { stiffness_n_per_m: 1e6, damping_ratio: 0.01, gravity_bias: true };
    PdGains::from_design(&design, &controller::LoopConstants::study()).unwrap()
}

/// The symmetric machine's derivative is the planar one at each plane, bit for bit, for states
/// levitated, in contact (rotor pressing the race onto its balls, slipping), with the spin
/// free, under a shock, and with a sampled current: `(F + F) / 2m = F / m` in IEEE arithmetic.
#[test]
fn symmetric_machine_derivative_is_the_planar_one_bit_for_bit() {
    let mut free = study_params();
    free.spin = Spin::Free { drive_gain: 0.05, torque_limit: 2.0 };
    let pulse = shock_table::DoubleHalfSine::from_peak(10.0 * 9.80665, 10.0, 80.0).unwrap();
    let shock = Programme::single(shock_table::Shock::lifting(pulse.into(), 0.02).unwrap());
    let cases: Vec<(model::Params, Control, Programme)> = vec![
        (study_params(), Control::Continuous(gains()), Programme::default()),
        (free.clone(), Control::Continuous(gains()), shock.clone()),
        (study_params(), Control::Held([0.3, 1.1]), shock),
    ];
    // Levitated on a small orbit; in contact at 160 µm with the race pressed onto its balls;
    // deep in contact, moving fast and the race spinning.
    let states: Vec<model::State> = vec![
        [1e-6, -2e-6, 0.3, 0.0, -1.2e-5, 0.1, 3e-3, -1e-3, 3141.6, 0.0, 0.0, 2.0],
        [1.2e-4, -1.0e-4, 1.7, 4e-6, -1.4e-5, 0.4, 0.05, -0.02, 3141.6, 0.01, 0.0, 300.0],
        [-1.5e-4, -0.9e-4, 5.9, -1.2e-5, -1.6e-5, 9.0, -0.2, 0.4, 3100.0, -0.05, 0.02, 1500.0],
    ];
    for (params, control, base) in cases {
        let planar = model::Model { base: base.clone(), ..planar_model(params.clone(), control) };
        let two = tp::Model { base, ..two_plane_model(symmetric_two_plane(&params), control) };
        for y in &states {
            for t in [0.0, 0.021, 0.03] {
                let (p, q) = (planar.evaluate(t, y), two.evaluate(t, &lift(y)));
                let expect = lift(&p.dy);
                for (i, (a, b)) in expect.iter().zip(&q.dy).enumerate() {
                    if i == ix::SX || i == ix::SY || i == ix::VSX || i == ix::VSY {
                        assert_eq!(b.abs(), 0.0, "slope row {i} at {y:?}");
                        continue;
                    }
                    assert_eq!(a.to_bits(), b.to_bits(), "row {i}: planar {a:e}, two-plane {b:e} at {y:?}, t {t}");
                }
                for plane in &q.planes {
                    assert_eq!(plane.current, p.current);
                    assert_eq!(plane.contact, p.contact);
                    assert_eq!(plane.balls, p.balls);
                }
            }
        }
        // The parked race, too.
        let planar = model::Model { race_parked: true, ..planar };
        let two = tp::Model { race_parked: [true; 2], ..two };
        let (p, q) = (planar.evaluate(0.0, &states[0]), two.evaluate(0.0, &lift(&states[0])));
        assert_eq!(lift(&p.dy).map(f64::to_bits), q.dy.map(f64::to_bits), "parked");
    }
}

/// The symmetric machine's initial state is the planar one at each plane, bit for bit.
#[test]
fn symmetric_initial_state_is_the_planar_one() {
    for (orbit, bias, phase) in [(true, true, 0.0), (true, false, 1.3), (false, false, 0.0)] {
        let p = study_params();
        let ic = plant_physics::initial::InitialConditions {
            unbalance_orbit: orbit,
            unbalance_phase: phase,
            stiffness: 1e6,
            damping_ratio: 0.01,
            gravity_bias: bias,
            rotor_offset: [1e-6, -3e-6],
        };
        let planar = plant_physics::initial::initial_state(&p, &ic);
        let two = initial_state(
            &symmetric_two_plane(&p),
            &InitialConditions {
                unbalance_orbit: orbit,
                unbalance_phase: phase,
                stiffness: 1e6,
                damping_ratio: 0.01,
                gravity_bias: bias,
                rotor_offset: [1e-6, -3e-6],
                slope_offset: [0.0; 2],
            },
        );
        assert_eq!(lift(&planar).map(f64::to_bits), two.map(f64::to_bits));
    }
}

/// An asymmetric machine: the centre of mass nearer plane A (stations −0.15 and +0.21 m),
/// sensors 20 mm outboard of the actuators, plane B's race with a smaller gap, a couple
/// unbalance; the rotor spinning at 300 Hz.
fn asymmetric() -> (tp::Params, [PdGains; 2]) {
    let mut p = symmetric_two_plane(&study_params());
    p.planes[0].station = -0.15;
    p.planes[0].sensor = -0.17;
    p.planes[1].station = 0.21;
    p.planes[1].sensor = 0.23;
    p.planes[1].params.contact.gap = 0.1e-3;
    p.rotor.couple = 50e-6;
    p.rotor.couple_phase = 0.7;
    p.rotor.speed = 300.0 * TAU;
    let gains = [0, 1].map(|i| {
        let mut c = p.planes[i].params.loop_constants;
        c.rotor_mass_kg = p.load_share(i);
        let design = PdDesign { stiffness_n_per_m: 1e6, damping_ratio: 0.05, gravity_bias: true };
        PdGains::from_design(&design, &c).unwrap()
    });
    (p, gains)
}

/// The model's Jacobian at the centred rotor (finite differences) is the linear rotor's: the
/// stiffness and damping of each plane's PD on its own sensor with the bearing's negative
/// stiffness at the actuator, and the gyroscopic coupling `∓ I_p Ω / I_t` between the slope
/// rates, with its sign: `I_t ä = … − I_p Ω ḃ`, `I_t b̈ = … + I_p Ω ȧ`.
#[test]
fn finite_difference_jacobian_is_the_linear_rotor() {
    let (mut p, gains) = asymmetric();
    p.gravity = 0.0;
    p.rotor.eccentricity = 0.0;
    p.rotor.couple = 0.0;
    let lin = tp::linear::LinearRotor::from_gains(&p, &gains);
    let w = p.rotor.speed;
    let (m, it, ip) = (p.rotor.mass, p.rotor.transverse_inertia, p.rotor.polar_inertia);
    let model = two_plane_model(p, Control::Continuous(gains[0]));
    let model = tp::Model { control: [Control::Continuous(gains[0]), Control::Continuous(gains[1])], ..model };
    let mut y0 = [0.0; tp::N];
    y0[ix::WR] = w;
    let column = |j: usize, h: f64| {
        let (mut up, mut down) = (y0, y0);
        up[j] += h;
        down[j] -= h;
        let (fu, fd) = (model.evaluate(0.0, &up).dy, model.evaluate(0.0, &down).dy);
        std::array::from_fn::<f64, { tp::N }, _>(|i| (fu[i] - fd[i]) / (2.0 * h))
    };
    let (k, c) = (lin.stiffness(), lin.damping());
    let close = |got: f64, want: f64, what: &str| {
        assert!((got - want).abs() <= 1e-6 * want.abs().max(1e-3), "{what}: {got:e} against {want:e}");
    };
    // Columns of x, a (and y, b, the same by isotropy); rows of ẍ, ä, ÿ, b̈.
    for (axis, (pos, slope)) in [(ix::X, ix::SX), (ix::Y, ix::SY)].into_iter().enumerate() {
        let (acc, tilt) = (pos + ix::V, slope + ix::V);
        for (col, scale, kcol) in [(pos, 1e-7, 0), (slope, 1e-7, 1), (pos + ix::V, 1e-5, 0), (slope + ix::V, 1e-5, 1)] {
            let d = column(col, scale);
            let matrix = if col >= ix::V { &c } else { &k };
            close(d[acc], -matrix[0][kcol] / m, &format!("axis {axis}: d(accel)/d(state {col})"));
            close(d[tilt], -matrix[1][kcol] / it, &format!("axis {axis}: d(tilt accel)/d(state {col})"));
        }
    }
    // Gyroscopic coupling between the slope rates.
    let da = column(ix::VSX, 1e-5);
    let db = column(ix::VSY, 1e-5);
    close(db[ix::VSX], -ip * w / it, "d(ä)/d(ḃ)");
    close(da[ix::VSY], ip * w / it, "d(b̈)/d(ȧ)");
    // x and y do not couple otherwise.
    assert!(column(ix::X, 1e-7)[ix::VY].abs() < 1e-6 * k[0][0] / m);
}

/// Started on its linear unbalance response (static and couple unbalance, non-collocated
/// sensors, the centre of mass off mid-span), the levitated rotor stays on it: after 40 ms
/// (12 revolutions) the state is the initial response turned by ωt, to the integrator's
/// accuracy. This checks the couple unbalance's forcing, the gyroscopic terms and
/// `initial_state` together.
#[test]
fn unbalance_response_is_steady() {
    let (mut p, gains) = asymmetric();
    p.rotor.eccentricity = 2e-6;
    let ic = InitialConditions {
        unbalance_orbit: true,
        unbalance_phase: 0.4,
        stiffness: 1e6,
        damping_ratio: 0.05,
        gravity_bias: true,
        rotor_offset: [0.0; 2],
        slope_offset: [0.0; 2],
    };
    let y0 = initial_state(&p, &ic);
    // The design's loops are the PD gains' (to rounding), so the start is on the orbit.
    let lin = design_loops(&p, 1e6, 0.05);
    assert!((lin.stiffness()[1][1] - tp::linear::LinearRotor::from_gains(&p, &gains).stiffness()[1][1]).abs() < 1e-6);
    let w = p.rotor.speed;
    let model = tp::Model {
        params: p,
        base: Programme::default(),
        control: [Control::Continuous(gains[0]), Control::Continuous(gains[1])],
        race_parked: [true; 2],
    };
    let mut y = y0;
    let t1 = 0.04;
    let mut integrator = Integrator::new(Settings::adaptive(Method::Dop853, 1e-11, 1e-15));
    integrator.advance(&model, 0.0, t1, &mut y).unwrap();
    let turn = |v: [f64; 2], angle: f64| {
        let (s, c) = angle.sin_cos();
        [v[0] * c - v[1] * s, v[0] * s + v[1] * c]
    };
    let amplitude = y0[ix::X].hypot(y0[ix::Y]);
    let tilt = y0[ix::SX].hypot(y0[ix::SY]);
    assert!(tilt * 0.18 > 0.1 * amplitude, "the couple unbalance tilts the orbit: {tilt:e} rad, {amplitude:e} m");
    for (pair, scale) in [(ix::X, amplitude), (ix::SX, tilt), (ix::VX, amplitude * w), (ix::VSX, tilt * w)] {
        let want = turn([y0[pair], y0[pair + 1]], w * t1);
        for k in 0..2 {
            assert!(
                (y[pair + k] - want[k]).abs() < 1e-6 * scale,
                "state {}: {:e} against {:e}",
                pair + k,
                y[pair + k],
                want[k]
            );
        }
    }
}

/// Without bearing forces, contact, drive, gravity or shock, the free rotor keeps its energy
/// and angular momentum (`two_plane::invariants`) over 1 s at 500 Hz, with static and couple
/// unbalance and a nutation started by a tilt rate; the spin is integrated (`free`, no drive).
///
/// The energy is an exact invariant of the equations (MODEL.md §10.3): kept to the integrator's
/// tolerance. So is the angular momentum while the spin is constant (static unbalance only).
/// With a couple unbalance the spin exchanges energy with the tilt and the linearised model
/// keeps `H_z` only to its own order, `κ |φ̇|` (the couple unbalance's share of it, measured
/// 1.9e-9 of |H|), `H_x`, `H_y` to the tolerance.
#[test]
fn free_rotor_conserves_energy_and_angular_momentum() {
    let mut planar = study_params();
    planar.gravity = 0.0;
    planar.amb = AmbLaw::Linear { ki: 216.0, ks: 0.0 };
    planar.spin = Spin::Free { drive_gain: 0.0, torque_limit: 0.0 };
    let mut p = symmetric_two_plane(&planar);
    p.planes[0].station = -0.15;
    p.planes[1].station = 0.21;
    // Energy drift relative to the energy, drift of (H_x, H_y) and of H_z relative to |H|, and
    // the largest κ |φ̇| met.
    let run = |couple: f64| {
        let mut p = p.clone();
        p.rotor.couple = couple;
        p.rotor.couple_phase = 0.7;
        let model = two_plane_model(p.clone(), Control::Held([0.0; 2]));
        let (w, e, chi) = (p.rotor.speed, p.rotor.eccentricity, couple);
        let mut y = [0.0; tp::N];
        y[ix::WR] = w;
        // The centre of mass at rest (the axis turns about it), the rotor turning about its
        // principal axis (the slopes −χ towards ψ, turning with the spin), and a nutation from
        // a tilt rate of 2 mrad/s.
        y[ix::X] = -e;
        y[ix::VY] = -e * w;
        let (s, c) = p.rotor.couple_phase.sin_cos();
        y[ix::SX] = -chi * c;
        y[ix::SY] = -chi * s;
        y[ix::VSX] = chi * s * w + 2e-3;
        y[ix::VSY] = -chi * c * w;
        let before = invariants(&p.rotor, &y);
        let h0 = before.angular_momentum;
        let norm = h0.iter().map(|v| v * v).sum::<f64>().sqrt();
        let mut integrator = Integrator::new(Settings::adaptive(Method::Dop853, 1e-12, 1e-16));
        let mut worst = [0.0f64; 4];
        for k in 0..100 {
            let t = k as f64 * 0.01;
            integrator.advance(&model, t, t + 0.01, &mut y).unwrap();
            let now = invariants(&p.rotor, &y);
            let h = now.angular_momentum;
            let transverse = (h[0] - h0[0]).hypot(h[1] - h0[1]) / norm;
            let rate = y[ix::VSX].hypot(y[ix::VSY]);
            let drifts = [
                (now.energy - before.energy).abs() / before.energy,
                transverse,
                (h[2] - h0[2]).abs() / norm,
                p.rotor.couple_moment().abs() * rate / norm,
            ];
            for (w, d) in worst.iter_mut().zip(drifts) {
                *w = w.max(d);
            }
        }
        // No contact happened: the races were never touched.
        assert!(y[ix::RACE_A..ix::RACE_B + 3].iter().all(|v| *v == 0.0), "{y:?}");
        worst
    };
    let [energy, transverse, axial, _] = run(0.0);
    eprintln!("static unbalance: energy {energy:e}, H_x,y {transverse:e}, H_z {axial:e}");
    assert!(energy < 1e-12 && transverse < 1e-12 && axial < 1e-12, "{energy:e} {transverse:e} {axial:e}");
    let [energy, transverse, axial, order] = run(50e-6);
    eprintln!("couple unbalance: energy {energy:e}, H_x,y {transverse:e}, H_z {axial:e} (κ|φ̇|/|H| {order:e})");
    assert!(energy < 1e-12 && transverse < 1e-10, "{energy:e} {transverse:e}");
    assert!(axial < order, "H_z drifts by {axial:e}, beyond the model's order {order:e}");
}
