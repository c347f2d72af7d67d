//! The one SIGINT/SIGTERM handler of the `plant` process.
//!
//! A command that stops cleanly (`run`, `soak`, `bench ipc`, the running part of `sweep` and
//! `ensemble`) asks for [`stop_flag`] and polls it; the handler sets it. The first call
//! installs the handler, later calls return the same flag, so every command and the sweep
//! engine share one path however they are combined. A command that never asks keeps the
//! default action (a signal ends it at once).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

/// The flag SIGINT and SIGTERM set; installs the handler on the first call. Where the system
/// refuses the handler, a warning says so and the flag is never set (the signal's default
/// action then ends the process).
pub fn stop_flag() -> Arc<AtomicBool> {
    static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();
    FLAG.get_or_init(|| {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        if let Err(e) = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed)) {
            eprintln!("plant: warning: cannot install the Ctrl-C handler: {e}");
        }
        stop
    })
    .clone()
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_call_returns_the_one_flag() {
        let (a, b) = (super::stop_flag(), super::stop_flag());
        assert!(std::sync::Arc::ptr_eq(&a, &b));
    }
}
