"""What a law is built from and what it gets each tick; why it refuses to be built.

A law (:class:`Law`) is a class with a ``name`` (its ``controller.law``),
built as ``Law(design, params)`` from one bearing plane's :class:`Design`
and its own parameters (:class:`Params`, the scene's
``[controller.params]``), with a method ``update(sample) -> (i_x, i_y)``:
that plane's coil currents (A) before the amplifier limit, which the kit
applies. On the planar model (2 axes) it is the whole controller; on a
two-plane rotor (4 axes) the kit builds it once per plane, each from its
plane's design, and feeds each its plane's pair (decentralised). A class
may say ``axes = (2,)`` to drive the planar model only: the kit then
refuses a 4-axis hello (code 3). A law of the whole rotor
(:class:`RotorLaw`, ``whole_rotor = True``) is built as
``Law(rotor_design, params)`` from the :class:`RotorDesign` and answers
``update(rotor_sample)`` with every axis's current. Every sample carries
the keyphasor (the rotor's speed and angle). State lives in the object;
time comes in the sample, never from a clock. Refuse a design with
:class:`DesignError` and a parameter with ``params.error(...)`` (a
:class:`ParamError`); the kit answers the plant's hello with the refusal.
"""

import math
import tomllib
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol

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
    """The rotor mass this bearing carries m_r (kg): the planar model's mass, a plane's share on
    a two-plane rotor."""
    gravity_m_s2: float
    """Gravity g (m/s²)."""
    air_gap_m: float
    """Radial air gap r_0 of the touchdown bearing (m): the radius at which the rotor touches."""


@dataclass(frozen=True)
class Design:
    """One bearing plane's loop design a law is built from (``controller::Design`` in Rust)."""

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
        """Plane A's design (the planar design of a planar hello)."""
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


    def plane_b(self, h: "wire.Hello") -> "Design":
        """Plane B's design from a two-plane hello, sharing this (plane A's) period, delay,
        gravity bias switch and gravity."""
        return Design(
            stiffness_n_per_m=h.b_stiffness_n_per_m,
            damping_ratio=h.b_damping_ratio,
            period_s=self.period_s,
            gravity_bias=self.gravity_bias,
            current_limit_a=h.b_current_limit_a,
            delay_samples=self.delay_samples,
            constants=LoopConstants(
                ki_n_per_a=h.b_ki_n_per_a,
                ks_n_per_m=h.b_ks_n_per_m,
                amp_gain_a_per_v=h.b_amp_gain_a_per_v,
                sensor_gain_v_per_m=h.b_sensor_gain_v_per_m,
                rotor_mass_kg=h.b_rotor_mass_kg,
                gravity_m_s2=self.constants.gravity_m_s2,
                air_gap_m=h.b_air_gap_m,
            ),
        )


@dataclass(frozen=True)
class Geometry:
    """A two-plane rotor's geometry and inertia (SI; ``controller::Geometry`` in Rust).
    Stations are along z from the centre of mass, plane A on the negative side."""

    mass_kg: float
    """The whole rotor's mass M (kg)."""
    transverse_inertia_kg_m2: float
    """I_t about the centre of mass (kg m²)."""
    polar_inertia_kg_m2: float
    """I_p (kg m²)."""
    rated_speed_rad_s: float
    """Rated spin speed (rad/s)."""
    bearing_z_m: tuple[float, float]
    """Stations of bearings A and B (m), z_A < z_B."""
    sensor_z_m: tuple[float, float]
    """Stations of sensors A and B (m)."""


@dataclass(frozen=True)
class RotorDesign:
    """The whole rotor's design (``controller::RotorDesign`` in Rust): one :class:`Design` per
    bearing plane (A, then B) and, for a two-plane rotor, its :class:`Geometry`."""

    planes: tuple[Design, ...]
    geometry: Geometry | None

    @property
    def axes(self) -> int:
        """2 (planar) or 4 (two-plane)."""
        return 2 * len(self.planes)

    @classmethod
    def from_hello(cls, h: "wire.Hello") -> "RotorDesign":
        """The design a hello of 2 or 4 axes carries."""
        a = Design.from_hello(h)
        if h.axes != wire.TWO_PLANE_AXES:
            return cls(planes=(a,), geometry=None)
        geometry = Geometry(
            mass_kg=h.total_mass_kg,
            transverse_inertia_kg_m2=h.transverse_inertia_kg_m2,
            polar_inertia_kg_m2=h.polar_inertia_kg_m2,
            rated_speed_rad_s=h.rated_speed_rad_s,
            bearing_z_m=(h.bearing_a_z_m, h.bearing_b_z_m),
            sensor_z_m=(h.sensor_a_z_m, h.sensor_b_z_m),
        )
        return cls(planes=(a, a.plane_b(h)), geometry=geometry)


