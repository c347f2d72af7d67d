"""The wire protocol, version 4, as ctypes structures.

The layouts and iceoryx2 type names are those of ``controller/src/wire/``
(the source of truth) and ``docs/wire-protocol.md``: native endianness, no
padding, ``f64`` = IEEE binary64, text UTF-8 padded with NUL bytes. Every
size and offset is checked at import against the documented table
(``LAYOUT`` below), so a structure that drifts from the protocol fails at
once instead of exchanging garbage; the Rust test suite compares
:func:`describe` (every constant, size and offset) with the Rust
definitions.
"""

import ctypes
import re
import time
from typing import Any

PROTOCOL_VERSION = 4
"""Also part of every type name: peers of other versions cannot open the services."""
MAX_AXES = 8
"""Room for axes in a frame; ``axes`` says how many entries are in use."""
AXES = 2
"""Axes of the planar model: x then y."""
TWO_PLANE_AXES = 4
"""Axes of the two-plane rotor: x_A, y_A, x_B, y_B."""
SUPPORTED_AXES = (AXES, TWO_PLANE_AXES)
"""The axis counts a hello may carry."""
UNITS_SI = 1
"""Units code: sensor in volts, currents in amperes, time in seconds, all else SI."""
RUN_ID_LEN = 32
LAW_NAME_LEN = 32
MESSAGE_LEN = 256
PARAMS_LEN = 4096
OVERRIDES_LEN = 4096
SERVICE_PREFIX = "amb-testbed"

# Hello.mode
LOCKSTEP, REALTIME, BENCH = 1, 2, 3

# Ack.status: 0 accepted, else why the hello is refused.
ACCEPTED = 0
REFUSAL = {
    1: "protocol version mismatch",
    2: "rate mismatch",
    3: "axis count mismatch",
    4: "units mismatch",
    5: "law rejected",
    6: "run id mismatch",
    7: "parameters rejected",
}
VERSION, RATE, AXES_MISMATCH, UNITS, LAW, RUN_ID, PARAMS = range(1, 8)

u32, u64, f64 = ctypes.c_uint32, ctypes.c_uint64, ctypes.c_double


def field_offset(cls: type[ctypes.Structure], name: str) -> int:
    """A field's offset in its structure (bytes), as ctypes lays it out."""
    return int(getattr(cls, name).offset)


def field_names(cls: type[ctypes.Structure]) -> list[str]:
    """The structure's field names, in order."""
    return [f[0] for f in cls._fields_]


class _Message(ctypes.Structure):
    """A wire message: its iceoryx2 type name is ``amb_testbed.v4.<class name>``."""

    @classmethod
    def type_name(cls) -> str:
        return f"amb_testbed.v{PROTOCOL_VERSION}.{cls.__name__}"


class SensorFrame(_Message):
    """One sample of the sensors with the keyphasor (rotor speed and angle), plant → controller."""

    STOP = 1
    """``status`` bit: the run is over (the controller exits 0)."""

    seq: int
    t_s: float
    token: int
    sent_ns: int
    status: int
    session: int
    axes: int
    reserved: int
    sensor_v: "ctypes.Array[ctypes.c_double]"
    speed_rad_s: float
    angle_rad: float

    _fields_ = [
        ("seq", u64),
        ("t_s", f64),
        ("token", u64),
        ("sent_ns", u64),
        ("status", u32),
        ("session", u32),
        ("axes", u32),
        ("reserved", u32),
        ("sensor_v", f64 * MAX_AXES),
        ("speed_rad_s", f64),
        ("angle_rad", f64),
    ]


class CommandFrame(_Message):
    """The answer to one sample, controller → plant."""

    STOPPING = 1
    """``status`` bit: the controller was asked to stop and is exiting."""

    seq: int
    token: int
    received_ns: int
    sent_ns: int
    status: int
    session: int
    axes: int
    reserved: int
    current_a: "ctypes.Array[ctypes.c_double]"

    _fields_ = [
        ("seq", u64),
        ("token", u64),
        ("received_ns", u64),
        ("sent_ns", u64),
        ("status", u32),
        ("session", u32),
        ("axes", u32),
        ("reserved", u32),
        ("current_a", f64 * MAX_AXES),
    ]


