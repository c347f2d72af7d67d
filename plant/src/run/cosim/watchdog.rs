//! The watchdog of a shared core: with `pin_cores = [c, c]` and a priority the controller
//! runs one `SCHED_FIFO` level above the plant, so a controller that stops blocking between
//! frames (a hand-written one that busy-waits, or one stuck in a loop) would hold the core
//! and the plant would never run again: not its liveness checks, not its reaction to Ctrl-C.
//!
//! A thread one level above the controller, pinned to the same core, sleeps and looks at the
//! plant's tick count every [`Watchdog::check`]; when the count has not moved for
//! [`STALL`] while the controller is running, it puts the controller under the normal
//! scheduler (`SCHED_OTHER`), which gives the core back to the plant. A controller that is
//! stopped (a debugger) or waiting holds no core and is left to the plant's own timeouts. The run goes on and says so: a peer event, a warning,
//! and the misses that follow. The thread costs one wake-up every [`Watchdog::check`] on
//! the core.

use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How long the plant may go without a tick before the controller above it is demoted. A
/// controller that answers each frame holds the core for its answer's time only (microseconds
/// to milliseconds); half a second without one tick is a controller that no longer blocks.
pub const STALL: Duration = Duration::from_millis(500);

/// What the plant and the watchdog thread share.
#[derive(Debug, Default)]
struct Shared {
    /// The plant's ticks so far.
    ticks: AtomicU64,
    /// The connected controller's process id (0: none).
    pid: AtomicU32,
    /// The process id of a controller demoted, once (0: none).
    demoted: AtomicU32,
    /// Set when the session ends.
    stop: AtomicBool,
}

/// The watchdog (see the module doc); stops its thread when dropped.
#[derive(Debug)]
pub struct Watchdog {
    shared: Arc<Shared>,
    thread: Option<std::thread::JoinHandle<()>>,
    /// How often the thread looks.
    pub check: Duration,
}

impl Watchdog {
    /// Starts the thread on `core` under `SCHED_FIFO` at `priority` (above the controller's).
    /// `None` where the system refuses either: a watchdog below the controller could not run.
    pub fn start(core: usize, priority: i32) -> Option<Self> {
        let shared = Arc::new(Shared::default());
        let check = STALL / 5;
        let (ready_tx, ready_rx) = std::sync::mpsc::channel();
        let s = shared.clone();
        let thread = std::thread::Builder::new()
            .name("plant-watchdog".into())
            .spawn(move || {
                let ok = controller::link::pin_to_core(core).is_ok() && controller::link::set_fifo(0, priority).is_ok();
                let _ = ready_tx.send(ok);
                if ok {
                    watch(&s, check, STALL);
                }
            })
            .ok()?;
        if ready_rx.recv() != Ok(true) {
            let _ = thread.join();
            return None;
        }
        Some(Self { shared, thread: Some(thread), check })
    }

    /// The plant ran a tick.
    #[inline]
    pub fn tick(&self) {
        self.shared.ticks.fetch_add(1, Ordering::Relaxed);
    }

    /// The controller now connected (its process id).
    pub fn watch_controller(&self, pid: u32) {
        self.shared.pid.store(pid, Ordering::Relaxed);
    }

    /// The process id of the controller the watchdog demoted, the first time it is asked.
    pub fn take_demoted(&self) -> Option<u32> {
        match self.shared.demoted.swap(0, Ordering::Relaxed) {
            0 => None,
            pid => Some(pid),
        }
    }
}

impl Drop for Watchdog {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            // The thread sleeps at most `check` before it sees the flag.
            let _ = t.join();
        }
    }
}

/// The watchdog's loop: every `check`, demote the controller if the plant has not ticked for
/// `stall`.
fn watch(s: &Shared, check: Duration, stall: Duration) {
    let mut seen = s.ticks.load(Ordering::Relaxed);
    let mut since = Instant::now();
    while !s.stop.load(Ordering::Relaxed) {
        std::thread::sleep(check);
        let now = s.ticks.load(Ordering::Relaxed);
        if now != seen {
            (seen, since) = (now, Instant::now());
            continue;
        }
        let pid = s.pid.load(Ordering::Relaxed);
        // Only a controller that is running holds the core: one stopped (a debugger, SIGSTOP)
        // or waiting is not demoted; the plant's own timeouts deal with it.
        if pid != 0 && since.elapsed() >= stall && running(pid) && demote(pid) {
            s.demoted.store(pid, Ordering::Relaxed);
            s.pid.store(0, Ordering::Relaxed);
        }
    }
}

