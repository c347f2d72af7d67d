//! The live view (issue 42 item 2): `plant run SCENE --live [ADDR]` serves the run's rows as
//! they are made over the Foxglove WebSocket protocol (`foxglove.websocket.v1`), on the
//! recording's topics and schemas ([`crate::recording::topics`]), at `[output] live_rate_hz`
//! (default 200 Hz of simulated time), for Foxglove, Lichtblick or any client of the protocol.
//! docs/guide/live-view.md is the user's page.
//!
//! * [`protocol`]: the protocol's messages and frames (pure).
//! * [`server`]: the listener and the clients' threads; frames handed over without waiting.
//! * [`sink`]: the run's side, a [`crate::run::Sink`].
//!
//! Why not the `foxglove` crate (the Foxglove SDK, which has a WebSocket server): its server
//! runs on `tokio` and brings `tokio-tungstenite`, `futures-util`, `flume`, `serde_with` and its
//! own `mcap` into the plant's build, on a host where the build is the bottleneck; the part of
//! the protocol a server of logged topics needs (server info, advertise, subscribe,
//! unsubscribe, status, message data, time) is a few JSON objects and two binary frames, over
//! the blocking `tungstenite`.

pub mod protocol;
pub mod server;
pub mod sink;

pub use server::{Served, Server};
pub use sink::LiveSink;

use crate::config::Scene;

/// The address `--live` listens on without one: this host only.
pub const DEFAULT_ADDR: &str = "127.0.0.1:8765";

/// Starts the live view's server of a run of `scene` on `addr` (before the run starts: an
/// address that cannot be bound is bad input, exit 2, and nothing is run).
pub fn start(addr: &str, scene: &Scene) -> Result<Server, crate::argument::BadArgument> {
    let session = format!(
        "{}-{}",
        std::process::id(),
        std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_millis())
    );
    let info = protocol::server_info(concat!("plant ", env!("CARGO_PKG_VERSION")), &scene.name, &session);
    Server::start(addr, info, sink::channels(scene))
}

/// Hands a tick of the loop to the recording and the live view a run's sink holds (`plant
/// run`'s folder, a soak's sink): their [`crate::run::Sink::tick`] in one call.
pub fn tick(
    mcap: &mut Option<crate::recording::mcap_file::McapSink>,
    live: &mut Option<LiveSink>,
    sample: &controller::RotorSample,
    command: &[f64; controller::ROTOR_AXES],
) {
    if let Some(m) = mcap {
        m.tick(sample, command);
    }
    if let Some(l) = live {
        l.tick(sample, command);
    }
}

/// Whether either takes the loop's ticks ([`crate::run::Sink::wants_ticks`]).
pub fn wants_ticks(mcap: &Option<crate::recording::mcap_file::McapSink>, live: &Option<LiveSink>) -> bool {
    mcap.as_ref().is_some_and(|m| m.wants_ticks()) || live.as_ref().is_some_and(|l| l.wants_ticks())
}
