//! The iceoryx2 plumbing both processes share: nodes, the services of a run,
//! spin-then-block waiting with the wake-request handshake of
//! [`crate::wire`], and peer liveness.
//!
//! Nothing here knows about the plant or the law; the plant's `cosim` module
//! and the `controller` binary build their loops on [`Endpoint`] and
//! [`Mailbox`].
//!
//! Signals: nodes are created with iceoryx2's signal handling disabled. Both
//! binaries install one `ctrlc` handler at start-up and poll its flag in
//! their loops (the callers' `keep_waiting` closures). iceoryx2's own handler
//! is installed lazily, at the first `Node::wait`, and reading it consumes
//! the signal; one mechanism, installed first thing, is simpler to reason
//! about in a process that also blocks on listeners.

use crate::wire::{self, WakeRequest};
use iceoryx2::node::NodeView;
use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use iceoryx2::service::builder::publish_subscribe::{PublishSubscribeOpenError, PublishSubscribeOpenOrCreateError};
use std::fmt::Debug;
use std::sync::atomic::{fence, Ordering};
use std::time::{Duration, Instant};

/// The iceoryx2 service variant of the testbed (inter-process).
pub type Ipc = ipc::Service;

/// Samples a subscriber buffers before the oldest is overwritten.
pub const BUFFER: usize = 16;
/// Publishers, subscribers, listeners, notifiers per service: a run, a
/// reconnected controller, and a dead one not yet cleaned up.
pub const MAX_PORTS: usize = 4;
/// Nodes per service.
pub const MAX_NODES: usize = 8;

/// A failed iceoryx2 operation, or a peer that cannot be reached.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum LinkError {
    /// An iceoryx2 call failed.
    #[error("{what}: {detail}")]
    Ipc {
        /// What was attempted (names the service).
        what: String,
        /// iceoryx2's error.
        detail: String,
    },
    /// A service exists with other message types: the peer was built with
    /// another protocol version (the version is part of every type name). The
    /// existing service's type name tells which, when it can be read.
    #[error("{service}: the peer uses other message types ({peer}; this side speaks version {version}, type names amb_testbed.v{version}.*): run a plant and a controller of the same protocol version", peer = describe_peer(peer_type.as_deref()), version = wire::PROTOCOL_VERSION)]
    Incompatible {
        /// Service name.
        service: String,
        /// The payload type name the existing service was created with, if it could be read.
        peer_type: Option<String>,
    },
}

/// The protocol version in a type name `amb_testbed.v<N>.<Struct>`.
pub fn version_of(type_name: &str) -> Option<u32> {
    type_name.strip_prefix("amb_testbed.v")?.split('.').next()?.parse().ok()
}

fn describe_peer(peer_type: Option<&str>) -> String {
    match peer_type {
        Some(t) => match version_of(t) {
            Some(v) if v == wire::PROTOCOL_VERSION => {
                format!("its type is {t}: this protocol version, but another message on this service")
            }
            Some(v) => format!("the peer speaks protocol version {v}: its type is {t}"),
            None => format!("its type is {t}, not of this testbed's protocol"),
        },
        None => "another protocol version".to_string(),
    }
}

/// The payload type name of the publish-subscribe service `name` as its creator made it, if
/// it exists and can be read (to name a peer's protocol version).
fn existing_type_name(name: &ServiceName) -> Option<String> {
    use iceoryx2::service::static_config::messaging_pattern::MessagingPattern as Static;
    let details = <Ipc as iceoryx2::service::Service>::details(
        name,
        Config::global_config(),
        iceoryx2::service::messaging_pattern::MessagingPattern::PublishSubscribe,
    )
    .ok()??;
    match details.static_details.messaging_pattern() {
        Static::PublishSubscribe(c) => Some(c.message_type_details().payload.type_name().to_string()),
        _ => None,
    }
}

fn ipc_err(what: impl Into<String>) -> impl FnOnce(&dyn Debug) -> LinkError {
    let what = what.into();
    move |e| LinkError::Ipc { what, detail: format!("{e:?}") }
}

