"""The kit's structures: protocol 4's sizes, type names and constants, and its own drift check."""

import ctypes

import pytest

from amb_testbed_controller import link, wire


def test_sizes_and_type_names_are_protocol_4s() -> None:
    d = wire.describe()
    sizes = {m["name"]: m["size"] for m in d["messages"]}
    assert sizes == {"SensorFrame": 128, "CommandFrame": 112, "WakeRequest": 8, "Hello": 4448, "Ack": 4416}
    assert all(m["type_name"] == f"amb_testbed.v4.{m['name']}" for m in d["messages"])
    # Every message is tiled by its fields, without padding.
    for m in d["messages"]:
        at = 0
        for name, offset, size in m["fields"]:
            assert offset == at, (m["name"], name)
            at += size
        assert at == m["size"], m["name"]


def test_the_keyphasor_sits_after_the_sensor_voltages() -> None:
    f = wire.SensorFrame(speed_rad_s=3141.5, angle_rad=6.25)
    raw = bytes(f)
    assert ctypes.c_double.from_buffer_copy(raw, 112).value == 3141.5
    assert ctypes.c_double.from_buffer_copy(raw, 120).value == 6.25


def test_constants_name_every_refusal_and_type_name() -> None:
    c = wire.CONSTANTS
    assert (c["PROTOCOL_VERSION"], c["AXES"], c["TWO_PLANE_AXES"], c["ACK_AXES"]) == (4, 2, 4, 3)
    assert sorted(k for k in c if k.startswith("ACK_")) == sorted(
        ["ACK_ACCEPTED", "ACK_VERSION", "ACK_RATE", "ACK_AXES", "ACK_UNITS", "ACK_LAW", "ACK_RUN_ID", "ACK_PARAMS",
         "ACK_TYPE_NAME"])
    assert {code for code in wire.REFUSAL} == {c[k] for k in c if k.startswith("ACK_") and k not in
                                               ("ACK_ACCEPTED", "ACK_TYPE_NAME")}


def test_a_structure_that_drifts_fails_the_import_check(monkeypatch: pytest.MonkeyPatch) -> None:
    size, fields = wire.LAYOUT[wire.SensorFrame]
    monkeypatch.setitem(wire.LAYOUT, wire.SensorFrame, (size, fields[:-1] + [("angle_rad", 128)]))
    with pytest.raises(ImportError, match="SensorFrame.angle_rad: offset 120, the protocol says 128"):
        wire.check_layout()


def test_a_peer_of_another_version_is_named() -> None:
    assert link.version_of("amb_testbed.v3.Hello") == 3
    assert link.version_of("something.else") is None
    m = link.incompatible_message("amb-testbed/r/hello", "amb_testbed.v3.Hello")
    assert "the peer speaks protocol version 3: its type is amb_testbed.v3.Hello" in m
    assert "this side speaks version 4, type names amb_testbed.v4.*" in m
    assert "another protocol version" in link.incompatible_message("s", None)


def test_run_ids_are_checked() -> None:
    assert wire.valid_run_id("a-1.b_c") == "a-1.b_c"
    with pytest.raises(ValueError, match="run id 'a/b'"):
        wire.valid_run_id("a/b")
