//! The flexible rotor (a finite-element shaft reduced to its modes, two AMBs, two sensors and
//! two touchdown bearings at its nodes, MODEL.md §13.6) behind [`Machine`].
//!
//! Its trace is the two-plane rotor's layout: plane A's and B's rows are taken at each plane's
//! touchdown-bearing node (where its race and contact are), and the "slopes" are those of the
//! line through the two touchdown nodes (the rigid part of the motion there); after them the
//! rotor at mid-span ([`mid_span`], the trace's `mid_dx_m`, `mid_dy_m`).

use super::two_plane::RaceFailure;
use super::{Builds, Linearised, Machine, PlaneState, Start, WhirlMode};
use crate::model::{Control, Params, Release};
use crate::park::{self, GapMotion};
use crate::rows::{self, Record};
use nalgebra::Vector2;
use plant_physics::flex::linear::{OpenLoop, PlanePd};
use plant_physics::flex::machine::{ix, Model, Params as FlexParams, State, MAX_MODES, N};
use plant_physics::flex::reduce::Kind;
use serde::Serialize;
use shock_table::Programme;

/// The flexible rotor's failing state.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FlexibleFailure {
    /// Time of the failure (s).
    pub t_s: f64,
    /// The rotor at touchdown node A and B, x, y relative to the housing (m).
    pub rotor_at_touchdown_m: [[f64; 2]; 2],
    /// Their velocities (m/s).
    pub rotor_velocity_at_touchdown_m_s: [[f64; 2]; 2],
    /// Rotor spin angle (rad) and speed (rad/s).
    pub rotor_spin: [f64; 2],
    /// Race A.
    pub race_a: RaceFailure,
    /// Race B.
    pub race_b: RaceFailure,
}

/// The rotor at plane `i`'s touchdown node: displacement and velocity relative to the housing.
fn touchdown(m: &Model, y: &State, i: usize) -> (Vector2<f64>, Vector2<f64>) {
    m.node(y, m.params.nodes[i].touchdown)
}

/// The line through the two touchdown nodes: its slopes a = dx/dz, b = dy/dz and their rates.
fn slopes(m: &Model, y: &State) -> [f64; 4] {
    let [za, zb] = [0, 1].map(|i| m.params.z[m.params.nodes[i].touchdown]);
    let ((pa, va), (pb, vb)) = (touchdown(m, y, 0), touchdown(m, y, 1));
    let l = zb - za;
    [(pb.x - pa.x) / l, (pb.y - pa.y) / l, (vb.x - va.x) / l, (vb.y - va.y) / l]
}

/// The shaft's node at mid-span: the nearest to the middle between the two touchdown nodes (the
/// trace's `mid_dx_m`, `mid_dy_m`).
pub fn mid_span(m: &Model) -> usize {
    mid_span_node(&m.params)
}

/// [`mid_span`] of the machine `p`.
pub fn mid_span_node(p: &FlexParams) -> usize {
    let z = &p.z;
    let middle = 0.5 * (z[p.nodes[0].touchdown] + z[p.nodes[1].touchdown]);
    (0..z.len()).min_by(|&a, &b| (z[a] - middle).abs().total_cmp(&(z[b] - middle).abs())).unwrap_or(0)
}

/// Where the mid-span node lies between the touchdown nodes: 0 at A's, 1 at B's (the weight of
/// the line through the rotor at the two touchdown bearings, [`crate::analysis::mid_span`]).
pub fn mid_span_weight(p: &FlexParams) -> f64 {
    let z = |n: usize| p.z[n];
    let (a, b) = (z(p.nodes[0].touchdown), z(p.nodes[1].touchdown));
    if b == a {
        0.5
    } else {
        (z(mid_span_node(p)) - a) / (b - a)
    }
}

/// The race of plane `i` in `y`: position and velocity relative to the housing.
fn race(y: &State, i: usize) -> (Vector2<f64>, Vector2<f64>) {
    let x = ix::RACE[i];
    (Vector2::new(y[x], y[x + 1]), Vector2::new(y[x + ix::V], y[x + 1 + ix::V]))
}

impl Machine<N> for Model {
    const PLANES: usize = 2;

    fn bearing(&self, i: usize) -> &Params {
        &self.params.machine.planes[i].params
    }

    fn set_control(&mut self, i: usize, control: Control) {
        self.control[i] = control;
    }

    fn sensed(&self, y: &State, i: usize) -> [f64; 2] {
        self.bearing(i).axes.pair_to_plane(self.node(y, self.params.nodes[i].sensor).0.into())
    }

    fn parked(&self, i: usize) -> bool {
        self.race_parked[i]
    }

    fn set_parked(&mut self, i: usize, parked: bool) {
        self.race_parked[i] = parked;
    }

