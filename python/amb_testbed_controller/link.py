"""The iceoryx2 plumbing of the controller side (``controller/src/link.rs`` in Rust).

Services are opened with the settings of ``link.rs``: ``open_or_create``
fails unless both sides ask for the same limits. Waiting spins, then
blocks on an event listener with the wake-request handshake of the
protocol ("Waking a blocked peer"); serving the plant's wake requests is
mandatory (a controller that never notifies makes the plant sleep out its
timed waits on every tick).

What the Python bindings (iceoryx2 0.10.0) lack, and what stands in:

* a memory fence: the handshake needs a sequentially consistent fence
  between publishing and polling. :func:`fence` locks and unlocks a
  process-private pthread mutex through ctypes: POSIX (4.12, "Memory
  Synchronization") makes that synchronize memory; on x86-64 glibc it is a
  locked instruction, a full barrier.
* error variants: an ``open_or_create`` failure is one exception class whose
  text names the variant (``PublishSubscribeOpenError(IncompatibleTypes)``),
  so another protocol version is recognised by that text.
* a service's static configuration: ``Service.details`` gives it only in its
  text form, so the peer's type name (and so its protocol version) is read
  from that text.
"""

import ctypes
import ctypes.util
import re
import time
from collections.abc import Callable
from typing import Any

import iceoryx2 as iox2

from . import wire

BUFFER = 16
"""Samples a subscriber buffers before the oldest is overwritten."""
MAX_PORTS = 4
"""Publishers, subscribers, listeners, notifiers per service."""
MAX_NODES = 8
"""Nodes per service."""


class LinkError(Exception):
    """An iceoryx2 call failed (exit code 1)."""


class Incompatible(LinkError):
    """A service exists with other message types: the peer speaks another protocol version (exit code 2)."""


def version_of(type_name: str) -> int | None:
    """The protocol version in a type name ``amb_testbed.v<N>.<Struct>``."""
    m = re.fullmatch(r"amb_testbed\.v(\d+)\..+", type_name)
    return int(m.group(1)) if m else None


def _peer_type(full: str) -> str | None:
    """The payload type name the existing service ``full`` was created with, if readable."""
    try:
        details = iox2.Service.details(iox2.ServiceName.new(full), iox2.config.global_config(),
                                       iox2.MessagingPattern.PublishSubscribe, iox2.ServiceType.Ipc)
    except Exception:
        return None
    # Its str() is the Rust side's debug dump of the static configuration, type names included.
    found = re.search(r"amb_testbed\.v\d+\.\w+", str(details)) if details is not None else None
    return found.group(0) if found else None


def incompatible_message(full: str, peer_type: str | None) -> str:
    """What a side that finds another version's service says (as ``controller::link`` in Rust)."""
    version = None if peer_type is None else version_of(peer_type)
    if version == wire.PROTOCOL_VERSION:
        peer = f"its type is {peer_type}: this protocol version, but another message on this service"
    elif version is not None:
        peer = f"the peer speaks protocol version {version}: its type is {peer_type}"
    elif peer_type is not None:
        peer = f"its type is {peer_type}, not of this testbed's protocol"
    else:
        peer = "another protocol version"
    return (f"{full}: the peer uses other message types ({peer}; this side speaks version "
            f"{wire.PROTOCOL_VERSION}, type names amb_testbed.v{wire.PROTOCOL_VERSION}.*): "
            "run a plant and a controller of the same protocol version")


def _fail(what: str, e: Exception) -> LinkError:
    return LinkError(f"{what}: {type(e).__name__}: {e}")


class _Fence:
    """A sequentially consistent fence (see the module doc)."""

    def __init__(self) -> None:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or None, use_errno=True)
        self._mutex = ctypes.create_string_buffer(64)  # >= sizeof(pthread_mutex_t) on Linux and BSDs
        if libc.pthread_mutex_init(self._mutex, None) != 0:
            raise LinkError("pthread_mutex_init failed: no memory fence for the wake handshake")
        self._lock, self._unlock = libc.pthread_mutex_lock, libc.pthread_mutex_unlock

    def __call__(self) -> None:
        self._lock(self._mutex)
        self._unlock(self._mutex)


