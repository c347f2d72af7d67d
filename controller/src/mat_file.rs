//! MATLAB's `.mat` (level 5, what MATLAB's `save` writes by default since 7.0 and what
//! scipy's `savemat` writes) read into the same JSON object a law file holds
//! ([`crate::law_file`]): each real numeric variable under its name as an array of rows
//! (MATLAB has no scalars: `dt = 0` is a 1 × 1 matrix, `num = [1 2]` a 1 × 2 one; the
//! accessors take those as a number and as a list).
//!
//! Parsed by the `matrw` crate (pure Rust; CI has no C library, so matio-rs, which binds
//! libmatio, cannot be used). Around it, checks written here because matrw does not make them:
//! * the file's level: a v7.3 file is HDF5 (refused naming `save -v7`), a v4 file has no text
//!   header;
//! * the top-level framing: matrw takes a variable cut short at the end of the file as the
//!   end of the file (the variable silently dropped), so every top-level element's tag is
//!   walked and the elements must end exactly where the file ends;
//! * a panic inside the parser on input it does not expect becomes a refusal.

use serde_json::{Map, Value};

/// The header's length (bytes): 116 of text, 8 of subsystem offset, version, endian.
const HEADER: usize = 128;
/// `miMATRIX` and `miCOMPRESSED`, the top-level element types a level-5 file holds.
const MI_MATRIX: u32 = 14;
const MI_COMPRESSED: u32 = 15;

/// Whether `bytes` look like a `.mat` file (any level: its text header).
pub fn is_mat(bytes: &[u8]) -> bool {
    bytes.starts_with(b"MATLAB ")
}

/// The variables of the level-5 `.mat` file `bytes`, as JSON; the error says what is wrong.
pub fn read(bytes: &[u8]) -> Result<Map<String, Value>, String> {
    if bytes.starts_with(b"MATLAB 7.3 MAT-file") || bytes.get(512..520) == Some(b"\x89HDF\r\n\x1a\n") {
        return Err("a MATLAB v7.3 (HDF5) file: expected level 5 (MATLAB: save(..., '-v7'); scipy's savemat)".into());
    }
    if bytes.len() < HEADER {
        return Err(format!("{} bytes, shorter than a .mat file's 128-byte header (truncated?)", bytes.len()));
    }
    if !bytes.starts_with(b"MATLAB 5.0 MAT-file") {
        return Err("not a level-5 .mat file (its header does not begin `MATLAB 5.0 MAT-file`)".into());
    }
    let little = match &bytes[126..128] {
        b"IM" => true,
        b"MI" => false,
        other => return Err(format!("endian indicator {other:?}: expected \"IM\" or \"MI\"")),
    };
    frame(&bytes[HEADER..], little)?;
    // The body parsed by matrw's level-5 parser, the header checked above: matrw's own loader
    // wants the text to begin `MATLAB 5.0 MAT-file, ` (MATLAB's), and scipy's `savemat` writes
    // `MATLAB 5.0 MAT-file Platform: …` (the text is free by the format's definition).
    // matrw's parser may panic on input it does not expect (its own `panic!`s and
    // `unimplemented!`s): a refusal, not an abort of the plant.
    let endian = if little { matrw_binrw::Endian::Little } else { matrw_binrw::Endian::Big };
    let parsed = std::panic::catch_unwind(|| {
        use matrw_binrw::BinRead;
        let mut body = std::io::Cursor::new(&bytes[HEADER..]);
        matrw::parser::v7::matfile7::MatFile7::read_options(&mut body, endian, ()).map(matrw::MatFile::from)
    });
    let file = parsed
        .map_err(|_| "a .mat file its parser cannot read".to_string())?
        .map_err(|e| format!("a .mat file that cannot be read: {}", first_line(&e.to_string())))?;
    let mut out = Map::new();
    for (name, var) in file.iter() {
        out.insert(name.clone(), variable(name, var)?);
    }
    Ok(out)
}

/// binrw's error's first line that says something (it appends a backtrace in colour).
fn first_line(text: &str) -> String {
    let plain: String = text.chars().filter(|c| !c.is_control() || *c == '\n').collect();
    plain.lines().map(str::trim).find(|l| !l.is_empty()).unwrap_or("").to_string()
}

