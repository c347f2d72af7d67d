//! The wire's layout as data: every message's fields with their offsets and sizes, and the
//! constants, for the C header, the Python kit and docs/wire-protocol.md to be checked against;
//! and the compile-time checks of the offsets.

use super::*;

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
pub(crate) fn field_size<T, F>(_: fn(&T) -> &F) -> usize {
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
