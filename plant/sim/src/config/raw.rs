//! The scene file format: TOML parsed into these raw structs (unknown keys
//! are errors; every key has a default, the study's value). Each key is
//! declared once, with its doc and its default, by `scene_table!`; the
//! guide's key table (`docs/guide/scenes.md`) is checked against the
//! declarations by a test. Every choice is an enum, so a bad value names the
//! key and the allowed values. Nothing outside [`crate::config`] reads this
//! layer: the validated [`super::Scene`] is the only source of truth.

use crate::integrate::Method;
use crate::model::Cage;
use serde::{Deserialize, Serialize};
use shock_table::ShockSpec;

use super::scene_table::scene_table;

scene_table! {
/// `[scene]`: name and span of the run.
pub struct RawMeta {
    /// Scene name (empty: the file stem).
    pub name: String = String::new(),
    /// Free text.
    pub description: String = String::new(),
    /// Simulated time (s).
    pub duration_s: f64 = 1.5,
    /// Gravity (m/s²).
    pub gravity_m_s2: f64 = 9.80665,
}
}

/// `[rotor]` as a whole, the keys every model reads and the rotor models' names and key structs
/// (`config/models/`).
pub use super::models::{RawRotor, RossAxes, RotorKeys, RotorModel, RotorShared, SpinChoice};

scene_table! {
/// `[touchdown]`: the touchdown bearing.
pub struct RawTouchdown {
    /// r_0, radial air gap shaft – race bore (mm); the bore radius is r_r + r_0.
    pub air_gap_mm: f64 = 0.15,
    /// m_b (kg).
    pub race_mass_kg: f64 = 0.048,
    /// J_b (kg·m²).
    pub race_polar_inertia_kg_m2: f64 = 2.33e-5,
    /// Ball diameter (mm).
    pub ball_diameter_mm: f64 = 5.5,
    /// z.
    pub ball_count: u32 = 19,
    /// d_m (mm).
    pub pitch_diameter_mm: f64 = 51.0,
    /// Outer race diameter (mm), for reference.
    pub outer_diameter_mm: f64 = 62.0,
    /// Width B (mm), for reference.
    pub width_mm: f64 = 12.0,
    /// r_cl, race – ball radial clearance (mm).
    pub ball_clearance_mm: f64 = 0.01,
    /// `rotating` or `fixed`.
    pub cage: Cage = Cage::Rotating,
    /// `balls` (each ball a Hertz contact) or `lumped` (an isotropic ring calibrated on the balls).
    pub support: SupportChoice = SupportChoice::Balls,
    /// Deflection beyond the clearance at which the lumped ring is calibrated (mm).
    pub lumped_reference_mm: f64 = 0.01,
    /// Angle of ball 0 at t = 0 (deg).
    pub cage_phase_deg: f64 = -90.0,
    /// `constant` or `palmgren`.
    pub drag: DragChoice = DragChoice::Constant,
    /// Constant drag torque (N·m).
    pub drag_torque_n_m: f64 = 0.1,
    /// Speed below which the drag is smoothed to zero (rad/s).
    pub drag_smoothing_rad_s: f64 = 1.0,
    /// Palmgren f_0.
    pub palmgren_f0: f64 = 2.0,
    /// Palmgren ν_0 (cSt).
    pub palmgren_viscosity_cst: f64 = 20.0,
    /// Palmgren f_1.
    pub palmgren_f1: f64 = 5e-4,
    /// What the race does while the rotor – race gap is open by a safe margin: `free` (always
    /// integrated on its supports) or `parked` (held in the housing frame, support and
    /// contact kernels skipped; see [`crate::park`]).
    pub race_when_clear: RaceWhenClearChoice = RaceWhenClearChoice::Free,
    /// With `race_when_clear = "parked"`: the state the race is released with when the gap may
    /// close: `equilibrium` (at rest on its supports under gravity and the current
    /// housing acceleration) or `held` (where it was parked, at rest).
    pub race_release: ReleaseChoice = ReleaseChoice::Equilibrium,
    /// Two-plane: plane A's own values of this table's keys (the others are shared).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub a: Option<toml::Table> = None,
    /// Two-plane: plane B's own values of this table's keys.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub b: Option<toml::Table> = None,
}
}

