"""The plant's derivative in Python: a peer of plant/src/model.rs.

The same model on the same state layout, read from a peer spec written by
``cargo run --release -p plant --example peer_dump``:

    y = [x_r, y_r, θ_r, x_b, y_b, θ_b,  ẋ_r, ẏ_r, ω_r, ẋ_b, ẏ_b, ω_b]

positions relative to the housing (the housing frame is accelerated by the
shock; each body feels −m a_h), continuous PD inside the derivative, current
saturated at ±i_max. Every formula follows the Rust kernels operation by
operation (same association order, δ^(3/2) as δ·√δ, δ^(10/9) via pow, the
same precomputed ball pitch angles, the same early exits), so that the two
agree to rounding — in practice bit for bit, since both call the platform's
libm for sin, cos and pow.

One source, two back ends: ``_deriv`` is compiled by numba (``@njit``) when
numba is importable and ``use_numba`` is true; otherwise the very same
function runs under CPython on Python floats (the pure-Python fallback, also
used to measure the numba speed-up). Set ``PEER_NO_NUMBA=1`` to force the
fallback everywhere.
"""

from __future__ import annotations

import json
import math
import os

import numpy as np

try:  # numba is optional: without it the pure-Python path runs.
    import numba

    HAVE_NUMBA = os.environ.get("PEER_NO_NUMBA", "") not in ("1", "true", "yes")
except ImportError:  # pragma: no cover
    numba = None
    HAVE_NUMBA = False

N = 12
XR, YR, TR, XB, YB, TB, VXR, VYR, WR, VXB, VYB, WB = range(N)
STATE_NAMES = ["x_r", "y_r", "theta_r", "x_b", "y_b", "theta_b", "vx_r", "vy_r", "w_r", "vx_b", "vy_b", "w_b"]

PI = math.pi
TAU = 2.0 * math.pi  # == std::f64::consts::TAU exactly

# Indices into the float parameter vector P (all SI).
(
    P_G, P_M, P_E, P_JR, P_SPEED, P_DRIVE_GAIN, P_TORQUE_LIMIT,
    P_MB, P_JB, P_CAGE_PHASE, P_CAGE_RATIO,
    P_GAP, P_RR, P_RIN, P_KR, P_CR_MAX, P_CR_DEPTH, P_MU_S, P_MU_D, P_V_S, P_V_D,
    P_RCL, P_KB, P_CB_MAX, P_CB_DEPTH,
    P_DRAG_TORQUE, P_DRAG_REG, P_PALM_F0, P_PALM_NU0, P_PALM_F1, P_PALM_DM,
    P_KI, P_KS, P_NL_K, P_NL_I0, P_NL_S0, P_NL_FLIM,
    P_AS, P_KP, P_KD, P_AA, P_BIAS_X, P_BIAS_Y, P_ILIM,
    P_L_RCL, P_L_K, P_L_CMAX, P_L_DEPTH,
    P_LEN,
) = range(49)

# Indices into the integer flag vector F.
F_SPIN_FREE, F_CAGE_FIXED, F_DRAG_PALMGREN, F_AMB_NONLINEAR, F_NBALLS, F_NSHOCKS, F_SUPPORT_LUMPED, F_LEN = range(8)

# Shock table: 7 numbers per double half-sine, flattened.
S_START, S_UX, S_UY, S_A1, S_A2, S_T1, S_T2, S_LEN = range(8)


# --------------------------------------------------------------------------
# Kernels. Plain functions on floats, so that they run under numba and under
# CPython alike. Each mirrors the Rust function named in its docstring.
# --------------------------------------------------------------------------


def _step(x, x0, h0, x1, h1):
    """plant::force::smooth::step."""
    if x <= x0:
        return h0
    elif x >= x1:
        return h1
    else:
        eta = (x - x0) / (x1 - x0)
        return h0 + (h1 - h0) * eta * eta * (3.0 - 2.0 * eta)


def _fmax(a, b):
    """f64::max for non-NaN operands."""
    return a if a >= b else b


def _fmin(a, b):
    """f64::min for non-NaN operands."""
    return a if a <= b else b


def _clamp(x, lo, hi):
    """f64::clamp."""
    if x < lo:
        x = lo
    if x > hi:
        x = hi
    return x


def _friction(v, mu_s, mu_d, v_s, v_d):
    """plant::force::friction::Friction::coefficient."""
    speed = abs(v)
    if speed >= v_d:
        return math.copysign(mu_d, v)
    elif speed >= v_s:
        return math.copysign(_step(speed, v_s, mu_s, v_d, mu_d), v)
    else:
        return _step(v, -v_s, -mu_s, v_s, mu_s)


