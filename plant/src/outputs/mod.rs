//! A run's folder and what it says of the run: the folder ([`output`]), `summary.json`
//! ([`summary`]), how a run ended ([`status`]), the MCAP recording ([`recording`]) and the live view of a run ([`live`]), the plant's
//! FMU file ([`fmu_export`]). Above the run loop, below the studies.

pub mod fmu_export;
pub mod live;
pub mod output;
pub mod recording;
pub mod status;
pub mod summary;
