//! The linear plant's files: `linear.json` (every matrix, name and unit; the schema is
//! docs/guide/linear.md's), `linear.npz` (numpy's zip of `.npy` arrays) and `linear.mat`
//! (MATLAB's level 5), the last two with the same names. Pure: each returns the bytes, the
//! command writes them.

use super::model::{LinearPlant, Signal, System};
use nalgebra::DMatrix;
use serde::Serialize;
use std::io::Write;

/// The format's name and version, in both files.
pub const FORMAT: &str = "plant-linear";
/// Its version: a key added keeps it; a key renamed or removed would bump it.
pub const VERSION: u32 = 1;

/// The exported model: the continuous plant and its discrete form.
pub struct Export<'a> {
    /// The continuous plant.
    pub plant: &'a LinearPlant,
    /// The discrete system (zero-order hold, the delay states appended).
    pub discrete: &'a System,
    /// Its states.
    pub discrete_states: &'a [Signal],
    /// Its period (s).
    pub period: f64,
    /// Its command delay (ticks).
    pub delay: u32,
    /// The scene's law as a linear form, where it has one, with its name.
    pub law: Option<(&'a str, &'a super::law::LinearLaw)>,
    /// Each axis' margins with that law.
    pub margins: &'a [super::margins::AxisMargins],
}

#[derive(Serialize)]
struct JsonLaw<'a> {
    name: &'a str,
    form: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    dt: Option<f64>,
    axes: Vec<super::law::Transfer>,
    /// A state-space law's discrete system (its `axes` empty).
    #[serde(skip_serializing_if = "Option::is_none")]
    system: Option<JsonMatrices>,
    /// The law's own poles outside the unit circle (summed over the axes of a per-axis law).
    unstable_poles: usize,
}

/// A system's matrices as rows under `A`, `B`, `C`, `D`: the law's system as it is, the
/// plant's flattened into [`JsonSystem`] (one struct, so that both are written the same way).
#[derive(Serialize)]
struct JsonMatrices {
    #[serde(rename = "A")]
    a: Vec<Vec<f64>>,
    #[serde(rename = "B")]
    b: Vec<Vec<f64>>,
    #[serde(rename = "C")]
    c: Vec<Vec<f64>>,
    #[serde(rename = "D")]
    d: Vec<Vec<f64>>,
}

impl JsonMatrices {
    fn of(a: &DMatrix<f64>, b: &DMatrix<f64>, c: &DMatrix<f64>, d: &DMatrix<f64>) -> Self {
        Self { a: rows(a), b: rows(b), c: rows(c), d: rows(d) }
    }
}

#[derive(Serialize)]
struct JsonMargins<'a> {
    axis: &'a str,
    gain_margin_db: Option<f64>,
    gain_margin_f_hz: Option<f64>,
    phase_margin_deg: Option<f64>,
    phase_margin_f_hz: Option<f64>,
    phase_crossovers: &'a [super::margins::Crossing],
    gain_crossovers: &'a [super::margins::Crossing],
}

/// A matrix as its rows.
fn rows(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows()).map(|i| m.row(i).iter().copied().collect()).collect()
}

#[derive(Serialize)]
struct JsonSystem<'a> {
    #[serde(skip_serializing_if = "Option::is_none")]
    dt: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    delay_samples: Option<u32>,
    states: &'a [Signal],
    #[serde(flatten)]
    matrices: JsonMatrices,
}

#[derive(Serialize)]
struct Json<'a> {
    format: &'static str,
    version: u32,
    scene: &'a str,
    rotor_model: &'a str,
    speed_hz: f64,
    about: &'static str,
    parts: &'a [String],
    inputs: &'a [Signal],
    outputs: &'a [Signal],
    continuous: JsonSystem<'a>,
    discrete: JsonSystem<'a>,
    law: Option<JsonLaw<'a>>,
    margins: Vec<JsonMargins<'a>>,
}

/// What the model is linearised about, in both files.
pub const ABOUT: &str = "the rotor centred and levitated, clear of the touchdown bearings, its spin held at speed_hz; \
    inputs and outputs are deviations from that state (the bias currents left out)";