/// Creates the node of one side of a run (`amb-testbed/<run_id>/<role>`),
/// with iceoryx2's signal handling off, and removes the resources of dead
/// nodes left by crashed runs, so they never block this one.
pub fn node(run_id: &str, role: &str) -> Result<Node<Ipc>, LinkError> {
    let full = wire::name(run_id, role);
    let name = NodeName::new(&full).map_err(|e| ipc_err(format!("node name {full}"))(&e))?;
    let node = NodeBuilder::new()
        .name(&name)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<Ipc>()
        .map_err(|e| ipc_err(format!("creating node {full}"))(&e))?;
    node.try_cleanup_dead_nodes();
    Ok(node)
}

/// The state of a peer's node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Peer {
    /// Its process holds its node.
    Alive,
    /// Its process died without removing its node (the stale resources were
    /// just removed).
    Dead,
    /// No such node: never started, or exited cleanly.
    Absent,
}

/// Looks up the node `amb-testbed/<run_id>/<role>` and removes it if its
/// process is dead. Costs a directory listing: call it when a peer is
/// silent, not per message.
pub fn peer(run_id: &str, role: &str) -> Peer {
    let wanted = wire::name(run_id, role);
    let (mut alive, mut dead) = (false, false);
    let listed = Node::<Ipc>::list(Config::global_config(), |state| {
        match state {
            NodeState::Alive(view) => {
                if view.details().as_ref().is_some_and(|d| d.name().as_str() == wanted) {
                    alive = true;
                }
            }
            NodeState::Dead(view) => {
                if view.details().as_ref().is_some_and(|d| d.name().as_str() == wanted) {
                    dead = true;
                    // Best effort: another process may be cleaning it up already.
                    let _ = view.try_remove_stale_resources();
                }
            }
            NodeState::Inaccessible(_) | NodeState::Undefined(_) => {}
        }
        CallbackProgression::Continue
    });
    match (listed, alive, dead) {
        (_, true, _) => Peer::Alive,
        (_, false, true) => Peer::Dead,
        // A failed listing proves nothing: report the peer alive so that a
        // reply timeout, not a guess, ends the wait.
        (Err(_), false, false) => Peer::Alive,
        (Ok(()), false, false) => Peer::Absent,
    }
}

/// A node lookup ([`peer`]) may take this many times its own duration of the wall time at
/// most: after a lookup that took `d`, the next one comes no sooner than `LOOKUP_SHARE × d`
/// later (its cost then stays under 1/20 of the time a peer is waited for).
///
/// A lookup lists every iceoryx2 node of the machine (a directory and a file or two per
/// node), so its cost grows with the runs of everyone on the machine and with their load.
/// Measured on the shared 2-core machine: 1.4 ms (p50) in a debug build with a handful of
/// nodes (`timed_wait`), but 200 to 340 ms each in a debug build at a load average of 23 with
/// 48 nodes, where unpaced lookups took 79 % of a lockstep run's wall time (292 of 370 s for
/// 2 000 ticks: docs/wire-protocol.md, "Liveness and deadlines").
pub const LOOKUP_SHARE: u32 = 20;

/// Watches a silent peer by its node, pacing the lookups so that their cost stays a bounded
/// share of the wait ([`LOOKUP_SHARE`]), and counts them.
#[derive(Debug)]
pub struct PeerWatch {
    run_id: String,
    role: &'static str,
    /// No lookup before this instant (the pacing), `None` before the first.
    not_before: Option<Instant>,
    /// The last lookup's duration.
    last: Duration,
    lookups: u64,
    spent: Duration,
}

impl PeerWatch {
    /// Watches the node `amb-testbed/<run_id>/<role>`.
    pub fn new(run_id: &str, role: &'static str) -> Self {
        Self {
            run_id: run_id.to_string(),
            role,
            not_before: None,
            last: Duration::ZERO,
            lookups: 0,
            spent: Duration::ZERO,
        }
    }

