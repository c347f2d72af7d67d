#!/usr/bin/env python3
"""`relev_py`: a re-levitation law written in Python, with parameters of its own.

The nominal loop is the design's PD (k_e, ξ_e) with the sampling lag
compensated to first order: zero-order hold, `delay_samples` of delay and the
backward difference lag the loop by about ω (d + 1) T, which turns part of
the proportional force into a negative damping (k_e + k_s)(d + 1) T; the law
adds it back to the derivative gain,

    k_p = (k_e + k_s) / L,    k_d = (2 ξ √(k_e m_r) + (k_e + k_s)(d + 1) T) / L,    L = k_i A_a A_s.

While the rotor touches its touchdown bearing (sensor radius ≥ `touch_um`)
the same loop runs with the damping ratio `recovery_damping_ratio`; once the
radius has stayed below `release_um` for `calm_ms` the nominal damping
returns. The rule acts from `arm_ms` on.

Parameters (`[controller.params]`):

| key | unit | default | meaning |
|---|---|---|---|
| `touch_um` | µm | 0.8 × air gap | radius at which the rotor counts as touching |
| `release_um` | µm | 0.3 × air gap | radius below which it counts as levitating (< `touch_um`) |
| `calm_ms` | ms | 50 | time below `release_um` before the nominal damping returns |
| `recovery_damping_ratio` | – | 0.2 | damping ratio while recovering (0 < ξ < 1) |
| `arm_ms` | ms | 0 | time from which the rule acts |

    [controller]
    law = "relev_py"
    command = ["python3", "relev_py.py"]    # the plant appends --run-id ID
"""

import math

from amb_testbed_controller import Check, serve


class RelevPy:
    name = "relev_py"

    def __init__(self, design, params):
        c = design.constants
        touch = params.number("touch_um", "µm", 0.8e6 * c.air_gap_m, Check.POSITIVE)
        release = params.number("release_um", "µm", 0.3e6 * c.air_gap_m, Check.POSITIVE)
        if release >= touch:
            raise params.error("release_um", release, "µm", f"must be below controller.params.touch_um = {touch} µm")
        calm_ms = params.number("calm_ms", "ms", 50.0, Check.NON_NEGATIVE)
        xi_recovery = params.number("recovery_damping_ratio", "", 0.2, Check.between(0.0, 1.0))
        self.arm_s = params.number("arm_ms", "ms", 0.0, Check.NON_NEGATIVE) * 1e-3

        loop_gain = c.ki_n_per_a * c.amp_gain_a_per_v * c.sensor_gain_v_per_m
        k = design.stiffness_n_per_m
        lag = (k + c.ks_n_per_m) * (design.delay_samples + 1) * design.period_s  # N·s/m

        def kd(xi):
            return (2.0 * xi * math.sqrt(k * c.rotor_mass_kg) + lag) / loop_gain

        self.kp = (k + c.ks_n_per_m) / loop_gain
        self.kd_nominal, self.kd_recovery = kd(design.damping_ratio), kd(xi_recovery)
        self.amp = c.amp_gain_a_per_v
        self.bias_y = c.rotor_mass_kg * c.gravity_m_s2 / c.ki_n_per_a if design.gravity_bias else 0.0
        self.period = design.period_s
        volts = c.sensor_gain_v_per_m * 1e-6  # V per µm
        self.touch_v2, self.release_v2 = (touch * volts) ** 2, (release * volts) ** 2
        self.calm_samples = round(calm_ms * 1e-3 / design.period_s)
        self.recovering, self.calm = False, 0
        self.prev = None

    def update(self, sample):
        x, y = sample.sensor_v
        px, py = self.prev or (x, y)
        self.prev = (x, y)
        vx, vy = (x - px) / self.period, (y - py) / self.period
        if sample.t_s >= self.arm_s:
            r2 = x * x + y * y
            if r2 >= self.touch_v2:
                self.recovering, self.calm = True, 0
            elif self.recovering:
                self.calm = self.calm + 1 if r2 < self.release_v2 else 0
                self.recovering = self.calm <= self.calm_samples
        kd = self.kd_recovery if self.recovering else self.kd_nominal
        return (-self.amp * (self.kp * x + kd * vx), self.bias_y - self.amp * (self.kp * y + kd * vy))


if __name__ == "__main__":
    serve(RelevPy)