def _dhs_accel(a1, a2, t1, t2, t):
    """shock_table::DoubleHalfSine::accel (half_sine_accel: p · sin(π/T · τ))."""
    if t < 0.0 or t >= t2:
        return 0.0
    elif t < t1:
        return a1 * math.sin(PI / t1 * t)
    else:
        return a2 * math.sin(PI / (t2 - t1) * (t - t1))


def _amb_axis(d, i, k, i0, s0, flim):
    """The nonlinear branch of plant::force::amb::AmbLaw::force, one axis."""
    plus = _fmax(i0 + i, 0.0)
    minus = _fmax(i0 - i, 0.0)
    gap_plus = _fmax(s0 - d, 1e-3 * s0)
    gap_minus = _fmax(s0 + d, 1e-3 * s0)
    pull_plus = _fmin(k * plus * plus / (gap_plus * gap_plus), flim)
    pull_minus = _fmin(k * minus * minus / (gap_minus * gap_minus), flim)
    return pull_plus - pull_minus


def _drag(omega, load, P, palmgren):
    """plant::force::drag::RaceDrag::torque."""
    if palmgren:
        f0 = P[P_PALM_F0]
        nu0 = P[P_PALM_NU0]
        dm = P[P_PALM_DM]
        rpm = abs(omega) * 60.0 / TAU
        if nu0 * rpm >= 2000.0:
            viscous = 1e-7 * f0 * math.pow(nu0 * rpm, 2.0 / 3.0) * (dm * dm * dm)
        else:
            viscous = 160e-7 * f0 * (dm * dm * dm)
        load_part = P[P_PALM_F1] * abs(load) * dm
        magnitude = (viscous + load_part) * 1e-3
    else:
        magnitude = P[P_DRAG_TORQUE]
    reg = P[P_DRAG_REG]
    return -magnitude * _step(omega, -reg, -1.0, reg, 1.0)


