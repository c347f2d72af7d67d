//! The physics of the AMB/touchdown-bearing testbed (MODEL.md): the rotor with unbalance, the
//! inner race on Hertzian balls, the rotor – race contact with friction, the AMB force law and
//! the housing moved by a base shock, with the integrators that step it.
//!
//! Layout: [`force`] holds one kernel per force law; [`model`] the pure derivative on a
//! fixed-size state; [`integrate`] the hand-written integrators, which do not own the state;
//! [`park`] the parked-race simplification; [`initial`] the levitated state a run starts from;
//! [`stability`] the fixed-step integrators' stability estimate; [`amplifier`] one axis's amplifier
//! and coil; [`axes`] a bearing plane's own axes, turned from the housing's (the run loop appends its states to the model's). Scene files, runs and outputs are the `plant`
//! crate's; this crate builds and tests without them.
#![warn(missing_docs)]

pub mod amplifier;
pub mod axes;
pub mod flex;
pub mod force;
pub mod initial;
pub mod integrate;
pub mod model;
pub mod number;
pub mod park;
pub mod stability;
pub mod two_plane;
