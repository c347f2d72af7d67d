//! The frames of every tick: the plant's sensor sample, the controller's command, and the
//! request that wakes a blocked peer.

use super::*;

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
