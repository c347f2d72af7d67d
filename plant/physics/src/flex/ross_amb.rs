//! ROSS's `MagneticBearingElement` as a ROSS file saves it (a `BearingElement` table with its
//! frequency-dependent equivalent coefficients and its parameters; MODEL.md §13.8): read, checked
//! and turned into the constants it stands for by ROSS's own formulas. A scene with
//! `rotor.ross_ambs = "use"` or `"constants"` makes each element its plane's AMB
//! ([`MagneticBearing::used`], what the run records); without it the reader refuses the element
//! with those constants ([`MagneticBearing::refusal`]).
//!
//! Line numbers are those of `ross/bearing_seal_element.py` in ROSS 3.1.0 as PyPI ships it.

use super::ross::{as_number, node, unknown_key, BEARING_KEYS, MAGNETIC_KEYS};
use super::FlexError;
use toml::{Table, Value};

/// ROSS's default pole angle and axis rotation (rad): the decimals its signature writes (lines
/// 2541, 2549), not π/8 and π/4 exactly, so that a file without them reads as ROSS reads it.
#[allow(clippy::approx_constant)]
const ROSS_ALPHA: f64 = 0.39269908;
#[allow(clippy::approx_constant)]
const ROSS_AXIS_ROTATION: f64 = 0.78539816;

/// The vacuum permeability μ₀ ROSS uses (`4π·10⁻⁷` H/m).
const MU_0: f64 = 4.0 * std::f64::consts::PI * 1e-7;

/// A `MagneticBearingElement` as its file saves it, checked.
#[derive(Clone, Debug, PartialEq)]
pub struct MagneticBearing {
    /// The element's table name.
    pub element: String,
    /// The actuator's node.
    pub node: usize,
    /// The sensor's node (`sensor_node`; ROSS 2.3 has none: the actuator's).
    pub sensor_node: usize,
    /// Air gap `g0` (m).
    pub g0: f64,
    /// Bias current `i0` (A).
    pub i0: f64,
    /// Pole area `ag` (m²).
    pub ag: f64,
    /// Turns per coil `nw`.
    pub nw: f64,
    /// Pole angle `alpha` (rad).
    pub alpha: f64,
    /// Amplifier gain `k_amp` (A/V).
    pub k_amp: f64,
    /// Sensor gain `k_sense` (V/m).
    pub k_sense: f64,
    /// PID gains `kp_pid`, `ki_pid` (1/s), `kd_pid` (s).
    pub pid: [f64; 3],
    /// The derivative filter's cutoff `n_f` (rad/s).
    pub n_f: f64,
    /// `sensors_axis_rotation` (rad).
    pub axis_rotation: f64,
}

impl MagneticBearing {
    /// The force per ampere `k_i = μ₀ nw² ag i0 cos(alpha) / g0²` (N/A), ROSS's `ki` (lines
    /// 2615–2625, written as ROSS writes it).
    pub fn ki_n_per_a(&self) -> f64 {
        4.0 * self.i0 * self.alpha.cos() * MU_0 * self.nw.powi(2) * self.ag / (4.0 * self.g0.powi(2))
    }

    /// The negative stiffness `k_s = μ₀ nw² ag i0² cos(alpha) / g0³` (N/m) in this testbed's sign
    /// (`F = k_i i + k_s Δ`, `k_s > 0`): ROSS's `ks` is its negative (lines 2603–2613).
    pub fn ks_n_per_m(&self) -> f64 {
        4.0 * self.i0.powi(2) * self.alpha.cos() * MU_0 * self.nw.powi(2) * self.ag / (4.0 * self.g0.powi(3))
    }

    /// ROSS's controller `C(jω) = kp + ki / (jω) + kd jω / (1 + jω / n_f)` (lines 2916–2922), as
    /// (real part, imaginary part).
    pub fn controller_at(&self, omega: f64) -> (f64, f64) {
        let [kp, ki, kd] = self.pid;
        // kd jω / (1 + jω/n_f) = kd jω (1 − jω/n_f) / (1 + (ω/n_f)²)
        let r = omega / self.n_f;
        let den = 1.0 + r * r;
        (kp + kd * omega * r / den, -ki / omega + kd * omega / den)
    }

