//! The exit codes of `plant`, one per kind of ending, and the one way from an error to its
//! code: each error type that ends a command implements [`HasExitCode`] here, and [`code`]
//! walks an error's chain to the first cause whose type has a code (ripgrep's model: by type,
//! never by text). `main` calls [`code`] and nothing else; a new error type gets its line in
//! [`code_of`] and its `impl` below, and the test at the end pins every mapping.
//!
//! The table users read is `docs/guide/running.md`, "Exit codes". The map lives beside `main`,
//! in the binary: the library's modules raise the error types and never depend on their codes.

use plant::assess::{AssessError, Failure};
use plant::claim::ClaimError;
use plant::config::ConfigError;
use plant::cosim::CosimError;
use plant::exit::{BadArgument, Ending, Interrupted, StopKind};
use plant::grid::GridError;
use plant::output::AnalyzeError;
use plant::status::CosimFailure;

/// An exit code of `plant`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Code {
    /// An output could not be written, or the system refused a resource.
    Io = 1,
    /// Bad input: a file, `--set`, an argument, a value past a bound, a controller that
    /// refuses the run or speaks another protocol, a run id or an output folder in use.
    BadInput = 2,
    /// The simulation diverged (non-finite state, step-size underflow, radius guard).
    Diverged = 3,
    /// Co-simulation: the controller process was lost and none took its place.
    PeerLost = 4,
    /// `plant soak`: the run completed but a criterion of the programme failed.
    CriterionFailed = 5,
    /// Realtime: the deadline-miss budget was exceeded.
    MissBudget = 6,
    /// `plant sweep` / `plant ensemble` `--merge` (or `--round R`): units missing or corrupt.
    Incomplete = 7,
    /// The controller's commands were non-finite past `controller.max_invalid_burst` or
    /// `controller.max_invalid_fraction` (status `invalid_commands`).
    InvalidCommands = 8,
    /// `plant assess`: a controller could not be graded (its rotor not levitated before the
    /// shock, or the excitation drove it into the touchdown bearing); the report was written.
    NotGradable = 9,
    /// Realtime: the plant-overrun budget was exceeded (status `overrun_budget`).
    OverrunBudget = 10,
    /// Stopped by SIGINT/SIGTERM; results up to that point were written.
    Interrupted = 130,
}

impl Code {
    /// Every code, in the order of the table in `docs/guide/running.md`.
    pub const ALL: [Code; 11] = [
        Code::Io,
        Code::BadInput,
        Code::Diverged,
        Code::PeerLost,
        Code::CriterionFailed,
        Code::MissBudget,
        Code::Incomplete,
        Code::InvalidCommands,
        Code::NotGradable,
        Code::OverrunBudget,
        Code::Interrupted,
    ];
}

// A new variant fails to compile here until it is added to `Code::ALL` (and so to the test of
// the guide's table).
const _: fn(Code) = |c| match c {
    Code::Io
    | Code::BadInput
    | Code::Diverged
    | Code::PeerLost
    | Code::CriterionFailed
    | Code::MissBudget
    | Code::Incomplete
    | Code::InvalidCommands
    | Code::NotGradable
    | Code::OverrunBudget
    | Code::Interrupted => {}
};

impl From<Code> for u8 {
    fn from(c: Code) -> u8 {
        c as u8
    }
}

/// An error type that says how the command it ends exits.
pub trait HasExitCode {
    /// The exit code.
    fn exit_code(&self) -> Code;
}

/// The exit code of an error: that of the first cause in its chain whose type has one;
/// [`Code::Io`] (an output or a resource) for the rest.
pub fn code(err: &anyhow::Error) -> Code {
    err.chain().find_map(code_of).unwrap_or(Code::Io)
}