fence = _Fence()


def node(run_id: str, role: str) -> Any:
    """The node ``amb-testbed/<run_id>/<role>``, iceoryx2's signal handling off; dead nodes' leftovers removed."""
    full = wire.name(run_id, role)
    try:
        n = (
            iox2.NodeBuilder.new()
            .name(iox2.NodeName.new(full))
            .signal_handling_mode(iox2.SignalHandlingMode.Disabled)
            .create(iox2.ServiceType.Ipc)
        )
        n.try_cleanup_dead_nodes()
    except Exception as e:
        raise _fail(f"creating node {full}", e) from None
    return n


ALIVE, DEAD, ABSENT = "alive", "dead", "absent"


def peer(run_id: str, role: str) -> str:
    """The state of the node ``amb-testbed/<run_id>/<role>``: ALIVE, DEAD (its leftovers removed) or ABSENT.

    Costs a directory listing: call it when the peer is silent, not per message.
    A failed listing proves nothing and counts as ALIVE.
    """
    wanted = wire.name(run_id, role)
    try:
        states = iox2.Node.list(iox2.ServiceType.Ipc, iox2.config.global_config())
    except Exception:
        return ALIVE
    dead = False
    for state in states:
        view = state[0]
        details = view.details
        if details is None or details.name.as_str() != wanted:
            continue
        if isinstance(state, iox2.NodeState.Alive):
            return ALIVE
        if isinstance(state, iox2.NodeState.Dead):
            dead = True
            try:
                view.try_remove_stale_resources()
            except Exception:
                pass  # another process may be cleaning it up already
    return DEAD if dead else ABSENT


def _pubsub(n: Any, run_id: str, what: str, payload: type[ctypes.Structure]) -> Any:
    full = wire.name(run_id, what)
    try:
        return (
            n.service_builder(iox2.ServiceName.new(full))
            .publish_subscribe(payload)
            .subscriber_max_buffer_size(BUFFER)
            .history_size(0)
            .enable_safe_overflow(True)
            .max_publishers(MAX_PORTS)
            .max_subscribers(MAX_PORTS)
            .max_nodes(MAX_NODES)
            .open_or_create()
        )
    except iox2.PublishSubscribeOpenOrCreateError as e:
        if "IncompatibleTypes" in str(e):
            raise Incompatible(incompatible_message(full, _peer_type(full))) from None
        raise _fail(f"opening service {full}", e) from None


def _event(n: Any, run_id: str, what: str) -> Any:
    full = wire.name(run_id, what)
    try:
        return (
            n.service_builder(iox2.ServiceName.new(full))
            .event()
            .max_notifiers(MAX_PORTS)
            .max_listeners(MAX_PORTS)
            .max_nodes(MAX_NODES)
            .open_or_create()
        )
    except Exception as e:
        raise _fail(f"opening event service {full}", e) from None


class Mailbox:
    """A publisher of ``tx_type`` on ``<run_id>/<tx>`` and a subscriber of ``rx_type`` on ``<run_id>/<rx>``, polled."""

    def __init__(self, n: Any, run_id: str, tx: str, rx: str, tx_type: type[ctypes.Structure],
                 rx_type: type[ctypes.Structure]) -> None:
        self.tx_name, self.rx_name = wire.name(run_id, tx), wire.name(run_id, rx)
        tx_service = _pubsub(n, run_id, tx, tx_type)
        rx_service = _pubsub(n, run_id, rx, rx_type)
        try:
            self.publisher = tx_service.publisher_builder().create()
            self.subscriber = rx_service.subscriber_builder().create()
        except Exception as e:
            raise _fail(f"ports on {self.tx_name} and {self.rx_name}", e) from None
        self._rx = rx_type()
        self._rx_size = ctypes.sizeof(rx_type)
        self._rx_address = ctypes.addressof(self._rx)

    def send(self, message: ctypes.Structure) -> None:
        """Publishes a message (copied into a loaned sample)."""
        self.publisher.send_copy(message)

    def try_receive(self) -> Any:
        """The next message, copied out (the sample is released), or ``None``.

        The returned structure is reused by the next call: copy what you keep.
        """
        sample = self.subscriber.receive()
        if sample is None:
            return None
        ctypes.memmove(self._rx_address, sample.payload_ptr, self._rx_size)
        sample.delete()
        return self._rx


