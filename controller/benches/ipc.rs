//! Ping-pong of the IPC loop: one sensor frame out, one command frame back,
//! through the same [`controller::link::Endpoint`]s the plant and the
//! controller process use, with the peer in a second thread of this process
//! (same shared-memory path as two processes; `plant bench ipc` measures
//! the two-process round trip with the real `controller` binary and prints
//! p50/p99/p99.9/max).
//!
//! Run: `cargo bench -p controller --bench ipc`.

use controller::link::{self, Endpoint};
use controller::wire::{CommandFrame, SensorFrame};
use criterion::{criterion_group, criterion_main, Criterion};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

const SPIN: Duration = Duration::from_micros(200);
const SLICE: Duration = Duration::from_millis(1);

fn ping_pong(c: &mut Criterion) {
    iceoryx2::prelude::set_log_level(iceoryx2::prelude::LogLevel::Fatal);
    let run_id = format!("bench-{}", std::process::id());
    let stop = Arc::new(AtomicBool::new(false));
    let echo = {
        let (run_id, stop) = (run_id.clone(), stop.clone());
        std::thread::spawn(move || {
            let node = link::node(&run_id, "controller").expect("controller node");
            let mut ep: Endpoint<CommandFrame, SensorFrame> =
                Endpoint::open(&node, &run_id, "command", "sensor", SPIN).expect("controller endpoint");
            while !stop.load(Ordering::Relaxed) {
                if let Ok(Some(f)) = ep.wait(SLICE, || !stop.load(Ordering::Relaxed)) {
                    let reply = CommandFrame { seq: f.seq, current_a: f.sensor_v, ..Default::default() };
                    ep.send(reply).expect("reply");
                }
            }
        })
    };
    let node = link::node(&run_id, "plant").expect("plant node");
    let mut ep: Endpoint<SensorFrame, CommandFrame> =
        Endpoint::open(&node, &run_id, "sensor", "command", SPIN).expect("plant endpoint");
    let mut seq = 0u64;
    // Sends a frame and waits for its reply; sends again if none comes within
    // 10 ms (frames sent before the echo thread subscribed are lost).
    let mut round_trip = |ep: &mut Endpoint<SensorFrame, CommandFrame>| {
        seq += 1;
        loop {
            ep.send(SensorFrame { seq, ..Default::default() }).expect("send");
            let sent = Instant::now();
            loop {
                match ep.wait(SLICE, || sent.elapsed() < Duration::from_millis(10)).expect("wait") {
                    Some(r) if r.seq == seq => return,
                    Some(_) => continue,
                    None => break,
                }
            }
        }
    };
    let warm = Instant::now();
    while warm.elapsed() < Duration::from_millis(200) {
        round_trip(&mut ep);
    }
    c.bench_function("ipc round trip (sensor frame -> command frame)", |b| b.iter(|| round_trip(&mut ep)));
    stop.store(true, Ordering::Relaxed);
    let _ = ep.send(SensorFrame::default());
    echo.join().expect("echo thread");
}

criterion_group!(benches, ping_pong);
criterion_main!(benches);
