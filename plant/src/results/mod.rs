//! What a run leaves in memory and the figures made of it: the rows and `trace.csv`
//! ([`trace`]), the one pass over them ([`record`], bounded stores in [`bounded`]), their
//! analysis and figures ([`analysis`], [`figures`]), the charts ([`plot`]), a saved state's file
//! ([`snapshot`]). Below the run loop: the loop writes into them.

pub mod analysis;
pub mod bounded;
pub mod figures;
pub mod plot;
pub mod record;
pub mod snapshot;
pub mod trace;
