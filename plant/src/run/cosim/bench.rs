//! `plant bench ipc`: round trips with a controller process, through the
//! same [`Session`] a lockstep run uses.

use super::session::{Halt, Session};
use super::{CosimError, Launch, Percentiles};
use crate::config::{ControlMode, CosimSettings, Fallback};
use crate::hooks::Hooks;
use controller::wire::{self, mode, Hello};
use controller::{RotorSample, ROTOR_AXES};

/// `plant bench ipc`: `n` round trips with a controller process (lockstep,
/// zero sensor values), after `warmup` unrecorded ones. Returns the round trips,
/// the latencies (frame published → reply published) and the blocking waits.
pub fn bench_round_trips(
    n: u64,
    warmup: u64,
    launch: &Launch,
    pin_cores: Option<[usize; 2]>,
    spin_us: f64,
    hooks: &mut dyn Hooks,
) -> Result<(Percentiles, Percentiles, u64), CosimError> {
    let run_id = match &launch.run_id {
        Some(id) => wire::valid_run_id(id).map_err(CosimError::RunId)?.to_string(),
        None => super::new_run_id(),
    };
    let mut hello = Hello::example(&run_id);
    hello.token = super::new_token();
    hello.mode = mode::BENCH;
    hello.spin_ns = (spin_us * 1e3) as u64;
    hello.plant_pid = std::process::id();
    let settings = CosimSettings {
        fallback: Fallback::Stop,
        reply_timeout: 0.001,
        reconnect_timeout: 0.0,
        connect_timeout: 10.0,
        lockstep_timeout: 5.0,
        spin: spin_us * 1e-6,
        pin_cores,
        command: None,
        realtime_priority: 0,
        max_miss_fraction: 1.0,
        max_overrun_fraction: 1.0,
        pacing: crate::config::Pacing::Spin,
    };
    let bias = [0.0; ROTOR_AXES];
    let mut s = Session::open(ControlMode::Lockstep, settings, hello, launch, bias, hello.period_s, hooks)?;
    for k in 0..(warmup + n) {
        if k == warmup {
            s.reset_figures();
        }
        let sample = RotorSample { seq: k, t_s: k as f64 * hello.period_s, axes: hello.axes, ..Default::default() };
        if let Err(halt) = s.lockstep(&sample, hooks) {
            let why = match halt {
                Halt::Lost(w) | Halt::Interrupted(w) | Halt::MissBudget(w) | Halt::OverrunBudget(w) => w,
            };
            return Err(CosimError::NoController { waited_s: 0.0, run_id: s.run_id.clone(), hint: format!(": {why}") });
        }
    }
    let blocks = s.frames.blocks();
    let report = s.finish(0.0, warmup + n);
    Ok((report.round_trip_us.unwrap_or_default(), report.latency_us, blocks))
}
