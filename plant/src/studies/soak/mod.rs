//! Soak tests (`plant soak`): one long co-simulation, the controller process
//! living through a whole programme of shocks, with per-shock recovery
//! figures, message loss, deadline misses and the resident memory of both
//! processes over time, judged against the programme's criteria.
//!
//! Memory stays flat however long the programme: the output samples go to
//! an online monitor ([`monitor`]) instead of a trace, the co-simulation's
//! latency figures to fixed-size histograms, and everything per shock,
//! per RSS sample and per envelope bin is written to its file as it comes
//! (`soak.csv`, `rss.csv`, `envelope.csv`), so a stopped soak keeps what it
//! measured. `soak.json` is written at the end, through a temporary file and
//! a rename.
//!
//! Files written as the soak goes hold their header from their creation and
//! only whole rows, even after a SIGKILL: rows are formatted (by the `csv`
//! crate) into memory and reach the file in one write of whole rows, at each
//! shock's end (and each RSS sample) and whenever 64 KiB are pending.
//!
//! Rooms: [`run`] (the loop's hooks and the whole soak), [`sink`] (the
//! per-sample figures and the files written as it goes), [`checkpoint`]
//! (the state `plant soak --resume` continues from), [`report`]
//! (`soak.json` and the criteria), [`plots`].

pub mod checkpoint;
pub mod monitor;
pub mod plots;
pub mod programme;
pub mod report;
pub mod rss;
pub mod run;
pub mod sink;

pub use report::{judge, CriterionResult, Finished, ProcessRss, Report, RssReport, Spread};
pub use run::{default_dir, run, Options, Progress, SoakError};

/// Bin of the coarse trace (`envelope.csv`, `radius.png`), s.
pub const ENVELOPE_BIN_S: f64 = 0.005;

/// Header of `soak.csv`.
pub const SOAK_CSV_HEADER: &str = sink::SoakFields::HEADER;

/// Header of `envelope.csv`.
pub const ENVELOPE_CSV_HEADER: &str = monitor::EnvelopeRow::HEADER;

/// Header of `rss.csv`.
pub const RSS_CSV_HEADER: &str = sink::RssFields::HEADER;