/// `linear.json`.
pub fn json(e: &Export<'_>) -> Vec<u8> {
    let s = &e.plant.system;
    let doc = Json {
        format: FORMAT,
        version: VERSION,
        scene: &e.plant.scene,
        rotor_model: e.plant.rotor_model,
        speed_hz: e.plant.speed_hz,
        about: ABOUT,
        parts: &e.plant.parts,
        inputs: &e.plant.inputs,
        outputs: &e.plant.outputs,
        continuous: JsonSystem {
            dt: None,
            delay_samples: None,
            states: &e.plant.states,
            matrices: JsonMatrices::of(&s.a, &s.b, &s.c, &s.d),
        },
        discrete: JsonSystem {
            dt: Some(e.period),
            delay_samples: Some(e.delay),
            states: e.discrete_states,
            matrices: JsonMatrices::of(&e.discrete.a, &e.discrete.b, &e.discrete.c, &e.discrete.d),
        },
        law: e.law.map(|(name, law)| JsonLaw {
            name,
            form: law.form(),
            dt: law.period().map(|_| e.period),
            axes: law.transfers(),
            system: match law {
                super::law::LinearLaw::StateSpace { system: l, .. } => Some(JsonMatrices::of(&l.a, &l.b, &l.c, &l.d)),
                _ => None,
            },
            unstable_poles: law.unstable_poles(),
        }),
        margins: e
            .margins
            .iter()
            .map(|m| JsonMargins {
                axis: e.plant.outputs.get(m.axis).map_or("", |o| o.name.strip_prefix("v_").unwrap_or(&o.name)),
                gain_margin_db: m.gain_margin_db.map(|g| g.0),
                gain_margin_f_hz: m.gain_margin_db.map(|g| g.1),
                phase_margin_deg: m.phase_margin_deg.map(|p| p.0),
                phase_margin_f_hz: m.phase_margin_deg.map(|p| p.1),
                phase_crossovers: &m.phase_crossovers,
                gain_crossovers: &m.gain_crossovers,
            })
            .collect(),
    };
    let mut text = serde_json::to_string_pretty(&doc).expect("serialisable");
    text.push('\n');
    text.into_bytes()
}

/// One `.npy` file (format version 1.0): the magic, the header's length, the header (a Python
/// dict literal padded with spaces to a multiple of 64 bytes, ending in a newline), the data.
/// Written by hand: the format is a page long (numpy's `format.py`), and a crate for it
/// (`ndarray-npy`) would bring `ndarray` for nothing else.
fn npy(descr: &str, shape: &[usize], data: &[u8]) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(usize::to_string).collect();
    let shape = match dims.len() {
        1 => format!("({},)", dims[0]),
        _ => format!("({})", dims.join(", ")),
    };
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    let total = 10 + header.len() + 1;
    header.push_str(&" ".repeat((64 - total % 64) % 64));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + data.len());
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(data);
    out
}

/// A matrix as a C-ordered `<f8` array.
fn npy_matrix(m: &DMatrix<f64>) -> Vec<u8> {
    let mut data = Vec::with_capacity(8 * m.len());
    for i in 0..m.nrows() {
        for v in m.row(i).iter() {
            data.extend_from_slice(&v.to_le_bytes());
        }
    }
    npy("<f8", &[m.nrows(), m.ncols()], &data)
}

/// A scalar as a 0-dimensional `<f8` array.
fn npy_scalar(v: f64) -> Vec<u8> {
    npy("<f8", &[], &v.to_le_bytes())
}

/// Strings as a `<U{n}` array (UTF-32, little endian, each padded with NULs to the longest).
fn npy_strings(items: &[&str]) -> Vec<u8> {
    let width = items.iter().map(|s| s.chars().count()).max().unwrap_or(0).max(1);
    let mut data = Vec::with_capacity(4 * width * items.len());
    for s in items {
        let n = s.chars().count();
        for ch in s.chars() {
            data.extend_from_slice(&(ch as u32).to_le_bytes());
        }
        data.extend(std::iter::repeat_n(0u8, 4 * (width - n)));
    }
    npy(&format!("<U{width}"), &[items.len()], &data)
}

