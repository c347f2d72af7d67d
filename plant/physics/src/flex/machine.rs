//! The flexible rotor as a machine of the plant (MODEL.md §13.6): the reduced shaft
//! ([`Reduced`]) with two AMBs, two displacement sensors and two touchdown bearings at nodes of
//! the shaft, each touchdown bearing the planar race dynamics the rigid rotors call per plane
//! ([`crate::model`]), the spin as for the rigid rotors.
//!
//! **State.** The plant steps fixed-size states, so the reduced coordinates sit in
//! [`MAX_MODES`] slots (a scene whose basis is larger is refused when it loads); the slots past
//! the basis' size stay zero:
//!
//! ```text
//! y = [η_0 … η_{R−1}, θ,  x_A, y_A, θ_A,  x_B, y_B, θ_B,   (their rates)]   R = MAX_MODES
//! ```
//!
//! **Forces** at the force nodes `[AMB A, AMB B, touchdown A, touchdown B]`: each AMB's force
//! at its node's displacement with its plane's current (the continuous PD reads the plane's
//! sensor node), each touchdown bearing's contact force at its node. **Unbalance**: the
//! rotor's eccentricity `e` is every mass's (the rigid rotors' static unbalance: the centre of
//! every section `e` off the axis, in phase), so it enters as the frame's acceleration:
//! `a_f = g ŷ + a_h − e ω² u − e θ̈ J u`, which the rigid-body modes carry exactly. **Spin**:
//! held, or `I_p θ̈ = T_drive + Σ T_i` (free; the eccentricity's coupling to the spin, second
//! order in `e`, is left out).

use super::reduce::Reduced;
use super::rotor::DOF_PER_NODE;
use crate::integrate::System;
use crate::model::{parked_race_spin_accel, race_dynamics, Control, RaceInput, Spin};
use crate::two_plane;
use nalgebra::{DMatrix, DVector, Vector2};
use shock_table::Programme;
use std::sync::Arc;

/// Reduced coordinates the state has room for.
pub const MAX_MODES: usize = 24;
/// State dimension.
pub const N: usize = 2 * (MAX_MODES + 7);
/// The state vector.
pub type State = [f64; N];

/// Indices into [`State`].
pub mod ix {
    use super::MAX_MODES;
    /// Rotor spin angle (rad).
    pub const TR: usize = MAX_MODES;
    /// Race of plane A: x, then y and angle.
    pub const RACE_A: usize = MAX_MODES + 1;
    /// Race of plane B.
    pub const RACE_B: usize = MAX_MODES + 4;
    /// The races' position pairs, plane A then B.
    pub const RACE: [usize; 2] = [RACE_A, RACE_B];
    /// Offset from a position to its rate.
    pub const V: usize = super::N / 2;
    /// Rotor spin speed (rad/s).
    pub const WR: usize = TR + V;
}

/// The nodes of one bearing plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct PlaneNodes {
    /// The AMB's node.
    pub amb: usize,
    /// The displacement sensor's node.
    pub sensor: usize,
    /// The touchdown bearing's node.
    pub touchdown: usize,
}

/// The flexible machine, validated.
#[derive(Clone, Debug)]
pub struct Params {
    /// The machine as the two-plane rotor sees it: gravity, the rigid body (mass, inertias,
    /// eccentricity, speed, spin), each plane's bearing parameters (touchdown bearing, AMB, loop
    /// constants, load share) with the AMB node's station and the sensor node's, from the
    /// centre of mass (m).
    pub machine: two_plane::Params,
    /// Each plane's nodes.
    pub nodes: [PlaneNodes; 2],
    /// The reduced shaft (force nodes AMB A, AMB B, touchdown A, touchdown B).
    pub reduced: Arc<Reduced>,
    /// The finite-element rotor it was reduced from (for its Campbell diagram).
    pub shaft: Arc<super::Rotor>,
    /// Each node's axial position from the centre of mass (m).
    pub z: Vec<f64>,
    /// A ROSS file's plain bearings and what became of each (added to the shaft, ignored for
    /// the AMB at their node, or kept beside it); empty for a shaft given as a table.
    pub file_bearings: Vec<super::ross::UsedBearing>,
    /// A ROSS file's AMB elements made the planes' AMBs (`rotor.ross_ambs`); empty otherwise.
    pub file_ambs: Vec<super::ross_amb::UsedAmb>,
}