    /// ROSS's frequency-dependent equivalent stiffness and damping at `omega` (rad/s), what its
    /// file's `kxx`, `cxx` hold (lines 2661–2662): `k_eq = ks + ki k_amp k_sense Re C`,
    /// `c_eq = ki k_amp k_sense Im C / ω`, with ROSS's `ks` (negative).
    pub fn equivalent_at(&self, omega: f64) -> (f64, f64) {
        let (re, im) = self.controller_at(omega);
        let gain = self.ki_n_per_a() * self.k_amp * self.k_sense;
        (-self.ks_n_per_m() + gain * re, gain * im / omega)
    }

    /// Why the element is refused, with what it stands for in this testbed's terms.
    pub fn refusal(&self) -> String {
        let [kp, ki, kd] = self.pid;
        format!(
            "element \"{}\" (node {}) is ROSS's MagneticBearingElement, which the scene must say what to do with; \
             by ROSS's formulas it stands for k_i = {:.6e} N/A and k_s = {:.6e} N/m (amb.ki_n_per_a, \
             amb.ks_n_per_m), its sensor at node {} (rotor.sensor_*_node), amplifier gain {} A/V and sensor gain {} \
             V/m (amb.amp_gain_a_per_v, amb.sensor_gain_v_per_m), a PID kp = {kp}, ki = {ki} 1/s, kd = {kd} s with its \
             derivative filtered at n_f = {} rad/s, axes turned by {:.1}°: rotor.ross_ambs = \"use\" makes it the \
             plane's AMB with its PID as the law (ross_pid, sampled modes), \"constants\" the plane's AMB with the \
             scene's [controller]",
            self.element,
            self.node,
            self.ki_n_per_a(),
            self.ks_n_per_m(),
            self.sensor_node,
            self.k_amp,
            self.k_sense,
            self.n_f,
            self.axis_rotation.to_degrees(),
        )
    }
}

/// ROSS's PID of an element as the plane's law `ross_pid` takes it (its parameters).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct RossPid {
    /// `kp_pid` (V/V on the sensor voltage).
    pub kp: f64,
    /// `ki_pid` (1/s).
    pub ki_per_s: f64,
    /// `kd_pid` (s).
    pub kd_s: f64,
    /// `n_f` (rad/s).
    pub n_f_rad_s: f64,
}

/// A file's AMB element made a plane's AMB: what the run took from it (`summary.json`
/// `model.ross_ambs`).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct UsedAmb {
    /// The element, as the file names its table.
    pub element: String,
    /// The plane it became (`"A"` or `"B"`).
    pub plane: &'static str,
    /// The actuator's node (`n`).
    pub node: usize,
    /// The sensor's node (`sensor_node`).
    pub sensor_node: usize,
    /// `k_i` (N/A), `amb.ki_n_per_a`.
    pub ki_n_per_a: f64,
    /// `k_s` (N/m, this testbed's sign), `amb.ks_n_per_m`.
    pub ks_n_per_m: f64,
    /// `k_amp` (A/V), `amb.amp_gain_a_per_v`.
    pub amp_gain_a_per_v: f64,
    /// `k_sense` (V/m), `amb.sensor_gain_v_per_m`.
    pub sensor_gain_v_per_m: f64,
    /// `g0` (mm), `amb.nominal_gap_mm` (the nonlinear law's magnet gap).
    pub nominal_gap_mm: f64,
    /// The PID made the plane's law (`rotor.ross_ambs = "use"`); none with `"constants"`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pid: Option<RossPid>,
    /// `sensors_axis_rotation` (degrees) when it is not applied: the plant's axes are at 0°
    /// (without `rotor.ross_axes = "apply"`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis_rotation_deg_not_applied: Option<f64>,
    /// `sensors_axis_rotation` (degrees) when it turns the plane's axes
    /// (`rotor.ross_axes = "apply"`: the plane's `amb.axis_angle_deg`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis_rotation_deg: Option<f64>,
}

impl MagneticBearing {
    /// Its PID as law `ross_pid`'s parameters.
    pub fn ross_pid(&self) -> RossPid {
        let [kp, ki, kd] = self.pid;
        RossPid { kp, ki_per_s: ki, kd_s: kd, n_f_rad_s: self.n_f }
    }

