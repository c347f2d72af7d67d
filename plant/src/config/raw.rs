//! The scene file format: TOML parsed into these raw structs (unknown keys
//! are errors; every key has a default, the study's value, listed in the
//! README). Every choice is an enum, so a bad value names the key and the
//! allowed values. Nothing outside [`crate::config`] reads this layer: the
//! validated [`super::Scene`] is the only source of truth.

use crate::integrate::Method;
use crate::model::Cage;
use serde::{Deserialize, Serialize};
use shock_table::ShockSpec;

macro_rules! defaults {
    ($name:ident { $($field:ident : $ty:ty = $val:expr),* $(,)? }) => {
        impl Default for $name {
            fn default() -> Self { Self { $($field: $val),* } }
        }
    };
}

/// `[scene]`: name and span of the run.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawMeta {
    /// Scene name (default: the file stem).
    pub name: String,
    /// Free text.
    pub description: String,
    /// Simulated time (s). Default 1.5.
    pub duration_s: f64,
    /// Gravity (m/s²). Default 9.80665.
    pub gravity_m_s2: f64,
}
defaults!(RawMeta {
    name: String = String::new(),
    description: String = String::new(),
    duration_s: f64 = 1.5,
    gravity_m_s2: f64 = 9.80665
});

/// `[rotor]`.
///
/// `model` chooses the planar model (one bearing plane: the study's, `mass_kg` the share one
/// bearing carries) or the two-plane rotor (the whole rotor on two bearings with its tilt). The
/// keys without a fixed default take the model's: a two-plane scene's defaults are the
/// symmetric machine equivalent to the study (docs/MODEL.md §10.1). The keys after `model`'s
/// own are the two-plane rotor's and refused in a planar scene.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawRotor {
    /// `planar` (default) or `two_plane`.
    pub model: RotorModel,
    /// Mass (kg): planar, the share of one bearing, default 11.5; two-plane, the whole rotor,
    /// default 23.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// e (µm): the centre of mass's offset from the geometric axis (static unbalance). Default 2.
    pub eccentricity_um: f64,
    /// Polar moment of inertia (kg·m²): planar, the share of one bearing, default 5.81e-3;
    /// two-plane, the whole rotor's I_p, default 11.62e-3.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub polar_inertia_kg_m2: Option<f64>,
    /// r_r (mm). Default 19.85.
    pub radius_mm: f64,
    /// Rated speed (Hz). Default 500.
    pub speed_hz: f64,
    /// Angle of the unbalance at t = 0 (deg). Default 0.
    pub unbalance_phase_deg: f64,
    /// `held` (default) or `free`.
    pub spin: SpinChoice,
    /// Speed-loop gain for `free` spin (N·m·s/rad). Default 0.05 (two-plane: 0.1, the whole rotor's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drive_gain_n_m_s: Option<f64>,
    /// Drive torque limit for `free` spin (N·m). Default 2 (two-plane: 4).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drive_torque_limit_n_m: Option<f64>,
    /// Two-plane: transverse moment of inertia I_t about the centre of mass (kg·m²). Default 0.414.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub transverse_inertia_kg_m2: Option<f64>,
    /// Two-plane: couple unbalance, the tilt χ of the principal axis of inertia from the
    /// geometric axis (µrad). Default 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub couple_unbalance_urad: Option<f64>,
    /// Two-plane: the rotor-fixed direction of that tilt, from the static unbalance's (deg). Default 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub couple_unbalance_phase_deg: Option<f64>,
    /// Two-plane: axial position of bearing A (AMB and touchdown bearing) from the centre of
    /// mass (mm), < 0. Default −180.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bearing_a_mm: Option<f64>,
    /// Two-plane: axial position of bearing B (mm), > 0. Default 180.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bearing_b_mm: Option<f64>,
    /// Two-plane: axial position of plane A's displacement sensor (mm). Default: `bearing_a_mm`
    /// (collocated).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sensor_a_mm: Option<f64>,
    /// Two-plane: axial position of plane B's displacement sensor (mm). Default: `bearing_b_mm`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sensor_b_mm: Option<f64>,
    /// Two-plane: axial position of the rotor's end on plane A's side (mm). Default −230.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end_a_mm: Option<f64>,
    /// Two-plane: axial position of the rotor's end on plane B's side (mm). Default 230.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end_b_mm: Option<f64>,
}
defaults!(RawRotor {
    model: RotorModel = RotorModel::Planar,
    mass_kg: Option<f64> = None,
    eccentricity_um: f64 = 2.0,
    polar_inertia_kg_m2: Option<f64> = None,
    radius_mm: f64 = 19.85,
    speed_hz: f64 = 500.0,
    unbalance_phase_deg: f64 = 0.0,
    spin: SpinChoice = SpinChoice::Held,
    drive_gain_n_m_s: Option<f64> = None,
    drive_torque_limit_n_m: Option<f64> = None,
    transverse_inertia_kg_m2: Option<f64> = None,
    couple_unbalance_urad: Option<f64> = None,
    couple_unbalance_phase_deg: Option<f64> = None,
    bearing_a_mm: Option<f64> = None,
    bearing_b_mm: Option<f64> = None,
    sensor_a_mm: Option<f64> = None,
    sensor_b_mm: Option<f64> = None,
    end_a_mm: Option<f64> = None,
    end_b_mm: Option<f64> = None,
});

