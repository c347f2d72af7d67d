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
//!    controller answers with an [`Ack`] of the same `session`. The controller
//!    checks the protocol version, the rate, the number of axes and the
//!    units ([`check_hello`]) and builds its law; on any mismatch it answers
//!    with a non-zero [`Ack::status`] (a [`Refusal`] code) and a message, and
//!    exits; the plant prints the message and stops.
//! 2. For each tick `k` the plant publishes a [`SensorFrame`] with `seq = k`;
//!    the controller runs its law on it and publishes a [`CommandFrame`] with
//!    the same `seq`. In `lockstep` the plant waits for it; in `realtime` the
//!    plant paces the wall clock and a reply missing at the next tick is a
//!    deadline miss.
//! 3. A [`SensorFrame`] with [`SensorFrame::STOP`] ends the run (the
//!    controller exits 0); a [`CommandFrame`] with [`CommandFrame::STOPPING`]
//!    tells the plant that the controller was asked to stop (SIGINT/SIGTERM).
//!
//! # Waking a blocked peer
//!
//! Each side busy-polls its subscriber for a short budget (`Hello::spin_ns`),
//! then blocks on its event listener. To avoid a system call per message, a
//! sender notifies only a peer that asked for it: before blocking, the
//! receiver publishes a [`WakeRequest`], issues a sequentially-consistent
//! fence and polls once more; the sender, after publishing a frame, issues
//! the same fence and notifies if it finds a wake request. One of the two
//! always sees the other (Dekker), so no wake-up is lost. A controller that
//! never blocks may ignore the wake services; one that blocks must publish a
//! wake request first (or wake up on its own at least every millisecond).

use iceoryx2::prelude::ZeroCopySend;

/// Protocol version. Incremented on any change of a layout or of the meaning
/// of a field; it is also part of every iceoryx2 type name below, so peers of
/// different versions cannot even open each other's services.
pub const PROTOCOL_VERSION: u32 = 2;

/// Number of controlled axes (x, y).
pub const AXES: u32 = 2;

/// Units code: sensor in volts, currents in amperes, time in seconds, all
/// other quantities SI.
pub const UNITS_SI: u32 = 1;

/// Longest run id (bytes).
pub const RUN_ID_LEN: usize = 32;

/// Length of a law name field (bytes, UTF-8, NUL-padded).
pub const LAW_NAME_LEN: usize = 32;

/// Length of an [`Ack`] message (bytes, UTF-8, NUL-padded).
pub const MESSAGE_LEN: usize = 128;

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

/// One sample of the sensors, plant → controller. 48 bytes.
///
/// | offset | size | field      | type      |
/// |-------:|-----:|------------|-----------|
/// | 0      | 8    | `seq`      | u64       |
/// | 8      | 8    | `t_s`      | f64       |
/// | 16     | 16   | `sensor_v` | [f64; 2]  |
/// | 32     | 8    | `sent_ns`  | u64       |
/// | 40     | 4    | `status`   | u32       |
/// | 44     | 4    | `session`  | u32       |
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[type_name("amb_testbed.v2.SensorFrame")]
#[repr(C)]
pub struct SensorFrame {
    /// Tick index k (0, 1, 2, …).
    pub seq: u64,
    /// Simulated time of the sample, `k T` (s).
    pub t_s: f64,
    /// Sensor voltages `A_s·Δ` (V), x then y.
    pub sensor_v: [f64; 2],
    /// `CLOCK_MONOTONIC` of the plant when it published the frame (ns).
    pub sent_ns: u64,
    /// Bit flags: [`SensorFrame::STOP`].
    pub status: u32,
    /// Session of the handshake this frame belongs to ([`Hello::session`]).
    pub session: u32,
}

impl SensorFrame {
    /// The run is over: the controller exits with code 0. `seq` and the
    /// values carry no sample.
    pub const STOP: u32 = 1;
}

