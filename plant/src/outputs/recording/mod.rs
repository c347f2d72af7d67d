//! Recordings of a run for the tools robotics and test engineers use (issue 42): `run.mcap`
//! (`plant run --mcap`, `[output] mcap = true`), read by Foxglove, Lichtblick, PlotJuggler and
//! the `mcap` libraries. docs/guide/live-view.md is the user's page.
//!
//! * [`topics`]: the one mapping from a row to the topics' messages and schemas.
//! * [`events`]: the run's events as log lines.
//! * [`orbit`]: each plane's orbit window with its clearance circle, for an x-y plot.
//! * [`ticks`]: the loop's samples and commands.
//! * [`extra`]: the topics besides the rows', in the sinks' order.
//! * [`mcap_file`]: the file, a [`crate::run::Sink`].
//! * [`member`]: an ensemble's member recorded on request (`plant ensemble --record-member`).

pub mod events;
pub mod extra;
pub mod mcap_file;
pub mod member;
pub mod orbit;
pub mod ticks;
pub mod topics;

use controller::{RotorSample, ROTOR_AXES};

/// Hands a tick of the loop to the recording and the live view a run's sink holds (`plant
/// run`'s folder, a soak's sink): their [`crate::run::Sink::tick`] in one call.
pub fn tick(
    mcap: &mut Option<mcap_file::McapSink>,
    live: &mut Option<crate::live::LiveSink>,
    sample: &RotorSample,
    command: &[f64; ROTOR_AXES],
) {
    if let Some(m) = mcap {
        m.tick(sample, command);
    }
    if let Some(l) = live {
        l.tick(sample, command);
    }
}

/// Whether either takes the loop's ticks ([`crate::run::Sink::wants_ticks`]).
pub fn wants_ticks(mcap: &Option<mcap_file::McapSink>, live: &Option<crate::live::LiveSink>) -> bool {
    mcap.as_ref().is_some_and(|m| m.wants_ticks()) || live.as_ref().is_some_and(|l| l.wants_ticks())
}
