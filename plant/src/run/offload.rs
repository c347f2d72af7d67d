//! A sink on a thread of its own, for realtime runs and for `plant run` on a host with a
//! spare core ([`When`]): the loop hands each output sample over a bounded channel and goes
//! on; the thread formats it, writes it out and feeds the recorder (`trace.csv` and the
//! charts' data of `plant run`, the soak's monitor and files).
//!
//! Inside a realtime tick these took more than a 20 kHz period: writing a 64 KiB chunk of
//! `trace.csv` took 50–200 µs every 170 rows, the recorder up to 100 µs every 256 rows,
//! and formatting a row 2–3 µs of a tick whose integration takes 2 µs. What stays in the
//! tick is a copy into the channel.
//!
//! Written here because the standard library's bounded channel does all it needs: the
//! thread waits for the first sample, takes what has come since, then sleeps for
//! [`PAUSE`], so that the loop's sends seldom find a thread waiting to be woken (a wake is
//! a system call in the tick). A full channel makes the loop wait: no sample is dropped.

use crate::config::{ControlMode, Scene};
use crate::cosim::Launch;
use crate::hooks::Hooks;
use crate::run::{run_into_from, SetupError, Sink, SinkRun};
use crate::snapshot::Snapshot;
use crate::trace::Record;
use controller::{RotorSample, ROTOR_AXES};
use std::sync::mpsc::{sync_channel, SyncSender};
use std::time::Duration;

/// Samples the channel holds: 200 ms of a 20 kHz run with one row per tick.
pub const CAPACITY: usize = 4096;

/// How long the thread sleeps after taking what has come.
const PAUSE: Duration = Duration::from_millis(2);

/// What the loop hands the thread: a sample, or a tick of the loop for a sink that takes them
/// ([`Sink::tick`]).
#[expect(
    clippy::large_enum_variant,
    reason = "the channel held rows before ticks were added: boxing the row would allocate in every tick"
)]
enum Item {
    Row(Record),
    Tick(RotorSample, [f64; ROTOR_AXES]),
}

/// The loop's side: sends each sample (and each tick, if the sink takes them) to the thread.
struct Handoff {
    tx: SyncSender<Item>,
    ticks: bool,
}

impl Sink for Handoff {
    fn sample(&mut self, record: &Record) {
        // Fails only when the thread has ended, which it does by panicking: the scope's join
        // passes the panic on.
        let _ = self.tx.send(Item::Row(*record));
    }

    fn tick(&mut self, sample: &RotorSample, command: &[f64; ROTOR_AXES]) {
        let _ = self.tx.send(Item::Tick(*sample, *command));
    }

    fn wants_ticks(&self) -> bool {
        self.ticks
    }
}

impl Item {
    fn to(self, sink: &mut dyn Sink) {
        match self {
            Item::Row(r) => sink.sample(&r),
            Item::Tick(s, c) => sink.tick(&s, &c),
        }
    }
}

/// Which runs hand their samples to a thread of their own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum When {
    /// Realtime runs only: their ticks must not format or write rows.
    Realtime,
    /// Realtime runs, and the others where the host has a second core for the thread: there
    /// formatting and writing the rows overlaps the integration instead of following it (the
    /// rows of `trace.csv` take about 12 % of the instructions of a flexible or two-plane run in
    /// process, `callgrind`; docs/results/speed.md). The rows are the same, in the same order.
    SpareCore,
}

/// [`run_into`]; a realtime run (and, with [`When::SpareCore`], any run on a host with more
/// than one core) hands its samples to `sink` on a thread of its own ([`crate::offload`]), so
/// that writing and analysing them stays out of its ticks.
///
/// The run starts from `from` if given ([`run_into_from`]).
pub fn run_into_offloaded<S: Sink + Send>(
    scene: &Scene,
    launch: &Launch,
    hooks: &mut dyn Hooks,
    sink: &mut S,
    from: Option<&Snapshot>,
    when: When,
) -> Result<SinkRun, SetupError> {
    let spare_core = || std::thread::available_parallelism().is_ok_and(|n| n.get() > 1);
    if scene.controller.mode == ControlMode::Realtime || (when == When::SpareCore && spare_core()) {
        offload(sink, scene.controller.cosim.pinned_cores(), |s| run_into_from(scene, launch, hooks, s, from))
            .map_err(SetupError::Thread)?
    } else {
        run_into_from(scene, launch, hooks, sink, from)
    }
}

/// Runs `body` with a sink that hands every sample to `sink` on a thread named
/// `plant-rows`, and returns what `body` returned once the thread has taken every sample.
///
/// The thread is an ordinary one (`SCHED_OTHER`, on any core the process may use but those
/// in `avoid`, the loop's `controller.pin_cores`), whatever the caller's scheduling: a
/// realtime loop puts its own thread under `SCHED_FIFO` and pins it. `sink` receives samples only:
/// [`Sink::planes`] is not handed over ([`Sink::tick`] is, if the sink takes ticks), so a sink that
/// needs the planes must not be offloaded. A panic on the thread is passed on to the caller; a
/// thread that cannot be started (a process at its thread limit) is an error, before `body`
/// runs.
pub fn offload<S: Sink + Send, R>(
    sink: &mut S,
    avoid: &[usize],
    body: impl FnOnce(&mut dyn Sink) -> R,
) -> std::io::Result<R> {
    let (tx, rx) = sync_channel::<Item>(CAPACITY);
    let ticks = sink.wants_ticks();
    std::thread::scope(|scope| {
        let thread = std::thread::Builder::new().name("plant-rows".into()).spawn_scoped(scope, move || {
            // A run after a realtime one starts it from a thread under `SCHED_FIFO`,
            // pinned: it must not take the loop's core at the loop's priority.
            controller::link::ordinary_thread(avoid);
            while let Ok(first) = rx.recv() {
                first.to(sink);
                while let Ok(item) = rx.try_recv() {
                    item.to(sink);
                }
                std::thread::sleep(PAUSE);
            }
        });
        thread.map(|_| body(&mut Handoff { tx, ticks }))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::Row;

    /// A sink that keeps the times it was given, on whatever thread.
    struct Times(Vec<f64>, Option<String>);

    impl Sink for Times {
        fn sample(&mut self, r: &Record) {
            self.0.push(r.a.t_s);
            self.1 = std::thread::current().name().map(String::from);
        }
    }

    fn record(t: f64) -> Record {
        Record::planar(Row { t_s: t, ..Row::default() })
    }

    #[test]
    fn every_sample_arrives_in_order_on_the_rows_thread_even_past_the_channels_capacity() {
        let mut sink = Times(Vec::new(), None);
        let n = 3 * CAPACITY + 17;
        let returned = offload(&mut sink, &[], |s| {
            for i in 0..n {
                s.sample(&record(i as f64));
            }
            "body's value"
        })
        .unwrap();
        assert_eq!(returned, "body's value");
        assert_eq!(sink.0.len(), n);
        assert!(sink.0.iter().enumerate().all(|(i, t)| *t == i as f64), "out of order");
        assert_eq!(sink.1.as_deref(), Some("plant-rows"));
    }

    #[test]
    fn a_panic_on_the_rows_thread_reaches_the_caller() {
        struct Fails;
        impl Sink for Fails {
            fn sample(&mut self, _: &Record) {
                panic!("the sink failed");
            }
        }
        let caught = std::panic::catch_unwind(|| {
            offload(&mut Fails, &[], |s| {
                for i in 0..(2 * CAPACITY) {
                    s.sample(&record(i as f64));
                }
            })
        });
        assert!(caught.is_err());
    }
}
