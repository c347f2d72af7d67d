//! A run's status, as `summary.json` and `soak.json` write it, and the one
//! mapping from how a run ended ([`Outcome`]) to its status and error text (a run that could
//! not start: `plant::status`).

use crate::run::Outcome;
use serde::{Deserialize, Serialize};

/// The `status` of `summary.json` and `soak.json`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Ran to the scene's duration.
    Completed,
    /// Stopped by a numerical failure (exit 3).
    Diverged,
    /// Stopped by SIGINT/SIGTERM (exit 130).
    Interrupted,
    /// The controller process was lost and none took its place (exit 4).
    PeerLost,
    /// The controller refused the run, or is incompatible (exit 2).
    Refused,
    /// The controller could not be started or never answered the hello (exit 4, or 2).
    NotStarted,
    /// Realtime: the deadline-miss budget was exceeded (exit 6).
    MissBudget,
    /// The controller's commands were non-finite past the budget (exit 8).
    InvalidCommands,
    /// Realtime: the plant-overrun budget was exceeded (exit 10).
    OverrunBudget,
}

impl Status {
    /// The name written in the outputs (`completed`, `peer_lost`, …).
    pub fn name(self) -> &'static str {
        match self {
            Status::Completed => "completed",
            Status::Diverged => "diverged",
            Status::Interrupted => "interrupted",
            Status::PeerLost => "peer_lost",
            Status::Refused => "refused",
            Status::NotStarted => "not_started",
            Status::MissBudget => "miss_budget",
            Status::InvalidCommands => "invalid_commands",
            Status::OverrunBudget => "overrun_budget",
        }
    }
}

impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Outcome {
    /// The status of a run that ended so.
    pub fn status(&self) -> Status {
        match self {
            Outcome::Completed => Status::Completed,
            Outcome::Diverged(_) => Status::Diverged,
            Outcome::Interrupted => Status::Interrupted,
            Outcome::PeerLost(_) => Status::PeerLost,
            Outcome::MissBudget(_) => Status::MissBudget,
            Outcome::InvalidCommands(_) => Status::InvalidCommands,
            Outcome::OverrunBudget(_) => Status::OverrunBudget,
        }
    }

    /// What went wrong, for the `error` key (`None` for a completed run).
    pub fn error(&self) -> Option<String> {
        match self {
            Outcome::Completed => None,
            Outcome::Diverged(e) => Some(e.to_string()),
            Outcome::Interrupted => Some("interrupted by a signal".to_string()),
            Outcome::PeerLost(why)
            | Outcome::MissBudget(why)
            | Outcome::InvalidCommands(why)
            | Outcome::OverrunBudget(why) => Some(why.clone()),
        }
    }

    /// When a diverged run failed (s).
    pub fn failure_time(&self) -> Option<f64> {
        match self {
            Outcome::Diverged(e) => Some(e.time()),
            _ => None,
        }
    }
}
