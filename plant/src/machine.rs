//! The rotor models the run loop steps, behind one trait: the planar model (one bearing plane,
//! the study's) and the two-plane rotor (two bearing planes, tilt). The loop ([`crate::run`])
//! is generic over it, so that the planar model runs the very code it ran before the second
//! plane existed: its `trace.csv` is unchanged byte for byte.

use crate::model::{Control, Model, Params, Release};
use crate::park::{self, GapMotion};
use crate::trace::{self, Record};
use controller::{saturate, PdGains};
use plant_physics::integrate::System;
use plant_physics::two_plane;

/// A rotor model on a state of `N` numbers with one or two bearing planes, each with its AMB,
/// sensor and touchdown bearing.
pub trait Machine<const N: usize>: System<N> {
    /// Bearing planes: 1 (planar) or 2.
    const PLANES: usize;

    /// Plane `i`'s bearing: its touchdown bearing, AMB and loop constants (a planar model's
    /// parameters; for the two-plane rotor, those of the plane's share).
    fn bearing(&self, i: usize) -> &Params;

    /// Sets plane `i`'s control for the coming macro step.
    fn set_control(&mut self, i: usize, control: Control);

    /// The rotor's displacement at plane `i`'s sensor, relative to the housing (m), x then y.
    fn sensed(&self, y: &[f64; N], i: usize) -> [f64; 2];

    /// Whether plane `i`'s race is parked.
    fn parked(&self, i: usize) -> bool;

    /// Parks (`true`) or frees plane `i`'s race for the coming macro step.
    fn set_parked(&mut self, i: usize, parked: bool);

    /// Whether the rotor stays clear of plane `i`'s race over `[t0, t0 + h]` ([`crate::park`]).
    fn race_clear(&self, t0: f64, h: f64, y: &[f64; N], i: usize) -> bool;

    /// Holds plane `i`'s race in the housing frame (its velocity set to zero).
    fn park_race(&self, y: &mut [f64; N], i: usize);

    /// Releases plane `i`'s race at time `t` as `release` says.
    fn release_race(&self, t: f64, y: &mut [f64; N], i: usize, release: Release);

    /// Plane `i`'s radii relative to the housing (m): the rotor at the bearing, and the race.
    fn radii(&self, y: &[f64; N], i: usize) -> (f64, f64);

    /// The rotor's spin angle (rad, unwrapped) and speed (rad/s) in state `y`: the keyphasor.
    fn spin(&self, y: &[f64; N]) -> (f64, f64);

    /// Whether the rotor touches plane `i`'s race (their distance exceeds the gap).
    fn touching(&self, y: &[f64; N], i: usize) -> bool;

    /// The output sample of state `y` at time `t`.
    fn record(&self, t: f64, y: &[f64; N]) -> Record;

    /// The planar model itself (for a sink that reads its state, [`crate::run::Sink::planar_state`]);
    /// `None` for any other model.
    fn planar(&self) -> Option<&Model> {
        None
    }

    /// The two-plane rotor itself (for a sink that reads its state,
    /// [`crate::run::Sink::two_plane_state`]); `None` for any other model.
    fn two_plane(&self) -> Option<&two_plane::Model> {
        None
    }

    /// The rate of [`Machine::sensed`] (m/s): the rotor's velocity at plane `i`'s sensor (through
    /// a sensor's front end, the rate of what it reads, [`crate::hardware`]).
    fn sensed_rate(&self, y: &[f64; N], i: usize) -> [f64; 2];

    /// Plane `i`'s continuous PD current in state `y` (A): the PD on what the plane's sensor
    /// reads ([`Machine::sensed`]) and its rate, saturated at the plane's limit. For the bare
    /// models, what their `Control::Continuous(gains)` applies.
    fn pd_current(&self, gains: &PdGains, y: &[f64; N], i: usize) -> [f64; 2] {
        let p = self.bearing(i);
        let a_s = p.loop_constants.sensor_gain_v_per_m;
        let (d, v) = (self.sensed(y, i), self.sensed_rate(y, i));
        saturate(gains.current([d[0] * a_s, d[1] * a_s], [v[0] * a_s, v[1] * a_s]), p.current_limit)
    }

    /// The rotor's velocity at plane `i`'s bearing, relative to the housing (m/s).
    fn bearing_velocity(&self, y: &[f64; N], i: usize) -> [f64; 2];

    /// Time spent with an amplifier at its voltage limit (s), for a model with amplifiers
    /// ([`crate::hardware`]).
    fn voltage_saturation(&self, _y: &[f64; N]) -> Option<f64> {
        None
    }
}

impl Machine<{ crate::model::N }> for Model {
    const PLANES: usize = 1;

