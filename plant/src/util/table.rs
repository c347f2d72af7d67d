//! The small CSV tables the benches and comparisons write and read
//! (`accuracy.csv`, `models.csv`, `compare.csv`, …), through the `csv` crate
//! and serde: one row type per table, its fields the columns in order, read
//! back by column name (a reader ignores columns it does not know, and names
//! the file, line and column it cannot read).
//!
//! Numbers keep the text they always had: most columns in Rust's `{:e}`
//! (`1.25e-5`, `0e0`, `inf`, `NaN`), written through [`sci`]; a few in
//! `{}` ([`plain`]). The csv crate's own float format (`20000.0`) would
//! change files that scripts and tests read. Any float text reads back.
//!
//! ```
//! #[derive(serde::Serialize, serde::Deserialize, Debug, PartialEq)]
//! struct Point {
//!     name: String,
//!     #[serde(with = "plant::table::sci")]
//!     x_m: f64,
//! }
//! let dir = std::env::temp_dir().join(format!("table-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let path = dir.join("points.csv");
//! plant::table::write(&path, &[Point { name: "a".into(), x_m: 1.5e-6 }]).unwrap();
//! assert_eq!(std::fs::read_to_string(&path).unwrap(), "name,x_m\na,1.5e-6\n");
//! assert_eq!(plant::table::read::<Point>(&path).unwrap(), [Point { name: "a".into(), x_m: 1.5e-6 }]);
//! std::fs::remove_dir_all(&dir).unwrap();
//! ```

use anyhow::Context;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::path::Path;