/// Walks the top-level elements' tags (type and byte count, each padded to 8 bytes but a
/// compressed one): they must fill the data exactly.
fn frame(data: &[u8], little: bool) -> Result<(), String> {
    let word = |b: &[u8]| {
        let w: [u8; 4] = b.try_into().unwrap_or([0; 4]);
        if little {
            u32::from_le_bytes(w)
        } else {
            u32::from_be_bytes(w)
        }
    };
    let mut at = 0usize;
    let mut k = 0;
    while at < data.len() {
        k += 1;
        let Some(tag) = data.get(at..at + 8) else {
            return Err(format!("element {k} at byte {}: its tag is cut short (truncated file?)", HEADER + at));
        };
        let (kind, size) = (word(&tag[..4]), word(&tag[4..]) as usize);
        if kind != MI_MATRIX && kind != MI_COMPRESSED {
            return Err(format!(
                "element {k} at byte {} has type {kind}: expected a matrix (14) or compressed (15)",
                HEADER + at
            ));
        }
        if data.len() - at - 8 < size {
            return Err(format!(
                "element {k} at byte {} says {size} bytes, the file has {} left (truncated file?)",
                HEADER + at,
                data.len() - at - 8
            ));
        }
        let padded = if kind == MI_COMPRESSED { size } else { size.div_ceil(8) * 8 };
        at = (at + 8 + padded).min(data.len());
    }
    Ok(())
}