/// What one plane does during an evaluation.
pub type PlaneEvaluation = two_plane::PlaneEvaluation;

/// Everything one evaluation computes.
#[derive(Clone, Copy, Debug)]
pub struct Evaluation {
    /// Time derivative of the state.
    pub dy: State,
    /// Planes A and B.
    pub planes: [PlaneEvaluation; 2],
}

/// The model: parameters, base motion, and the control in force at each plane.
#[derive(Clone, Debug)]
pub struct Model {
    /// Physical parameters.
    pub params: Params,
    /// Housing motion.
    pub base: Programme,
    /// Control during the current macro step, plane A then B.
    pub control: [Control; 2],
    /// Each race is parked during the current macro step.
    pub race_parked: [bool; 2],
}

impl Model {
    /// Node `node`'s displacement and velocity relative to the housing (m, m/s).
    pub fn node(&self, y: &State, node: usize) -> (Vector2<f64>, Vector2<f64>) {
        let [x, v] = self.params.reduced.motion_of(&y[..MAX_MODES], &y[ix::V..ix::V + MAX_MODES], node);
        (Vector2::from(x), Vector2::from(v))
    }

    /// Evaluates all forces and the state derivative at time `t`.
    pub fn evaluate(&self, t: f64, y: &State) -> Evaluation {
        let mut dy = [0.0; N];
        let planes = self.evaluate_into(t, y, &mut dy);
        Evaluation { dy, planes }
    }

    /// [`Model::evaluate`] with the derivative written into `dy` (every entry), the planes
    /// returned: the integrator's form, which spares the hot loop a copy of the state.
    pub fn evaluate_into(&self, t: f64, y: &State, dy: &mut State) -> [PlaneEvaluation; 2] {
        use ix::*;
        let p = &self.params;
        let red = &*p.reduced;
        let r = red.size();
        let (eta, rate) = (&y[..MAX_MODES], &y[V..V + MAX_MODES]);
        let at = |node: usize| {
            let [x, v] = red.motion_of(eta, rate, node);
            (Vector2::from(x), Vector2::from(v))
        };
        let a_h = Vector2::from(self.base.accel(t));
        let w = y[WR];
        dy[V..].fill(0.0);
        dy[r..V].copy_from_slice(&y[V + r..]);
        dy[..r].copy_from_slice(&y[V..V + r]);
        let mut planes = [PlaneEvaluation::default(); 2];
        for (i, (plane, out)) in p.machine.planes.iter().zip(&mut planes).enumerate() {
            let bearing = &plane.params;
            let nodes = p.nodes[i];
            // Each node is read once: the AMB's, and the sensor's and the touchdown bearing's
            // where they are not at the AMB (a collocated plane reads one node, not three).
            let amb = at(nodes.amb);
            let delta = amb.0;
            let sensor = || if nodes.sensor == nodes.amb { amb } else { at(nodes.sensor) };
            (out.current, out.amb_force) = self.control[i].amb(t, bearing, delta, sensor);
            let race = RaceInput::of(y, RACE[i]);
            let (x, v) = (RACE[i], RACE[i] + V);
            if self.race_parked[i] {
                dy[x] = 0.0;
                dy[x + 1] = 0.0;
                dy[v + 2] = parked_race_spin_accel(bearing, race.speed, a_h);
            } else {
                let (pos, vel) = if nodes.touchdown == nodes.amb { amb } else { at(nodes.touchdown) };
                let rd = race_dynamics(bearing, race, pos, vel, w, a_h);
                out.contact = rd.contact;
                out.balls = rd.balls;
                dy[v] = rd.accel.x;
                dy[v + 1] = rd.accel.y;
                dy[v + 2] = rd.spin_accel;
            }
        }
        let rotor = &p.machine.rotor;
        let spin_accel = match rotor.spin {
            Spin::Held => 0.0,
            Spin::Free { drive_gain, torque_limit } => {
                let drive = (drive_gain * (rotor.speed - w)).clamp(-torque_limit, torque_limit);
                (drive + planes[0].contact.torque_rotor + planes[1].contact.torque_rotor) / rotor.polar_inertia
            }
        };
        let (sn, cs) = y[TR].sin_cos();
        let e = rotor.eccentricity;
        let frame = [
            a_h.x - e * w * w * cs + e * spin_accel * sn,
            a_h.y + p.machine.gravity - e * w * w * sn - e * spin_accel * cs,
        ];
        let forces = [
            planes[0].amb_force.into(),
            planes[1].amb_force.into(),
            planes[0].contact.on_rotor.into(),
            planes[1].contact.on_rotor.into(),
        ];
        red.accelerations(eta, rate, w, &forces, frame, &mut dy[V..V + r]);
        dy[WR] = spin_accel;
        planes
    }