scene_table! {
/// `[housing]`.
pub struct RawHousing {
    /// M_h (kg), for reference: the housing motion is prescribed.
    pub mass_kg: f64 = 80.96,
}
}

scene_table! {
/// `[contact]`: contact and friction laws.
pub struct RawContact {
    /// K_r (N/m^(10/9)).
    pub rotor_race_stiffness_n_per_m10_9: f64 = 1.988e9,
    /// C_r,max (N·s/m).
    pub rotor_race_damping_n_s_per_m: f64 = 1000.0,
    /// K_b (N/m^(3/2)).
    pub ball_stiffness_n_per_m1_5: f64 = 7.81e9,
    /// C_b,max (N·s/m).
    pub ball_damping_n_s_per_m: f64 = 750.0,
    /// δ_max, depth of full damping (mm).
    pub damping_depth_mm: f64 = 0.01,
    /// μ_s.
    pub friction_static: f64 = 0.1,
    /// μ_d.
    pub friction_dynamic: f64 = 0.1,
    /// v_s (m/s).
    pub stribeck_static_m_s: f64 = 0.1,
    /// v_d (m/s).
    pub stribeck_dynamic_m_s: f64 = 0.1,
    /// Two-plane: plane A's own values of this table's keys (the others are shared).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub a: Option<toml::Table> = None,
    /// Two-plane: plane B's own values of this table's keys.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub b: Option<toml::Table> = None,
}
}

scene_table! {
/// `[amb]`: the magnetic bearing.
pub struct RawAmb {
    /// `linear` or `nonlinear`.
    pub force_law: ForceLaw = ForceLaw::Linear,
    /// k_i (N/A).
    pub ki_n_per_a: f64 = 216.0,
    /// k_s (N/m).
    pub ks_n_per_m: f64 = 4.32e5,
    /// A_a (A/V).
    pub amp_gain_a_per_v: f64 = 1.0,
    /// A_s (V/m).
    pub sensor_gain_v_per_m: f64 = 25000.0,
    /// Nominal magnet air gap s_0 for the nonlinear law (mm).
    pub nominal_gap_mm: f64 = 1.0,
    /// Largest pull of one magnet, from flux saturation (N).
    pub magnet_force_limit_n: f64 = 1000.0,
    /// Model the amplifier and coil of each axis (docs/MODEL.md §12): the command becomes the
    /// current loop's reference and the force follows the coil's real current.
    pub amplifier: bool = false,
    /// The amplifier's bus voltage V_dc (V): the coil voltage is limited to ±V_dc.
    pub bus_voltage_v: f64 = 150.0,
    /// Coil inductance L (mH); the default is one magnet's at the nominal gap,
    /// 2 k / (s_0 cos η) with k from k_i, k_s and s_0 = 1 mm.
    pub coil_inductance_mh: f64 = 58.0,
    /// Coil resistance R (Ω).
    pub coil_resistance_ohm: f64 = 1.0,
    /// Closed current-loop bandwidth (Hz); the PI is designed for it from L and R.
    pub current_loop_hz: f64 = 1500.0,
    /// Back-EMF constant k_b (V·s/m) in L di/dt = v − R i − k_b ẋ; 0: none (k_i is the
    /// energy-consistent value).
    pub back_emf_v_s_per_m: f64 = 0.0,
    /// With `amplifier`: `bipolar`, one amplifier per axis driving the control current
    /// (default); `unipolar`, one amplifier per magnet driving `i_0 ± i` (needs the nonlinear
    /// law, whose bias `i_0` it carries; docs/MODEL.md §12.3).
    pub amplifier_topology: AmplifierTopology = AmplifierTopology::Bipolar,
    /// A unipolar amplifier's bridge: `one_quadrant`, `0..V_dc` (default); `two_quadrant`,
    /// `−V_dc..V_dc` while the current flows.
    pub unipolar_bridge: plant_physics::amplifier::Bridge = plant_physics::amplifier::Bridge::OneQuadrant,
    /// The angle θ of the plane's coil pair and sensor axis u from x (degrees, in [−90, 90],
    /// counter-clockwise; v is 90° further): 45 puts the magnet pairs at ±45° from the vertical,
    /// sharing the weight (docs/MODEL.md §3.3). The sensor, the wire, the currents and the
    /// controller speak in (u, v). Unset: 0, or with `rotor.ross_ambs` the ROSS file's
    /// `sensors_axis_rotation` when `rotor.ross_axes = "apply"`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis_angle_deg: Option<f64> = None,
    /// Two-plane: plane A's own values of this table's keys (the others are shared).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub a: Option<toml::Table> = None,
    /// Two-plane: plane B's own values of this table's keys.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub b: Option<toml::Table> = None,
}
}

