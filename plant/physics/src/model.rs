//! The plant's equations of motion: a pure derivative on a fixed-size state.
//!
//! Frames: positions are taken **relative to the housing** (the stator, the
//! TDB outer ring and the sensor form one rigid body moved by the shock), so
//! the state holds directly what the sensor and the contacts see. The housing
//! frame is accelerated by `a_h(t)`; each body feels the fictitious force
//! `−m a_h(t)` at its mass centre. This is the same model as MODEL.md's
//! inertial-frame equations, written where the gaps live.
//!
//! State ordering (SI), positions then velocities, as [`crate::integrate`]'s
//! symplectic Euler expects:
//!
//! ```text
//! y = [x_r, y_r, θ_r, x_b, y_b, θ_b,  ẋ_r, ẏ_r, ω_r, ẋ_b, ẏ_b, ω_b]
//! ```
//!
//! rotor geometric centre (x_r, y_r), spin angle θ_r; inner race centre
//! (x_b, y_b) and angle θ_b; the cage angle is kinematic:
//! `θ_c = θ_c0 + θ_b R_in / (R_in + R_out)` (rotating cage) or `θ_c0` (fixed).
//!
//! Rotor (MODEL.md §2, `s = sin θ_r`, `c = cos θ_r`, unbalance e at θ_r):
//!
//! ```text
//! m ẍ − m e s θ̈ = m e ω² c + F_x − m a_hx
//! m ÿ + m e c θ̈ = m e ω² s + F_y − m g − m a_hy
//! (J + m e²) θ̈ − m e s ẍ + m e c ÿ = T_drive + T_contact − m e ((g + a_hy) c − a_hx s)
//! ```
//!
//! Eliminating ẍ, ÿ gives `J θ̈ = R_3 + e (s R_1 − c R_2)` with `R_i` the
//! right-hand sides. With the speed held (default) `θ̈ = 0`.
//! Race: `m_b ẍ_b = −F_contact + F_balls − m_b (g ŷ + a_h)`,
//! `J_b θ̈_b = r_inner F_t + M_drag`.
//!
//! In vector form (2-D, `u = (c, s)` the unbalance direction, `f = g ŷ + a_h` the
//! housing frame's specific force, `a × b = a_x b_y − a_y b_x`):
//! `R = m e ω² u + F_amb + F_contact − m f`, `R_3 = T_drive + T_contact − m e (u × f)`,
//! `J θ̈ = R_3 + e (R × u)`, `m r̈ = R − m e θ̈ J u` (`J u = (−s, c)`, the +90° turn).
//!
//! The state stays a plain array that the integrators step; the kernels take
//! [`nalgebra::Vector2`] views of its pairs, on the stack, without allocation.

use crate::axes::Axes;
use crate::force::lumped::LumpedSupport;
use crate::force::rotor_race::RotorRaceForce;
use crate::force::{amb::AmbLaw, balls::BallForce, balls::BallSet, drag::RaceDrag, rotor_race::RotorRace};
use crate::integrate::System;
use controller::{saturate, LoopConstants, PdGains};
use nalgebra::Vector2;
use shock_table::Programme;

/// State dimension.
pub const N: usize = 12;
/// The state vector (see the module doc for its ordering).
pub type State = [f64; N];

/// Indices into [`State`].
pub mod ix {
    /// Rotor x relative to housing (m).
    pub const XR: usize = 0;
    /// Rotor y relative to housing (m).
    pub const YR: usize = 1;
    /// Rotor spin angle (rad).
    pub const TR: usize = 2;
    /// Race x relative to housing (m).
    pub const XB: usize = 3;
    /// Race y relative to housing (m).
    pub const YB: usize = 4;
    /// Race angle (rad).
    pub const TB: usize = 5;
    /// Rotor x velocity (m/s).
    pub const VXR: usize = 6;
    /// Rotor y velocity (m/s).
    pub const VYR: usize = 7;
    /// Rotor spin speed (rad/s).
    pub const WR: usize = 8;
    /// Race x velocity (m/s).
    pub const VXB: usize = 9;
    /// Race y velocity (m/s).
    pub const VYB: usize = 10;
    /// Race spin speed (rad/s).
    pub const WB: usize = 11;
}