    fn race_clear(&self, t0: f64, h: f64, y: &State, i: usize) -> bool {
        let (pos, vel) = touchdown(self, y, i);
        let (rp, rv) = race(y, i);
        // The node's acceleration: the derivative's rates through the basis.
        let dy = self.evaluate(t0, y).dy;
        let mut shifted = [0.0; N];
        shifted[..ix::V].copy_from_slice(&dy[ix::V..]);
        let (acc, _) = self.node(&shifted, self.params.nodes[i].touchdown);
        let motion = GapMotion { distance: (pos - rp).norm(), speed: (vel - rv).norm(), accel: acc.norm() };
        park::stays_open(self.bearing(i), &self.base, t0, h, motion)
    }

    fn park_race(&self, y: &mut State, i: usize) {
        park::park_race(y, ix::RACE[i]);
    }

    fn release_race(&self, t: f64, y: &mut State, i: usize, release: Release) {
        park::release_race(self.bearing(i), &self.base, t, y, ix::RACE[i], release);
    }

    fn radii(&self, y: &State, i: usize) -> (f64, f64) {
        let (pos, _) = touchdown(self, y, i);
        let (rp, _) = race(y, i);
        (pos.norm(), rp.norm())
    }

    fn spin(&self, y: &State) -> (f64, f64) {
        (y[ix::TR], y[ix::WR])
    }

    fn touching(&self, y: &State, i: usize) -> bool {
        let (pos, _) = touchdown(self, y, i);
        let (rp, _) = race(y, i);
        (pos - rp).norm() > self.bearing(i).contact.gap
    }

    fn record(&self, t: f64, y: &State) -> Record {
        let ev = self.evaluate(t, y);
        let housing = self.base.eval(t);
        let plane = |i: usize| {
            let (pos, vel) = touchdown(self, y, i);
            let race = ix::RACE[i];
            let race = [y[race], y[race + 1], y[race + ix::V], y[race + 1 + ix::V], y[race + 2 + ix::V]];
            rows::plane_values([pos.x, pos.y], [vel.x, vel.y], race, &ev.planes[i])
        };
        let mut r =
            rows::two_bearing_record(t, [y[ix::TR], y[ix::WR]], housing.disp, [plane(0), plane(1)], slopes(self, y));
        let (mid, _) = self.node(y, mid_span(self));
        r.mid = Some(rows::Mid { mid_dx_m: mid.x, mid_dy_m: mid.y });
        r
    }

    /// The rigid two-plane rotor's contact state (its bearing planes, the AMB nodes, pressed into
    /// the races) as a rigid motion of the shaft: where the touchdown nodes are the AMB nodes,
    /// both press into their races. The shaft's rates, spin and races stay as `levitated` has them.
    fn contact_state(&self, levitated: &State) -> State {
        use plant_physics::two_plane::{self, ix as rigid_ix};
        // The rigid rotor on the shaft's races, pressed into them: only its displacement
        // (translation and slopes) is projected on the shaft's basis.
        let mut rigid = [0.0; two_plane::N];
        for (fx, rx) in ix::RACE.iter().zip(rigid_ix::RACE) {
            rigid[rx..rx + 3].copy_from_slice(&levitated[*fx..*fx + 3]);
        }
        super::two_plane::press_into_races(&self.params.machine, &mut rigid);
        let pressed = Model::from_rigid(&self.params, &rigid);
        let mut y = *levitated;
        y[..ix::TR].copy_from_slice(&pressed[..ix::TR]);
        y
    }

    fn sensed_rate(&self, y: &State, i: usize) -> [f64; 2] {
        self.bearing(i).axes.pair_to_plane(self.node(y, self.params.nodes[i].sensor).1.into())
    }

    fn bearing_velocity(&self, y: &State, i: usize) -> [f64; 2] {
        self.bearing(i).axes.pair_to_plane(self.node(y, self.params.nodes[i].amb).1.into())
    }

    fn plane_states(&self, t: f64, y: &State, visit: &mut dyn FnMut(usize, &PlaneState<'_>)) {
        let ev = self.evaluate(t, y);
        for i in 0..2 {
            let x = ix::RACE[i];
            visit(
                i,
                &PlaneState {
                    params: self.bearing(i),
                    normal: ev.planes[i].contact.normal,
                    tangential: ev.planes[i].contact.tangential,
                    rotor: touchdown(self, y, i),
                    race: race(y, i),
                    rotor_speed: y[ix::WR],
                    race_angle: y[x + 2],
                    race_speed: y[x + 2 + ix::V],
                    race_accel: ev.dy[x + 2 + ix::V],
                },
            );
        }
    }

    /// The reduced coordinates of the basis, the spin and both races, with their rates: the
    /// slots past the basis stay zero and are not counted.
    fn used_components(&self) -> usize {
        N - 2 * (MAX_MODES - self.params.reduced.size())
    }

    /// The modal coordinates count as positions and their rates as velocities (the basis is
    /// mass-normalised, so a coordinate's error moves a node by about that error / √M: for a
    /// rotor heavier than 1 kg the tolerance at the nodes is tighter than the groups say).
    fn atol(groups: [f64; 4]) -> [f64; N] {
        let [p, v, a, w] = groups;
        let mut t = [p; N];
        t[ix::V..].fill(v);
        t[ix::TR] = a;
        t[ix::WR] = w;
        for x in ix::RACE {
            t[x + 2] = a;
            t[x + 2 + ix::V] = w;
        }
        t
    }

    type Failure = FlexibleFailure;

    fn failure(t: f64, y: &State) -> FlexibleFailure {
        let race = |x: usize| RaceFailure {
            race_radius_m: y[x].hypot(y[x + 1]),
            race_m: [y[x], y[x + 1]],
            race_velocity_m_s: [y[x + ix::V], y[x + 1 + ix::V]],
            race_spin: [y[x + 2], y[x + 2 + ix::V]],
        };
        // The node displacements need the model's basis, which `failure` does not have: the
        // races and the spin are what the state alone says.
        FlexibleFailure {
            t_s: t,
            rotor_at_touchdown_m: [[f64::NAN; 2]; 2],
            rotor_velocity_at_touchdown_m_s: [[f64::NAN; 2]; 2],
            rotor_spin: [y[ix::TR], y[ix::WR]],
            race_a: race(ix::RACE_A),
            race_b: race(ix::RACE_B),
        }
    }
}

impl Builds<N> for FlexParams {
    type Machine = Model;

