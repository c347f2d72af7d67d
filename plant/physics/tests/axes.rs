//! Issue 38 item 2: a bearing plane's axes turned by θ (`plant_physics::axes`). The coil pair
//! on u pushes along u, the sensor of u reads the projection onto u: a turned plane driven with
//! the currents `i_uv` is the housing-axes plane driven with the same currents turned back,
//! `i_xy = R i_uv`, written out here by hand; the continuous PD reads its sensor along (u, v).

mod common;

use common::{model, study_params};
use plant_physics::axes::Axes;
use plant_physics::force::amb::AmbLaw;
use plant_physics::model::{ix, Control, State};

/// A state off centre and moving, with the race elsewhere (so that the contact is open).
fn state() -> State {
    let mut y = [0.0; 12];
    y[ix::XR] = 2.1e-5;
    y[ix::YR] = -3.7e-5;
    y[ix::VXR] = 0.013;
    y[ix::VYR] = -0.021;
    y[ix::WR] = 3000.0;
    y[ix::YB] = -4e-6;
    y
}

/// The turned plane held at `i_uv` has the derivative of the plane in the housing's axes held
/// at `(i_u cos θ − i_v sin θ, i_u sin θ + i_v cos θ)`, to rounding, at several angles, the
/// linear law; and the nonlinear law, which is not the same in every direction, turned too:
/// its force along u is the one-axis law of the displacement along u.
#[test]
fn a_turned_plane_is_the_plane_with_its_currents_turned_back() {
    let y = state();
    let i_uv = [0.31, -0.83];
    for deg in [45.0f64, 30.0, -60.0, 90.0, -90.0] {
        let (s, c) = deg.to_radians().sin_cos();
        let mut turned = model(study_params());
        turned.params.axes = Axes::new(deg.to_radians());
        turned.control = Control::Held(i_uv);
        let mut plain = model(study_params());
        plain.control = Control::Held([i_uv[0] * c - i_uv[1] * s, i_uv[0] * s + i_uv[1] * c]);
        let (a, b) = (turned.evaluate(0.0, &y), plain.evaluate(0.0, &y));
        for k in 0..12 {
            assert!(
                (a.dy[k] - b.dy[k]).abs() <= 1e-12 * b.dy[k].abs().max(1.0),
                "{deg}°: state {k}: {} against {}",
                a.dy[k],
                b.dy[k]
            );
        }
        // The force is k_i R i + k_s d, by hand.
        let f = [
            216.0 * (i_uv[0] * c - i_uv[1] * s) + 4.32e5 * y[ix::XR],
            216.0 * (i_uv[0] * s + i_uv[1] * c) + 4.32e5 * y[ix::YR],
        ];
        assert!(
            (a.amb_force.x - f[0]).abs() < 1e-9 && (a.amb_force.y - f[1]).abs() < 1e-9,
            "{deg}°: {:?}",
            a.amb_force
        );
        // The currents the evaluation reports are the coil pairs' own.
        assert_eq!(a.current, i_uv);
    }
    // The nonlinear law turned by 45°: the displacement along u is (x + y)/√2, along v (y − x)/√2.
    let mut p = study_params();
    p.amb = AmbLaw::nonlinear_matching(216.0, 4.32e5, 1e-3, 1e6);
    p.axes = Axes::new(45f64.to_radians());
    let law = p.amb;
    let mut m = model(p);
    m.control = Control::Held(i_uv);
    let got = m.evaluate(0.0, &y).amb_force;
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let d = nalgebra::Vector2::new((y[ix::XR] + y[ix::YR]) * h, (y[ix::YR] - y[ix::XR]) * h);
    let f = law.force(d, nalgebra::Vector2::from(i_uv));
    let want = [(f.x - f.y) * h, (f.x + f.y) * h];
    assert!((got.x - want[0]).abs() < 1e-9 && (got.y - want[1]).abs() < 1e-9, "{got:?} against {want:?}");
}

/// The continuous PD reads its sensor along (u, v): turned by θ with the bias turned to
/// `(m g / k_i)(sin θ, cos θ)`, its force is the plain plane's PD force to rounding (the linear
/// loop is the same in every direction), and its currents are the plain plane's turned,
/// `i_u = i_x cos θ + i_y sin θ`, `i_v = −i_x sin θ + i_y cos θ`.
#[test]
fn the_continuous_pd_speaks_in_the_planes_axes() {
    let y = state();
    let c = controller::LoopConstants::study();
    let design = controller::PdDesign { stiffness_n_per_m: 1e6, damping_ratio: 0.01, gravity_bias: true };
    let g = controller::PdGains::from_design(&design, &c).unwrap();
    let weight = 11.5 * 9.80665 / 216.0;
    for deg in [45.0f64, -30.0] {
        let (s, co) = deg.to_radians().sin_cos();
        let mut turned = model(study_params());
        turned.params.axes = Axes::new(deg.to_radians());
        turned.control = Control::Continuous(controller::PdGains { bias_a: [weight * s, weight * co], ..g });
        let mut plain = model(study_params());
        plain.control = Control::Continuous(g);
        let (a, b) = (turned.evaluate(0.0, &y), plain.evaluate(0.0, &y));
        assert!((a.amb_force - b.amb_force).norm() < 1e-9, "{deg}°: {:?} against {:?}", a.amb_force, b.amb_force);
        let want = [b.current[0] * co + b.current[1] * s, -b.current[0] * s + b.current[1] * co];
        assert!(
            (a.current[0] - want[0]).abs() < 1e-12 && (a.current[1] - want[1]).abs() < 1e-12,
            "{deg}°: {:?}",
            a.current
        );
    }
}
