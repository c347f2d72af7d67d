"""``serve(Law)``: a complete controller process for one run of the plant.

Handshake (hello → ack, refusals with their codes and messages), one reply
per sensor frame with the wake protocol, liveness of the plant's node,
signals and exit codes, as the Rust ``controller`` binary
(``controller/src/main.rs``):

====  =====================================================================
code  meaning
====  =====================================================================
0     the plant ended the run (a STOP frame)
1     an IPC failure
2     bad input: a bad argument, a run id held by another live controller, a
      refused hello (it was told why), a plant of another protocol version, a
      law that answers a sample with the wrong number of currents (not one per
      axis: the frame would drop some or feed another plane)
4     the plant is gone (its node died or vanished), or no hello came in time
130   SIGINT or SIGTERM (the plant is told with a STOPPING frame)
====  =====================================================================

Command line: ``--run-id ID`` (default: ``$AMB_TESTBED_RUN_ID``, which the
plant sets for a ``controller.command``), ``--connect-timeout-s S`` (default
``$AMB_TESTBED_CONNECT_TIMEOUT_S``, else 30), ``--quiet``. With
``AMB_TESTBED_REALTIME_PRIORITY=N`` (1 to 99; 0 is off) the process puts
itself under ``SCHED_FIFO`` at N and locks its memory, with a warning for
each step the system refuses.
"""

import argparse
import contextlib
import ctypes
import ctypes.util
import fcntl
import math
import os
import signal
import sys
import time
import traceback
from collections.abc import Sequence
from types import FrameType
from typing import Any, NoReturn, TextIO

import iceoryx2 as iox2

from . import link, wire
from .law import DesignError, LawClass, ParamError, Params, RotorDesign, RotorSample, Sample, saturate

OK, IO, BAD_INPUT, PLANT_LOST, INTERRUPTED = 0, 1, 2, 4, 130

LIVENESS_EVERY_NS = 20_000_000
"""How often a silent plant is looked up by its node (a directory listing)."""
SLICE = iox2.Duration.from_millis(1)
"""Slice of a blocking wait: the longest a signal goes unnoticed while blocked."""
HELLO_POLL_S = 0.001


class Ending(Exception):
    """An ending that is not a success, with its exit code."""

    code = IO


class BadInput(Ending):
    code = BAD_INPUT


class PlantLost(Ending):
    code = PLANT_LOST


class WrongCount(BadInput):
    """A law answered a sample with another number of currents than it drives (exit 2): never
    sent, since a frame of the wrong count would drop currents or feed one plane another's."""


def _count(law: str, got: Any, want: int, what: str, seq: int, t_s: float) -> None:
    """Raises :class:`WrongCount` unless ``got`` holds ``want`` currents."""
    try:
        if len(got) == want:
            return
        n = len(got)
    except TypeError:
        raise WrongCount(f"law {law} answered sample {seq} (t = {t_s} s) with {got!r}, not a sequence of "
                         f"{want} currents ({what})") from None
    raise WrongCount(f"law {law} answered sample {seq} (t = {t_s} s) with {n} currents, {list(got)!r} A; "
                         f"it must answer {want} ({what}): refused, nothing sent")


class Interrupted(Ending):
    code = INTERRUPTED


class _Signals:
    """SIGINT/SIGTERM set a flag, polled by the loops (as the Rust binary's ctrlc handler)."""

    def __init__(self) -> None:
        self.stop = False
        for s in (signal.SIGINT, signal.SIGTERM):
            signal.signal(s, self._handle)

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        self.stop = True


def serve(*laws: LawClass, argv: Sequence[str] | None = None) -> NoReturn:
    """Serves one run of the plant with the law the hello names among ``laws`` (classes), then exits.

    A per-plane law class (:class:`~amb_testbed_controller.law.Law`) has a ``name`` (its
    ``controller.law``), is built as ``Law(design, params)`` and answers
    ``update(sample) -> (i_x, i_y)``; on a two-plane rotor it runs once per plane. A law of the
    whole rotor (:class:`~amb_testbed_controller.law.RotorLaw`) has ``whole_rotor = True``.
    """
    sys.exit(run(laws, argv))


