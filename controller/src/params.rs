//! A law's own parameters: the scene's `[controller.params]` table (free
//! TOML), passed through the plant unread and read by the law alone.
//!
//! A law reads its keys with a [`ParamReader`]: each getter takes the key,
//! its unit and its default and checks the value, and [`ParamReader::finish`]
//! refuses the keys the law did not read. Every error names the law, the
//! key, the value and the unit:
//!
//! ```
//! use controller::{Check, Params};
//! let p = Params::parse("hold_ms = -5.0").unwrap();
//! let mut r = p.reader("relev");
//! let e = r.number("hold_ms", "ms", 50.0, Check::NonNegative).unwrap_err().to_string();
//! assert_eq!(e, "law relev: controller.params.hold_ms = -5.0 ms: must be a finite number >= 0");
//!
//! let p = Params::parse("hold_ms = 5.0\nbogus = 1").unwrap();
//! let mut r = p.reader("relev");
//! assert_eq!(r.number("hold_ms", "ms", 50.0, Check::NonNegative).unwrap(), 5.0);
//! assert!(r.finish().unwrap_err().to_string().contains("unknown parameter controller.params.bogus"));
//! ```

use crate::error::LawError;

/// Longest `[controller.params]` document, as TOML text (bytes): the size of
/// the hello's `params` field ([`crate::wire::Hello::params`]).
pub const PARAMS_LEN: usize = 4096;

/// A law's parameters: a TOML table (`[controller.params]`).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
#[serde(transparent)]
pub struct Params {
    table: toml::Table,
}

/// Why a parameter document could not be read.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum ParamsError {
    /// Not valid TOML (or not UTF-8).
    #[error("the [controller.params] document is not valid TOML: {0}")]
    Syntax(String),
    /// Longer than [`PARAMS_LEN`].
    #[error("the [controller.params] table is {len} bytes as TOML text: the limit is {limit} bytes ({PARAMS_LEN})", limit = PARAMS_LEN)]
    TooLong {
        /// Its length (bytes).
        len: usize,
    },
}

impl Params {
    /// Parameters from a table.
    pub fn new(table: toml::Table) -> Self {
        Self { table }
    }

    /// Parameters from a TOML document (the hello's `params`).
    pub fn parse(text: &str) -> Result<Self, ParamsError> {
        if text.len() > PARAMS_LEN {
            return Err(ParamsError::TooLong { len: text.len() });
        }
        let table: toml::Table = text.parse().map_err(|e: toml::de::Error| ParamsError::Syntax(e.to_string()))?;
        Ok(Self { table })
    }

    /// The document as TOML text, checked against [`PARAMS_LEN`].
    pub fn to_document(&self) -> Result<String, ParamsError> {
        let text = toml::to_string(&self.table).map_err(|e| ParamsError::Syntax(e.to_string()))?;
        if text.len() > PARAMS_LEN {
            return Err(ParamsError::TooLong { len: text.len() });
        }
        Ok(text)
    }

    /// The table.
    pub fn table(&self) -> &toml::Table {
        &self.table
    }

    /// True when no parameter is given.
    pub fn is_empty(&self) -> bool {
        self.table.is_empty()
    }

    /// A reader for law `law` (the name its errors give).
    pub fn reader(&self, law: &'static str) -> ParamReader<'_> {
        ParamReader { law, table: &self.table, read: Vec::new() }
    }
}

/// The range a number must lie in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Check {
    /// Finite.
    Finite,
    /// Finite and `> 0`.
    Positive,
    /// Finite and `>= 0`.
    NonNegative,
    /// Finite and strictly between the two bounds.
    Between(f64, f64),
}

impl Check {
    fn why(self) -> String {
        match self {
            Check::Finite => "must be finite".into(),
            Check::Positive => "must be a finite number > 0".into(),
            Check::NonNegative => "must be a finite number >= 0".into(),
            Check::Between(lo, hi) => format!("must be > {lo} and < {hi}"),
        }
    }

    fn holds(self, v: f64) -> bool {
        v.is_finite()
            && match self {
                Check::Finite => true,
                Check::Positive => v > 0.0,
                Check::NonNegative => v >= 0.0,
                Check::Between(lo, hi) => v > lo && v < hi,
            }
    }
}

/// Reads a law's parameters key by key (see the module doc).
#[derive(Debug)]
pub struct ParamReader<'a> {
    law: &'static str,
    table: &'a toml::Table,
    read: Vec<&'static str>,
}

