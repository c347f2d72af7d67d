"""What a law is built from and what it gets each tick; why it refuses to be built.

A law is a class with a ``name`` (its ``controller.law``), built as
``Law(design, params)`` from the hello's :class:`Design` and its own
parameters (:class:`Params`, the scene's ``[controller.params]``), with a
method ``update(sample) -> (i_x, i_y)``: coil currents (A) before the
amplifier limit, which the kit applies. State lives in the object; time
comes in the sample, never from a clock. Refuse a design with
:class:`DesignError` and a parameter with ``params.error(...)`` (a
:class:`ParamError`); the kit answers the plant's hello with the refusal.
"""

import math
import tomllib
from dataclasses import dataclass

from . import wire


@dataclass(frozen=True)
class LoopConstants:
    """Plant constants a law needs for its design (SI)."""

    ki_n_per_a: float
    """Force-current coefficient k_i (N/A)."""
    ks_n_per_m: float
    """Force-displacement coefficient k_s (N/m)."""
    amp_gain_a_per_v: float
    """Amplifier gain A_a (A/V)."""
    sensor_gain_v_per_m: float
    """Sensor gain A_s (V/m)."""
    rotor_mass_kg: float
    """Rotor mass m_r (kg)."""
    gravity_m_s2: float
    """Gravity g (m/s²)."""
    air_gap_m: float
    """Radial air gap r_0 of the touchdown bearing (m): the radius at which the rotor touches."""


@dataclass(frozen=True)
class Design:
    """The common loop design a law is built from (``controller::Design`` in Rust)."""

    stiffness_n_per_m: float
    """Closed-loop stiffness k_e (N/m)."""
    damping_ratio: float
    """Closed-loop damping ratio ξ_e."""
    period_s: float
    """Sampling period T (s)."""
    gravity_bias: bool
    """Add the gravity bias current m_r g / k_i on the y axis."""
    current_limit_a: float
    """Amplifier limit i_max (A); the kit saturates the law's currents at it."""
    delay_samples: int
    """The command computed from sample k is applied from tick k + delay_samples."""
    constants: LoopConstants

    @classmethod
    def from_hello(cls, h: "wire.Hello") -> "Design":
        return cls(
            stiffness_n_per_m=h.stiffness_n_per_m,
            damping_ratio=h.damping_ratio,
            period_s=h.period_s,
            gravity_bias=h.gravity_bias != 0,
            current_limit_a=h.current_limit_a,
            delay_samples=h.delay_samples,
            constants=LoopConstants(
                ki_n_per_a=h.ki_n_per_a,
                ks_n_per_m=h.ks_n_per_m,
                amp_gain_a_per_v=h.amp_gain_a_per_v,
                sensor_gain_v_per_m=h.sensor_gain_v_per_m,
                rotor_mass_kg=h.rotor_mass_kg,
                gravity_m_s2=h.gravity_m_s2,
                air_gap_m=h.air_gap_m,
            ),
        )


class Sample:
    """One controller input: sample index, its simulated time (s), sensor voltages (V, x then y)."""

    __slots__ = ("seq", "t_s", "sensor_v")

    def __init__(self, seq: int, t_s: float, sensor_v: tuple[float, float]):
        self.seq = seq
        self.t_s = t_s
        self.sensor_v = sensor_v

    def __repr__(self) -> str:
        return f"Sample(seq={self.seq}, t_s={self.t_s!r}, sensor_v={self.sensor_v!r})"


class DesignError(Exception):
    """A value of the common design is out of range for this law (Ack status 5, law rejected)."""

    def __init__(self, key: str, value: float, unit: str, why: str):
        super().__init__(f"{key} = {_number(value)}{_unit(unit)}: {why}")


class ParamError(Exception):
    """One of the law's parameters is refused (Ack status 7, parameters rejected)."""


