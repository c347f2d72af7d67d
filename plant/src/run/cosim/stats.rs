//! Figures of a co-simulation: message counts, deadline misses and their
//! bursts, latency percentiles, peer events, and the `cosim` object of
//! `summary.json` they make ([`CosimReport`]).
//!
//! Latencies go to HDR histograms (the `hdrhistogram` crate) of fixed size,
//! allocated once per session, so a run's memory does not grow with its
//! number of ticks. Precision: three significant digits, i.e. a percentile is
//! the upper end of the histogram bucket that holds the nearest-rank sample,
//! at most 1/1024 (0.1 %) above the exact value and never below it; the
//! maximum and the count are exact. Range: 1 ns to one hour (longer ones are
//! recorded as one hour).

use super::PeerEvent;
use serde::Serialize;

pub use plant_sim::tick_time::{Latencies, Percentiles, Tet, TetBin, TetReport, TickTime, HIGHEST_NS, TET_CHART_BINS};

/// Counts deadline misses and the longest run of consecutive ones.
#[derive(Debug, Default, Clone, Copy, PartialEq)]
pub struct Misses {
    /// Ticks whose reply was missing.
    pub total: u64,
    /// Longest run of consecutive misses.
    pub longest_burst: u64,
    current: u64,
}

impl Misses {
    /// Records one tick: `missed` or on time.
    ///
    /// ```
    /// let mut m = plant::cosim::stats::Misses::default();
    /// for missed in [true, true, false, true] { m.record(missed); }
    /// assert_eq!((m.total, m.longest_burst), (3, 2));
    /// ```
    #[inline]
    pub fn record(&mut self, missed: bool) {
        if missed {
            self.total += 1;
            self.current += 1;
            self.longest_burst = self.longest_burst.max(self.current);
        } else {
            self.current = 0;
        }
    }
}

/// The counters of a session, kept as the run goes.
#[derive(Debug, Default, Clone)]
pub struct Figures {
    /// Sensor frames published.
    pub sent: u64,
    /// Command frames of the current session received.
    pub received: u64,
    /// Samples skipped in the sequence of replies.
    pub gaps: u64,
    /// Replies to an older sample (or late, realtime).
    pub stale: u64,
    /// Frames and acks with another run's token.
    pub foreign: u64,
    /// Deadline misses (realtime).
    pub misses: Misses,
    /// Ticks that had a reply due (realtime).
    pub due: u64,
    /// Realtime ticks started more than a period late.
    pub overruns: u64,
    /// Realtime ticks started.
    pub ticks: u64,
    /// Ticks run on the fallback current.
    pub fallback_ticks: u64,
    /// The last reply's `seq` (for the gaps).
    pub last_reply_seq: Option<u64>,
    /// Sensor frame published → command frame published (ns).
    pub latency: Latencies,
    /// Sensor frame published → reply in the plant's hands (ns), lockstep.
    pub round_trip: Latencies,
    /// Connections, losses, reconnections, stops.
    pub events: Vec<PeerEvent>,
}

impl Figures {
    /// `Some(why)` if the share of ticks without the controller's reply (the deadline misses,
    /// and the fallback ticks while no controller was connected: either way not the scene's
    /// loop) exceeds `budget` (`controller.max_miss_fraction`), judged over at least `min_due`
    /// such ticks.
    ///
    /// ```
    /// let mut f = plant::cosim::stats::Figures::default();
    /// (f.due, f.fallback_ticks) = (1000, 0);
    /// (0..5).for_each(|_| f.misses.record(true));
    /// assert_eq!(f.miss_budget(0.01, 1000), None); // 5 in 1000
    /// f.fallback_ticks = 20;                          // the controller lost, a new one awaited
    /// let why = f.miss_budget(0.01, 1000).unwrap();   // 25 in 1020
    /// assert!(why.contains("5 deadline misses and 20 fallback ticks without a controller in 1020 ticks"), "{why}");
    /// assert_eq!(f.miss_budget(1.0, 1000), None);   // 1: no limit
    /// assert_eq!(f.miss_budget(0.01, 2000), None);  // not yet judged
    /// ```
    pub fn miss_budget(&self, budget: f64, min_due: u64) -> Option<String> {
        let (without, ticks) = (self.misses.total + self.fallback_ticks, self.due + self.fallback_ticks);
        let share = without as f64 / ticks.max(1) as f64;
        (ticks >= min_due.max(1) && share > budget).then(|| {
            let fallback = match self.fallback_ticks {
                0 => String::new(),
                n => format!(" and {n} fallback ticks without a controller"),
            };
            format!(
                "realtime: {} deadline misses{fallback} in {ticks} ticks ({:.3} %) exceed controller.max_miss_fraction \
                 = {budget}: the loop that ran is not the scene's (1 is no limit)",
                self.misses.total,
                100.0 * share
            )
        })
    }

