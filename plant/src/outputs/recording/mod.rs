//! Recordings of a run for the tools robotics and test engineers use (issue 42): `run.mcap`
//! (`plant run --mcap`, `[output] mcap = true`), read by Foxglove, Lichtblick, PlotJuggler and
//! the `mcap` libraries. docs/guide/live-view.md is the user's page.
//!
//! * [`topics`]: the one mapping from a row to the topics' messages and schemas.
//! * [`events`]: the run's events as log lines.
//! * [`mcap_file`]: the file, a [`crate::run::Sink`].

pub mod events;
pub mod mcap_file;
pub mod topics;
