//! The planar model (one bearing plane, the study's, MODEL.md §1–§6) behind [`Machine`].

use super::{Builds, Machine, PlaneState, Start};
use crate::model::ix::*;
use crate::model::{Control, Model, Params, Release, State, N};
use crate::park;
use crate::rows::{self, Record};
use nalgebra::Vector2;
use serde::Serialize;
use shock_table::Programme;

/// The planar model's failing state.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlanarFailure {
    /// Time of the failure (s).
    pub t_s: f64,
    /// Rotor radius relative to the housing (m).
    pub rotor_radius_m: f64,
    /// Race radius relative to the housing (m).
    pub race_radius_m: f64,
    /// Rotor x, y relative to the housing (m).
    pub rotor_m: [f64; 2],
    /// Rotor velocity relative to the housing (m/s).
    pub rotor_velocity_m_s: [f64; 2],
    /// Race x, y relative to the housing (m).
    pub race_m: [f64; 2],
    /// Race velocity relative to the housing (m/s).
    pub race_velocity_m_s: [f64; 2],
    /// Rotor spin angle (rad) and speed (rad/s).
    pub rotor_spin: [f64; 2],
    /// Race angle (rad) and speed (rad/s).
    pub race_spin: [f64; 2],
}

impl Machine<N> for Model {
    const PLANES: usize = 1;

    fn bearing(&self, _i: usize) -> &Params {
        &self.params
    }

    fn set_control(&mut self, _i: usize, control: Control) {
        self.control = control;
    }

    fn sensed(&self, y: &State, _i: usize) -> [f64; 2] {
        self.params.axes.pair_to_plane([y[XR], y[YR]])
    }

    fn parked(&self, _i: usize) -> bool {
        self.race_parked
    }

    fn set_parked(&mut self, _i: usize, parked: bool) {
        self.race_parked = parked;
    }

    fn race_clear(&self, t0: f64, h: f64, y: &State, _i: usize) -> bool {
        park::clear(self, t0, h, y)
    }

    fn park_race(&self, y: &mut State, _i: usize) {
        park::park(y);
    }

    fn release_race(&self, t: f64, y: &mut State, _i: usize, release: Release) {
        park::release(self, t, y, release);
    }

    fn touching(&self, y: &State, _i: usize) -> bool {
        let (dx, dy) = (y[XR] - y[XB], y[YR] - y[YB]);
        let gap = self.params.contact.gap;
        dx * dx + dy * dy > gap * gap
    }

    fn radii(&self, y: &State, _i: usize) -> (f64, f64) {
        (y[XR].hypot(y[YR]), y[XB].hypot(y[YB]))
    }

    fn spin(&self, y: &State) -> (f64, f64) {
        (y[TR], y[WR])
    }

    fn record(&self, t: f64, y: &State) -> Record {
        Record::planar(rows::row(self, t, y))
    }

    fn contact_state(&self, levitated: &State) -> State {
        let mut y = *levitated;
        y[XR] = y[XB];
        y[YR] = y[YB] - self.params.contact.gap - super::CONTACT_DEPTH;
        y
    }

    fn sensed_rate(&self, y: &State, _i: usize) -> [f64; 2] {
        self.params.axes.pair_to_plane([y[VXR], y[VYR]])
    }

    fn bearing_velocity(&self, y: &State, _i: usize) -> [f64; 2] {
        self.params.axes.pair_to_plane([y[VXR], y[VYR]])
    }

    fn plane_states(&self, t: f64, y: &State, visit: &mut dyn FnMut(usize, &PlaneState<'_>)) {
        let ev = self.evaluate(t, y);
        visit(
            0,
            &PlaneState {
                params: &self.params,
                normal: ev.contact.normal,
                tangential: ev.contact.tangential,
                rotor: (Vector2::new(y[XR], y[YR]), Vector2::new(y[VXR], y[VYR])),
                race: (Vector2::new(y[XB], y[YB]), Vector2::new(y[VXB], y[VYB])),
                rotor_speed: y[WR],
                race_angle: y[TB],
                race_speed: y[WB],
                race_accel: ev.dy[WB],
            },
        );
    }

    fn atol(groups: [f64; 4]) -> [f64; N] {
        let [p, v, a, w] = groups;
        [p, p, a, p, p, a, v, v, w, v, v, w]
    }

    type Failure = PlanarFailure;

    fn failure(t: f64, y: &State) -> PlanarFailure {
        PlanarFailure {
            t_s: t,
            rotor_radius_m: y[XR].hypot(y[YR]),
            race_radius_m: y[XB].hypot(y[YB]),
            rotor_m: [y[XR], y[YR]],
            rotor_velocity_m_s: [y[VXR], y[VYR]],
            race_m: [y[XB], y[YB]],
            race_velocity_m_s: [y[VXB], y[VYB]],
            rotor_spin: [y[TR], y[WR]],
            race_spin: [y[TB], y[WB]],
        }
    }
}

impl Builds<N> for Params {
    type Machine = Model;

    fn machine(&self, base: &Programme, controls: [Control; 2]) -> Model {
        Model { params: self.clone(), base: base.clone(), control: controls[0], race_parked: false }
    }

    fn initial_state(&self, start: &Start<'_>) -> State {
        plant_physics::initial::initial_state(self, &start.conditions)
    }
}
