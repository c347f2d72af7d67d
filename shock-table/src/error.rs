//! Errors of the shock library.
//!
//! Every error that comes from a user-supplied number names the key, the
//! value and its unit, e.g. `shock[0].f2_hz = -3 Hz: must be > 0`. Errors
//! found while building one shock of a programme carry the shock's index.

use std::fmt;
use std::path::{Path, PathBuf};

/// Error building or loading a shock pulse or programme.
#[derive(Debug, thiserror::Error)]
pub enum ShockError {
    /// A numeric parameter is out of range (or not finite).
    #[error("{key} = {value}{}: {reason}", unit_suffix(unit))]
    InvalidParameter {
        /// Name of the parameter or configuration key, e.g. `shock[0].f2_hz`.
        key: String,
        /// The offending value, in the unit `unit`.
        value: f64,
        /// Unit of `value` as written in the key (`Hz`, `G`, `s`, …); empty
        /// for dimensionless values.
        unit: &'static str,
        /// Why the value is rejected.
        reason: String,
    },
    /// A configuration is inconsistent in a way that is not a single value
    /// (e.g. two mutually exclusive keys both given).
    #[error("{key}: {reason}")]
    InvalidConfig {
        /// Name of the key (or keys) concerned.
        key: String,
        /// What is wrong.
        reason: String,
    },
    /// An acceleration record (in memory or from a CSV file) is malformed.
    #[error("{}{message}", Loc(path.as_deref(), *line))]
    Record {
        /// File the record was read from, if any.
        path: Option<PathBuf>,
        /// 1-based line number in that file, if the error is tied to a line.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// A TOML programme file could not be parsed (syntax, unknown key,
    /// missing key, wrong type).
    #[error("{}: {error}", path.display())]
    Toml {
        /// File being parsed.
        path: PathBuf,
        /// The parser's error, which names the key and line (included in
        /// this error's message, so not repeated as its `source()`).
        error: toml::de::Error,
    },
    /// A file could not be read.
    #[error("cannot read {}: {error}", path.display())]
    Io {
        /// File being read.
        path: PathBuf,
        /// Underlying I/O error (included in this error's message, so not
        /// repeated as its `source()`).
        error: std::io::Error,
    },
    /// An error in one shock of a programme that is not tied to a single
    /// numeric key (file errors of a recorded shock, for instance).
    #[error("shock[{index}].{key}: {inner}")]
    InShock {
        /// Index of the shock in the programme (0-based, as in `shock[0]`).
        index: usize,
        /// Key of the shock the error concerns (e.g. `file`).
        key: &'static str,
        /// The underlying error (included in this error's message).
        inner: Box<ShockError>,
    },
}

fn unit_suffix(unit: &str) -> String {
    if unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    }
}

/// `path: line N: ` prefix of a record error.
struct Loc<'a>(Option<&'a Path>, Option<usize>);

impl fmt::Display for Loc<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (&self.0, self.1) {
            (Some(p), Some(l)) => write!(f, "{}: line {l}: ", p.display()),
            (Some(p), None) => write!(f, "{}: ", p.display()),
            (None, Some(l)) => write!(f, "line {l}: "),
            (None, None) => Ok(()),
        }
    }
}

impl ShockError {
    /// `true` if the error is an I/O failure (a file could not be read), as
    /// opposed to bad input; binaries map the two to different exit codes.
    pub fn is_io(&self) -> bool {
        match self {
            ShockError::Io { .. } => true,
            ShockError::InShock { inner, .. } => inner.is_io(),
            _ => false,
        }
    }

    /// Attribute the error to shock number `index` of a programme: parameter
    /// keys get the prefix `shock[index].`; other errors are wrapped with
    /// the key `key` they concern.
    pub(crate) fn in_shock(self, index: usize, key: &'static str) -> ShockError {
        match self {
            ShockError::InvalidParameter { key: k, value, unit, reason } => {
                ShockError::InvalidParameter { key: format!("shock[{index}].{k}"), value, unit, reason }
            }
            ShockError::InvalidConfig { key: k, reason } => {
                ShockError::InvalidConfig { key: format!("shock[{index}].{k}"), reason }
            }
            other => ShockError::InShock { index, key, inner: Box::new(other) },
        }
    }
}

/// Build an [`ShockError::InvalidParameter`].
pub(crate) fn invalid(key: impl Into<String>, value: f64, unit: &'static str, reason: impl Into<String>) -> ShockError {
    ShockError::InvalidParameter { key: key.into(), value, unit, reason: reason.into() }
}

/// Require `value` finite and `> 0`.
pub(crate) fn require_positive(key: &str, value: f64, unit: &'static str) -> Result<(), ShockError> {
    if !value.is_finite() {
        Err(invalid(key, value, unit, "must be finite"))
    } else if value <= 0.0 {
        Err(invalid(key, value, unit, "must be > 0"))
    } else {
        Ok(())
    }
}

/// Require `value` finite and `>= 0`.
pub(crate) fn require_non_negative(key: &str, value: f64, unit: &'static str) -> Result<(), ShockError> {
    if !value.is_finite() {
        Err(invalid(key, value, unit, "must be finite"))
    } else if value < 0.0 {
        Err(invalid(key, value, unit, "must be >= 0"))
    } else {
        Ok(())
    }
}

/// Require `value` finite.
pub(crate) fn require_finite(key: &str, value: f64, unit: &'static str) -> Result<(), ShockError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(invalid(key, value, unit, "must be finite"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameter_message_names_key_value_unit() {
        let e = invalid("f2_hz", -3.0, "Hz", "must be > 0").in_shock(0, "f2_hz");
        assert_eq!(e.to_string(), "shock[0].f2_hz = -3 Hz: must be > 0");
    }

    #[test]
    fn dimensionless_has_no_unit_suffix() {
        let e = invalid("scale", f64::NAN, "", "must be finite");
        assert_eq!(e.to_string(), "scale = NaN: must be finite");
    }

    #[test]
    fn record_message_names_line() {
        let e = ShockError::Record { path: Some(PathBuf::from("a.csv")), line: Some(4), message: "bad".into() };
        assert_eq!(e.to_string(), "a.csv: line 4: bad");
    }

    #[test]
    fn io_is_io_through_wrapping() {
        let e = ShockError::Io { path: PathBuf::from("x"), error: std::io::Error::from(std::io::ErrorKind::NotFound) }
            .in_shock(2, "file");
        assert!(e.is_io());
        assert!(e.to_string().starts_with("shock[2].file: cannot read x"));
    }
}