    /// Looks the peer up, unless the last lookup was less than `every`, or less than
    /// [`LOOKUP_SHARE`] times its own duration, ago: `None` then (not looked up).
    pub fn paced(&mut self, every: Duration) -> Option<Peer> {
        let now = Instant::now();
        if self.not_before.is_some_and(|t| now < t) {
            return None;
        }
        let peer = self.lookup();
        self.not_before = Some(now + pacing(every, self.last));
        Some(peer)
    }

    /// Looks the peer up now, whatever the pacing (a decision that needs the answer).
    pub fn lookup(&mut self) -> Peer {
        let start = Instant::now();
        let state = peer(&self.run_id, self.role);
        self.last = start.elapsed();
        self.spent += self.last;
        self.lookups += 1;
        state
    }

    /// Lookups made.
    pub fn lookups(&self) -> u64 {
        self.lookups
    }

    /// Wall time spent in lookups.
    pub fn spent(&self) -> Duration {
        self.spent
    }
}

/// The least time from the start of one paced lookup to the next: `every`, or [`LOOKUP_SHARE`]
/// times the lookup's duration `took` if that is longer.
pub fn pacing(every: Duration, took: Duration) -> Duration {
    every.max(took * LOOKUP_SHARE)
}

fn service_name(run_id: &str, what: &str) -> Result<ServiceName, LinkError> {
    let full = wire::name(run_id, what);
    ServiceName::new(&full).map_err(|e| ipc_err(format!("service name {full}"))(&e))
}

fn pubsub<T: Debug + Copy + ZeroCopySend + 'static>(
    node: &Node<Ipc>,
    run_id: &str,
    what: &str,
) -> Result<iceoryx2::service::port_factory::publish_subscribe::PortFactory<Ipc, T, ()>, LinkError> {
    let name = service_name(run_id, what)?;
    node.service_builder(&name)
        .publish_subscribe::<T>()
        .subscriber_max_buffer_size(BUFFER)
        .history_size(0)
        .enable_safe_overflow(true)
        .max_publishers(MAX_PORTS)
        .max_subscribers(MAX_PORTS)
        .max_nodes(MAX_NODES)
        .open_or_create()
        .map_err(|e| match e {
            PublishSubscribeOpenOrCreateError::PublishSubscribeOpenError(
                PublishSubscribeOpenError::IncompatibleTypes,
            ) => LinkError::Incompatible { service: name.to_string(), peer_type: existing_type_name(&name) },
            other => ipc_err(format!("opening service {name}"))(&other),
        })
}

fn event(
    node: &Node<Ipc>,
    run_id: &str,
    what: &str,
) -> Result<iceoryx2::service::port_factory::event::PortFactory<Ipc>, LinkError> {
    let name = service_name(run_id, what)?;
    node.service_builder(&name)
        .event()
        .max_notifiers(MAX_PORTS)
        .max_listeners(MAX_PORTS)
        .max_nodes(MAX_NODES)
        .open_or_create()
        .map_err(|e| ipc_err(format!("opening event service {name}"))(&e))
}

/// A publisher of `Tx` and a subscriber of `Rx`, polled (the handshake).
pub struct Mailbox<Tx: Debug + Copy + ZeroCopySend + 'static, Rx: Debug + Copy + ZeroCopySend + 'static> {
    publisher: Publisher<Ipc, Tx, ()>,
    subscriber: Subscriber<Ipc, Rx, ()>,
    tx_name: String,
    rx_name: String,
}

impl<Tx: Debug + Copy + ZeroCopySend + 'static, Rx: Debug + Copy + ZeroCopySend + 'static> Mailbox<Tx, Rx> {
    /// Opens (or creates) the services `<run_id>/<tx>` and `<run_id>/<rx>`.
    pub fn open(node: &Node<Ipc>, run_id: &str, tx: &str, rx: &str) -> Result<Self, LinkError> {
        let tx_name = wire::name(run_id, tx);
        let rx_name = wire::name(run_id, rx);
        let publisher = pubsub::<Tx>(node, run_id, tx)?
            .publisher_builder()
            .create()
            .map_err(|e| ipc_err(format!("publisher on {tx_name}"))(&e))?;
        let subscriber = pubsub::<Rx>(node, run_id, rx)?
            .subscriber_builder()
            .create()
            .map_err(|e| ipc_err(format!("subscriber on {rx_name}"))(&e))?;
        Ok(Self { publisher, subscriber, tx_name, rx_name })
    }