def run(laws: Sequence[LawClass], argv: Sequence[str] | None = None) -> int:
    """As :func:`serve`, returning the exit code instead of exiting."""
    prog = os.path.basename(sys.argv[0]) or "controller"
    iox2.set_log_level_from_env_or(iox2.LogLevel.Fatal)
    signals = _Signals()
    try:
        options = _options(prog, argv)
        _serve(laws, options, signals)
        return OK
    except link.Incompatible as e:
        code, text = BAD_INPUT, f"error: {e}"
    except link.LinkError as e:
        code, text = IO, f"error: {e}"
    except (PlantLost, Interrupted) as e:
        code, text = e.code, str(e)
    except Ending as e:
        code, text = e.code, f"error: {e}"
    except IOX2_ERRORS as e:
        code, text = IO, f"error: IPC failure: {type(e).__name__}: {e}"
    print(f"{prog}: {text}", file=sys.stderr)
    return code


IOX2_ERRORS: tuple[type[Exception], ...] = tuple(
    c for c in vars(iox2).values()
    if isinstance(c, type) and issubclass(c, Exception) and c.__module__.startswith("iceoryx2")
)
"""The exception classes of the iceoryx2 bindings: an IPC failure (exit code 1)."""

_PASSED_ON: tuple[type[Exception], ...] = (Ending, link.LinkError, *IOX2_ERRORS)
"""What the frame loop lets through as it is (any other exception is the law's failure)."""


