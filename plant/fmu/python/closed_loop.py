"""The plant FMU (FMI 2.0 or 3.0) in a closed loop with the Python kit's ``pd``, tick by tick, under FMPy.

    python closed_loop.py plant.fmu out.csv [--ticks N] [--save-at K state.bin] [--from-state state.bin]

The FMU (``plant fmu SCENE --out plant.fmu``, a planar scene with ``amb.force_law = "linear"``)
is stepped one controller tick at a time: at each communication point the script reads the
sensor and keyphasor outputs, asks ``pd`` (``amb_testbed_controller.PD``, designed from the
scene inside the FMU, ``resources/scene.toml``) for the currents, saturates them at
``controller.current_limit_a``, delays them ``controller.delay_samples`` ticks (the bias
currents, the inputs' start values, before the first answer) and sets them as the inputs
for the next step: what ``plant run`` does in ``controller.mode = "sampled"``.

``out.csv`` has one line per communication point: ``tick``, ``t_s``, the command applied
over the step that starts there (``current_x_A``, ``current_y_A``; ``nan`` on the last line),
and every output of the FMU, each number as Python's ``repr`` (the shortest text that reads
back to the same double).

``--save-at K state.bin`` serialises the FMU's state at tick K (``fmi2SerializeFMUstate``,
``fmi3SerializeFMUState``), with the controller's own state beside it; ``--from-state
state.bin`` starts a fresh instance from such a file (deserialised, set) and goes on
from tick K: another process continues the run where this one saved it.
"""

import argparse
import json
import math
import sys
import tomllib

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

from amb_testbed_controller import PD, Design, LoopConstants, Params, Sample, saturate


def design_of(scene: dict) -> Design:
    """The planar design the plant's sampled loop builds ``pd`` from (``Scene::design``)."""
    amb, ctl, rotor = scene["amb"], scene["controller"], scene["rotor"]
    if amb.get("force_law", "linear") != "linear":
        sys.exit("closed_loop.py: the design here reads amb.ki_n_per_a and ks_n_per_m: amb.force_law must be linear")
    return Design(
        stiffness_n_per_m=float(ctl["stiffness_n_per_m"]),
        damping_ratio=float(ctl["damping_ratio"]),
        period_s=1.0 / float(ctl["rate_hz"]),
        gravity_bias=bool(ctl["gravity_bias"]),
        current_limit_a=float(ctl["current_limit_a"]),
        delay_samples=int(ctl["delay_samples"]),
        constants=LoopConstants(
            ki_n_per_a=float(amb["ki_n_per_a"]),
            ks_n_per_m=float(amb["ks_n_per_m"]),
            amp_gain_a_per_v=float(amb["amp_gain_a_per_v"]),
            sensor_gain_v_per_m=float(amb["sensor_gain_v_per_m"]),
            rotor_mass_kg=float(rotor["mass_kg"]),
            gravity_m_s2=float(scene["scene"]["gravity_m_s2"]),
            air_gap_m=float(scene["touchdown"]["air_gap_mm"]) * 1e-3,
        ),
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("fmu")
    ap.add_argument("out")
    ap.add_argument("--ticks", type=int, default=None, help="ticks to run (default: the scene's duration)")
    ap.add_argument("--save-at", nargs=2, metavar=("K", "FILE"))
    ap.add_argument("--from-state", metavar="FILE")
    args = ap.parse_args()

    md = read_model_description(args.fmu)
    unzipdir = extract(args.fmu)
    with open(f"{unzipdir}/resources/scene.toml", "rb") as f:
        scene = tomllib.load(f)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    if "current_x_B" in vr:
        sys.exit("closed_loop.py: a planar scene's FMU, please (this one has bearing B)")
    design = design_of(scene)
    period = design.period_s
    ticks = args.ticks if args.ticks is not None else round(float(scene["scene"]["duration_s"]) / period)
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    out_vrs = [vr[n] for n in outputs]
    inputs = [vr["current_x_A"], vr["current_y_A"]]

    identifier = md.coSimulation.modelIdentifier
    if md.fmiVersion.startswith("3"):
        fmu = FMU3Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=identifier, instanceName="plant")
        fmu.instantiate()
        fmu.enterInitializationMode(startTime=0.0)
        get, put = fmu.getFloat64, fmu.setFloat64
        get_state, set_state, free_state = fmu.getFMUState, fmu.setFMUState, fmu.freeFMUState
        serialize, deserialize = fmu.serializeFMUState, fmu.deserializeFMUState
    else:
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=identifier, instanceName="plant")
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        get, put = fmu.getReal, fmu.setReal
        get_state, set_state, free_state = fmu.getFMUstate, fmu.setFMUstate, fmu.freeFMUstate
        serialize, deserialize = fmu.serializeFMUstate, fmu.deSerializeFMUstate
    fmu.exitInitializationMode()
    law = PD(design, Params.parse("pd", ""))
    bias = tuple(get(inputs))
    line = [bias] * design.delay_samples
    first = 0
    if args.from_state:
        with open(args.from_state, "rb") as f:
            saved = json.loads(f.readline())
            blob = f.read()
        state = deserialize(blob)
        set_state(state)
        free_state(state)
        first, line, law.prev = saved["tick"], [tuple(c) for c in saved["line"]], saved["prev"]
        law.prev = tuple(law.prev) if law.prev is not None else None

    rows = []
    limit = design.current_limit_a
    for k in range(first, ticks + 1):
        if args.save_at and k == int(args.save_at[0]):
            state = get_state()
            blob = serialize(state)
            free_state(state)
            with open(args.save_at[1], "wb") as f:
                f.write((json.dumps({"tick": k, "line": line, "prev": law.prev}) + "\n").encode())
                f.write(blob)
        y = get(out_vrs)
        if k == ticks:
            rows.append([k, k * period, math.nan, math.nan, *y])
            break
        o = dict(zip(outputs, y))
        ix, iy = law.update(Sample(k, k * period, (o["sensor_x_A"], o["sensor_y_A"]), o["speed"], o["angle"]))
        line.append((saturate(ix, limit), saturate(iy, limit)))
        applied = line.pop(0)
        rows.append([k, k * period, *applied, *y])
        put(inputs, list(applied))
        fmu.doStep(currentCommunicationPoint=k * period, communicationStepSize=period)
    fmu.terminate()
    fmu.freeInstance()

    with open(args.out, "w") as f:
        f.write(",".join(["tick", "t_s", "current_x_A", "current_y_A", *outputs]) + "\n")
        for r in rows:
            f.write(",".join(repr(x) for x in r) + "\n")


if __name__ == "__main__":
    main()
