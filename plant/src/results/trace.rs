//! The recorded time series of a run: one [`Record`] per output sample, kept
//! columnar in memory ([`Trace`]) or streamed to `trace.csv` as it is made
//! ([`TraceWriter`]), and read back strictly ([`read_rows`]).
//!
//! `trace.csv` is a header row with the columns of [`Layout::names`] (the typed rows of
//! [`plant_sim::rows`] name them), then one line per sample, every number in Rust's shortest
//! round-trip scientific notation (`{:e}`: `-4.3e-4`, `0e0`; non-finite values as `NaN`,
//! `inf`, `-inf`), so that a trace read back is bit-identical to the run's samples.

use crate::row_file::RowFile;
pub use plant_sim::rows::{
    plane_values, row, two_bearing_record, two_plane_record, Coils, Columns, Housing, HousingColumns, Layout, Loads,
    LoadsColumns, Magnets, Mid, Motion, MotionColumns, PerPlane, PlaneValues, Record, Row, RowB, RowHw, RowMagnets,
    RowMid, Spin, SpinColumns, Tilt, WIDTH, WIDTH_B, WIDTH_HW, WIDTH_MAGNETS, WIDTH_MID,
};
use std::path::{Path, PathBuf};

/// The samples of a run, in memory: the planar columns (plane A's and the shared ones, the
/// planar model's) kept columnar, one `Vec` per column named like the column; a two-plane
/// run's plane B and tilt, the coils, the magnets and the mid-span as rows, where the run has
/// them.
#[derive(Clone, Debug, Default)]
pub struct Trace {
    /// Time (s).
    pub t_s: Vec<f64>,
    /// The motion at plane A (the planar model's only plane).
    pub motion: MotionColumns,
    /// The rotor's spin.
    pub spin: SpinColumns,
    /// The loads at plane A.
    pub loads: LoadsColumns,
    /// The housing.
    pub housing: HousingColumns,
    /// A two-plane run's plane B and tilt (`None` for the planar model).
    pub b: Option<Vec<RowB>>,
    /// A run with amplifiers: the coils' currents and voltages (`None` without).
    pub hw: Option<Vec<RowHw>>,
    /// A run with unipolar amplifiers: each magnet's current and voltage (`None` without).
    pub magnets: Option<Vec<RowMagnets>>,
    /// A flexible run's rotor at mid-span (`None` for the rigid rotors).
    pub mid: Option<Vec<RowMid>>,
}

