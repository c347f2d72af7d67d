//! The wire protocol between the plant and a controller process (iceoryx2,
//! shared memory, one machine).
//!
//! Every message is a plain `#[repr(C)]` struct of integers, `f64` and fixed
//! byte arrays: no pointers, no heap, **native endianness** (both processes
//! run on the same machine). Sizes and offsets below are checked at compile
//! time; a controller written in C, C++ or Python (iceoryx2 has bindings for
//! each) declares the same structs with the same iceoryx2 type names and
//! plugs in. `docs/wire-protocol.md` is the long form of this page.
//!
//! # Services (`<id>` = the run id, see [`valid_run_id`])
//!
//! | service name                    | pattern           | payload         | from → to          |
//! |---------------------------------|-------------------|-----------------|--------------------|
//! | `amb-testbed/<id>/hello`        | publish-subscribe | [`Hello`]       | plant → controller |
//! | `amb-testbed/<id>/ack`          | publish-subscribe | [`Ack`]         | controller → plant |
//! | `amb-testbed/<id>/sensor`       | publish-subscribe | [`SensorFrame`] | plant → controller |
//! | `amb-testbed/<id>/sensor`       | event             | –               | wakes the controller |
//! | `amb-testbed/<id>/sensor/wake`  | publish-subscribe | [`WakeRequest`] | controller → plant |
//! | `amb-testbed/<id>/command`      | publish-subscribe | [`CommandFrame`]| controller → plant |
//! | `amb-testbed/<id>/command`      | event             | –               | wakes the plant    |
//! | `amb-testbed/<id>/command/wake` | publish-subscribe | [`WakeRequest`] | plant → controller |
//!
//! Nodes are named `amb-testbed/<id>/plant` and `amb-testbed/<id>/controller`;
//! each side watches the other's node to tell a dead peer from a slow one.
//!
//! # Sequence
//!
//! 1. The plant publishes [`Hello`] (again every few milliseconds) until a
//!    controller answers with an [`Ack`] of the same `session` and `token`.
//!    The hello carries the common loop design ([`Hello::design`]), the law's
//!    name and its parameter document (`[controller.params]` as TOML text,
//!    at most [`PARAMS_LEN`] bytes), and the run's random `token`. The
//!    controller checks the protocol version, the rate, the number of axes,
//!    the units and the run id ([`check_hello`]) and builds its law through
//!    the registry; on any mismatch, or a law refusing its parameters, it
//!    answers with a non-zero [`Ack::status`] (a [`Refusal`] code) and a
//!    message, and exits; the plant prints the message and stops. What the
//!    controller runs differently from the hello (its `--config` file or
//!    `--law`) comes back in [`Ack::overrides`].
//! 2. For each tick `k` the plant publishes a [`SensorFrame`] with `seq = k`;
//!    the controller runs its law on it and publishes a [`CommandFrame`] with
//!    the same `seq`. In `lockstep` the plant waits for it; in `realtime` the
//!    plant paces the wall clock and a reply missing at the next tick is a
//!    deadline miss. Every frame carries the run's token; each side ignores
//!    frames with another token (another run under the same id, a stale
//!    process), before looking at anything else in them.
//! 3. A [`SensorFrame`] with [`SensorFrame::STOP`] and the run's token ends
//!    the run, whatever its session (the controller exits 0); a
//!    [`CommandFrame`] with [`CommandFrame::STOPPING`] tells the plant that
//!    the controller was asked to stop (SIGINT/SIGTERM). Checks on a received
//!    frame, in order: token, then STOP, then session.
//!
//! # Waking a blocked peer
//!
//! Each side busy-polls its subscriber for a short budget (`Hello::spin_ns`),
//! then blocks on its event listener. To avoid a system call per message, a
//! sender notifies only a peer that asked for it: before blocking, the
//! receiver publishes a [`WakeRequest`], issues a sequentially-consistent
//! fence and polls once more; the sender, after publishing a frame, issues
//! the same fence and notifies if it finds a wake request. One of the two
//! always sees the other (Dekker), so no wake-up is lost. **Serving the
//! plant's wake requests is mandatory** (after publishing a command frame:
//! fence, drain `command/wake`, notify if it held any): a controller that
//! does not leaves every late reply waiting for the plant's timed wait, which
//! iceoryx2 may stretch to several milliseconds (the plant warns). A
//! controller that blocks must also publish its own wake request on
//! `sensor/wake` before it does; one that never blocks may skip that half.
//! Open every service (the `sensor` subscriber included) before answering
//! the hello: the plant sends frame 0 right after the ack, and subscribers
//! get no history. `docs/wire-protocol.md` says the rest (the order of the
//! checks, liveness, the exact form of the shipped laws).

use crate::law::{Design, Geometry, LoopConstants, RotorDesign, RotorSample, ROTOR_AXES};
use crate::params::{ParamsError, PARAMS_LEN};
use iceoryx2::prelude::ZeroCopySend;

/// Protocol version. Incremented on any change of a layout or of the meaning
/// of a field; it is also part of every iceoryx2 type name below, so peers of
/// different versions cannot even open each other's services (`docs/wire-protocol.md`,
/// "Versions", says what each side then sees).
pub const PROTOCOL_VERSION: u32 = 4;

/// Room for axes in a frame: entries `0..axes` are used, the rest are 0.
pub const MAX_AXES: usize = 8;

/// Axes of the planar model (x, y): `Hello.axes` of a planar run.
pub const AXES: u32 = 2;

/// Axes of the two-plane rotor (x_A, y_A, x_B, y_B): `Hello.axes` of a two-plane run.
pub const TWO_PLANE_AXES: u32 = 4;

/// Units code: sensor in volts, currents in amperes, time in seconds, all
/// other quantities SI.
pub const UNITS_SI: u32 = 1;

/// Longest run id (bytes).
pub const RUN_ID_LEN: usize = 32;

/// Length of a law name field (bytes, UTF-8, NUL-padded).
pub const LAW_NAME_LEN: usize = 32;

/// Length of an [`Ack`] message (bytes, UTF-8, NUL-padded).
pub const MESSAGE_LEN: usize = 256;

/// Length of an [`Ack`]'s overrides document (bytes, UTF-8 TOML).
pub const OVERRIDES_LEN: usize = 4096;

/// Prefix of every service and node name.
pub const SERVICE_PREFIX: &str = "amb-testbed";

/// How the plant drives the controller ([`Hello::mode`]).
pub mod mode {
    /// The plant waits for every reply.
    pub const LOCKSTEP: u32 = 1;
    /// The plant paces the wall clock; late replies are deadline misses.
    pub const REALTIME: u32 = 2;
    /// A benchmark of the round trip (sensor values are not physical).
    pub const BENCH: u32 = 3;
}

/// One sample of the sensors with the keyphasor, plant → controller. 128 bytes.
///
/// | offset | size | field         | type      |
/// |-------:|-----:|---------------|-----------|
/// | 0      | 8    | `seq`         | u64       |
/// | 8      | 8    | `t_s`         | f64       |
/// | 16     | 8    | `token`       | u64       |
/// | 24     | 8    | `sent_ns`     | u64       |
/// | 32     | 4    | `status`      | u32       |
/// | 36     | 4    | `session`     | u32       |
/// | 40     | 4    | `axes`        | u32       |
/// | 44     | 4    | `reserved`    | u32       |
/// | 48     | 64   | `sensor_v`    | [f64; 8]  |
/// | 112    | 8    | `speed_rad_s` | f64       |
/// | 120    | 8    | `angle_rad`   | f64       |
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[type_name("amb_testbed.v4.SensorFrame")]
#[repr(C)]
pub struct SensorFrame {
    /// Tick index k (0, 1, 2, …).
    pub seq: u64,
    /// Simulated time of the sample, `k T` (s).
    pub t_s: f64,
    /// The run's token ([`Hello::token`]): a frame with another token is never applied.
    pub token: u64,
    /// `CLOCK_MONOTONIC` of the plant when it published the frame (ns).
    pub sent_ns: u64,
    /// Bit flags: [`SensorFrame::STOP`].
    pub status: u32,
    /// Session of the handshake this frame belongs to ([`Hello::session`]).
    pub session: u32,
    /// Entries of `sensor_v` in use: [`AXES`] or [`TWO_PLANE_AXES`], as the hello.
    pub axes: u32,
    /// 0.
    pub reserved: u32,
    /// Sensor voltages `A_s·Δ` (V) in axis order: x, y (planar) or x_A, y_A, x_B, y_B;
    /// unused entries 0.
    pub sensor_v: [f64; MAX_AXES],
    /// The keyphasor's speed: the rotor's spin speed Ω (rad/s) at the sample.
    pub speed_rad_s: f64,
    /// The keyphasor's angle: the rotor's angle (rad) in [0, 2π) at the sample, in the sensor
    /// frame; 0 when the unbalance points along +x ([`crate::Sample::angle_rad`]).
    pub angle_rad: f64,
}

