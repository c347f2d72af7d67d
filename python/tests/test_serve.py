"""The kit's handshake decisions, without a plant: which hellos it refuses with which code, and
how a law is built for the hello's rotor (once per plane on 4 axes)."""

import math
from typing import ClassVar

import pytest
from conftest import hello

from amb_testbed_controller import PD, Design, Params, RotorDesign, RotorSample, Sample, saturate, wire
from amb_testbed_controller.serve import WrongCount, _build, _check_hello, _count, _describe, _limits


class PlanarOnly:
    """A law written for the planar model only."""

    name: ClassVar[str] = "planar_only"
    axes = (2,)

    def __init__(self, design: Design, params: Params) -> None:
        pass

    def update(self, sample: Sample) -> tuple[float, float]:
        return (0.0, 0.0)


class Sum:
    """A law of the whole rotor: every current is the sum of the sensor voltages (A/V)."""

    name: ClassVar[str] = "sum"
    whole_rotor: ClassVar[bool] = True

    def __init__(self, design: RotorDesign, params: Params) -> None:
        self.axes = design.axes
        self.gain = params.number("gain", "A/V", 1.0)

    def update(self, sample: RotorSample) -> tuple[float, ...]:
        return tuple(self.gain * sum(sample.sensor_v) for _ in range(self.axes))


def test_hellos_of_another_version_or_axis_count_are_refused_with_their_codes() -> None:
    h = hello()
    assert _check_hello(h, "r") is None
    assert _check_hello(hello(axes=4), "r") is None
    h.protocol_version = 3
    assert _check_hello(h, "r") == (1, "protocol version 3 from the plant, this controller speaks 4")
    h = hello()
    h.axes = 3
    assert _check_hello(h, "r") == (3, "the plant has 3 axes, this controller drives 2 or 4")
    assert _check_hello(hello(), "other") == (6, "hello for run id 'r', this controller serves 'other'")


def test_a_planar_only_law_refuses_a_two_plane_hello_with_code_3() -> None:
    law, refusal = _build([PlanarOnly], hello("planar_only", axes=4))
    assert law is None and refusal == (3, "law planar_only drives 2 axes; the plant has 4 axes")
    law, refusal = _build([PlanarOnly], hello("planar_only"))
    assert refusal is None and isinstance(law, PlanarOnly)


def test_a_per_plane_law_runs_once_per_plane_from_each_planes_design() -> None:
    h = hello(axes=4)
    law, refusal = _build([PD], h)
    assert refusal is None and law is not None
    design = RotorDesign.from_hello(h)
    a, b = PD(design.planes[0], Params("pd", {})), PD(design.planes[1], Params("pd", {}))
    for k, v in enumerate([(0.1, -0.2, 0.3, 0.05), (0.12, -0.1, 0.31, 0.0), (3.0, -3.0, 0.0, 1.0)]):
        got = law.update(RotorSample(k, k * 5e-5, v, 100.0, 0.5))
        want = a.update(Sample(k, k * 5e-5, (v[0], v[1]))) + b.update(Sample(k, k * 5e-5, (v[2], v[3])))
        assert got == want
    assert _limits(design) == (2.0, 2.0, 3.0, 3.0)
    assert _describe("pd", design, 20_000.0).startswith("pd (Python): 4 axes, k_e = 1000000.0 / 1500000.0 N/m")


def test_a_whole_rotor_law_gets_the_rotor_design_and_its_parameters() -> None:
    law, refusal = _build([Sum], hello("sum", axes=4, params="gain = 2.0"))
    assert refusal is None and law is not None
    assert law.update(RotorSample(0, 0.0, (0.5, 0.25, 0.0, 0.25), 0.0, 0.0)) == (2.0, 2.0, 2.0, 2.0)
    law, refusal = _build([Sum], hello("sum", axes=4, params="gain = 2.0\nbogus = 1"))
    assert law is None and refusal is not None and refusal[0] == wire.PARAMS
    assert "law sum: unknown parameter controller.params.bogus = 1" in refusal[1]


def test_unknown_laws_and_bad_designs_are_refused_with_code_5() -> None:
    assert _build([PD], hello("pid")) == (None, (5, "unknown controller law `pid` (this controller serves pd)"))
    h = hello()
    h.stiffness_n_per_m = -1.0
    assert _build([PD], h) == (None, (5, "law pd: controller.stiffness_n_per_m = -1 N/m: must be > 0"))


class Three:
    """A per-plane law that answers three currents (issue 31 item 7)."""

    name: ClassVar[str] = "three"

    def __init__(self, design: Design, params: Params) -> None:
        pass

    def update(self, sample: Sample) -> tuple[float, float, float]:
        return (0.0, 0.0, 1.0)


def test_a_wrong_number_of_currents_is_refused_naming_law_sample_and_count() -> None:
    """A per-plane law lifted to 4 axes that answers 3 currents would feed plane B plane A's third."""
    law, refusal = _build([Three], hello("three", axes=4))
    assert refusal is None and law is not None
    with pytest.raises(WrongCount, match=r"law three answered sample 7 \(t = 0.1 s\) with 3 currents.*i_x, i_y of plane A"):
        law.update(RotorSample(7, 0.1, (0.0, 0.0, 0.0, 0.0), 0.0, 0.0))
    for got in [(0.0,) * 3, (0.0,) * 5, [], 1.0]:
        with pytest.raises(WrongCount, match="law sum answered sample 3"):
            _count("sum", got, 4, "one per axis", 3, 0.0)
    _count("sum", (0.0,) * 4, 4, "one per axis", 3, 0.0)
    assert WrongCount.code == 2


def test_every_non_finite_current_saturates_to_nan_never_to_the_limit() -> None:
    for i in (math.nan, math.inf, -math.inf):
        assert math.isnan(saturate(i, 2.0))
    assert (saturate(3.0, 2.0), saturate(-3.0, 2.0), saturate(1.5, 2.0)) == (2.0, -2.0, 1.5)