def _deriv(t, y, P, F, pcos, psin, shocks, dy):
    """plant::model::Model::evaluate(t, y).dy with Control::Continuous(gains), into dy."""
    # Housing acceleration: shock_table::Programme::accel.
    ahx = 0.0
    ahy = 0.0
    for j in range(F[F_NSHOCKS]):
        o = S_LEN * j
        tau = t - shocks[o + S_START]
        if tau >= 0.0:
            ai = _dhs_accel(shocks[o + S_A1], shocks[o + S_A2], shocks[o + S_T1], shocks[o + S_T2], tau)
            ahx += ai * shocks[o + S_UX]
            ahy += ai * shocks[o + S_UY]

    # Continuous PD (controller::PdGains::current), saturated (controller::saturate).
    a_s = P[P_AS]
    u0 = a_s * y[XR]
    u1 = a_s * y[YR]
    ud0 = a_s * y[VXR]
    ud1 = a_s * y[VYR]
    aa = P[P_AA]
    kp = P[P_KP]
    kd = P[P_KD]
    ilim = P[P_ILIM]
    i0 = _clamp(P[P_BIAS_X] - aa * (kp * u0 + kd * ud0), -ilim, ilim)
    i1 = _clamp(P[P_BIAS_Y] - aa * (kp * u1 + kd * ud1), -ilim, ilim)

    # AMB force.
    if F[F_AMB_NONLINEAR]:
        amb0 = _amb_axis(y[XR], i0, P[P_NL_K], P[P_NL_I0], P[P_NL_S0], P[P_NL_FLIM])
        amb1 = _amb_axis(y[YR], i1, P[P_NL_K], P[P_NL_I0], P[P_NL_S0], P[P_NL_FLIM])
    else:
        ki = P[P_KI]
        ks = P[P_KS]
        amb0 = ki * i0 + ks * y[XR]
        amb1 = ki * i1 + ks * y[YR]

    # Rotor – race contact: plant::force::rotor_race::RotorRace::force.
    d0 = y[XR] - y[XB]
    d1 = y[YR] - y[YB]
    dv0 = y[VXR] - y[VXB]
    dv1 = y[VYR] - y[VYB]
    gap = P[P_GAP]
    on_rotor0 = 0.0
    on_rotor1 = 0.0
    torque_rotor = 0.0
    torque_race = 0.0
    dist2 = d0 * d0 + d1 * d1
    if dist2 > gap * gap:
        dist = math.sqrt(dist2)
        delta = dist - gap
        n0 = d0 / dist
        n1 = d1 / dist
        t0 = -n1
        t1 = n0
        delta_dot = dv0 * n0 + dv1 * n1
        damping = _step(delta, 0.0, 0.0, P[P_CR_DEPTH], P[P_CR_MAX])
        normal = _fmax(P[P_KR] * math.pow(delta, 10.0 / 9.0) + damping * delta_dot, 0.0)
        slip = dv0 * t0 + dv1 * t1 + y[WR] * P[P_RR] - y[WB] * P[P_RIN]
        tangential = _friction(slip, P[P_MU_S], P[P_MU_D], P[P_V_S], P[P_V_D]) * normal
        on_rotor0 = -normal * n0 - tangential * t0
        on_rotor1 = -normal * n1 - tangential * t1
        torque_rotor = -P[P_RR] * tangential
        torque_race = P[P_RIN] * tangential

    # Cage.
    if F[F_CAGE_FIXED]:
        cage = P[P_CAGE_PHASE]
        cage_rate = 0.0
    else:
        cage = P[P_CAGE_PHASE] + P[P_CAGE_RATIO] * y[TB]
        cage_rate = P[P_CAGE_RATIO] * y[WB]

    # Race support: plant::model::Params::race_support.
    ex = y[XB]
    ey = y[YB]
    rcl = P[P_RCL]
    ball0 = 0.0
    ball1 = 0.0
    if F[F_SUPPORT_LUMPED]:
        # plant::force::lumped::LumpedSupport::force: an isotropic Hertz ring.
        lc = P[P_L_RCL]
        r2 = ex * ex + ey * ey
        if r2 > lc * lc:
            r = math.sqrt(r2)
            n0 = ex / r
            n1 = ey / r
            delta = r - lc
            delta_dot = y[VXB] * n0 + y[VYB] * n1
            damping = _step(delta, 0.0, 0.0, P[P_L_DEPTH], P[P_L_CMAX])
            load = _fmax(P[P_L_K] * delta * math.sqrt(delta) + damping * delta_dot, 0.0)
            ball0 = -load * n0
            ball1 = -load * n1
    elif ex * ex + ey * ey > rcl * rcl:
        # plant::force::balls::BallSet::force (in the cage frame).
        s0 = math.sin(cage)
        c0 = math.cos(cage)
        a = ex * c0 + ey * s0
        b = ey * c0 - ex * s0
        a_dot = y[VXB] * c0 + y[VYB] * s0 + cage_rate * b
        b_dot = y[VYB] * c0 - y[VXB] * s0 - cage_rate * a
        kb = P[P_KB]
        cb_depth = P[P_CB_DEPTH]
        cb_max = P[P_CB_MAX]
        sum_c = 0.0
        sum_s = 0.0
        for k in range(F[F_NBALLS]):
            cp = pcos[k]
            sp = psin[k]
            delta = a * cp + b * sp - rcl
            if delta <= 0.0:
                continue
            delta_dot = a_dot * cp + b_dot * sp
            damping = _step(delta, 0.0, 0.0, cb_depth, cb_max)
            load = _fmax(kb * delta * math.sqrt(delta) + damping * delta_dot, 0.0)
            sum_c += load * cp
            sum_s += load * sp
        ball0 = -(c0 * sum_c - s0 * sum_s)
        ball1 = -(s0 * sum_c + c0 * sum_s)

    # Rotor (plant::model).
    m = P[P_M]
    e = P[P_E]
    g = P[P_G]
    s = math.sin(y[TR])
    c = math.cos(y[TR])
    w = y[WR]
    r1 = m * e * w * w * c + amb0 + on_rotor0 - m * ahx
    r2 = m * e * w * w * s + amb1 + on_rotor1 - m * (g + ahy)
    if F[F_SPIN_FREE]:
        tl = P[P_TORQUE_LIMIT]
        drive = _clamp(P[P_DRIVE_GAIN] * (P[P_SPEED] - w), -tl, tl)
        r3 = drive + torque_rotor - m * e * ((g + ahy) * c - ahx * s)
        spin_accel = (r3 + e * (s * r1 - c * r2)) / P[P_JR]
    else:
        spin_accel = 0.0

    # Race.
    mb = P[P_MB]
    race_load = math.sqrt(ball0 * ball0 + ball1 * ball1)
    race_torque = torque_race + _drag(y[WB], race_load, P, F[F_DRAG_PALMGREN])

    for k in range(6):
        dy[k] = y[k + 6]
    dy[VXR] = (r1 + m * e * s * spin_accel) / m
    dy[VYR] = (r2 - m * e * c * spin_accel) / m
    dy[WR] = spin_accel
    dy[VXB] = (ball0 - on_rotor0) / mb - ahx
    dy[VYB] = (ball1 - on_rotor1) / mb - g - ahy
    dy[WB] = race_torque / P[P_JB]


