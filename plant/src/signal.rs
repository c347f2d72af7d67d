//! The one SIGINT/SIGTERM handler of a `plant` process: it sets a flag that
//! the commands poll, so that each stops in order (writes what it has, says
//! so, exits 130) instead of dying by the signal. Installed once, by the
//! first command that asks for it ([`install`]); the commands that never ask
//! keep the default action (a signal ends them at once).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;

static STOP: AtomicBool = AtomicBool::new(false);
static INSTALLED: OnceLock<Option<String>> = OnceLock::new();

/// Installs the handler (once per process) and returns the flag it sets; the second element
/// is a warning when the handler could not be installed (the first time only).
pub fn install() -> (&'static AtomicBool, Option<String>) {
    let mut first = false;
    let failed = INSTALLED.get_or_init(|| {
        first = true;
        ctrlc::set_handler(|| STOP.store(true, Ordering::Relaxed))
            .err()
            .map(|e| format!("cannot install the Ctrl-C handler: {e}"))
    });
    (&STOP, failed.clone().filter(|_| first))
}

/// True once SIGINT or SIGTERM has arrived (after [`install`]).
pub fn stopped() -> bool {
    STOP.load(Ordering::Relaxed)
}
