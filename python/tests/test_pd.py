"""``pd`` against its documented floating-point form (docs/wire-protocol.md, "The shipped laws,
exactly"), written out here independently of pd.py: the same bits."""

import math

from conftest import hello

from amb_testbed_controller import PD, Design, Params, Sample


def documented_pd(d: Design, samples: list[tuple[float, float]]) -> list[tuple[float, float]]:
    c = d.constants
    big_l = (c.ki_n_per_a * c.amp_gain_a_per_v) * c.sensor_gain_v_per_m
    c_e = (2.0 * d.damping_ratio) * math.sqrt(d.stiffness_n_per_m * c.rotor_mass_kg)
    k_p = (d.stiffness_n_per_m + c.ks_n_per_m) / big_l
    k_d = c_e / big_l
    bias = [0.0, (c.rotor_mass_kg * c.gravity_m_s2) / c.ki_n_per_a if d.gravity_bias else 0.0]
    out, prev = [], None
    for u in samples:
        rate = [0.0, 0.0] if prev is None else [(u[j] - prev[j]) / d.period_s for j in (0, 1)]
        prev = u
        i = [bias[j] - c.amp_gain_a_per_v * ((k_p * u[j]) + (k_d * rate[j])) for j in (0, 1)]
        out.append((i[0], i[1]))
    return out


def test_pd_is_the_documented_form_bit_for_bit() -> None:
    d = Design.from_hello(hello())
    samples = [(0.1234567891234, -0.0987654321987), (0.1334567891234, -0.1087654321987), (3.0, -3.0), (0.0, 0.0)]
    law = PD(d, Params("pd", {}))
    got = [law.update(Sample(k, k * d.period_s, u)) for k, u in enumerate(samples)]
    assert got == documented_pd(d, samples)
    assert got[0][1] > 0.52  # the gravity bias m g / k_i