    fn machine(&self, base: &Programme, controls: [Control; 2]) -> Model {
        Model { params: self.clone(), base: base.clone(), control: controls, race_parked: [false; 2] }
    }

    /// At rest on its bearings (the shaft sagged under gravity, the bias currents and the
    /// levitation design's loop, or the run's law where it has a static gain:
    /// [`plant_physics::flex::initial::static_sag_with`]), with the two-plane rotor's unbalance
    /// orbit and the scene's `[initial]` offsets as a rigid motion of the shaft on top of it.
    fn initial_state(&self, start: &Start<'_>) -> State {
        // The rigid rotor's start without its sag under gravity (the shaft's own is solved for
        // below, with or without the gravity bias): its unbalance orbit, offsets and races.
        let rigid_start = super::two_plane::rigid_conditions(start, true);
        let rigid = plant_physics::two_plane::initial::initial_state(&self.machine, &rigid_start);
        let mut y = Model::from_rigid(self, &rigid);
        let ic = &start.conditions;
        let at_rest = (start.law_at_rest)();
        let design = controller::PdDesign {
            stiffness_n_per_m: ic.stiffness,
            damping_ratio: ic.damping_ratio,
            // A law whose integral holds the weight from the start rests as the bias would hold it.
            gravity_bias: ic.gravity_bias || at_rest.holds_weight,
        };
        // A shaft the levitation design cannot hold still has no equilibrium to start from: it
        // starts straight (the rigid start), and the run shows it move.
        // Held by the run's law at rest where it has a static gain (crate::rest_law).
        let kp = at_rest.static_gains;
        if let Some(sag) = plant_physics::flex::initial::static_sag_with(self, &design, kp, &y) {
            for (k, s) in sag.iter().enumerate() {
                y[k] += s;
            }
        }
        y
    }
}

/// The flexible rotor linearised on the continuous PD of each plane ([`Linearised`]): the
/// closed loop of [`OpenLoop`], its whirl modes below 0.9 times its lowest static-correction
/// pseudo-mode (those above stand for the modes the reduction left out).
pub struct FlexibleLinear {
    open: OpenLoop,
    pd: [PlanePd; 2],
    f_max_hz: f64,
}

impl FlexibleLinear {
    /// `p` on the continuous PD `gains` of each plane.
    pub fn new(p: &FlexParams, gains: &[controller::PdGains]) -> Self {
        let pd = [0, 1].map(|i| PlanePd {
            kp: gains[i].kp,
            kd: gains[i].kd,
            amp_gain: gains[i].amp_gain_a_per_v,
            sensor_gain: p.machine.planes[i].params.loop_constants.sensor_gain_v_per_m,
        });
        // The modes below the lowest static-correction pseudo-mode (which lies above the
        // cutoff): the retained modes' range.
        let red = &p.reduced;
        let lowest_correction = red
            .frequencies_hz()
            .iter()
            .zip(&red.kinds)
            .filter(|(_, k)| **k == Kind::Correction)
            .map(|(f, _)| *f)
            .fold(f64::INFINITY, f64::min);
        FlexibleLinear { open: OpenLoop::of(p), pd, f_max_hz: 0.9 * lowest_correction }
    }
}

impl Linearised for FlexibleLinear {
    fn whirl_modes(&self, speed: f64) -> Result<Vec<WhirlMode>, super::WhirlError> {
        Ok(self
            .open
            .whirl_modes(&self.pd, speed, self.f_max_hz)?
            .into_iter()
            .map(|m| WhirlMode {
                kind: m.kind,
                whirl: m.whirl,
                frequency_hz: m.frequency_hz,
                damping_ratio: m.damping_ratio,
            })
            .collect())
    }
}
