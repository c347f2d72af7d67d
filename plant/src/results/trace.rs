//! The recorded time series of a run: one [`Row`] per output sample, kept
//! columnar in memory ([`Trace`]) or streamed to `trace.csv` as it is made
//! ([`TraceWriter`]), and read back strictly ([`read_rows`]).
//!
//! `trace.csv` is a header row with [`Trace::COLUMNS`], then one line per
//! sample, every number in Rust's shortest round-trip scientific notation
//! (`{:e}`: `-4.3e-4`, `0e0`; non-finite values as `NaN`, `inf`, `-inf`), so
//! that a trace read back is bit-identical to the run's samples.

use crate::row_file::RowFile;
pub use plant_sim::rows::*;
use std::path::{Path, PathBuf};

macro_rules! columns {
    ($(#[$meta:meta])* $name:ident: $row:ty; $($field:ident : $doc:literal),* $(,)?; $($extra:ident : $ety:ty : $edoc:literal),*) => {
        $(#[$meta])*
        #[derive(Clone, Debug, Default)]
        pub struct $name { $(#[doc = $doc] pub $field: Vec<f64>,)* $(#[doc = $edoc] pub $extra: $ety,)* }

        impl $name {
            /// CSV header names, in order.
            pub const COLUMNS: &'static [&'static str] = &[$(stringify!($field)),*];

            /// An empty trace with room for `n` rows.
            pub fn with_capacity(n: usize) -> Self {
                Self { $($field: Vec::with_capacity(n),)* $($extra: Default::default(),)* }
            }

            /// Appends one row of these columns.
            pub fn push_row(&mut self, row: &$row) {
                let mut i = 0;
                $(self.$field.push(row[i]); i += 1;)*
                debug_assert_eq!(i, row.len());
            }

            /// Row `i` of these columns.
            pub fn row(&self, i: usize) -> $row {
                [$(self.$field[i]),*]
            }
        }
    };
}

columns! {
    /// Trace columns (plane A's and the shared ones, the planar model's); each is one CSV
    /// column named like the field. A two-plane run's trace also has plane B's and the tilt's
    /// ([`TraceB`], in `b`).
    Trace: Row;
    t_s: "Time (s).",
    dx_m: "Rotor x relative to the housing (m); two-plane: at bearing A.",
    dy_m: "Rotor y relative to the housing (m); two-plane: at bearing A.",
    vx_m_s: "Rotor x velocity relative to the housing (m/s); two-plane: at bearing A.",
    vy_m_s: "Rotor y velocity relative to the housing (m/s); two-plane: at bearing A.",
    xb_m: "Race x relative to the housing (m); two-plane: race A.",
    yb_m: "Race y relative to the housing (m); two-plane: race A.",
    vxb_m_s: "Race x velocity relative to the housing (m/s); two-plane: race A.",
    vyb_m_s: "Race y velocity relative to the housing (m/s); two-plane: race A.",
    rotor_angle_rad: "Rotor spin angle (rad).",
    rotor_speed_rad_s: "Rotor spin speed (rad/s).",
    race_speed_rad_s: "Race spin speed (rad/s); two-plane: race A.",
    contact_force_n: "Rotor – race normal force (N); two-plane: plane A.",
    friction_force_n: "Rotor – race friction force (N), signed like the slip; two-plane: plane A.",
    ball_force_n: "Resultant of the ball forces on the race (N); two-plane: race A.",
    ix_a: "Coil current, x (A); two-plane: bearing A.",
    iy_a: "Coil current, y (A); two-plane: bearing A.",
    housing_x_m: "Housing displacement, x (m).",
    housing_y_m: "Housing displacement, y (m).";
    b: Option<TraceB>: "A two-plane run's plane B and tilt columns (`None` for the planar model).",
    hw: Option<TraceHw>: "A run with amplifiers: the coils' currents and voltages (`None` without).",
    magnets: Option<TraceMagnets>: "A run with unipolar amplifiers: each magnet's current and voltage (`None` without).",
    mid: Option<TraceMid>: "A flexible run's rotor at mid-span (`None` for the rigid rotors)."
}

columns! {
    /// A flexible run's rotor at mid-span, after all other columns in `trace.csv`: the shaft's
    /// node nearest the middle between its two touchdown-bearing nodes (MODEL.md §13.6), where
    /// the first bending mode's deflection is largest; the rigid rotors have no such columns.
    TraceMid: RowMid;
    mid_dx_m: "Rotor x at mid-span relative to the housing (m), flexible rotor.",
    mid_dy_m: "Rotor y at mid-span relative to the housing (m), flexible rotor.";
}

columns! {
    /// The coils' real currents and voltages of a run with amplifiers (`amb.amplifier`), after
    /// all other columns in `trace.csv` (plane B's four only in a two-plane run). The current
    /// columns `ix_a`, `iy_a` (`b_ix_a`, `b_iy_a`) are then the commanded currents, the
    /// references of the current loops.
    TraceHw: RowHw;
    ix_coil_a: "Coil current, x (A): the real current the force follows; two-plane: bearing A.",
    iy_coil_a: "Coil current, y (A); two-plane: bearing A.",
    vx_coil_v: "Coil voltage, x (V): the amplifier's output; two-plane: bearing A.",
    vy_coil_v: "Coil voltage, y (V); two-plane: bearing A.",
    b_ix_coil_a: "Coil current of bearing B, x (A).",
    b_iy_coil_a: "Coil current of bearing B, y (A).",
    b_vx_coil_v: "Coil voltage of bearing B, x (V).",
    b_vy_coil_v: "Coil voltage of bearing B, y (V).";
}

columns! {
    /// Each magnet's coil current and voltage of a run with unipolar amplifiers
    /// (`amb.amplifier_topology = "unipolar"`, docs/MODEL.md §12.3), after all other columns in
    /// `trace.csv` (plane B's eight only in a two-plane run). `plus` is the magnet on the + side
    /// of the axis (it pulls the rotor toward +x, +y), `minus` the one on the − side. The coil
    /// columns (`ix_coil_a`, `vx_coil_v`, …) are then the differential current `(i₊ − i₋)/2`
    /// and voltage `(v₊ − v₋)/2`: what the bipolar amplifier's coil carries.
    TraceMagnets: RowMagnets;
    ix_plus_a: "Current of the +x magnet's coil (A); two-plane: bearing A.",
    ix_minus_a: "Current of the −x magnet's coil (A); two-plane: bearing A.",
    iy_plus_a: "Current of the +y (upper) magnet's coil (A); two-plane: bearing A.",
    iy_minus_a: "Current of the −y (lower) magnet's coil (A); two-plane: bearing A.",
    vx_plus_v: "Voltage on the +x magnet's coil (V); two-plane: bearing A.",
    vx_minus_v: "Voltage on the −x magnet's coil (V); two-plane: bearing A.",
    vy_plus_v: "Voltage on the +y magnet's coil (V); two-plane: bearing A.",
    vy_minus_v: "Voltage on the −y magnet's coil (V); two-plane: bearing A.",
    b_ix_plus_a: "Current of bearing B's +x magnet's coil (A).",
    b_ix_minus_a: "Current of bearing B's −x magnet's coil (A).",
    b_iy_plus_a: "Current of bearing B's +y magnet's coil (A).",
    b_iy_minus_a: "Current of bearing B's −y magnet's coil (A).",
    b_vx_plus_v: "Voltage on bearing B's +x magnet's coil (V).",
    b_vx_minus_v: "Voltage on bearing B's −x magnet's coil (V).",
    b_vy_plus_v: "Voltage on bearing B's +y magnet's coil (V).",
    b_vy_minus_v: "Voltage on bearing B's −y magnet's coil (V).";
}

columns! {
    /// A two-plane trace's plane B and tilt columns, after the planar ones in `trace.csv`:
    /// plane B's columns are plane A's (the planar names) with the prefix `b_`.
    TraceB: RowB;
    b_dx_m: "Rotor x at bearing B relative to the housing (m).",
    b_dy_m: "Rotor y at bearing B relative to the housing (m).",
    b_vx_m_s: "Rotor x velocity at bearing B (m/s).",
    b_vy_m_s: "Rotor y velocity at bearing B (m/s).",
    b_xb_m: "Race B x relative to the housing (m).",
    b_yb_m: "Race B y relative to the housing (m).",
    b_vxb_m_s: "Race B x velocity (m/s).",
    b_vyb_m_s: "Race B y velocity (m/s).",
    b_race_speed_rad_s: "Race B spin speed (rad/s).",
    b_contact_force_n: "Rotor – race B normal force (N).",
    b_friction_force_n: "Rotor – race B friction force (N), signed like the slip.",
    b_ball_force_n: "Resultant of race B's ball forces (N).",
    b_ix_a: "Coil current of bearing B, x (A).",
    b_iy_a: "Coil current of bearing B, y (A).",
    slope_x_rad: "Slope a = dx/dz of the rotor axis (rad): the tilt about y.",
    slope_y_rad: "Slope b = dy/dz of the rotor axis (rad): minus the tilt about x.",
    slope_x_rate_rad_s: "Rate of the slope a (rad/s).",
    slope_y_rate_rad_s: "Rate of the slope b (rad/s).";
}

impl Trace {
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
        if let Some(b) = &r.b {
            self.b.get_or_insert_with(|| TraceB::with_capacity(room)).push_row(b);
        }
        if let Some(hw) = &r.hw {
            self.hw.get_or_insert_with(|| TraceHw::with_capacity(room)).push_row(hw);
        }
        if let Some(m) = &r.magnets {
            self.magnets.get_or_insert_with(|| TraceMagnets::with_capacity(room)).push_row(m);
        }
        if let Some(m) = &r.mid {
            self.mid.get_or_insert_with(|| TraceMid::with_capacity(room)).push_row(m);
        }
    }

    /// Sample `i`.
    pub fn record(&self, i: usize) -> Record {
        Record {
            a: self.row(i),
            b: self.b.as_ref().map(|b| b.row(i)),
            hw: self.hw.as_ref().map(|h| h.row(i)),
            magnets: self.magnets.as_ref().map(|m| m.row(i)),
            mid: self.mid.as_ref().map(|m| m.row(i)),
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
        self.dx_m.iter().zip(&self.dy_m).map(|(x, y)| x.hypot(*y)).collect()
    }

    /// Writes the trace as `trace.csv` (see the module docs).
    pub fn write_csv(&self, path: &Path) -> std::io::Result<()> {
        let mut w = TraceWriter::create_with_columns(
            path,
            self.planes(),
            self.hw.is_some(),
            self.magnets.is_some(),
            self.mid.is_some(),
        )?;
        for r in self.records() {
            w.write(&r)?;
        }
        w.flush()
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
    /// Plane B columns written (0 or [`WIDTH_B`]).
    b_cols: usize,
    /// Coil columns written (0, or 4 per plane).
    coils: usize,
    /// Magnet columns written (0, or 8 per plane).
    magnets: usize,
    /// Mid-span columns written (0 or [`WIDTH_MID`]).
    mid: usize,
}

impl TraceWriter {
    /// Creates (truncates) `path` and writes the header of a trace of `planes` bearing planes
    /// (1: the planar columns; 2: also plane B's and the tilt's), with the coils' columns after
    /// them when `amplified`.
    pub fn create(path: &Path, planes: usize, amplified: bool) -> std::io::Result<Self> {
        Self::create_with_magnets(path, planes, amplified, false)
    }

    /// [`TraceWriter::create`], with each magnet's columns after all the others when
    /// `unipolar` (a run with unipolar amplifiers, [`TraceMagnets`]).
    pub fn create_with_magnets(path: &Path, planes: usize, amplified: bool, unipolar: bool) -> std::io::Result<Self> {
        Self::create_with_columns(path, planes, amplified, unipolar, false)
    }

    /// [`TraceWriter::create_with_magnets`], with the rotor's mid-span columns after all the
    /// others when `mid_span` (a flexible run, [`TraceMid`]).
    pub fn create_with_columns(
        path: &Path,
        planes: usize,
        amplified: bool,
        unipolar: bool,
        mid_span: bool,
    ) -> std::io::Result<Self> {
        let mid = if mid_span { WIDTH_MID } else { 0 };
        let coils = if amplified { 4 * planes } else { 0 };
        let magnets = if unipolar { 8 * planes } else { 0 };
        let header: Vec<&str> = Trace::COLUMNS
            .iter()
            .chain(if planes == 2 { TraceB::COLUMNS } else { &[] })
            .chain(&TraceHw::COLUMNS[..coils])
            .chain(&TraceMagnets::COLUMNS[..magnets])
            .chain(&TraceMid::COLUMNS[..mid])
            .copied()
            .collect();
        let rows = RowFile::create(path, &header)?;
        Ok(Self {
            fields: vec![String::with_capacity(32); header.len()],
            rows,
            b_cols: if planes == 2 { WIDTH_B } else { 0 },
            coils,
            magnets,
            mid,
        })
    }

    /// Appends one sample (in memory until a chunk of whole rows is written out); a sample
    /// without the trace's plane B columns fills them with `NaN`.
    pub fn write(&mut self, r: &Record) -> std::io::Result<()> {
        use std::fmt::Write as _;
        let b = r.b.unwrap_or([f64::NAN; WIDTH_B]);
        let hw = r.hw.unwrap_or([f64::NAN; WIDTH_HW]);
        let magnets = r.magnets.unwrap_or([f64::NAN; WIDTH_MAGNETS]);
        let mid = r.mid.unwrap_or([f64::NAN; WIDTH_MID]);
        let values =
            r.a.iter()
                .chain(&b[..self.b_cols])
                .chain(&hw[..self.coils])
                .chain(&magnets[..self.magnets])
                .chain(&mid[..self.mid]);
        for (field, v) in self.fields.iter_mut().zip(values) {
            field.clear();
            let _ = write!(field, "{v:e}");
        }
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
/// The header must hold every name of [`Trace::COLUMNS`] (other columns are
/// ignored); a two-plane trace also every name of [`TraceB::COLUMNS`] (a header
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
    let mut index = [0usize; WIDTH];
    for (slot, name) in index.iter_mut().zip(Trace::COLUMNS) {
        *slot = find(name).ok_or_else(|| bad(1, Some(name), format!("the header has no column `{name}`")))?;
    }
    let index_b = if TraceB::COLUMNS.iter().any(|name| find(name).is_some()) {
        let mut index_b = [0usize; WIDTH_B];
        for (slot, name) in index_b.iter_mut().zip(TraceB::COLUMNS) {
            *slot = find(name).ok_or_else(|| {
                bad(
                    1,
                    Some(name),
                    format!("the header has plane B columns but not `{name}`: a two-plane trace has all of them"),
                )
            })?;
        }
        Some(index_b)
    } else {
        None
    };
    // A flexible trace's mid-span columns: both or none.
    let index_mid = if TraceMid::COLUMNS.iter().any(|name| find(name).is_some()) {
        let mut index_mid = [0usize; WIDTH_MID];
        for (slot, name) in index_mid.iter_mut().zip(TraceMid::COLUMNS) {
            *slot = find(name).ok_or_else(|| {
                bad(
                    1,
                    Some(name),
                    format!("the header has mid-span columns but not `{name}`: a flexible trace has both"),
                )
            })?;
        }
        Some(index_mid)
    } else {
        None
    };
    let mut previous_t = f64::NEG_INFINITY;
    let mut last_line = 1;
    let mut values = [0.0; WIDTH];
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
        let number = |i: usize, name: &str| {
            let field = std::str::from_utf8(&record[i]).unwrap_or("").trim();
            field.parse::<f64>().map_err(|_| bad(line, Some(name), format!("`{field}` is not a number")))
        };
        for ((v, &i), name) in values.iter_mut().zip(&index).zip(Trace::COLUMNS) {
            *v = number(i, name)?;
        }
        let b = match &index_b {
            Some(index_b) => {
                let mut b = [0.0; WIDTH_B];
                for ((v, &i), name) in b.iter_mut().zip(index_b).zip(TraceB::COLUMNS) {
                    *v = number(i, name)?;
                }
                Some(b)
            }
            None => None,
        };
        let mid = match &index_mid {
            Some(index_mid) => {
                let mut m = [0.0; WIDTH_MID];
                for ((v, &i), name) in m.iter_mut().zip(index_mid).zip(TraceMid::COLUMNS) {
                    *v = number(i, name)?;
                }
                Some(m)
            }
            None => None,
        };
        let t = values[col::T_S];
        if !t.is_finite() {
            return Err(bad(line, Some("t_s"), format!("time {t} is not finite")));
        }
        if t <= previous_t {
            let how = if t == previous_t { "repeats" } else { "runs backwards" };
            return Err(bad(line, Some("t_s"), format!("time {how}: {t:e} s after {previous_t:e} s")));
        }
        previous_t = t;
        if !row(&Record { a: values, b, hw: None, magnets: None, mid }) {
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
        let e = (trace.dx_m[i] - reference.dx_m[i]).hypot(trace.dy_m[i] - reference.dy_m[i]) / gap;
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
            let mut row = [0.0; crate::trace::WIDTH];
            row[0] = t[i];
            row[1] = dx[i];
            row[2] = dy[i];
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
            let mut r: Row = std::array::from_fn(|c| (i * WIDTH + c) as f64 * 1.234_567_890_123e-5 - 0.1);
            r[col::T_S] = i as f64 * 5e-5;
            r[col::CONTACT_FORCE_N] = if i == 2 { f64::NAN } else { 0.0 };
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
            let (a, b) = (tr.row(i), back.row(i));
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
        assert!(Trace::read_csv(&path).unwrap().dy_m[0].is_nan());
        let _ = std::fs::remove_dir_all(path.parent().unwrap());
    }
}