    /// Notes a reply's `seq`, counting the samples skipped since the last one.
    ///
    /// ```
    /// let mut f = plant::cosim::stats::Figures::default();
    /// for seq in [0, 1, 4, 5] { f.note_reply_seq(seq); }
    /// assert_eq!(f.gaps, 2);
    /// ```
    pub fn note_reply_seq(&mut self, seq: u64) {
        if let Some(last) = self.last_reply_seq {
            if seq > last + 1 {
                self.gaps += seq - last - 1;
            }
        }
        self.last_reply_seq = Some(seq);
    }

    /// The deadline-miss fraction so far (misses over the ticks that had a reply due).
    pub fn miss_fraction(&self) -> f64 {
        self.misses.total as f64 / self.due.max(1) as f64
    }

    /// The plant-overrun fraction so far (overruns over the realtime ticks started).
    pub fn overrun_fraction(&self) -> f64 {
        self.overruns as f64 / self.ticks.max(1) as f64
    }

    /// Starts the latency figures afresh (after a warm-up).
    pub fn reset_latencies(&mut self) {
        self.latency = Latencies::new();
        self.round_trip = Latencies::new();
    }
}

/// The `cosim` object of `summary.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CosimReport {
    /// `lockstep` or `realtime`.
    pub mode: &'static str,
    /// Run id (service names `amb-testbed/<run_id>/…`).
    pub run_id: String,
    /// What the (last) controller said it runs.
    pub controller: String,
    /// The controller process's command line, when the scene gives one (`controller.command`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub controller_command: Option<Vec<String>>,
    /// Handshakes made (1 + reconnections).
    pub sessions: u32,
    /// Sensor frames published.
    pub messages_sent: u64,
    /// Command frames received (current session's).
    pub messages_received: u64,
    /// Samples skipped in the sequence of replies (never answered).
    pub sequence_gaps: u64,
    /// Replies that came after their tick (realtime) or answered an older sample.
    pub stale_replies: u64,
    /// Replies with non-finite currents (the last valid command was held), counted by the run
    /// loop (`invalid_commands` of the summary, the same number in co-simulation).
    pub invalid_replies: u64,
    /// Frames and handshake answers carrying another run's token (never applied).
    pub foreign_frames: u64,
    /// Ticks whose reply was missing (realtime).
    pub deadline_misses: u64,
    /// `deadline_misses` over the ticks that had a reply due.
    pub deadline_miss_fraction: f64,
    /// Longest run of consecutive misses.
    pub longest_miss_burst: u64,
    /// Realtime ticks that started more than one period late (the plant could not keep up).
    pub plant_overruns: u64,
    /// `plant_overruns` over the realtime ticks.
    pub plant_overrun_fraction: f64,
    /// Realtime: no deadline miss and no plant overrun, every tick on time (`null` in lockstep).
    pub schedule_held: Option<bool>,
    /// Ticks run on the fallback current while no controller was connected.
    pub fallback_ticks: u64,
    /// Waits of the plant that outlasted the spin budget and blocked.
    pub blocking_waits: u64,
    /// Blocked waits of the plant that the controller ended by a notification (it served the
    /// plant's wake request).
    pub woken_waits: u64,
    /// Slices of the plant's blocked waits (1 ms asked, longer in fact) that ran out without a
    /// notification: a controller slower than a slice, or one that does not wake the plant.
    pub timed_out_waits: u64,
    /// Blocked waits of the plant whose reply was found only after a slice had run out
    /// without a notification: those that progressed by a timeout, not by the controller's
    /// wake-up (every blocked wait of a controller that does not serve wake requests).
    pub unwoken_waits: u64,
    /// Lookups of the controller's node (a listing of the machine's iceoryx2 nodes) while it
    /// was silent: an external controller's sign of life, paced so that they take at most a
    /// twentieth of the wait; none for a controller the plant started and that still runs.
    pub node_lookups: u64,
    /// Scheduling of the plant's loop thread and of the controller (`fifo` with
    /// `controller.realtime_priority`, else `other`).
    pub scheduling: Scheduling,
    /// Sensor frame published → command frame published by the controller (both stamped
    /// with `CLOCK_MONOTONIC`), µs, from the first frame of the run (or after the warm-up of
    /// `plant bench ipc`) to the last.
    pub latency_us: Percentiles,
    /// Lockstep: sensor frame published → reply in the plant's hands, µs.
    pub round_trip_us: Option<Percentiles>,
    /// The plant's execution time per tick, µs ([`TetReport`]), filled in by the run loop.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tet_us: Option<TetReport>,
    /// Connections, losses, reconnections, stops.
    pub peer_events: Vec<PeerEvent>,
    /// What the (last) controller ran differently from the scene (the `[controller]` table of
    /// its handshake's overrides, from its `--config` or `--law`); absent if nothing.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub controller_overrides: Option<toml::Table>,
}