/// `linear.npz`: `A`, `B`, `C`, `D` (continuous), `Ad`, `Bd`, `Cd`, `Dd`, `dt`,
/// `delay_samples`, `speed_hz`, and the names and units (`inputs`, `input_units`, `outputs`,
/// `output_units`, `states`, `state_units`, `states_d`, `state_units_d`).
pub fn npz(e: &Export<'_>) -> anyhow::Result<Vec<u8>> {
    let s = &e.plant.system;
    let names = |v: &[Signal]| npy_strings(&v.iter().map(|s| s.name.as_str()).collect::<Vec<_>>());
    let units = |v: &[Signal]| npy_strings(&v.iter().map(|s| s.unit.as_str()).collect::<Vec<_>>());
    let arrays: Vec<(&str, Vec<u8>)> = vec![
        ("A", npy_matrix(&s.a)),
        ("B", npy_matrix(&s.b)),
        ("C", npy_matrix(&s.c)),
        ("D", npy_matrix(&s.d)),
        ("Ad", npy_matrix(&e.discrete.a)),
        ("Bd", npy_matrix(&e.discrete.b)),
        ("Cd", npy_matrix(&e.discrete.c)),
        ("Dd", npy_matrix(&e.discrete.d)),
        ("dt", npy_scalar(e.period)),
        ("delay_samples", npy_scalar(f64::from(e.delay))),
        ("speed_hz", npy_scalar(e.plant.speed_hz)),
        ("inputs", names(&e.plant.inputs)),
        ("input_units", units(&e.plant.inputs)),
        ("outputs", names(&e.plant.outputs)),
        ("output_units", units(&e.plant.outputs)),
        ("states", names(&e.plant.states)),
        ("state_units", units(&e.plant.states)),
        ("states_d", names(e.discrete_states)),
        ("state_units_d", units(e.discrete_states)),
        ("format", npy_strings(&[FORMAT])),
    ];
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    // Stored, as numpy's own `savez`; a fixed time so that the same model gives the same bytes.
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Stored)
        .last_modified_time(zip::DateTime::default())
        .unix_permissions(0o644);
    for (name, bytes) in arrays {
        zip.start_file(format!("{name}.npy"), options)?;
        zip.write_all(&bytes)?;
    }
    Ok(zip.finish()?.into_inner())
}

/// The header's descriptive text (116 bytes, space-padded): fixed, so that the same model
/// gives the same bytes (matrw writes the time of writing there).
const MAT_TEXT: &str = "MATLAB 5.0 MAT-file, Platform: GLNXA64, Created by: plant linear";