/// How the rotor's spin is treated.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "spin", rename_all = "snake_case")]
pub enum Spin {
    /// The drive holds the speed exactly (the study's setup): θ̈_r = 0.
    Held,
    /// The spin is integrated; a proportional speed loop drives it.
    Free {
        /// Speed-loop gain (N·m·s/rad).
        drive_gain: f64,
        /// Drive torque limit (N·m).
        torque_limit: f64,
    },
}

/// How the balls move.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Cage {
    /// The cage rolls with the race: θ̇_c = θ̇_b R_in / (R_in + R_out).
    Rotating,
    /// The balls stay at their initial angles.
    Fixed,
}

/// What carries the inner race.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(tag = "support", rename_all = "snake_case")]
pub enum Support {
    /// The individual balls (MODEL.md §5), the study's model.
    Balls,
    /// An isotropic Hertz ring calibrated on the ball set (a simplification).
    Lumped(LumpedSupport),
}

/// What the race does while the rotor – race gap is open by a safe margin ([`crate::park`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(tag = "race_when_clear", content = "release", rename_all = "snake_case")]
pub enum RaceWhenClear {
    /// Always integrated on its supports (the study's model, default).
    Free,
    /// Held in the housing frame while the gap is clear; released with the given state.
    Parked(Release),
}

/// The state a parked race is released with when the gap may close.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Release {
    /// At rest on its supports under gravity and the current housing acceleration (default).
    Equilibrium,
    /// Where it was parked, at rest relative to the housing.
    Held,
}

/// The touchdown bearing's geometry (SI): what its duty (contact pressures, ball loads) needs
/// beyond the equations of motion, which do not read it.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct TouchdownGeometry {
    /// Ball diameter D (m).
    pub ball_diameter: f64,
    /// Pitch diameter d_m (m).
    pub pitch_diameter: f64,
    /// Race width B, the rotor – race contact length (m).
    pub width: f64,
}

/// Physical parameters, validated, SI.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Params {
    /// Gravity g (m/s²).
    pub gravity: f64,
    /// Rotor mass m_r (kg).
    pub rotor_mass: f64,
    /// Unbalance eccentricity e (m).
    pub eccentricity: f64,
    /// Rotor polar moment of inertia J_r (kg·m²).
    pub rotor_inertia: f64,
    /// Rated speed ω (rad/s); held, or the speed loop's target.
    pub speed: f64,
    /// Spin treatment.
    pub spin: Spin,
    /// Race mass m_b (kg).
    pub race_mass: f64,
    /// Race polar moment J_b (kg·m²).
    pub race_inertia: f64,
    /// Cage motion.
    pub cage: Cage,
    /// Cage angle at θ_b = 0 (rad): where ball 0 sits.
    pub cage_phase: f64,
    /// R_in / (R_in + R_out).
    pub cage_ratio: f64,
    /// Rotor – race contact.
    pub contact: RotorRace,
    /// Race – ball contacts.
    pub balls: BallSet,
    /// What carries the race: the balls, or a lumped ring.
    pub support: Support,
    /// Whether the race is parked while the gap is clear.
    pub race_when_clear: RaceWhenClear,
    /// Race drag.
    pub drag: RaceDrag,
    /// Bearing force law.
    pub amb: AmbLaw,
    /// Constants of the AMB loop (sensor, amplifier, k_i, k_s).
    pub loop_constants: LoopConstants,
    /// Amplifier current limit i_max (A).
    pub current_limit: f64,
    /// The plane's own axes (u, v) of its coil pairs and sensors, turned from (x, y)
    /// ([`crate::axes`]); the default: not turned. Not serialised at 0°.
    #[serde(skip_serializing_if = "Axes::is_housings")]
    pub axes: Axes,
    /// The touchdown bearing's geometry, for its duty (not in the equations of motion; not
    /// serialised, so that what is serialised of the parameters stays as it was).
    #[serde(skip)]
    pub touchdown: TouchdownGeometry,
}

