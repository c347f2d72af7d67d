//! The plant of the AMB/touchdown-bearing testbed: the physics of MODEL.md
//! (rotor with unbalance, inner race on Hertzian balls, rotor – race contact
//! with friction, AMB force law, housing moved by a base shock), its
//! integrators, and scene runs with their outputs.
//!
//! Layout: [`force`] holds one kernel per force law; [`model`] the pure
//! derivative; [`integrate`] the hand-written integrators; [`park`] the parked
//! race (these four are the `plant-physics` crate's, re-exported); [`config`] the
//! scene files; [`run`] the loop that owns time ([`hooks`] what it reports
//! while it runs); [`trace`] the rows of a run and `trace.csv`, [`record`]
//! the one pass over them (bounded stores in [`bounded`]), [`summary`] and
//! [`analysis`] their figures, [`status`] how a run ended, [`output`] the run
//! folder ([`claim`]: one live process per folder) and [`plot`] the charts.
#![warn(missing_docs)]

pub use plant_physics::{force, integrate, model, park};
pub use run::stepper::Plant;
pub use run::{digital, stepper};

pub mod analysis;
pub mod argument;
pub mod assess;
pub mod atomic;
pub mod bench;
pub mod bounded;
pub mod campbell;
pub mod check;
pub mod claim;
pub mod compare;
pub mod config;
pub mod cosim;
pub mod ensemble;
pub mod exit;
pub mod figures;
pub mod fmu_export;
pub mod grid;
pub mod hardware;
pub mod hooks;
pub mod initial;
pub mod input;
pub mod interrupt;
pub mod invalid;
pub mod linear;
pub mod machine;
pub mod offload;
pub mod outfile;
pub mod output;
pub mod plot;
pub mod record;
pub mod recording;
pub mod rest_law;
pub mod rng;
pub mod robustness;
pub mod row_file;
pub mod run;
pub mod sensor;
pub mod snapshot;
pub mod soak;
pub mod stability;
pub mod status;
pub mod summary;
pub mod sweep;
pub mod table;
pub mod trace;
