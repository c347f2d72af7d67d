//! AMB control laws, written once and run in three places: inside the plant's
//! derivative (continuous PD), in the plant's sampled loop (`sampled` mode), and
//! in the separate controller process.
//!
//! Signal chain (MODEL.md §3): inductive sensor (gain `A_s`, V/m) → controller
//! → power amplifier (gain `A_a`, A/V) → coil. A law sees the sensor voltages
//! `u = A_s·Δ` (per axis, x then y, Δ the rotor position relative to the
//! housing) and returns coil currents in amperes, before the amplifier limit.
//!
//! Laws are built by name through the [`registry`], from a bearing plane's
//! loop [`Design`] and their own [`Params`] (the scene's `[controller.params]`,
//! which the plant passes through unread). A per-plane law ([`ControlLaw`])
//! reads one plane's x and y in a [`Sample`] (with the keyphasor: the rotor's
//! speed and angle) and runs once per plane on a two-plane rotor
//! ([`Decentralised`]); a law of the whole rotor ([`RotorLaw`], such as
//! [`modal`]) reads every axis at once from a [`RotorDesign`].
//!
//! # A law of your own
//!
//! A per-plane law is a type implementing [`ControlLaw`] and a [`LawEntry`]
//! that builds it; `controller::serve(&[LAW])` in your crate's `main` makes
//! it a controller process (`examples/rust-controller/` is a whole crate):
//!
//! ```
//! use controller::{Check, ControlLaw, Design, LawEntry, LawError, Params, Sample};
//!
//! /// A spring of stiffness `gain` times the design's, no damping (an illustration, not a law
//! /// to levitate with).
//! pub struct Spring {
//!     amps_per_volt: f64,
//!     bias_y: f64,
//! }
//!
//! impl ControlLaw for Spring {
//!     fn name(&self) -> &'static str {
//!         LAW.name
//!     }
//!     fn update(&mut self, s: &Sample) -> [f64; 2] {
//!         // s.sensor_v: this plane's x, y (V); s.speed_rad_s, s.angle_rad: the keyphasor.
//!         [-self.amps_per_volt * s.sensor_v[0], self.bias_y - self.amps_per_volt * s.sensor_v[1]]
//!     }
//!     fn reset(&mut self) {}
//! }
//!
//! fn build(design: &Design, params: &Params) -> Result<Box<dyn ControlLaw>, LawError> {
//!     let mut p = params.reader(LAW.name);
//!     let gain = p.number("gain", "", 1.0, Check::Positive)?; // [controller.params] gain
//!     p.finish()?; // refuses keys the law does not read
//!     let c = &design.constants;
//!     let loop_gain = c.ki_n_per_a * c.sensor_gain_v_per_m; // k_i A_s: i = -(k_e + k_s) u / (k_i A_s)
//!     let bias_y = if design.gravity_bias { c.rotor_mass_kg * c.gravity_m_s2 / c.ki_n_per_a } else { 0.0 };
//!     Ok(Box::new(Spring {
//!         amps_per_volt: gain * (design.stiffness_n_per_m + c.ks_n_per_m) / loop_gain,
//!         bias_y,
//!     }))
//! }
//!
//! pub const LAW: LawEntry = LawEntry { name: "spring", summary: "a spring, no damping (param gain)", build };
//!
//! // In your crate: fn main() -> std::process::ExitCode { controller::serve(&[LAW]) }
//! let mut law = (LAW.build)(&Design::study(), &Params::parse("gain = 2.0").unwrap()).unwrap();
//! let i = law.update(&Sample { seq: 0, t_s: 0.0, sensor_v: [0.25, 0.0], ..Default::default() });
//! assert!(i[0] < 0.0 && i[1] > 0.5);
//! let e = (LAW.build)(&Design::study(), &Params::parse("gian = 2.0").unwrap()).err().unwrap();
//! assert_eq!(e.to_string(), "law spring: unknown parameter controller.params.gian = 2.0 (law spring reads gain)");
//! ```
//!
//! The process side lives here too, so that both binaries link one crate:
//! [`wire`] holds the `#[repr(C)]` message types of the plant ⇄ controller
//! protocol, [`link`] the iceoryx2 plumbing, [`file`] the controller's
//! `--config` file, [`lock`] the one-process-per-run-id lock, and [`mod@serve`]
//! the whole controller process: a crate of your own that calls
//! `controller::serve(&[MY_LAW])` from its `main` is a controller the plant
//! can start (`[controller] command`). The `controller` binary is that call
//! with every law of the registry ([`ALL_LAWS`]).
#![warn(missing_docs)]

pub mod cores;
pub mod design;
pub mod discrete_pd;
pub mod discretisation;
pub mod error;
#[cfg(feature = "ipc")]
pub mod file;
pub mod law;
pub mod law_file;
#[cfg(feature = "ipc")]
pub mod link;
#[cfg(feature = "ipc")]
pub mod lock;
pub mod mat_file;
pub mod modal;
pub mod notch;
pub mod params;
pub mod pd;
pub mod pd_delay;
pub mod pid;
pub mod registry;
pub mod relev;
pub mod ross_pid;
#[cfg(feature = "ipc")]
pub mod serve;
pub mod state_space;
#[cfg(test)]
mod test_plant;
pub mod transfer_function;
#[cfg(feature = "ipc")]
pub mod wire;

pub use discrete_pd::{DelayPd, DelayPdGains};
pub use law::{
    build_among, saturate, saturate_axes, wrap_angle, AnyLaw, BuildLaw, BuildRotorLaw, ControlLaw, Decentralised,
    Design, Geometry, LawEntry, LawError, LinearLaw, LinearPd, LoopConstants, PdDesign, RotorDesign, RotorLaw,
    RotorLawEntry, RotorSample, Sample, ROTOR_AXES,
};
pub use modal::{Modal, ModalGains, ModalSpec};
pub use params::{Check, ParamReader, Params, ParamsError, PARAMS_LEN};
pub use pd::{PdGains, SampledPd};
pub use pid::{PidDesign, PidGains, SampledPid};
pub use registry::{all_law_names, build_law, build_rotor_law, find_law, law_names, ALL_LAWS, LAWS, ROTOR_LAWS};
pub use relev::{Relev, RelevSpec};
pub use ross_pid::{RossPid, RossPidGains};
#[cfg(feature = "ipc")]
pub use serve::{serve, ServeOptions};