def toml_value(v) -> str:
    """A TOML value as it would be written in the scene (for messages)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {toml_value(x)}" for k, x in v.items()) + " }"
    return str(v)  # dates and times


def _number(x: float) -> str:
    return repr(x)[:-2] if isinstance(x, float) and x.is_integer() and abs(x) < 1e16 else repr(x)


def _unit(unit: str) -> str:
    return f" {unit}" if unit else ""


class Check:
    """The range a number must lie in (``controller::Check`` in Rust)."""

    def __init__(self, holds, why: str):
        self.holds, self.why = holds, why

    @staticmethod
    def between(lo: float, hi: float) -> "Check":
        """Strictly between ``lo`` and ``hi``."""
        return Check(lambda v: lo < v < hi, f"must be > {_number(lo)} and < {_number(hi)}")


Check.FINITE = Check(lambda v: True, "must be finite")
Check.POSITIVE = Check(lambda v: v > 0.0, "must be a finite number > 0")
Check.NON_NEGATIVE = Check(lambda v: v >= 0.0, "must be a finite number >= 0")


class Params:
    """A law's own parameters, the scene's ``[controller.params]`` table, read key by key.

    Each getter takes the key, its unit and its default, and checks the value;
    the kit refuses every key the law did not read (:meth:`finish`). Errors
    name the law, the key, the value and the unit, as the Rust laws' do:

    >>> p = Params.parse("relev_py", "hold_ms = -5.0")
    >>> p.number("hold_ms", "ms", 50.0, Check.NON_NEGATIVE)
    Traceback (most recent call last):
    ...
    amb_testbed_controller.law.ParamError: law relev_py: controller.params.hold_ms = -5.0 ms: must be a finite number >= 0
    """

    def __init__(self, law: str, table: dict):
        self.law = law
        self.table = table
        self.read: list[str] = []

    @classmethod
    def parse(cls, law: str, text: str) -> "Params":
        """Parameters of ``law`` from a TOML document; :class:`ParamError` if it is not TOML."""
        if len(text.encode()) > wire.PARAMS_LEN:
            raise ParamError(
                f"the [controller.params] table is {len(text.encode())} bytes as TOML text: "
                f"the limit is {wire.PARAMS_LEN} bytes"
            )
        try:
            return cls(law, tomllib.loads(text))
        except tomllib.TOMLDecodeError as e:
            raise ParamError(f"the [controller.params] document is not valid TOML: {e}") from None

    def error(self, key: str, value, unit: str, why: str) -> ParamError:
        """An error about ``key``, whose value is ``value`` (a TOML value), in ``unit``."""
        return ParamError(f"law {self.law}: controller.params.{key} = {toml_value(value)}{_unit(unit)}: {why}")

    def number(self, key: str, unit: str, default: float, check: Check = Check.FINITE) -> float:
        """The number at ``key`` (an integer is taken as a float), or ``default`` when absent; checked."""
        self.read.append(key)
        if key not in self.table:
            return default
        value = self.table[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.error(key, value, unit, f"expected a number ({unit or 'dimensionless'})")
        v = float(value)
        if not (math.isfinite(v) and check.holds(v)):
            raise self.error(key, value, unit, check.why)
        return v

    def flag(self, key: str, default: bool) -> bool:
        """The boolean at ``key``, or ``default`` when absent."""
        self.read.append(key)
        value = self.table.get(key, default)
        if not isinstance(value, bool):
            raise self.error(key, value, "", "expected true or false")
        return value

    def finish(self) -> None:
        """Refuses the first key that was not read, naming it and the keys the law reads."""
        for key, value in self.table.items():
            if key not in self.read:
                known = ", ".join(self.read) or "no parameters"
                raise ParamError(
                    f"law {self.law}: unknown parameter controller.params.{key} = {toml_value(value)} "
                    f"(law {self.law} reads {known})"
                )


def saturate(i: float, limit: float) -> float:
    """Clamps a current to ``|i| <= limit`` (A); NaN stays NaN, as Rust's ``f64::clamp``."""
    return limit if i > limit else -limit if i < -limit else i
