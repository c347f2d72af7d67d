//! What the plant's ticks cost: the execution time of each tick (TET) and its parts, and the
//! latency histograms they go to (also the co-simulation's, `plant::cosim::stats`).
//!
//! Latencies go to HDR histograms (the `hdrhistogram` crate) of fixed size, allocated once per
//! run, so a run's memory does not grow with its number of ticks. Precision: three significant
//! digits, i.e. a percentile is the upper end of the histogram bucket that holds the
//! nearest-rank sample, at most 1/1024 (0.1 %) above the exact value and never below it; the
//! maximum and the count are exact. Range: 1 ns to one hour (longer ones are recorded as one
//! hour).

use hdrhistogram::Histogram;
use serde::Serialize;

/// Latency percentiles (µs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Percentiles {
    /// Samples the figures are taken over.
    pub count: u64,
    /// Median (µs).
    pub p50: f64,
    /// 99th percentile (µs).
    pub p99: f64,
    /// 99.9th percentile (µs).
    pub p999: f64,
    /// Largest (µs).
    pub max: f64,
}

/// Largest latency a histogram holds (ns): one hour.
pub const HIGHEST_NS: u64 = 3_600_000_000_000;

/// Latencies in nanoseconds, in a fixed-size HDR histogram (about 270 kB, allocated once).
#[derive(Debug, Clone)]
pub struct Latencies {
    histogram: Histogram<u64>,
    /// The exact largest sample (ns).
    max: u64,
}

impl Default for Latencies {
    fn default() -> Self {
        Self::new()
    }
}

impl Latencies {
    /// An empty store.
    pub fn new() -> Self {
        // Bounds and precision are constants that Histogram accepts (1 ≤ low, high ≥ 2 low, 3
        // significant digits): this cannot fail.
        let histogram = Histogram::new_with_bounds(1, HIGHEST_NS, 3).expect("valid histogram bounds");
        Self { histogram, max: 0 }
    }

    /// Records one latency (ns); saturates at one hour.
    #[inline]
    pub fn record(&mut self, ns: u64) {
        let ns = ns.clamp(1, HIGHEST_NS);
        self.histogram.saturating_record(ns);
        self.max = self.max.max(ns);
    }

    /// Nearest-rank percentiles, within 0.1 % (see the module doc); the maximum exact.
    ///
    /// ```
    /// let mut l = plant_sim::tick_time::Latencies::new();
    /// for ns in [1000, 2000, 3000, 4000] { l.record(ns); }
    /// let p = l.percentiles();
    /// assert_eq!((p.count, p.max), (4, 4.0));
    /// assert!(p.p50 >= 2.0 && p.p50 <= 2.0 * (1.0 + 1.0 / 1024.0), "{}", p.p50);
    /// ```
    pub fn percentiles(&self) -> Percentiles {
        let count = self.histogram.len();
        if count == 0 {
            return Percentiles::default();
        }
        let at = |q: f64| self.histogram.value_at_quantile(q).min(self.max) as f64 * 1e-3;
        Percentiles { count, p50: at(0.5), p99: at(0.99), p999: at(0.999), max: self.max as f64 * 1e-3 }
    }
}

/// Bins of the chart of execution times over a run (`tet.png`).
pub const TET_CHART_BINS: u64 = 2000;

/// The plant's execution time of one tick (ns): what [`Tet`] records.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TickTime {
    /// From the tick's start to the command applied to the model.
    pub command_ns: u64,
    /// The integration over the tick alone (the output rows it hands on left out).
    pub integration_ns: u64,
    /// From the tick's start to the end of its integration.
    pub tick_ns: u64,
    /// The rotor touched its race at the tick's start or end.
    pub contact: bool,
}

/// The execution times of one bin of ticks over the run (ns): the largest and the sum.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TetBin {
    /// First tick of the bin.
    pub first_tick: u64,
    /// Ticks recorded in the bin.
    pub ticks: u64,
    /// Largest tick time.
    pub tick_max_ns: u64,
    /// Sum of the tick times (for the mean).
    pub tick_sum_ns: u64,
    /// Largest command time.
    pub command_max_ns: u64,
    /// Largest integration time.
    pub integration_max_ns: u64,
}