impl SensorFrame {
    /// The run is over: the controller exits with code 0. `seq` and the
    /// values carry no sample.
    pub const STOP: u32 = 1;

    /// The x and y sensor voltages (V) (plane A's on a two-plane rotor).
    pub fn sensor_xy(&self) -> [f64; 2] {
        [self.sensor_v[0], self.sensor_v[1]]
    }

    /// The sample this frame carries, for a law of the whole rotor (at most
    /// [`ROTOR_AXES`] axes read; `axes` as the frame says, capped there).
    pub fn rotor_sample(&self) -> RotorSample {
        let axes = self.axes.min(ROTOR_AXES as u32);
        let mut sensor_v = [0.0; ROTOR_AXES];
        sensor_v[..axes as usize].copy_from_slice(&self.sensor_v[..axes as usize]);
        RotorSample {
            seq: self.seq,
            t_s: self.t_s,
            axes,
            sensor_v,
            speed_rad_s: self.speed_rad_s,
            angle_rad: self.angle_rad,
        }
    }
}

/// Widens an x, y pair to a frame's axis array (unused entries 0).
pub fn axes_of(xy: [f64; 2]) -> [f64; MAX_AXES] {
    let mut out = [0.0; MAX_AXES];
    out[..2].copy_from_slice(&xy);
    out
}

/// Widens the first `axes` entries of a rotor's axis array to a frame's (the rest 0).
pub fn rotor_axes_of(values: [f64; ROTOR_AXES], axes: u32) -> [f64; MAX_AXES] {
    let n = (axes as usize).min(ROTOR_AXES);
    let mut out = [0.0; MAX_AXES];
    out[..n].copy_from_slice(&values[..n]);
    out
}

/// The answer to one sample, controller → plant. 112 bytes.
///
/// | offset | size | field         | type     |
/// |-------:|-----:|---------------|----------|
/// | 0      | 8    | `seq`         | u64      |
/// | 8      | 8    | `token`       | u64      |
/// | 16     | 8    | `received_ns` | u64      |
/// | 24     | 8    | `sent_ns`     | u64      |
/// | 32     | 4    | `status`      | u32      |
/// | 36     | 4    | `session`     | u32      |
/// | 40     | 4    | `axes`        | u32      |
/// | 44     | 4    | `reserved`    | u32      |
/// | 48     | 64   | `current_a`   | [f64; 8] |
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[type_name("amb_testbed.v4.CommandFrame")]
#[repr(C)]
pub struct CommandFrame {
    /// The `seq` of the [`SensorFrame`] this answers.
    pub seq: u64,
    /// The run's token, copied from the hello ([`Hello::token`]).
    pub token: u64,
    /// `CLOCK_MONOTONIC` of the controller when it took the sensor frame (ns).
    pub received_ns: u64,
    /// `CLOCK_MONOTONIC` of the controller when it published this frame (ns).
    pub sent_ns: u64,
    /// 0, or [`CommandFrame::STOPPING`].
    pub status: u32,
    /// Session of the handshake ([`Hello::session`]).
    pub session: u32,
    /// Entries of `current_a` in use: the hello's `axes`.
    pub axes: u32,
    /// 0.
    pub reserved: u32,
    /// Coil currents (A) in axis order (x, y, or x_A, y_A, x_B, y_B), each saturated at its
    /// plane's limit ([`Hello::current_limit_a`], [`Hello::b_current_limit_a`]); unused
    /// entries 0.
    pub current_a: [f64; MAX_AXES],
}

impl CommandFrame {
    /// The controller was asked to stop (SIGINT/SIGTERM) and is exiting;
    /// `seq` and `current_a` carry no answer.
    pub const STOPPING: u32 = 1;

    /// The x and y currents (A) (plane A's on a two-plane rotor).
    pub fn current_xy(&self) -> [f64; 2] {
        [self.current_a[0], self.current_a[1]]
    }

    /// The currents of the first [`ROTOR_AXES`] axes (A), in axis order.
    pub fn current_axes(&self) -> [f64; ROTOR_AXES] {
        [self.current_a[0], self.current_a[1], self.current_a[2], self.current_a[3]]
    }
}

/// Ask the peer to notify the event service of the stream it waits on,
/// because the sender is about to block. 8 bytes.
///
/// | offset | size | field  | type |
/// |-------:|-----:|--------|------|
/// | 0      | 8    | `seq`  | u64  |
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[type_name("amb_testbed.v4.WakeRequest")]
#[repr(C)]
pub struct WakeRequest {
    /// The `seq` the sender waits for (informative).
    pub seq: u64,
}

