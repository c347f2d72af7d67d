"""The registry's `pd` (controller/src/pd.rs) as a pythonfmu (PyPI) FMI 2.0 co-simulation FMU,
for tests/tests/fmu_controller.rs (issue 29 item 3): built there with `pythonfmu build -f` and
run as `controller.fmu`. The arithmetic is the Rust law's, in its order, on IEEE doubles:

    u_dot = (u - prev) / tau        (0 at the first step; tau the design's period, as pd.rs's T)
    i     = bias - A_a (k_p u + k_d u_dot)      (bias on y only; 0.0 - ... on x, as PdGains)

Parameters (set through [controller.params]): kp, kd, amp_gain, bias_y, tau (s).
"""
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


class PythonPd(Fmi2Slave):
    description = "the testbed's pd law, in Python (pythonfmu)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.sensor_x = 0.0
        self.sensor_y = 0.0
        self.current_x = 0.0
        self.current_y = 0.0
        self.kp = 1.0
        self.kd = 0.0
        self.amp_gain = 1.0
        self.bias_y = 0.0
        self.tau = 1e-4
        self.prev = None
        for name in ("sensor_x", "sensor_y"):
            self.register_variable(Real(name, causality=Fmi2Causality.input))
        for name in ("current_x", "current_y"):
            self.register_variable(Real(name, causality=Fmi2Causality.output))
        for name in ("kp", "kd", "amp_gain", "bias_y", "tau"):
            self.register_variable(
                Real(name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable)
            )

    def do_step(self, current_time, step_size):
        u = (self.sensor_x, self.sensor_y)
        if self.prev is None:
            u_dot = (0.0, 0.0)
        else:
            u_dot = ((u[0] - self.prev[0]) / self.tau, (u[1] - self.prev[1]) / self.tau)
        self.prev = u
        bias = (0.0, self.bias_y)
        i = [bias[k] - self.amp_gain * (self.kp * u[k] + self.kd * u_dot[k]) for k in (0, 1)]
        self.current_x, self.current_y = i
        return True
