//! The status of a run that could not start ([`SetupError::status`]) and of the controller's
//! refusals; how a run that started ended is the simulation's ([`plant_sim::status`],
//! re-exported here).

pub use plant_sim::status::*;

use crate::cosim::CosimError;
use crate::run::SetupError;

impl SetupError {
    /// The status of a run that could not start: `refused` (the controller refused the run or
    /// is incompatible, the design or its overrides are invalid, the run id is in use),
    /// `interrupted` (a signal while waiting for it), else `not_started`.
    pub fn status(&self) -> Status {
        match self {
            SetupError::Law(_) | SetupError::Overrides(_) | SetupError::State(_) => Status::Refused,
            SetupError::Cosim(CosimError::Interrupted) => Status::Interrupted,
            SetupError::Cosim(c) if c.is_refusal() => Status::Refused,
            SetupError::Cosim(_) | SetupError::Thread(_) => Status::NotStarted,
        }
    }
}

/// What kind of failure a co-simulation error is: the one sorting of its variants that the
/// status of a run that could not start ([`SetupError::status`]) and `plant`'s exit code both
/// read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CosimFailure {
    /// The controller (or the run's setting) refused the run: bad input on the plant's side
    /// (exit 2), status `refused`.
    Refusal,
    /// A `controller.command` that cannot be run: bad input too, but the run did not start
    /// (`not_started`).
    BadCommand,
    /// No controller came, or it exited.
    PeerLost,
    /// A signal while waiting for the controller.
    Interrupted,
    /// The system refused a resource (the controller's executable, a process, a lock, IPC).
    Io,
}

impl CosimError {
    /// Which kind of failure this is.
    pub fn failure(&self) -> CosimFailure {
        use controller::link::LinkError;
        use controller::lock::LockError;
        match self {
            CosimError::Refused { .. }
            | CosimError::RunId(_)
            | CosimError::Pin(_)
            | CosimError::Params(_)
            | CosimError::Protocol(_)
            | CosimError::Overrides { .. }
            | CosimError::Lock(LockError::InUse { .. })
            | CosimError::Link(LinkError::Incompatible { .. })
            | CosimError::ControllerExited { code: Some(2), .. } => CosimFailure::Refusal,
            CosimError::Command { .. } => CosimFailure::BadCommand,
            CosimError::NoController { .. } | CosimError::ControllerExited { .. } => CosimFailure::PeerLost,
            CosimError::Interrupted => CosimFailure::Interrupted,
            CosimError::ControllerMissing { .. }
            | CosimError::Spawn { .. }
            | CosimError::Lock(LockError::Io { .. })
            | CosimError::Link(LinkError::Ipc { .. }) => CosimFailure::Io,
        }
    }

    /// The controller (or the run's setting) refused the run ([`CosimFailure::Refusal`]).
    pub fn is_refusal(&self) -> bool {
        self.failure() == CosimFailure::Refusal
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_the_serialised_names() {
        for s in [
            Status::Completed,
            Status::Diverged,
            Status::Interrupted,
            Status::PeerLost,
            Status::Refused,
            Status::NotStarted,
            Status::MissBudget,
            Status::InvalidCommands,
            Status::OverrunBudget,
        ] {
            assert_eq!(serde_json::to_value(s).unwrap(), s.name());
        }
    }

    #[test]
    fn an_interrupted_run_has_an_error_text() {
        use crate::run::Outcome;
        // The summary and the soak once disagreed here (the soak wrote no error).
        assert_eq!(Outcome::Interrupted.status(), Status::Interrupted);
        assert!(Outcome::Interrupted.error().is_some());
        assert_eq!(Outcome::Completed.error(), None);
    }
}
