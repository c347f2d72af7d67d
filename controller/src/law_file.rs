//! A linear law read from a file (`[controller.params] file`): the JSON object a few lines of
//! python-control or MATLAB write (docs/guide/controllers.md), read through the project's
//! bounded, non-blocking reader (`shock_table::input`: a FIFO or a device is refused, never
//! waited on). A relative path is taken from the current directory of the process that builds
//! the law (the plant's, and the `controller` process it starts inherits it).

use crate::error::LawError;
use crate::params::ParamReader;
use std::path::Path;

/// The most a law file may hold (bytes).
pub const MAX_LAW_FILE_BYTES: u64 = 16 << 20;

/// The file's top-level object, with the reader to name `file` in refusals.
pub struct LawFile {
    path: String,
    object: serde_json::Map<String, serde_json::Value>,
}

impl LawFile {
    /// Reads `path` (the value of `file`): a regular file, UTF-8 JSON, an object holding at
    /// least the keys `needs` (named in a refusal).
    pub fn read(p: &ParamReader<'_>, path: &str, needs: &str) -> Result<Self, LawError> {
        let bad = |why: String| p.error("file", format!("{path:?}"), "", why);
        let text = shock_table::input::read_text(Path::new(path), MAX_LAW_FILE_BYTES)
            .map_err(|e| bad(format!("cannot be read: {e}")))?;
        let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
            bad(format!(
                "is not JSON ({e}): expected a JSON object {needs} (a .npz or .mat file is not read; see \
                 docs/guide/controllers.md)"
            ))
        })?;
        match value {
            serde_json::Value::Object(object) => Ok(Self { path: path.to_string(), object }),
            other => Err(bad(format!("holds a JSON {}: expected an object {needs}", kind(&other)))),
        }
    }

    fn bad(&self, p: &ParamReader<'_>, key: &str, why: String) -> LawError {
        p.error("file", format!("{:?}", self.path), "", format!("its `{key}` {why}"))
    }

    /// Whether the file has `key`.
    pub fn has(&self, key: &str) -> bool {
        self.object.get(key).is_some_and(|v| !v.is_null())
    }

    /// A finite number at `key`, if present (`null` is absent).
    pub fn number(&self, p: &ParamReader<'_>, key: &str) -> Result<Option<f64>, LawError> {
        match self.object.get(key) {
            None | Some(serde_json::Value::Null) => Ok(None),
            Some(v) => match v.as_f64().filter(|x| x.is_finite()) {
                Some(x) => Ok(Some(x)),
                None => Err(self.bad(p, key, format!("= {v}: expected a finite number"))),
            },
        }
    }

    /// A non-empty array of finite numbers at `key` (a one-row matrix `[[…]]`, as MATLAB's
    /// `jsonencode` and numpy's `tolist()` of a 2-D array write it, is taken as its row).
    pub fn numbers(&self, p: &ParamReader<'_>, key: &str) -> Result<Vec<f64>, LawError> {
        let Some(v) = self.object.get(key) else { return Err(self.bad(p, key, "is missing".into())) };
        let items = match v {
            serde_json::Value::Array(rows) if rows.len() == 1 && rows[0].is_array() => rows[0].as_array(),
            other => other.as_array(),
        };
        let Some(items) = items.filter(|a| !a.is_empty()) else {
            return Err(self.bad(p, key, format!("= {v}: expected a non-empty array of numbers")));
        };
        items
            .iter()
            .enumerate()
            .map(|(k, x)| {
                x.as_f64()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| self.bad(p, key, format!("element {} = {x} is not a finite number", k + 1)))
            })
            .collect()
    }

    /// A matrix (array of rows of finite numbers, every row as long as the first) at `key`; an
    /// empty one (`[]`) has no rows.
    pub fn matrix(&self, p: &ParamReader<'_>, key: &str) -> Result<Vec<Vec<f64>>, LawError> {
        let Some(v) = self.object.get(key) else { return Err(self.bad(p, key, "is missing".into())) };
        let Some(rows) = v.as_array() else {
            return Err(self.bad(p, key, "is not an array of rows".into()));
        };
        let mut out: Vec<Vec<f64>> = Vec::with_capacity(rows.len());
        for (r, row) in rows.iter().enumerate() {
            let Some(items) = row.as_array() else {
                return Err(self.bad(p, key, format!("row {} is not an array of numbers", r + 1)));
            };
            let mut line = Vec::with_capacity(items.len());
            for (c, x) in items.iter().enumerate() {
                match x.as_f64().filter(|x| x.is_finite()) {
                    Some(x) => line.push(x),
                    None => {
                        return Err(self.bad(
                            p,
                            key,
                            format!("row {} column {} = {x} is not a finite number", r + 1, c + 1),
                        ))
                    }
                }
            }
            if let Some(first) = out.first().map(Vec::len) {
                if line.len() != first {
                    return Err(self.bad(
                        p,
                        key,
                        format!("row {} has {} columns, row 1 has {first}", r + 1, line.len()),
                    ));
                }
            }
            out.push(line);
        }
        Ok(out)
    }
}

fn kind(v: &serde_json::Value) -> &'static str {
    match v {
        serde_json::Value::Null => "null",
        serde_json::Value::Bool(_) => "boolean",
        serde_json::Value::Number(_) => "number",
        serde_json::Value::String(_) => "string",
        serde_json::Value::Array(_) => "array",
        serde_json::Value::Object(_) => "object",
    }
}