/// The answer to one sample, controller → plant. 48 bytes.
///
/// | offset | size | field         | type     |
/// |-------:|-----:|---------------|----------|
/// | 0      | 8    | `seq`         | u64      |
/// | 8      | 16   | `current_a`   | [f64; 2] |
/// | 24     | 8    | `received_ns` | u64      |
/// | 32     | 8    | `sent_ns`     | u64      |
/// | 40     | 4    | `status`      | u32      |
/// | 44     | 4    | `session`     | u32      |
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[type_name("amb_testbed.v2.CommandFrame")]
#[repr(C)]
pub struct CommandFrame {
    /// The `seq` of the [`SensorFrame`] this answers.
    pub seq: u64,
    /// Coil currents (A), x then y, saturated at [`Hello::current_limit_a`].
    pub current_a: [f64; 2],
    /// `CLOCK_MONOTONIC` of the controller when it took the sensor frame (ns).
    pub received_ns: u64,
    /// `CLOCK_MONOTONIC` of the controller when it published this frame (ns).
    pub sent_ns: u64,
    /// 0, or [`CommandFrame::STOPPING`].
    pub status: u32,
    /// Session of the handshake ([`Hello::session`]).
    pub session: u32,
}

impl CommandFrame {
    /// The controller was asked to stop (SIGINT/SIGTERM) and is exiting;
    /// `seq` and `current_a` carry no answer.
    pub const STOPPING: u32 = 1;
}

/// Ask the peer to notify the event service of the stream it waits on,
/// because the sender is about to block. 8 bytes.
///
/// | offset | size | field  | type |
/// |-------:|-----:|--------|------|
/// | 0      | 8    | `seq`  | u64  |
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[type_name("amb_testbed.v2.WakeRequest")]
#[repr(C)]
pub struct WakeRequest {
    /// The `seq` the sender waits for (informative).
    pub seq: u64,
}

/// The plant's side of the handshake: what it runs and the law design it
/// wants. 232 bytes.
///
/// | offset | size | field                  | type     |
/// |-------:|-----:|------------------------|----------|
/// | 0      | 4    | `protocol_version`     | u32      |
/// | 4      | 4    | `axes`                 | u32      |
/// | 8      | 4    | `units`                | u32      |
/// | 12     | 4    | `session`              | u32      |
/// | 16     | 8    | `rate_hz`              | f64      |
/// | 24     | 8    | `period_s`             | f64      |
/// | 32     | 32   | `run_id`               | [u8; 32] |
/// | 64     | 32   | `law`                  | [u8; 32] |
/// | 96     | 8    | `stiffness_n_per_m`    | f64      |
/// | 104    | 8    | `damping_ratio`        | f64      |
/// | 112    | 8    | `ki_n_per_a`           | f64      |
/// | 120    | 8    | `ks_n_per_m`           | f64      |
/// | 128    | 8    | `amp_gain_a_per_v`     | f64      |
/// | 136    | 8    | `sensor_gain_v_per_m`  | f64      |
/// | 144    | 8    | `rotor_mass_kg`        | f64      |
/// | 152    | 8    | `gravity_m_s2`         | f64      |
/// | 160    | 8    | `current_limit_a`      | f64      |
/// | 168    | 4    | `delay_samples`        | u32      |
/// | 172    | 4    | `gravity_bias`         | u32      |
/// | 176    | 8    | `spin_ns`              | u64      |
/// | 184    | 4    | `mode`                 | u32      |
/// | 188    | 4    | `plant_pid`            | u32      |
/// | 192    | 8    | `relev_enter_m`        | f64      |
/// | 200    | 8    | `relev_exit_m`         | f64      |
/// | 208    | 8    | `relev_damping_ratio`  | f64      |
/// | 216    | 8    | `relev_hold_s`         | f64      |
/// | 224    | 8    | `relev_arm_s`          | f64      |
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("amb_testbed.v2.Hello")]
#[repr(C)]
pub struct Hello {
    /// [`PROTOCOL_VERSION`] of the plant.
    pub protocol_version: u32,
    /// Number of axes, [`AXES`].
    pub axes: u32,
    /// Units code, [`UNITS_SI`].
    pub units: u32,
    /// Handshake number: 1 for the first controller, +1 per reconnection.
    pub session: u32,
    /// Controller rate (Hz).
    pub rate_hz: f64,
    /// Controller period `T` (s), as the plant computed it from the rate.
    pub period_s: f64,
    /// The run id, UTF-8, NUL-padded.
    pub run_id: [u8; RUN_ID_LEN],
    /// Law name (`controller.law`), UTF-8, NUL-padded.
    pub law: [u8; LAW_NAME_LEN],
    /// Design stiffness k_e (N/m).
    pub stiffness_n_per_m: f64,
    /// Design damping ratio ξ_e.
    pub damping_ratio: f64,
    /// Force-current coefficient k_i (N/A).
    pub ki_n_per_a: f64,
    /// Force-displacement coefficient k_s (N/m).
    pub ks_n_per_m: f64,
    /// Amplifier gain A_a (A/V).
    pub amp_gain_a_per_v: f64,
    /// Sensor gain A_s (V/m).
    pub sensor_gain_v_per_m: f64,
    /// Rotor mass m_r (kg).
    pub rotor_mass_kg: f64,
    /// Gravity g (m/s²).
    pub gravity_m_s2: f64,
    /// Amplifier limit i_max (A): the controller saturates at it.
    pub current_limit_a: f64,
    /// Samples between a sample and the tick its command is applied from (informative).
    pub delay_samples: u32,
    /// 1: add the gravity bias current on y.
    pub gravity_bias: u32,
    /// How long a waiting side busy-polls before it blocks (ns).
    pub spin_ns: u64,
    /// [`mode`] code.
    pub mode: u32,
    /// Process id of the plant (informative).
    pub plant_pid: u32,
    /// `relev`: radius at which the rotor counts as touching (m).
    pub relev_enter_m: f64,
    /// `relev`: radius below which it counts as levitating again (m).
    pub relev_exit_m: f64,
    /// `relev`: damping ratio of the recovery design.
    pub relev_damping_ratio: f64,
    /// `relev`: time below the exit radius before the nominal design returns (s).
    pub relev_hold_s: f64,
    /// `relev`: time from which the switching rule acts (s).
    pub relev_arm_s: f64,
}

