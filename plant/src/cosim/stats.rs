//! Figures of a co-simulation: latency percentiles and deadline-miss bursts.
//! Storage is reserved before the loop; recording is a push into it.

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

/// Latencies in nanoseconds, stored whole (exact percentiles), capacity
/// reserved up front.
#[derive(Debug, Default)]
pub struct Latencies {
    ns: Vec<u32>,
}

impl Latencies {
    /// Room for `n` samples without reallocation.
    pub fn with_capacity(n: usize) -> Self {
        Self { ns: Vec::with_capacity(n) }
    }

    /// Records one latency (ns); saturates at about 4.3 s.
    #[inline]
    pub fn record(&mut self, ns: u64) {
        self.ns.push(u32::try_from(ns).unwrap_or(u32::MAX));
    }

    /// Nearest-rank percentiles.
    ///
    /// ```
    /// let mut l = plant::cosim::stats::Latencies::with_capacity(4);
    /// for ns in [1000, 2000, 3000, 4000] { l.record(ns); }
    /// let p = l.percentiles();
    /// assert_eq!((p.p50, p.max, p.count), (2.0, 4.0, 4));
    /// ```
    pub fn percentiles(&self) -> Percentiles {
        if self.ns.is_empty() {
            return Percentiles::default();
        }
        let mut sorted = self.ns.clone();
        sorted.sort_unstable();
        let rank = |q: f64| {
            let i = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len()) - 1;
            f64::from(sorted[i]) * 1e-3
        };
        Percentiles {
            count: sorted.len() as u64,
            p50: rank(0.5),
            p99: rank(0.99),
            p999: rank(0.999),
            max: f64::from(*sorted.last().unwrap_or(&0)) * 1e-3,
        }
    }
}

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
