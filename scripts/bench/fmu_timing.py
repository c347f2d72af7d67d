"""Costs of the plant FMU under FMPy, call by call (issue 29, "Speed"; scripts/bench/fmu.sh).

    python fmu_timing.py plant.fmu [--ticks N] [--save-at K] [--repeats R]

The FMU (``plant fmu SCENE --out plant.fmu``, a planar scene, FMI 2.0 or 3.0) in the closed
loop of ``plant/fmu/python/closed_loop.py`` (the Python kit's ``pd``, saturated and delayed as
``plant run``'s sampled loop), with each part of a tick timed apart: reading the outputs, the
law, setting the inputs and ``doStep``. At tick K (default: 0.5 s) the state is taken, set,
serialised and deserialised R times each and timed (``fmi2GetFMUstate``, ``fmi2SetFMUstate``,
``fmi2SerializeFMUstate``, ``fmi2DeSerializeFMUstate``; FMI 3.0 the same); the loop then goes on
from the state set last, which is the state taken (a restored FMU continues bit for bit).

Prints one JSON object: the loop's wall and process CPU time, each part's mean and median per
tick (µs), each state call's mean and median (µs) and the serialised state's size.
"""

import argparse
import importlib.util
import json
import os
import statistics
import sys
import time
import tomllib

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

from amb_testbed_controller import PD, Params, Sample, saturate

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location(
    "closed_loop", os.path.join(HERE, "..", "..", "plant", "fmu", "python", "closed_loop.py")
)
closed_loop = importlib.util.module_from_spec(spec)
spec.loader.exec_module(closed_loop)


def figures(ns: list[int]) -> dict:
    return {"mean_us": statistics.fmean(ns) / 1e3, "median_us": statistics.median(ns) / 1e3, "count": len(ns)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("fmu")
    ap.add_argument("--ticks", type=int, default=None, help="ticks to run (default: the scene's duration)")
    ap.add_argument("--save-at", type=int, default=None, help="tick of the state calls (default: 0.5 s)")
    ap.add_argument("--repeats", type=int, default=200, help="times each state call is timed")
    args = ap.parse_args()

    md = read_model_description(args.fmu)
    unzipdir = extract(args.fmu)
    with open(f"{unzipdir}/resources/scene.toml", "rb") as f:
        scene = tomllib.load(f)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    design = closed_loop.design_of(scene)
    period = design.period_s
    ticks = args.ticks if args.ticks is not None else round(float(scene["scene"]["duration_s"]) / period)
    save_at = args.save_at if args.save_at is not None else round(0.5 / period)
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    out_vrs = [vr[n] for n in outputs]
    inputs = [vr["current_x_A"], vr["current_y_A"]]
    ix = {n: outputs.index(n) for n in ("sensor_x_A", "sensor_y_A", "speed", "angle")}

    identifier = md.coSimulation.modelIdentifier
    three = md.fmiVersion.startswith("3")
    if three:
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
    limit = design.current_limit_a

    clock = time.perf_counter_ns
    parts: dict[str, list[int]] = {"get_outputs": [], "law": [], "set_inputs": [], "doStep": []}
    state_calls: dict[str, list[int]] = {"get_state": [], "set_state": [], "serialize": [], "deserialize": []}
    size = None
    wall0, cpu0 = time.perf_counter(), time.process_time()
    for k in range(ticks):
        if k == save_at:
            for _ in range(args.repeats):
                t = clock()
                state = get_state()
                state_calls["get_state"].append(clock() - t)
                t = clock()
                set_state(state)
                state_calls["set_state"].append(clock() - t)
                t = clock()
                blob = serialize(state)
                state_calls["serialize"].append(clock() - t)
                free_state(state)
                t = clock()
                again = deserialize(blob)
                state_calls["deserialize"].append(clock() - t)
                set_state(again)
                free_state(again)
                size = len(blob)
        t0 = clock()
        y = get(out_vrs)
        t1 = clock()
        c = law.update(Sample(k, k * period, (y[ix["sensor_x_A"]], y[ix["sensor_y_A"]]), y[ix["speed"]], y[ix["angle"]]))
        line.append((saturate(c[0], limit), saturate(c[1], limit)))
        applied = line.pop(0)
        t2 = clock()
        put(inputs, list(applied))
        t3 = clock()
        fmu.doStep(currentCommunicationPoint=k * period, communicationStepSize=period)
        t4 = clock()
        parts["get_outputs"].append(t1 - t0)
        parts["law"].append(t2 - t1)
        parts["set_inputs"].append(t3 - t2)
        parts["doStep"].append(t4 - t3)
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    last = dict(zip(outputs, get(out_vrs)))
    fmu.terminate()
    fmu.freeInstance()
    print(
        json.dumps(
            {
                "fmu": os.path.basename(args.fmu),
                "fmi": md.fmiVersion,
                "ticks": ticks,
                "simulated_s": ticks * period,
                "loop_wall_s": wall,
                "loop_cpu_s": cpu,
                "realtime_factor": ticks * period / wall,
                "per_tick": {k: figures(v) for k, v in parts.items()},
                "state_at_tick": save_at,
                "state": {k: figures(v) for k, v in state_calls.items()},
                "serialized_bytes": size,
                "last_radius_A_m": last.get("radius_A"),
            },
            indent=1,
        )
    )


if __name__ == "__main__":
    main()
