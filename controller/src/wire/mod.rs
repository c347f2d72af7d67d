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

mod frames;
mod hello;
mod layout;

pub use frames::*;
pub use hello::*;
pub use layout::*;

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