/// The plant's side of the handshake: what it runs, each bearing plane's loop design
/// ([`Design`]: plane A in the fields of protocol 3, plane B's in the `b_` fields), the
/// rotor's geometry for 4 axes ([`Geometry`]), and the law's own parameters. 4448 bytes.
/// The fields of a planar hello past `params` are 0.
///
/// | offset | size | field                  | type       |
/// |-------:|-----:|------------------------|------------|
/// | 0      | 4    | `protocol_version`     | u32        |
/// | 4      | 4    | `axes`                 | u32        |
/// | 8      | 4    | `units`                | u32        |
/// | 12     | 4    | `session`              | u32        |
/// | 16     | 8    | `token`                | u64        |
/// | 24     | 8    | `rate_hz`              | f64        |
/// | 32     | 8    | `period_s`             | f64        |
/// | 40     | 32   | `run_id`               | [u8; 32]   |
/// | 72     | 32   | `law`                  | [u8; 32]   |
/// | 104    | 8    | `stiffness_n_per_m`    | f64        |
/// | 112    | 8    | `damping_ratio`        | f64        |
/// | 120    | 8    | `ki_n_per_a`           | f64        |
/// | 128    | 8    | `ks_n_per_m`           | f64        |
/// | 136    | 8    | `amp_gain_a_per_v`     | f64        |
/// | 144    | 8    | `sensor_gain_v_per_m`  | f64        |
/// | 152    | 8    | `rotor_mass_kg`        | f64        |
/// | 160    | 8    | `gravity_m_s2`         | f64        |
/// | 168    | 8    | `current_limit_a`      | f64        |
/// | 176    | 8    | `air_gap_m`            | f64        |
/// | 184    | 4    | `delay_samples`        | u32        |
/// | 188    | 4    | `gravity_bias`         | u32        |
/// | 192    | 8    | `spin_ns`              | u64        |
/// | 200    | 4    | `mode`                 | u32        |
/// | 204    | 4    | `plant_pid`            | u32        |
/// | 208    | 4    | `params_len`           | u32        |
/// | 212    | 4    | `reserved`             | u32        |
/// | 216    | 4096 | `params`               | [u8; 4096] |
/// | 4312   | 8    | `b_stiffness_n_per_m`  | f64        |
/// | 4320   | 8    | `b_damping_ratio`      | f64        |
/// | 4328   | 8    | `b_ki_n_per_a`         | f64        |
/// | 4336   | 8    | `b_ks_n_per_m`         | f64        |
/// | 4344   | 8    | `b_amp_gain_a_per_v`   | f64        |
/// | 4352   | 8    | `b_sensor_gain_v_per_m`| f64        |
/// | 4360   | 8    | `b_rotor_mass_kg`      | f64        |
/// | 4368   | 8    | `b_current_limit_a`    | f64        |
/// | 4376   | 8    | `b_air_gap_m`          | f64        |
/// | 4384   | 8    | `total_mass_kg`        | f64        |
/// | 4392   | 8    | `transverse_inertia_kg_m2` | f64    |
/// | 4400   | 8    | `polar_inertia_kg_m2`  | f64        |
/// | 4408   | 8    | `rated_speed_rad_s`    | f64        |
/// | 4416   | 8    | `bearing_a_z_m`        | f64        |
/// | 4424   | 8    | `bearing_b_z_m`        | f64        |
/// | 4432   | 8    | `sensor_a_z_m`         | f64        |
/// | 4440   | 8    | `sensor_b_z_m`         | f64        |
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("amb_testbed.v4.Hello")]
#[repr(C)]
pub struct Hello {
    /// [`PROTOCOL_VERSION`] of the plant.
    pub protocol_version: u32,
    /// Number of axes: [`AXES`] (planar) or [`TWO_PLANE_AXES`].
    pub axes: u32,
    /// Units code, [`UNITS_SI`].
    pub units: u32,
    /// Handshake number: 1 for the first controller, +1 per reconnection.
    pub session: u32,
    /// The run's token: random per run, never 0. Every frame of the run carries it; a frame
    /// with another token (another run, a stale process) is never applied.
    pub token: u64,
    /// Controller rate (Hz).
    pub rate_hz: f64,
    /// Controller period `T` (s), as the plant computed it from the rate.
    pub period_s: f64,
    /// The run id, UTF-8, NUL-padded.
    pub run_id: [u8; RUN_ID_LEN],
    /// Law name (`controller.law`), UTF-8, NUL-padded.
    pub law: [u8; LAW_NAME_LEN],
    /// Design stiffness k_e (N/m) (plane A's).
    pub stiffness_n_per_m: f64,
    /// Design damping ratio ξ_e (plane A's).
    pub damping_ratio: f64,
    /// Force-current coefficient k_i (N/A) (plane A's).
    pub ki_n_per_a: f64,
    /// Force-displacement coefficient k_s (N/m) (plane A's).
    pub ks_n_per_m: f64,
    /// Amplifier gain A_a (A/V) (plane A's).
    pub amp_gain_a_per_v: f64,
    /// Sensor gain A_s (V/m) (plane A's).
    pub sensor_gain_v_per_m: f64,
    /// Rotor mass m_r (kg) carried by the bearing: the planar model's mass, plane A's share on
    /// a two-plane rotor.
    pub rotor_mass_kg: f64,
    /// Gravity g (m/s²) (both planes).
    pub gravity_m_s2: f64,
    /// Amplifier limit i_max (A) (plane A's): the controller saturates at it.
    pub current_limit_a: f64,
    /// Radial air gap r_0 of the touchdown bearing (m) (plane A's).
    pub air_gap_m: f64,
    /// Samples between a sample and the tick its command is applied from.
    pub delay_samples: u32,
    /// 1: add the gravity bias current on y.
    pub gravity_bias: u32,
    /// How long a waiting side busy-polls before it blocks (ns).
    pub spin_ns: u64,
    /// [`mode`] code.
    pub mode: u32,
    /// Process id of the plant (informative).
    pub plant_pid: u32,
    /// Bytes of `params` in use.
    pub params_len: u32,
    /// 0.
    pub reserved: u32,
    /// The scene's `[controller.params]` table as TOML text, UTF-8 (the first `params_len`
    /// bytes; the rest 0).
    pub params: [u8; PARAMS_LEN],
    /// Plane B's design stiffness k_e (N/m); 0 on a planar hello (as every field below).
    pub b_stiffness_n_per_m: f64,
    /// Plane B's design damping ratio ξ_e.
    pub b_damping_ratio: f64,
    /// Plane B's k_i (N/A).
    pub b_ki_n_per_a: f64,
    /// Plane B's k_s (N/m).
    pub b_ks_n_per_m: f64,
    /// Plane B's amplifier gain A_a (A/V).
    pub b_amp_gain_a_per_v: f64,
    /// Plane B's sensor gain A_s (V/m).
    pub b_sensor_gain_v_per_m: f64,
    /// The rotor mass plane B carries (kg).
    pub b_rotor_mass_kg: f64,
    /// Plane B's amplifier limit (A).
    pub b_current_limit_a: f64,
    /// Plane B's touchdown air gap (m).
    pub b_air_gap_m: f64,
    /// The whole rotor's mass M (kg).
    pub total_mass_kg: f64,
    /// Transverse moment of inertia I_t about the centre of mass (kg m²).
    pub transverse_inertia_kg_m2: f64,
    /// Polar moment of inertia I_p (kg m²).
    pub polar_inertia_kg_m2: f64,
    /// Rated spin speed (rad/s).
    pub rated_speed_rad_s: f64,
    /// Bearing plane A's station z_A from the centre of mass (m, negative: A is on −z).
    pub bearing_a_z_m: f64,
    /// Bearing plane B's station z_B (m), > z_A.
    pub bearing_b_z_m: f64,
    /// Sensor plane A's station (m).
    pub sensor_a_z_m: f64,
    /// Sensor plane B's station (m).
    pub sensor_b_z_m: f64,
}

/// The controller's side of the handshake. 4416 bytes.
///
/// | offset | size | field              | type       |
/// |-------:|-----:|--------------------|------------|
/// | 0      | 4    | `protocol_version` | u32        |
/// | 4      | 4    | `session`          | u32        |
/// | 8      | 4    | `status`           | u32        |
/// | 12     | 4    | `controller_pid`   | u32        |
/// | 16     | 8    | `token`            | u64        |
/// | 24     | 32   | `law`              | [u8; 32]   |
/// | 56     | 256  | `message`          | [u8; 256]  |
/// | 312    | 4    | `overrides_len`    | u32        |
/// | 316    | 4    | `reserved`         | u32        |
/// | 320    | 4096 | `overrides`        | [u8; 4096] |
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("amb_testbed.v4.Ack")]
#[repr(C)]
pub struct Ack {
    /// [`PROTOCOL_VERSION`] of the controller.
    pub protocol_version: u32,
    /// The [`Hello::session`] this answers.
    pub session: u32,
    /// 0: accepted; otherwise a [`Refusal`] code.
    pub status: u32,
    /// Process id of the controller.
    pub controller_pid: u32,
    /// Echo of [`Hello::token`].
    pub token: u64,
    /// The law the controller runs (it may override the plant's choice).
    pub law: [u8; LAW_NAME_LEN],
    /// What the controller runs, or why it refuses; UTF-8, NUL-padded.
    pub message: [u8; MESSAGE_LEN],
    /// Bytes of `overrides` in use.
    pub overrides_len: u32,
    /// 0.
    pub reserved: u32,
    /// What the controller runs differently from the hello, as TOML text: a `[controller]`
    /// table (with `[controller.params]`), empty if nothing. The plant writes it into the run
    /// folder's `scene.toml` and `summary.json`, so that the folder reproduces the run.
    pub overrides: [u8; OVERRIDES_LEN],
}

/// Why a controller refuses a [`Hello`] ([`Ack::status`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum Refusal {
    /// Different [`PROTOCOL_VERSION`].
    Version = 1,
    /// The controller is configured for another rate.
    Rate = 2,
    /// Different number of axes.
    Axes = 3,
    /// Different units code.
    Units = 4,
    /// Unknown law or invalid design.
    Law = 5,
    /// The hello carries another run id.
    RunId = 6,
    /// The law refuses its parameters (or the parameter document is malformed).
    Params = 7,
}

impl Refusal {
    /// Every refusal, in code order.
    pub const ALL: [Refusal; 7] =
        [Refusal::Version, Refusal::Rate, Refusal::Axes, Refusal::Units, Refusal::Law, Refusal::RunId, Refusal::Params];