    /// What plane `plane` takes from it, with its PID as the law or not.
    pub fn used(&self, plane: &'static str, with_pid: bool) -> UsedAmb {
        UsedAmb {
            element: self.element.clone(),
            plane,
            node: self.node,
            sensor_node: self.sensor_node,
            ki_n_per_a: self.ki_n_per_a(),
            ks_n_per_m: self.ks_n_per_m(),
            amp_gain_a_per_v: self.k_amp,
            sensor_gain_v_per_m: self.k_sense,
            nominal_gap_mm: self.g0 * 1e3,
            pid: with_pid.then(|| self.ross_pid()),
            axis_rotation_deg_not_applied: Some(self.axis_rotation.to_degrees()),
            axis_rotation_deg: None,
        }
    }
}

/// A `MagneticBearingElement`'s table (`name`, `at` for messages): each parameter present, a
/// number, in its range (ROSS's defaults where it has one), else refused naming the element,
/// key, value and unit.
pub fn magnetic(t: &Table, name: &str, at: &str, file: &str) -> Result<MagneticBearing, FlexError> {
    let err = |message: String| FlexError::Ross { file: file.into(), message };
    let known: Vec<&str> = BEARING_KEYS.iter().chain(MAGNETIC_KEYS).copied().collect();
    unknown_key(t, &known, at, file)?;
    let node = node(t, at, file)?;
    // One value, or one per axis, the two the same (this model has one actuator per plane).
    let scalar = |key: &str, unit: &str, default: Option<f64>| -> Result<f64, FlexError> {
        let values: Vec<f64> = match t.get(key) {
            None => return default.ok_or_else(|| err(format!("{at}: {key} ({unit}) is missing"))),
            Some(Value::Array(a)) => a
                .iter()
                .map(|v| as_number(v).ok_or_else(|| err(format!("{at}: {key} holds {v}, not a number"))))
                .collect::<Result<_, _>>()?,
            Some(v) => vec![as_number(v).ok_or_else(|| err(format!("{at}: {key} = {v} is not a number")))?],
        };
        match values.as_slice() {
            [v] => Ok(*v),
            [x, y] if x == y => Ok(*x),
            _ => Err(err(format!(
                "{at}: {key} = {values:?} {unit}: one value per axis, which differ, is not represented"
            ))),
        }
    };
    let positive = |key: &str, unit: &str, default: Option<f64>| -> Result<f64, FlexError> {
        let v = scalar(key, unit, default)?;
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(err(format!("{at}: {key} = {v} {unit} must be positive")))
        }
    };
    let finite = |key: &str, unit: &str, default: f64| -> Result<f64, FlexError> {
        let v = scalar(key, unit, Some(default))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(err(format!("{at}: {key} = {v} {unit} is not a number")))
        }
    };
    let alpha = finite("alpha", "rad", ROSS_ALPHA)?;
    if !(alpha > 0.0 && alpha < std::f64::consts::FRAC_PI_2) {
        return Err(err(format!(
            "{at}: alpha = {alpha} rad ({:.1}°): the pole angle must be between 0 and 90° (π/2 rad)",
            alpha.to_degrees()
        )));
    }
    let sensor_node = match t.get("sensor_node") {
        None => node,
        Some(Value::Integer(n)) if *n >= 0 => *n as usize,
        Some(v) => return Err(err(format!("{at}: sensor_node = {v} is not a node number"))),
    };
    Ok(MagneticBearing {
        element: name.to_string(),
        node,
        sensor_node,
        g0: positive("g0", "m", None)?,
        i0: positive("i0", "A", None)?,
        ag: positive("ag", "m²", None)?,
        nw: positive("nw", "turns", None)?,
        alpha,
        k_amp: positive("k_amp", "A/V", Some(1.0))?,
        k_sense: positive("k_sense", "V/m", Some(1.0))?,
        pid: [finite("kp_pid", "", 0.0)?, finite("ki_pid", "1/s", 0.0)?, finite("kd_pid", "s", 0.0)?],
        n_f: positive("n_f", "rad/s", Some(10_000.0))?,
        axis_rotation: finite("sensors_axis_rotation", "rad", ROSS_AXIS_ROTATION)?,
    })
}