/// The controller's side of the handshake. 176 bytes.
///
/// | offset | size | field              | type      |
/// |-------:|-----:|--------------------|-----------|
/// | 0      | 4    | `protocol_version` | u32       |
/// | 4      | 4    | `session`          | u32       |
/// | 8      | 4    | `status`           | u32       |
/// | 12     | 4    | `controller_pid`   | u32       |
/// | 16     | 32   | `law`              | [u8; 32]  |
/// | 48     | 128  | `message`          | [u8; 128] |
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("amb_testbed.v2.Ack")]
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
    /// The law the controller runs (it may override the plant's choice).
    pub law: [u8; LAW_NAME_LEN],
    /// What the controller runs, or why it refuses; UTF-8, NUL-padded.
    pub message: [u8; MESSAGE_LEN],
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
}

impl Refusal {
    /// The code as sent.
    pub fn code(self) -> u32 {
        self as u32
    }

    /// A short name for a code (`"unknown"` for codes this version does not know).
    pub fn describe(code: u32) -> &'static str {
        match code {
            1 => "protocol version mismatch",
            2 => "rate mismatch",
            3 => "axis count mismatch",
            4 => "units mismatch",
            5 => "law rejected",
            6 => "run id mismatch",
            _ => "unknown reason",
        }
    }
}