    /// Its name in the C header (`AMB_TESTBED_ACK_<name>`) and [`constants`].
    pub fn constant_name(self) -> &'static str {
        match self {
            Refusal::Version => "VERSION",
            Refusal::Rate => "RATE",
            Refusal::Axes => "AXES",
            Refusal::Units => "UNITS",
            Refusal::Law => "LAW",
            Refusal::RunId => "RUN_ID",
            Refusal::Params => "PARAMS",
        }
    }

    /// The code as sent.
    pub fn code(self) -> u32 {
        self as u32
    }

    /// A short name for a code (`"unknown reason"` for codes this version does not know).
    pub fn describe(code: u32) -> &'static str {
        match code {
            1 => "protocol version mismatch",
            2 => "rate mismatch",
            3 => "axis count mismatch",
            4 => "units mismatch",
            5 => "law rejected",
            6 => "run id mismatch",
            7 => "parameters rejected",
            _ => "unknown reason",
        }
    }
}

// The layouts above are the protocol: a change must fail to compile here.
const _: () = {
    use core::mem::{align_of, offset_of, size_of};
    assert!(size_of::<SensorFrame>() == 128 && align_of::<SensorFrame>() == 8);
    assert!(offset_of!(SensorFrame, seq) == 0 && offset_of!(SensorFrame, t_s) == 8);
    assert!(offset_of!(SensorFrame, token) == 16 && offset_of!(SensorFrame, sent_ns) == 24);
    assert!(offset_of!(SensorFrame, status) == 32 && offset_of!(SensorFrame, session) == 36);
    assert!(offset_of!(SensorFrame, axes) == 40 && offset_of!(SensorFrame, reserved) == 44);
    assert!(offset_of!(SensorFrame, sensor_v) == 48);
    assert!(offset_of!(SensorFrame, speed_rad_s) == 112 && offset_of!(SensorFrame, angle_rad) == 120);
    assert!(size_of::<CommandFrame>() == 112 && align_of::<CommandFrame>() == 8);
    assert!(offset_of!(CommandFrame, seq) == 0 && offset_of!(CommandFrame, token) == 8);
    assert!(offset_of!(CommandFrame, received_ns) == 16 && offset_of!(CommandFrame, sent_ns) == 24);
    assert!(offset_of!(CommandFrame, status) == 32 && offset_of!(CommandFrame, session) == 36);
    assert!(offset_of!(CommandFrame, axes) == 40 && offset_of!(CommandFrame, reserved) == 44);
    assert!(offset_of!(CommandFrame, current_a) == 48);
    assert!(size_of::<WakeRequest>() == 8 && align_of::<WakeRequest>() == 8);
    assert!(size_of::<Hello>() == 4448 && align_of::<Hello>() == 8);
    assert!(offset_of!(Hello, protocol_version) == 0 && offset_of!(Hello, axes) == 4);
    assert!(offset_of!(Hello, units) == 8 && offset_of!(Hello, session) == 12);
    assert!(offset_of!(Hello, token) == 16 && offset_of!(Hello, rate_hz) == 24);
    assert!(offset_of!(Hello, period_s) == 32 && offset_of!(Hello, run_id) == 40);
    assert!(offset_of!(Hello, law) == 72 && offset_of!(Hello, stiffness_n_per_m) == 104);
    assert!(offset_of!(Hello, damping_ratio) == 112 && offset_of!(Hello, ki_n_per_a) == 120);
    assert!(offset_of!(Hello, ks_n_per_m) == 128 && offset_of!(Hello, amp_gain_a_per_v) == 136);
    assert!(offset_of!(Hello, sensor_gain_v_per_m) == 144 && offset_of!(Hello, rotor_mass_kg) == 152);
    assert!(offset_of!(Hello, gravity_m_s2) == 160 && offset_of!(Hello, current_limit_a) == 168);
    assert!(offset_of!(Hello, air_gap_m) == 176 && offset_of!(Hello, delay_samples) == 184);
    assert!(offset_of!(Hello, gravity_bias) == 188 && offset_of!(Hello, spin_ns) == 192);
    assert!(offset_of!(Hello, mode) == 200 && offset_of!(Hello, plant_pid) == 204);
    assert!(offset_of!(Hello, params_len) == 208 && offset_of!(Hello, reserved) == 212);
    assert!(offset_of!(Hello, params) == 216);
    assert!(offset_of!(Hello, b_stiffness_n_per_m) == 4312 && offset_of!(Hello, b_damping_ratio) == 4320);
    assert!(offset_of!(Hello, b_ki_n_per_a) == 4328 && offset_of!(Hello, b_ks_n_per_m) == 4336);
    assert!(offset_of!(Hello, b_amp_gain_a_per_v) == 4344 && offset_of!(Hello, b_sensor_gain_v_per_m) == 4352);
    assert!(offset_of!(Hello, b_rotor_mass_kg) == 4360 && offset_of!(Hello, b_current_limit_a) == 4368);
    assert!(offset_of!(Hello, b_air_gap_m) == 4376 && offset_of!(Hello, total_mass_kg) == 4384);
    assert!(offset_of!(Hello, transverse_inertia_kg_m2) == 4392 && offset_of!(Hello, polar_inertia_kg_m2) == 4400);
    assert!(offset_of!(Hello, rated_speed_rad_s) == 4408 && offset_of!(Hello, bearing_a_z_m) == 4416);
    assert!(offset_of!(Hello, bearing_b_z_m) == 4424 && offset_of!(Hello, sensor_a_z_m) == 4432);
    assert!(offset_of!(Hello, sensor_b_z_m) == 4440);
    assert!(size_of::<Ack>() == 4416 && align_of::<Ack>() == 8);
    assert!(offset_of!(Ack, protocol_version) == 0 && offset_of!(Ack, session) == 4);
    assert!(offset_of!(Ack, status) == 8 && offset_of!(Ack, controller_pid) == 12);
    assert!(offset_of!(Ack, token) == 16 && offset_of!(Ack, law) == 24);
    assert!(offset_of!(Ack, message) == 56 && offset_of!(Ack, overrides_len) == 312);
    assert!(offset_of!(Ack, reserved) == 316 && offset_of!(Ack, overrides) == 320);
};

/// Writes `text` into a NUL-padded fixed field, cut at a character boundary
/// if too long.
///
/// ```
/// let f: [u8; 4] = controller::wire::fixed_str("pd");
/// assert_eq!(&f, b"pd\0\0");
/// assert_eq!(controller::wire::str_of(&f), "pd");
/// ```
pub fn fixed_str<const N: usize>(text: &str) -> [u8; N] {
    let mut out = [0u8; N];
    let mut end = text.len().min(N);
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    out[..end].copy_from_slice(&text.as_bytes()[..end]);
    out
}

/// The text of a NUL-padded fixed field (up to the first NUL; invalid UTF-8
/// is replaced).
pub fn str_of(field: &[u8]) -> std::borrow::Cow<'_, str> {
    let end = field.iter().position(|b| *b == 0).unwrap_or(field.len());
    String::from_utf8_lossy(&field[..end])
}

/// Checks a run id: 1 to [`RUN_ID_LEN`] bytes of ASCII letters, digits, `-`, `_`, `.`.
///
/// ```
/// assert!(controller::wire::valid_run_id("1234-5f").is_ok());
/// assert!(controller::wire::valid_run_id("a/b").is_err());
/// ```
pub fn valid_run_id(id: &str) -> Result<&str, String> {
    let ok = !id.is_empty()
        && id.len() <= RUN_ID_LEN
        && id.bytes().all(|b| b.is_ascii_alphanumeric() || matches!(b, b'-' | b'_' | b'.'));
    if ok {
        Ok(id)
    } else {
        Err(format!(
            "run id {id:?}: must be 1 to {RUN_ID_LEN} characters among A-Z a-z 0-9 - _ . (it names shared-memory services)"
        ))
    }
}

/// A service or node name of a run: `amb-testbed/<run_id>/<what>`.
pub fn name(run_id: &str, what: &str) -> String {
    format!("{SERVICE_PREFIX}/{run_id}/{what}")
}

