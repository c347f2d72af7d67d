//! The two-plane rotor (MODEL.md §10): a rigid rotor that translates and tilts, on two radial
//! AMBs with a touchdown bearing beside each, four controlled axes. A pure derivative on a
//! fixed-size state, as [`crate::model`] is for the planar model.
//!
//! **Frame and coordinates.** `z` is the rotor axis, from plane A towards plane B, its origin
//! at the rotor's centre of mass; `x` horizontal, `y` up, the spin `Ω` about `+z`. The rotor's
//! geometric axis is given by its point `(x, y)` at the station `z = 0`, relative to the housing,
//! and its slopes `a = dx/dz`, `b = dy/dz` (small angles): the axis passes a station `z` at
//! `(x + a z, y + b z)`. The housing (stators, sensors, the touchdown bearings' outer rings)
//! translates with the shock, the same at both planes, and does not rotate: each body feels
//! `−m (g ŷ + a_h)` at its mass centre, which exerts no moment about the rotor's centre of mass.
//!
//! State ordering (SI), positions then velocities, as [`crate::integrate`]'s symplectic Euler
//! expects:
//!
//! ```text
//! y = [x, y, a, b, θ,  x_A, y_A, θ_A,  x_B, y_B, θ_B,   (their 11 rates)]
//! ```
//!
//! `θ` the spin angle (the static unbalance lies at `θ`), `(x_i, y_i, θ_i)` the race of plane
//! `i` relative to the housing.
//!
//! **Equations** (derivation in MODEL.md §10; `u = (cos θ, sin θ)`, `J u = (−sin θ, cos θ)`,
//! `f = g ŷ + a_h`, `F_i` the bearing force plus the contact force on the rotor at plane `i`,
//! at station `z_i`; `ψ = θ + φ_c`; `κ = (I_t − I_p) χ` the couple unbalance):
//!
//! ```text
//! R = M e ω² u + Σ F_i − M f
//! M r̈ = R + M e θ̈ J u
//! I_t ä + I_p ω ḃ = Σ z_i F_ix + κ (ω² cos ψ + θ̈ sin ψ)
//! I_t b̈ − I_p ω ȧ = Σ z_i F_iy + κ (ω² sin ψ − θ̈ cos ψ)
//! (I_p − κ²/I_t) θ̈ = T_drive + Σ T_i − M e (u × f) + e (R × u) + κ (G_a sin ψ − G_b cos ψ) / I_t
//! ```
//!
//! with `G_a`, `G_b` the right-hand sides of the tilt rows without their `κ` terms. With the
//! speed held (default) `θ̈ = 0`. Each race obeys the planar model's equations in its plane
//! (MODEL.md §4, §5), seeing the rotor's axis at its station.
//!
//! The planar model is the symmetric case: with the centre of mass mid-span, identical planes
//! and no couple unbalance, every plane's force is the same, the moments cancel exactly, the
//! slopes stay zero and `R / M` is the planar `R / m` bit for bit (`M = 2 m`).

pub mod initial;
pub mod linear;

use crate::force::balls::BallForce;
use crate::force::rotor_race::RotorRaceForce;
use crate::integrate::System;
use crate::model::{self, parked_race_spin_accel, race_dynamics, Control, RaceInput, Spin};
use nalgebra::Vector2;
use shock_table::Programme;

/// State dimension.
pub const N: usize = 22;
/// The state vector (see the module doc for its ordering).
pub type State = [f64; N];

