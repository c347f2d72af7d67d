//! A linear law read from a file (`[controller.params] file`): the JSON object a few lines of
//! python-control or MATLAB write, numpy's `.npz` of the same arrays (`np.savez`,
//! `np.savez_compressed`; docs/guide/controllers.md) or MATLAB's level-5 `.mat` (`save`,
//! scipy's `savemat`; [`crate::mat_file`]), read through the project's
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
    /// What the file must hold (named when a key is missing).
    needs: String,
    object: serde_json::Map<String, serde_json::Value>,
}

impl LawFile {
    /// Reads `path` (the value of `file`): a regular file, UTF-8 JSON, an object holding at
    /// least the keys `needs` (named in a refusal).
    pub fn read(p: &ParamReader<'_>, path: &str, needs: &str) -> Result<Self, LawError> {
        let bad = |why: String| p.error("file", format!("{path:?}"), "", why);
        let bytes = shock_table::input::read_bytes(Path::new(path), MAX_LAW_FILE_BYTES)
            .map_err(|e| bad(format!("cannot be read: {e}")))?;
        if crate::mat_file::is_mat(&bytes) {
            let object = crate::mat_file::read(&bytes).map_err(|e| bad(format!("is not a readable .mat file: {e}")))?;
            return Ok(Self { path: path.to_string(), needs: needs.to_string(), object });
        }
        if bytes.starts_with(b"PK\x03\x04") {
            let object = npz(&bytes).map_err(|e| bad(format!("is not a numpy .npz of float64 arrays: {e}")))?;
            return Ok(Self { path: path.to_string(), needs: needs.to_string(), object });
        }
        let value: serde_json::Value = std::str::from_utf8(&bytes)
            .map_err(|e| e.to_string())
            .and_then(|text| serde_json::from_str(text).map_err(|e| e.to_string()))
            .map_err(|e| {
                bad(format!(
                    "is neither JSON, numpy's .npz nor MATLAB's .mat ({e}): expected a JSON object {needs}, or an \
                     .npz or a level-5 .mat of the same arrays (see docs/guide/linear.md)"
                ))
            })?;
        match value {
            serde_json::Value::Object(object) => Ok(Self { path: path.to_string(), needs: needs.to_string(), object }),
            other => Err(bad(format!("holds a JSON {}: expected an object {needs}", kind(&other)))),
        }
    }

    fn bad(&self, p: &ParamReader<'_>, key: &str, why: String) -> LawError {
        p.error("file", format!("{:?}", self.path), "", format!("its `{key}` {why}"))
    }

    fn missing(&self, p: &ParamReader<'_>, key: &str) -> LawError {
        self.bad(p, key, format!("is missing: expected {}", self.needs))
    }

    /// Whether the file has `key`.
    pub fn has(&self, key: &str) -> bool {
        self.object.get(key).is_some_and(|v| !v.is_null())
    }

    /// A finite number at `key`, if present (`null` is absent; a 1 × 1 matrix `[[x]]`, as a
    /// `.mat` file holds every number, is its number).
    pub fn number(&self, p: &ParamReader<'_>, key: &str) -> Result<Option<f64>, LawError> {
        match self.object.get(key) {
            None | Some(serde_json::Value::Null) => Ok(None),
            Some(v) => match one_by_one(v).as_f64().filter(|x| x.is_finite()) {
                Some(x) => Ok(Some(x)),
                None => Err(self.bad(p, key, format!("= {v}: expected a finite number"))),
            },
        }
    }