    /// Publishes a message (loaned and written in place).
    #[inline]
    pub fn send(&self, value: Tx) -> Result<(), LinkError> {
        let sample = self.publisher.loan_uninit().map_err(|e| ipc_err(format!("loan on {}", self.tx_name))(&e))?;
        sample.write_payload(value).send().map_err(|e| ipc_err(format!("send on {}", self.tx_name))(&e))?;
        Ok(())
    }

    /// The next received message, if any (copied out; the sample is released).
    #[inline]
    pub fn try_receive(&self) -> Result<Option<Rx>, LinkError> {
        match self.subscriber.receive() {
            Ok(Some(sample)) => Ok(Some(*sample.payload())),
            Ok(None) => Ok(None),
            Err(e) => Err(ipc_err(format!("receive on {}", self.rx_name))(&e)),
        }
    }
}

/// One side of a frame stream pair: sends `Tx` frames, waits for `Rx`
/// frames, spinning for `spin` and then blocking on an event listener,
/// with the wake-request handshake of [`crate::wire`].
pub struct Endpoint<Tx: Debug + Copy + ZeroCopySend + 'static, Rx: Debug + Copy + ZeroCopySend + 'static> {
    mail: Mailbox<Tx, Rx>,
    /// Wakes the peer (event service of the `Tx` stream).
    notifier: Notifier<Ipc>,
    /// Where this side blocks (event service of the `Rx` stream).
    listener: Listener<Ipc>,
    /// Asks the peer to wake this side (`<rx>/wake`).
    wake_out: Publisher<Ipc, WakeRequest, ()>,
    /// The peer's requests to be woken (`<tx>/wake`).
    wake_in: Subscriber<Ipc, WakeRequest, ()>,
    /// Busy-poll budget (the most a wait spins).
    spin_max: Duration,
    /// The budget of the next wait (adapted, see [`Endpoint::wait`]).
    spin: Duration,
    /// Blocking waits since creation (how often the spin budget ran out).
    blocks: u64,
    /// Blocking waits the peer ended with a notification.
    woken: u64,
    /// Blocking waits that found a frame after a slice ran out without a notification: the
    /// frame had been published, but the peer did not wake this side although it asked.
    unwoken: u64,
    /// Slices of blocked waits that ran out without a notification (whether or not a frame
    /// was then found): the waits that made progress by a timeout, not by the peer.
    timeouts: u64,
}

impl<Tx: Debug + Copy + ZeroCopySend + 'static, Rx: Debug + Copy + ZeroCopySend + 'static> Endpoint<Tx, Rx> {
    /// Opens the services of streams `tx` (sent) and `rx` (received) of a run.
    pub fn open(node: &Node<Ipc>, run_id: &str, tx: &str, rx: &str, spin: Duration) -> Result<Self, LinkError> {
        let mail = Mailbox::open(node, run_id, tx, rx)?;
        let notifier = event(node, run_id, tx)?
            .notifier_builder()
            .create()
            .map_err(|e| ipc_err(format!("notifier on {}", wire::name(run_id, tx)))(&e))?;
        let listener = event(node, run_id, rx)?
            .listener_builder()
            .create()
            .map_err(|e| ipc_err(format!("listener on {}", wire::name(run_id, rx)))(&e))?;
        let wake_rx = format!("{rx}/wake");
        let wake_tx = format!("{tx}/wake");
        let wake_out = pubsub::<WakeRequest>(node, run_id, &wake_rx)?
            .publisher_builder()
            .create()
            .map_err(|e| ipc_err(format!("publisher on {}", wire::name(run_id, &wake_rx)))(&e))?;
        let wake_in = pubsub::<WakeRequest>(node, run_id, &wake_tx)?
            .subscriber_builder()
            .create()
            .map_err(|e| ipc_err(format!("subscriber on {}", wire::name(run_id, &wake_tx)))(&e))?;
        Ok(Self {
            mail,
            notifier,
            listener,
            wake_out,
            wake_in,
            spin_max: spin,
            spin,
            blocks: 0,
            woken: 0,
            unwoken: 0,
            timeouts: 0,
        })
    }

