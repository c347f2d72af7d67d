//! How long iceoryx2's timed waits really take on this machine, and what a
//! peer lookup costs: the figures `docs/wire-protocol.md` quotes.
//!
//! 1. A listener with nobody to notify it waits `--slice-us` (default 1000 µs)
//!    at a time, through the same [`Endpoint::wait`] the plant and the
//!    controller use (spin budget 0): each slice's wall time is recorded.
//! 2. [`link::peer`] (a listing of iceoryx2's nodes) is timed.
//!
//! Run: `cargo run --release -p controller --example timed_wait [-- --slices N --slice-us US]`.

use controller::link::{self, Endpoint};
use controller::wire::{CommandFrame, SensorFrame};
use std::time::{Duration, Instant};

fn percentile(sorted: &[f64], q: f64) -> f64 {
    let rank = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    sorted[rank - 1]
}

fn summary(name: &str, mut v: Vec<f64>) {
    v.sort_by(f64::total_cmp);
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    println!(
        "{name}: n {}, mean {mean:.1} us, p50 {:.1} us, p99 {:.1} us, max {:.1} us",
        v.len(),
        percentile(&v, 0.5),
        percentile(&v, 0.99),
        v.last().copied().unwrap_or(0.0)
    );
}

fn main() {
    iceoryx2::prelude::set_log_level(iceoryx2::prelude::LogLevel::Fatal);
    let args: Vec<String> = std::env::args().collect();
    let arg = |flag: &str, default: u64| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .and_then(|v| v.parse().ok())
            .unwrap_or(default)
    };
    let (slices, slice_us) = (arg("--slices", 500), arg("--slice-us", 1000));
    let run_id = format!("timed-wait-{}", std::process::id());
    let node = link::node(&run_id, "plant").expect("node");
    let mut ep: Endpoint<SensorFrame, CommandFrame> =
        Endpoint::open(&node, &run_id, "sensor", "command", Duration::ZERO).expect("endpoint");
    let mut lengths = Vec::with_capacity(slices as usize);
    let mut last = Instant::now();
    let _ = ep.wait(Duration::from_micros(slice_us), || {
        let now = Instant::now();
        lengths.push((now - last).as_secs_f64() * 1e6);
        last = now;
        lengths.len() < slices as usize
    });
    summary(&format!("timed wait of {slice_us} us, nobody notifying"), lengths);
    let mut lookups = Vec::new();
    for _ in 0..200 {
        let t = Instant::now();
        let _ = link::peer(&run_id, "controller");
        lookups.push(t.elapsed().as_secs_f64() * 1e6);
    }
    summary("peer lookup (link::peer, a listing of the nodes)", lookups);
}
