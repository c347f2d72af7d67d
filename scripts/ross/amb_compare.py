"""ROSS's side of the AMB check (issue 38 item 6, docs/results/ross-amb.md).

Two machines with ROSS's own MagneticBearingElements: ROSS's UFU test rig
(``rotor_example_amb_general_controllers``, its PID) and the testbed's AMB machine
(``fixture.machine()``) with its two springs replaced by elements of hand-chosen parameters
(``OURS``). For each, saved with ``Rotor.save()`` (the file the testbed imports), then:

- ``run_modal`` at rest and at speed with the AMBs' equivalent coefficients evaluated at one
  fixed whirl frequency (``frequency=``), that frequency put in the element's table so no
  interpolation enters; the coefficients ROSS used are written beside its frequencies;
- ``run_amb_sensitivity`` (a logarithmic chirp added to the sensor signal, Newmark time
  response with the element's discrete PID) at rest and at speed on each AMB's first axis, its
  peak over the chirp's band (ROSS's own ``max_abs_sensitivities`` takes every FFT bin, the
  ones outside the band too, and is written as well), and its wall time.

A third machine, ``soft_machine``: the testbed's rotor on smaller actuators with a soft PID
(``SOFT``), whose time response ROSS's Newmark carries through the chirp.

Writes ``<out>/amb_compare.json`` and the three files ``ufu_rig.toml``, ``amb_machine_ambs.toml``,
``soft_machine.toml``. ``ONLY=<name>`` runs one machine again and keeps the others' figures.
Nothing here is computed by the testbed.

    target/ross-venv/bin/python -W ignore scripts/ross/amb_compare.py [OUT]
"""

import importlib.util
import json
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import ross as rs

HERE = Path(__file__).resolve().parent
spec = importlib.util.spec_from_file_location("fixture", HERE / "fixture.py")
fixture = importlib.util.module_from_spec(spec)
spec.loader.exec_module(fixture)

# The whirl frequency at which run_modal evaluates the AMBs' coefficients (rad/s).
F_EVAL = 2.0 * np.pi * 50.0
TABLE = np.union1d(np.logspace(0, 4), [F_EVAL])
MODES = 16  # run_modal's num_modes: 8 frequencies

# The testbed's machine: the actuator tests/tests/ross_ambs.rs gives its elements, with unit
# amplifier and sensor gains and the PID scaled by their product (25 000): the same loop for
# run_modal's equivalent coefficients, and the loop run_amb_sensitivity simulates, whose
# discrete controller (compute_amb_controller, bearing_seal_element.py 3.1.0 l. 2849-2854)
# leaves k_amp and k_sense out.
OURS = dict(g0=1e-3, i0=2.0, ag=2.15e-3, nw=200, alpha=0.39269908, k_amp=1.0, k_sense=1.0,
            kp_pid=7000.0, ki_pid=70000.0, kd_pid=3.325, n_f=5000.0)
# ROSS's UFU rig (amb_models.py, rotor_example_amb_general_controllers without a transfer
# function): its elements' parameters, rebuilt with the evaluation frequency in the table.
UFU = dict(g0=1e-3, i0=1.0, ag=1e-4, nw=200, alpha=0.392, k_amp=1.0, k_sense=1.0,
           kp_pid=1000.0, ki_pid=0.0, kd_pid=5.0)

# A machine of the testbed's own whose loop ROSS's time response simulates to the end (issue 38
# item 6): the same rotor (fixture.machine()) on smaller actuators (i0 = 1 A, ag = 10 cm^2:
# ki = 46.4 N/A, |ks| = 4.64e4 N/m) with a soft PID: a static stiffness ki kp - |ks| = 1.39e5
# N/m, its damping kd at 24 Hz and a derivative filter at n_f = 800 rad/s. The AMB machine's
# stiffer loop (OURS) makes ROSS's Newmark diverge: ROSS's force uses the displacement of the
# step before (one step late), which takes damping from the shaft's undamped high modes (a mode
# near 3.9 kHz grows) in proportion to the loop's gain above n_f, ki (kp + kd n_f): 3.3e6 N/m
# there, 7.1e5 N/m here, whose growth stays below the chirp's response over 2 s.
SOFT = dict(g0=1e-3, i0=1.0, ag=1e-3, nw=200, alpha=0.39269908, k_amp=1.0, k_sense=1.0,
            kp_pid=4000.0, ki_pid=20000.0, kd_pid=14.0, n_f=800.0)

CHIRP = dict(disturbance_min_frequency=5.0, disturbance_max_frequency=200.0, disturbance_amplitude=1e-6)


def ufu_rig():
    base = rs.rotor_example_amb_general_controllers()
    ambs = [
        rs.MagneticBearingElement(n=b.n, frequency=TABLE, tag=b.tag, **UFU)
        for b in base.bearing_elements
    ]
    return rs.Rotor(base.shaft_elements, base.disk_elements, ambs), dict(UFU, n_f=10000.0)


