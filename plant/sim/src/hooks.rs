//! What the run loop reports to its caller while it runs: progress, a
//! cancellation flag, messages for the user, controller connections.
//!
//! Its own room, so that the run loop ([`crate::run`]) and the
//! co-simulation session ([`crate::cosim`]) both use it without importing
//! each other.

/// What the loop reports to its caller while it runs.
pub trait Hooks {
    /// Called after each macro step with the simulated time (s).
    fn progress(&mut self, _t: f64) {}
    /// Polled after each macro step; `true` stops the run cleanly.
    fn cancelled(&self) -> bool {
        false
    }
    /// Polled after each macro step, after [`Hooks::cancelled`]; `true` ends the run there as
    /// completed: the caller has what it needs from it (an assessment's ladder member whose
    /// outcome is decided before the scene's end: [`crate::assess::ladder`]). The default: never.
    fn finished(&self) -> bool {
        false
    }
    /// A message for the user (co-simulation: waiting for a controller, a
    /// lost controller); the loop itself never prints.
    fn note(&mut self, _message: &str) {}
    /// Co-simulation: a controller process connected (at the start, or after a
    /// reconnection), with its process id from the handshake.
    fn controller_connected(&mut self, _pid: u32) {}
    /// Measure the plant's execution time per tick in every mode (co-simulation runs always
    /// do): `plant bench tick`.
    fn time_ticks(&self) -> bool {
        false
    }
    /// A sine to add to the sensor signal the controller reads over the macro step from tick
    /// `k` at time `t` (s) (the summing point of a sensitivity measurement, ISO 14839-3), on
    /// one bearing plane's two axes; `sensor_v` holds the values read at that tick, before the
    /// sine, one per axis (the planes in order). The loop adds `E(t_k)` to the sample a sampled
    /// or co-simulated law gets, and hands the sine itself to the plane's continuous PD, which
    /// reads it inside the derivative. `None` (the default): no excitation.
    fn excitation(&mut self, _k: u64, _t: f64, _sensor_v: &[f64]) -> Option<Excitation> {
        None
    }
    /// Times (s, sorted) at which to take the plant's state (`plant run --save-state-at`): the
    /// loop takes it at the end of the first tick at or after each, and hands it to
    /// [`Hooks::state_saved`]. The default: none.
    fn save_state_at(&self) -> &[f64] {
        &[]
    }
    /// The state asked for at `at` (s) by [`Hooks::save_state_at`].
    fn state_saved(&mut self, _at: f64, _snapshot: crate::snapshot::Snapshot) {}
}

/// A sine on one bearing plane's sensor signal ([`Hooks::excitation`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Excitation {
    /// The bearing plane (0: A, the planar model's only one; 1: B).
    pub plane: usize,
    /// The sine on that plane's x and y axes.
    pub sine: crate::model::SensorSine,
}

/// Hooks that do nothing.
pub struct Quiet;
impl Hooks for Quiet {}

/// Hooks that only stop the run when the flag is set (a sweep's or an ensemble's runs, stopped
/// by SIGINT/SIGTERM).
pub struct Cancel<'a>(pub &'a std::sync::atomic::AtomicBool);
impl Hooks for Cancel<'_> {
    fn cancelled(&self) -> bool {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }
}