class WakeRequest(_Message):
    """Asks the peer to notify the event service of the stream the sender waits on."""

    seq: int

    _fields_ = [("seq", u64)]


class Hello(_Message):
    """The plant's side of the handshake: each plane's loop design (plane A in the fields of
    protocol 3, plane B's ``b_*``), the rotor's geometry (4 axes), the law and its parameters."""

    protocol_version: int
    axes: int
    units: int
    session: int
    token: int
    rate_hz: float
    period_s: float
    run_id: bytes
    law: bytes
    stiffness_n_per_m: float
    damping_ratio: float
    ki_n_per_a: float
    ks_n_per_m: float
    amp_gain_a_per_v: float
    sensor_gain_v_per_m: float
    rotor_mass_kg: float
    gravity_m_s2: float
    current_limit_a: float
    air_gap_m: float
    delay_samples: int
    gravity_bias: int
    spin_ns: int
    mode: int
    plant_pid: int
    params_len: int
    reserved: int
    params: bytes
    b_stiffness_n_per_m: float
    b_damping_ratio: float
    b_ki_n_per_a: float
    b_ks_n_per_m: float
    b_amp_gain_a_per_v: float
    b_sensor_gain_v_per_m: float
    b_rotor_mass_kg: float
    b_current_limit_a: float
    b_air_gap_m: float
    total_mass_kg: float
    transverse_inertia_kg_m2: float
    polar_inertia_kg_m2: float
    rated_speed_rad_s: float
    bearing_a_z_m: float
    bearing_b_z_m: float
    sensor_a_z_m: float
    sensor_b_z_m: float

    _fields_ = [
        ("protocol_version", u32),
        ("axes", u32),
        ("units", u32),
        ("session", u32),
        ("token", u64),
        ("rate_hz", f64),
        ("period_s", f64),
        ("run_id", ctypes.c_char * RUN_ID_LEN),
        ("law", ctypes.c_char * LAW_NAME_LEN),
        ("stiffness_n_per_m", f64),
        ("damping_ratio", f64),
        ("ki_n_per_a", f64),
        ("ks_n_per_m", f64),
        ("amp_gain_a_per_v", f64),
        ("sensor_gain_v_per_m", f64),
        ("rotor_mass_kg", f64),
        ("gravity_m_s2", f64),
        ("current_limit_a", f64),
        ("air_gap_m", f64),
        ("delay_samples", u32),
        ("gravity_bias", u32),
        ("spin_ns", u64),
        ("mode", u32),
        ("plant_pid", u32),
        ("params_len", u32),
        ("reserved", u32),
        ("params", ctypes.c_char * PARAMS_LEN),
        ("b_stiffness_n_per_m", f64),
        ("b_damping_ratio", f64),
        ("b_ki_n_per_a", f64),
        ("b_ks_n_per_m", f64),
        ("b_amp_gain_a_per_v", f64),
        ("b_sensor_gain_v_per_m", f64),
        ("b_rotor_mass_kg", f64),
        ("b_current_limit_a", f64),
        ("b_air_gap_m", f64),
        ("total_mass_kg", f64),
        ("transverse_inertia_kg_m2", f64),
        ("polar_inertia_kg_m2", f64),
        ("rated_speed_rad_s", f64),
        ("bearing_a_z_m", f64),
        ("bearing_b_z_m", f64),
        ("sensor_a_z_m", f64),
        ("sensor_b_z_m", f64),
    ]

    def params_text(self) -> str:
        """The ``[controller.params]`` document (TOML text); ``ValueError`` if malformed."""
        if self.params_len > PARAMS_LEN:
            raise ValueError(f"params_len = {self.params_len} bytes: the field holds {PARAMS_LEN}")
        raw = ctypes.string_at(ctypes.addressof(self) + field_offset(Hello, "params"), self.params_len)
        return raw.decode("utf-8")