impl ParamReader<'_> {
    /// The law this reader reads for.
    pub fn law(&self) -> &'static str {
        self.law
    }

    /// An error about `key`, whose value is `value` (any `Display`), in `unit`.
    pub fn error(
        &self,
        key: &str,
        value: impl std::fmt::Display,
        unit: &'static str,
        why: impl Into<String>,
    ) -> LawError {
        LawError::Param { law: self.law, key: key.to_string(), value: value.to_string(), unit, why: why.into() }
    }

    /// The number at `key` (an integer is taken as a float), or `default` when absent; both
    /// checked (a default that fails the check is the law's fault, and said so: issue 31
    /// item 11, the C API's laws passed any default through).
    pub fn number(
        &mut self,
        key: &'static str,
        unit: &'static str,
        default: f64,
        check: Check,
    ) -> Result<f64, LawError> {
        match self.optional_number(key, unit, check)? {
            Some(v) => Ok(v),
            None if check.holds(default) => Ok(default),
            None => Err(self.error(
                key,
                default,
                unit,
                format!("the law's own default (the key is not set) {}: a fault of the law", check.why()),
            )),
        }
    }

    /// The number at `key`, if given; checked.
    pub fn optional_number(
        &mut self,
        key: &'static str,
        unit: &'static str,
        check: Check,
    ) -> Result<Option<f64>, LawError> {
        self.read.push(key);
        let Some(value) = self.table.get(key) else { return Ok(None) };
        let v = match value {
            toml::Value::Float(f) => *f,
            toml::Value::Integer(i) => *i as f64,
            other => return Err(self.error(key, other, unit, format!("expected a number ({})", unit_or_ratio(unit)))),
        };
        if check.holds(v) {
            Ok(Some(v))
        } else {
            Err(self.error(key, value, unit, check.why()))
        }
    }

    /// The array of numbers at `key` (integers taken as floats), if given: every element finite,
    /// at least one. A refusal names the key, the whole array as given and the element at fault
    /// (counted from 1).
    pub fn optional_numbers(&mut self, key: &'static str, unit: &'static str) -> Result<Option<Vec<f64>>, LawError> {
        self.read.push(key);
        let Some(value) = self.table.get(key) else { return Ok(None) };
        let toml::Value::Array(items) = value else {
            return Err(self.error(
                key,
                value,
                unit,
                format!("expected an array of numbers ({})", unit_or_ratio(unit)),
            ));
        };
        if items.is_empty() {
            return Err(self.error(key, value, unit, "expected at least one coefficient"));
        }
        let mut out = Vec::with_capacity(items.len());
        for (k, item) in items.iter().enumerate() {
            let v = match item {
                toml::Value::Float(f) => *f,
                toml::Value::Integer(i) => *i as f64,
                other => {
                    return Err(self.error(key, value, unit, format!("element {} = {other} is not a number", k + 1)))
                }
            };
            if !v.is_finite() {
                return Err(self.error(key, value, unit, format!("element {} = {v} must be finite", k + 1)));
            }
            out.push(v);
        }
        Ok(Some(out))
    }

    /// The matrix at `key` (an array of rows, each an array of numbers, every row as long as the
    /// first, every element finite), if given. A refusal names the key, the row and the column
    /// at fault (counted from 1).
    pub fn optional_matrix(
        &mut self,
        key: &'static str,
        unit: &'static str,
    ) -> Result<Option<Vec<Vec<f64>>>, LawError> {
        self.read.push(key);
        let Some(value) = self.table.get(key) else { return Ok(None) };
        let shape = || format!("expected an array of rows, each an array of numbers ({})", unit_or_ratio(unit));
        let toml::Value::Array(rows) = value else { return Err(self.error(key, value, unit, shape())) };
        let mut out = Vec::with_capacity(rows.len());
        for (r, row) in rows.iter().enumerate() {
            let toml::Value::Array(items) = row else { return Err(self.error(key, value, unit, shape())) };
            let mut line = Vec::with_capacity(items.len());
            for (c, item) in items.iter().enumerate() {
                let v = match item {
                    toml::Value::Float(f) => *f,
                    toml::Value::Integer(i) => *i as f64,
                    other => {
                        return Err(self.error(
                            key,
                            value,
                            unit,
                            format!("row {} column {} = {other} is not a number", r + 1, c + 1),
                        ))
                    }
                };
                if !v.is_finite() {
                    return Err(self.error(
                        key,
                        value,
                        unit,
                        format!("row {} column {} = {v} must be finite", r + 1, c + 1),
                    ));
                }
                line.push(v);
            }
            if let Some(first) = out.first().map(Vec::len) {
                if line.len() != first {
                    return Err(self.error(
                        key,
                        value,
                        unit,
                        format!("row {} has {} columns, row 1 has {first}", r + 1, line.len()),
                    ));
                }
            }
            out.push(line);
        }
        Ok(Some(out))
    }

    /// The string at `key`, if given.
    pub fn optional_text(&mut self, key: &'static str) -> Result<Option<String>, LawError> {
        self.read.push(key);
        match self.table.get(key) {
            None => Ok(None),
            Some(toml::Value::String(s)) => Ok(Some(s.clone())),
            Some(other) => Err(self.error(key, other, "", "expected a string")),
        }
    }

    /// The boolean at `key`, or `default` when absent.
    pub fn flag(&mut self, key: &'static str, default: bool) -> Result<bool, LawError> {
        self.read.push(key);
        match self.table.get(key) {
            None => Ok(default),
            Some(toml::Value::Boolean(b)) => Ok(*b),
            Some(other) => Err(self.error(key, other, "", "expected true or false")),
        }
    }

    /// Refuses every key that was not read (naming it and the keys the law reads).
    pub fn finish(self) -> Result<(), LawError> {
        match self.table.iter().find(|(k, _)| !self.read.contains(&k.as_str())) {
            None => Ok(()),
            Some((key, value)) => Err(LawError::UnknownParam {
                law: self.law,
                key: key.clone(),
                value: value.to_string(),
                known: self.read,
            }),
        }
    }
}