class Endpoint:
    """One side of a frame stream pair: sends on ``tx``, waits on ``rx``, spinning then blocking.

    The wake handshake: before blocking, publish a ``WakeRequest`` on
    ``<rx>/wake``, fence, poll once more, then block on the ``rx`` event
    listener; after sending, fence, drain ``<tx>/wake`` and notify the ``tx``
    event service if it held a request.
    """

    def __init__(self, n: Any, run_id: str, tx: str, rx: str, tx_type: type[ctypes.Structure],
                 rx_type: type[ctypes.Structure], spin_ns: int) -> None:
        self.mail = Mailbox(n, run_id, tx, rx, tx_type, rx_type)
        try:
            self.notifier = _event(n, run_id, tx).notifier_builder().create()
            self.listener = _event(n, run_id, rx).listener_builder().create()
            self.wake_out = _pubsub(n, run_id, f"{rx}/wake", wire.WakeRequest).publisher_builder().create()
            self.wake_in = _pubsub(n, run_id, f"{tx}/wake", wire.WakeRequest).subscriber_builder().create()
        except LinkError:
            raise
        except Exception as e:
            raise _fail(f"event and wake ports of {wire.name(run_id, tx)} and {wire.name(run_id, rx)}", e) from None
        self.spin_max = self.spin = spin_ns
        self.blocks = 0
        self._request = wire.WakeRequest(seq=0)

    def set_spin(self, spin_ns: int) -> None:
        """Sets the busy-poll budget before blocking (ns)."""
        self.spin_max = self.spin = spin_ns

    def send(self, frame: ctypes.Structure) -> None:
        """Publishes a frame, then notifies the peer if it asked to be woken."""
        self.mail.send(frame)
        fence()
        asked = False
        receive = self.wake_in.receive
        while (request := receive()) is not None:
            request.delete()
            asked = True
        if asked:
            self.notifier.notify()

    def send_and_wake(self, frame: ctypes.Structure) -> None:
        """Publishes a frame and always notifies (the last frame of a run)."""
        self.mail.send(frame)
        while (request := self.wake_in.receive()) is not None:
            request.delete()
        self.notifier.notify()

    def wait(self, slice_: Any, keep_waiting: Callable[[], bool]) -> Any:
        """The next frame: busy-polls for the spin budget, then blocks in slices of ``slice_``
        (an ``iceoryx2.Duration``), calling ``keep_waiting()`` after each; ``None`` when it says stop.

        The budget adapts as in ``link.rs``: a wait that lasted ``w <= spin_max``
        raises the next budget to ``2 w``, a longer one halves it.
        """
        try_receive = self.mail.try_receive
        frame = try_receive()
        if frame is not None:
            return frame
        now = time.perf_counter_ns
        start = now()
        deadline = start + self.spin
        while now() < deadline:
            frame = try_receive()
            if frame is not None:
                break
        else:
            frame = self._block(slice_, keep_waiting)
        waited = now() - start
        self.spin = min(max(self.spin, 2 * waited), self.spin_max) if waited <= self.spin_max else self.spin // 2
        return frame

    def _block(self, slice_: Any, keep_waiting: Callable[[], bool]) -> Any:
        self.blocks += 1
        try_receive = self.mail.try_receive
        while True:
            self.wake_out.send_copy(self._request)
            fence()
            frame = try_receive()
            if frame is not None:
                return frame
            try:
                self.listener.timed_wait(slice_)
            except iox2.ListenerWaitError as e:
                # A signal ends the slice early (keep_waiting decides); anything else is a failure.
                if "Interrupt" not in str(e):
                    raise _fail(f"waiting on {self.mail.rx_name}", e) from None
            frame = try_receive()
            if frame is not None:
                return frame
            if not keep_waiting():
                return None