/// `rotor.model`: the rotor model.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RotorModel {
    /// One bearing plane (the study's model): x, y, the race of one touchdown bearing.
    #[default]
    Planar,
    /// The whole rigid rotor on two bearing planes, A and B: translation and tilt, four axes.
    TwoPlane,
}

/// `[touchdown]`: the touchdown bearing.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawTouchdown {
    /// r_0, radial air gap shaft – race bore (mm); the bore radius is r_r + r_0. Default 0.15.
    pub air_gap_mm: f64,
    /// m_b (kg). Default 0.048.
    pub race_mass_kg: f64,
    /// J_b (kg·m²). Default 2.33e-5.
    pub race_polar_inertia_kg_m2: f64,
    /// Ball diameter (mm). Default 5.5.
    pub ball_diameter_mm: f64,
    /// z. Default 19.
    pub ball_count: u32,
    /// d_m (mm). Default 51.
    pub pitch_diameter_mm: f64,
    /// Outer race diameter (mm), for reference. Default 62.
    pub outer_diameter_mm: f64,
    /// Width B (mm), for reference. Default 12.
    pub width_mm: f64,
    /// r_cl, race – ball radial clearance (mm). Default 0.01.
    pub ball_clearance_mm: f64,
    /// `rotating` (default) or `fixed`.
    pub cage: Cage,
    /// `balls` (default: each ball a Hertz contact) or `lumped` (an isotropic ring calibrated on the balls).
    pub support: SupportChoice,
    /// Deflection beyond the clearance at which the lumped ring is calibrated (mm). Default 0.01.
    pub lumped_reference_mm: f64,
    /// Angle of ball 0 at t = 0 (deg). Default −90 (straight down).
    pub cage_phase_deg: f64,
    /// `constant` (default) or `palmgren`.
    pub drag: DragChoice,
    /// Constant drag torque (N·m). Default 0.1.
    pub drag_torque_n_m: f64,
    /// Speed below which the drag is smoothed to zero (rad/s). Default 1.
    pub drag_smoothing_rad_s: f64,
    /// Palmgren f_0. Default 2.
    pub palmgren_f0: f64,
    /// Palmgren ν_0 (cSt). Default 20.
    pub palmgren_viscosity_cst: f64,
    /// Palmgren f_1. Default 5e-4.
    pub palmgren_f1: f64,
    /// What the race does while the rotor – race gap is open by a safe margin: `free` (default:
    /// always integrated on its supports) or `parked` (held in the housing frame, support and
    /// contact kernels skipped; see [`crate::park`]).
    pub race_when_clear: RaceWhenClearChoice,
    /// With `race_when_clear = "parked"`: the state the race is released with when the gap may
    /// close: `equilibrium` (default: at rest on its supports under gravity and the current
    /// housing acceleration) or `held` (where it was parked, at rest).
    pub race_release: ReleaseChoice,
    /// Two-plane: plane A's own values of this table's keys (the others are shared).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub a: Option<toml::Table>,
    /// Two-plane: plane B's own values of this table's keys.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub b: Option<toml::Table>,
}
defaults!(RawTouchdown {
    air_gap_mm: f64 = 0.15,
    race_mass_kg: f64 = 0.048,
    race_polar_inertia_kg_m2: f64 = 2.33e-5,
    ball_diameter_mm: f64 = 5.5,
    ball_count: u32 = 19,
    pitch_diameter_mm: f64 = 51.0,
    outer_diameter_mm: f64 = 62.0,
    width_mm: f64 = 12.0,
    ball_clearance_mm: f64 = 0.01,
    cage: Cage = Cage::Rotating,
    support: SupportChoice = SupportChoice::Balls,
    lumped_reference_mm: f64 = 0.01,
    cage_phase_deg: f64 = -90.0,
    drag: DragChoice = DragChoice::Constant,
    drag_torque_n_m: f64 = 0.1,
    drag_smoothing_rad_s: f64 = 1.0,
    palmgren_f0: f64 = 2.0,
    palmgren_viscosity_cst: f64 = 20.0,
    palmgren_f1: f64 = 5e-4,
    race_when_clear: RaceWhenClearChoice = RaceWhenClearChoice::Free,
    race_release: ReleaseChoice = ReleaseChoice::Equilibrium,
    a: Option<toml::Table> = None,
    b: Option<toml::Table> = None,
});