/// One variable as JSON rows (real, numeric or logical, at most 2 dimensions).
fn variable(name: &str, var: &matrw::MatVariable) -> Result<Value, String> {
    use matrw::MatVariable as V;
    let array = match var {
        V::Compressed(c) => return variable(name, &c.value),
        V::NumericArray(a) => a,
        // An empty matrix (`D = []`): no rows.
        V::Null => return Ok(Value::Array(Vec::new())),
        V::Unsupported => {
            return Err(format!("variable `{name}` is of a kind not read (an object?): expected a real matrix"))
        }
        V::SparseArray(_) => {
            return Err(format!("variable `{name}` is sparse: expected a full real matrix (full(...))"))
        }
        V::CellArray(_) => return Err(format!("variable `{name}` is a cell array: expected a real matrix")),
        V::Structure(_) | V::StructureArray(_) => {
            return Err(format!("variable `{name}` is a struct: expected a real matrix"));
        }
    };
    let what = |kind: &str| format!("variable `{name}` is {kind}: expected a real matrix of numbers");
    if array.value_cmp.is_some() {
        return Err(what("complex"));
    }
    use matrw::MatlabType as T;
    let values: Vec<f64> = match &array.value {
        T::F64(v) => v.clone(),
        T::F32(v) => v.iter().map(|x| f64::from(*x)).collect(),
        T::I8(v) => v.iter().map(|x| f64::from(*x)).collect(),
        T::U8(v) => v.iter().map(|x| f64::from(*x)).collect(),
        T::I16(v) => v.iter().map(|x| f64::from(*x)).collect(),
        T::U16(v) => v.iter().map(|x| f64::from(*x)).collect(),
        T::I32(v) => v.iter().map(|x| f64::from(*x)).collect(),
        T::U32(v) => v.iter().map(|x| f64::from(*x)).collect(),
        // 64-bit integers above 2^53 round; a law's coefficients are not such integers.
        T::I64(v) => v.iter().map(|x| *x as f64).collect(),
        T::U64(v) => v.iter().map(|x| *x as f64).collect(),
        T::BOOL(v) => v.iter().map(|x| f64::from(u8::from(*x))).collect(),
        T::UTF8(_) | T::UTF16(_) => return Err(what("text (a char array)")),
    };
    let dims = &array.dim;
    let (r, c) = match dims.as_slice() {
        [] => (usize::from(!values.is_empty()), values.len()),
        [r] => (*r, 1),
        [r, c] => (*r, *c),
        more if more.iter().skip(2).all(|d| *d == 1) => (more[0], more[1]),
        more => {
            let shape: Vec<String> = more.iter().map(usize::to_string).collect();
            return Err(format!("variable `{name}` is {}: expected a matrix (2 dimensions)", shape.join(" × ")));
        }
    };
    if r * c != values.len() {
        return Err(format!("variable `{name}`: {} values for {r} × {c}", values.len()));
    }
    // Column-major in the file; a non-finite value becomes null, refused by the accessors as
    // not a finite number.
    let at = |i: usize, j: usize| serde_json::Number::from_f64(values[j * r + i]).map_or(Value::Null, Value::Number);
    Ok(Value::Array((0..r).map(|i| Value::Array((0..c).map(|j| at(i, j)).collect())).collect()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// scipy's `savemat` of a lead in `s` (uncompressed; tests/fixtures/make_mat_fixtures.py).
    const TF: &[u8] = include_bytes!("../tests/fixtures/tf-savemat.mat");
    /// scipy's `savemat` of a discrete two-axis system, compressed, B as float32.
    const SS: &[u8] = include_bytes!("../tests/fixtures/ss-savemat-compressed.mat");

    #[test]
    fn scipys_savemat_reads_as_the_arrays_it_was_given() {
        let tau = 2.0 * std::f64::consts::PI;
        let tf = read(TF).unwrap();
        // The script's own arithmetic, the same IEEE operations in the same order.
        assert_eq!(tf["num"], serde_json::json!([[-1.2 / (tau * 150.0), -1.2]]));
        assert_eq!(tf["den"], serde_json::json!([[1.0 / (tau * 1500.0), 1.0]]));
        assert_eq!(tf["dt"], serde_json::json!([[0.0]]));
        let ss = read(SS).unwrap();
        assert_eq!(ss["A"], serde_json::json!([[0.5, 0.125], [0.0, 0.25]]));
        assert_eq!(ss["B"], serde_json::json!([[1.0, 0.0], [0.0, 1.0]]));
        assert_eq!(ss["C"], serde_json::json!([[1.0, 2.0], [3.0, 4.0]]));
        assert_eq!(ss["D"], serde_json::json!([[0.0, 0.0], [0.0, 0.0]]));
        assert_eq!(ss["dt"], serde_json::json!([[5e-5]]));
    }

    /// Cut anywhere, a file is refused or reads as fewer whole variables (cut between two),
    /// never as a variable with other values; never a panic.
    #[test]
    fn a_truncated_file_is_refused_or_short_of_a_variable_never_misread() {
        for whole in [TF, SS] {
            let full = read(whole).unwrap();
            for cut in 0..whole.len() {
                match read(&whole[..cut]) {
                    Err(e) => assert!(!e.is_empty()),
                    Ok(part) => {
                        assert!(part.len() < full.len(), "cut at {cut}: every variable read");
                        for (k, v) in &part {
                            assert_eq!(Some(v), full.get(k), "cut at {cut}: {k} misread");
                        }
                    }
                }
            }
            let e = read(&whole[..whole.len() - 10]).unwrap_err();
            assert!(e.contains("truncated"), "{e}");
        }
    }

    #[test]
    fn other_levels_and_formats_are_refused_by_what_they_are() {
        let mut v73 =
            b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Sun May 19 14:40:48 2024 HDF5 schema 1.00 .".to_vec();
        v73.resize(512, b' ');
        v73.extend_from_slice(b"\x89HDF\r\n\x1a\n");
        assert!(read(&v73).unwrap_err().contains("v7.3"));
        assert!(read(&TF[..100]).unwrap_err().contains("128-byte header"));
        let mut v4 = TF.to_vec();
        v4[..19].copy_from_slice(b"MATLAB 4.0 MAT-file");
        assert!(read(&v4).unwrap_err().contains("not a level-5"));
        let mut endian = TF.to_vec();
        endian[126..128].copy_from_slice(b"XX");
        assert!(read(&endian).unwrap_err().contains("endian"));
    }

    /// Any byte of the body overwritten: a refusal or a reading, never a panic.
    #[test]
    fn a_corrupted_body_never_panics() {
        for whole in [TF, SS] {
            for at in HEADER..whole.len() {
                for byte in [0x00, 0xff] {
                    let mut bad = whole.to_vec();
                    bad[at] = byte;
                    let _ = read(&bad);
                }
            }
        }
    }
}