/// Indices into [`State`].
pub mod ix {
    /// Rotor axis x at the centre of mass's station, relative to the housing (m).
    pub const X: usize = 0;
    /// Rotor axis y at the centre of mass's station, relative to the housing (m).
    pub const Y: usize = 1;
    /// Slope a = dx/dz of the rotor axis (rad).
    pub const SX: usize = 2;
    /// Slope b = dy/dz of the rotor axis (rad).
    pub const SY: usize = 3;
    /// Rotor spin angle (rad).
    pub const TR: usize = 4;
    /// Race of plane A: x, then y and angle (m, m, rad).
    pub const RACE_A: usize = 5;
    /// Race of plane B: x, then y and angle (m, m, rad).
    pub const RACE_B: usize = 8;
    /// The races' position pairs, plane A then B.
    pub const RACE: [usize; 2] = [RACE_A, RACE_B];
    /// Offset from a position to its rate.
    pub const V: usize = super::N / 2;
    /// Rotor x velocity (m/s).
    pub const VX: usize = X + V;
    /// Rotor y velocity (m/s).
    pub const VY: usize = Y + V;
    /// Slope rate ȧ (rad/s).
    pub const VSX: usize = SX + V;
    /// Slope rate ḃ (rad/s).
    pub const VSY: usize = SY + V;
    /// Rotor spin speed (rad/s).
    pub const WR: usize = TR + V;
}

/// The rigid rotor.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Rotor {
    /// Whole mass M (kg).
    pub mass: f64,
    /// Transverse moment of inertia I_t about the centre of mass (kg·m²), > 0.
    pub transverse_inertia: f64,
    /// Polar moment of inertia I_p (kg·m²), > 0.
    pub polar_inertia: f64,
    /// Static unbalance: the centre of mass is `e` (m) off the geometric axis, at spin angle θ.
    pub eccentricity: f64,
    /// Couple unbalance: the principal axis of inertia is tilted by `χ` (rad) from the geometric
    /// axis, towards the rotor-fixed direction at angle `couple_phase` from the static unbalance.
    pub couple: f64,
    /// Angle φ_c of the couple unbalance from the static unbalance (rad).
    pub couple_phase: f64,
    /// Rated speed ω (rad/s); held, or the speed loop's target.
    pub speed: f64,
    /// Spin treatment (the drive acts on the whole rotor).
    pub spin: Spin,
}

impl Rotor {
    /// `κ = (I_t − I_p) χ` (kg·m²): the couple unbalance's moment is `κ ω²`.
    pub fn couple_moment(&self) -> f64 {
        (self.transverse_inertia - self.polar_inertia) * self.couple
    }
}

/// One bearing plane: an AMB and a touchdown bearing at axial station `station`, read by a
/// sensor at `sensor`.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Plane {
    /// Axial position z of the bearing (the AMB's actuator and the touchdown bearing) from the
    /// centre of mass (m).
    pub station: f64,
    /// Axial position z of the displacement sensor (m); equal to `station` when collocated.
    pub sensor: f64,
    /// The plane as the planar model it is one share of: its touchdown bearing (race, balls,
    /// cage, drag, contact, parking), its AMB (force law, loop constants, current limit), and
    /// the rotor's share carried by this bearing (`rotor_mass` its static load share,
    /// `rotor_inertia` the same share of I_p, the rotor's eccentricity, speed and spin). The
    /// two-plane derivative reads the bearing's fields; the rotor's come from [`Rotor`].
    pub params: model::Params,
}

/// Physical parameters of the two-plane machine, validated, SI.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Params {
    /// Gravity g (m/s²).
    pub gravity: f64,
    /// The rotor.
    pub rotor: Rotor,
    /// Bearing planes A and B (`planes[0].station < 0 < planes[1].station`).
    pub planes: [Plane; 2],
}

impl Params {
    /// The share of the rotor's weight that plane `i` carries at rest (kg): `M z_B / (z_B − z_A)`
    /// for A, `M (−z_A) / (z_B − z_A)` for B (the bearing forces balance the weight and have no
    /// moment about the centre of mass).
    pub fn load_share(&self, i: usize) -> f64 {
        load_share(self.rotor.mass, [self.planes[0].station, self.planes[1].station], i)
    }
}

/// [`Params::load_share`] for a rotor of mass `mass` (kg) with bearings at `stations` (m).
pub fn load_share(mass: f64, stations: [f64; 2], i: usize) -> f64 {
    let [za, zb] = stations;
    let other = if i == 0 { zb } else { -za };
    mass * (other / (zb - za))
}