/// `[housing]`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawHousing {
    /// M_h (kg), for reference: the housing motion is prescribed. Default 80.96.
    pub mass_kg: f64,
}
defaults!(RawHousing { mass_kg: f64 = 80.96 });

/// `[contact]`: contact and friction laws.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawContact {
    /// K_r (N/m^(10/9)). Default 1.988e9.
    pub rotor_race_stiffness_n_per_m10_9: f64,
    /// C_r,max (N·s/m). Default 1000.
    pub rotor_race_damping_n_s_per_m: f64,
    /// K_b (N/m^(3/2)). Default 7.81e9.
    pub ball_stiffness_n_per_m1_5: f64,
    /// C_b,max (N·s/m). Default 750.
    pub ball_damping_n_s_per_m: f64,
    /// δ_max, depth of full damping (mm). Default 0.01.
    pub damping_depth_mm: f64,
    /// μ_s. Default 0.1.
    pub friction_static: f64,
    /// μ_d. Default 0.1.
    pub friction_dynamic: f64,
    /// v_s (m/s). Default 0.1.
    pub stribeck_static_m_s: f64,
    /// v_d (m/s). Default 0.1.
    pub stribeck_dynamic_m_s: f64,
    /// Two-plane: plane A's own values of this table's keys (the others are shared).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub a: Option<toml::Table>,
    /// Two-plane: plane B's own values of this table's keys.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub b: Option<toml::Table>,
}
defaults!(RawContact {
    rotor_race_stiffness_n_per_m10_9: f64 = 1.988e9,
    rotor_race_damping_n_s_per_m: f64 = 1000.0,
    ball_stiffness_n_per_m1_5: f64 = 7.81e9,
    ball_damping_n_s_per_m: f64 = 750.0,
    damping_depth_mm: f64 = 0.01,
    friction_static: f64 = 0.1,
    friction_dynamic: f64 = 0.1,
    stribeck_static_m_s: f64 = 0.1,
    stribeck_dynamic_m_s: f64 = 0.1,
    a: Option<toml::Table> = None,
    b: Option<toml::Table> = None,
});