impl Trace {
    /// The planar columns' names ([`Row`]'s), in order.
    pub const COLUMNS: &'static [&'static str] = <Row as Columns>::NAMES;

    /// An empty trace with room for `n` rows.
    pub fn with_capacity(n: usize) -> Self {
        Self {
            t_s: Vec::with_capacity(n),
            motion: MotionColumns::with_capacity(n),
            spin: SpinColumns::with_capacity(n),
            loads: LoadsColumns::with_capacity(n),
            housing: HousingColumns::with_capacity(n),
            ..Self::default()
        }
    }

    /// Appends one planar row.
    pub fn push_row(&mut self, r: &Row) {
        self.t_s.push(r.t_s);
        self.motion.push(&r.motion);
        self.spin.push(&r.spin);
        self.loads.push(&r.loads);
        self.housing.push(&r.housing);
    }

    /// Planar row `i`.
    pub fn row(&self, i: usize) -> Row {
        Row {
            t_s: self.t_s[i],
            motion: self.motion.get(i),
            spin: self.spin.get(i),
            loads: self.loads.get(i),
            housing: self.housing.get(i),
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// True when no row was recorded.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// Appends one sample (plane B's and the tilt's columns only with a two-plane sample).
    pub fn push(&mut self, r: &Record) {
        self.push_row(&r.a);
        // The optional columns start with the room the main ones were given: a trace sized for
        // its run never grows inside the run's loop (a realtime tick that doubled 18 columns of
        // a two-plane trace took 1.5-2 ms).
        let room = self.t_s.capacity();
        fn push<R: Copy>(rows: &mut Option<Vec<R>>, r: &Option<R>, room: usize) {
            if let Some(r) = r {
                rows.get_or_insert_with(|| Vec::with_capacity(room)).push(*r);
            }
        }
        push(&mut self.b, &r.b, room);
        push(&mut self.hw, &r.hw, room);
        push(&mut self.magnets, &r.magnets, room);
        push(&mut self.mid, &r.mid, room);
    }

    /// Sample `i`.
    pub fn record(&self, i: usize) -> Record {
        Record {
            a: self.row(i),
            b: self.b.as_ref().map(|b| b[i]),
            hw: self.hw.as_ref().map(|h| h[i]),
            magnets: self.magnets.as_ref().map(|m| m[i]),
            mid: self.mid.as_ref().map(|m| m[i]),
        }
    }

    /// The samples, in order.
    pub fn records(&self) -> impl Iterator<Item = Record> + '_ {
        (0..self.len()).map(|i| self.record(i))
    }

    /// Bearing planes in the trace: 1 (planar) or 2.
    pub fn planes(&self) -> usize {
        1 + usize::from(self.b.is_some())
    }

    /// Plane `i`'s trace in the planar columns ([`Record::plane`]): the planar columns for 0, a
    /// copy of plane B's with the shared ones for 1.
    pub fn plane(&self, i: usize) -> Trace {
        let mut t = Trace::with_capacity(self.len());
        self.records().for_each(|r| t.push_row(&r.plane(i)));
        t
    }

    /// The planar columns' rows (plane A's, for a two-plane trace), in order.
    pub fn rows(&self) -> impl Iterator<Item = Row> + '_ {
        (0..self.len()).map(|i| self.row(i))
    }

    /// Rotor radius relative to the housing at each row (m) (at bearing A, two-plane).
    pub fn radius(&self) -> Vec<f64> {
        self.motion.dx_m.iter().zip(&self.motion.dy_m).map(|(x, y)| x.hypot(*y)).collect()
    }

    /// Writes the trace as `trace.csv` (see the module docs).
    pub fn write_csv(&self, path: &Path) -> std::io::Result<()> {
        let mut w = TraceWriter::with_layout(path, self.layout())?;
        for r in self.records() {
            w.write(&r)?;
        }
        w.flush()
    }

    /// The columns of this trace's `trace.csv`.
    pub fn layout(&self) -> Layout {
        Layout {
            planes: self.planes(),
            coils: self.hw.is_some(),
            magnets: self.magnets.is_some(),
            mid: self.mid.is_some(),
        }
    }

    /// Reads a `trace.csv` strictly (see [`read_rows`]).
    pub fn read_csv(path: &Path) -> Result<Self, TraceError> {
        let mut trace = Trace::default();
        read_rows(path, |r| {
            trace.push(r);
            true
        })?;
        Ok(trace)
    }
}

/// Streams samples to a `trace.csv` as they are made: the header at creation,
/// then one record per sample through the `csv` crate, in whole rows
/// ([`RowFile`]: a run killed by SIGKILL leaves a file that ends on a row, and
/// `plant analyze` reads it). Each number is formatted here with `{:e}` (the
/// csv crate's own float format differs).
pub struct TraceWriter {
    rows: RowFile,
    fields: Vec<String>,
    /// The file's columns.
    layout: Layout,
}

impl TraceWriter {
    /// Creates (truncates) `path` and writes the header of a trace of `planes` bearing planes
    /// (1: the planar columns; 2: also plane B's and the tilt's), with the coils' columns after
    /// them when `amplified`.
    pub fn create(path: &Path, planes: usize, amplified: bool) -> std::io::Result<Self> {
        Self::create_with_magnets(path, planes, amplified, false)
    }

    /// [`TraceWriter::create`], with each magnet's columns after all the others when
    /// `unipolar` (a run with unipolar amplifiers, [`Magnets`]).
    pub fn create_with_magnets(path: &Path, planes: usize, amplified: bool, unipolar: bool) -> std::io::Result<Self> {
        Self::create_with_columns(path, planes, amplified, unipolar, false)
    }

    /// [`TraceWriter::create_with_magnets`], with the rotor's mid-span columns after all the
    /// others when `mid_span` (a flexible run, [`Mid`]).
    pub fn create_with_columns(
        path: &Path,
        planes: usize,
        amplified: bool,
        unipolar: bool,
        mid_span: bool,
    ) -> std::io::Result<Self> {
        Self::with_layout(path, Layout { planes, coils: amplified, magnets: unipolar, mid: mid_span })
    }

    /// Creates (truncates) `path` and writes the header of `layout`'s columns.
    pub fn with_layout(path: &Path, layout: Layout) -> std::io::Result<Self> {
        let header = layout.names();
        let rows = RowFile::create(path, &header)?;
        Ok(Self { fields: vec![String::with_capacity(32); header.len()], rows, layout })
    }

