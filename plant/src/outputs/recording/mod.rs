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

pub mod events;
pub mod extra;
pub mod mcap_file;
pub mod orbit;
pub mod ticks;
pub mod topics;