/// What one plane does during an evaluation.
#[derive(Clone, Copy, Debug, Default)]
pub struct PlaneEvaluation {
    /// Rotor – race contact.
    pub contact: RotorRaceForce,
    /// Ball contacts.
    pub balls: BallForce,
    /// Coil currents after the amplifier limit (A), x then y.
    pub current: [f64; 2],
    /// AMB force on the rotor (N).
    pub amb_force: Vector2<f64>,
}

/// Everything one evaluation computes; `dy` is the derivative.
#[derive(Clone, Copy, Debug)]
pub struct Evaluation {
    /// Time derivative of the state.
    pub dy: State,
    /// Planes A and B.
    pub planes: [PlaneEvaluation; 2],
    /// Housing acceleration (m/s²).
    pub housing_accel: Vector2<f64>,
}

/// The model: parameters, base motion, and the control in force at each plane.
#[derive(Clone, Debug)]
pub struct Model {
    /// Physical parameters.
    pub params: Params,
    /// Housing motion (the same at both planes).
    pub base: Programme,
    /// Control during the current macro step, plane A then B.
    pub control: [Control; 2],
    /// Each race is parked during the current macro step ([`crate::park`]), plane A then B.
    pub race_parked: [bool; 2],
}

#[inline]
fn pair(y: &State, i: usize) -> Vector2<f64> {
    Vector2::new(y[i], y[i + 1])
}

#[inline]
fn set_pair(dy: &mut State, i: usize, v: Vector2<f64>) {
    dy[i] = v.x;
    dy[i + 1] = v.y;
}

/// Where the rotor axis is at station `z` (m) and how it moves there, relative to the housing.
#[inline]
pub fn at_station(y: &State, z: f64) -> (Vector2<f64>, Vector2<f64>) {
    use ix::*;
    (pair(y, X) + pair(y, SX) * z, pair(y, VX) + pair(y, VSX) * z)
}

impl Model {
    /// Evaluates all forces and the state derivative at time `t`.
    #[inline]
    pub fn evaluate(&self, t: f64, y: &State) -> Evaluation {
        use ix::*;
        let p = &self.params;
        let rotor = &p.rotor;
        let a_h = Vector2::from(self.base.accel(t));
        let w = y[WR];
        let mut dy = [0.0; N];
        dy[..V].copy_from_slice(&y[V..]);
        let mut planes = [PlaneEvaluation::default(); 2];
        for (i, (plane, out)) in p.planes.iter().zip(&mut planes).enumerate() {
            let bearing = &plane.params;
            let (delta, velocity) = at_station(y, plane.station);
            (out.current, out.amb_force) = self.control[i].amb(t, bearing, delta, || at_station(y, plane.sensor));
            let race = RaceInput::of(y, RACE[i]);
            let (x, v) = (RACE[i], RACE[i] + V);
            if self.race_parked[i] {
                // Translation frozen in the housing frame; the spin runs down under the drag.
                dy[x] = 0.0;
                dy[x + 1] = 0.0;
                dy[v + 2] = parked_race_spin_accel(bearing, race.speed, a_h);
            } else {
                let r = race_dynamics(bearing, race, delta, velocity, w, a_h);
                out.contact = r.contact;
                out.balls = r.balls;
                set_pair(&mut dy, v, r.accel);
                dy[v + 2] = r.spin_accel;
            }
        }
        let [pa, pb] = &planes;
        let (za, zb) = (p.planes[0].station, p.planes[1].station);

        // Translation and spin (the planar model's equations with the sums of both planes).
        let (m, e) = (rotor.mass, rotor.eccentricity);
        let (s, c) = y[TR].sin_cos();
        let unbalance = Vector2::new(c, s);
        let frame = Vector2::new(a_h.x, a_h.y + p.gravity);
        let r =
            unbalance * (m * e * w * w) + (pa.amb_force + pb.amb_force) + (pa.contact.on_rotor + pb.contact.on_rotor)
                - frame * m;
        // Tilt: the moments of the bearing and contact forces about the centre of mass and the
        // gyroscopic coupling.
        let moment = (pa.amb_force + pa.contact.on_rotor) * za + (pb.amb_force + pb.contact.on_rotor) * zb;
        let (ip, it) = (rotor.polar_inertia, rotor.transverse_inertia);
        let g_a = moment.x - ip * w * y[VSY];
        let g_b = moment.y + ip * w * y[VSX];
        let kappa = rotor.couple_moment();
        let (sp, cp) = if kappa != 0.0 { (y[TR] + rotor.couple_phase).sin_cos() } else { (0.0, 0.0) };
        let spin_accel = match rotor.spin {
            Spin::Held => 0.0,
            Spin::Free { drive_gain, torque_limit } => {
                let drive = (drive_gain * (rotor.speed - w)).clamp(-torque_limit, torque_limit);
                let r3 = drive + (pa.contact.torque_rotor + pb.contact.torque_rotor) - m * e * unbalance.perp(&frame);
                let torque = r3 + e * r.perp(&unbalance);
                if kappa != 0.0 {
                    (torque + kappa * (g_a * sp - g_b * cp) / it) / (ip - kappa * kappa / it)
                } else {
                    torque / ip
                }
            }
        };
        set_pair(&mut dy, VX, (r - Vector2::new(-s, c) * (m * e) * spin_accel) / m);
        let (ua, ub) = if kappa != 0.0 {
            let w2 = w * w;
            (kappa * (w2 * cp + spin_accel * sp), kappa * (w2 * sp - spin_accel * cp))
        } else {
            (0.0, 0.0)
        };
        dy[VSX] = (g_a + ua) / it;
        dy[VSY] = (g_b + ub) / it;
        dy[WR] = spin_accel;
        Evaluation { dy, planes, housing_accel: a_h }
    }
}

