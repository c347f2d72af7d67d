//! The simulation of the AMB/touchdown-bearing testbed, on a floor of its own: the scene
//! ([`config`]), the rotor models ([`machine`]: planar, two-plane, flexible), the AMB hardware
//! and the sensor ([`hardware`], [`sensor`]), the initial state ([`initial`]), the plant as a
//! value anything steps ([`Plant`], [`stepper`]) and its [`snapshot`], the digital loop with its
//! invalid-command budget ([`digital`], [`invalid`]), and the contract of a run: the rows it
//! makes ([`rows`]), where they go and how it ends ([`run`]), what its ticks cost
//! ([`tick_time`]), what it reports while it runs ([`hooks`]); and the variables the plant
//! answers to as an FMU ([`fmi`]).
//!
//! The physics kernels are the `plant-physics` crate's ([`force`], [`model`], [`integrate`],
//! [`park`], re-exported). The CLI (`plant`: its run loop, co-simulation, outputs, studies)
//! and the plant FMU (`plant-fmu`) stand on this crate; it imports nothing of theirs, and
//! writes no file.
#![warn(missing_docs)]

pub use plant_physics::{force, integrate, model, park};
pub use stepper::Plant;

pub mod config;
pub mod digital;
pub mod fmi;
pub mod hardware;
pub mod hooks;
pub mod initial;
pub mod invalid;
pub mod machine;
pub mod rest_law;
pub mod rng;
pub mod rows;
pub mod run;
pub mod sensor;
pub mod snapshot;
pub mod start;
pub mod status;
pub mod stepper;
pub mod tick_time;