/// The plant's execution time per tick (TET, as real-time targets call a task's execution
/// time), in fixed-size HDR histograms ([`Latencies`]) and at most [`TET_CHART_BINS`] bins
/// over the run for its chart: allocated once, whatever the run's length.
#[derive(Clone, Debug)]
pub struct Tet {
    tick: Latencies,
    command: Latencies,
    integration: Latencies,
    contact: Latencies,
    per_bin: u64,
    bins: Vec<TetBin>,
}

impl Tet {
    /// An empty record for a run of `ticks` ticks.
    pub fn new(ticks: u64) -> Self {
        let per_bin = ticks.div_ceil(TET_CHART_BINS).max(1);
        Self {
            tick: Latencies::new(),
            command: Latencies::new(),
            integration: Latencies::new(),
            contact: Latencies::new(),
            per_bin,
            bins: Vec::with_capacity(ticks.div_ceil(per_bin).min(TET_CHART_BINS) as usize),
        }
    }

    /// Records tick `k` (ticks come in order).
    ///
    /// ```
    /// use plant_sim::tick_time::{Tet, TickTime};
    /// let mut tet = Tet::new(4);
    /// for k in 0..4 {
    ///     tet.record(k, TickTime { command_ns: 1000, integration_ns: 2000 * (k + 1), tick_ns: 4000 * (k + 1), contact: k == 3 });
    /// }
    /// let r = tet.report();
    /// assert_eq!((r.tick.count, r.tick.max, r.integration_contact.count), (4, 16.0, 1));
    /// assert_eq!(tet.bins().len(), 4);
    /// ```
    pub fn record(&mut self, k: u64, t: TickTime) {
        self.tick.record(t.tick_ns);
        self.command.record(t.command_ns);
        self.integration.record(t.integration_ns);
        if t.contact {
            self.contact.record(t.integration_ns);
        }
        let first_tick = k / self.per_bin * self.per_bin;
        if self.bins.last().is_none_or(|b| b.first_tick != first_tick) {
            if self.bins.len() as u64 >= TET_CHART_BINS {
                return; // a tick past the run's length (never: the loop runs the ticks it was made for)
            }
            self.bins.push(TetBin { first_tick, ..TetBin::default() });
        }
        if let Some(b) = self.bins.last_mut() {
            b.ticks += 1;
            b.tick_max_ns = b.tick_max_ns.max(t.tick_ns);
            b.tick_sum_ns += t.tick_ns;
            b.command_max_ns = b.command_max_ns.max(t.command_ns);
            b.integration_max_ns = b.integration_max_ns.max(t.integration_ns);
        }
    }

    /// The percentiles (µs).
    pub fn report(&self) -> TetReport {
        TetReport {
            tick: self.tick.percentiles(),
            command: self.command.percentiles(),
            integration: self.integration.percentiles(),
            integration_contact: self.contact.percentiles(),
        }
    }

    /// The bins over the run, in order.
    pub fn bins(&self) -> &[TetBin] {
        &self.bins
    }
}

/// The `tet_us` object of `summary.json`'s `cosim`: the plant's execution time per tick,
/// percentiles in µs (see [`Percentiles`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct TetReport {
    /// From the tick's start (lockstep: the plant reads the sample; realtime: the plant wakes
    /// at the tick's wall-clock time) to the end of its integration: the plant's whole tick,
    /// its output rows included.
    pub tick: Percentiles,
    /// From the tick's start to the command applied to the model: lockstep, the round trip
    /// through the controller; realtime, taking the reply that came and publishing the sample.
    pub command: Percentiles,
    /// The integration over the tick alone (the park decision and the output rows left out).
    pub integration: Percentiles,
    /// `integration` over the ticks that start or end with the rotor touching its race.
    pub integration_contact: Percentiles,
}