/// `[amb]`: the magnetic bearing.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawAmb {
    /// `linear` (default) or `nonlinear`.
    pub force_law: ForceLaw,
    /// k_i (N/A). Default 216.
    pub ki_n_per_a: f64,
    /// k_s (N/m). Default 4.32e5.
    pub ks_n_per_m: f64,
    /// A_a (A/V). Default 1.
    pub amp_gain_a_per_v: f64,
    /// A_s (V/m). Default 25000.
    pub sensor_gain_v_per_m: f64,
    /// Nominal magnet air gap s_0 for the nonlinear law (mm). Default 1.
    pub nominal_gap_mm: f64,
    /// Largest pull of one magnet, from flux saturation (N). Default 1000.
    pub magnet_force_limit_n: f64,
    /// Two-plane: plane A's own values of this table's keys (the others are shared).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub a: Option<toml::Table>,
    /// Two-plane: plane B's own values of this table's keys.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub b: Option<toml::Table>,
}
defaults!(RawAmb {
    force_law: ForceLaw = ForceLaw::Linear,
    ki_n_per_a: f64 = 216.0,
    ks_n_per_m: f64 = 4.32e5,
    amp_gain_a_per_v: f64 = 1.0,
    sensor_gain_v_per_m: f64 = 25000.0,
    nominal_gap_mm: f64 = 1.0,
    magnet_force_limit_n: f64 = 1000.0,
    a: Option<toml::Table> = None,
    b: Option<toml::Table> = None,
});

/// `rotor.spin`: how the rotor's speed is driven.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpinChoice {
    /// The drive holds the speed exactly.
    Held,
    /// A speed loop with a gain and a torque limit drives it.
    Free,
}

/// `touchdown.support`: how the race is supported.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SupportChoice {
    /// Each ball a Hertz contact.
    Balls,
    /// An isotropic ring calibrated on the balls.
    Lumped,
}

/// `touchdown.drag`: the race's drag torque.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DragChoice {
    /// A constant torque, smoothed to zero near standstill.
    Constant,
    /// Palmgren's load- and speed-dependent friction torque.
    Palmgren,
}

/// `touchdown.race_when_clear`: what the race does while the rotor – race gap is open.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RaceWhenClearChoice {
    /// Always integrated on its supports.
    Free,
    /// Held in the housing frame, support and contact kernels skipped (see [`crate::park`]).
    Parked,
}

/// `touchdown.race_release`: the state a parked race is released with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReleaseChoice {
    /// At rest on its supports under gravity and the current housing acceleration.
    Equilibrium,
    /// Where it was parked, at rest.
    Held,
}

/// `amb.force_law`: the magnetic bearing's force law.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ForceLaw {
    /// `F = k_i i + k_s x`.
    Linear,
    /// Two opposed magnets with flux saturation, matched to k_i and k_s at the centre.
    Nonlinear,
}

/// `controller.fallback`: what the plant applies when the controller process is lost.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Fallback {
    /// Hold the last current.
    Hold,
    /// Bias current only (the gravity bias on y, if any).
    Bias,
    /// End the run.
    Stop,
}

impl SpinChoice {
    /// The choice a validated spin model was made from.
    pub fn of(spin: &crate::model::Spin) -> Self {
        match spin {
            crate::model::Spin::Held => SpinChoice::Held,
            crate::model::Spin::Free { .. } => SpinChoice::Free,
        }
    }
}

impl SupportChoice {
    /// The choice a validated race support was made from.
    pub fn of(support: &crate::model::Support) -> Self {
        match support {
            crate::model::Support::Balls => SupportChoice::Balls,
            crate::model::Support::Lumped(_) => SupportChoice::Lumped,
        }
    }
}