class Sample:
    """One controller input of a per-plane law: sample index, its simulated time (s), the
    plane's sensor voltages (V, x then y) and the keyphasor: the rotor's speed (rad/s) and angle
    (rad, in [0, 2π), 0 when the unbalance points along +x)."""

    __slots__ = ("seq", "t_s", "sensor_v", "speed_rad_s", "angle_rad")

    def __init__(self, seq: int, t_s: float, sensor_v: tuple[float, float], speed_rad_s: float = 0.0,
                 angle_rad: float = 0.0):
        self.seq = seq
        self.t_s = t_s
        self.sensor_v = sensor_v
        self.speed_rad_s = speed_rad_s
        self.angle_rad = angle_rad

    def __repr__(self) -> str:
        return (f"Sample(seq={self.seq}, t_s={self.t_s!r}, sensor_v={self.sensor_v!r}, "
                f"speed_rad_s={self.speed_rad_s!r}, angle_rad={self.angle_rad!r})")


class RotorSample:
    """One controller input of a law of the whole rotor: every axis's sensor voltage (V), in
    axis order (x, y or x_A, y_A, x_B, y_B), with the keyphasor."""

    __slots__ = ("seq", "t_s", "sensor_v", "speed_rad_s", "angle_rad")

    def __init__(self, seq: int, t_s: float, sensor_v: tuple[float, ...], speed_rad_s: float, angle_rad: float):
        self.seq = seq
        self.t_s = t_s
        self.sensor_v = sensor_v
        self.speed_rad_s = speed_rad_s
        self.angle_rad = angle_rad

    @property
    def axes(self) -> int:
        return len(self.sensor_v)

    def plane(self, p: int) -> Sample:
        """Bearing plane ``p``'s sample (0 = A, 1 = B)."""
        return Sample(self.seq, self.t_s, (self.sensor_v[2 * p], self.sensor_v[2 * p + 1]), self.speed_rad_s,
                      self.angle_rad)


class Law(Protocol):
    """A per-plane law, as :func:`amb_testbed_controller.serve` takes it: a class with these
    members, built as ``Law(design, params)``."""

    name: ClassVar[str]

    def __init__(self, design: Design, params: "Params") -> None: ...

    def update(self, sample: Sample) -> tuple[float, float]:
        """The plane's coil currents (A), x then y, before the amplifier limit."""
        ...


class RotorLaw(Protocol):
    """A law of the whole rotor: ``whole_rotor = True``, built as ``Law(rotor_design, params)``."""

    name: ClassVar[str]
    whole_rotor: ClassVar[bool]

    def __init__(self, design: RotorDesign, params: "Params") -> None: ...

    def update(self, sample: RotorSample) -> Sequence[float]:
        """Every axis's coil current (A) in axis order, before the amplifier limits."""
        ...


LawClass = type[Law] | type[RotorLaw]
"""What ``serve`` takes: law classes of either kind."""


class DesignError(Exception):
    """A value of the common design is out of range for this law (Ack status 5, law rejected)."""

    def __init__(self, key: str, value: float, unit: str, why: str) -> None:
        super().__init__(f"{key} = {_number(value)}{_unit(unit)}: {why}")


class ParamError(Exception):
    """One of the law's parameters is refused (Ack status 7, parameters rejected)."""


def toml_value(v: Any) -> str:
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

    FINITE: ClassVar["Check"]
    POSITIVE: ClassVar["Check"]
    NON_NEGATIVE: ClassVar["Check"]

    def __init__(self, holds: Callable[[float], bool], why: str) -> None:
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

    def __init__(self, law: str, table: dict[str, Any]) -> None:
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

    def error(self, key: str, value: Any, unit: str, why: str) -> ParamError:
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
    """Clamps a current to ``|i| <= limit`` (A); a non-finite one (NaN, ±inf) becomes NaN, as
    Rust's ``controller::saturate``: no current at all, which the plant holds, counts and judges
    as an invalid command (never +inf clamped into a valid full-scale current).

    >>> saturate(3.0, 2.0), saturate(-0.5, 2.0)
    (2.0, -0.5)
    >>> saturate(float("inf"), 2.0), saturate(float("-inf"), 2.0), saturate(float("nan"), 2.0)
    (nan, nan, nan)
    """
    if i - i != 0.0:  # NaN or ±inf (inf - inf is NaN), without a call in the frame loop
        return math.nan
    return limit if i > limit else -limit if i < -limit else i