    /// Sets the busy-poll budget before blocking.
    pub fn set_spin(&mut self, spin: Duration) {
        self.spin_max = spin;
        self.spin = spin;
    }

    /// How many waits ran out of their spin budget and blocked.
    pub fn blocks(&self) -> u64 {
        self.blocks
    }

    /// How many blocked waits the peer ended by notifying this side.
    pub fn woken(&self) -> u64 {
        self.woken
    }

    /// How many blocked waits found their frame only after a slice had run out without a
    /// notification: a peer that never serves wake requests shows here (each such wait
    /// costs a whole timed slice, which iceoryx2 may stretch well past the one asked for).
    pub fn unwoken(&self) -> u64 {
        self.unwoken
    }

    /// How many slices of blocked waits ran out without a notification (each costs a whole
    /// timed slice; a peer that is merely slow shows here too, a lost wake-up always does).
    pub fn timeouts(&self) -> u64 {
        self.timeouts
    }

    /// Publishes a frame, then notifies the peer if it asked to be woken.
    #[inline]
    pub fn send(&self, frame: Tx) -> Result<(), LinkError> {
        self.mail.send(frame)?;
        // Dekker with the receiver's `wait`: publish, fence, look for a wake request.
        fence(Ordering::SeqCst);
        let mut asked = false;
        while let Some(_request) =
            self.wake_in.receive().map_err(|e| ipc_err(format!("receive on {}/wake", self.mail.tx_name))(&e))?
        {
            asked = true;
        }
        if asked {
            self.wake_peer()?;
        }
        Ok(())
    }

    /// Publishes a frame and always notifies (for the last frame of a run).
    pub fn send_and_wake(&self, frame: Tx) -> Result<(), LinkError> {
        self.mail.send(frame)?;
        while let Ok(Some(_)) = self.wake_in.receive() {}
        self.wake_peer()
    }

    fn wake_peer(&self) -> Result<(), LinkError> {
        self.notifier.notify().map_err(|e| ipc_err(format!("notify on {}", self.mail.tx_name))(&e))?;
        Ok(())
    }

    /// The next received frame, if any, without waiting.
    #[inline]
    pub fn try_receive(&self) -> Result<Option<Rx>, LinkError> {
        self.mail.try_receive()
    }

    /// Waits for the next frame: busy-polls for the spin budget, then
    /// blocks in slices of `slice`, calling `keep_waiting` after each slice
    /// (it checks signals, peer liveness and timeouts); `Ok(None)` when it
    /// says stop.
    ///
    /// The budget adapts: a wait that lasted `w ≤ spin_max` raises the next
    /// budget to `2w` (spinning would have paid), a longer one halves it. On
    /// an oversubscribed machine (the peer not running) waits are long and
    /// the spin falls away, leaving the core to the peer.
    pub fn wait(&mut self, slice: Duration, keep_waiting: impl FnMut() -> bool) -> Result<Option<Rx>, LinkError> {
        if let Some(frame) = self.try_receive()? {
            return Ok(Some(frame));
        }
        let start = Instant::now();
        let got = self.wait_inner(slice, keep_waiting);
        let waited = start.elapsed();
        self.spin = if waited <= self.spin_max { self.spin.max(2 * waited).min(self.spin_max) } else { self.spin / 2 };
        got
    }