impl DragChoice {
    /// The choice a validated drag law was made from.
    pub fn of(drag: &crate::force::drag::RaceDrag) -> Self {
        match drag {
            crate::force::drag::RaceDrag::Constant { .. } => DragChoice::Constant,
            crate::force::drag::RaceDrag::Palmgren { .. } => DragChoice::Palmgren,
        }
    }
}

impl RaceWhenClearChoice {
    /// The choices (race when clear, and its release if parked) a validated setting was made from.
    pub fn of(r: &crate::model::RaceWhenClear) -> (Self, Option<ReleaseChoice>) {
        match r {
            crate::model::RaceWhenClear::Free => (RaceWhenClearChoice::Free, None),
            crate::model::RaceWhenClear::Parked(crate::model::Release::Equilibrium) => {
                (RaceWhenClearChoice::Parked, Some(ReleaseChoice::Equilibrium))
            }
            crate::model::RaceWhenClear::Parked(crate::model::Release::Held) => {
                (RaceWhenClearChoice::Parked, Some(ReleaseChoice::Held))
            }
        }
    }
}

impl ForceLaw {
    /// The choice a validated bearing force law was made from.
    pub fn of(law: &crate::force::amb::AmbLaw) -> Self {
        match law {
            crate::force::amb::AmbLaw::Linear { .. } => ForceLaw::Linear,
            crate::force::amb::AmbLaw::Nonlinear { .. } => ForceLaw::Nonlinear,
        }
    }
}

/// How the controller is connected.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ControlMode {
    /// PD inside the derivative (the study's setup).
    Continuous,
    /// The law runs in the plant at `rate_hz`, zero-order hold, `delay_samples`.
    Sampled,
    /// The law runs in the controller process, in lockstep with the plant.
    Lockstep,
    /// The law runs in the controller process, paced by the wall clock.
    Realtime,
}