/// `output.mcap_compression`: how `run.mcap`'s chunks are compressed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum McapCompression {
    /// Not compressed (the default): the recording's cost within 10 % of the run's.
    None,
    /// lz4: about half the size, for about twice the recording's CPU time.
    Lz4,
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

/// `integrator.realtime`: the integrator a realtime run uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RealtimeSetting {
    /// A bounded cost per tick: RK4 at fixed steps, the race parked while clear
    /// ([`super::Scene::fixed_step_overrides`]).
    Fixed,
    /// The scene's own integrator keys.
    Scene,
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

/// `controller.pacing`: how a realtime run waits between its ticks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Pacing {
    /// The plant busy-waits for each tick and the controller spins for at least 100
    /// periods before it blocks: a core each, the shortest wake-up.
    #[default]
    Spin,
    /// The plant sleeps to each tick (an absolute `clock_nanosleep`) and the controller
    /// blocks between frames: both can share one core (`pin_cores = [c, c]`), and the
    /// other cores stay free for the rest of the machine.
    Sleep,
}

/// `amb.amplifier_topology`: how the amplifiers drive an axis's two magnets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AmplifierTopology {
    /// One amplifier and coil per axis, the current of either sign (`±V_dc`).
    Bipolar,
    /// One amplifier and coil per magnet, the current one way only (`0..V_dc`).
    Unipolar,
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

