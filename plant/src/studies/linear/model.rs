//! The plant of a scene linearised about its levitated state, as a continuous state-space
//! system: a pure function of the scene and a spin speed ([`continuous`]).
//!
//! **About what.** The rotor centred in its bearings, the races clear of it (no contact), the
//! spin held at the speed asked for. Every input and output is a deviation from that state:
//! the bias currents (the gravity bias among them) and the offsets they hold are left out. The
//! AMB's force is `F = k_i i + k_s Δ` at the actuator (the linear law; the nonlinear law has
//! the same `k_i`, `k_s` at the centre, MODEL.md §7).
//!
//! **The mechanics** `ẋ_m = A_m x_m + B_m i`, `x_m = [q, q̇]`:
//!
//! * planar (one plane, axes x, y): `m ẍ = k_i i_x + k_s x`, the same in y;
//! * two-plane rigid rotor (axes x_A, y_A, x_B, y_B; MODEL.md §10): `q = (x, y, a, b)` at the
//!   centre of mass, `M q̈ + Ω G q̇ = Φ_aᵀ (K_i i + K_s Φ_a q)` with `M = diag(M, M, I_t, I_t)`,
//!   `G` the gyroscopic coupling `(a, b)` rows `(+I_p ḃ, −I_p ȧ)`, `Φ_a` the axes' rows at the
//!   actuators' stations (`x + z_i a`), the sensors read `Φ_s q` at theirs;
//! * flexible: the reduced shaft's [`plant_physics::flex::linear::OpenLoop::state_space`] (its
//!   retained modes, damping and gyroscopics at the speed).
//!
//! **The hardware** (MODEL.md §12), where the scene has it: each axis' amplifier and coil
//! (bipolar: the PI current loop `L i̇ = K_p (r − i) + q − R i − k_b v_a`, `q̇ = K_I (r − i)`,
//! `v_a` the rotor's velocity at the actuator: the back-EMF) between the command `r` and the
//! current the bearing sees, and the sensor's low-pass (first order `ż₀ = ω (u − z₀)`, second
//! order Butterworth `ż₀ = z₁`, `ż₁ = ω² (u − z₀) − √2 ω z₁`) between the displacement `u` and
//! what is read. A unipolar drive about its bias is the bipolar one on the differential current
//! `(i₊ − i₋)/2` with each magnet's half of the back-EMF (MODEL.md §12.3). The output is the
//! sensor's voltage `A_s z₀` (`A_s u` without a filter). The voltage limit, the current limit, the range's clip, the noise and the ADC are not linear
//! and are left out (the loop stays inside them at small motion); the runout is an input the
//! rotor does not see and is left out too.

use crate::config::{Rotor, Scene};
use crate::sensor::LowPass;
use nalgebra::DMatrix;
use plant_physics::amplifier::Amplifier;
pub use plant_sim::machine::mechanics::{Mechanics, Signal};
use std::f64::consts::{SQRT_2, TAU};

/// A linear time-invariant system `ẋ = A x + B u`, `y = C x + D u` (or `x⁺ = A x + B u`).
#[derive(Clone, Debug, PartialEq)]
pub struct System {
    /// `A` (n × n).
    pub a: DMatrix<f64>,
    /// `B` (n × m).
    pub b: DMatrix<f64>,
    /// `C` (p × n).
    pub c: DMatrix<f64>,
    /// `D` (p × m).
    pub d: DMatrix<f64>,
}

/// The linear plant of a scene at a spin speed: continuous, inputs the axes' current commands
/// (A), outputs their sensor voltages (V).
#[derive(Clone, Debug, PartialEq)]
pub struct LinearPlant {
    /// The scene's name.
    pub scene: String,
    /// `planar`, `two_plane` or `flexible`.
    pub rotor_model: &'static str,
    /// Spin speed (Hz).
    pub speed_hz: f64,
    /// The system.
    pub system: System,
    /// The states, in order.
    pub states: Vec<Signal>,
    /// The inputs: each axis' current command.
    pub inputs: Vec<Signal>,
    /// The outputs: each axis' sensor voltage.
    pub outputs: Vec<Signal>,
    /// What the model holds (the parts of the scene in it), for the reader.
    pub parts: Vec<String>,
}

/// The highest spin speed linearised at (Hz): 6 million rpm, past any AMB rotor's (the
/// gyroscopic terms grow with it until the discretisation overflows).
pub const MAX_SPEED_HZ: f64 = 1e5;

/// A number as said in a message: in full, or in scientific notation when very large or small.
fn show(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e7).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        v.to_string()
    }
}

