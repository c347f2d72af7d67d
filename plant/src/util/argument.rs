//! Bad input that is not a scene key: an argument of a command that cannot be used (exit 2,
//! [`crate::exit`]). A leaf: any module may refuse with it without importing the exit map,
//! which imports the commands' own error types.

/// An argument of a command that cannot be used (bad input: exit 2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct BadArgument(pub String);
