//! The two-plane rotor (the whole rigid rotor on bearing planes A and B, with tilt and
//! gyroscopics, MODEL.md §9) behind [`Machine`].

use super::{Builds, Machine, PlaneState, Start};
use crate::model::{Control, Params, Release};
use crate::park::{self, GapMotion};
use crate::rows::{self, Record};
use nalgebra::Vector2;
use plant_physics::two_plane::{self, ix, Model, State, N};
use serde::Serialize;
use shock_table::Programme;

/// One race of the two-plane rotor's failing state.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RaceFailure {
    /// Race radius relative to the housing (m).
    pub race_radius_m: f64,
    /// Race x, y relative to the housing (m).
    pub race_m: [f64; 2],
    /// Race velocity relative to the housing (m/s).
    pub race_velocity_m_s: [f64; 2],
    /// Race angle (rad) and speed (rad/s).
    pub race_spin: [f64; 2],
}

/// The two-plane rotor's failing state.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TwoPlaneFailure {
    /// Time of the failure (s).
    pub t_s: f64,
    /// The rotor axis at the centre of mass's station, x, y relative to the housing (m).
    pub rotor_m: [f64; 2],
    /// Its velocity (m/s).
    pub rotor_velocity_m_s: [f64; 2],
    /// The slopes a, b of the axis (rad).
    pub slopes_rad: [f64; 2],
    /// Their rates (rad/s).
    pub slope_rates_rad_s: [f64; 2],
    /// Rotor spin angle (rad) and speed (rad/s).
    pub rotor_spin: [f64; 2],
    /// Race A.
    pub race_a: RaceFailure,
    /// Race B.
    pub race_b: RaceFailure,
}

/// Moves the rotor of `y` so that both bearing planes press [`super::CONTACT_DEPTH`] into their
/// races as `y` has them, straight down (the rotor level where the gaps are equal, tilted where
/// they differ), centred on them in x. Plane i's rotor position is `X + z_i a`, `Y + z_i b`: two
/// planes, two unknowns per axis.
pub(super) fn press_into_races(params: &two_plane::Params, y: &mut State) {
    let [za, zb] = [params.planes[0].station, params.planes[1].station];
    let line = |a: f64, b: f64| ((b - a) / (zb - za), a - za * (b - a) / (zb - za));
    let want = |i: usize| y[ix::RACE[i] + 1] - params.planes[i].params.contact.gap - super::CONTACT_DEPTH;
    (y[ix::SY], y[ix::Y]) = line(want(0), want(1));
    (y[ix::SX], y[ix::X]) = line(y[ix::RACE_A], y[ix::RACE_B]);
}

impl Machine<N> for Model {
    const PLANES: usize = 2;

    fn bearing(&self, i: usize) -> &Params {
        &self.params.planes[i].params
    }

    fn set_control(&mut self, i: usize, control: Control) {
        self.control[i] = control;
    }

    fn sensed(&self, y: &State, i: usize) -> [f64; 2] {
        self.bearing(i).axes.pair_to_plane(two_plane::at_station(y, self.params.planes[i].sensor).0.into())
    }

    fn parked(&self, i: usize) -> bool {
        self.race_parked[i]
    }

    fn set_parked(&mut self, i: usize, parked: bool) {
        self.race_parked[i] = parked;
    }

    fn race_clear(&self, t0: f64, h: f64, y: &State, i: usize) -> bool {
        use ix;
        let plane = &self.params.planes[i];
        let z = plane.station;
        let dy = self.evaluate(t0, y).dy;
        let (pos, vel) = two_plane::at_station(y, z);
        let race = ix::RACE[i];
        let motion = GapMotion {
            distance: (pos.x - y[race]).hypot(pos.y - y[race + 1]),
            speed: (vel.x - y[race + ix::V]).hypot(vel.y - y[race + 1 + ix::V]),
            accel: (dy[ix::VX] + dy[ix::VSX] * z).hypot(dy[ix::VY] + dy[ix::VSY] * z),
        };
        park::stays_open(&plane.params, &self.base, t0, h, motion)
    }

    fn touching(&self, y: &State, i: usize) -> bool {
        let plane = &self.params.planes[i];
        let (pos, _) = two_plane::at_station(y, plane.station);
        let race = ix::RACE[i];
        (pos.x - y[race]).hypot(pos.y - y[race + 1]) > plane.params.contact.gap
    }

    fn park_race(&self, y: &mut State, i: usize) {
        park::park_race(y, ix::RACE[i]);
    }

    fn release_race(&self, t: f64, y: &mut State, i: usize, release: Release) {
        park::release_race(&self.params.planes[i].params, &self.base, t, y, ix::RACE[i], release);
    }

    fn radii(&self, y: &State, i: usize) -> (f64, f64) {
        let (pos, _) = two_plane::at_station(y, self.params.planes[i].station);
        let race = ix::RACE[i];
        (pos.x.hypot(pos.y), y[race].hypot(y[race + 1]))
    }

    fn spin(&self, y: &State) -> (f64, f64) {
        (y[ix::TR], y[ix::WR])
    }

