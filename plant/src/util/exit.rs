//! How a command ends when it does not succeed and no error of another library type says why:
//! the error types library code raises for those endings ([`Ending`], [`Interrupted`],
//! [`BadArgument`]). Their exit codes are the binary's (`plant/src/exit_code.rs`, beside
//! `main`): this module imports nothing from the modules above it.

/// Endings of a command that are not successes and carry no error of another library type.
#[derive(Debug, thiserror::Error)]
pub enum Ending {
    /// A command-line argument (or a scene the stability check refuses) is bad input.
    #[error("{0}")]
    BadArgument(String),
    /// A run stopped before its end; its results up to then were written.
    #[error("{why}; results up to t = {simulated_s} s were written")]
    Stopped {
        /// How it stopped.
        kind: StopKind,
        /// What happened.
        why: String,
        /// Simulated time reached (s).
        simulated_s: f64,
    },
    /// `plant soak` completed, but criteria failed (each was named above).
    #[error("{0} soak criterion (criteria) failed")]
    CriteriaFailed(usize),
    /// A command of several runs (`compare`) stopped by SIGINT/SIGTERM: what it had finished was written, as the text says.
    #[error("interrupted: {0}")]
    Interrupted(String),
}

/// How a run stopped early.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopKind {
    /// A numerical failure.
    Diverged,
    /// SIGINT/SIGTERM.
    Interrupted,
    /// The controller process was lost.
    PeerLost,
    /// Realtime: past the deadline-miss budget.
    MissBudget,
    /// Past the budget of non-finite commands.
    InvalidCommands,
    /// Realtime: past the plant-overrun budget.
    OverrunBudget,
}

pub use crate::argument::BadArgument;

/// A command stopped by SIGINT/SIGTERM (exit 130): what it had finished was written, as the
/// text says.
#[derive(Debug, thiserror::Error)]
#[error("interrupted: {0}")]
pub struct Interrupted(pub String);
