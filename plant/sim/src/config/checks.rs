//! The checks every key goes through: a value in range, or an error naming the key, the value
//! and its unit.

use super::ConfigError;

/// An out-of-range error naming the key, the value and its unit.
pub fn range(key: &str, value: impl std::fmt::Display, unit: &str, why: &str) -> ConfigError {
    ConfigError::Range {
        key: key.to_string(),
        value: readable(value.to_string()),
        unit: if unit.is_empty() { String::new() } else { format!(" {unit}") },
        why: why.to_string(),
    }
}

/// A number as it reads best in a message: Rust prints `1e300_f64` as 301 digits, so a long
/// decimal becomes scientific notation (`1e300`); anything else is kept as written.
fn readable(value: String) -> String {
    match value.parse::<f64>() {
        Ok(v) if value.len() > 16 && v.is_finite() => format!("{v:e}"),
        _ => value,
    }
}

/// Checks `value > 0` and finite.
pub fn positive(key: &str, value: f64, unit: &str) -> Result<f64, ConfigError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(range(key, value, unit, "must be a finite number > 0"))
    }
}

/// Checks `value ≥ 0` and finite.
pub fn non_negative(key: &str, value: f64, unit: &str) -> Result<f64, ConfigError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(range(key, value, unit, "must be a finite number >= 0"))
    }
}

/// Checks that `value` is finite.
pub fn finite(key: &str, value: f64, unit: &str) -> Result<f64, ConfigError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(range(key, value, unit, "must be finite"))
    }
}