/// A CSV row type: its columns (`COLUMNS`, the fields' names in order, as serde writes them)
/// and its header line (`HEADER`), derived from the struct's own fields, so that a table's
/// header is never a second hand-written list of its columns. Wrap the row struct's
/// definition: `table_row! { #[derive(Serialize)] pub struct Row { pub a_m: f64, … } }`.
///
/// A declarative macro rather than a derive crate: serde gives a type's field names only
/// through a `Deserialize` impl (which most of these write-only rows do not have) or an
/// instance (which an empty table does not have); a proc-macro crate for a list of
/// `stringify!`s would be a crate to build and keep. A row type whose serde attributes rename,
/// skip or flatten a field must not use it (none does).
macro_rules! table_row {
    ($(#[$meta:meta])* $vis:vis struct $name:ident { $($(#[$fmeta:meta])* $fvis:vis $field:ident : $ty:ty),* $(,)? }) => {
        $(#[$meta])*
        $vis struct $name { $($(#[$fmeta])* $fvis $field: $ty,)* }

        impl $name {
            /// The table's columns: the fields' names, in order.
            pub const COLUMNS: &'static [&'static str] = &[$(stringify!($field)),*];
            /// The table's header line (without its line end): the columns joined by commas.
            pub const HEADER: &'static str = {
                const BYTES: [u8; $crate::table::joined_len($name::COLUMNS)] = $crate::table::join($name::COLUMNS);
                match std::str::from_utf8(&BYTES) {
                    Ok(s) => s,
                    Err(_) => panic!("a column name is not UTF-8"),
                }
            };
        }
    };
}
pub(crate) use table_row;

/// A [`table_row!`] of text fields, for a table written as records of strings (each field
/// formatted by its writer): `into_fields` gives the fields in the columns' order, so that the
/// header and the record come from the one list of fields.
macro_rules! text_row {
    ($(#[$meta:meta])* $vis:vis struct $name:ident { $($(#[$fmeta:meta])* $field:ident),* $(,)? }) => {
        $crate::table::table_row! {
            $(#[$meta])*
            #[derive(Clone, Debug, Default, PartialEq)]
            $vis struct $name { $($(#[$fmeta])* pub $field: String),* }
        }

        impl $name {
            /// The fields, in the columns' order.
            pub fn into_fields(self) -> Vec<String> {
                vec![$(self.$field),*]
            }
        }
    };
}
pub(crate) use text_row;

/// The length of `names` joined by commas (bytes).
pub const fn joined_len(names: &[&str]) -> usize {
    let mut n = names.len().saturating_sub(1);
    let mut i = 0;
    while i < names.len() {
        n += names[i].len();
        i += 1;
    }
    n
}

/// `names` joined by commas, as `N` bytes ([`joined_len`]); at compile time, for a header
/// constant.
pub const fn join<const N: usize>(names: &[&str]) -> [u8; N] {
    let mut out = [0u8; N];
    let (mut k, mut i) = (0, 0);
    while i < names.len() {
        if i > 0 {
            out[k] = b',';
            k += 1;
        }
        let bytes = names[i].as_bytes();
        let mut j = 0;
        while j < bytes.len() {
            out[k] = bytes[j];
            k += 1;
            j += 1;
        }
        i += 1;
    }
    assert!(k == N, "the header's length is not joined_len");
    out
}

/// The rows as CSV text: a header from the row type's field names, then one record per row,
/// `\n`-terminated.
pub fn to_bytes<T: Serialize>(rows: &[T]) -> anyhow::Result<Vec<u8>> {
    let mut w = csv::WriterBuilder::new().terminator(csv::Terminator::Any(b'\n')).from_writer(Vec::new());
    for r in rows {
        w.serialize(r)?;
    }
    w.into_inner().map_err(|e| anyhow::anyhow!("{}", e.error()))
}

/// The rows as CSV text with `header` as the first line, also when there are no rows (serde
/// writes the header with the first row only).
pub fn to_bytes_with_header<T: Serialize>(header: &str, rows: &[T]) -> anyhow::Result<Vec<u8>> {
    let body = to_bytes(rows)?;
    let mut out = format!("{header}\n").into_bytes();
    match body.iter().position(|&b| b == b'\n') {
        Some(end) if !rows.is_empty() => {
            anyhow::ensure!(body[..end] == *header.as_bytes(), "the row type's columns are not `{header}`");
            out.extend_from_slice(&body[end + 1..]);
        }
        _ => {}
    }
    Ok(out)
}

/// Writes the rows to `path` (whole or not at all, [`crate::atomic::write`]).
pub fn write<T: Serialize>(path: &Path, rows: &[T]) -> anyhow::Result<()> {
    let bytes = to_bytes(rows).with_context(|| format!("formatting {}", path.display()))?;
    crate::outfile::write(path, &bytes)
}

/// Writes the rows to `path` under `header`, which is written even when there are no rows.
pub fn write_with_header<T: Serialize>(path: &Path, header: &str, rows: &[T]) -> anyhow::Result<()> {
    let bytes = to_bytes_with_header(header, rows).with_context(|| format!("formatting {}", path.display()))?;
    crate::outfile::write(path, &bytes)
}

/// Reads every row of a CSV file with a header row, matching fields to columns by name.
pub fn read<T: DeserializeOwned>(path: &Path) -> anyhow::Result<Vec<T>> {
    let file = crate::input::open_bounded(path, crate::input::MAX_TABLE_BYTES)
        .with_context(|| format!("reading {}", path.display()))?;
    let mut r = csv::Reader::from_reader(file);
    let header = r.headers().with_context(|| format!("reading {}", path.display()))?.clone();
    let mut rows = Vec::new();
    for (i, record) in r.records().enumerate() {
        let line = i as u64 + 2;
        let record = record.with_context(|| format!("{}: line {line}", path.display()))?;
        let line = record.position().map_or(line, |p| p.line());
        let row = record.deserialize(Some(&header)).map_err(|e| {
            let what = match e.kind() {
                csv::ErrorKind::Deserialize { err, .. } => match err.field().map(|f| f as usize) {
                    Some(f) => format!(
                        "column {}: `{}`: {}",
                        header.get(f).unwrap_or("?"),
                        record.get(f).unwrap_or_default(),
                        err.kind()
                    ),
                    None => err.kind().to_string(),
                },
                _ => e.to_string(),
            };
            anyhow::anyhow!("{}: line {line}: {what}", path.display())
        })?;
        rows.push(row);
    }
    Ok(rows)
}

/// Parses float text (any of Rust's or Python's forms: `1e-3`, `0.001`, `inf`, `nan`).
fn parse_f64<E: serde::de::Error>(text: &str) -> Result<f64, E> {
    let t = text.trim();
    t.parse().map_err(|_| E::custom(format!("`{t}` is not a number")))
}

/// `f64` as `{:e}` (`#[serde(with = "plant::table::sci")]`).
pub mod sci {
    use serde::{Deserialize, Deserializer, Serializer};

    /// Writes `{:e}`.
    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(&format_args!("{v:e}"))
    }

    /// Reads any float text.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        super::parse_f64(&String::deserialize(d)?)
    }
}

/// `Option<f64>` as `{:e}`, `None` as an empty field.
pub mod sci_or_empty {
    use serde::{Deserialize, Deserializer, Serializer};

    /// Writes `{:e}`, or nothing for `None`.
    pub fn serialize<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(v) => s.collect_str(&format_args!("{v:e}")),
            None => s.serialize_str(""),
        }
    }

    /// Reads any float text; an empty field is `None`.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        let t = String::deserialize(d)?;
        if t.trim().is_empty() {
            Ok(None)
        } else {
            super::parse_f64(&t).map(Some)
        }
    }
}

/// `f64` as `{}` (`20000`, `0.01`), for the columns that were always written so.
pub mod plain {
    use serde::{Deserialize, Deserializer, Serializer};

    /// Writes `{}`.
    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(v)
    }

    /// Reads any float text.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        super::parse_f64(&String::deserialize(d)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[derive(Serialize, Deserialize, Debug, PartialEq)]
    struct Row {
        name: String,
        #[serde(with = "sci")]
        x: f64,
        #[serde(with = "sci_or_empty")]
        y: Option<f64>,
        #[serde(with = "plain")]
        rate_hz: f64,
        n: u32,
        ok: bool,
    }

    #[test]
    fn numbers_keep_their_text_and_read_back() {
        let rows = [
            Row { name: "a".into(), x: 0.0, y: None, rate_hz: 20_000.0, n: 3, ok: true },
            Row { name: "b c".into(), x: f64::INFINITY, y: Some(-1.25e-5), rate_hz: 0.5, n: 0, ok: false },
        ];
        let text = String::from_utf8(to_bytes(&rows).unwrap()).unwrap();
        assert_eq!(text, "name,x,y,rate_hz,n,ok\na,0e0,,20000,3,true\nb c,inf,-1.25e-5,0.5,0,false\n");
        let back: Vec<Row> = csv::Reader::from_reader(text.as_bytes()).deserialize().map(Result::unwrap).collect();
        assert_eq!(back, rows);
    }

    #[test]
    fn a_header_is_written_without_rows_and_checked_with_them() {
        assert_eq!(to_bytes_with_header::<Row>("name,x,y,rate_hz,n,ok", &[]).unwrap(), b"name,x,y,rate_hz,n,ok\n");
        let row = Row { name: "a".into(), x: 1.0, y: Some(2.0), rate_hz: 3.0, n: 4, ok: true };
        assert_eq!(
            to_bytes_with_header("name,x,y,rate_hz,n,ok", std::slice::from_ref(&row)).unwrap(),
            b"name,x,y,rate_hz,n,ok\na,1e0,2e0,3,4,true\n"
        );
        assert!(to_bytes_with_header("name,x", &[row]).is_err());
    }

    #[test]
    fn columns_are_read_by_name_in_any_order_and_bad_fields_are_located() {
        let dir = std::env::temp_dir().join(format!("table-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.csv");
        // Other order, an extra column, Python's float text.
        std::fs::write(&path, "ok,extra,n,rate_hz,y,x,name\nfalse,zz,7,2e4,0.001,nan,q\n").unwrap();
        let rows: Vec<Row> = read(&path).unwrap();
        assert_eq!((rows[0].name.as_str(), rows[0].y, rows[0].rate_hz, rows[0].n), ("q", Some(1e-3), 2e4, 7));
        assert!(rows[0].x.is_nan() && !rows[0].ok);
        std::fs::write(&path, "name,x,y,rate_hz,n,ok\na,1,2,3,4,true\nb,1,2,3x,4,true\n").unwrap();
        let err = format!("{:#}", read::<Row>(&path).unwrap_err());
        assert!(err.contains("t.csv: line 3: `3x` is not a number"), "{err}");
        std::fs::write(&path, "name,x,y,rate_hz,n,ok\na,1,2,3,-4,true\n").unwrap();
        let err = format!("{:#}", read::<Row>(&path).unwrap_err());
        assert!(err.contains("t.csv: line 2: column n: `-4`"), "{err}");
        std::fs::write(&path, "name,x\na,1\n").unwrap();
        let err = format!("{:#}", read::<Row>(&path).unwrap_err());
        assert!(err.contains("line 2") && err.contains("missing field `y`"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