impl Params {
    /// Force of the race's support for race position `eps` (m) and velocity `eps_dot` (m/s)
    /// relative to the housing, cage angle `cage` (rad) and rate `cage_rate` (rad/s).
    #[inline]
    pub fn race_support(&self, eps: Vector2<f64>, eps_dot: Vector2<f64>, cage: f64, cage_rate: f64) -> BallForce {
        match self.support {
            Support::Balls => self.balls.force(eps, eps_dot, cage, cage_rate),
            Support::Lumped(ring) => ring.force(eps, eps_dot),
        }
    }
}

/// The cage angle (rad) for race angle `theta_b` (rad): see [`Cage`].
pub fn cage_angle(p: &Params, theta_b: f64) -> f64 {
    match p.cage {
        Cage::Rotating => p.cage_phase + p.cage_ratio * theta_b,
        Cage::Fixed => p.cage_phase,
    }
}

/// Where the coil current comes from during a derivative evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Control {
    /// PD evaluated inside the derivative on the exact Δ, Δ̇ (the study's setup).
    Continuous(PdGains),
    /// The continuous PD reading its sensor signal plus a sine ([`SensorSine`]): the summing
    /// point of a sensitivity measurement (ISO 14839-3) on the continuous loop.
    ContinuousExcited(PdGains, SensorSine),
    /// A current held over the macro step (zero-order hold of a sampled law).
    Held([f64; 2]),
    /// Each magnet's own current, x then y (A): `plus` the magnet on the + side of each axis,
    /// `minus` the one on the − side ([`AmbLaw::magnet_force`]). Unipolar amplifiers
    /// (MODEL.md §12.3) drive the plane this way; its current is the differential
    /// `(i₊ − i₋)/2`.
    Magnets {
        /// The + side's magnets (A).
        plus: [f64; 2],
        /// The − side's magnets (A).
        minus: [f64; 2],
    },
}

impl Control {
    /// The coil current (A, x then y) and the AMB's force (N) of a bearing `p` whose rotor sits
    /// at `delta` (m) in the magnets' gap, at time `t`; the continuous laws read `sensor()`, the
    /// sensor's position and rate (m, m/s), only when they need it. One match for every rotor
    /// model (planar, two-plane, flexible).
    ///
    /// With the plane's axes turned ([`Params::axes`]) the currents are the coil pairs' of u and
    /// v, the law reads `delta` and the sensor in (u, v), and the force it gives is turned back
    /// to (x, y); not turned, the arithmetic is the one of before the axes could turn.
    #[inline]
    pub(crate) fn amb(
        self,
        t: f64,
        p: &Params,
        delta: Vector2<f64>,
        sensor: impl FnOnce() -> (Vector2<f64>, Vector2<f64>),
    ) -> ([f64; 2], Vector2<f64>) {
        if p.axes.turned() {
            return self.amb_turned(t, p, delta, sensor);
        }
        self.amb_plane(t, p, delta, sensor)
    }

    /// [`Control::amb`] with the plane's axes turned: the plane's own arithmetic in (u, v).
    #[cold]
    #[inline(never)]
    fn amb_turned(
        self,
        t: f64,
        p: &Params,
        delta: Vector2<f64>,
        sensor: impl FnOnce() -> (Vector2<f64>, Vector2<f64>),
    ) -> ([f64; 2], Vector2<f64>) {
        let axes = p.axes;
        let turned = || {
            let (x, v) = sensor();
            (axes.to_plane(x), axes.to_plane(v))
        };
        let (current, force) = self.amb_plane(t, p, axes.to_plane(delta), turned);
        (current, axes.to_housing(force))
    }