/// What a controller is configured for, to check a [`Hello`] against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Expect<'a> {
    /// The run id it was started with.
    pub run_id: &'a str,
    /// The rate it is configured for (Hz), if any; `None` accepts the plant's.
    pub rate_hz: Option<f64>,
}

/// The axis counts a hello may carry: planar and two-plane.
pub const SUPPORTED_AXES: [u32; 2] = [AXES, TWO_PLANE_AXES];

/// Checks a [`Hello`] against this controller: protocol version, axes (2 or 4),
/// units, run id and rate. The message names both values.
///
/// ```
/// use controller::wire::{check_hello, Expect, Hello, Refusal};
/// let mut h = Hello::example("run1");
/// assert!(check_hello(&h, &Expect { run_id: "run1", rate_hz: Some(20_000.0) }).is_ok());
/// h.rate_hz = 10_000.0;
/// let (why, msg) = check_hello(&h, &Expect { run_id: "run1", rate_hz: Some(20_000.0) }).unwrap_err();
/// assert_eq!(why, Refusal::Rate);
/// assert!(msg.contains("10000") && msg.contains("20000"), "{msg}");
/// ```
pub fn check_hello(h: &Hello, expect: &Expect) -> Result<(), (Refusal, String)> {
    check_hello_for(h, expect, &SUPPORTED_AXES)
}

/// [`check_hello`] for a controller that drives only the axis counts `axes` (a controller
/// written for the planar model passes `&[AXES]` and so refuses a two-plane hello with
/// [`Refusal::Axes`], code 3).
///
/// ```
/// use controller::wire::{check_hello_for, Expect, Hello, Refusal, AXES};
/// let h = Hello::example_two_plane("r");
/// let (why, msg) = check_hello_for(&h, &Expect { run_id: "r", rate_hz: None }, &[AXES]).unwrap_err();
/// assert_eq!((why, why.code()), (Refusal::Axes, 3));
/// assert_eq!(msg, "the plant has 4 axes, this controller drives 2");
/// ```
pub fn check_hello_for(h: &Hello, expect: &Expect, axes: &[u32]) -> Result<(), (Refusal, String)> {
    if h.protocol_version != PROTOCOL_VERSION {
        return Err((
            Refusal::Version,
            format!(
                "protocol version {} from the plant, this controller speaks {PROTOCOL_VERSION}",
                h.protocol_version
            ),
        ));
    }
    if !axes.contains(&h.axes) {
        let drives: Vec<String> = axes.iter().map(u32::to_string).collect();
        return Err((
            Refusal::Axes,
            format!("the plant has {} axes, this controller drives {}", h.axes, drives.join(" or ")),
        ));
    }
    if h.units != UNITS_SI {
        return Err((
            Refusal::Units,
            format!("units code {} from the plant, this controller uses {UNITS_SI} (SI)", h.units),
        ));
    }
    let id = str_of(&h.run_id);
    if id != expect.run_id {
        return Err((Refusal::RunId, format!("hello for run id {id:?}, this controller serves {:?}", expect.run_id)));
    }
    if let Some(rate) = expect.rate_hz {
        if !(h.rate_hz.is_finite() && (h.rate_hz - rate).abs() <= 1e-9 * rate) {
            return Err((
                Refusal::Rate,
                format!(
                    "the plant runs at controller.rate_hz = {} Hz, this controller is configured for {rate} Hz",
                    h.rate_hz
                ),
            ));
        }
    }
    Ok(())
}

impl Hello {
    /// The hello of a planar run: law `law` built from `design` at `rate_hz`, with the law's
    /// parameter document `params` (TOML text, at most [`PARAMS_LEN`] bytes). Session 0 (the
    /// plant counts handshakes from 1), token 0 (the plant sets the run's), lockstep, no spin,
    /// this process as the plant.
    pub fn new(run_id: &str, law: &str, design: &Design, rate_hz: f64, params: &str) -> Result<Self, ParamsError> {
        Self::for_rotor(run_id, law, &RotorDesign::Planar(*design), rate_hz, params)
    }

    /// [`Hello::new`] for any rotor: a planar design gives `axes` = 2 and zeros past
    /// `params`; a two-plane design `axes` = 4, plane B's design in the `b_` fields and the
    /// geometry. The planes' shared fields (period, delay, gravity bias, gravity) are plane
    /// A's ([`RotorDesign::check`]).
    pub fn for_rotor(
        run_id: &str,
        law: &str,
        design: &RotorDesign,
        rate_hz: f64,
        params: &str,
    ) -> Result<Self, ParamsError> {
        if params.len() > PARAMS_LEN {
            return Err(ParamsError::TooLong { len: params.len() });
        }
        let a = design.plane_a();
        let c = &a.constants;
        let mut hello = Hello {
            protocol_version: PROTOCOL_VERSION,
            axes: design.axes(),
            units: UNITS_SI,
            session: 0,
            token: 0,
            rate_hz,
            period_s: a.period_s,
            run_id: fixed_str(run_id),
            law: fixed_str(law),
            stiffness_n_per_m: a.stiffness_n_per_m,
            damping_ratio: a.damping_ratio,
            ki_n_per_a: c.ki_n_per_a,
            ks_n_per_m: c.ks_n_per_m,
            amp_gain_a_per_v: c.amp_gain_a_per_v,
            sensor_gain_v_per_m: c.sensor_gain_v_per_m,
            rotor_mass_kg: c.rotor_mass_kg,
            gravity_m_s2: c.gravity_m_s2,
            current_limit_a: a.current_limit_a,
            air_gap_m: c.air_gap_m,
            delay_samples: a.delay_samples,
            gravity_bias: u32::from(a.gravity_bias),
            spin_ns: 0,
            mode: mode::LOCKSTEP,
            plant_pid: std::process::id(),
            params_len: params.len() as u32,
            reserved: 0,
            params: [0; PARAMS_LEN],
            b_stiffness_n_per_m: 0.0,
            b_damping_ratio: 0.0,
            b_ki_n_per_a: 0.0,
            b_ks_n_per_m: 0.0,
            b_amp_gain_a_per_v: 0.0,
            b_sensor_gain_v_per_m: 0.0,
            b_rotor_mass_kg: 0.0,
            b_current_limit_a: 0.0,
            b_air_gap_m: 0.0,
            total_mass_kg: 0.0,
            transverse_inertia_kg_m2: 0.0,
            polar_inertia_kg_m2: 0.0,
            rated_speed_rad_s: 0.0,
            bearing_a_z_m: 0.0,
            bearing_b_z_m: 0.0,
            sensor_a_z_m: 0.0,
            sensor_b_z_m: 0.0,
        };
        hello.params[..params.len()].copy_from_slice(params.as_bytes());
        if let RotorDesign::TwoPlane { planes: [_, b], geometry: g } = design {
            let c = &b.constants;
            hello.b_stiffness_n_per_m = b.stiffness_n_per_m;
            hello.b_damping_ratio = b.damping_ratio;
            hello.b_ki_n_per_a = c.ki_n_per_a;
            hello.b_ks_n_per_m = c.ks_n_per_m;
            hello.b_amp_gain_a_per_v = c.amp_gain_a_per_v;
            hello.b_sensor_gain_v_per_m = c.sensor_gain_v_per_m;
            hello.b_rotor_mass_kg = c.rotor_mass_kg;
            hello.b_current_limit_a = b.current_limit_a;
            hello.b_air_gap_m = c.air_gap_m;
            hello.total_mass_kg = g.mass_kg;
            hello.transverse_inertia_kg_m2 = g.transverse_inertia_kg_m2;
            hello.polar_inertia_kg_m2 = g.polar_inertia_kg_m2;
            hello.rated_speed_rad_s = g.rated_speed_rad_s;
            [hello.bearing_a_z_m, hello.bearing_b_z_m] = g.bearing_z_m;
            [hello.sensor_a_z_m, hello.sensor_b_z_m] = g.sensor_z_m;
        }
        Ok(hello)
    }

