//! Base shock for a rotor on active magnetic bearings: pulses, programmes of
//! shocks ("shock tables") and their TOML configuration.
//!
//! The housing (base) moves in the x-y plane (x horizontal, y up). A
//! [`Pulse`] prescribes its motion along one direction, from rest, with the
//! exact closed-form integrals
//!
//! ```text
//! v(t) = ∫₀ᵗ a(s) ds,    d(t) = ∫₀ᵗ v(s) ds,    all zero for t < 0
//! ```
//!
//! A [`Programme`] places pulses at start times `s_j` along unit directions
//! `e_j = (cos θ_j, sin θ_j)` and adds them as vectors:
//! `a(t) = Σ_j a_j(t − s_j) e_j` (same for `v`, `d`).
//!
//! Pulse kinds (each module states its equations):
//!
//! - [`DoubleHalfSine`]: the BV043/85 design shock (MODEL.md §6), from the
//!   design acceleration `A_0` and SRS corners `f_1 < f_2`; ends at rest,
//!   lifted by `h`. Includes the note on the study's misprinted `a_2`.
//! - [`HalfSine`]: single positive half-sine; ends moving.
//! - [`SineVibration`]: `A cos ωt` over whole cycles; ends at rest at zero.
//! - [`Recorded`]: measured acceleration, linearly interpolated.
//!
//! Units are SI (m, s, m/s, m/s², rad) in the library API; the TOML keys
//! carry their units (`peak_g`, `f1_hz`, `direction_deg`) and are converted
//! once, in [`programme_from_specs`], with `1 G =` [`G0_M_S2`].
//!
//! ```
//! use shock_table::{DoubleHalfSine, Programme, Shock, G0_M_S2};
//! let pulse = DoubleHalfSine::from_peak(10.0 * G0_M_S2, 10.0, 80.0).unwrap();
//! let prog = Programme::single(Shock::lifting(pulse.into(), 0.02).unwrap());
//! let k = prog.eval(1.0);
//! assert_eq!(k.disp[0], 0.0);
//! assert!((k.disp[1] * 1e3 - 6.75).abs() < 0.005); // lifted by h ≈ 6.75 mm
//! ```
#![warn(missing_docs)]

pub mod config;
pub mod double_half_sine;
pub mod error;
pub mod half_sine;
pub mod input;
pub mod kinematics;
#[cfg(test)]
mod numeric;
pub mod programme;
pub mod pulse;
pub mod recorded;
pub mod sine;

pub use config::{
    load_programme, parse_programme, programme_from_specs, ProgrammeSpec, ShockSpec, DEFAULT_DIRECTION_DEG,
};
pub use double_half_sine::DoubleHalfSine;
pub use error::ShockError;
pub use half_sine::HalfSine;
pub use kinematics::{Kinematics, Kinematics2};
pub use programme::{Programme, Shock, DEFAULT_DIRECTION_RAD};
pub use pulse::Pulse;
pub use recorded::{Recorded, MAX_RECORD_BYTES, RECORD_CSV_HEADER};
pub use sine::SineVibration;

/// Standard gravity, m/s²: the `G` of all `*_g` keys (`1 G = 9.80665 m/s²`).
pub const G0_M_S2: f64 = 9.80665;
