"""Builds tests/fmu/pd.c as a planar FMI 2.0 co-simulation controller FMU (scripts/bench/fmu.sh).

    python3 pd_fmu.py OUT.fmu

Compiles the C ``pd`` that tests/tests/fmu_controller.rs builds (``cc``, -O2) and zips it with
its modelDescription.xml (the value references of pd.c), as that test does.
"""

import os
import subprocess
import sys
import tempfile
import zipfile

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")


def model_description() -> str:
    def var(name: str, vr: int, causality: str, ty: str, extra: str) -> str:
        fixed = ' variability="fixed"' if causality == "parameter" else ""
        return (
            f'    <ScalarVariable name="{name}" valueReference="{vr}" causality="{causality}"{fixed}>'
            f"<{ty}{extra}/></ScalarVariable>\n"
        )

    vs = var("sensor_x", 1, "input", "Real", ' start="0"') + var("sensor_y", 2, "input", "Real", ' start="0"')
    vs += var("speed", 10, "input", "Real", ' start="0"') + var("angle", 11, "input", "Real", ' start="0"')
    vs += var("time", 12, "input", "Real", ' start="0"')
    vs += var("current_x", 20, "output", "Real", "") + var("current_y", 21, "output", "Real", "")
    params = [("kp", 30), ("kd", 31), ("amp_gain", 32), ("bias_y", 33), ("kp_b", 34), ("kd_b", 35)]
    params += [("amp_gain_b", 36), ("bias_y_b", 37), ("tau", 38)]
    for name, vr in params:
        vs += var(name, vr, "parameter", "Real", ' start="1"')
    vs += var("fault", 40, "parameter", "Integer", ' start="0"')
    vs += var("fault_tick", 41, "parameter", "Integer", ' start="0"')
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<fmiModelDescription fmiVersion="2.0" modelName="pd" guid="{pd-cs}">\n'
        '  <CoSimulation modelIdentifier="pd"/>\n'
        f"  <ModelVariables>\n{vs}  </ModelVariables>\n"
        "</fmiModelDescription>\n"
    )


def main() -> None:
    out = sys.argv[1]
    with tempfile.TemporaryDirectory() as tmp:
        so = os.path.join(tmp, "pd.so")
        subprocess.run(
            ["cc", "-std=c11", "-O2", "-ffp-contract=off", "-shared", "-fPIC", "-DAXES=2", "-DFMI=2"]
            + [os.path.join(ROOT, "tests", "fmu", "pd.c"), "-o", so, "-lm"],
            check=True,
        )
        with zipfile.ZipFile(out, "w", zipfile.ZIP_STORED) as z:
            z.writestr("modelDescription.xml", model_description())
            z.write(so, "binaries/linux64/pd.so")


if __name__ == "__main__":
    main()