/// The code of one cause, if its type has one.
fn code_of(cause: &(dyn std::error::Error + 'static)) -> Option<Code> {
    macro_rules! by_type {
        ($($t:ty),* $(,)?) => {
            $(if let Some(e) = cause.downcast_ref::<$t>() {
                return Some(e.exit_code());
            })*
        };
    }
    by_type!(
        Ending,
        CosimError,
        GridError,
        ClaimError,
        ConfigError,
        controller::LawError,
        controller::ParamsError,
        shock_table::ShockError,
        BadArgument,
        Interrupted,
        AnalyzeError,
        AssessError,
        plant::snapshot::SnapshotError,
    );
    None
}

impl HasExitCode for Ending {
    fn exit_code(&self) -> Code {
        match self {
            Ending::BadArgument(_) => Code::BadInput,
            Ending::Stopped { kind: StopKind::Diverged, .. } => Code::Diverged,
            Ending::Stopped { kind: StopKind::PeerLost, .. } => Code::PeerLost,
            Ending::Stopped { kind: StopKind::MissBudget, .. } => Code::MissBudget,
            Ending::Stopped { kind: StopKind::InvalidCommands, .. } => Code::InvalidCommands,
            Ending::Stopped { kind: StopKind::OverrunBudget, .. } => Code::OverrunBudget,
            Ending::Stopped { kind: StopKind::Interrupted, .. } => Code::Interrupted,
            Ending::CriteriaFailed(_) => Code::CriterionFailed,
            Ending::Interrupted(_) => Code::Interrupted,
        }
    }
}

impl HasExitCode for CosimError {
    fn exit_code(&self) -> Code {
        match self.failure() {
            CosimFailure::Refusal | CosimFailure::BadCommand => Code::BadInput,
            CosimFailure::PeerLost => Code::PeerLost,
            CosimFailure::Interrupted => Code::Interrupted,
            CosimFailure::Io => Code::Io,
        }
    }
}

impl HasExitCode for GridError {
    fn exit_code(&self) -> Code {
        match self {
            GridError::Mismatch { .. } => Code::BadInput,
            GridError::Failed { .. } => Code::Diverged,
            GridError::Incomplete { .. } => Code::Incomplete,
            GridError::Interrupted => Code::Interrupted,
        }
    }
}

impl HasExitCode for ClaimError {
    fn exit_code(&self) -> Code {
        match self {
            ClaimError::InUse { .. } => Code::BadInput,
            ClaimError::Io { .. } => Code::Io,
        }
    }
}

impl HasExitCode for AnalyzeError {
    fn exit_code(&self) -> Code {
        match self {
            AnalyzeError::Scene(_) | AnalyzeError::Trace(_) | AnalyzeError::Summary { .. } => Code::BadInput,
            AnalyzeError::Output(_) => Code::Io,
            AnalyzeError::Interrupted(_) => Code::Interrupted,
        }
    }
}

impl HasExitCode for plant::snapshot::SnapshotError {
    fn exit_code(&self) -> Code {
        match self {
            plant::snapshot::SnapshotError::Write { .. } => Code::Io,
            _ => Code::BadInput,
        }
    }
}

impl HasExitCode for AssessError {
    fn exit_code(&self) -> Code {
        match self.kind {
            Failure::NotGradable => Code::NotGradable,
            Failure::PeerLost => Code::PeerLost,
            Failure::InvalidCommands => Code::InvalidCommands,
            Failure::Diverged => Code::Diverged,
            Failure::Interrupted => Code::Interrupted,
            Failure::Other => Code::Io,
        }
    }
}

/// Bad input, whatever the variant.
macro_rules! bad_input {
    ($($t:ty),* $(,)?) => {
        $(impl HasExitCode for $t {
            fn exit_code(&self) -> Code {
                Code::BadInput
            }
        })*
    };
}
bad_input!(ConfigError, controller::LawError, controller::ParamsError, shock_table::ShockError, BadArgument);

impl HasExitCode for Interrupted {
    fn exit_code(&self) -> Code {
        Code::Interrupted
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plant::run::SetupError;

    fn exited(code: Option<i32>) -> CosimError {
        CosimError::ControllerExited { program: "c".into(), status: "x".into(), code, output: String::new() }
    }

    fn assessed(kind: Failure) -> anyhow::Error {
        AssessError { kind, message: "m".into(), dir: "d".into() }.into()
    }

    #[test]
    fn exit_codes_follow_the_error_types_not_their_text() {
        let stopped = |kind| anyhow::Error::from(Ending::Stopped { kind, why: "x".into(), simulated_s: 0.1 });
        let law = controller::LawError::Unknown { name: "nope".into(), known: vec!["pd"] };
        let cases: Vec<(anyhow::Error, u8)> = vec![
            (stopped(StopKind::Diverged), 3),
            (stopped(StopKind::PeerLost), 4),
            (stopped(StopKind::Interrupted), 130),
            (Ending::CriteriaFailed(1).into(), 5),
            (Ending::Interrupted("2 of 5 runs written".into()).into(), 130),
            (Interrupted("1 of 2 loops finished".into()).into(), 130),
            (Ending::BadArgument("diverged".into()).into(), 2),
            (anyhow::Error::from(BadArgument("--peer-rows: x".into())).context("bench"), 2),
            (anyhow::Error::from(ConfigError::Alias { old: "a".into(), new: "b".into() }).context("loading"), 2),
            (anyhow::Error::from(SetupError::Law(law)).context("the run"), 2),
            (SetupError::Cosim(CosimError::Refused { reason: "r", message: "m".into() }).into(), 2),
            (SetupError::Cosim(CosimError::Interrupted).into(), 130),
            (CosimError::NoController { waited_s: 1.0, run_id: "r".into(), hint: String::new() }.into(), 4),
            (
                CosimError::Link(controller::link::LinkError::Incompatible { service: "s".into(), peer_type: None })
                    .into(),
                2,
            ),
            (exited(Some(2)).into(), 2),
            (exited(Some(1)).into(), 4),
            (stopped(StopKind::MissBudget), 6),
            (stopped(StopKind::InvalidCommands), 8),
            (AnalyzeError::Interrupted("nothing was written").into(), 130),
            (stopped(StopKind::OverrunBudget), 10),
            (CosimError::Command { argv0: "c".into(), why: "w".into() }.into(), 2),
            (CosimError::Protocol("version 4".into()).into(), 2),
            (CosimError::Overrides { controller: "c".into(), why: "controller.rate_hz = 1000".into() }.into(), 2),
            (
                CosimError::Lock(controller::lock::LockError::InUse {
                    run_id: "r".into(),
                    role: "plant".into(),
                    holder: "pid 1".into(),
                    path: "p".into(),
                })
                .into(),
                2,
            ),
            (AnalyzeError::Trace(plant::trace::TraceError::TooShort { path: "trace.csv".into(), rows: 1 }).into(), 2),
            (AnalyzeError::Output(anyhow::anyhow!("read-only")).into(), 1),
            (GridError::Mismatch { dir: "d".into(), units: Vec::new() }.into(), 2),
            (GridError::Failed { failed: Vec::new() }.into(), 3),
            (
                anyhow::Error::from(GridError::Incomplete {
                    dir: "d".into(),
                    missing: Vec::new(),
                    corrupt: Vec::new(),
                })
                .context("merging"),
                7,
            ),
            (GridError::Interrupted.into(), 130),
            (ClaimError::InUse { path: "d".into(), holder: String::new() }.into(), 2),
            (assessed(Failure::NotGradable), 9),
            (assessed(Failure::PeerLost), 4),
            (assessed(Failure::InvalidCommands), 8),
            (assessed(Failure::Diverged), 3),
            (assessed(Failure::Interrupted), 130),
            (assessed(Failure::Other), 1),
            // An output that could not be written, whatever its message says.
            (anyhow::Error::from(std::io::Error::other("bad input")).context("writing summary.json"), 1),
        ];
        for (err, expected) in cases {
            assert_eq!(u8::from(code(&err)), expected, "{err:#}");
        }
    }

    #[test]
    fn the_guide_lists_every_exit_code_and_no_other() {
        let guide = include_str!("../../docs/guide/running.md");
        let start = guide.find("| code | meaning |").expect("the exit-code table in docs/guide/running.md");
        let listed: Vec<u8> = guide[start..]
            .lines()
            .skip(2)
            .take_while(|l| l.starts_with('|'))
            .map(|l| l.trim_start_matches('|').split('|').next().unwrap_or("").trim().parse().expect("a code"))
            .collect();
        let mut expected: Vec<u8> = Code::ALL.iter().map(|&c| u8::from(c)).collect();
        expected.insert(0, 0);
        assert_eq!(listed, expected, "docs/guide/running.md's exit codes against crate::exit_code::Code");
    }
}