    /// The rotor's displacement field as the rigid two-plane rotor's state `rigid` puts it
    /// (translation `x, y` at the centre of mass and slopes `a, b`), projected on the basis:
    /// the flexible state that starts where the rigid rotor starts, its races as `rigid`'s.
    pub fn from_rigid(params: &Params, rigid: &two_plane::State) -> State {
        use two_plane::ix as rix;
        let red = &*params.reduced;
        let shaft = &*params.shaft;
        let n = shaft.dof();
        let field = |x: f64, y: f64, a: f64, b: f64| {
            let mut q = DVector::zeros(n);
            for (k, &z) in params.z.iter().enumerate() {
                q[DOF_PER_NODE * k] = x + a * z;
                q[DOF_PER_NODE * k + 1] = y + b * z;
                q[DOF_PER_NODE * k + 2] = -b;
                q[DOF_PER_NODE * k + 3] = a;
            }
            q
        };
        let (position, velocity) = (
            field(rigid[rix::X], rigid[rix::Y], rigid[rix::SX], rigid[rix::SY]),
            field(rigid[rix::VX], rigid[rix::VY], rigid[rix::VSX], rigid[rix::VSY]),
        );
        // `Φᵀ M q`: with the dense mass matrix up to the dense limit (the shipped scenes' start
        // as it was), by its band above it (no full-size square matrix).
        let (eta, rate) = if super::dense_model(shaft) {
            let project: DMatrix<f64> = red.basis.transpose() * shaft.matrices().mass;
            (&project * position, &project * velocity)
        } else {
            let mass = shaft.band_matrices().mass;
            let both = mass.mul(&DMatrix::from_columns(&[position, velocity]));
            (red.basis.transpose() * both.column(0), red.basis.transpose() * both.column(1))
        };
        let mut y = [0.0; N];
        let r = red.size();
        y[..r].copy_from_slice(eta.as_slice());
        y[ix::V..ix::V + r].copy_from_slice(rate.as_slice());
        y[ix::TR] = rigid[rix::TR];
        y[ix::WR] = rigid[rix::WR];
        for (fx, rx) in ix::RACE.iter().zip(rix::RACE) {
            for k in 0..3 {
                y[fx + k] = rigid[rx + k];
                y[fx + k + ix::V] = rigid[rx + k + rix::V];
            }
        }
        y
    }
}

impl System<N> for Model {
    #[inline]
    fn rhs(&self, t: f64, y: &State, dy: &mut State) {
        self.evaluate_into(t, y, dy);
    }
}
