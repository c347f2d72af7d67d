"""The wire protocol, version 3, as ctypes structures.

The layouts and iceoryx2 type names are those of ``controller/src/wire.rs``
(the source of truth) and ``docs/wire-protocol.md``: native endianness, no
padding, ``f64`` = IEEE binary64, text UTF-8 padded with NUL bytes. Every
size and offset is checked at import against the documented table
(``LAYOUT`` below), so a structure that drifts from the protocol fails at
once instead of exchanging garbage.
"""

import ctypes
import re
import time

PROTOCOL_VERSION = 3
"""Also part of every type name: peers of other versions cannot open the services."""
MAX_AXES = 8
"""Room for axes in a frame; ``axes`` says how many entries are in use."""
AXES = 2
"""Axes in use: x then y."""
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


class _Message(ctypes.Structure):
    """A wire message: its iceoryx2 type name is ``amb_testbed.v3.<class name>``."""

    @classmethod
    def type_name(cls) -> str:
        return f"amb_testbed.v{PROTOCOL_VERSION}.{cls.__name__}"


class SensorFrame(_Message):
    """One sample of the sensors, plant → controller."""

    STOP = 1
    """``status`` bit: the run is over (the controller exits 0)."""

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
    ]


class CommandFrame(_Message):
    """The answer to one sample, controller → plant."""

    STOPPING = 1
    """``status`` bit: the controller was asked to stop and is exiting."""

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

    _fields_ = [("seq", u64)]


class Hello(_Message):
    """The plant's side of the handshake: the loop design, the law and its parameters."""

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
    ]

    def params_text(self) -> str:
        """The ``[controller.params]`` document (TOML text); ``ValueError`` if malformed."""
        if self.params_len > PARAMS_LEN:
            raise ValueError(f"params_len = {self.params_len} bytes: the field holds {PARAMS_LEN}")
        raw = ctypes.string_at(ctypes.addressof(self) + Hello.params.offset, self.params_len)
        return raw.decode("utf-8")


class Ack(_Message):
    """The controller's side of the handshake."""

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
LAYOUT = {
    SensorFrame: (112, [("seq", 0), ("t_s", 8), ("token", 16), ("sent_ns", 24), ("status", 32),
                        ("session", 36), ("axes", 40), ("reserved", 44), ("sensor_v", 48)]),
    CommandFrame: (112, [("seq", 0), ("token", 8), ("received_ns", 16), ("sent_ns", 24), ("status", 32),
                         ("session", 36), ("axes", 40), ("reserved", 44), ("current_a", 48)]),
    WakeRequest: (8, [("seq", 0)]),
    Hello: (4312, [("protocol_version", 0), ("axes", 4), ("units", 8), ("session", 12), ("token", 16),
                   ("rate_hz", 24), ("period_s", 32), ("run_id", 40), ("law", 72),
                   ("stiffness_n_per_m", 104), ("damping_ratio", 112), ("ki_n_per_a", 120),
                   ("ks_n_per_m", 128), ("amp_gain_a_per_v", 136), ("sensor_gain_v_per_m", 144),
                   ("rotor_mass_kg", 152), ("gravity_m_s2", 160), ("current_limit_a", 168),
                   ("air_gap_m", 176), ("delay_samples", 184), ("gravity_bias", 188), ("spin_ns", 192),
                   ("mode", 200), ("plant_pid", 204), ("params_len", 208), ("reserved", 212),
                   ("params", 216)]),
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
        if names != [f[0] for f in cls._fields_]:
            raise ImportError(f"{cls.type_name()}: fields {[f[0] for f in cls._fields_]}, the protocol says {names}")
        for name, offset in offsets:
            if getattr(cls, name).offset != offset:
                raise ImportError(f"{cls.type_name()}.{name}: offset {getattr(cls, name).offset}, the protocol says {offset}")


check_layout()


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
