"""Controller kit for the AMB touchdown testbed: a control law as a Python class, served to the
plant over iceoryx2 shared memory (wire protocol version 3, ``docs/wire-protocol.md``).

    from amb_testbed_controller import Check, serve

    class MyLaw:
        name = "my_law"                       # the scene's controller.law

        def __init__(self, design, params):   # Design; Params = [controller.params]
            self.gain = params.number("gain", "", 1.0, Check.POSITIVE)
            ...

        def update(self, sample):             # Sample: seq, t_s, sensor_v (V, x then y)
            return (i_x, i_y)                 # coil currents (A), before the amplifier limit

    serve(MyLaw)

Run it from a scene with ``[controller] command = ["python3", "my_law.py"]``.
"""

from .law import Check, Design, DesignError, LoopConstants, ParamError, Params, Sample, saturate
from .pd import PD
from .serve import run, serve

__all__ = [
    "Check", "Design", "DesignError", "LoopConstants", "PD", "ParamError", "Params", "Sample",
    "run", "saturate", "serve",
]