    /// A planar hello with the study's design ([`Design::study`], law `pd`, 20 kHz; for
    /// examples and tests).
    ///
    /// ```
    /// let h = controller::wire::Hello::example("run1");
    /// assert_eq!((h.axes, h.design().stiffness_n_per_m), (2, 1e6));
    /// assert_eq!(h.params_text().unwrap(), "");
    /// ```
    pub fn example(run_id: &str) -> Self {
        Self::example_of(run_id, &RotorDesign::Planar(Design::study()))
    }

    /// A two-plane hello of the study's symmetric machine ([`RotorDesign::symmetric_study`],
    /// law `pd`, 20 kHz; for examples and tests).
    ///
    /// ```
    /// let h = controller::wire::Hello::example_two_plane("run1");
    /// assert_eq!((h.axes, h.total_mass_kg, h.b_rotor_mass_kg), (4, 23.0, 11.5));
    /// assert_eq!(h.rotor_design(), Some(controller::RotorDesign::symmetric_study()));
    /// ```
    pub fn example_two_plane(run_id: &str) -> Self {
        Self::example_of(run_id, &RotorDesign::symmetric_study())
    }

    fn example_of(run_id: &str, design: &RotorDesign) -> Self {
        let mut h = Self::for_rotor(run_id, "pd", design, 20_000.0, "").expect("an empty document fits");
        h.session = 1;
        h.token = 1;
        h.spin_ns = 200_000;
        h.plant_pid = 0;
        h
    }

    /// Plane A's loop design (the planar design of a planar hello; the inverse of
    /// [`Hello::new`]).
    pub fn design(&self) -> Design {
        Design {
            stiffness_n_per_m: self.stiffness_n_per_m,
            damping_ratio: self.damping_ratio,
            period_s: self.period_s,
            gravity_bias: self.gravity_bias != 0,
            current_limit_a: self.current_limit_a,
            delay_samples: self.delay_samples,
            constants: LoopConstants {
                ki_n_per_a: self.ki_n_per_a,
                ks_n_per_m: self.ks_n_per_m,
                amp_gain_a_per_v: self.amp_gain_a_per_v,
                sensor_gain_v_per_m: self.sensor_gain_v_per_m,
                rotor_mass_kg: self.rotor_mass_kg,
                gravity_m_s2: self.gravity_m_s2,
                air_gap_m: self.air_gap_m,
            },
        }
    }

    /// The whole rotor's design the hello carries (the inverse of [`Hello::for_rotor`]);
    /// `None` for an axis count other than 2 and 4.
    pub fn rotor_design(&self) -> Option<RotorDesign> {
        let a = self.design();
        match self.axes {
            AXES => Some(RotorDesign::Planar(a)),
            TWO_PLANE_AXES => {
                let b = Design {
                    stiffness_n_per_m: self.b_stiffness_n_per_m,
                    damping_ratio: self.b_damping_ratio,
                    current_limit_a: self.b_current_limit_a,
                    constants: LoopConstants {
                        ki_n_per_a: self.b_ki_n_per_a,
                        ks_n_per_m: self.b_ks_n_per_m,
                        amp_gain_a_per_v: self.b_amp_gain_a_per_v,
                        sensor_gain_v_per_m: self.b_sensor_gain_v_per_m,
                        rotor_mass_kg: self.b_rotor_mass_kg,
                        air_gap_m: self.b_air_gap_m,
                        ..a.constants
                    },
                    ..a
                };
                let geometry = Geometry {
                    mass_kg: self.total_mass_kg,
                    transverse_inertia_kg_m2: self.transverse_inertia_kg_m2,
                    polar_inertia_kg_m2: self.polar_inertia_kg_m2,
                    rated_speed_rad_s: self.rated_speed_rad_s,
                    bearing_z_m: [self.bearing_a_z_m, self.bearing_b_z_m],
                    sensor_z_m: [self.sensor_a_z_m, self.sensor_b_z_m],
                };
                Some(RotorDesign::TwoPlane { planes: [a, b], geometry })
            }
            _ => None,
        }
    }

    /// The law's parameter document (TOML text).
    pub fn params_text(&self) -> Result<&str, ParamsError> {
        let len = self.params_len as usize;
        if len > PARAMS_LEN {
            return Err(ParamsError::TooLong { len });
        }
        std::str::from_utf8(&self.params[..len]).map_err(|e| ParamsError::Syntax(format!("not UTF-8: {e}")))
    }
}

impl Ack {
    /// An acceptance (`status` 0) or refusal (a [`Refusal`] code) of the hello of `session`
    /// with token `token`, without overrides.
    pub fn new(session: u32, token: u64, status: u32, law: &str, message: &str) -> Self {
        Ack {
            protocol_version: PROTOCOL_VERSION,
            session,
            status,
            controller_pid: std::process::id(),
            token,
            law: fixed_str(law),
            message: fixed_str(message),
            overrides_len: 0,
            reserved: 0,
            overrides: [0; OVERRIDES_LEN],
        }
    }

    /// The same with an overrides document (TOML text); `Err(len)` if it is longer than
    /// [`OVERRIDES_LEN`].
    pub fn with_overrides(mut self, text: &str) -> Result<Self, usize> {
        if text.len() > OVERRIDES_LEN {
            return Err(text.len());
        }
        self.overrides = [0; OVERRIDES_LEN];
        self.overrides[..text.len()].copy_from_slice(text.as_bytes());
        self.overrides_len = text.len() as u32;
        Ok(self)
    }

    /// The overrides document (TOML text; empty if none).
    pub fn overrides_text(&self) -> Result<&str, String> {
        let len = self.overrides_len as usize;
        if len > OVERRIDES_LEN {
            return Err(format!("overrides_len = {len} bytes: the field holds {OVERRIDES_LEN}"));
        }
        std::str::from_utf8(&self.overrides[..len]).map_err(|e| format!("overrides are not UTF-8: {e}"))
    }
}

/// One field of a message as it lies in memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FieldLayout {
    /// The field's name (the same in Rust, C and Python).
    pub name: &'static str,
    /// Offset from the message's start (bytes).
    pub offset: usize,
    /// Size (bytes).
    pub size: usize,
}

/// A message's layout: what a port must reproduce.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MessageLayout {
    /// The struct's name (`SensorFrame`, …; `amb_testbed_<name>` in C).
    pub name: &'static str,
    /// Its iceoryx2 type name.
    pub type_name: &'static str,
    /// Size (bytes).
    pub size: usize,
    /// Alignment (bytes).
    pub align: usize,
    /// Every field, in order.
    pub fields: Vec<FieldLayout>,
}

/// The size of a field, through an accessor (no value needed).
fn field_size<T, F>(_: fn(&T) -> &F) -> usize {
    core::mem::size_of::<F>()
}

macro_rules! message_layout {
    ($t:ident; $($f:ident),+ $(,)?) => {
        MessageLayout {
            name: stringify!($t),
            // SAFETY: type_name has no preconditions; it is unsafe only because implementors
            // promise uniqueness.
            type_name: unsafe { <$t as ZeroCopySend>::type_name() },
            size: core::mem::size_of::<$t>(),
            align: core::mem::align_of::<$t>(),
            fields: vec![$(FieldLayout {
                name: stringify!($f),
                offset: core::mem::offset_of!($t, $f),
                size: field_size::<$t, _>(|m| &m.$f),
            }),+],
        }
    };
}