    /// [`Control::amb`] in the plane's own axes: `delta` and the sensor read along them, the
    /// force along them.
    #[inline(always)]
    fn amb_plane(
        self,
        t: f64,
        p: &Params,
        delta: Vector2<f64>,
        sensor: impl FnOnce() -> (Vector2<f64>, Vector2<f64>),
    ) -> ([f64; 2], Vector2<f64>) {
        let current = match self {
            Control::Continuous(gains) => {
                let a_s = p.loop_constants.sensor_gain_v_per_m;
                let (x, v) = sensor();
                saturate(gains.current((x * a_s).into(), (v * a_s).into()), p.current_limit)
            }
            Control::ContinuousExcited(gains, sine) => {
                // The excitation is added at the sensor, before the PD (its rate to the rate).
                let a_s = p.loop_constants.sensor_gain_v_per_m;
                let (x, v) = sensor();
                let (e, e_dot) = sine.at(t);
                let u = x * a_s + Vector2::from(e);
                let u_dot = v * a_s + Vector2::from(e_dot);
                saturate(gains.current(u.into(), u_dot.into()), p.current_limit)
            }
            Control::Held(i) => i,
            Control::Magnets { plus, minus } => [(plus[0] - minus[0]) * 0.5, (plus[1] - minus[1]) * 0.5],
        };
        let force = match self {
            // Unipolar amplifiers: each magnet's own current.
            Control::Magnets { plus, minus } => p.amb.magnet_force(delta, plus.into(), minus.into()),
            _ => p.amb.force(delta, current.into()),
        };
        (current, force)
    }
}

/// A sine added to the sensor signal the controller reads, per axis (V):
/// `E(t) = a_k sin(ω t + φ)`, with its rate `Ė(t) = a_k ω cos(ω t + φ)`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct SensorSine {
    /// Amplitude per axis, x then y (V); 0 on an axis not excited.
    pub amplitude_v: [f64; 2],
    /// Angular frequency ω (rad/s).
    pub omega_rad_s: f64,
    /// Phase φ at t = 0 (rad).
    pub phase_rad: f64,
}

impl SensorSine {
    /// `(E(t), Ė(t))` per axis (V, V/s).
    ///
    /// ```
    /// use plant_physics::model::SensorSine;
    /// let e = SensorSine { amplitude_v: [0.0, 2.0], omega_rad_s: 3.0, phase_rad: 0.0 };
    /// let (v, rate) = e.at(0.0);
    /// assert_eq!((v, rate), ([0.0, 0.0], [0.0, 6.0]));
    /// ```
    #[inline]
    pub fn at(&self, t: f64) -> ([f64; 2], [f64; 2]) {
        let (s, c) = (self.omega_rad_s * t + self.phase_rad).sin_cos();
        let a = self.amplitude_v;
        ([a[0] * s, a[1] * s], [a[0] * self.omega_rad_s * c, a[1] * self.omega_rad_s * c])
    }
}

/// The model: parameters, base motion, and the control in force.
#[derive(Clone, Debug)]
pub struct Model {
    /// Physical parameters.
    pub params: Params,
    /// Housing motion.
    pub base: Programme,
    /// Control during the current macro step.
    pub control: Control,
    /// The race is parked during the current macro step: its translation is frozen in the
    /// housing frame (derivative zero), the support and rotor – race kernels are skipped, and
    /// only its spin runs down under the drag (load: its weight under gravity and the housing
    /// acceleration). Set by the run loop ([`crate::park`]); `false` gives the full model.
    pub race_parked: bool,
}

/// Everything one evaluation computes; `dy` is the derivative.
#[derive(Clone, Copy, Debug, Default)]
pub struct Evaluation {
    /// Time derivative of the state.
    pub dy: State,
    /// Rotor – race contact.
    pub contact: RotorRaceForce,
    /// Ball contacts.
    pub balls: BallForce,
    /// Coil currents after the amplifier limit (A).
    pub current: [f64; 2],
    /// AMB force on the rotor (N).
    pub amb_force: Vector2<f64>,
    /// Housing acceleration (m/s²).
    pub housing_accel: Vector2<f64>,
}

/// The pair `(y[i], y[i + 1])` of the state as a vector.
#[inline]
fn pair(y: &State, i: usize) -> Vector2<f64> {
    Vector2::new(y[i], y[i + 1])
}

/// Writes `v` into the pair `(dy[i], dy[i + 1])`.
#[inline]
fn set_pair(dy: &mut State, i: usize, v: Vector2<f64>) {
    dy[i] = v.x;
    dy[i + 1] = v.y;
}

