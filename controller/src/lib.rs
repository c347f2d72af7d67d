//! AMB control laws, written once and run in three places: inside the plant's
//! derivative (continuous PD), in the plant's sampled loop (`sampled` mode), and
//! in the separate controller process.
//!
//! Signal chain (MODEL.md §3): inductive sensor (gain `A_s`, V/m) → controller
//! → power amplifier (gain `A_a`, A/V) → coil. A law sees the sensor voltages
//! `u = A_s·Δ` (per axis, x then y, Δ the rotor position relative to the
//! housing) and returns coil currents in amperes, before the amplifier limit.
//!
//! Laws are built by name through the [`registry`], from the common loop
//! [`Design`] and their own [`Params`] (the scene's `[controller.params]`,
//! which the plant passes through unread).
//!
//! The process side lives here too, so that both binaries link one crate:
//! [`wire`] holds the `#[repr(C)]` message types of the plant ⇄ controller
//! protocol, [`link`] the iceoryx2 plumbing, [`file`] the controller's
//! `--config` file, [`lock`] the one-process-per-run-id lock, and [`mod@serve`]
//! the whole controller process: a crate of your own that calls
//! `controller::serve(&[MY_LAW])` from its `main` is a controller the plant
//! can start (`[controller] command`). The `controller` binary is that call
//! with the registry's laws.
#![warn(missing_docs)]

pub mod design;
pub mod discrete_pd;
pub mod error;
#[cfg(feature = "ipc")]
pub mod file;
pub mod law;
#[cfg(feature = "ipc")]
pub mod link;
#[cfg(feature = "ipc")]
pub mod lock;
pub mod modal;
pub mod params;
pub mod pd;
pub mod pd_delay;
pub mod pid;
pub mod registry;
pub mod relev;
#[cfg(feature = "ipc")]
pub mod serve;
#[cfg(test)]
mod test_plant;
#[cfg(feature = "ipc")]
pub mod wire;

pub use discrete_pd::{DelayPd, DelayPdGains};
pub use law::{
    build_among, saturate, saturate_axes, wrap_angle, AnyLaw, BuildLaw, BuildRotorLaw, ControlLaw, Decentralised,
    Design, Geometry, LawEntry, LawError, LoopConstants, PdDesign, RotorDesign, RotorLaw, RotorLawEntry, RotorSample,
    Sample, ROTOR_AXES,
};
pub use modal::{Modal, ModalGains, ModalSpec};
pub use params::{Check, ParamReader, Params, ParamsError, PARAMS_LEN};
pub use pd::{PdGains, SampledPd};
pub use pid::{PidDesign, PidGains, SampledPid};
pub use registry::{all_law_names, build_law, build_rotor_law, find_law, law_names, ALL_LAWS, LAWS, ROTOR_LAWS};
pub use relev::{Relev, RelevSpec};
#[cfg(feature = "ipc")]
pub use serve::{serve, ServeOptions};