def _rhs_alloc(t, y, P, F, pcos, psin, shocks):
    dy = np.empty(N)
    _deriv(t, y, P, F, pcos, psin, shocks, dy)
    return dy


def _build_numba():
    """Compiled copies of the kernels, in a namespace of their own."""
    import builtins
    import types

    ns = {"__builtins__": builtins, "math": math, "np": np, "PI": PI, "TAU": TAU}
    # Integer constants are frozen into the compiled code. fastmath stays off: no FMA
    # contraction or reassociation, which the bit-for-bit agreement with Rust relies on.
    for k, v in globals().items():
        if k.startswith(("P_", "F_", "S_")) or k in ("N", "XR", "YR", "TR", "XB", "YB", "TB", "VXR", "VYR", "WR",
                                                     "VXB", "VYB", "WB"):
            ns[k] = v
    order = ["_step", "_fmax", "_fmin", "_clamp", "_friction", "_dhs_accel", "_amb_axis", "_drag", "_deriv",
             "_rhs_alloc"]
    out = {}
    for name in order:
        f = globals()[name]
        g = types.FunctionType(f.__code__, ns, name, f.__defaults__, f.__closure__)
        jf = numba.njit(cache=False, nogil=True, fastmath=False, error_model="numpy")(g)
        ns[name] = jf
        out[name] = jf
    return out


_NB = None


def numba_kernels():
    """The numba-compiled kernels (compiled on first use)."""
    global _NB
    if _NB is None:
        if not HAVE_NUMBA:
            raise RuntimeError("numba is not available")
        _NB = _build_numba()
    return _NB


# --------------------------------------------------------------------------
# The spec and the model object.
# --------------------------------------------------------------------------


def load_spec(path):
    with open(path) as f:
        return json.load(f)


def pack(spec):
    """The spec's parameters as (P float64[P_LEN], F int64[F_LEN], pcos, psin, shocks) arrays."""
    p = spec["params"]
    P = np.zeros(P_LEN)
    F = np.zeros(F_LEN, dtype=np.int64)
    P[P_G] = p["gravity"]
    P[P_M] = p["rotor_mass"]
    P[P_E] = p["eccentricity"]
    P[P_JR] = p["rotor_inertia"]
    P[P_SPEED] = p["speed"]
    spin = p["spin"]
    if spin["spin"] == "held":
        F[F_SPIN_FREE] = 0
    elif spin["spin"] == "free":
        F[F_SPIN_FREE] = 1
        P[P_DRIVE_GAIN] = spin["drive_gain"]
        P[P_TORQUE_LIMIT] = spin["torque_limit"]
    else:
        raise ValueError(f"unknown spin {spin!r}")
    P[P_MB] = p["race_mass"]
    P[P_JB] = p["race_inertia"]
    if p["cage"] == "rotating":
        F[F_CAGE_FIXED] = 0
    elif p["cage"] == "fixed":
        F[F_CAGE_FIXED] = 1
    else:
        raise ValueError(f"unknown cage {p['cage']!r}")
    P[P_CAGE_PHASE] = p["cage_phase"]
    P[P_CAGE_RATIO] = p["cage_ratio"]
    ct = p["contact"]
    P[P_GAP] = ct["gap"]
    P[P_RR] = ct["rotor_radius"]
    P[P_RIN] = ct["bore_radius"]
    P[P_KR] = ct["stiffness"]
    P[P_CR_MAX] = ct["damping_max"]
    P[P_CR_DEPTH] = ct["damping_depth"]
    fr = ct["friction"]
    P[P_MU_S] = fr["mu_static"]
    P[P_MU_D] = fr["mu_dynamic"]
    P[P_V_S] = fr["v_static"]
    P[P_V_D] = fr["v_dynamic"]
    b = p["balls"]
    z = int(spec.get("ball_count", b.get("count")))
    if "count" in b and int(b["count"]) != z:
        raise ValueError("ball_count and params.balls.count disagree")
    P[P_RCL] = b["clearance"]
    P[P_KB] = b["stiffness"]
    P[P_CB_MAX] = b["damping_max"]
    P[P_CB_DEPTH] = b["damping_depth"]
    F[F_NBALLS] = z
    sup = p.get("support", {"support": "balls"})  # specs from before the support switch: balls
    if sup["support"] == "balls":
        F[F_SUPPORT_LUMPED] = 0
    elif sup["support"] == "lumped":
        F[F_SUPPORT_LUMPED] = 1
        P[P_L_RCL] = sup["clearance"]
        P[P_L_K] = sup["stiffness"]
        P[P_L_CMAX] = sup["damping_max"]
        P[P_L_DEPTH] = sup["damping_depth"]
    else:
        raise ValueError(f"unknown race support {sup!r}")
    dr = p["drag"]
    if dr["model"] == "constant":
        F[F_DRAG_PALMGREN] = 0
        P[P_DRAG_TORQUE] = dr["torque"]
    elif dr["model"] == "palmgren":
        F[F_DRAG_PALMGREN] = 1
        P[P_PALM_F0] = dr["f0"]
        P[P_PALM_NU0] = dr["nu0_cst"]
        P[P_PALM_F1] = dr["f1"]
        P[P_PALM_DM] = dr["pitch_diameter_mm"]
    else:
        raise ValueError(f"unknown drag {dr!r}")
    P[P_DRAG_REG] = dr["reg_speed"]
    amb = p["amb"]
    if amb["law"] == "linear":
        F[F_AMB_NONLINEAR] = 0
        P[P_KI] = amb["ki"]
        P[P_KS] = amb["ks"]
    elif amb["law"] == "nonlinear":
        F[F_AMB_NONLINEAR] = 1
        P[P_NL_K] = amb["k"]
        P[P_NL_I0] = amb["i0"]
        P[P_NL_S0] = amb["s0"]
        P[P_NL_FLIM] = amb["force_limit"]
    else:
        raise ValueError(f"unknown AMB law {amb!r}")
    P[P_AS] = p["loop_constants"]["sensor_gain_v_per_m"]
    gains = spec["gains"]
    P[P_KP] = gains["kp"]
    P[P_KD] = gains["kd"]
    P[P_AA] = gains["amp_gain_a_per_v"]
    P[P_BIAS_X] = gains["bias_a"][0]
    P[P_BIAS_Y] = gains["bias_a"][1]
    P[P_ILIM] = spec["current_limit_a"]
    # Ball pitch tables as BallSet::new builds them: sin_cos(TAU * i / z).
    pcos = np.array([math.cos(TAU * i / z) for i in range(z)])
    psin = np.array([math.sin(TAU * i / z) for i in range(z)])
    shocks = []
    for sh in spec["shocks"]:
        if sh["kind"] != "double_half_sine":
            raise ValueError(f"unsupported shock kind {sh['kind']!r}")
        row = [0.0] * S_LEN
        row[S_START] = sh["start_s"]
        row[S_UX], row[S_UY] = sh["unit"]
        row[S_A1] = sh["a1"]
        row[S_A2] = sh["a2"]
        row[S_T1] = sh["t1"]
        row[S_T2] = sh["t2"]
        shocks.extend(row)
    F[F_NSHOCKS] = len(spec["shocks"])
    return P, F, pcos, psin, np.array(shocks, dtype=np.float64)


