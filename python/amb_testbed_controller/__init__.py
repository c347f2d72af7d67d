"""Controller kit for the AMB touchdown testbed: a control law as a Python class, served to the
plant over iceoryx2 shared memory (wire protocol version 4, ``docs/wire-protocol.md``).

    from amb_testbed_controller import Check, Design, Params, Sample, serve

    class MyLaw:
        name = "my_law"                       # the scene's controller.law

        def __init__(self, design: Design, params: Params) -> None:   # one plane's Design
            self.gain = params.number("gain", "", 1.0, Check.POSITIVE)
            ...

        def update(self, sample: Sample) -> tuple[float, float]:
            # sample: seq, t_s, sensor_v (V, x then y), speed_rad_s, angle_rad (the keyphasor)
            return (i_x, i_y)                 # coil currents (A), before the amplifier limit

    serve(MyLaw)

On a two-plane rotor (4 axes) the kit builds the class once per bearing plane, each from its
plane's design, and feeds each its plane's pair. A class with ``axes = (2,)`` drives the
planar model only (a 4-axis hello is refused, code 3); a law of the whole rotor has
``whole_rotor = True`` (``RotorLaw``). Run it from a scene with
``[controller] command = ["python3", "my_law.py"]``. The kit is typed (``py.typed``).
"""

from .law import (
    Check,
    Design,
    DesignError,
    Geometry,
    Law,
    LawClass,
    LoopConstants,
    ParamError,
    Params,
    RotorDesign,
    RotorLaw,
    RotorSample,
    Sample,
    saturate,
)
from .pd import PD
from .serve import run, serve

__all__ = [
    "Check", "Design", "DesignError", "Geometry", "Law", "LawClass", "LoopConstants", "PD", "ParamError", "Params",
    "RotorDesign", "RotorLaw", "RotorSample", "Sample", "run", "saturate", "serve",
]
