"""ROSS's side of the flexible rotor's check (docs/results/flexible-rotor.md).

For each rotor: builds it in ROSS, saves it with ``Rotor.save()`` (the file our reader takes),
runs ``run_modal`` (at rest and at each Campbell speed) and ``run_campbell`` (0 to 500 Hz, the
first six modes, damped natural frequencies, forward and backward), and writes ROSS's figures
to ``<name>.json`` beside the ``.toml``. Run by ``scripts/ross/fixture.sh`` with ROSS 3.1.0 and
with ROSS 2.3.0 (the same rotors, each version's file and figures); nothing here is computed by
the testbed.
"""

import json
import sys
import warnings
from pathlib import Path

import numpy as np
import ross as rs

SPEEDS_HZ = np.linspace(0.0, 500.0, 11)
CAMPBELL_MODES = 6
MODAL_MODES = 12  # run_modal's num_modes: num_modes // 2 = 6 frequencies


def machine():
    """An AMB machine rotor like the testbed's two-plane machine (config/two-plane-*.toml):
    0.46 m long, about 23 kg, bearings 360 mm apart at 50 mm and 410 mm from the left end,
    a motor's lamination stack as three disks in the middle, a thrust collar at the left end
    and an impeller at the right end; a stepped shaft (40 mm journals, a 50 mm body, a conical
    step, a hollow end). Bearings as linear springs: the study's closed-loop stiffness
    k_e = 1e6 N/m and damping 68 N s/m (xi_e = 0.01 on an 11.5 kg share) per bearing."""
    steel = rs.Material(name="Steel", rho=7810.0, E=211e9, G_s=81.2e9)
    # (length, idl, odl, idr, odr) in m; nodes at 0, 25, 50, 80, ..., 380, 410, 435, 460 mm.
    rows = [(0.025, 0.0, 0.040, 0.0, 0.040), (0.025, 0.0, 0.040, 0.0, 0.040), (0.030, 0.0, 0.040, 0.0, 0.040)]
    rows += [(0.030, 0.0, 0.050, 0.0, 0.050)] * 10
    rows += [(0.030, 0.0, 0.050, 0.0, 0.040)]  # the conical step, 380 to 410 mm
    rows += [(0.025, 0.0, 0.040, 0.0, 0.040), (0.025, 0.020, 0.040, 0.020, 0.040)]  # hollow end
    shaft = [
        rs.ShaftElement(L=L, idl=idl, odl=odl, idr=idr, odr=odr, material=steel,
                        shear_effects=True, rotary_inertia=True, gyroscopic=True)
        for (L, idl, odl, idr, odr) in rows
    ]
    disks = [
        rs.DiskElement(n=0, m=1.5, Id=0.6e-3, Ip=1.2e-3, tag="thrust collar"),
        rs.DiskElement(n=5, m=4.0, Id=1.3e-3, Ip=1.7e-3, tag="stack 1"),
        rs.DiskElement(n=6, m=4.0, Id=1.3e-3, Ip=1.7e-3, tag="stack 2"),
        rs.DiskElement(n=7, m=4.0, Id=1.3e-3, Ip=1.7e-3, tag="stack 3"),
        rs.DiskElement(n=16, m=3.0, Id=2.2e-3, Ip=4.0e-3, tag="impeller"),
    ]
    bearings = [
        rs.BearingElement(n=2, kxx=1e6, cxx=68.0, tag="AMB A"),
        rs.BearingElement(n=14, kxx=1e6, cxx=68.0, tag="AMB B"),
    ]
    return rs.Rotor(shaft, disks, bearings)


def amb_element():
    """A shaft with one of ROSS's MagneticBearingElements (its own doctest's actuator: g0 = 1 mm,
    i0 = 1 A, ag = 1 cm², 200 turns, 22.5° poles, a PID with its derivative filter, amplifier
    and sensor gains) and a plain bearing: the file keeps ROSS's frequency-dependent equivalent
    coefficients of the AMB, which the reader's formulas are checked against. Only saved."""
    steel = rs.Material(name="Steel", rho=7810.0, E=211e9, G_s=81.2e9)
    shaft = [rs.ShaftElement(L=0.1, idl=0.0, odl=0.05, material=steel) for _ in range(4)]
    bearings = [
        rs.MagneticBearingElement(n=1, g0=1e-3, i0=1.0, ag=1e-4, nw=200, alpha=0.39269908, kp_pid=2.0,
                                  ki_pid=30.0, kd_pid=3e-3, n_f=5000.0, k_amp=1.5, k_sense=2000.0,
                                  tag="AMB"),
        rs.BearingElement(n=4, kxx=1e6, cxx=10.0, tag="support"),
    ]
    return rs.Rotor(shaft, [], bearings)


def whirl_names(modal):
    names = []
    for shape in modal.shapes:
        if shape.mode_type != "Lateral":
            names.append(None)
        else:
            names.append(str(shape.whirl).lower())
    return names


def figures(rotor):
    speeds = SPEEDS_HZ * 2.0 * np.pi
    at_rest = rotor.run_modal(speed=0.0, num_modes=MODAL_MODES)
    modal = []
    for w in speeds:
        m = rotor.run_modal(speed=w, num_modes=MODAL_MODES)
        modal.append({
            "speed_rad_s": float(w),
            "wn_rad_s": [float(v) for v in m.wn],
            "wd_rad_s": [float(v) for v in m.wd],
            "whirl": whirl_names(m)[: len(m.wd)],
        })
    campbell = rotor.run_campbell(speeds, frequencies=CAMPBELL_MODES)
    whirl_code = {0.0: "forward", 1.0: "backward", 0.5: "mixed"}
    return {
        "ross_version": rs.__version__,
        "python_version": sys.version.split()[0],
        "mass_kg": float(rotor.m),
        "rest": {
            "wn_rad_s": [float(v) for v in at_rest.wn],
            "wd_rad_s": [float(v) for v in at_rest.wd],
            "whirl": whirl_names(at_rest)[: len(at_rest.wd)],
        },
        "modal": modal,
        "campbell": {
            "speeds_rad_s": [float(v) for v in speeds],
            "wd_rad_s": [[float(v) for v in row] for row in campbell.wd],
            "whirl": [[None if np.isnan(v) else whirl_code[float(v)] for v in row] for row in campbell.whirl_values],
        },
    }


def main(out):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    warnings.simplefilter("ignore")
    toml = out / "amb_element.toml"
    toml.unlink(missing_ok=True)
    amb_element().save(toml)
    print(f"amb_element: {toml}")
    for name, rotor in (("rotor_example", rs.rotor_example()), ("amb_machine", machine())):
        toml = out / f"{name}.toml"
        toml.unlink(missing_ok=True)  # save() adds to an existing file
        rotor.save(toml)
        data = figures(rs.Rotor.load(toml))
        data["rotor_file"] = toml.name
        (out / f"{name}.json").write_text(json.dumps(data, indent=1) + "\n")
        print(f"{name}: {toml}, {len(data['campbell']['speeds_rad_s'])} speeds; at rest (Hz):",
              [round(v / (2 * np.pi), 3) for v in data["rest"]["wd_rad_s"]])


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "plant/physics/tests/fixtures/ross")
