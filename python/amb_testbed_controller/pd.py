"""``pd``: the design's PD, naively sampled, bit for bit as the Rust law (``controller/src/pd.rs``).

With the linearised bearing ``F = k_i i + k_s Δ`` and
``i = i_bias − A_a (k_p u + k_d u̇)``, ``u = A_s Δ``, the loop is a spring
``k_e`` and a damper ``c_e = 2 ξ_e √(k_e m_r)``:

    k_p = (k_e + k_s) / (k_i A_a A_s)        k_d = c_e / (k_i A_a A_s)

with the gravity bias ``m_r g / k_i`` on y. The derivative is the backward
difference ``(u_k − u_{k−1}) / T``, zero at the first sample.

Python floats are IEEE binary64 and Python neither reorders nor fuses
floating-point operations, so writing each expression in the Rust law's
order (left to right, same parentheses) gives the same bits. A per-plane
law: on a two-plane rotor the kit runs one per plane, each from its plane's
design, as the Rust controller does.
"""

import math
from typing import ClassVar

from .law import Design, DesignError, Params, Sample


class PD:
    """The naively sampled PD of one plane's design; no parameters of its own."""

    name: ClassVar[str] = "pd"

    def __init__(self, design: Design, params: Params) -> None:
        k, xi, c = design.stiffness_n_per_m, design.damping_ratio, design.constants
        if not (math.isfinite(k) and k > 0.0):
            raise DesignError("controller.stiffness_n_per_m", k, "N/m", "must be > 0")
        if not (math.isfinite(xi) and xi >= 0.0):
            raise DesignError("controller.damping_ratio", xi, "", "must be >= 0")
        loop_gain = c.ki_n_per_a * c.amp_gain_a_per_v * c.sensor_gain_v_per_m
        c_e = 2.0 * xi * math.sqrt(k * c.rotor_mass_kg)
        self.kp = (k + c.ks_n_per_m) / loop_gain
        self.kd = c_e / loop_gain
        self.amp = c.amp_gain_a_per_v
        self.bias = (0.0, c.rotor_mass_kg * c.gravity_m_s2 / c.ki_n_per_a if design.gravity_bias else 0.0)
        self.period = design.period_s
        self.prev: tuple[float, float] | None = None

    def update(self, sample: Sample) -> tuple[float, float]:
        u = sample.sensor_v
        if self.prev is None:
            rate = (0.0, 0.0)
        else:
            rate = ((u[0] - self.prev[0]) / self.period, (u[1] - self.prev[1]) / self.period)
        self.prev = u
        amp, kp, kd, bias = self.amp, self.kp, self.kd, self.bias
        return (bias[0] - amp * (kp * u[0] + kd * rate[0]), bias[1] - amp * (kp * u[1] + kd * rate[1]))