/// `[controller]`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawController {
    /// `continuous` (default), `sampled`, `lockstep`, `realtime`.
    pub mode: ControlMode,
    /// Law name. Default `pd`.
    pub law: String,
    /// Controller rate (Hz): the macro step of the plant. Default 20000.
    pub rate_hz: f64,
    /// k_e (N/m). Default 1e6.
    pub stiffness_n_per_m: f64,
    /// ξ_e. Default 0.01.
    pub damping_ratio: f64,
    /// i_max (A). Default 2.
    pub current_limit_a: f64,
    /// Samples between the sample a command is computed from and the tick it is applied from. Default 1.
    pub delay_samples: u32,
    /// Add the gravity bias current m_r g / k_i on y. Default true.
    pub gravity_bias: bool,
    /// The law's own parameters (free TOML, read by the law alone; at most
    /// [`controller::PARAMS_LEN`] bytes as TOML text). Default empty.
    #[serde(skip_serializing_if = "toml::Table::is_empty")]
    pub params: toml::Table,
    /// Deprecated alias of `params.enter_um` (law `relev`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relev_enter_um: Option<f64>,
    /// Deprecated alias of `params.exit_um` (law `relev`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relev_exit_um: Option<f64>,
    /// Deprecated alias of `params.recovery_damping_ratio` (law `relev`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relev_damping_ratio: Option<f64>,
    /// Deprecated alias of `params.hold_ms` (law `relev`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relev_hold_ms: Option<f64>,
    /// Deprecated alias of `params.arm_ms` (law `relev`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relev_arm_ms: Option<f64>,
    /// Co-simulation: what the plant applies when the controller process is
    /// lost: `hold` (the last current, default), `bias` (bias current only)
    /// or `stop` (end the run, exit code 4).
    pub fallback: Fallback,
    /// Co-simulation: how long a reply may be missing before the plant looks
    /// up the controller's node; a dead or vanished node is a lost peer, a
    /// live one is waited for (lockstep) or missed (realtime). Repeated while
    /// the silence lasts (ms). Default 1 (20 periods at 20 kHz).
    pub reply_timeout_ms: f64,
    /// Co-simulation: how long to wait for a new controller after one is
    /// lost (ms); the plant respawns the controller it started itself.
    /// 0 (default) stops the run with exit code 4.
    pub reconnect_timeout_ms: f64,
    /// Co-simulation: how long to wait for the first controller's handshake (ms). Default 10000.
    pub connect_timeout_ms: f64,
    /// Co-simulation: how long a waiting side busy-polls before it blocks on
    /// an event (µs). Longer costs a core while idle; shorter adds a wake-up
    /// (several µs) to each late reply. Default 200.
    pub spin_us: f64,
    /// Co-simulation: CPU cores to pin `[plant, controller]` to; empty (default) = no pinning.
    pub pin_cores: Vec<usize>,
    /// Co-simulation: the controller process to start instead of the built-in `controller`:
    /// a list of strings (`["python3", "my_controller.py", "--gain", "2"]`) or one string (a
    /// path). The plant appends `--run-id ID` and sets `AMB_TESTBED_RUN_ID` and
    /// `AMB_TESTBED_CONNECT_TIMEOUT_S`. An element that is a relative path naming an existing
    /// file or folder in the scene file's folder is taken from there (written absolute in the
    /// run folder's `scene.toml`); others are left as they are (`argv[0]` without a `/` is
    /// looked up in `PATH`). With a command, the plant does not check `law` or `params`: the
    /// controller does, in the handshake. Default: none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub command: Option<toml::Value>,
    /// Co-simulation, lockstep: how long the plant waits for a reply from a controller that
    /// is alive (its node and process exist) before it treats it as lost (ms): a stopped
    /// (SIGSTOP), hung or confused controller. Default 5000.
    pub lockstep_timeout_ms: f64,
    /// Co-simulation: `SCHED_FIFO` priority (1 to 99) for the plant's loop thread and the
    /// controller, with memory locking; 0 (default) = the normal scheduler. Where the system
    /// refuses it, the run goes on without, with a warning.
    pub realtime_priority: u32,
    /// Co-simulation, realtime: the largest deadline-miss fraction a run may have; past it
    /// the run ends with status `miss_budget` (exit code 6). Default 1 (no limit).
    pub max_miss_fraction: f64,
}
defaults!(RawController {
    mode: ControlMode = ControlMode::Continuous,
    law: String = "pd".into(),
    rate_hz: f64 = 20000.0,
    stiffness_n_per_m: f64 = 1e6,
    damping_ratio: f64 = 0.01,
    current_limit_a: f64 = 2.0,
    delay_samples: u32 = 1,
    gravity_bias: bool = true,
    params: toml::Table = toml::Table::new(),
    relev_enter_um: Option<f64> = None,
    relev_exit_um: Option<f64> = None,
    relev_damping_ratio: Option<f64> = None,
    relev_hold_ms: Option<f64> = None,
    relev_arm_ms: Option<f64> = None,
    fallback: Fallback = Fallback::Hold,
    reply_timeout_ms: f64 = 1.0,
    reconnect_timeout_ms: f64 = 0.0,
    connect_timeout_ms: f64 = 10_000.0,
    spin_us: f64 = 200.0,
    pin_cores: Vec<usize> = Vec::new(),
    command: Option<toml::Value> = None,
    lockstep_timeout_ms: f64 = 5000.0,
    realtime_priority: u32 = 0,
    max_miss_fraction: f64 = 1.0,
});