    fn wait_inner(&mut self, slice: Duration, mut keep_waiting: impl FnMut() -> bool) -> Result<Option<Rx>, LinkError> {
        // No sched_yield in the spin: yielding lets the scheduler keep both
        // processes time-sliced on one core (measured: 17 µs instead of
        // 0.6 µs per reply); a pure spin makes it move the peer to a free core.
        let start = Instant::now();
        while start.elapsed() < self.spin {
            if let Some(frame) = self.try_receive()? {
                return Ok(Some(frame));
            }
            std::hint::spin_loop();
        }
        self.blocks += 1;
        loop {
            let request =
                self.wake_out.loan_uninit().map_err(|e| ipc_err(format!("loan on {}/wake", self.mail.rx_name))(&e))?;
            request
                .write_payload(WakeRequest { seq: 0 })
                .send()
                .map_err(|e| ipc_err(format!("send on {}/wake", self.mail.rx_name))(&e))?;
            fence(Ordering::SeqCst);
            if let Some(frame) = self.try_receive()? {
                return Ok(Some(frame));
            }
            let mut notified = false;
            match self.listener.timed_wait(|_| notified = true, slice) {
                // A signal (SIGINT/SIGTERM for the ctrlc flag) ends the slice early: `keep_waiting` decides.
                Ok(_) | Err(ListenerWaitError::InterruptSignal) => {}
                Err(e) => return Err(ipc_err(format!("waiting on {}", self.mail.rx_name))(&e)),
            }
            if notified {
                self.woken += 1;
            } else {
                self.timeouts += 1;
            }
            if let Some(frame) = self.try_receive()? {
                if !notified {
                    self.unwoken += 1;
                }
                return Ok(Some(frame));
            }
            if !keep_waiting() {
                return Ok(None);
            }
        }
    }
}

/// Asks the kernel to keep every core's idle wake-up latency at 0 µs while the returned
/// file is open (the PM QoS request of `/dev/cpu_dma_latency`, as `cyclictest` makes it):
/// an idle core then polls instead of halting, and a timer or a peer's frame wakes it in
/// microseconds. Closing the file (dropping it) withdraws the request.
pub fn hold_zero_idle_latency() -> Result<std::fs::File, String> {
    use std::io::Write;
    let mut f = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/cpu_dma_latency")
        .map_err(|e| format!("/dev/cpu_dma_latency: {e}"))?;
    f.write_all(&0i32.to_ne_bytes()).map_err(|e| format!("/dev/cpu_dma_latency: {e}"))?;
    Ok(f)
}

/// Sleeps until `CLOCK_MONOTONIC` reads `ns` (the clock of [`crate::wire::monotonic_ns`]):
/// an absolute `clock_nanosleep`, so a late wake-up does not add to the next one.
pub fn sleep_until_ns(ns: u64) {
    let target =
        libc::timespec { tv_sec: (ns / 1_000_000_000) as libc::time_t, tv_nsec: (ns % 1_000_000_000) as libc::c_long };
    // SAFETY: `target` is a valid timespec; the remaining-time pointer may be null with
    // TIMER_ABSTIME. EINTR (a signal) sleeps again: the caller checks its flags per tick.
    while unsafe { libc::clock_nanosleep(libc::CLOCK_MONOTONIC, libc::TIMER_ABSTIME, &target, std::ptr::null_mut()) }
        == libc::EINTR
    {}
}

/// Pins the calling thread to one CPU core.
pub fn pin_to_core(core: usize) -> Result<(), String> {
    // SAFETY: cpu_set_t is plain data; CPU_ZERO/CPU_SET write inside it;
    // sched_setaffinity(0, …) affects only the calling thread.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_ZERO(&mut set);
        if core >= libc::CPU_SETSIZE as usize {
            return Err(format!("core {core} is beyond the CPU set size"));
        }
        libc::CPU_SET(core, &mut set);
        if libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set) != 0 {
            return Err(format!("cannot pin to core {core}: {}", std::io::Error::last_os_error()));
        }
    }
    Ok(())
}