/// Why a scene has no linear plant here.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LinearError {
    /// The speed is negative, not finite or beyond any machine's.
    #[error(
        "--speed-hz {} Hz (by default the scene's rotor.speed_hz): must be a spin speed from 0 to {MAX_SPEED_HZ} Hz",
        show(*.0)
    )]
    Speed(f64),
    /// The model came out with a non-finite entry.
    #[error("the linear model of {scene} at {speed_hz} Hz has a non-finite entry ({what}); nothing written")]
    NotFinite {
        /// The scene.
        scene: String,
        /// The speed (Hz).
        speed_hz: f64,
        /// Which system.
        what: &'static str,
    },
}

/// The axes' names: `x`, `y` (planar) or `x_A`, `y_A`, `x_B`, `y_B`.
pub fn axis_names(rotor: &Rotor) -> Vec<&'static str> {
    match rotor.planes() {
        1 => vec!["x", "y"],
        _ => vec!["x_A", "y_A", "x_B", "y_B"],
    }
}

/// The plant of `scene` linearised about its levitated state at spin speed `speed_hz` (Hz)
/// (module doc).
pub fn continuous(scene: &Scene, speed_hz: f64) -> Result<LinearPlant, LinearError> {
    if !(speed_hz.is_finite() && (0.0..=MAX_SPEED_HZ).contains(&speed_hz)) {
        return Err(LinearError::Speed(speed_hz));
    }
    let omega = TAU * speed_hz;
    let mut mech = scene.rotor.params().mechanics(omega);
    let names = axis_names(&scene.rotor);
    let m = names.len();
    let plane_of = |k: usize| k / 2;
    let mut parts = vec![std::mem::take(&mut mech.what)];
    let hw = &scene.hardware;
    // A unipolar drive about its bias, both magnets conducting and neither amplifier limited:
    // the differential current `(i₊ − i₋)/2` obeys the bipolar coil's equation with each
    // magnet's share of the back-EMF, `k_b/2` (MODEL.md §12.3; tests/tests/unipolar.rs runs it).
    let amps: Vec<Option<Amplifier>> = (0..m)
        .map(|k| {
            hw.amplifiers[plane_of(k)].map(|mut a| {
                if hw.unipolar[plane_of(k)].is_some() {
                    a.back_emf *= 0.5;
                }
                a
            })
        })
        .collect();
    let amplified: Vec<usize> = (0..m).filter(|&k| amps[k].is_some()).collect();
    let filter = hw.front_end.low_pass;
    let filter_states = match filter {
        None => 0,
        Some(LowPass::First { .. }) => 1,
        Some(LowPass::Second { .. }) => 2,
    };
    let nm = mech.a.nrows();
    let n = nm + 2 * amplified.len() + filter_states * m;
    let mut a = DMatrix::zeros(n, n);
    let mut b = DMatrix::zeros(n, m);
    let mut c = DMatrix::zeros(m, n);
    let mut states = std::mem::take(&mut mech.states);
    a.view_mut((0, 0), (nm, nm)).copy_from(&mech.a);
    couple_coils(&mut a, &mut b, &mech, &amps, &amplified);
    if let Some(part) = coil_signals(&mut states, &names, &amps, &amplified, hw.is_unipolar()) {
        parts.push(part);
    }
    let gains: Vec<f64> = (0..m).map(|k| scene.plane(plane_of(k)).loop_constants.sensor_gain_v_per_m).collect();
    let z0 = nm + 2 * amplified.len();
    if let Some(part) = sense(&mut a, &mut c, &mut states, &mech, filter, &gains, &names, z0) {
        parts.push(part);
    }
    let inputs = names
        .iter()
        .map(|a| {
            Signal::new(
                format!("i_ref_{a}"),
                "A",
                format!("current command of axis {a} (the amplifier's reference), about its bias"),
            )
        })
        .collect();
    let outputs = names
        .iter()
        .map(|a| Signal::new(format!("v_{a}"), "V", format!("sensor signal of axis {a}, about its levitated value")))
        .collect();
    Ok(LinearPlant {
        scene: scene.name.clone(),
        rotor_model: scene.rotor.model().name(),
        speed_hz,
        system: System { a, b, c, d: DMatrix::zeros(m, m) },
        states,
        inputs,
        outputs,
        parts,
    })
}