/// `linear.mat`: MATLAB's level 5 (uncompressed, as scipy's `savemat` writes by default), the
/// same variables as [`npz`]: matrices as they are, numbers as 1 × 1, the names and units as
/// n × 1 cell arrays of text (MATLAB's `InputName` form: `ss(A, B, C, D, 'InputName', inputs)`).
///
/// Through the `matrw` crate (pure Rust: CI has no C library for matio-rs), but not its
/// `save_matfile_v7`: that writes to a path, not through the project's atomic writer, and drops
/// every write error. Its serialisers are called into memory here instead, the bytes read back
/// by its parser and every variable checked there with its size (the serialiser of one
/// variable drops that variable's error as well).
pub fn mat(e: &Export<'_>) -> anyhow::Result<Vec<u8>> {
    use matrw::{CellArray, MatFile, MatVariable, MatlabType, NumericArray};
    use matrw_binrw::BinWrite;
    let matrix = |m: &DMatrix<f64>| -> anyhow::Result<MatVariable> {
        // Column-major, as nalgebra holds it.
        let array = NumericArray::new(vec![m.nrows(), m.ncols()], MatlabType::from(m.as_slice().to_vec()), None)?;
        Ok(MatVariable::NumericArray(array))
    };
    let scalar = |v: f64| matrix(&DMatrix::from_element(1, 1, v));
    let text = |items: Vec<&str>| -> anyhow::Result<MatVariable> {
        let cells = items
            .iter()
            .map(|s| {
                let chars = s.chars().count();
                Ok(MatVariable::NumericArray(NumericArray::new(vec![1, chars], MatlabType::from(*s), None)?))
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        Ok(MatVariable::CellArray(CellArray::new(vec![items.len(), 1], cells)?))
    };
    let names = |v: &[Signal]| text(v.iter().map(|s| s.name.as_str()).collect());
    let units = |v: &[Signal]| text(v.iter().map(|s| s.unit.as_str()).collect());
    let s = &e.plant.system;
    let variables: Vec<(&str, MatVariable)> = vec![
        ("A", matrix(&s.a)?),
        ("B", matrix(&s.b)?),
        ("C", matrix(&s.c)?),
        ("D", matrix(&s.d)?),
        ("Ad", matrix(&e.discrete.a)?),
        ("Bd", matrix(&e.discrete.b)?),
        ("Cd", matrix(&e.discrete.c)?),
        ("Dd", matrix(&e.discrete.d)?),
        ("dt", scalar(e.period)?),
        ("delay_samples", scalar(f64::from(e.delay))?),
        ("speed_hz", scalar(e.plant.speed_hz)?),
        ("inputs", names(&e.plant.inputs)?),
        ("input_units", units(&e.plant.inputs)?),
        ("outputs", names(&e.plant.outputs)?),
        ("output_units", units(&e.plant.outputs)?),
        ("states", names(&e.plant.states)?),
        ("state_units", units(&e.plant.states)?),
        ("states_d", names(e.discrete_states)?),
        ("state_units_d", units(e.discrete_states)?),
        ("format", text(vec![FORMAT])?),
    ];
    let written: Vec<(String, Vec<usize>, Option<Vec<f64>>)> =
        variables.iter().map(|(n, v)| (n.to_string(), v.dim(), v.to_vec::<f64>())).collect();
    let mut file = MatFile::new();
    for (name, v) in variables {
        file.insert(name, v);
    }
    let header = matrw::parser::header::MatFileHeader::new(matrw::parser::header::MatFileVerFlag::V7);
    let endian = matrw_binrw::Endian::Little;
    let header = matrw::parser::header::MatFileHeader { matfile_endian: endian, ..header };
    let mut out = std::io::Cursor::new(Vec::new());
    header.write_options(&mut out, endian, ())?;
    matrw::parser::v7::matfile7::MatFile7::from(file).write_options(&mut out, endian, ())?;
    let mut bytes = out.into_inner();
    anyhow::ensure!(bytes.len() >= 128 && MAT_TEXT.len() <= 116, "the .mat header was not written");
    bytes[..116].copy_from_slice(format!("{MAT_TEXT:<116}").as_bytes());
    let back = matrw::load_matfile_from_u8(&bytes).map_err(|e| anyhow::anyhow!("linear.mat reads back wrong: {e}"))?;
    for (name, dim, values) in written {
        let got = back.iter().find(|(n, _)| **n == name).map(|(_, v)| v);
        let got_dim = got.map(|v| v.dim());
        anyhow::ensure!(
            got_dim.as_ref() == Some(&dim),
            "linear.mat: `{name}` reads back as {got_dim:?}, written {dim:?}"
        );
        // The numbers equal (a matrix of whole numbers is stored as integers, as MATLAB's `save`
        // does: a zero's sign is then not kept).
        if let Some(values) = values {
            let back = got.and_then(|v| v.to_vec::<f64>());
            anyhow::ensure!(back.as_ref() == Some(&values), "linear.mat: `{name}` reads back with other values");
        }
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The header numpy's `format.py` writes for a 2 × 3 float array, byte for byte (its
    /// length padded so that the data starts at 64).
    #[test]
    fn an_npy_header_is_numpys() {
        let m = DMatrix::from_row_slice(2, 3, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        let b = npy_matrix(&m);
        let header = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }";
        assert_eq!(&b[..8], b"\x93NUMPY\x01\x00");
        let len = u16::from_le_bytes([b[8], b[9]]) as usize;
        assert_eq!((10 + len) % 64, 0);
        assert_eq!(&b[10..10 + header.len()], header.as_bytes());
        assert_eq!(b[10 + len - 1], b'\n');
        assert_eq!(b.len(), 10 + len + 48);
        assert_eq!(f64::from_le_bytes(b[10 + len + 8..10 + len + 16].try_into().unwrap()), 2.0);
        let s = npy_strings(&["ab", "c"]);
        let len = u16::from_le_bytes([s[8], s[9]]) as usize;
        assert!(String::from_utf8_lossy(&s[10..10 + len]).contains("'descr': '<U2'"));
        assert_eq!(&s[10 + len..], &[97, 0, 0, 0, 98, 0, 0, 0, 99, 0, 0, 0, 0, 0, 0, 0]);
    }
}
