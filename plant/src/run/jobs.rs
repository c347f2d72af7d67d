//! How many runs of a scene go at once: a co-simulated scene's runs share a small pool, the
//! others rayon's global pool.

use crate::config::{ControlMode, Scene};

/// Runs of a co-simulated controller (lockstep, realtime) at once: each run is two processes
/// that mostly wait for each other, so more runs than cores fill the gaps. Measured on the shared
/// 2-core machine at a load average of 13 (10 000 lockstep ticks of `pd_notch` per run): 4 600
/// ticks a second in all with 2 runs at once, 8 600 with 4, 10 400 with 8, and with 16 the
/// plant's liveness checks of late replies piled up (p99 round trip 0.4 s, 50 times slower).
pub const COSIM_JOBS: usize = 4;

/// `f` on a pool of [`COSIM_JOBS`] threads when `scene`'s controller is a process of its own in
/// lockstep, on rayon's global pool (one thread per core) otherwise (a realtime run needs its
/// core: more runs at once would only miss their deadlines).
pub fn jobs_for<R: Send>(scene: &Scene, f: impl FnOnce() -> R + Send) -> R {
    if scene.controller.mode != ControlMode::Lockstep {
        return f();
    }
    match rayon::ThreadPoolBuilder::new().num_threads(COSIM_JOBS).build() {
        Ok(pool) => pool.install(f),
        Err(_) => f(),
    }
}