    fn record(&self, t: f64, y: &State) -> Record {
        rows::two_plane_record(self, t, y)
    }

    fn contact_state(&self, levitated: &State) -> State {
        let mut y = *levitated;
        press_into_races(&self.params, &mut y);
        y
    }

    fn sensed_rate(&self, y: &State, i: usize) -> [f64; 2] {
        self.bearing(i).axes.pair_to_plane(two_plane::at_station(y, self.params.planes[i].sensor).1.into())
    }

    fn bearing_velocity(&self, y: &State, i: usize) -> [f64; 2] {
        self.bearing(i).axes.pair_to_plane(two_plane::at_station(y, self.params.planes[i].station).1.into())
    }

    fn plane_states(&self, t: f64, y: &State, visit: &mut dyn FnMut(usize, &PlaneState<'_>)) {
        let ev = self.evaluate(t, y);
        for (i, plane) in self.params.planes.iter().enumerate() {
            let race = ix::RACE[i];
            visit(
                i,
                &PlaneState {
                    params: &plane.params,
                    normal: ev.planes[i].contact.normal,
                    tangential: ev.planes[i].contact.tangential,
                    rotor: two_plane::at_station(y, plane.station),
                    race: (Vector2::new(y[race], y[race + 1]), Vector2::new(y[race + ix::V], y[race + 1 + ix::V])),
                    rotor_speed: y[ix::WR],
                    race_angle: y[race + 2],
                    race_speed: y[race + 2 + ix::V],
                    race_accel: ev.dy[race + 2 + ix::V],
                },
            );
        }
    }

    /// The slopes and their rates count as angles and angular speeds.
    fn atol(groups: [f64; 4]) -> [f64; N] {
        let [p, v, a, w] = groups;
        [p, p, a, a, a, p, p, a, p, p, a, v, v, w, w, w, v, v, w, v, v, w]
    }

    type Failure = TwoPlaneFailure;

    fn failure(t: f64, y: &State) -> TwoPlaneFailure {
        let race = |x: usize| RaceFailure {
            race_radius_m: y[x].hypot(y[x + 1]),
            race_m: [y[x], y[x + 1]],
            race_velocity_m_s: [y[x + ix::V], y[x + 1 + ix::V]],
            race_spin: [y[x + 2], y[x + 2 + ix::V]],
        };
        TwoPlaneFailure {
            t_s: t,
            rotor_m: [y[ix::X], y[ix::Y]],
            rotor_velocity_m_s: [y[ix::VX], y[ix::VY]],
            slopes_rad: [y[ix::SX], y[ix::SY]],
            slope_rates_rad_s: [y[ix::VSX], y[ix::VSY]],
            rotor_spin: [y[ix::TR], y[ix::WR]],
            race_a: race(ix::RACE_A),
            race_b: race(ix::RACE_B),
        }
    }
}

impl Builds<N> for two_plane::Params {
    type Machine = Model;

    fn machine(&self, base: &Programme, controls: [Control; 2]) -> Model {
        Model { params: self.clone(), base: base.clone(), control: controls, race_parked: [false; 2] }
    }

    fn initial_state(&self, start: &Start<'_>) -> State {
        let gravity_bias = start.conditions.gravity_bias;
        two_plane::initial::initial_state(self, &rigid_conditions(start, gravity_bias))
    }
}

/// The rigid rotor's initial conditions of `start`, with `gravity_bias` (the flexible rotor
/// solves its sag itself and starts the rigid motion without it).
pub(super) fn rigid_conditions(start: &Start<'_>, gravity_bias: bool) -> two_plane::initial::InitialConditions {
    let ic = &start.conditions;
    two_plane::initial::InitialConditions {
        unbalance_orbit: ic.unbalance_orbit,
        unbalance_phase: ic.unbalance_phase,
        stiffness: ic.stiffness,
        damping_ratio: ic.damping_ratio,
        gravity_bias,
        rotor_offset: ic.rotor_offset,
        slope_offset: start.slope_offset,
    }
}

impl super::Linearised for plant_physics::two_plane::linear::LinearRotor {
    fn whirl_modes(&self, speed: f64) -> Result<Vec<super::WhirlMode>, super::WhirlError> {
        use plant_physics::flex::{linear::ModeKind, Whirl};
        use plant_physics::two_plane::linear::{Shape, Whirl as RigidWhirl};
        // In the order `LinearRotor::modes` gives (campbell.csv's rows as before).
        Ok(self
            .modes(speed)?
            .iter()
            .map(|m| super::WhirlMode {
                kind: match m.shape {
                    Shape::Cylindrical => ModeKind::Cylindrical,
                    Shape::Conical => ModeKind::Conical,
                },
                whirl: match m.whirl {
                    RigidWhirl::Forward => Whirl::Forward,
                    RigidWhirl::Backward => Whirl::Backward,
                },
                frequency_hz: m.frequency_hz,
                damping_ratio: m.damping_ratio,
            })
            .collect())
    }
}
