//! The plant of the AMB/touchdown-bearing testbed: the physics of MODEL.md
//! (rotor with unbalance, inner race on Hertzian balls, rotor – race contact
//! with friction, AMB force law, housing moved by a base shock), its
//! integrators, and scene runs with their outputs.
//!
//! Layout: the simulation is the `plant-sim` crate's ([`config`] the scene, [`machine`] the
//! rotor models, [`Plant`] the plant as a value, [`digital`] the digital loop, [`hooks`] what a
//! run reports while it runs), the physics the `plant-physics` crate's ([`force`], [`model`],
//! [`integrate`], [`park`]), both re-exported. This crate is the CLI on them, in layers, each
//! importing only from those below it: [`util`] (shared rooms: files in and out, signals,
//! endings), [`results`] (the rows, their analysis, figures and charts), [`run`] (the loop that
//! owns time, the co-simulation), [`outputs`] (the run folder, `summary.json`, the recording,
//! the FMU file), [`studies`] (report card, comparisons, soaks, sweeps, ensembles, benches). Each
//! module is also re-exported at the crate root, its old path.
#![warn(missing_docs)]

pub use plant_physics::{force, integrate, model, park};
// The simulation's modules at their old paths (`plant::config`, `plant::Plant`, …): the
// `plant-sim` crate's.
pub use plant_sim::{
    config, digital, hardware, hooks, initial, invalid, machine, rest_law, rng, sensor, stepper, Plant,
};

// The layers, each importing only from those below it (util < results < run < outputs <
// studies; tests/tests/modules.rs fails on a cycle between them).
pub mod outputs;
pub mod results;
pub mod run;
pub mod studies;
pub mod util;

// Every module at its old path (`plant::trace`, `plant::assess`, …).
pub use outputs::{fmu_export, live, output, recording, status, summary};
pub use results::{analysis, bounded, figures, plot, record, snapshot, trace};
pub use run::{cosim, offload};
pub use studies::{
    assess, bench, campbell, check, compare, ensemble, grid, linear, robustness, soak, stability, sweep,
};
pub use util::{argument, atomic, claim, exit, input, interrupt, outfile, row_file, table};

/// A shipped scene (`config/FILE`) with `sets` applied, for the library's tests.
#[cfg(test)]
pub(crate) fn shipped(file: &str, sets: &[&str]) -> config::Scene {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config").join(file);
    config::load_scene(&path, &sets.iter().map(|s| s.to_string()).collect::<Vec<_>>())
        .unwrap_or_else(|e| panic!("config/{file} {sets:?}: {e}"))
}