def _options(prog: str, argv: Sequence[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog=prog, description="AMB controller process (Python): serves one plant run over iceoryx2")
    parser.add_argument("--run-id", default=os.environ.get("AMB_TESTBED_RUN_ID"),
                        help="the run id (default: $AMB_TESTBED_RUN_ID)")
    parser.add_argument("--connect-timeout-s", type=float, default=os.environ.get("AMB_TESTBED_CONNECT_TIMEOUT_S", "30"),
                        help="how long to wait for the plant's hello, s (default: $AMB_TESTBED_CONNECT_TIMEOUT_S, else 30)")
    parser.add_argument("--quiet", action="store_true", help="no start-up and end lines")
    o = parser.parse_args(None if argv is None else list(argv))  # exits 2 with a usage message on a bad argument
    if o.run_id is None:
        raise BadInput("--run-id: missing (and AMB_TESTBED_RUN_ID is not set)")
    try:
        wire.valid_run_id(o.run_id)
    except ValueError as e:
        raise BadInput(str(e)) from None
    t = float(o.connect_timeout_s)
    if not (math.isfinite(t) and 0.0 < t <= 1e6):
        raise BadInput(f"--connect-timeout-s {o.connect_timeout_s} s: must be a finite number > 0 and <= 1e6")
    o.connect_timeout_s = t
    o.prog = prog
    text = os.environ.get(REALTIME_PRIORITY_ENV, "0")
    try:
        o.realtime_priority = int(text)
    except ValueError:
        o.realtime_priority = -1
    if not 0 <= o.realtime_priority <= 99:
        raise BadInput(f"{REALTIME_PRIORITY_ENV}={text}: must be an integer from 0 (off) to 99")
    return o


REALTIME_PRIORITY_ENV = "AMB_TESTBED_REALTIME_PRIORITY"


def realtime(priority: int) -> list[str]:
    """``SCHED_FIFO`` at ``priority`` and ``mlockall``: what the system refused, step by step."""
    refused = []
    try:
        if os.sched_getscheduler(0) != os.SCHED_FIFO:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except OSError as e:
        refused.append(f"SCHED_FIFO at priority {priority}: {e.strerror}")
    libc = ctypes.CDLL(ctypes.util.find_library("c") or None, use_errno=True)
    mcl_current, mcl_future = 1, 2  # <sys/mman.h> on Linux
    if libc.mlockall(mcl_current | mcl_future) != 0:
        refused.append(f"mlockall: {os.strerror(ctypes.get_errno())}")
    return refused


Refusal = tuple[int, str]
"""A refusal code (``wire.VERSION``, …) and its message."""


def _check_hello(h: wire.Hello, run_id: str) -> Refusal | None:
    """``(refusal code, message)`` if this controller cannot serve the hello, else ``None``."""
    if h.protocol_version != wire.PROTOCOL_VERSION:
        return wire.VERSION, (f"protocol version {h.protocol_version} from the plant, "
                              f"this controller speaks {wire.PROTOCOL_VERSION}")
    if h.axes not in wire.SUPPORTED_AXES:
        return wire.AXES_MISMATCH, f"the plant has {h.axes} axes, this controller drives 2 or 4"
    if h.units != wire.UNITS_SI:
        return wire.UNITS, f"units code {h.units} from the plant, this controller uses {wire.UNITS_SI} (SI)"
    got = wire.str_of(h.run_id)
    if got != run_id:
        return wire.RUN_ID, f"hello for run id {got!r}, this controller serves {run_id!r}"
    return None


class _Decentralised:
    """Per-plane laws side by side: plane p's law reads and drives axes 2p, 2p + 1."""

    whole_rotor = True

    def __init__(self, planes: list[Any]) -> None:
        self.planes = planes
        self.name = planes[0].name

    def update(self, sample: RotorSample) -> tuple[float, ...]:
        out: list[float] = []
        for p, law in enumerate(self.planes):
            currents = law.update(sample.plane(p))
            _count(self.name, currents, 2, f"i_x, i_y of plane {'AB'[p]}", sample.seq, sample.t_s)
            out.extend(currents)
        return tuple(out)


def _build(laws: Sequence[LawClass], hello: wire.Hello) -> tuple[Any, None] | tuple[None, Refusal]:
    """The law the hello asks for, built for its rotor (a per-plane law once per plane); or
    ``(None, (refusal code, message))``."""
    name = wire.str_of(hello.law)
    by_name = {law.name: law for law in laws}
    if name not in by_name:
        return None, (wire.LAW, f"unknown controller law `{name}` (this controller serves {', '.join(by_name)})")
    cls: Any = by_name[name]
    drives = tuple(getattr(cls, "axes", wire.SUPPORTED_AXES))
    if hello.axes not in drives:
        return None, (wire.AXES_MISMATCH, f"law {name} drives {' or '.join(map(str, drives))} axes; "
                                          f"the plant has {hello.axes} axes")
    try:
        design = RotorDesign.from_hello(hello)
        text = hello.params_text()
        if getattr(cls, "whole_rotor", False):
            params = Params.parse(name, text)
            law = cls(design, params)
            params.finish()
            return law, None
        planes = []
        for plane in design.planes:
            params = Params.parse(name, text)
            planes.append(cls(plane, params))
            params.finish()
        return (planes[0] if len(planes) == 1 else _Decentralised(planes)), None
    except UnicodeDecodeError as e:
        return None, (wire.PARAMS, f"the [controller.params] document is not UTF-8: {e}")
    except ParamError as e:
        return None, (wire.PARAMS, str(e))
    except DesignError as e:
        return None, (wire.LAW, f"law {name}: {e}")
    except Exception as e:
        traceback.print_exc()
        return None, (wire.LAW, f"law {name} could not be built: {type(e).__name__}: {e}")


def _limits(design: RotorDesign) -> tuple[float, ...]:
    """Each axis's current limit (A), in axis order."""
    return tuple(plane.current_limit_a for plane in design.planes for _ in (0, 1))


def _describe(name: str, design: RotorDesign, rate_hz: float) -> str:
    a = design.planes[0]
    if len(design.planes) == 1:
        return (f"{name} (Python): k_e = {a.stiffness_n_per_m} N/m, xi_e = {a.damping_ratio}, "
                f"i_max = {a.current_limit_a} A at {rate_hz} Hz")
    b = design.planes[1]
    return (f"{name} (Python): 4 axes, k_e = {a.stiffness_n_per_m} / {b.stiffness_n_per_m} N/m, "
            f"xi_e = {a.damping_ratio} / {b.damping_ratio}, i_max = {a.current_limit_a} / {b.current_limit_a} A "
            f"(planes A / B) at {rate_hz} Hz")


def _ack(hello: wire.Hello, status: int, law: str, message: str) -> wire.Ack:
    return wire.Ack(
        protocol_version=wire.PROTOCOL_VERSION,
        session=hello.session,
        status=status,
        controller_pid=os.getpid() & 0xFFFF_FFFF,
        token=hello.token,
        law=wire.fixed_str(law, wire.LAW_NAME_LEN),
        message=wire.fixed_str(message, wire.MESSAGE_LEN),
        overrides_len=0,  # this kit runs what the hello asks, nothing else
    )


def lock_run_id(run_id: str, role: str = "controller") -> "_RunLock":
    """Takes ``<lock dir>/<run_id>.<role>.lock`` with an exclusive ``flock``, as the Rust side does
    (``controller/src/lock.rs``): one live controller per run id. The lock dir is
    ``$AMB_TESTBED_LOCK_DIR``, else ``$TMPDIR/amb-testbed`` (``/tmp/amb-testbed``). The kernel
    releases the lock when the process ends, however it ends. Returns the held lock (keep it:
    it deletes its file and releases the lock when it goes).
    """
    folder = os.environ.get("AMB_TESTBED_LOCK_DIR") or os.path.join(os.environ.get("TMPDIR") or "/tmp", "amb-testbed")
    path = os.path.join(folder, f"{run_id}.{role}.lock")
    try:
        if not os.path.isdir(folder):
            os.makedirs(folder, exist_ok=True)
            with contextlib.suppress(OSError):
                os.chmod(folder, 0o1777)  # machine-wide like /tmp: any user may add a lock
    except OSError as e:
        raise Ending(f"cannot lock run id {run_id} ({path}): {e}") from None
    # A holder deletes its file when it releases it (controller/src/lock.rs): a lock taken on a
    # file that was deleted between our open and our lock is not the run id's; start again.
    for _ in range(100):
        try:
            file = open(path, "a+")
        except OSError as e:
            raise Ending(f"cannot lock run id {run_id} ({path}): {e}") from None
        try:
            fcntl.flock(file, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            file.seek(0)
            holder = file.read().strip() or "a process that has not written its name yet"
            file.close()
            raise BadInput(f"run id {run_id} is in use by a live {role}: {holder} (lock {path}); "
                           "pick another --run-id or stop that process") from None
        except OSError as e:
            file.close()
            raise Ending(f"cannot lock run id {run_id} ({path}): {e}") from None
        named: os.stat_result | None
        try:
            named = os.stat(path)
        except OSError:
            named = None
        mine = os.fstat(file.fileno())
        if named is not None and (named.st_dev, named.st_ino) == (mine.st_dev, mine.st_ino):
            break
        file.close()
    else:
        raise Ending(f"cannot lock run id {run_id} ({path}): the file was deleted under this process 100 times")
    file.truncate(0)
    file.write(f"pid {os.getpid()} ({' '.join(sys.argv)})\n")
    file.flush()
    return _RunLock(file)


class _RunLock:
    """A held run-id lock: when it goes, it deletes its file while still holding it, then
    releases it, so that nothing is left behind (a process killed outright leaves its file to
    the next Rust plant or controller, which deletes the files of dead holders)."""

    def __init__(self, file: TextIO) -> None:
        self.file = file

    def __del__(self) -> None:
        with contextlib.suppress(OSError):
            os.unlink(self.file.name)
        self.file.close()


def _serve(laws: Sequence[LawClass], o: argparse.Namespace, signals: _Signals) -> None:
    run_id = o.run_id
    _lock = lock_run_id(run_id)  # held while the process serves
    if o.realtime_priority > 0:
        for refused in realtime(o.realtime_priority):
            print(f"{o.prog}: warning: {REALTIME_PRIORITY_ENV}={o.realtime_priority}: {refused}; carrying on without it",
                  file=sys.stderr)
    node = link.node(run_id, "controller")
    handshake = link.Mailbox(node, run_id, "ack", "hello", wire.Ack, wire.Hello)
    frames = link.Endpoint(node, run_id, "command", "sensor", wire.CommandFrame, wire.SensorFrame, 200_000)

    # Hello: wait for the plant.
    deadline = time.monotonic() + o.connect_timeout_s
    while (received := handshake.try_receive()) is None:
        if signals.stop:
            raise Interrupted(f"interrupted; stopped before run {run_id} began")
        if time.monotonic() > deadline:
            raise PlantLost(
                f"no hello from a plant with run id {run_id} within {o.connect_timeout_s} s "
                f"(start it with `plant run SCENE --controller external --run-id {run_id}`); exiting"
            )
        time.sleep(HELLO_POLL_S)
    hello = wire.Hello.from_buffer_copy(received)

    refusal = _check_hello(hello, run_id)
    law = None
    if refusal is None:
        law, refusal = _build(laws, hello)
    if refusal is not None:
        code, message = refusal
        handshake.send(_ack(hello, code, "", message))
        raise BadInput(f"refused the plant's hello ({wire.REFUSAL[code]}): {message}")

    assert law is not None  # built, since nothing refused it
    design = RotorDesign.from_hello(hello)
    description = _describe(law.name, design, hello.rate_hz)
    handshake.send(_ack(hello, wire.ACCEPTED, law.name, description))
    frames.set_spin(hello.spin_ns)
    if not o.quiet:
        print(f"{o.prog}: serving run {run_id} (session {hello.session}, pid {os.getpid()}): {description}",
              file=sys.stderr)
    _loop(law, frames, hello.session, hello.token, hello.axes, _limits(design), run_id, o, signals)


def _loop(law: Any, frames: link.Endpoint, session: int, token: int, axes: int, limits: tuple[float, ...],
          run_id: str, o: argparse.Namespace, signals: _Signals) -> None:
    """One reply per sensor frame until STOP (returns), a signal or a lost plant (raises)."""
    now = time.monotonic_ns
    state: dict[str, Any] = {"heard": now(), "checked": now(), "lost": None}

    def keep_waiting() -> bool:
        if signals.stop:
            return False
        t = now()
        if t - state["checked"] >= LIVENESS_EVERY_NS and t - state["heard"] >= LIVENESS_EVERY_NS:
            state["checked"] = t
            seen = link.peer(run_id, "plant")
            if seen != link.ALIVE:
                state["lost"] = (f"the plant of run {run_id} died (its node is dead)" if seen == link.DEAD
                                 else f"the plant of run {run_id} is gone (its node no longer exists)")
                return False
        return True

    reply = wire.CommandFrame(token=token, session=session, axes=axes)
    current = reply.current_a
    update = law.update
    whole_rotor = getattr(law, "whole_rotor", False)
    name = law.name
    what = "one per axis: x_A, y_A, x_B, y_B" if axes == 4 else "i_x, i_y"
    limit = limits[0]
    stop_bit = wire.SensorFrame.STOP
    answered = 0
    try:
        while True:
            if signals.stop:
                frames.send_and_wake(wire.CommandFrame(status=wire.CommandFrame.STOPPING, session=session,
                                                       token=token, axes=axes, sent_ns=now()))
                raise Interrupted(f"interrupted; told the plant (run {run_id}) and stopped")
            frame = frames.wait(SLICE, keep_waiting)
            if frame is None:
                if state["lost"] is not None:
                    raise PlantLost(f"{state['lost']}; exiting")
                continue  # a signal: answered at the top of the loop
            if frame.token != token:
                continue  # another run's frame (same run id), or a stale process's: never applied
            state["heard"] = now()
            if frame.status & stop_bit:
                if not o.quiet:
                    print(f"{o.prog}: run {run_id} ended: answered {answered} frames, blocked {frames.blocks} times",
                          file=sys.stderr)
                return
            if frame.session != session:
                continue  # a frame of an earlier session, still in the buffer
            received_ns = now()
            sensor = frame.sensor_v
            if whole_rotor:
                currents = update(RotorSample(frame.seq, frame.t_s, tuple(sensor[:axes]), frame.speed_rad_s,
                                              frame.angle_rad))
                _count(name, currents, axes, what, frame.seq, frame.t_s)
                for k in range(axes):
                    current[k] = saturate(currents[k], limits[k])
            else:
                currents = update(Sample(frame.seq, frame.t_s, (sensor[0], sensor[1]), frame.speed_rad_s,
                                         frame.angle_rad))
                _count(name, currents, 2, "i_x, i_y", frame.seq, frame.t_s)
                ix, iy = currents
                current[0] = saturate(ix, limit)
                current[1] = saturate(iy, limit)
            reply.seq = frame.seq
            reply.received_ns = received_ns
            reply.sent_ns = now()
            frames.send(reply)
            answered += 1
    except _PASSED_ON:
        raise
    except BaseException:
        # A failing law: tell the plant at once (it treats STOPPING as a lost controller), then
        # let the traceback end the process (exit code 1).
        with contextlib.suppress(Exception):
            frames.send_and_wake(wire.CommandFrame(status=wire.CommandFrame.STOPPING, session=session,
                                                   token=token, axes=axes, sent_ns=now()))
        raise