class Ack(_Message):
    """The controller's side of the handshake."""

    protocol_version: int
    session: int
    status: int
    controller_pid: int
    token: int
    law: bytes
    message: bytes
    overrides_len: int
    reserved: int
    overrides: bytes

    _fields_ = [
        ("protocol_version", u32),
        ("session", u32),
        ("status", u32),
        ("controller_pid", u32),
        ("token", u64),
        ("law", ctypes.c_char * LAW_NAME_LEN),
        ("message", ctypes.c_char * MESSAGE_LEN),
        ("overrides_len", u32),
        ("reserved", u32),
        ("overrides", ctypes.c_char * OVERRIDES_LEN),
    ]


# The protocol's table (docs/wire-protocol.md), written out independently of
# the _fields_ above: (size, [(field, offset), ...]); alignment is 8 for all.
LAYOUT: dict[type[_Message], tuple[int, list[tuple[str, int]]]] = {
    SensorFrame: (128, [("seq", 0), ("t_s", 8), ("token", 16), ("sent_ns", 24), ("status", 32),
                        ("session", 36), ("axes", 40), ("reserved", 44), ("sensor_v", 48),
                        ("speed_rad_s", 112), ("angle_rad", 120)]),
    CommandFrame: (112, [("seq", 0), ("token", 8), ("received_ns", 16), ("sent_ns", 24), ("status", 32),
                         ("session", 36), ("axes", 40), ("reserved", 44), ("current_a", 48)]),
    WakeRequest: (8, [("seq", 0)]),
    Hello: (4448, [("protocol_version", 0), ("axes", 4), ("units", 8), ("session", 12), ("token", 16),
                   ("rate_hz", 24), ("period_s", 32), ("run_id", 40), ("law", 72),
                   ("stiffness_n_per_m", 104), ("damping_ratio", 112), ("ki_n_per_a", 120),
                   ("ks_n_per_m", 128), ("amp_gain_a_per_v", 136), ("sensor_gain_v_per_m", 144),
                   ("rotor_mass_kg", 152), ("gravity_m_s2", 160), ("current_limit_a", 168),
                   ("air_gap_m", 176), ("delay_samples", 184), ("gravity_bias", 188), ("spin_ns", 192),
                   ("mode", 200), ("plant_pid", 204), ("params_len", 208), ("reserved", 212),
                   ("params", 216), ("b_stiffness_n_per_m", 4312), ("b_damping_ratio", 4320),
                   ("b_ki_n_per_a", 4328), ("b_ks_n_per_m", 4336), ("b_amp_gain_a_per_v", 4344),
                   ("b_sensor_gain_v_per_m", 4352), ("b_rotor_mass_kg", 4360), ("b_current_limit_a", 4368),
                   ("b_air_gap_m", 4376), ("total_mass_kg", 4384), ("transverse_inertia_kg_m2", 4392),
                   ("polar_inertia_kg_m2", 4400), ("rated_speed_rad_s", 4408), ("bearing_a_z_m", 4416),
                   ("bearing_b_z_m", 4424), ("sensor_a_z_m", 4432), ("sensor_b_z_m", 4440)]),
    Ack: (4416, [("protocol_version", 0), ("session", 4), ("status", 8), ("controller_pid", 12),
                 ("token", 16), ("law", 24), ("message", 56), ("overrides_len", 312), ("reserved", 316),
                 ("overrides", 320)]),
}


def check_layout() -> None:
    """Raises ``ImportError`` naming the first size, alignment or offset that differs from the table."""
    for cls, (size, offsets) in LAYOUT.items():
        got = (ctypes.sizeof(cls), ctypes.alignment(cls))
        if got != (size, 8):
            raise ImportError(f"{cls.type_name()}: size, alignment {got}, the protocol says ({size}, 8)")
        names = [name for name, _ in offsets]
        if names != field_names(cls):
            raise ImportError(f"{cls.type_name()}: fields {field_names(cls)}, the protocol says {names}")
        for name, offset in offsets:
            if field_offset(cls, name) != offset:
                raise ImportError(f"{cls.type_name()}.{name}: offset {field_offset(cls, name)}, the protocol says {offset}")


check_layout()