/// The specific force of the housing frame, `f = g ŷ + a_h` (m/s²): each body of mass `m`
/// feels `−m f` in it. Built per component, so that `f_x` is `a_h,x` itself (the sums the
/// derivative made before nalgebra, bit for bit).
#[inline]
fn frame_force(g: f64, a_h: Vector2<f64>) -> Vector2<f64> {
    Vector2::new(a_h.x, a_h.y + g)
}

/// A touchdown race's state, relative to the housing: centre (m), velocity (m/s), angle (rad)
/// and spin speed (rad/s).
#[derive(Clone, Copy, Debug)]
pub(crate) struct RaceInput {
    pub(crate) position: Vector2<f64>,
    pub(crate) velocity: Vector2<f64>,
    pub(crate) angle: f64,
    pub(crate) speed: f64,
}

impl RaceInput {
    /// The race of a state whose race position pair starts at `x` (its angle at `x + 2`, its
    /// velocities `n/2` further on: the `[positions; velocities]` layout of a state of size `n`).
    #[inline]
    pub(crate) fn of<const M: usize>(y: &[f64; M], x: usize) -> Self {
        let v = x + M / 2;
        Self {
            position: Vector2::new(y[x], y[x + 1]),
            velocity: Vector2::new(y[v], y[v + 1]),
            angle: y[x + 2],
            speed: y[v + 2],
        }
    }
}

/// What one touchdown bearing does at an instant: the rotor – race contact, the support's force
/// on the race, and the race's accelerations relative to the housing.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RaceDynamics {
    pub(crate) contact: RotorRaceForce,
    pub(crate) balls: BallForce,
    /// The race centre's acceleration relative to the housing (m/s²).
    pub(crate) accel: Vector2<f64>,
    /// The race's angular acceleration (rad/s²).
    pub(crate) spin_accel: f64,
}

/// One bearing plane's touchdown bearing (MODEL.md §4, §5), the kernel both rotor models call
/// per plane: the rotor's centre in that plane at `rotor` (m) moving at `rotor_v` (m/s) and
/// spinning at `w` (rad/s), the race `race`, the housing accelerated by `a_h` (m/s²). The race
/// obeys `m_b r̈_b = F_balls − F_contact − m_b (g ŷ + a_h)`, `J_b θ̈_b = r_inner F_t + M_drag`.
///
/// Always inlined: called from two models, it would otherwise become a function of its own,
/// which the compiler optimises worse than the code inlined in each derivative (the planar
/// derivative took 7 % more instructions that way, `examples/derivative_count.rs`).
#[inline(always)]
pub(crate) fn race_dynamics(
    p: &Params,
    race: RaceInput,
    rotor: Vector2<f64>,
    rotor_v: Vector2<f64>,
    w: f64,
    a_h: Vector2<f64>,
) -> RaceDynamics {
    let contact = p.contact.force(rotor - race.position, rotor_v - race.velocity, w, race.speed);
    let (cage, cage_rate) = match p.cage {
        Cage::Rotating => (p.cage_phase + p.cage_ratio * race.angle, p.cage_ratio * race.speed),
        Cage::Fixed => (p.cage_phase, 0.0),
    };
    let balls = p.race_support(race.position, race.velocity, cage, cage_rate);
    let race_load = balls.on_race.norm();
    let race_torque = contact.torque_race + p.drag.torque(race.speed, race_load);
    RaceDynamics {
        contact,
        balls,
        accel: (balls.on_race - contact.on_rotor) / p.race_mass - Vector2::new(0.0, p.gravity) - a_h,
        spin_accel: race_torque / p.race_inertia,
    }
}

/// The spin deceleration of a parked race (rad/s²): the drag at speed `speed` (rad/s) under
/// the race's weight in the housing frame, `m_b |g ŷ + a_h|`.
#[inline]
pub(crate) fn parked_race_spin_accel(p: &Params, speed: f64, a_h: Vector2<f64>) -> f64 {
    let frame = frame_force(p.gravity, a_h);
    // hypot, not a norm, as before (kept for bit-identical traces).
    let load = p.race_mass * frame.x.hypot(frame.y);
    p.drag.torque(speed, load) / p.race_inertia
}