/// The layout of every message, from the Rust definitions: the one source the C header, the
/// Python kit and `docs/wire-protocol.md` are checked against (the tests fail naming the
/// difference). A unit test checks that the fields listed here tile each struct exactly, so a
/// field added to a struct and not here fails too.
pub fn layouts() -> Vec<MessageLayout> {
    vec![
        message_layout!(SensorFrame; seq, t_s, token, sent_ns, status, session, axes, reserved, sensor_v,
            speed_rad_s, angle_rad),
        message_layout!(CommandFrame; seq, token, received_ns, sent_ns, status, session, axes, reserved, current_a),
        message_layout!(WakeRequest; seq),
        message_layout!(Hello; protocol_version, axes, units, session, token, rate_hz, period_s, run_id, law,
            stiffness_n_per_m, damping_ratio, ki_n_per_a, ks_n_per_m, amp_gain_a_per_v, sensor_gain_v_per_m,
            rotor_mass_kg, gravity_m_s2, current_limit_a, air_gap_m, delay_samples, gravity_bias, spin_ns, mode,
            plant_pid, params_len, reserved, params, b_stiffness_n_per_m, b_damping_ratio, b_ki_n_per_a,
            b_ks_n_per_m, b_amp_gain_a_per_v, b_sensor_gain_v_per_m, b_rotor_mass_kg, b_current_limit_a,
            b_air_gap_m, total_mass_kg, transverse_inertia_kg_m2, polar_inertia_kg_m2, rated_speed_rad_s,
            bearing_a_z_m, bearing_b_z_m, sensor_a_z_m, sensor_b_z_m),
        message_layout!(Ack; protocol_version, session, status, controller_pid, token, law, message,
            overrides_len, reserved, overrides),
    ]
}

/// A constant of the protocol.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Constant {
    /// An integer.
    Number(u64),
    /// A text (a name or prefix).
    Text(&'static str),
}

/// Every constant of the protocol by its name in the C header (`AMB_TESTBED_<name>`) and in
/// the Python kit's `wire.CONSTANTS`: the one source both are checked against.
pub fn constants() -> Vec<(String, Constant)> {
    use Constant::{Number, Text};
    let mut out: Vec<(String, Constant)> = vec![
        ("PROTOCOL_VERSION".into(), Number(PROTOCOL_VERSION.into())),
        ("MAX_AXES".into(), Number(MAX_AXES as u64)),
        ("AXES".into(), Number(AXES.into())),
        ("TWO_PLANE_AXES".into(), Number(TWO_PLANE_AXES.into())),
        ("UNITS_SI".into(), Number(UNITS_SI.into())),
        ("RUN_ID_LEN".into(), Number(RUN_ID_LEN as u64)),
        ("LAW_NAME_LEN".into(), Number(LAW_NAME_LEN as u64)),
        ("MESSAGE_LEN".into(), Number(MESSAGE_LEN as u64)),
        ("PARAMS_LEN".into(), Number(PARAMS_LEN as u64)),
        ("OVERRIDES_LEN".into(), Number(OVERRIDES_LEN as u64)),
        ("SERVICE_PREFIX".into(), Text(SERVICE_PREFIX)),
        ("SENSOR_STOP".into(), Number(SensorFrame::STOP.into())),
        ("COMMAND_STOPPING".into(), Number(CommandFrame::STOPPING.into())),
        ("MODE_LOCKSTEP".into(), Number(mode::LOCKSTEP.into())),
        ("MODE_REALTIME".into(), Number(mode::REALTIME.into())),
        ("MODE_BENCH".into(), Number(mode::BENCH.into())),
        ("ACK_ACCEPTED".into(), Number(0)),
    ];
    for r in Refusal::ALL {
        out.push((format!("ACK_{}", r.constant_name()), Number(r.code().into())));
    }
    for m in layouts() {
        // SensorFrame -> SENSOR_FRAME_TYPE_NAME
        let mut upper = String::new();
        for (i, c) in m.name.chars().enumerate() {
            if c.is_uppercase() && i > 0 {
                upper.push('_');
            }
            upper.push(c.to_ascii_uppercase());
        }
        out.push((format!("{upper}_TYPE_NAME"), Text(m.type_name)));
    }
    out
}

/// `CLOCK_MONOTONIC` now (ns): the clock both processes stamp frames with.
#[inline]
pub fn monotonic_ns() -> u64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec; CLOCK_MONOTONIC always exists on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

#[cfg(test)]
mod tests {
    use super::*;
    use iceoryx2::prelude::ZeroCopySend;

    #[test]
    fn type_names_carry_the_protocol_version() {
        let tag = format!(".v{PROTOCOL_VERSION}.");
        // SAFETY: type_name has no preconditions; it is unsafe only because implementors promise uniqueness.
        let names = unsafe {
            [
                SensorFrame::type_name(),
                CommandFrame::type_name(),
                WakeRequest::type_name(),
                Hello::type_name(),
                Ack::type_name(),
            ]
        };
        for n in names {
            assert!(n.contains(&tag), "{n} lacks {tag}");
        }
    }

    /// The fields [`layouts`] lists tile each struct from byte 0 to its size, in order, with no
    /// gap: a field added to a struct and not to the list (or a padding byte) fails here.
    #[test]
    fn the_layout_list_covers_every_byte_of_every_message() {
        for m in layouts() {
            let mut at = 0;
            for f in &m.fields {
                assert_eq!(
                    f.offset, at,
                    "{}.{} at {} (expected {at}: a field is missing or padded)",
                    m.name, f.name, f.offset
                );
                at += f.size;
            }
            assert_eq!(at, m.size, "{}: the listed fields end at {at}, the struct is {} bytes", m.name, m.size);
            assert_eq!(m.align, 8, "{}", m.name);
        }
        let sizes: Vec<(&str, usize)> = layouts().iter().map(|m| (m.name, m.size)).collect();
        assert_eq!(
            sizes,
            [("SensorFrame", 128), ("CommandFrame", 112), ("WakeRequest", 8), ("Hello", 4448), ("Ack", 4416)]
        );
        let names: Vec<String> = constants().into_iter().map(|(n, _)| n).collect();
        assert!(names.contains(&"ACK_PARAMS".to_string()) && names.contains(&"HELLO_TYPE_NAME".to_string()));
        assert!(
            constants().contains(&("SENSOR_FRAME_TYPE_NAME".to_string(), Constant::Text("amb_testbed.v4.SensorFrame")))
        );
    }

    /// A two-plane design goes through the hello and back whole; a planar hello's v4 fields
    /// are 0.
    #[test]
    fn a_two_plane_design_travels_in_the_hello() {
        let RotorDesign::TwoPlane { planes: [a, _], geometry } = RotorDesign::symmetric_study() else { unreachable!() };
        let b = Design {
            stiffness_n_per_m: 1.3e6,
            damping_ratio: 0.02,
            current_limit_a: 3.0,
            constants: LoopConstants {
                ki_n_per_a: 190.0,
                ks_n_per_m: 3e5,
                amp_gain_a_per_v: 0.5,
                sensor_gain_v_per_m: 2e4,
                rotor_mass_kg: 9.5,
                air_gap_m: 1.2e-4,
                ..a.constants
            },
            ..a
        };
        let g = Geometry { bearing_z_m: [-0.2, 0.16], sensor_z_m: [-0.22, 0.19], ..geometry };
        let design = RotorDesign::TwoPlane { planes: [a, b], geometry: g };
        let h = Hello::for_rotor("r", "modal", &design, 20_000.0, "").unwrap();
        assert_eq!(h.axes, 4);
        assert_eq!(h.rotor_design(), Some(design));
        assert_eq!(h.design(), a);
        let planar = Hello::example("r");
        assert_eq!(planar.rotor_design(), Some(RotorDesign::Planar(planar.design())));
        let bytes = unsafe { std::slice::from_raw_parts((&planar as *const Hello).cast::<u8>(), size_of::<Hello>()) };
        assert!(bytes[4312..].iter().all(|b| *b == 0), "a planar hello's v4 fields are 0");
        let mut odd = planar;
        odd.axes = 3;
        assert_eq!(odd.rotor_design(), None);
    }

    #[test]
    fn each_mismatch_is_refused_with_its_code() {
        let ok = Expect { run_id: "r", rate_hz: None };
        let base = Hello::example("r");
        assert!(check_hello(&base, &ok).is_ok());
        type Spoil = fn(&mut Hello);
        assert!(check_hello(&Hello::example_two_plane("r"), &ok).is_ok(), "this controller drives 4 axes too");
        let cases: [(Spoil, Refusal); 5] = [
            (|h| h.protocol_version += 1, Refusal::Version),
            (|h| h.axes = 3, Refusal::Axes),
            (|h| h.axes = 8, Refusal::Axes),
            (|h| h.units = 7, Refusal::Units),
            (|h| h.run_id = fixed_str("other"), Refusal::RunId),
        ];
        for (spoil, code) in cases {
            let mut h = base;
            spoil(&mut h);
            assert_eq!(check_hello(&h, &ok).unwrap_err().0, code);
        }
    }