/// Puts the calling thread under `SCHED_FIFO` at `priority` (1 to 99) and locks the
/// process's memory (`mlockall(MCL_CURRENT | MCL_FUTURE)`), so that neither ordinary
/// processes nor page faults delay it. Each step that the system refuses (no
/// `CAP_SYS_NICE`, an `RLIMIT_RTPRIO` or `RLIMIT_MEMLOCK` too low) is reported in the
/// returned list; the other steps still apply.
pub fn realtime(priority: i32) -> Vec<String> {
    let mut refused = Vec::new();
    if let Err(e) = set_fifo(0, priority) {
        refused.push(e);
    }
    // SAFETY: mlockall has no memory-safety preconditions.
    if unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) } != 0 {
        refused.push(format!("mlockall: {}", std::io::Error::last_os_error()));
    }
    refused
}

/// Puts thread `pid` (0: the calling thread) under `SCHED_FIFO` at `priority`, unless it
/// already runs there.
pub fn set_fifo(pid: u32, priority: i32) -> Result<(), String> {
    if policy(pid) == "fifo" && fifo_priority(pid) == Some(priority) {
        return Ok(());
    }
    let pid = libc::pid_t::try_from(pid).map_err(|_| format!("pid {pid} is out of range"))?;
    // SAFETY: sched_setscheduler reads only `param`, a valid sched_param; it has no other
    // preconditions.
    unsafe {
        let param = libc::sched_param { sched_priority: priority };
        if libc::sched_setscheduler(pid, libc::SCHED_FIFO, &param) != 0 {
            return Err(format!(
                "SCHED_FIFO at priority {priority}{}: {}",
                if pid == 0 { String::new() } else { format!(" for pid {pid}") },
                std::io::Error::last_os_error()
            ));
        }
    }
    Ok(())
}

/// Makes the calling thread an ordinary one: `SCHED_OTHER`, on every core the process may
/// use but those in `avoid` (every core if that leaves none). For a realtime process's
/// helper threads (writing its rows, reading its controller's output), which would otherwise
/// inherit the loop's `SCHED_FIFO` priority and pinned core, or land on the loop's cores and
/// take them from it (`avoid`: `controller.pin_cores`). Best effort: a refusal leaves the
/// thread as it was.
pub fn ordinary_thread(avoid: &[usize]) {
    // SAFETY: sched_setscheduler reads a valid sched_param; cpu_set_t is plain data that
    // CPU_SET writes inside; both calls affect only the calling thread (0). The kernel
    // intersects the mask with the cores the process's cpuset allows, and refuses (EINVAL) a
    // mask that leaves none.
    unsafe {
        let param = libc::sched_param { sched_priority: 0 };
        if libc::sched_getscheduler(0) != libc::SCHED_OTHER {
            libc::sched_setscheduler(0, libc::SCHED_OTHER, &param);
        }
        let mask = |skip: &[usize]| {
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            for core in (0..libc::CPU_SETSIZE as usize).filter(|c| !skip.contains(c)) {
                libc::CPU_SET(core, &mut set);
            }
            set
        };
        let size = std::mem::size_of::<libc::cpu_set_t>();
        if libc::sched_setaffinity(0, size, &mask(avoid)) != 0 {
            libc::sched_setaffinity(0, size, &mask(&[]));
        }
    }
}

/// `kernel.sched_rt_runtime_us` (`-1`: RT throttling off), where `/proc` tells: the time of
/// each second that `SCHED_FIFO` threads may run before Linux stops them for the rest of it.
pub fn rt_runtime_us() -> Option<i64> {
    std::fs::read_to_string("/proc/sys/kernel/sched_rt_runtime_us").ok()?.trim().parse().ok()
}

/// How long RT throttling stops a `SCHED_FIFO` thread that wants its core all the time, ms of
/// every second (the default `sched_rt_period_us`), for `kernel.sched_rt_runtime_us =
/// runtime_us`; `None` when throttling is off (−1).
pub fn rt_throttle_ms(runtime_us: i64) -> Option<i64> {
    (runtime_us >= 0).then(|| (1_000_000 - runtime_us).max(0) / 1000)
}