    fn planar(&self) -> Option<&Model> {
        Some(self)
    }

    fn bearing(&self, _i: usize) -> &Params {
        &self.params
    }

    fn set_control(&mut self, _i: usize, control: Control) {
        self.control = control;
    }

    fn sensed(&self, y: &crate::model::State, _i: usize) -> [f64; 2] {
        [y[crate::model::ix::XR], y[crate::model::ix::YR]]
    }

    fn parked(&self, _i: usize) -> bool {
        self.race_parked
    }

    fn set_parked(&mut self, _i: usize, parked: bool) {
        self.race_parked = parked;
    }

    fn race_clear(&self, t0: f64, h: f64, y: &crate::model::State, _i: usize) -> bool {
        park::clear(self, t0, h, y)
    }

    fn park_race(&self, y: &mut crate::model::State, _i: usize) {
        park::park(y);
    }

    fn release_race(&self, t: f64, y: &mut crate::model::State, _i: usize, release: Release) {
        park::release(self, t, y, release);
    }

    fn touching(&self, y: &crate::model::State, _i: usize) -> bool {
        use crate::model::ix::*;
        let (dx, dy) = (y[XR] - y[XB], y[YR] - y[YB]);
        let gap = self.params.contact.gap;
        dx * dx + dy * dy > gap * gap
    }

    fn radii(&self, y: &crate::model::State, _i: usize) -> (f64, f64) {
        use crate::model::ix::*;
        (y[XR].hypot(y[YR]), y[XB].hypot(y[YB]))
    }

    fn spin(&self, y: &crate::model::State) -> (f64, f64) {
        (y[crate::model::ix::TR], y[crate::model::ix::WR])
    }

    fn record(&self, t: f64, y: &crate::model::State) -> Record {
        Record::planar(trace::row(self, t, y))
    }

    fn sensed_rate(&self, y: &crate::model::State, _i: usize) -> [f64; 2] {
        [y[crate::model::ix::VXR], y[crate::model::ix::VYR]]
    }

    fn bearing_velocity(&self, y: &crate::model::State, _i: usize) -> [f64; 2] {
        [y[crate::model::ix::VXR], y[crate::model::ix::VYR]]
    }
}

impl Machine<{ two_plane::N }> for two_plane::Model {
    const PLANES: usize = 2;

    fn two_plane(&self) -> Option<&two_plane::Model> {
        Some(self)
    }

    fn bearing(&self, i: usize) -> &Params {
        &self.params.planes[i].params
    }

    fn set_control(&mut self, i: usize, control: Control) {
        self.control[i] = control;
    }

    fn sensed(&self, y: &two_plane::State, i: usize) -> [f64; 2] {
        two_plane::at_station(y, self.params.planes[i].sensor).0.into()
    }

    fn parked(&self, i: usize) -> bool {
        self.race_parked[i]
    }

    fn set_parked(&mut self, i: usize, parked: bool) {
        self.race_parked[i] = parked;
    }

    fn race_clear(&self, t0: f64, h: f64, y: &two_plane::State, i: usize) -> bool {
        use two_plane::ix;
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

    fn touching(&self, y: &two_plane::State, i: usize) -> bool {
        let plane = &self.params.planes[i];
        let (pos, _) = two_plane::at_station(y, plane.station);
        let race = two_plane::ix::RACE[i];
        (pos.x - y[race]).hypot(pos.y - y[race + 1]) > plane.params.contact.gap
    }

    fn park_race(&self, y: &mut two_plane::State, i: usize) {
        park::park_race(y, two_plane::ix::RACE[i]);
    }

    fn release_race(&self, t: f64, y: &mut two_plane::State, i: usize, release: Release) {
        park::release_race(&self.params.planes[i].params, &self.base, t, y, two_plane::ix::RACE[i], release);
    }

    fn radii(&self, y: &two_plane::State, i: usize) -> (f64, f64) {
        let (pos, _) = two_plane::at_station(y, self.params.planes[i].station);
        let race = two_plane::ix::RACE[i];
        (pos.x.hypot(pos.y), y[race].hypot(y[race + 1]))
    }

    fn spin(&self, y: &two_plane::State) -> (f64, f64) {
        (y[two_plane::ix::TR], y[two_plane::ix::WR])
    }

    fn record(&self, t: f64, y: &two_plane::State) -> Record {
        trace::two_plane_record(self, t, y)
    }

    fn sensed_rate(&self, y: &two_plane::State, i: usize) -> [f64; 2] {
        two_plane::at_station(y, self.params.planes[i].sensor).1.into()
    }

    fn bearing_velocity(&self, y: &two_plane::State, i: usize) -> [f64; 2] {
        two_plane::at_station(y, self.params.planes[i].station).1.into()
    }
}