    /// The layout seen through the bytes: each field written, then read back at the offset
    /// of the protocol table (docs/wire-protocol.md), independently of `offset_of!`.
    #[test]
    fn fields_sit_at_the_documented_offsets() {
        fn bytes<T: Copy>(v: &T) -> Vec<u8> {
            // SAFETY: T is a plain #[repr(C)] struct of integers, floats and byte arrays with
            // no padding (checked by the size assertions), so all its bytes are initialised.
            unsafe { std::slice::from_raw_parts((v as *const T).cast::<u8>(), std::mem::size_of::<T>()).to_vec() }
        }
        let u64_at = |b: &[u8], off: usize| u64::from_ne_bytes(b[off..off + 8].try_into().unwrap());
        let u32_at = |b: &[u8], off: usize| u32::from_ne_bytes(b[off..off + 4].try_into().unwrap());
        let f64_at = |b: &[u8], off: usize| f64::from_ne_bytes(b[off..off + 8].try_into().unwrap());

        let mut sensor = [0.0; MAX_AXES];
        sensor[0] = 1.5;
        sensor[1] = -2.5;
        let s = SensorFrame {
            seq: 7,
            t_s: 0.25,
            token: 0xA1,
            sent_ns: 9,
            status: 1,
            session: 3,
            axes: 2,
            reserved: 0,
            sensor_v: sensor,
            speed_rad_s: 3141.5,
            angle_rad: 6.25,
        };
        let b = bytes(&s);
        assert_eq!(b.len(), 128);
        assert_eq!((u64_at(&b, 0), f64_at(&b, 8), u64_at(&b, 16), u64_at(&b, 24)), (7, 0.25, 0xA1, 9));
        assert_eq!((u32_at(&b, 32), u32_at(&b, 36), u32_at(&b, 40), u32_at(&b, 44)), (1, 3, 2, 0));
        assert_eq!((f64_at(&b, 48), f64_at(&b, 56), f64_at(&b, 104)), (1.5, -2.5, 0.0));
        assert_eq!((f64_at(&b, 112), f64_at(&b, 120)), (3141.5, 6.25));

        let c = CommandFrame {
            seq: 7,
            token: 0xB2,
            received_ns: 5,
            sent_ns: 6,
            status: 1,
            session: 4,
            axes: 2,
            reserved: 0,
            current_a: sensor,
        };
        let b = bytes(&c);
        assert_eq!(b.len(), 112);
        assert_eq!((u64_at(&b, 0), u64_at(&b, 8), u64_at(&b, 16), u64_at(&b, 24)), (7, 0xB2, 5, 6));
        assert_eq!((u32_at(&b, 32), u32_at(&b, 36), u32_at(&b, 40)), (1, 4, 2));
        assert_eq!((f64_at(&b, 48), f64_at(&b, 56)), (1.5, -2.5));

        let mut h = Hello::new("run-7", "relev", &Hello::example("x").design(), 20_000.0, "arm_ms = 5.0\n").unwrap();
        h.token = 0xC3;
        h.session = 2;
        h.spin_ns = 11;
        h.mode = mode::REALTIME;
        h.plant_pid = 42;
        let b = bytes(&h);
        assert_eq!(b.len(), 4448);
        assert_eq!((u32_at(&b, 0), u32_at(&b, 4), u32_at(&b, 8), u32_at(&b, 12)), (4, 2, 1, 2));
        assert_eq!((u64_at(&b, 16), f64_at(&b, 24), f64_at(&b, 32)), (0xC3, 20_000.0, 5e-5));
        assert_eq!((&b[40..45], b[45], &b[72..77]), (&b"run-7"[..], 0, &b"relev"[..]));
        let doubles = [1e6, 0.01, 216.0, 4.32e5, 1.0, 25_000.0, 11.5, 9.80665, 2.0, 150e-6];
        for (i, v) in doubles.iter().enumerate() {
            assert_eq!(f64_at(&b, 104 + 8 * i), *v, "f64 #{i} at {}", 104 + 8 * i);
        }
        assert_eq!((u32_at(&b, 184), u32_at(&b, 188), u64_at(&b, 192)), (1, 1, 11));
        assert_eq!((u32_at(&b, 200), u32_at(&b, 204), u32_at(&b, 208), u32_at(&b, 212)), (2, 42, 13, 0));
        assert_eq!(&b[216..229], b"arm_ms = 5.0\n");
        let RotorDesign::TwoPlane { planes: [a, _], geometry } = RotorDesign::symmetric_study() else { unreachable!() };
        let mut plane_b = a;
        plane_b.stiffness_n_per_m = 2e6;
        plane_b.damping_ratio = 0.03;
        plane_b.current_limit_a = 2.5;
        plane_b.constants = LoopConstants {
            ki_n_per_a: 200.0,
            ks_n_per_m: 4e5,
            amp_gain_a_per_v: 0.75,
            sensor_gain_v_per_m: 2e4,
            rotor_mass_kg: 12.5,
            air_gap_m: 1.4e-4,
            ..a.constants
        };
        let g = Geometry {
            mass_kg: 24.0,
            transverse_inertia_kg_m2: 0.5,
            polar_inertia_kg_m2: 0.012,
            rated_speed_rad_s: 3000.0,
            bearing_z_m: [-0.18, 0.2],
            sensor_z_m: [-0.19, 0.21],
        };
        let _ = geometry;
        let h = Hello::for_rotor("r", "pd", &RotorDesign::TwoPlane { planes: [a, plane_b], geometry: g }, 20_000.0, "")
            .unwrap();
        let b = bytes(&h);
        assert_eq!(u32_at(&b, 4), 4);
        let tail =
            [2e6, 0.03, 200.0, 4e5, 0.75, 2e4, 12.5, 2.5, 1.4e-4, 24.0, 0.5, 0.012, 3000.0, -0.18, 0.2, -0.19, 0.21];
        for (i, v) in tail.iter().enumerate() {
            assert_eq!(f64_at(&b, 4312 + 8 * i), *v, "f64 #{i} at {}", 4312 + 8 * i);
        }

        let a = Ack::new(2, 0xD4, 7, "relev", "why").with_overrides("[controller]\n").unwrap();
        let b = bytes(&a);
        assert_eq!(b.len(), 4416);
        assert_eq!((u32_at(&b, 0), u32_at(&b, 4), u32_at(&b, 8)), (4, 2, 7));
        assert_eq!((u64_at(&b, 16), &b[24..29], &b[56..59]), (0xD4, &b"relev"[..], &b"why"[..]));
        assert_eq!((u32_at(&b, 312), u32_at(&b, 316), &b[320..333]), (13, 0, &b"[controller]\n"[..]));
    }

    #[test]
    fn hello_carries_the_design_and_the_params_both_ways() {
        let design = Hello::example("r").design();
        let h = Hello::new("r", "relev", &design, 20_000.0, "enter_um = 100.0\n").unwrap();
        assert_eq!(h.design(), design);
        assert_eq!(h.params_text().unwrap(), "enter_um = 100.0\n");
        let long = "x".repeat(PARAMS_LEN + 1);
        assert!(matches!(Hello::new("r", "pd", &design, 20_000.0, &long), Err(ParamsError::TooLong { .. })));
        let mut bad = h;
        bad.params_len = PARAMS_LEN as u32 + 1;
        assert!(bad.params_text().is_err());
    }

    #[test]
    fn fixed_str_cuts_at_a_char_boundary() {
        let f: [u8; 3] = fixed_str("aéb");
        assert_eq!(str_of(&f), "aé");
        let f: [u8; 2] = fixed_str("aé");
        assert_eq!(str_of(&f), "a");
    }
}