impl Model {
    /// Evaluates all forces and the state derivative at time `t`.
    #[inline]
    pub fn evaluate(&self, t: f64, y: &State) -> Evaluation {
        use ix::*;
        let p = &self.params;
        let a_h = Vector2::from(self.base.accel(t));
        let delta = pair(y, XR);
        let (current, amb_force) = self.control.amb(t, p, delta, || (delta, pair(y, VXR)));
        if self.race_parked {
            return self.evaluate_parked(t, y, a_h, current, amb_force);
        }

        let race = race_dynamics(p, RaceInput::of(y, XB), delta, pair(y, VXR), y[WR], a_h);
        let contact = race.contact;

        // Rotor.
        let (m, e, g) = (p.rotor_mass, p.eccentricity, p.gravity);
        let (s, c) = y[TR].sin_cos();
        let unbalance = Vector2::new(c, s);
        let frame = frame_force(g, a_h);
        let w = y[WR];
        let r = unbalance * (m * e * w * w) + amb_force + contact.on_rotor - frame * m;
        let spin_accel = match p.spin {
            Spin::Held => 0.0,
            Spin::Free { drive_gain, torque_limit } => {
                let drive = (drive_gain * (p.speed - w)).clamp(-torque_limit, torque_limit);
                let r3 = drive + contact.torque_rotor - m * e * unbalance.perp(&frame);
                (r3 + e * r.perp(&unbalance)) / p.rotor_inertia
            }
        };

        let mut dy = [0.0; N];
        dy[..6].copy_from_slice(&y[6..]);
        set_pair(&mut dy, VXR, (r - Vector2::new(-s, c) * (m * e) * spin_accel) / m);
        dy[WR] = spin_accel;
        set_pair(&mut dy, VXB, race.accel);
        dy[WB] = race.spin_accel;
        Evaluation { dy, contact, balls: race.balls, current, amb_force, housing_accel: a_h }
    }
}

impl Model {
    /// [`Model::evaluate`] with the race parked: no contact, no support forces; the race's
    /// translation is frozen, its spin decays under the drag.
    #[inline]
    fn evaluate_parked(
        &self,
        _t: f64,
        y: &State,
        a_h: Vector2<f64>,
        current: [f64; 2],
        amb_force: Vector2<f64>,
    ) -> Evaluation {
        use ix::*;
        let p = &self.params;
        let (m, e, g) = (p.rotor_mass, p.eccentricity, p.gravity);
        let (s, c) = y[TR].sin_cos();
        let unbalance = Vector2::new(c, s);
        let frame = frame_force(g, a_h);
        let w = y[WR];
        let r = unbalance * (m * e * w * w) + amb_force - frame * m;
        let spin_accel = match p.spin {
            Spin::Held => 0.0,
            Spin::Free { drive_gain, torque_limit } => {
                let drive = (drive_gain * (p.speed - w)).clamp(-torque_limit, torque_limit);
                let r3 = drive - m * e * unbalance.perp(&frame);
                (r3 + e * r.perp(&unbalance)) / p.rotor_inertia
            }
        };
        let mut dy = [0.0; N];
        dy[XR] = y[VXR];
        dy[YR] = y[VYR];
        dy[TR] = y[WR];
        dy[TB] = y[WB];
        set_pair(&mut dy, VXR, (r - Vector2::new(-s, c) * (m * e) * spin_accel) / m);
        dy[WR] = spin_accel;
        dy[WB] = parked_race_spin_accel(p, y[WB], a_h);
        Evaluation {
            dy,
            contact: RotorRaceForce::default(),
            balls: BallForce::default(),
            current,
            amb_force,
            housing_accel: a_h,
        }
    }
}

impl System<N> for Model {
    #[inline]
    fn rhs(&self, t: f64, y: &State, dy: &mut State) {
        *dy = self.evaluate(t, y).dy;
    }
}
