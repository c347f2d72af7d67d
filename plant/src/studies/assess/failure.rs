//! How a part of an assessment failed ([`Failure`]): its own room, so that the parts that
//! fail (sensitivity, the ladder) and the outcome that collects them both use it without
//! importing each other.

use serde::Serialize;

/// How a part of an assessment failed; each has its exit code.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Failure {
    /// The rotor is not levitated before the shock, or the excitation drove it into the
    /// touchdown bearing: nothing to grade (exit 9).
    NotGradable,
    /// The controller process was lost (exit 4).
    PeerLost,
    /// The controller's commands were non-finite past the scene's budget (exit 8).
    InvalidCommands,
    /// A run diverged (exit 3).
    Diverged,
    /// Interrupted by SIGINT/SIGTERM (exit 130).
    Interrupted,
    /// Anything else (exit 1).
    Other,
}

impl Failure {
    pub(super) fn rank(self) -> u8 {
        match self {
            Failure::Interrupted => 6,
            Failure::PeerLost => 5,
            Failure::InvalidCommands => 4,
            Failure::Diverged => 3,
            Failure::NotGradable => 2,
            Failure::Other => 1,
        }
    }
}