/// The current each axis' bearing sees: the coil's (its PI current loop's two states, current
/// from `nm` and integral after them, in the order of `amplified`), or the command itself.
fn couple_coils(
    a: &mut DMatrix<f64>,
    b: &mut DMatrix<f64>,
    mech: &Mechanics,
    amps: &[Option<Amplifier>],
    amplified: &[usize],
) {
    let nm = mech.a.nrows();
    let (i0, q0) = (nm, nm + amplified.len());
    for (k, amp) in amps.iter().enumerate() {
        match amplified.iter().position(|&j| j == k) {
            None => {
                for r in 0..nm {
                    b[(r, k)] += mech.b[(r, k)];
                }
            }
            Some(slot) => {
                let (ci, cq) = (i0 + slot, q0 + slot);
                for r in 0..nm {
                    a[(r, ci)] += mech.b[(r, k)];
                }
                let p = amp.expect("amplified axis");
                let l = p.inductance;
                // L i̇ = K_p (r − i) + q − R i − k_b v_a;  q̇ = K_I (r − i).
                a[(ci, ci)] = -(p.kp + p.resistance) / l;
                a[(ci, cq)] = 1.0 / l;
                b[(ci, k)] = p.kp / l;
                let half = nm / 2;
                for col in 0..half {
                    // v_a: the actuator's displacement row on the rates.
                    a[(ci, half + col)] -= p.back_emf / l * mech.actuator[(k, col)];
                }
                a[(cq, ci)] = -p.ki;
                b[(cq, k)] = p.ki;
            }
        }
    }
}

/// The coils' states appended to `states`, and the model's part they make (none without one).
fn coil_signals(
    states: &mut Vec<Signal>,
    names: &[&str],
    amps: &[Option<Amplifier>],
    amplified: &[usize],
    unipolar: bool,
) -> Option<String> {
    for &k in amplified {
        states.push(Signal::new(format!("i_{}", names[k]), "A", format!("coil current of axis {}", names[k])));
    }
    for &k in amplified {
        states.push(Signal::new(
            format!("q_{}", names[k]),
            "V",
            format!("integral of the current loop's PI, axis {}", names[k]),
        ));
    }
    let p = amps[*amplified.first()?].expect("amplified axis");
    let unipolar =
        if unipolar { " (unipolar: the differential current about the bias, each magnet's k_b/2)" } else { "" };
    Some(format!(
        "amplifier and coil of {} axes{unipolar}: PI current loop (bandwidth {:.6} Hz), coil L = {} H, R = {} ohm, \
         back-EMF k_b = {} V s/m; its voltage limit left out",
        amplified.len(),
        p.bandwidth / TAU,
        p.inductance,
        p.resistance,
        p.back_emf
    ))
}

/// What each axis' sensor reads (`gains` V/m): the displacement, or the low-pass's output from
/// state `z0` on (its states appended to `states`); the model's part the filter makes.
#[allow(clippy::too_many_arguments)] // the assembly's parts, each a different one
fn sense(
    a: &mut DMatrix<f64>,
    c: &mut DMatrix<f64>,
    states: &mut Vec<Signal>,
    mech: &Mechanics,
    filter: Option<LowPass>,
    gains: &[f64],
    names: &[&str],
    z0: usize,
) -> Option<String> {
    let (m, nm) = (names.len(), mech.a.nrows());
    let Some(lp) = filter else {
        for k in 0..m {
            for col in 0..nm {
                c[(k, col)] = gains[k] * mech.sensor[(k, col)];
            }
        }
        return None;
    };
    let w = lp.corner();
    for k in 0..m {
        let z = z0 + k;
        c[(k, z)] = gains[k];
        match lp {
            LowPass::First { .. } => {
                a[(z, z)] = -w;
                for col in 0..nm {
                    a[(z, col)] += w * mech.sensor[(k, col)];
                }
            }
            LowPass::Second { .. } => {
                let zr = z0 + m + k;
                a[(z, zr)] = 1.0;
                a[(zr, z)] = -w * w;
                a[(zr, zr)] = -SQRT_2 * w;
                for col in 0..nm {
                    a[(zr, col)] += w * w * mech.sensor[(k, col)];
                }
            }
        }
    }
    for name in names {
        states.push(Signal::new(format!("z_{name}"), "m", format!("sensor filter output, axis {name}")));
    }
    let order = match lp {
        LowPass::First { .. } => 1,
        LowPass::Second { .. } => {
            for name in names {
                states.push(Signal::new(
                    format!("zdot_{name}"),
                    "m/s",
                    format!("sensor filter output's rate, axis {name}"),
                ));
            }
            2
        }
    };
    Some(format!(
        "sensor low-pass of order {order}, corner {:.6} Hz; the range, noise, ADC and runout left out",
        w / TAU
    ))
}