    /// Appends one sample (in memory until a chunk of whole rows is written out); a sample
    /// without some of the trace's columns (plane B's, …) fills them with `NaN`.
    pub fn write(&mut self, r: &Record) -> std::io::Result<()> {
        use std::fmt::Write as _;
        let mut fields = self.fields.iter_mut();
        self.layout.put(r, &mut |v| {
            if let Some(field) = fields.next() {
                field.clear();
                let _ = write!(field, "{v:e}");
            }
        });
        self.rows.row(&self.fields)
    }

    /// Writes the rows gathered so far to the file.
    pub fn flush(&mut self) -> std::io::Result<()> {
        self.rows.flush()
    }
}

/// Why a trace could not be read: the file, and where in it.
#[derive(Debug, thiserror::Error)]
pub enum TraceError {
    /// The file could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Too few rows to analyse.
    #[error("{}: {rows} rows: at least two are needed", path.display())]
    TooShort {
        /// The file.
        path: PathBuf,
        /// Rows read.
        rows: usize,
    },
    /// The file is malformed at a line (and column, where one is to blame).
    #[error("{}: line {line}{}: {what}", path.display(), column.as_ref().map(|c| format!(", column {c}")).unwrap_or_default())]
    Malformed {
        /// The file.
        path: PathBuf,
        /// Line number, from 1 (the header is line 1).
        line: u64,
        /// The column's name, where one is to blame.
        column: Option<String>,
        /// What is wrong.
        what: String,
    },
}

/// The longest line a `trace.csv` may have (bytes): a two-plane row of 40 numbers takes about 1000.
pub const MAX_LINE_BYTES: usize = 64 << 10;

