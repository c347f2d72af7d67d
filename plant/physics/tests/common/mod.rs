//! The study's parameters (MODEL.md; the plant's scene defaults), written out by hand so that
//! the physics tests need no scene file.

use controller::LoopConstants;
use plant_physics::force::amb::AmbLaw;
use plant_physics::force::balls::BallSet;
use plant_physics::force::drag::RaceDrag;
use plant_physics::force::friction::Friction;
use plant_physics::force::rotor_race::RotorRace;
use plant_physics::model::{Cage, Control, Model, Params, RaceWhenClear, Spin, Support, TouchdownGeometry};
use shock_table::Programme;
use std::f64::consts::TAU;

/// Race mass m_b (kg).
pub const RACE_MASS: f64 = 0.048;
/// Race polar moment J_b (kg·m²).
pub const RACE_INERTIA: f64 = 2.33e-5;
/// Ball clearance r_cl (m).
pub const CLEARANCE: f64 = 1e-5;
/// Ball Hertz stiffness K_b (N/m^1.5).
pub const BALL_STIFFNESS: f64 = 7.81e9;
/// Pitch diameter d_m (mm).
pub const PITCH_DIAMETER_MM: f64 = 51.0;

/// The study's parameters: 11.5 kg rotor at 500 Hz, 19-ball touchdown bearing with a rotating
/// cage (ball 0 straight down), constant 0.1 N·m drag, linear bearing.
#[allow(dead_code)] // not every test binary uses every helper
pub fn study_params() -> Params {
    let (ball_d, dm) = (5.5, PITCH_DIAMETER_MM);
    let (r_in, r_out) = (dm / 2.0 - ball_d / 2.0, dm / 2.0 + ball_d / 2.0);
    Params {
        gravity: 9.80665,
        rotor_mass: 11.5,
        eccentricity: 2e-6,
        rotor_inertia: 5.81e-3,
        speed: 500.0 * TAU,
        spin: Spin::Held,
        race_mass: RACE_MASS,
        race_inertia: RACE_INERTIA,
        cage: Cage::Rotating,
        cage_phase: -90f64.to_radians(),
        cage_ratio: r_in / (r_in + r_out),
        contact: RotorRace {
            gap: 0.15e-3,
            rotor_radius: 19.85e-3,
            bore_radius: 20e-3,
            stiffness: 1.988e9,
            damping_max: 1000.0,
            damping_depth: 1e-5,
            friction: Friction { mu_static: 0.1, mu_dynamic: 0.1, v_static: 0.1, v_dynamic: 0.1 },
        },
        balls: BallSet::new(19, CLEARANCE, BALL_STIFFNESS, 750.0, 1e-5),
        support: Support::Balls,
        race_when_clear: RaceWhenClear::Free,
        drag: RaceDrag::Constant { torque: 0.1, reg_speed: 1.0 },
        amb: AmbLaw::Linear { ki: 216.0, ks: 4.32e5 },
        loop_constants: LoopConstants::study(),
        current_limit: 2.0,
        axes: Default::default(),
        touchdown: TouchdownGeometry { ball_diameter: ball_d * 1e-3, pitch_diameter: dm * 1e-3, width: 12e-3 },
    }
}

/// The model of `params` without a shock and with no coil current (the tests that use it
/// look at the race, which the bearing does not act on).
#[allow(dead_code)]
pub fn model(params: Params) -> Model {
    Model { params, base: Programme::default(), control: Control::Held([0.0; 2]), race_parked: false }
}

/// The symmetric two-plane machine equivalent to `planar` (docs/MODEL.md §10.1): a whole rotor
/// of twice the mass and polar inertia, the centre of mass mid-span between bearings at
/// ±0.18 m, sensors collocated, each plane the planar scene's bearing; I_t = 0.414 kg·m².
#[allow(dead_code)]
pub fn symmetric_two_plane(planar: &Params) -> plant_physics::two_plane::Params {
    use plant_physics::two_plane::{Params as TwoPlane, Plane, Rotor};
    let spin = match planar.spin {
        Spin::Held => Spin::Held,
        Spin::Free { drive_gain, torque_limit } => {
            Spin::Free { drive_gain: 2.0 * drive_gain, torque_limit: 2.0 * torque_limit }
        }
    };
    let plane = |z: f64| Plane { station: z, sensor: z, params: planar.clone() };
    TwoPlane {
        gravity: planar.gravity,
        rotor: Rotor {
            mass: 2.0 * planar.rotor_mass,
            transverse_inertia: 0.414,
            polar_inertia: 2.0 * planar.rotor_inertia,
            eccentricity: planar.eccentricity,
            couple: 0.0,
            couple_phase: 0.0,
            speed: planar.speed,
            spin,
        },
        planes: [plane(-0.18), plane(0.18)],
    }
}