scene_table! {
/// `[controller]`.
pub struct RawController {
    /// `continuous`, `sampled`, `lockstep` or `realtime`.
    pub mode: ControlMode = ControlMode::Continuous,
    /// Law name.
    pub law: String = "pd".into(),
    /// Controller rate (Hz): the macro step of the plant.
    pub rate_hz: f64 = 20000.0,
    /// k_e (N/m).
    pub stiffness_n_per_m: f64 = 1e6,
    /// ξ_e.
    pub damping_ratio: f64 = 0.01,
    /// i_max (A).
    pub current_limit_a: f64 = 2.0,
    /// Samples between the sample a command is computed from and the tick it is applied from.
    pub delay_samples: u32 = 1,
    /// Add the gravity bias current m_r g / k_i on y.
    pub gravity_bias: bool = true,
    /// The law's own parameters (free TOML, read by the law alone; at most
    /// [`controller::PARAMS_LEN`] bytes as TOML text).
    #[serde(skip_serializing_if = "toml::Table::is_empty")]
    pub params: toml::Table = toml::Table::new(),
    /// Deprecated alias of `params.enter_um` (law `relev`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relev_enter_um: Option<f64> = None,
    /// Deprecated alias of `params.exit_um` (law `relev`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relev_exit_um: Option<f64> = None,
    /// Deprecated alias of `params.recovery_damping_ratio` (law `relev`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relev_damping_ratio: Option<f64> = None,
    /// Deprecated alias of `params.hold_ms` (law `relev`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relev_hold_ms: Option<f64> = None,
    /// Deprecated alias of `params.arm_ms` (law `relev`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relev_arm_ms: Option<f64> = None,
    /// Co-simulation: what the plant applies when the controller process is
    /// lost: `hold` (the last current), `bias` (bias current only)
    /// or `stop` (end the run, exit code 4).
    pub fallback: Fallback = Fallback::Hold,
    /// Co-simulation: how long a reply may be missing before the plant looks
    /// up the controller's node; a dead or vanished node is a lost peer, a
    /// live one is waited for (lockstep) or missed (realtime). Repeated while
    /// the silence lasts (ms).
    pub reply_timeout_ms: f64 = 1.0,
    /// Co-simulation: how long to wait for a new controller after one is
    /// lost (ms); the plant respawns the controller it started itself.
    /// 0 stops the run with exit code 4.
    pub reconnect_timeout_ms: f64 = 0.0,
    /// Co-simulation: how long to wait for the first controller's handshake (ms).
    pub connect_timeout_ms: f64 = 10_000.0,
    /// Co-simulation: how long a waiting side busy-polls before it blocks on
    /// an event (µs). Longer costs a core while idle; shorter adds a wake-up
    /// (several µs) to each late reply.
    pub spin_us: f64 = 200.0,
    /// Co-simulation: CPU cores to pin `[plant, controller]` to; empty = no pinning.
    pub pin_cores: Vec<usize> = Vec::new(),
    /// Co-simulation: the controller process to start instead of the built-in `controller`:
    /// a list of strings (`["python3", "my_controller.py", "--gain", "2"]`) or one string (a
    /// path). The plant appends `--run-id ID` and sets `AMB_TESTBED_RUN_ID` and
    /// `AMB_TESTBED_CONNECT_TIMEOUT_S`. An element that is a relative path naming an existing
    /// file or folder in the scene file's folder is taken from there (written absolute in the
    /// run folder's `scene.toml`); others are left as they are (`argv[0]` without a `/` is
    /// looked up in `PATH`). With a command, the plant does not check `law` or `params`: the
    /// controller does, in the handshake. `None`: the built-in `controller`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub command: Option<toml::Value> = None,
    /// A controller FMU as the controller (docs/guide/fmu-controller.md): its path (from the
    /// scene file's folder) or a table `path`, `map`, `solver`, `substeps`, `step_timeout_ms`
    /// ([`super::fmu`]). `None`: no FMU.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fmu: Option<toml::Value> = None,
    /// Co-simulation (lockstep, and realtime too): how long the plant waits for a reply from a
    /// controller that is alive (its node and process exist) before it treats it as lost (ms):
    /// a stopped (SIGSTOP), hung or confused controller (one answering another session).
    pub lockstep_timeout_ms: f64 = 5000.0,
    /// Co-simulation: `SCHED_FIFO` priority (1 to 99) for the plant's loop thread and the
    /// controller, with memory locking; 0 = the normal scheduler. Where the system
    /// refuses it, the run goes on without, with a warning.
    pub realtime_priority: u32 = 0,
    /// Co-simulation, realtime: the largest share of ticks a run may go without its
    /// controller's reply (deadline misses, and fallback ticks while no controller is
    /// connected); past it the run ends with status `miss_budget` (exit code 6); 1 is no
    /// limit. The default, 1 %, is met with room by a host set up to run the scene (0 misses
    /// in 65 runs, docs/results/realtime.md); a collapsed schedule misses 28–99 %, and a
    /// miss is a held current: another loop than the scene's.
    pub max_miss_fraction: f64 = 0.01,
    /// Sampled and co-simulation: the most non-finite commands (NaN currents) in a row a run
    /// holds the last valid command through; past it the run ends with status
    /// `invalid_commands` (exit code 8).
    pub max_invalid_burst: u64 = 10,
    /// Sampled and co-simulation: the largest share of non-finite commands a run may have
    /// (judged from 1000 ticks on and over the whole run); past it the run ends with status
    /// `invalid_commands` (exit code 8); 1 is no limit.
    pub max_invalid_fraction: f64 = 0.01,
    /// Co-simulation, realtime: the largest fraction of ticks that may start more than one
    /// period late (plant overruns); past it the run ends with status `overrun_budget` (exit
    /// code 10); 1 is no limit. The default, 5 %, is above what a host set up to run the scene
    /// shows (up to 3 % in runs without a miss that wrote the lockstep trace bit for bit: an
    /// overrun alone lets the simulated clock fall behind, it does not change the loop); a
    /// collapsed schedule overruns 54–61 % (docs/results/realtime.md).
    pub max_overrun_fraction: f64 = 0.05,
    /// Co-simulation, realtime: `spin` (a core each, busy-waiting) or `sleep` (the plant
    /// sleeps to each tick, the controller blocks between frames; both may share one core).
    pub pacing: Pacing = Pacing::Spin,
}
}