/// `[integrator]`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawIntegrator {
    /// `explicit_euler`, `symplectic_euler`, `rk4`, `dp5` (default), `dop853`.
    pub method: Method,
    /// Relative tolerance (adaptive). Default 1e-6.
    pub rtol: f64,
    /// Absolute tolerance for every component (adaptive). Default 1e-9.
    pub atol: f64,
    /// Override for positions (m).
    pub atol_position_m: Option<f64>,
    /// Override for velocities (m/s).
    pub atol_velocity_m_s: Option<f64>,
    /// Override for angles (rad).
    pub atol_angle_rad: Option<f64>,
    /// Override for angular speeds (rad/s).
    pub atol_angular_speed_rad_s: Option<f64>,
    /// Substeps per controller period (fixed-step). Default 16.
    pub substeps: u32,
    /// Substeps per controller period while the race is free, with
    /// `touchdown.race_when_clear = "parked"` (fixed-step); 0 (default) = `substeps`.
    pub contact_substeps: u32,
    /// The run stops as diverged when the rotor or race leaves the clearance by more than this (mm). Default 0.5.
    pub radius_guard_mm: f64,
}
defaults!(RawIntegrator {
    method: Method = Method::Dp5, rtol: f64 = 1e-6, atol: f64 = 1e-9, atol_position_m: Option<f64> = None,
    atol_velocity_m_s: Option<f64> = None, atol_angle_rad: Option<f64> = None, atol_angular_speed_rad_s: Option<f64> = None,
    substeps: u32 = 16, contact_substeps: u32 = 0, radius_guard_mm: f64 = 0.5,
});

/// `[initial]`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawInitial {
    /// Start the rotor on its linear unbalance orbit (default true), else at rest.
    pub unbalance_orbit: bool,
    /// Offset added to the rotor's initial x (µm). Default 0.
    pub rotor_x_um: f64,
    /// Offset added to the rotor's initial y (µm). Default 0.
    pub rotor_y_um: f64,
    /// Two-plane: offset added to the initial slope a = dx/dz of the rotor axis (µrad). Default 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slope_x_urad: Option<f64>,
    /// Two-plane: offset added to the initial slope b = dy/dz (µrad). Default 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slope_y_urad: Option<f64>,
}
defaults!(RawInitial {
    unbalance_orbit: bool = true,
    rotor_x_um: f64 = 0.0,
    rotor_y_um: f64 = 0.0,
    slope_x_urad: Option<f64> = None,
    slope_y_urad: Option<f64> = None,
});

/// `[sensor]`: what the digital controller reads (sampled and co-simulation modes; the
/// continuous PD sees the exact state). The gain is `amb.sensor_gain_v_per_m`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawSensor {
    /// White noise added to each sample, standard deviation (V). Default 0.
    pub noise_v_rms: f64,
    /// Seed of the noise. Default 1.
    pub noise_seed: u64,
    /// ADC resolution (bits); 0 = ideal. Default 0.
    pub adc_bits: u32,
    /// ADC input range ±V (V). Default 10.
    pub adc_range_v: f64,
}
defaults!(RawSensor { noise_v_rms: f64 = 0.0, noise_seed: u64 = 1, adc_bits: u32 = 0, adc_range_v: f64 = 10.0 });

/// `[output]`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawOutput {
    /// Trace rate (Hz). Default 20000.
    pub rate_hz: f64,
    /// Write PNG plots. Default true.
    pub plots: bool,
}
defaults!(RawOutput { rate_hz: f64 = 20000.0, plots: bool = true });

/// A whole scene file as written.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RawScene {
    /// `[scene]`.
    pub scene: RawMeta,
    /// `[rotor]`.
    pub rotor: RawRotor,
    /// `[touchdown]`.
    pub touchdown: RawTouchdown,
    /// `[housing]`.
    pub housing: RawHousing,
    /// `[contact]`.
    pub contact: RawContact,
    /// `[amb]`.
    pub amb: RawAmb,
    /// `[controller]`.
    pub controller: RawController,
    /// `[integrator]`.
    pub integrator: RawIntegrator,
    /// `[initial]`.
    pub initial: RawInitial,
    /// `[sensor]`.
    pub sensor: RawSensor,
    /// `[output]`.
    pub output: RawOutput,
    /// `[[shock]]`: the shock programme.
    pub shock: Vec<ShockSpec>,
    /// `[ensemble]`: read by `plant ensemble`; scene validation ignores it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ensemble: Option<toml::Table>,
}
