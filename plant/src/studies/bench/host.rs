//! What the host adds (`plant bench host`): how late this machine lets a thread start each
//! tick of a realtime run, with no model and no controller, under the scheduling a realtime
//! plant gets (pinned with `--pin-core`, `SCHED_FIFO` and memory locked with
//! `--realtime-priority`, and then every core's idle latency held at 0).
//!
//! Two loops, one per `controller.pacing`, each for the same number of ticks at the run's
//! rate, each tick due at `start + k·period` as a realtime plant's is:
//!
//! * `sleep`: an absolute `clock_nanosleep` to each tick (what `cyclictest` measures): the
//!   lateness is the timer's and the wake-up's.
//! * `spin`: a loop reading the clock until each tick is due: the lateness is the time the
//!   core ran something else (an interrupt, a kernel thread, the hypervisor).
//!
//! A tick that starts more than a period late is what a realtime run counts as a plant
//! overrun (`cosim.plant_overruns`), and a late tick makes the next ones late until the loop
//! catches up, as in the plant. The figures are a floor: a realtime run on this host has at
//! least about as many overruns, whatever the plant computes. Writes `host.csv`
//! ([`HostRow`]).

use super::tick::load_average;
use crate::cosim::stats::{Latencies, Percentiles};
use crate::table::sci;
use controller::wire::monotonic_ns;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// Header of `host.csv`.
pub const HOST_HEADER: &str = HostRow::HEADER;

crate::table::table_row! {
/// One loop: a row of `host.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct HostRow {
    /// `sleep` or `spin`.
    pub pacing: &'static str,
    /// Ticks per second.
    #[serde(with = "sci")]
    pub rate_hz: f64,
    /// Ticks measured.
    pub ticks: u64,
    /// How late a tick started, median (µs).
    #[serde(with = "sci")]
    pub late_p50_us: f64,
    /// … 99th percentile (µs).
    #[serde(with = "sci")]
    pub late_p99_us: f64,
    /// … 99.9th percentile (µs).
    #[serde(with = "sci")]
    pub late_p999_us: f64,
    /// … largest (µs).
    #[serde(with = "sci")]
    pub late_max_us: f64,
    /// Ticks that started more than a period late: a realtime run's plant overruns with
    /// nothing to compute.
    pub over_period: u64,
    /// Their share of the ticks.
    #[serde(with = "sci")]
    pub over_period_fraction: f64,
    /// `other`, or `fifo N`, and the core.
    pub scheduling: String,
    /// Load average over 1 min (`/proc/loadavg`) at the end.
    #[serde(with = "sci")]
    pub load_1min: f64,
}
}

/// What `plant bench host` was asked to do.
pub struct Request<'a> {
    /// Ticks per second (a realtime scene's `controller.rate_hz`).
    pub rate_hz: f64,
    /// Seconds per loop.
    pub seconds: f64,
    /// Output folder (default `runs/bench-host`).
    pub out: Option<&'a Path>,
    /// Pin the bench's thread to this core.
    pub pin_core: Option<usize>,
    /// `SCHED_FIFO` priority (0: the normal scheduler).
    pub realtime_priority: u32,
}

/// How a loop waits for its next tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wait {
    /// An absolute `clock_nanosleep`.
    Sleep,
    /// Reading the clock until the tick is due.
    Spin,
}

/// The lateness of `ticks` ticks of `period_ns`, the first due `lead_ns` from now, waiting as
/// `wait` says; and how many started more than a period late. Ends early, with fewer ticks,
/// once `stop` is set (SIGINT/SIGTERM).
pub fn lateness(ticks: u64, period_ns: u64, lead_ns: u64, wait: Wait, stop: &AtomicBool) -> (Percentiles, u64) {
    let start = monotonic_ns() + lead_ns;
    tally(ticks, period_ns, start, stop, |due| match wait {
        Wait::Sleep => {
            controller::link::sleep_until_ns(due);
            monotonic_ns()
        }
        Wait::Spin => loop {
            let now = monotonic_ns();
            if now >= due {
                break now;
            }
            std::hint::spin_loop();
        },
    })
}

/// Ticks `k` due at `start + k·period_ns`, each started when `wait_until(due)` returns (the
/// clock then, ns): their lateness, and how many started more than a period late.
fn tally(
    ticks: u64,
    period_ns: u64,
    start: u64,
    stop: &AtomicBool,
    mut wait_until: impl FnMut(u64) -> u64,
) -> (Percentiles, u64) {
    let mut late = Latencies::new();
    let mut over = 0;
    for k in 0..ticks {
        if stop.load(Ordering::Relaxed) {
            break;
        }
        let due = start + k * period_ns;
        let by = wait_until(due).saturating_sub(due);
        late.record(by);
        over += u64::from(by > period_ns);
    }
    (late.percentiles(), over)
}