scene_table! {
/// `[integrator]`.
pub struct RawIntegrator {
    /// `explicit_euler`, `symplectic_euler`, `rk4`, `dp5` or `dop853`.
    pub method: Method = Method::Dp5,
    /// Relative tolerance (adaptive).
    pub rtol: f64 = 1e-6,
    /// Absolute tolerance for every component (adaptive).
    pub atol: f64 = 1e-9,
    /// Override for positions (m).
    pub atol_position_m: Option<f64> = None,
    /// Override for velocities (m/s).
    pub atol_velocity_m_s: Option<f64> = None,
    /// Override for angles (rad).
    pub atol_angle_rad: Option<f64> = None,
    /// Override for angular speeds (rad/s).
    pub atol_angular_speed_rad_s: Option<f64> = None,
    /// Substeps per controller period (fixed-step).
    pub substeps: u32 = 16,
    /// Substeps per controller period while the race is free, with
    /// `touchdown.race_when_clear = "parked"` (fixed-step); 0 = `substeps`.
    pub contact_substeps: u32 = 0,
    /// The run stops as diverged when the rotor or race leaves the clearance by more than this (mm).
    pub radius_guard_mm: f64 = 0.5,
    /// The integrator of `controller.mode = "realtime"` runs: `fixed` (a bounded cost per
    /// tick: RK4 with one step per tick while the race is parked and the contact substeps of
    /// the stability estimate while it is free, the ensembles' fast setting; it overrides
    /// `method`, `substeps`, `contact_substeps` and `touchdown.race_when_clear`/`race_release`)
    /// or `scene` (the keys above as written). Other modes ignore it.
    pub realtime: RealtimeSetting = RealtimeSetting::Fixed,
}
}

scene_table! {
/// `[initial]`.
pub struct RawInitial {
    /// Start the rotor on its linear unbalance orbit (true), else at rest.
    pub unbalance_orbit: bool = true,
    /// Offset added to the rotor's initial x (µm).
    pub rotor_x_um: f64 = 0.0,
    /// Offset added to the rotor's initial y (µm).
    pub rotor_y_um: f64 = 0.0,
    /// Two-plane: offset added to the initial slope a = dx/dz of the rotor axis (µrad); none: 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slope_x_urad: Option<f64> = None,
    /// Two-plane: offset added to the initial slope b = dy/dz (µrad); none: 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slope_y_urad: Option<f64> = None,
}
}

scene_table! {
/// `[sensor]`: what the controller reads. The bandwidth, runout and range act in every mode
/// (the continuous PD reads the front end's output and its rate); the noise and the ADC in the
/// sampled and co-simulation modes. The gain is `amb.sensor_gain_v_per_m`.
pub struct RawSensor {
    /// White noise added to each sample, standard deviation (V).
    pub noise_v_rms: f64 = 0.0,
    /// Seed of the noise.
    pub noise_seed: u64 = 1,
    /// ADC resolution (bits); 0 = ideal.
    pub adc_bits: u32 = 0,
    /// ADC input range ±V (V).
    pub adc_range_v: f64 = 10.0,
    /// The sensor's bandwidth, its low-pass corner (Hz); 0: ideal.
    pub bandwidth_hz: f64 = 0.0,
    /// Order of the low-pass: 1 (first order) or 2 (Butterworth).
    pub filter_order: u32 = 2,
    /// Measurement range ±r (µm): the measured displacement clips there; 0: unlimited.
    pub range_um: f64 = 0.0,
    /// Runout harmonics, `[[sensor.runout]]` tables of `axis`, `order`, `amplitude_um`,
    /// `phase_deg`, `kind`.
    pub runout: Vec<RawRunout> = Vec::new(),
}
}

/// One `[[sensor.runout]]` harmonic: `amplitude_um · cos(order · θ + phase_deg)` added to the
/// displacement `axis`'s sensor reads, θ the rotor's angle (the keyphasor's).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRunout {
    /// `x`, `y` (plane A's in a two-plane scene), `x_b`, `y_b`; `x_a`, `y_a` are `x`, `y`.
    pub axis: RunoutAxis,
    /// Order ≥ 1 (1 = once per revolution).
    pub order: u32,
    /// Amplitude (µm).
    pub amplitude_um: f64,
    /// Phase (deg).
    #[serde(default)]
    pub phase_deg: f64,
    /// `mechanical` or `electrical` (a label: both add alike).
    #[serde(default = "mechanical")]
    pub kind: crate::sensor::RunoutKind,
}

