"""The kit is typed: mypy --strict passes on it, and the law protocol catches a law whose update
returns the wrong thing."""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

KIT = Path(__file__).resolve().parent.parent


def mypy(*args: str) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, MYPY_CACHE_DIR=os.environ.get("MYPY_CACHE_DIR", str(KIT / ".mypy_cache")))
    return subprocess.run([sys.executable, "-m", "mypy", "--config-file", str(KIT / "pyproject.toml"), *args],
                          cwd=KIT, capture_output=True, text=True, env=env, timeout=600)


def test_the_kit_passes_mypy_strict() -> None:
    r = mypy("amb_testbed_controller")
    assert r.returncode == 0, r.stdout + r.stderr


def test_the_law_protocol_checks_a_users_law(tmp_path: Path) -> None:
    good = tmp_path / "good.py"
    good.write_text(textwrap.dedent("""
        from typing import ClassVar
        from amb_testbed_controller import Design, Law, Params, Sample, serve

        class Mine:
            name: ClassVar[str] = "mine"
            def __init__(self, design: Design, params: Params) -> None:
                self.k = design.stiffness_n_per_m
            def update(self, sample: Sample) -> tuple[float, float]:
                return (-self.k * sample.sensor_v[0], sample.speed_rad_s * 0.0)

        law: type[Law] = Mine
        def main() -> None:
            serve(Mine)
    """))
    r = mypy(str(good))
    assert r.returncode == 0, r.stdout + r.stderr
    bad = tmp_path / "bad.py"
    bad.write_text(good.read_text().replace("-> tuple[float, float]:", "-> str:").replace(
        "return (-self.k * sample.sensor_v[0], sample.speed_rad_s * 0.0)", "return 'no'"))
    r = mypy(str(bad))
    assert r.returncode != 0 and "Mine" in r.stdout, r.stdout
