"""What a law is built from: each plane's design from the hello, the keyphasor in the sample,
and parameters refused naming law, key, value and unit."""

import pytest
from conftest import hello

from amb_testbed_controller import Check, Design, ParamError, Params, RotorDesign, RotorSample, Sample, wire


def test_a_planar_hello_gives_one_plane_and_no_geometry() -> None:
    d = RotorDesign.from_hello(hello())
    assert (d.axes, len(d.planes), d.geometry) == (2, 1, None)
    assert d.planes[0] == Design.from_hello(hello())
    assert d.planes[0].constants.rotor_mass_kg == 11.5


def test_a_two_plane_hello_gives_each_plane_its_own_design() -> None:
    d = RotorDesign.from_hello(hello(axes=4))
    a, b = d.planes
    assert d.axes == 4
    assert (b.stiffness_n_per_m, b.damping_ratio, b.current_limit_a) == (1.5e6, 0.02, 3.0)
    assert (b.constants.ki_n_per_a, b.constants.rotor_mass_kg, b.constants.sensor_gain_v_per_m) == (190.0, 9.0, 24_000.0)
    # Shared with plane A: the period, the delay, the gravity bias and gravity.
    assert (b.period_s, b.delay_samples, b.gravity_bias, b.constants.gravity_m_s2) == (
        a.period_s, a.delay_samples, a.gravity_bias, a.constants.gravity_m_s2)
    assert d.geometry is not None
    assert (d.geometry.bearing_z_m, d.geometry.sensor_z_m, d.geometry.mass_kg) == ((-0.16, 0.2), (-0.18, 0.22), 20.5)


def test_samples_carry_the_keyphasor() -> None:
    s = Sample(3, 1.5e-4, (0.1, 0.2))
    assert (s.speed_rad_s, s.angle_rad) == (0.0, 0.0)
    r = RotorSample(3, 1.5e-4, (0.1, 0.2, 0.3, 0.4), 3141.5, 1.25)
    b = r.plane(1)
    assert (r.axes, b.sensor_v, b.speed_rad_s, b.angle_rad, b.seq) == (4, (0.3, 0.4), 3141.5, 1.25, 3)


def test_parameters_are_refused_naming_law_key_value_and_unit() -> None:
    p = Params.parse("law1", "hold_ms = -5.0\nother = 1")
    with pytest.raises(ParamError, match=r"^law law1: controller.params.hold_ms = -5.0 ms: must be a finite number >= 0$"):
        p.number("hold_ms", "ms", 50.0, Check.NON_NEGATIVE)
    p = Params.parse("law1", "x = 0.5\nother = 1")
    assert p.number("x", "", 1.0, Check.between(0.0, 1.0)) == 0.5
    with pytest.raises(ParamError, match="unknown parameter controller.params.other = 1 .law law1 reads x."):
        p.finish()
    with pytest.raises(ParamError, match="not valid TOML"):
        Params.parse("law1", "x = ")
    with pytest.raises(ParamError, match=f"the limit is {wire.PARAMS_LEN} bytes"):
        Params.parse("law1", "x" * (wire.PARAMS_LEN + 1))