class Model:
    """The derivative of a peer spec.

    ``rhs(t, y)`` returns a new float64 array, the signature scipy's
    ``solve_ivp`` calls. ``use_numba=False`` (or ``PEER_NO_NUMBA=1``) runs the
    same source under CPython.
    """

    def __init__(self, spec, use_numba=True):
        if isinstance(spec, (str, os.PathLike)):
            spec = load_spec(spec)
        self.spec = spec
        self.P, self.F, self.pcos, self.psin, self.shocks = pack(spec)
        self.use_numba = bool(use_numba and HAVE_NUMBA)
        self.y0 = np.array(spec["y0"], dtype=np.float64)
        self.duration = float(spec["duration_s"])
        self.r0 = float(spec["params"]["contact"]["gap"])
        if self.use_numba:
            # A two-argument compiled entry point with the parameter arrays frozen in as
            # constants: numba's dispatcher checks the type of every argument on each call,
            # and with seven arguments that costs more than the derivative itself.
            import builtins

            ns = {"__builtins__": builtins, "_k": numba_kernels()["_rhs_alloc"], "_P": self.P, "_F": self.F,
                  "_pc": self.pcos, "_ps": self.psin, "_sh": self.shocks}
            exec("def rhs(t, y):\n    return _k(t, y, _P, _F, _pc, _ps, _sh)\n", ns)
            rhs = numba.njit(nogil=True, error_model="numpy")(ns["rhs"])
        else:
            P, F, pc, ps, sh = (self.P.tolist(), self.F.tolist(), self.pcos.tolist(), self.psin.tolist(),
                                self.shocks.tolist())

            def rhs(t, y):
                out = [0.0] * N
                _deriv(float(t), y.tolist(), P, F, pc, ps, sh, out)
                return np.array(out)

        self.rhs = rhs

    def warm_up(self):
        """Compiles (numba) and runs the derivative once."""
        return self.rhs(0.0, self.y0)