/// Process `pid` is running or runnable (`R` in `/proc/PID/stat`).
fn running(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat"))
        .ok()
        .and_then(|s| s.rsplit_once(')').and_then(|(_, rest)| rest.split_whitespace().next().map(|st| st == "R")))
        .unwrap_or(false)
}

/// Puts process `pid` (its main thread) under `SCHED_OTHER`; false where that fails.
fn demote(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else { return false };
    let param = libc::sched_param { sched_priority: 0 };
    // SAFETY: sched_setscheduler reads a valid sched_param; no other preconditions.
    unsafe { libc::sched_setscheduler(pid, libc::SCHED_OTHER, &param) == 0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A process to demote: a busy shell loop, a child of the test (same user, so no privilege
    /// is needed to set its policy), running as a controller that holds its core does.
    fn busy() -> std::process::Child {
        std::process::Command::new("sh").args(["-c", "while :; do :; done"]).spawn().unwrap()
    }

    /// A waiting process: `sleep`.
    fn waiting() -> std::process::Child {
        std::process::Command::new("sleep").arg("30").spawn().unwrap()
    }

    /// `child` watched every 5 ms against a stall of `stall`: the shared state and the watcher.
    fn watched(child: &std::process::Child, stall: Duration) -> (Arc<Shared>, std::thread::JoinHandle<()>) {
        let s = Arc::new(Shared::default());
        s.pid.store(child.id(), Ordering::Relaxed);
        let t = {
            let s = s.clone();
            std::thread::spawn(move || watch(&s, Duration::from_millis(5), stall))
        };
        (s, t)
    }

    #[test]
    fn a_plant_that_stops_ticking_has_its_controller_demoted_and_one_that_ticks_does_not() {
        let mut c = busy();
        let (s, t) = watched(&c, Duration::from_millis(40));
        // Ticking for 200 ms (longer than the stall): nobody is demoted.
        let start = Instant::now();
        while start.elapsed() < Duration::from_millis(200) {
            s.ticks.fetch_add(1, Ordering::Relaxed);
            std::thread::sleep(Duration::from_millis(1));
        }
        assert_eq!(s.demoted.load(Ordering::Relaxed), 0, "demoted while the plant ticked");
        // Then no tick: the controller is demoted within a few checks past the stall.
        let start = Instant::now();
        while s.demoted.load(Ordering::Relaxed) == 0 && start.elapsed() < Duration::from_secs(5) {
            std::thread::sleep(Duration::from_millis(5));
        }
        assert_eq!(s.demoted.load(Ordering::Relaxed), c.id());
        assert_eq!(s.pid.load(Ordering::Relaxed), 0, "demoted once, then no longer watched");
        s.stop.store(true, Ordering::Relaxed);
        t.join().unwrap();
        let _ = c.kill();
        let _ = c.wait();
    }

    #[test]
    fn a_controller_that_is_not_running_is_not_demoted() {
        let mut c = waiting();
        let (s, t) = watched(&c, Duration::from_millis(20));
        std::thread::sleep(Duration::from_millis(200));
        s.stop.store(true, Ordering::Relaxed);
        t.join().unwrap();
        assert_eq!(s.demoted.load(Ordering::Relaxed), 0, "a sleeping controller holds no core");
        let _ = c.kill();
        let _ = c.wait();
    }

    #[test]
    fn without_a_controller_nothing_is_demoted() {
        let s = Arc::new(Shared::default());
        let t = {
            let s = s.clone();
            std::thread::spawn(move || watch(&s, Duration::from_millis(5), Duration::from_millis(20)))
        };
        std::thread::sleep(Duration::from_millis(100));
        s.stop.store(true, Ordering::Relaxed);
        t.join().unwrap();
        assert_eq!(s.demoted.load(Ordering::Relaxed), 0);
    }
}
