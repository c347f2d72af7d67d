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

impl CosimError {
    /// The controller (or the run's setting) refused the run: bad input on the plant's side
    /// (exit 2), status `refused`. A `controller.command` that cannot be run is bad input too,
    /// but the run did not start (`not_started`).
    pub fn is_refusal(&self) -> bool {
        use controller::link::LinkError;
        use controller::lock::LockError;
        matches!(
            self,
            CosimError::Refused { .. }
                | CosimError::RunId(_)
                | CosimError::Pin(_)
                | CosimError::Params(_)
                | CosimError::Protocol(_)
                | CosimError::Overrides { .. }
                | CosimError::Lock(LockError::InUse { .. })
                | CosimError::Link(LinkError::Incompatible { .. })
                | CosimError::ControllerExited { code: Some(2), .. }
        )
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