/// Scheduling policies in force (`fifo`, `other`, …).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Scheduling {
    /// `controller.realtime_priority` (0: off).
    pub realtime_priority: u32,
    /// The plant's loop thread.
    pub plant: String,
    /// The (last) controller's main thread, as the plant sees it.
    pub controller: String,
    /// The controller's `SCHED_FIFO` priority as the plant reads it: one below the plant's
    /// (`controller.realtime_priority` − 1, at least 1); absent when it is not under FIFO.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub controller_priority: Option<u32>,
    /// Realtime: `controller.pacing` (`spin` or `sleep`); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pacing: Option<String>,
    /// Realtime: `kernel.sched_rt_runtime_us` during the run (`-1`: RT throttling off), where
    /// `/proc` tells.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rt_runtime_us: Option<i64>,
    /// Realtime with a priority: the idle wake-up latency the run held every core to
    /// through `/dev/cpu_dma_latency` (0 µs), absent where it could not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub idle_latency_us: Option<u32>,
    /// What the system refused (no `SCHED_FIFO`, no memory locking), if anything.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub refused: Vec<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Nearest rank over the sorted samples, exactly.
    fn exact(sorted: &[u64], q: f64) -> f64 {
        let n = sorted.len() as f64;
        let rank = ((q * n).ceil() as usize).clamp(1, sorted.len());
        sorted[rank - 1] as f64 * 1e-3
    }

    #[test]
    fn percentiles_are_within_a_tenth_of_a_percent_above_the_exact_ones() {
        let mut l = Latencies::new();
        let mut all = Vec::new();
        // A deterministic spread from 0.5 µs to about 5 ms.
        let mut rng = crate::rng::SplitMix64::new(12345);
        for _ in 0..20_000 {
            let x = rng.next_u64();
            let ns = 500 + (x >> 33) % 5_000_000 / (1 + (x >> 60));
            l.record(ns);
            all.push(ns);
        }
        all.sort_unstable();
        let p = l.percentiles();
        assert_eq!(p.count, 20_000);
        assert_eq!(p.max, *all.last().unwrap() as f64 * 1e-3);
        for (q, got) in [(0.5, p.p50), (0.99, p.p99), (0.999, p.p999)] {
            let want = exact(&all, q);
            assert!(got >= want && got <= want * (1.0 + 1.0 / 1024.0), "q {q}: exact {want} µs, histogram {got} µs");
        }
    }

    #[test]
    fn an_empty_store_gives_zeros_and_huge_values_saturate() {
        assert_eq!(Latencies::new().percentiles(), Percentiles::default());
        let mut l = Latencies::new();
        l.record(u64::MAX);
        l.record(0);
        let p = l.percentiles();
        assert_eq!((p.count, p.max), (2, HIGHEST_NS as f64 * 1e-3));
    }
}