/// Reads `trace.csv` at `path` strictly, passing each sample to `row` in order, while `row`
/// returns `true`; returns whether every row was read.
///
/// The file must be a regular file (a device such as `/dev/zero`, a FIFO or a folder is
/// refused before it is read) and no line may be longer than [`MAX_LINE_BYTES`], so that a
/// file that is not a trace (a link to `/dev/zero`, a sparse file of zeros) is refused at
/// once in bounded memory.
///
/// The header must hold every name of [`Row`]'s columns (other columns are
/// ignored); a two-plane trace also every name of [`RowB`]'s (a header
/// with some but not all of them is refused, naming the first missing). Refused, naming the line and, where one is to blame, the
/// column: a row with more or fewer fields than the header (a ragged row), a
/// field that is not a number (`NaN`, `inf` and `-inf`, which the plant
/// writes for non-finite values, are numbers), a non-finite time, a time
/// that does not increase (running backwards or repeating), and a last line
/// without its line end (a file cut in the middle of a row, whose last field
/// may read as a number it never was).
pub fn read_rows(path: &Path, mut row: impl FnMut(&Record) -> bool) -> Result<bool, TraceError> {
    let io = |source| TraceError::Io { path: path.to_path_buf(), source };
    let bad = |line: u64, column: Option<&str>, what: String| TraceError::Malformed {
        path: path.to_path_buf(),
        line,
        column: column.map(str::to_string),
        what,
    };
    let file = shock_table::input::open_regular(path).map_err(io)?;
    let len = file.metadata().map_err(io)?.len();
    let lines = LineBound { inner: std::io::BufReader::new(file), line: 1, run: 0 };
    let mut reader = csv::ReaderBuilder::new().has_headers(false).flexible(true).from_reader(lines);
    let mut record = csv::ByteRecord::new();
    let csv_err = |e: csv::Error| match e.kind() {
        csv::ErrorKind::Io(_) => match e.into_kind() {
            csv::ErrorKind::Io(source) => TraceError::Io { path: path.to_path_buf(), source },
            _ => unreachable!("matched as Io above"),
        },
        _ => bad(e.position().map_or(0, |p| p.line()), None, e.to_string()),
    };
    if !reader.read_byte_record(&mut record).map_err(csv_err)? {
        return Err(bad(1, None, "empty file: no header".to_string()));
    }
    let header: Vec<String> = record.iter().map(|h| String::from_utf8_lossy(h).trim().to_string()).collect();
    let find = |name: &str| header.iter().position(|h| h == name);
    let mut index = Vec::with_capacity(WIDTH);
    for name in Row::NAMES {
        index.push(find(name).ok_or_else(|| bad(1, Some(name), format!("the header has no column `{name}`")))?);
    }
    // An optional group's columns: all of them or none (`why` says so when some are missing).
    let group = |names: &[&'static str], why: &str| -> Result<Option<Vec<usize>>, TraceError> {
        if !names.iter().any(|name| find(name).is_some()) {
            return Ok(None);
        }
        let mut index = Vec::with_capacity(names.len());
        for name in names {
            index.push(find(name).ok_or_else(|| bad(1, Some(name), format!("the header has {why} but not `{name}`")))?);
        }
        Ok(Some(index))
    };
    let index_b =
        group(RowB::NAMES, "plane B columns").map_err(|e| with_note(e, ": a two-plane trace has all of them"))?;
    let index_mid = group(Mid::NAMES, "mid-span columns").map_err(|e| with_note(e, ": a flexible trace has both"))?;
    let mut previous_t = f64::NEG_INFINITY;
    let mut last_line = 1;
    let mut values = Vec::with_capacity(WIDTH);
    while reader.read_byte_record(&mut record).map_err(csv_err)? {
        let line = record.position().map_or(last_line + 1, |p| p.line());
        last_line = line;
        if record.len() != header.len() {
            return Err(bad(
                line,
                None,
                format!("{} fields where the header has {}: a ragged or cut row", record.len(), header.len()),
            ));
        }
        // The fields at `index` (the columns `names`), parsed into `values`.
        let numbers = |index: &[usize], names: &[&str], values: &mut Vec<f64>| {
            values.clear();
            for (&i, name) in index.iter().zip(names) {
                let field = std::str::from_utf8(&record[i]).unwrap_or("").trim();
                values.push(
                    field.parse::<f64>().map_err(|_| bad(line, Some(name), format!("`{field}` is not a number")))?,
                );
            }
            Ok::<_, TraceError>(())
        };
        numbers(&index, Row::NAMES, &mut values)?;
        let a = Row::from_values(&values);
        let b = match &index_b {
            Some(index_b) => {
                numbers(index_b, RowB::NAMES, &mut values)?;
                Some(RowB::from_values(&values))
            }
            None => None,
        };
        let mid = match &index_mid {
            Some(index_mid) => {
                numbers(index_mid, Mid::NAMES, &mut values)?;
                Some(Mid::from_values(&values))
            }
            None => None,
        };
        let t = a.t_s;
        if !t.is_finite() {
            return Err(bad(line, Some("t_s"), format!("time {t} is not finite")));
        }
        if t <= previous_t {
            let how = if t == previous_t { "repeats" } else { "runs backwards" };
            return Err(bad(line, Some("t_s"), format!("time {how}: {t:e} s after {previous_t:e} s")));
        }
        previous_t = t;
        if !row(&Record { a, b, hw: None, magnets: None, mid }) {
            return Ok(false);
        }
    }
    if len > 0 {
        use std::io::{Read, Seek, SeekFrom};
        let mut file = reader.into_inner().inner.into_inner();
        file.seek(SeekFrom::End(-1)).map_err(io)?;
        let mut last = [0u8; 1];
        file.read_exact(&mut last).map_err(io)?;
        if last[0] != b'\n' {
            return Err(bad(last_line, None, "the last row has no line end: the file was cut".to_string()));
        }
    }
    Ok(true)
}

/// `e` with `note` after what it says is wrong.
fn with_note(e: TraceError, note: &str) -> TraceError {
    match e {
        TraceError::Malformed { path, line, column, what } => {
            TraceError::Malformed { path, line, column, what: format!("{what}{note}") }
        }
        e => e,
    }
}

/// A reader that fails (`InvalidData`, naming the line) as soon as a line grows past
/// [`MAX_LINE_BYTES`]: the csv reader would otherwise gather a line of any length in memory.
struct LineBound<R> {
    inner: R,
    /// The line being read, from 1.
    line: u64,
    /// Bytes of that line read so far.
    run: usize,
}

impl<R: std::io::Read> std::io::Read for LineBound<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        for segment in buf[..n].split_inclusive(|&b| b == b'\n') {
            let ends = segment.last() == Some(&b'\n');
            self.run += segment.len() - usize::from(ends);
            if self.run > MAX_LINE_BYTES {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    format!("line {} is longer than {MAX_LINE_BYTES} bytes: this is not a trace", self.line),
                ));
            }
            if ends {
                self.line += 1;
                self.run = 0;
            }
        }
        Ok(n)
    }
}