CONSTANTS: dict[str, int | str] = {
    "PROTOCOL_VERSION": PROTOCOL_VERSION,
    "MAX_AXES": MAX_AXES,
    "AXES": AXES,
    "TWO_PLANE_AXES": TWO_PLANE_AXES,
    "UNITS_SI": UNITS_SI,
    "RUN_ID_LEN": RUN_ID_LEN,
    "LAW_NAME_LEN": LAW_NAME_LEN,
    "MESSAGE_LEN": MESSAGE_LEN,
    "PARAMS_LEN": PARAMS_LEN,
    "OVERRIDES_LEN": OVERRIDES_LEN,
    "SERVICE_PREFIX": SERVICE_PREFIX,
    "SENSOR_STOP": SensorFrame.STOP,
    "COMMAND_STOPPING": CommandFrame.STOPPING,
    "MODE_LOCKSTEP": LOCKSTEP,
    "MODE_REALTIME": REALTIME,
    "MODE_BENCH": BENCH,
    "ACK_ACCEPTED": ACCEPTED,
    "ACK_VERSION": VERSION,
    "ACK_RATE": RATE,
    "ACK_AXES": AXES_MISMATCH,
    "ACK_UNITS": UNITS,
    "ACK_LAW": LAW,
    "ACK_RUN_ID": RUN_ID,
    "ACK_PARAMS": PARAMS,
    "SENSOR_FRAME_TYPE_NAME": SensorFrame.type_name(),
    "COMMAND_FRAME_TYPE_NAME": CommandFrame.type_name(),
    "WAKE_REQUEST_TYPE_NAME": WakeRequest.type_name(),
    "HELLO_TYPE_NAME": Hello.type_name(),
    "ACK_TYPE_NAME": Ack.type_name(),
}
"""Every constant of the protocol under its name in the C header (``AMB_TESTBED_<name>``) and in
``controller::wire::constants()``, which the Rust test suite compares with this."""


def describe() -> dict[str, Any]:
    """The kit's constants and the ctypes layouts as ctypes lays them out (for the cross-check
    against the Rust definitions): ``{"constants": {...}, "messages": [{name, type_name, size,
    align, fields: [[name, offset, size], ...]}, ...]}``."""
    messages = []
    for cls in (SensorFrame, CommandFrame, WakeRequest, Hello, Ack):
        fields = [[name, field_offset(cls, name), int(getattr(cls, name).size)] for name in field_names(cls)]
        messages.append({"name": cls.__name__, "type_name": cls.type_name(), "size": ctypes.sizeof(cls),
                         "align": ctypes.alignment(cls), "fields": fields})
    return {"constants": CONSTANTS, "messages": messages}


def fixed_str(text: str, length: int) -> bytes:
    """``text`` as UTF-8 in at most ``length`` bytes, cut at a character boundary."""
    raw = text.encode("utf-8")[:length]
    return raw.decode("utf-8", errors="ignore").encode("utf-8")


def str_of(field: bytes) -> str:
    """The text of a NUL-padded field (invalid UTF-8 replaced)."""
    return field.split(b"\0", 1)[0].decode("utf-8", errors="replace")


_RUN_ID = re.compile(r"[A-Za-z0-9._-]{1,%d}" % RUN_ID_LEN)


def valid_run_id(run_id: str) -> str:
    """The run id if valid (1 to 32 characters among ``A-Z a-z 0-9 - _ .``), else ``ValueError``."""
    if not _RUN_ID.fullmatch(run_id) or len(run_id.encode()) > RUN_ID_LEN:
        raise ValueError(
            f"run id {run_id!r}: must be 1 to {RUN_ID_LEN} characters among A-Z a-z 0-9 - _ . "
            "(it names shared-memory services)"
        )
    return run_id


def name(run_id: str, what: str) -> str:
    """A service or node name of a run: ``amb-testbed/<run_id>/<what>``."""
    return f"{SERVICE_PREFIX}/{run_id}/{what}"


monotonic_ns = time.monotonic_ns
"""``CLOCK_MONOTONIC`` (ns) on Linux: the clock the plant stamps frames with."""