fn unit_or_ratio(unit: &str) -> &str {
    if unit.is_empty() {
        "dimensionless"
    } else {
        unit
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrong_type_names_law_key_value_and_unit() {
        let p = Params::parse("enter_um = \"far\"").unwrap();
        let e = p.reader("relev").number("enter_um", "µm", 1.0, Check::Positive).unwrap_err().to_string();
        assert!(e.contains("law relev") && e.contains("controller.params.enter_um") && e.contains("\"far\""), "{e}");
        assert!(e.contains("µm"), "{e}");
    }

    #[test]
    fn out_of_range_names_law_key_value_and_unit() {
        let p = Params::parse("enter_um = -3").unwrap();
        let e = p.reader("relev").number("enter_um", "µm", 1.0, Check::Positive).unwrap_err().to_string();
        assert_eq!(e, "law relev: controller.params.enter_um = -3 µm: must be a finite number > 0");
        let p = Params::parse("xi = 1.5").unwrap();
        let e = p.reader("x").number("xi", "", 0.2, Check::Between(0.0, 1.0)).unwrap_err().to_string();
        assert_eq!(e, "law x: controller.params.xi = 1.5: must be > 0 and < 1");
    }

    #[test]
    fn unknown_keys_are_refused_listing_the_known() {
        let p = Params::parse("a = 1.0\nb = 2.0").unwrap();
        let mut r = p.reader("law1");
        r.number("a", "s", 0.0, Check::Finite).unwrap();
        let e = r.finish().unwrap_err().to_string();
        assert!(e.contains("unknown parameter controller.params.b = 2.0") && e.contains("reads a"), "{e}");
        let e = Params::parse("a = 1.0").unwrap().reader("pd").finish().unwrap_err().to_string();
        assert!(e.contains("law pd reads no parameters"), "{e}");
    }

    #[test]
    fn defaults_apply_when_absent_and_integers_are_numbers() {
        let p = Params::parse("n = 3").unwrap();
        let mut r = p.reader("l");
        assert_eq!(r.number("n", "", 1.0, Check::Positive).unwrap(), 3.0);
        assert_eq!(r.number("m", "", 1.5, Check::Positive).unwrap(), 1.5);
        assert!(r.finish().is_ok());
    }

    /// Issue 31 item 11: a default was never checked. Every check refuses a default that
    /// fails it (NaN and the infinities included), naming the law, the key and the value.
    #[test]
    fn a_default_that_fails_its_check_is_the_laws_fault() {
        let cases = [
            (Check::Finite, f64::NAN),
            (Check::Finite, f64::INFINITY),
            (Check::Positive, 0.0),
            (Check::NonNegative, -1.0),
            (Check::Between(0.0, 1.0), 1.0),
            (Check::Between(0.0, 1.0), f64::NEG_INFINITY),
        ];
        for (check, default) in cases {
            let p = Params::parse("").unwrap();
            let e = p.reader("mylaw").number("gain", "A/m", default, check).unwrap_err().to_string();
            assert!(
                e.contains("law mylaw") && e.contains("controller.params.gain") && e.contains(&default.to_string())
            );
            assert!(e.contains("the law's own default") && e.contains(&check.why()), "{e}");
            // A value given in the scene is checked as before, whatever the default.
            let p = Params::parse("gain = 0.5").unwrap();
            assert_eq!(p.reader("mylaw").number("gain", "A/m", default, check).unwrap(), 0.5);
        }
    }

    #[test]
    fn documents_over_the_limit_are_refused() {
        let long = format!("note = \"{}\"", "x".repeat(PARAMS_LEN));
        assert_eq!(Params::parse(&long), Err(ParamsError::TooLong { len: long.len() }));
        let mut t = toml::Table::new();
        t.insert("note".into(), toml::Value::String("x".repeat(PARAMS_LEN)));
        let e = Params::new(t).to_document().unwrap_err().to_string();
        assert!(e.contains("4096"), "{e}");
    }

    #[test]
    fn a_document_round_trips_floats_exactly() {
        let mut t = toml::Table::new();
        for (i, v) in [0.1, 1.0 / 3.0, 1e-300, 123.456e7, -0.0].iter().enumerate() {
            t.insert(format!("k{i}"), toml::Value::Float(*v));
        }
        let p = Params::new(t);
        assert_eq!(Params::parse(&p.to_document().unwrap()).unwrap(), p);
    }
}