// The layouts above are the protocol: a change must fail to compile here.
const _: () = {
    use core::mem::{align_of, offset_of, size_of};
    assert!(size_of::<SensorFrame>() == 48 && align_of::<SensorFrame>() == 8);
    assert!(offset_of!(SensorFrame, t_s) == 8 && offset_of!(SensorFrame, sensor_v) == 16);
    assert!(offset_of!(SensorFrame, sent_ns) == 32 && offset_of!(SensorFrame, status) == 40);
    assert!(offset_of!(SensorFrame, session) == 44);
    assert!(size_of::<CommandFrame>() == 48 && align_of::<CommandFrame>() == 8);
    assert!(offset_of!(CommandFrame, current_a) == 8 && offset_of!(CommandFrame, received_ns) == 24);
    assert!(offset_of!(CommandFrame, sent_ns) == 32 && offset_of!(CommandFrame, status) == 40);
    assert!(offset_of!(CommandFrame, session) == 44);
    assert!(size_of::<WakeRequest>() == 8);
    assert!(size_of::<Hello>() == 232 && align_of::<Hello>() == 8);
    assert!(offset_of!(Hello, rate_hz) == 16 && offset_of!(Hello, run_id) == 32 && offset_of!(Hello, law) == 64);
    assert!(offset_of!(Hello, stiffness_n_per_m) == 96 && offset_of!(Hello, ki_n_per_a) == 112);
    assert!(offset_of!(Hello, current_limit_a) == 160 && offset_of!(Hello, delay_samples) == 168);
    assert!(offset_of!(Hello, spin_ns) == 176 && offset_of!(Hello, mode) == 184);
    assert!(offset_of!(Hello, plant_pid) == 188);
    assert!(size_of::<Ack>() == 176 && align_of::<Ack>() == 4);
    assert!(offset_of!(Ack, law) == 16 && offset_of!(Ack, message) == 48);
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

/// Checks a [`Hello`] against this controller: protocol version, axes,
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
    if h.protocol_version != PROTOCOL_VERSION {
        return Err((
            Refusal::Version,
            format!(
                "protocol version {} from the plant, this controller speaks {PROTOCOL_VERSION}",
                h.protocol_version
            ),
        ));
    }
    if h.axes != AXES {
        return Err((Refusal::Axes, format!("the plant has {} axes, this controller drives {AXES}", h.axes)));
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
    /// A hello with the study's default constants (for examples and tests).
    pub fn example(run_id: &str) -> Self {
        Hello {
            protocol_version: PROTOCOL_VERSION,
            axes: AXES,
            units: UNITS_SI,
            session: 1,
            rate_hz: 20_000.0,
            period_s: 1.0 / 20_000.0,
            run_id: fixed_str(run_id),
            law: fixed_str("pd"),
            stiffness_n_per_m: 1e6,
            damping_ratio: 0.01,
            ki_n_per_a: 216.0,
            ks_n_per_m: 4.32e5,
            amp_gain_a_per_v: 1.0,
            sensor_gain_v_per_m: 25_000.0,
            rotor_mass_kg: 11.5,
            gravity_m_s2: 9.80665,
            current_limit_a: 2.0,
            delay_samples: 1,
            gravity_bias: 1,
            spin_ns: 200_000,
            mode: mode::LOCKSTEP,
            plant_pid: 0,
            relev_enter_m: 120e-6,
            relev_exit_m: 45e-6,
            relev_damping_ratio: 0.2,
            relev_hold_s: 0.05,
            relev_arm_s: 0.0,
        }
    }

    /// The `relev` switching rule the hello carries.
    pub fn relev(&self) -> crate::RelevSpec {
        crate::RelevSpec {
            enter_m: self.relev_enter_m,
            exit_m: self.relev_exit_m,
            damping_ratio: self.relev_damping_ratio,
            hold_s: self.relev_hold_s,
            arm_s: self.relev_arm_s,
        }
    }

    /// The plant constants the hello carries.
    pub fn loop_constants(&self) -> crate::LoopConstants {
        crate::LoopConstants {
            ki_n_per_a: self.ki_n_per_a,
            ks_n_per_m: self.ks_n_per_m,
            amp_gain_a_per_v: self.amp_gain_a_per_v,
            sensor_gain_v_per_m: self.sensor_gain_v_per_m,
            rotor_mass_kg: self.rotor_mass_kg,
            gravity_m_s2: self.gravity_m_s2,
        }
    }
}

impl Ack {
    /// An acceptance or refusal for `session`.
    pub fn new(session: u32, status: u32, law: &str, message: &str) -> Self {
        Ack {
            protocol_version: PROTOCOL_VERSION,
            session,
            status,
            controller_pid: std::process::id(),
            law: fixed_str(law),
            message: fixed_str(message),
        }
    }
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

    #[test]
    fn each_mismatch_is_refused_with_its_code() {
        let ok = Expect { run_id: "r", rate_hz: None };
        let base = Hello::example("r");
        assert!(check_hello(&base, &ok).is_ok());
        type Spoil = fn(&mut Hello);
        let cases: [(Spoil, Refusal); 4] = [
            (|h| h.protocol_version += 1, Refusal::Version),
            (|h| h.axes = 3, Refusal::Axes),
            (|h| h.units = 7, Refusal::Units),
            (|h| h.run_id = fixed_str("other"), Refusal::RunId),
        ];
        for (spoil, code) in cases {
            let mut h = base;
            spoil(&mut h);
            assert_eq!(check_hello(&h, &ok).unwrap_err().0, code);
        }
    }

    #[test]
    fn fixed_str_cuts_at_a_char_boundary() {
        let f: [u8; 3] = fixed_str("aéb");
        assert_eq!(str_of(&f), "aé");
        let f: [u8; 2] = fixed_str("aé");
        assert_eq!(str_of(&f), "a");
    }
}