impl System<N> for Model {
    #[inline]
    fn rhs(&self, t: f64, y: &State, dy: &mut State) {
        *dy = self.evaluate(t, y).dy;
    }
}

/// The energy and angular momentum of the rigid rotor (the conserved quantities of
/// [`Model::evaluate`] without bearing, contact, drive, gravity or shock), about its centre of
/// mass and the housing frame's origin (SI).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Invariants {
    /// Kinetic energy `½ M |v_G|² + ½ I_t (ȧ² + ḃ²) + ½ I_p ω² − κ ω (ȧ sin ψ − ḃ cos ψ)` (J).
    pub energy: f64,
    /// Angular momentum: the centre of mass's orbit `M (r_G × v_G)` (z component only, the
    /// motion being transverse) plus the rotor's own about G, linearised in the slopes:
    /// `H_x = −I_t ḃ + I_p ω a − κ ω cos ψ`, `H_y = I_t ȧ + I_p ω b − κ ω sin ψ`,
    /// `H_z = I_p ω − κ (ȧ sin ψ − ḃ cos ψ)` (N·m·s).
    pub angular_momentum: [f64; 3],
}

/// The rotor's [`Invariants`] in state `y`.
pub fn invariants(rotor: &Rotor, y: &State) -> Invariants {
    use ix::*;
    let (m, e, w) = (rotor.mass, rotor.eccentricity, y[WR]);
    let (s, c) = y[TR].sin_cos();
    let g = pair(y, X) + Vector2::new(c, s) * e;
    let v_g = pair(y, VX) + Vector2::new(-s, c) * (e * w);
    let (it, ip, kappa) = (rotor.transverse_inertia, rotor.polar_inertia, rotor.couple_moment());
    let (sp, cp) = (y[TR] + rotor.couple_phase).sin_cos();
    let (a, b, da, db) = (y[SX], y[SY], y[VSX], y[VSY]);
    // T_cu = (I_p − I_t) χ ω (ȧ sin ψ − ḃ cos ψ) = −κ ω (ȧ sin ψ − ḃ cos ψ).
    let energy = 0.5 * m * v_g.norm_squared() + 0.5 * it * (da * da + db * db) + 0.5 * ip * w * w
        - kappa * w * (da * sp - db * cp);
    let orbit = m * g.perp(&v_g);
    Invariants {
        energy,
        angular_momentum: [
            -it * db + ip * w * a - kappa * w * cp,
            it * da + ip * w * b - kappa * w * sp,
            ip * w - kappa * (da * sp - db * cp) + orbit,
        ],
    }
}