/// The `SCHED_FIFO`/`SCHED_RR` priority of thread `pid` (0: the calling thread); `None` for
/// another policy or a thread that cannot be read.
pub fn fifo_priority(pid: u32) -> Option<i32> {
    let pid = libc::pid_t::try_from(pid).ok()?;
    let mut param = libc::sched_param { sched_priority: 0 };
    // SAFETY: sched_getscheduler has no preconditions; sched_getparam writes only `param`.
    unsafe {
        matches!(libc::sched_getscheduler(pid), libc::SCHED_FIFO | libc::SCHED_RR)
            .then(|| libc::sched_getparam(pid, &mut param) == 0)
            .filter(|ok| *ok)
            .map(|_| param.sched_priority)
    }
}

/// The scheduling policy of thread `pid` (0: the calling thread): `fifo`, `rr`, `other`, ….
pub fn policy(pid: u32) -> &'static str {
    let Ok(pid) = libc::pid_t::try_from(pid) else { return "unknown" };
    // SAFETY: sched_getscheduler has no preconditions.
    match unsafe { libc::sched_getscheduler(pid) } {
        libc::SCHED_FIFO => "fifo",
        libc::SCHED_RR => "rr",
        libc::SCHED_OTHER => "other",
        libc::SCHED_BATCH => "batch",
        libc::SCHED_IDLE => "idle",
        _ => "unknown",
    }
}

pub use crate::cores::cores_online;

#[cfg(test)]
mod tests {
    use super::*;

    /// The cores the calling thread may run on.
    fn affinity() -> Vec<usize> {
        // SAFETY: sched_getaffinity writes only `set`, plain data of the size given.
        unsafe {
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            assert_eq!(libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set), 0);
            (0..libc::CPU_SETSIZE as usize).filter(|c| libc::CPU_ISSET(*c, &set)).collect()
        }
    }

    /// A peer's node is looked up at most once per pacing interval: `every`, or 20 times the
    /// lookup's own duration when that is longer (a slow listing, on a loaded machine with
    /// many nodes, is made rarer, not at every slice of a wait); a decision that needs the
    /// answer ([`PeerWatch::lookup`]) looks it up whatever the pacing.
    #[test]
    fn a_silent_peer_is_looked_up_at_the_paced_rate() {
        assert_eq!(pacing(Duration::from_millis(1), Duration::from_micros(20)), Duration::from_millis(1));
        assert_eq!(pacing(Duration::from_millis(1), Duration::from_millis(300)), Duration::from_secs(6));
        let run_id = format!("pacing-{}", std::process::id());
        let _watcher = node(&run_id, "controller").expect("node"); // iceoryx2's node folder exists
        let mut w = PeerWatch::new(&run_id, "plant");
        assert_eq!(w.paced(Duration::from_secs(600)), Some(Peer::Absent));
        assert_eq!(w.paced(Duration::from_secs(600)), None, "within the interval");
        assert_eq!(w.lookups(), 1);
        assert_eq!(w.lookup(), Peer::Absent);
        assert_eq!(w.lookups(), 2);
        let mut w = PeerWatch::new(&run_id, "plant");
        assert!(w.paced(Duration::ZERO).is_some());
        std::thread::sleep(w.spent() * (LOOKUP_SHARE + 1));
        assert!(w.paced(Duration::ZERO).is_some(), "due again after 20 times its duration");
    }

    /// A helper thread started by a pinned loop leaves the loop's core and runs under
    /// `SCHED_OTHER`; with every core to avoid it takes them all rather than none.
    #[test]
    fn an_ordinary_thread_leaves_the_loops_cores() {
        std::thread::spawn(|| {
            let all = affinity();
            let first = all[0];
            pin_to_core(first).unwrap();
            assert_eq!(affinity(), vec![first]);
            ordinary_thread(&[first]);
            let now = affinity();
            if all.len() > 1 {
                assert!(!now.contains(&first) && !now.is_empty(), "{now:?}");
            } else {
                assert_eq!(now, all);
            }
            ordinary_thread(&all);
            assert_eq!(affinity(), all, "avoiding every core leaves them all");
            assert_eq!(policy(0), "other");
        })
        .join()
        .unwrap();
    }
}
