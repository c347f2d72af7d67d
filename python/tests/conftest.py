"""Shared helpers of the kit's tests: hellos as the plant sends them (planar and two-plane)."""

import math

from amb_testbed_controller import wire

STUDY = dict(
    stiffness_n_per_m=1e6, damping_ratio=0.01, ki_n_per_a=216.0, ks_n_per_m=4.32e5, amp_gain_a_per_v=1.0,
    sensor_gain_v_per_m=25_000.0, rotor_mass_kg=11.5, gravity_m_s2=9.80665, current_limit_a=2.0, air_gap_m=150e-6,
)


def hello(law: str = "pd", axes: int = 2, params: str = "") -> wire.Hello:
    """A hello of the study's design at 20 kHz (``Hello::example`` and ``example_two_plane`` in Rust);
    with 4 axes, plane B differs (k_e, mass share, k_i, limit) so that the planes can be told apart."""
    h = wire.Hello(protocol_version=wire.PROTOCOL_VERSION, axes=axes, units=wire.UNITS_SI, session=1, token=7,
                   rate_hz=20_000.0, period_s=1.0 / 20_000.0, run_id=b"r", law=law.encode(), delay_samples=1,
                   gravity_bias=1, spin_ns=200_000, mode=wire.LOCKSTEP, **STUDY)
    raw = params.encode()
    ctypes_params = (wire.ctypes.c_char * wire.PARAMS_LEN).from_buffer(h, wire.field_offset(wire.Hello, "params"))
    ctypes_params[: len(raw)] = raw
    h.params_len = len(raw)
    if axes == wire.TWO_PLANE_AXES:
        h.b_stiffness_n_per_m, h.b_damping_ratio, h.b_ki_n_per_a, h.b_ks_n_per_m = 1.5e6, 0.02, 190.0, 3.9e5
        h.b_amp_gain_a_per_v, h.b_sensor_gain_v_per_m, h.b_rotor_mass_kg = 1.0, 24_000.0, 9.0
        h.b_current_limit_a, h.b_air_gap_m = 3.0, 140e-6
        h.total_mass_kg, h.transverse_inertia_kg_m2, h.polar_inertia_kg_m2 = 20.5, 0.414, 11.62e-3
        h.rated_speed_rad_s = 2 * math.pi * 500.0
        h.bearing_a_z_m, h.bearing_b_z_m, h.sensor_a_z_m, h.sensor_b_z_m = -0.16, 0.2, -0.18, 0.22
    return h