    /// A non-empty array of finite numbers at `key` (a one-row matrix `[[…]]`, as MATLAB's
    /// `jsonencode`, numpy's `tolist()` of a 2-D array and a `.mat` file hold it, is taken as its
    /// row; a one-column matrix `[[a], [b]]` as its column).
    pub fn numbers(&self, p: &ParamReader<'_>, key: &str) -> Result<Vec<f64>, LawError> {
        let Some(v) = self.object.get(key) else { return Err(self.missing(p, key)) };
        let column: Option<Vec<serde_json::Value>> = match v {
            serde_json::Value::Array(rows)
                if rows.len() > 1 && rows.iter().all(|r| r.as_array().is_some_and(|r| r.len() == 1)) =>
            {
                Some(rows.iter().map(one_by_one).cloned().collect())
            }
            _ => None,
        };
        let items = match (v, &column) {
            (_, Some(column)) => Some(column),
            (serde_json::Value::Array(rows), None) if rows.len() == 1 && rows[0].is_array() => rows[0].as_array(),
            (other, None) => other.as_array(),
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
        let Some(v) = self.object.get(key) else { return Err(self.missing(p, key)) };
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

/// A 1 × 1 matrix's element (a row of one), else the value itself.
fn one_by_one(v: &serde_json::Value) -> &serde_json::Value {
    match v.as_array().map(Vec::as_slice) {
        Some([row]) => match row.as_array().map(Vec::as_slice) {
            Some([x]) => x,
            _ => v,
        },
        _ => v,
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

/// numpy's `.npz`: each `NAME.npy` entry (float64 or int64, little-endian, any order, 0 to 2
/// dimensions) as a JSON number, array or array of rows under `NAME`. Written here rather than
/// through an npy crate: a few lines over the zip crate the workspace already has, and the
/// controller crate's dependencies stay few.
fn npz(bytes: &[u8]) -> Result<serde_json::Map<String, serde_json::Value>, String> {
    use std::io::Read;
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes)).map_err(|e| e.to_string())?;
    let mut out = serde_json::Map::new();
    for i in 0..zip.len() {
        let mut entry = zip.by_index(i).map_err(|e| e.to_string())?;
        let name = entry.name().to_string();
        let Some(key) = name.strip_suffix(".npy") else { continue };
        let mut data = Vec::new();
        (&mut entry).take(MAX_LAW_FILE_BYTES).read_to_end(&mut data).map_err(|e| format!("{name}: {e}"))?;
        let value = npy(&data).map_err(|e| format!("{name}: {e}"))?;
        out.insert(key.to_string(), value);
    }
    Ok(out)
}

/// One `.npy` array (numpy's format.py, versions 1 to 3) as JSON.
fn npy(b: &[u8]) -> Result<serde_json::Value, String> {
    if !b.starts_with(b"\x93NUMPY") || b.len() < 10 {
        return Err("not an .npy array".into());
    }
    let (len, start) = match b[6] {
        1 => (u16::from_le_bytes([b[8], b[9]]) as usize, 10),
        2 | 3 if b.len() >= 12 => (u32::from_le_bytes([b[8], b[9], b[10], b[11]]) as usize, 12),
        v => return Err(format!("npy version {v}")),
    };
    let header = b.get(start..start + len).ok_or("a truncated header")?;
    let header = std::str::from_utf8(header).map_err(|e| e.to_string())?;
    let field = |key: &str| -> Result<&str, String> {
        let at = header.find(&format!("'{key}':")).ok_or(format!("no {key} in the header"))?;
        Ok(header[at + key.len() + 3..].trim_start())
    };
    let descr = field("descr")?;
    let int = if descr.starts_with("'<f8'") {
        false
    } else if descr.starts_with("'<i8'") {
        true
    } else {
        return Err(format!("dtype {}: expected float64 ('<f8') or int64", descr.split(',').next().unwrap_or("")));
    };
    let fortran = field("fortran_order")?.starts_with("True");
    let shape = field("shape")?;
    let shape = &shape[1..shape.find(')').ok_or("a malformed shape")?];
    let dims: Vec<usize> = shape
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<usize>().map_err(|e| format!("shape ({shape}): {e}")))
        .collect::<Result<_, _>>()?;
    let count: usize = dims.iter().product();
    let data = &b[start + len..];
    if data.len() != 8 * count {
        return Err(format!("{} bytes of data for shape ({shape})", data.len()));
    }
    let at = |k: usize| {
        let w: [u8; 8] = data[8 * k..8 * k + 8].try_into().unwrap_or([0; 8]);
        let v = if int { i64::from_le_bytes(w) as f64 } else { f64::from_le_bytes(w) };
        // Not finite: a JSON null, refused by the accessors as not a finite number.
        serde_json::Number::from_f64(v).map_or(serde_json::Value::Null, serde_json::Value::Number)
    };
    Ok(match dims.as_slice() {
        [] => at(0),
        [n] => serde_json::Value::Array((0..*n).map(at).collect()),
        [r, c] => serde_json::Value::Array(
            (0..*r)
                .map(|i| {
                    serde_json::Value::Array((0..*c).map(|j| at(if fortran { j * r + i } else { i * c + j })).collect())
                })
                .collect(),
        ),
        _ => return Err(format!("{} dimensions: expected at most 2", dims.len())),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An .npy array as numpy's format.py writes it (version 1, header padded to 64 bytes).
    fn npy_bytes(descr: &str, fortran: bool, shape: &str, data: &[u8]) -> Vec<u8> {
        let mut header = format!(
            "{{'descr': '{descr}', 'fortran_order': {}, 'shape': {shape}, }}",
            if fortran { "True" } else { "False" }
        );
        while (10 + header.len() + 1) % 64 != 0 {
            header.push(' ');
        }
        header.push('\n');
        let mut b = b"\x93NUMPY\x01\x00".to_vec();
        b.extend((header.len() as u16).to_le_bytes());
        b.extend(header.as_bytes());
        b.extend(data);
        b
    }

    fn f8(v: &[f64]) -> Vec<u8> {
        v.iter().flat_map(|x| x.to_le_bytes()).collect()
    }

    #[test]
    fn npy_arrays_read_in_c_and_fortran_order_and_as_scalars() {
        let c = npy(&npy_bytes("<f8", false, "(2, 3)", &f8(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]))).unwrap();
        let f = npy(&npy_bytes("<f8", true, "(2, 3)", &f8(&[1.0, 4.0, 2.0, 5.0, 3.0, 6.0]))).unwrap();
        assert_eq!(c, serde_json::json!([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]));
        assert_eq!(f, c);
        assert_eq!(npy(&npy_bytes("<f8", false, "(2,)", &f8(&[0.5, -1.0]))).unwrap(), serde_json::json!([0.5, -1.0]));
        assert_eq!(npy(&npy_bytes("<f8", false, "()", &f8(&[5e-5]))).unwrap(), serde_json::json!(5e-5));
        let ints: Vec<u8> = [3i64, -2].iter().flat_map(|x| x.to_le_bytes()).collect();
        assert_eq!(npy(&npy_bytes("<i8", false, "(2,)", &ints)).unwrap(), serde_json::json!([3.0, -2.0]));
        let e = npy(&npy_bytes("<f4", false, "(1,)", &[0; 4])).unwrap_err();
        assert!(e.contains("'<f4'") && e.contains("float64"), "{e}");
        let e = npy(&npy_bytes("<f8", false, "(3,)", &f8(&[1.0]))).unwrap_err();
        assert!(e.contains("8 bytes of data for shape (3,)"), "{e}");
        let e = npy(&npy_bytes("<f8", false, "(1, 1, 1)", &f8(&[1.0]))).unwrap_err();
        assert!(e.contains("3 dimensions"), "{e}");
    }
}