/// Runs the bench and writes `host.csv`; returns its path.
pub fn command(req: &Request, log: &mut dyn FnMut(&str)) -> anyhow::Result<PathBuf> {
    let bad = |why: String| -> anyhow::Error { crate::exit::BadArgument(why).into() };
    if !(req.rate_hz.is_finite() && (1.0..=1e6).contains(&req.rate_hz)) {
        return Err(bad(format!("--rate-hz {}: must be from 1 to 1e6 Hz", req.rate_hz)));
    }
    if !(req.seconds.is_finite() && (1e-3..=3600.0).contains(&req.seconds)) {
        return Err(bad(format!("--seconds {}: must be from 0.001 to 3600 s", req.seconds)));
    }
    if req.realtime_priority > 99 {
        return Err(bad(format!("--realtime-priority {}: must be 0 (off) to 99", req.realtime_priority)));
    }
    let period_ns = (1e9 / req.rate_hz).round() as u64;
    let ticks = ((req.seconds * req.rate_hz).round() as u64).max(1);
    let dir = crate::output::out_dir(req.out, "bench-host");
    let _claim = crate::claim::claim(&dir, true)?;
    let scheduling = super::tick::schedule(req.pin_core, req.realtime_priority, log)?;
    let runtime = controller::link::rt_runtime_us().filter(|_| scheduling.starts_with("fifo"));
    let stall = runtime.and_then(controller::link::rt_throttle_ms);
    if let (Some(runtime), Some(stall)) = (runtime, stall) {
        log(&format!(
            "warning: kernel.sched_rt_runtime_us = {runtime}: RT throttling stops the spinning loop for {stall} ms \
             of every second, as it would a spinning realtime plant (`sysctl kernel.sched_rt_runtime_us=-1` or \
             scripts/shield-core.sh on to measure without it)"
        ));
    }
    // As a realtime run with a priority does: idle cores poll instead of halting.
    let _idle = (req.realtime_priority > 0)
        .then(controller::link::hold_zero_idle_latency)
        .and_then(|r| r.map_err(|e| log(&format!("warning: cannot hold the idle latency at 0 ({e})"))).ok());
    let stop = crate::interrupt::stop_flag();
    let mut rows = Vec::new();
    for (pacing, wait) in [("sleep", Wait::Sleep), ("spin", Wait::Spin)] {
        let (p, over) = lateness(ticks, period_ns, 1_000_000, wait, &stop);
        if stop.load(Ordering::Relaxed) {
            // A loop stopped part-way is not a measurement of the rate.
            break;
        }
        let row = HostRow {
            pacing,
            rate_hz: req.rate_hz,
            ticks: p.count,
            late_p50_us: p.p50,
            late_p99_us: p.p99,
            late_p999_us: p.p999,
            late_max_us: p.max,
            over_period: over,
            over_period_fraction: over as f64 / p.count.max(1) as f64,
            scheduling: scheduling.clone(),
            load_1min: load_average(),
        };
        log(&format!(
            "{pacing}: {} ticks at {} Hz started late by p50 {:.2} / p99 {:.2} / p99.9 {:.2} / max {:.1} µs; {} \
             ({:.3} %) more than a period ({:.1} µs) late: plant overruns with nothing to compute; {}; load {:.2}",
            row.ticks,
            row.rate_hz,
            row.late_p50_us,
            row.late_p99_us,
            row.late_p999_us,
            row.late_max_us,
            row.over_period,
            100.0 * row.over_period_fraction,
            period_ns as f64 * 1e-3,
            row.scheduling,
            row.load_1min
        ));
        rows.push(row);
    }
    let path = dir.join("host.csv");
    crate::table::write_with_header(&path, HOST_HEADER, &rows)?;
    if stop.load(Ordering::Relaxed) {
        let why = format!("{} of 2 loops finished, written to {}", rows.len(), path.display());
        return Err(crate::exit::Interrupted(why).into());
    }
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_tick_is_measured_on_either_wait() {
        for wait in [Wait::Sleep, Wait::Spin] {
            let (p, over) = lateness(50, 200_000, 0, wait, &AtomicBool::new(false));
            assert_eq!(p.count, 50, "{wait:?}");
            assert!(p.max >= p.p999 && p.p999 >= p.p50, "{wait:?}: {p:?}");
            assert!(over <= 50);
        }
    }

    #[test]
    fn a_stall_makes_the_ticks_after_it_late_until_the_loop_catches_up() {
        // A clock that the host stops for 230 µs at tick 10 (period 50 µs); each tick after it
        // then takes 10 µs until the loop is back on time, as a plant's late ticks run back to
        // back.
        let period = 50_000;
        let mut clock = 0u64;
        let (p, over) = tally(100, period, 0, &AtomicBool::new(false), |due| {
            if due == 10 * period {
                clock = due + 230_000;
            } else {
                clock = (clock + 10_000).max(due);
            }
            clock
        });
        // Late by 230, 190, 150, 110, 70, 30 µs at ticks 10 to 15: five by more than a period.
        assert_eq!(over, 5);
        assert_eq!(p.count, 100);
        assert!((p.max - 230.0).abs() < 0.5, "{p:?}");
    }
}
