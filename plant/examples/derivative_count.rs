//! Evaluates the model's derivative a fixed number of times, for instruction counts that do not
//! depend on the machine's load (the criterion bench `model` measures time):
//!
//! ```text
//! cargo build --profile bench -p plant --example derivative_count
//! valgrind --tool=callgrind --callgrind-out-file=/dev/null \
//!     target/release/examples/derivative_count contact 1000000
//! ```
//!
//! Run it with two counts and divide the difference of the instruction totals by the difference
//! of the counts: that is the cost of one evaluation without the set-up. The states are the
//! criterion bench's (`contact`: rotor 160 µm into the race, race on three or more balls;
//! `levitated`: the initial state of the default scene under a 10 G shock; `two_plane_contact`
//! and `two_plane_levitated`: the same for the symmetric two-plane machine, both planes alike).

#[path = "../benches/common/mod.rs"]
mod common;

use plant::model::{ix, State};
use std::hint::black_box;

fn main() {
    let mut args = std::env::args().skip(1);
    let which = args.next().unwrap_or_else(|| "contact".into());
    let count: u64 = args.next().and_then(|s| s.parse().ok()).unwrap_or(1_000_000);
    let mut sum = 0.0;
    match which.as_str() {
        "contact" | "levitated" => {
            let (model, scene) = common::model();
            let y: State = if which == "contact" {
                common::contact_state()
            } else {
                plant::initial::initial_state(&scene, &model.params)
            };
            for _ in 0..count {
                let dy = model.evaluate(black_box(0.002), black_box(&y)).dy;
                sum += black_box(dy)[ix::VYR];
            }
        }
        "two_plane_contact" | "two_plane_levitated" => {
            let (model, scene) = common::two_plane_model();
            let y = if which == "two_plane_contact" {
                common::two_plane_contact_state()
            } else {
                plant::initial::two_plane_initial_state(&scene, &model.params)
            };
            for _ in 0..count {
                let dy = model.evaluate(black_box(0.002), black_box(&y)).dy;
                sum += black_box(dy)[plant_physics::two_plane::ix::VY];
            }
        }
        other => {
            eprintln!(
                "derivative_count: unknown state {other:?} (contact, levitated, two_plane_contact or two_plane_levitated)"
            );
            std::process::exit(2);
        }
    }
    println!("{which}: {count} evaluations, checksum {sum:e}");
}