def amb_machine(params=OURS):
    base = fixture.machine()
    ambs = [
        rs.MagneticBearingElement(n=b.n, sensor_node=b.n, frequency=TABLE, tag=b.tag, **params)
        for b in base.bearing_elements
    ]
    return rs.Rotor(base.shaft_elements, base.disk_elements, ambs), params


def soft_machine():
    return amb_machine(SOFT)


def modal(rotor, speed):
    m = rotor.run_modal(speed=speed, num_modes=MODES, frequency=F_EVAL)
    return {"speed_rad_s": float(speed), "wn_rad_s": [float(v) for v in m.wn],
            "wd_rad_s": [float(v) for v in m.wd], "whirl": fixture.whirl_names(m)[: len(m.wd)]}


def sensitivity(rotor, speed, t_max, dt):
    amb = rotor.bearing_elements[0]
    start = time.perf_counter()
    res = rotor.run_amb_sensitivity(speed=speed, t_max=t_max, dt=dt, amb_tags=[amb.tag], verbose=0,
                                    **CHIRP)
    wall = time.perf_counter() - start
    # run_amb_sensitivity runs x and y: the time of one axis is half.
    f = np.asarray(res.sensitivities_frequencies)
    mag = np.asarray(res.sensitivities_abs[amb.tag]["x"])
    band = (f >= 1.2 * CHIRP["disturbance_min_frequency"]) & (f <= CHIRP["disturbance_max_frequency"] / 1.2)
    i = int(np.argmax(np.where(band, mag, 0.0)))
    return {
        "speed_rad_s": float(speed), "amb": amb.tag, "axis": "x (ROSS's v: the sensor axis turned by "
        f"{np.degrees(amb.sensors_axis_rotation):.1f} deg)",
        "t_max_s": t_max, "dt_s": dt,
        "peak_db": float(20.0 * np.log10(mag[i])), "peak_hz": float(f[i]),
        "resolution_hz": float(f[1] - f[0]),
        "ross_max_abs_sensitivity_db": float(20.0 * np.log10(res.max_abs_sensitivities[amb.tag]["x"])),
        "wall_s_both_axes": wall,
    }


def main(out, t_max, dt):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    warnings.simplefilter("ignore")
    result = {"ross_version": rs.__version__, "python_version": sys.version.split()[0],
              "f_eval_rad_s": F_EVAL, "chirp": CHIRP, "machines": {}}
    json_path = out / "amb_compare.json"
    only = os.environ.get("ONLY")  # one machine again, the other's figures kept
    if only and json_path.exists():
        result["machines"] = json.loads(json_path.read_text())["machines"]
    for name, build, speed, dt in (("ufu_rig", ufu_rig, 2 * np.pi * 50.0, dt),
                                   # ROSS's Newmark diverges at 20 kHz on this machine's stiffer loop
                                   ("amb_machine_ambs", amb_machine, 2 * np.pi * 300.0, min(dt, 2e-5)),
                                   ("soft_machine", soft_machine, 2 * np.pi * 300.0, dt)):
        if only and name != only:
            continue
        rotor, params = build()
        toml = out / f"{name}.toml"
        toml.unlink(missing_ok=True)  # save() adds to an existing file
        rotor.save(toml)
        # The rotor as built (Rotor.load gives plain BearingElements back, which
        # run_amb_sensitivity does not take as AMBs).
        amb = rotor.bearing_elements[0]
        at = int(np.argmin(np.abs(TABLE - F_EVAL)))
        k, c = float(amb.k_eq[at]), float(amb.c_eq[at])
        entry = {"rotor_file": toml.name, "params": params, "amb_nodes": [int(b.n) for b in rotor.bearing_elements],
                 "ki_n_per_a": float(amb.ki), "ks_n_per_m": float(amb.ks),
                 "kxx_at_f_eval": k, "cxx_at_f_eval": c, "mass_kg": float(rotor.m),
                 "modal": [modal(rotor, 0.0), modal(rotor, speed)],
                 "sensitivity": [sensitivity(rotor, s, t_max, dt) for s in (0.0, speed)]}
        result["machines"][name] = entry
        for s in entry["sensitivity"]:
            print(f"{name}: speed {s['speed_rad_s'] / (2 * np.pi):.0f} Hz: peak {s['peak_db']:.3f} dB at "
                  f"{s['peak_hz']:.2f} Hz, ROSS's max {s['ross_max_abs_sensitivity_db']:.3f} dB, "
                  f"{s['wall_s_both_axes']:.1f} s (x and y)", flush=True)
        print(f"{name}: modes at rest (Hz):", [round(v / (2 * np.pi), 3) for v in entry["modal"][0]["wd_rad_s"]], flush=True)
    json_path.write_text(json.dumps(result, indent=1) + "\n")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "plant/physics/tests/fixtures/ross",
         float(sys.argv[2]) if len(sys.argv) > 2 else 2.0, float(sys.argv[3]) if len(sys.argv) > 3 else 2e-5)