fn mechanical() -> crate::sensor::RunoutKind {
    crate::sensor::RunoutKind::Mechanical
}

/// `sensor.runout.axis`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RunoutAxis {
    /// x (plane A's).
    #[serde(alias = "x_a")]
    X,
    /// y (plane A's).
    #[serde(alias = "y_a")]
    Y,
    /// Plane B's x.
    XB,
    /// Plane B's y.
    YB,
}

scene_table! {
/// `[output]`.
pub struct RawOutput {
    /// Trace rate (Hz).
    pub rate_hz: f64 = 20000.0,
    /// Write PNG plots.
    pub plots: bool = true,
    /// Also record the run as `run.mcap` (issue 42); written into `scene.toml` only when set.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mcap: Option<bool> = None,
    /// The live view's rate (`plant run --live`, issue 42): rows sent per simulated second;
    /// written into `scene.toml` only when set.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub live_rate_hz: Option<f64> = None,
    /// The compression of `run.mcap`'s chunks; written into `scene.toml` only when set.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mcap_compression: Option<McapCompression> = None,
}
}

scene_table! {
/// `[robustness]`: `plant run` repeats the run with perturbations far below the model's own
/// uncertainty and says how robust its outcome is (`plant::robustness`); other commands ignore it.
pub struct RawRobustness {
    /// Perturbed runs beside the run (0: none; at most 256).
    pub members: i64 = 0,
    /// With `members` > 0, one more run with the integrator refined (a tenth of the adaptive
    /// tolerances, or four times the fixed-step substeps): an outcome integration error picks.
    pub integration: bool = true,
}
}

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
    /// `[robustness]`: read by `plant run` ([`RawRobustness`]); absent unless given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub robustness: Option<RawRobustness>,
    /// `[ensemble]`: read by `plant ensemble`; scene validation ignores it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ensemble: Option<toml::Table>,
}

impl RawScene {
    /// The integrator and the race's setting as written, in words (for messages): `dp5 rtol
    /// 1e-6, race free`, `rk4 with 1 step per tick (3 while the race is free), race parked`.
    pub fn integrator_and_race(&self) -> String {
        fn name<T: Serialize>(v: &T) -> String {
            toml::Value::try_from(v).ok().and_then(|v| v.as_str().map(str::to_owned)).unwrap_or_default()
        }
        let i = &self.integrator;
        let (method, race) = (name(&i.method), name(&self.touchdown.race_when_clear));
        let steps = match i.method.is_adaptive() {
            true => format!("rtol {:e}", i.rtol),
            false => {
                let free = if i.contact_substeps == 0 { i.substeps } else { i.contact_substeps };
                let plural = if i.substeps == 1 { "step" } else { "steps" };
                match self.touchdown.race_when_clear {
                    RaceWhenClearChoice::Parked => {
                        format!("with {} {plural} per tick ({free} while the race is free)", i.substeps)
                    }
                    RaceWhenClearChoice::Free => format!("with {} {plural} per tick", i.substeps),
                }
            }
        };
        format!("{method} {steps}, race {race}")
    }

    /// The tables `scene_table!` declares, by their name in the file, with their keys (the
    /// `[[shock]]` list and the `[ensemble]` table are declared by their own modules).
    pub fn tables() -> [(&'static str, &'static [&'static str]); 11] {
        [
            ("scene", RawMeta::KEYS),
            ("rotor", RawRotor::keys()),
            ("touchdown", RawTouchdown::KEYS),
            ("housing", RawHousing::KEYS),
            ("contact", RawContact::KEYS),
            ("amb", RawAmb::KEYS),
            ("controller", RawController::KEYS),
            ("integrator", RawIntegrator::KEYS),
            ("initial", RawInitial::KEYS),
            ("sensor", RawSensor::KEYS),
            ("output", RawOutput::KEYS),
        ]
    }
}