/// Scaled error `|Δ − Δ_ref| / r_0` on the common samples of `[t0, t1]`: (RMS, max).
/// A trace that stops early (diverged) counts as infinite error.
pub fn window_error(trace: &Trace, reference: &Trace, t0: f64, t1: f64, gap: f64) -> (f64, f64) {
    let (mut sum, mut max, mut n) = (0.0, 0.0_f64, 0usize);
    for (i, &t) in reference.t_s.iter().enumerate() {
        if t < t0 - 1e-12 || t > t1 + 1e-12 {
            continue;
        }
        let Some(&tt) = trace.t_s.get(i) else { return (f64::INFINITY, f64::INFINITY) };
        if (tt - t).abs() > 1e-9 {
            return (f64::INFINITY, f64::INFINITY);
        }
        let e = (trace.motion.dx_m[i] - reference.motion.dx_m[i])
            .hypot(trace.motion.dy_m[i] - reference.motion.dy_m[i])
            / gap;
        if !e.is_finite() {
            return (f64::INFINITY, f64::INFINITY);
        }
        sum += e * e;
        max = max.max(e);
        n += 1;
    }
    if n == 0 {
        (f64::INFINITY, f64::INFINITY)
    } else {
        ((sum / n as f64).sqrt(), max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trace(t: &[f64], dx: &[f64], dy: &[f64]) -> Trace {
        let mut tr = Trace::default();
        for i in 0..t.len() {
            let mut row = Row { t_s: t[i], ..Row::default() };
            row.motion.dx_m = dx[i];
            row.motion.dy_m = dy[i];
            tr.push_row(&row);
        }
        tr
    }

    #[test]
    fn window_error_is_the_rms_and_max_distance_over_the_window_scaled_by_the_gap() {
        let t = [0.0, 1.0, 2.0, 3.0];
        let reference = trace(&t, &[0.0; 4], &[0.0; 4]);
        // Distances 5 (outside the window), 3, 4 (inside), 100 (outside); gap 2.
        let run = trace(&t, &[3.0, 0.0, 4.0, 100.0], &[4.0, 3.0, 0.0, 0.0]);
        let (rms, max) = window_error(&run, &reference, 1.0, 2.0, 2.0);
        assert_eq!(max, 2.0);
        assert!((rms - (12.5_f64 / 4.0).sqrt()).abs() < 1e-15, "{rms}");
        // A run that stopped before the window's end, or off the reference's grid, is infinitely wrong.
        let short = trace(&t[..2], &[0.0; 2], &[0.0; 2]);
        assert_eq!(window_error(&short, &reference, 1.0, 2.0, 2.0), (f64::INFINITY, f64::INFINITY));
        let shifted = trace(&[0.0, 1.5, 2.0, 3.0], &[0.0; 4], &[0.0; 4]);
        assert_eq!(window_error(&shifted, &reference, 1.0, 2.0, 2.0), (f64::INFINITY, f64::INFINITY));
        // An empty window too.
        assert_eq!(window_error(&run, &reference, 5.0, 6.0, 2.0), (f64::INFINITY, f64::INFINITY));
    }

    fn scratch(name: &str, text: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("plant-trace-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("trace.csv");
        std::fs::write(&path, text).unwrap();
        path
    }

    fn header() -> String {
        Trace::COLUMNS.join(",")
    }

    fn line(t: f64, dy: &str) -> String {
        let mut f: Vec<String> = (0..WIDTH).map(|i| format!("{:e}", i as f64 * 1e-6)).collect();
        f[0] = format!("{t:e}");
        f[2] = dy.to_string();
        f.join(",")
    }

    fn error_of(name: &str, text: &str) -> String {
        let path = scratch(name, text);
        let e = Trace::read_csv(&path).expect_err("should be refused").to_string();
        let _ = std::fs::remove_dir_all(path.parent().unwrap());
        e
    }

    #[test]
    fn written_rows_read_back_bit_identical() {
        let mut tr = Trace::default();
        for i in 0..5 {
            let mut c = 0;
            let mut r = Row::take(&mut || {
                c += 1;
                ((i * WIDTH + c - 1) as f64) * 1.234_567_890_123e-5 - 0.1
            });
            r.t_s = i as f64 * 5e-5;
            r.loads.contact_force_n = if i == 2 { f64::NAN } else { 0.0 };
            tr.push_row(&r);
        }
        let path = scratch("roundtrip", "");
        tr.write_csv(&path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("t_s,dx_m,dy_m,") && text.ends_with('\n'));
        assert!(text.lines().nth(1).unwrap().starts_with("0e0,-9.998765432109878e-2,"), "{text}");
        assert!(text.lines().nth(3).unwrap().contains(",NaN,"), "{text}");
        let back = Trace::read_csv(&path).unwrap();
        for i in 0..5 {
            let (a, b) = (tr.row(i).values(), back.row(i).values());
            assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()), "{a:?} vs {b:?}");
        }
        let _ = std::fs::remove_dir_all(path.parent().unwrap());
    }

    /// Issue 21 item 7: `plant analyze` read `trace.csv` without a bound: a link to
    /// `/dev/zero` grew to 4 GiB and never ended, a 2 GB sparse file peaked at 8 GiB, a FIFO
    /// blocked forever. Each is refused at once now, in bounded memory.
    #[cfg(unix)]
    #[test]
    fn a_device_a_fifo_or_a_line_without_end_is_refused_at_once() {
        let dir = std::env::temp_dir().join(format!("plant-trace-hostile-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let zero = dir.join("zero.csv");
        std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
        let e = Trace::read_csv(&zero).unwrap_err().to_string();
        assert!(e.contains("zero.csv") && e.contains("not a regular file"), "{e}");
        let fifo = dir.join("fifo.csv");
        let name = std::ffi::CString::new(fifo.as_os_str().as_encoded_bytes()).unwrap();
        // SAFETY: mkfifo(3) with a NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o600) }, 0);
        let e = Trace::read_csv(&fifo).unwrap_err().to_string();
        assert!(e.contains("fifo.csv") && e.contains("not a regular file"), "{e}");
        // A sparse file of 2 GB of zeros: one line that never ends.
        let sparse = dir.join("sparse.csv");
        std::fs::File::create(&sparse).unwrap().set_len(2 << 30).unwrap();
        let e = Trace::read_csv(&sparse).unwrap_err().to_string();
        assert!(e.contains("sparse.csv") && e.contains("line 1 is longer than 65536 bytes"), "{e}");
        // The same after a good header and rows: the line is named.
        let mut text = format!("{}\n{}\n", header(), line(0.0, "1e-6"));
        text.push_str(&"7".repeat(MAX_LINE_BYTES + 1));
        let e = error_of("long", &text);
        assert!(e.contains("line 3 is longer"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_row_cut_in_the_middle_of_a_number_is_refused() {
        // The row of the issue: cut inside dy, which alone reads as 1.34 m.
        let text = format!("{}\n{}\n{}", header(), line(0.0, "1e-6"), &line(5e-5, "1.3412e-4")[..30]);
        let e = error_of("cut", &text);
        assert!(e.contains("line 3") && e.contains("ragged or cut"), "{e}");
        // Cut after a whole number of fields but before the line end.
        let full = line(5e-5, "1.3412e-4");
        let text = format!("{}\n{}\n{}", header(), line(0.0, "1e-6"), &full[..full.len() - 3]);
        let e = error_of("cut-last", &text);
        assert!(e.contains("line 3") && e.contains("no line end"), "{e}");
    }

    #[test]
    fn ragged_rows_non_numbers_and_bad_times_name_line_and_column() {
        let ok = |t: f64| line(t, "1e-6");
        let e = error_of("ragged", &format!("{}\n{}\n{},7\n", header(), ok(0.0), ok(1e-4)));
        assert!(e.contains("trace.csv: line 3") && e.contains("20 fields where the header has 19"), "{e}");
        let e = error_of("nan", &format!("{}\n{}\n{}\n", header(), ok(0.0), line(1e-4, "abc")));
        assert!(e.contains("line 3, column dy_m") && e.contains("`abc` is not a number"), "{e}");
        let e = error_of("back", &format!("{}\n{}\n{}\n{}\n", header(), ok(0.0), ok(2e-4), ok(1e-4)));
        assert!(e.contains("line 4, column t_s") && e.contains("runs backwards"), "{e}");
        let e = error_of("repeat", &format!("{}\n{}\n{}\n", header(), ok(1e-4), ok(1e-4)));
        assert!(e.contains("line 3, column t_s") && e.contains("repeats"), "{e}");
        let e = error_of("header", "t_s,dx_m\n0e0,1e0\n");
        assert!(e.contains("line 1, column dy_m") && e.contains("no column `dy_m`"), "{e}");
        let e = error_of("empty", "");
        assert!(e.contains("line 1") && e.contains("empty"), "{e}");
        // NaN is what the plant writes for a non-finite value: read as such.
        let path = scratch("nan-ok", &format!("{}\n{}\n", header(), line(0.0, "NaN")));
        assert!(Trace::read_csv(&path).unwrap().motion.dy_m[0].is_nan());
        let _ = std::fs::remove_dir_all(path.parent().unwrap());
    }
}
