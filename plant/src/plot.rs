//! PNG charts of runs and analyses: time traces, orbits, scatter maps and
//! heat maps.
//!
//! Every chart is a PNG with a white background, a grid, a title in 28 px
//! and axis labels in 20 px DejaVu Sans. The font is embedded (the `dejavu`
//! crate) and registered once with plotters' `ab_glyph` renderer under the
//! family name `"sans-serif"`, so no system font is needed.
//!
//! # Drawing long traces
//!
//! A run at 1 MHz for 1.5 s gives 1.5 million samples per channel; drawing
//! them all would be slow and no more informative than the screen allows.
//! * [`lines`] reduces each trace per pixel column of the plotting area:
//!   of the consecutive samples that fall into one column it keeps the
//!   first, the last, the smallest and the largest (at most four), so every
//!   peak and every envelope stays visible.
//! * [`orbit`] keeps every k-th sample beyond [`ORBIT_MAX_POINTS`] samples,
//!   plus the first and the last.
//! * [`scatter`] draws at most one marker per pixel and group.
//! * [`heatmap`] rasterises cells to pixels; where several cells share a
//!   pixel the largest value is shown (peaks stay visible).
//!
//! # Bad data
//!
//! Non-finite samples are skipped and break a line into separate pieces
//! (a gap shows where the data were missing); on a log axis the same holds
//! for values `<= 0`. Input with nothing drawable gives
//! [`PlotError::NoData`]; slices of unequal length give
//! [`PlotError::BadInput`]. No input makes these functions panic.
//!
//! # Legends
//!
//! [`lines`] and [`scatter`] put the legend inside the chart, in the corner
//! that hides the fewest drawn points. [`orbit`] puts it in a row above the
//! chart, because inside it would hide part of a reference circle.
//!
//! # Axis ranges
//!
//! Ranges come from the finite data with a 5 % margin on each side; a
//! constant series gets ±10 % of its value (±1 about zero). A log axis
//! that would hold fewer than two powers of ten is widened outwards to
//! whole decades, so that it always has labelled ticks. Orbits are centred
//! on the housing and reach 5 % beyond the largest of the orbit and the
//! circles.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};

/// Size of the wide charts ([`lines`], [`heatmap`], [`scatter`] with free
/// axes), in pixels.
pub const WIDE_SIZE: (u32, u32) = (1200, 800);
/// Size of the square charts ([`orbit`], [`scatter`] with equal axes), in
/// pixels.
pub const SQUARE_SIZE: (u32, u32) = (900, 900);
/// Orbits with more samples than this are stride-decimated for drawing.
pub const ORBIT_MAX_POINTS: usize = 200_000;

const FONT_FAMILY: &str = "sans-serif";
const TITLE_PX: u32 = 28;
const LABEL_PX: u32 = 20;
const TICK_PX: u32 = 18;
const LEGEND_PX: u32 = 18;
const MAX_TICKS: usize = 10;

/// Fixed line and marker palette (matplotlib's "tab10"), used in order.
const PALETTE: [RGBColor; 10] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0xe3, 0x77, 0xc2),
    RGBColor(0x7f, 0x7f, 0x7f),
    RGBColor(0xbc, 0xbd, 0x22),
    RGBColor(0x17, 0xbe, 0xcf),
];
const GRID_BOLD: RGBColor = RGBColor(0xc8, 0xc8, 0xc8);
const GRID_LIGHT: RGBColor = RGBColor(0xee, 0xee, 0xee);
const CIRCLE_COLOURS: [RGBColor; 3] =
    [RGBColor(0x40, 0x40, 0x40), RGBColor(0x94, 0x67, 0xbd), RGBColor(0x8c, 0x56, 0x4b)];
/// Viridis sampled at nine evenly spaced points, interpolated linearly.
const VIRIDIS: [(u8, u8, u8); 9] = [
    (0x44, 0x01, 0x54),
    (0x47, 0x2d, 0x7b),
    (0x3b, 0x52, 0x8b),
    (0x2c, 0x72, 0x8e),
    (0x21, 0x91, 0x8c),
    (0x28, 0xae, 0x80),
    (0x5e, 0xc9, 0x62),
    (0xad, 0xdc, 0x30),
    (0xfd, 0xe7, 0x25),
];

/// Why a chart could not be written.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// Nothing drawable: empty slices, or only non-finite (or, on a log
    /// axis, non-positive) values.
    #[error("nothing to plot in {path}: {what}")]
    NoData {
        /// The chart that was not written.
        path: PathBuf,
        /// Which input was empty.
        what: String,
    },
    /// Inconsistent input, such as x and y slices of different lengths.
    #[error("invalid input for {path}: {reason}")]
    BadInput {
        /// The chart that was not written.
        path: PathBuf,
        /// What is inconsistent.
        reason: String,
    },
    /// plotters failed to draw or to write the file.
    #[error("drawing {path} failed: {message}")]
    Draw {
        /// The chart that was not written.
        path: PathBuf,
        /// plotters' error, as text.
        message: String,
    },
    /// The embedded DejaVu Sans font could not be registered.
    #[error("could not register the embedded DejaVu Sans font (for {path})")]
    Font {
        /// The chart that was not written.
        path: PathBuf,
    },
}

/// One line on a time or x-y chart.
#[derive(Debug, Clone, Copy)]
pub struct Series<'a> {
    /// Legend text (legend shown when there is more than one series).
    pub label: &'a str,
    /// Abscissae, same length as `y`.
    pub x: &'a [f64],
    /// Ordinates, same length as `x`.
    pub y: &'a [f64],
}

/// Axis scaling.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Linear axis.
    Linear,
    /// Base-10 logarithmic axis; values `<= 0` are not drawn.
    Log10,
}

/// One group of markers on a [`scatter`] chart.
#[derive(Debug, Clone, Copy)]
pub struct PointGroup<'a> {
    /// Legend text (legend shown when there is more than one group).
    pub label: &'a str,
    /// Abscissae, same length as `y`.
    pub x: &'a [f64],
    /// Ordinates, same length as `x`.
    pub y: &'a [f64],
}

/// A reference circle about the housing centre on an [`orbit_with_circles`]
/// chart, such as the touchdown clearance or the AMB air gap.
#[derive(Debug, Clone, Copy)]
pub struct RefCircle<'a> {
    /// Legend text; the radius in µm is appended.
    pub label: &'a str,
    /// Radius in metres; non-finite or non-positive radii are not drawn.
    pub radius_m: f64,
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// Registers DejaVu Sans as `"sans-serif"` with plotters, once per process.
fn ensure_font(path: &Path) -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| register_font(FONT_FAMILY, FontStyle::Normal, dejavu::sans::regular()).is_ok());
    if ok {
        Ok(())
    } else {
        Err(PlotError::Font { path: path.to_path_buf() })
    }
}

fn draw_err<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> PlotError + '_ {
    move |e| PlotError::Draw { path: path.to_path_buf(), message: e.to_string() }
}

fn no_data(path: &Path, what: &str) -> PlotError {
    PlotError::NoData { path: path.to_path_buf(), what: what.to_string() }
}

fn check_lengths(path: &Path, label: &str, x: &[f64], y: &[f64]) -> Result<(), PlotError> {
    if x.len() == y.len() {
        Ok(())
    } else {
        Err(PlotError::BadInput {
            path: path.to_path_buf(),
            reason: format!("\"{label}\" has {} x values but {} y values", x.len(), y.len()),
        })
    }
}

fn font(px: u32) -> TextStyle<'static> {
    (FONT_FAMILY, px).into_font().color(&BLACK)
}

fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Paints the bitmap white and draws the title in a strip at the top;
/// returns the area below the strip.
fn titled_root<'a>(root: &Area<'a>, path: &Path, title: &str) -> Result<Area<'a>, PlotError> {
    const STRIP_PX: u32 = TITLE_PX + 24;
    root.fill(&WHITE).map_err(draw_err(path))?;
    let (strip, rest) = root.split_vertically(STRIP_PX);
    let (w, _) = strip.dim_in_pixel();
    strip
        .draw(&Text::new(
            title,
            (w as i32 / 2, STRIP_PX as i32 / 2 + 2),
            font(TITLE_PX).pos(Pos::new(HPos::Center, VPos::Center)),
        ))
        .map_err(draw_err(path))?;
    Ok(rest)
}

/// The common layout of every chart: margins and label areas. The same
/// builder on the same area always yields the same plotting area.
fn builder<'a, 'b>(area: &'a Area<'b>) -> ChartBuilder<'a, 'b, BitMapBackend<'b>> {
    let mut b = ChartBuilder::on(area);
    b.margin_top(10).margin_bottom(10).margin_left(15).margin_right(35).x_label_area_size(70).y_label_area_size(115);
    b
}

/// Width and height in pixels of the plotting area `builder` gives on `area`.
fn plot_pixels(area: &Area<'_>, path: &Path) -> Result<(usize, usize), PlotError> {
    let probe = builder(area).build_cartesian_2d(0f64..1f64, 0f64..1f64).map_err(draw_err(path))?;
    let (w, h) = probe.plotting_area().dim_in_pixel();
    Ok((w.max(1) as usize, h.max(1) as usize))
}

// ---------------------------------------------------------------------------
// Ranges and tick labels

/// Smallest and largest finite value, if any.
fn finite_bounds(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.filter(|v| v.is_finite()).fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

/// Largest magnitude of a linear axis bound: keeps `hi - lo` finite, which
/// plotters' tick search needs (it loops forever on an infinite span).
const AXIS_LIMIT: f64 = f64::MAX / 4.0;

/// Widens `[lo, hi]` by 5 % on each side; a (nearly) constant range gets
/// ±10 % of its value, or ±1 about zero. Bounds are clamped to
/// ±[`AXIS_LIMIT`].
fn padded(lo: f64, hi: f64) -> (f64, f64) {
    let (lo, hi) = (lo.clamp(-AXIS_LIMIT, AXIS_LIMIT), hi.clamp(-AXIS_LIMIT, AXIS_LIMIT));
    let span = hi - lo;
    let scale = lo.abs().max(hi.abs());
    let (a, b) = if span <= scale * 1e-12 || span <= f64::MIN_POSITIVE {
        let mid = lo + 0.5 * span;
        let half = if mid != 0.0 { 0.1 * mid.abs() } else { 1.0 };
        (mid - half, mid + half)
    } else {
        (lo - 0.05 * span, hi + 0.05 * span)
    };
    (a.max(-AXIS_LIMIT), b.min(AXIS_LIMIT))
}

/// `[lo, hi]` as it is (heat map axes and colour range), clamped to
/// ±[`AXIS_LIMIT`]; padded as by [`padded`] if that leaves it empty.
fn unpadded(lo: f64, hi: f64) -> (f64, f64) {
    let (lo, hi) = (lo.clamp(-AXIS_LIMIT, AXIS_LIMIT), hi.clamp(-AXIS_LIMIT, AXIS_LIMIT));
    if hi > lo {
        (lo, hi)
    } else {
        padded(lo, hi)
    }
}

/// Most decades a log axis shows; smaller values are not drawn.
const MAX_DECADES: f64 = 30.0;

/// Log axis bounds for positive `[lo, hi]`: 5 % of the span in decades on
/// each side; if that holds fewer than two powers of ten (too few to
/// label), rounded outwards to whole decades. Kept within 1e-300..1e300
/// and to at most [`MAX_DECADES`] below the top.
fn log_padded(lo: f64, hi: f64) -> (f64, f64) {
    let (a, b) = (lo.log10().clamp(-299.0, 299.0), hi.log10().clamp(-299.0, 299.0));
    let m = 0.05 * (b - a);
    let (a, b) = (a - m, b + m);
    let (mut a, mut b) = if b.floor() - a.ceil() >= 1.0 {
        (a, b)
    } else {
        let (mut a, mut b) = (a.floor(), b.ceil());
        if b - a < 1.0 {
            a -= 1.0;
            b += 1.0;
        }
        (a, b)
    };
    b = b.min(300.0);
    a = a.max(-300.0).max(b - MAX_DECADES);
    (10f64.powf(a), 10f64.powf(b))
}

/// Scales `(lo, hi)` about its centre to `span`.
fn centred(lo: f64, hi: f64, span: f64) -> (f64, f64) {
    let mid = lo + 0.5 * (hi - lo);
    (mid - 0.5 * span, mid + 0.5 * span)
}

/// Widens the two ranges so that one data unit is the same number of pixels
/// on both axes of a `w`×`h` plotting area.
fn equalise(x: (f64, f64), y: (f64, f64), w: usize, h: usize) -> ((f64, f64), (f64, f64)) {
    let per_px = ((x.1 - x.0) / w as f64).max((y.1 - y.0) / h as f64);
    (centred(x.0, x.1, per_px * w as f64), centred(y.0, y.1, per_px * h as f64))
}

/// The tick step plotters picks on a linear axis: the smallest 1, 2 or 5
/// × 10^k that gives no more than `max_ticks` ticks.
fn tick_step(lo: f64, hi: f64, max_ticks: usize) -> f64 {
    let span = (hi - lo).abs();
    if !(span.is_finite() && span > 0.0) {
        return 1.0;
    }
    let mut decade = 10f64.powf(span.log10().floor() - 1.0);
    loop {
        for m in [1.0, 2.0, 5.0] {
            let step = m * decade;
            if ((span / step).floor() as usize) < max_ticks {
                return step;
            }
        }
        decade *= 10.0;
    }
}

/// Tick label formatter for a linear axis over `[lo, hi]`: fixed-point with
/// just enough decimals for the tick step, or scientific notation for very
/// large or very small magnitudes.
fn linear_ticks(lo: f64, hi: f64) -> impl Fn(&f64) -> String {
    let step = tick_step(lo, hi, MAX_TICKS);
    let step_exp = step.log10().floor() as i32;
    let magnitude = lo.abs().max(hi.abs());
    let scientific = !(1e-3..1e5).contains(&magnitude);
    move |v: &f64| {
        // Snap values within rounding noise of zero to zero.
        if v.abs() < step * 1e-6 {
            return if scientific { "0".to_string() } else { format!("{:.*}", (-step_exp).max(0) as usize, 0.0) };
        }
        if scientific {
            let exp = v.abs().log10().floor() as i32;
            let digits = (exp - step_exp).max(0) as usize;
            format!("{:.*e}", digits, v)
        } else {
            let digits = (-step_exp).max(0) as usize;
            format!("{:.*}", digits, v)
        }
    }
}

/// Tick label formatter for a log axis: plain numbers between 10⁻³ and
/// 10⁵, scientific notation otherwise.
fn log_ticks(v: &f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".to_string()
    } else if (1e-3..1e5).contains(&a) {
        let digits = (-(a.log10().floor() as i32)).max(0) as usize;
        format!("{:.*}", digits, v)
    } else {
        format!("{:.0e}", v)
    }
}

/// Fraction `[0, 1]` of the axis at which a value lies.
#[derive(Clone, Copy)]
struct AxisMap {
    lo: f64,
    hi: f64,
    log: bool,
}

impl AxisMap {
    fn frac(&self, v: f64) -> f64 {
        if self.log {
            (v.log10() - self.lo.log10()) / (self.hi.log10() - self.lo.log10())
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }
}

// ---------------------------------------------------------------------------
// Decimation

/// Reduces a trace to at most four points per pixel column and run.
///
/// The x range `[x_lo, x_hi]` is split into `columns` equal columns. Of
/// each run of consecutive samples in one column the first, smallest,
/// largest and last sample are kept, in their original order. Samples that
/// are non-finite or rejected by `keep` are dropped and end the current
/// piece of line; the result is the list of pieces.
fn decimate_min_max(
    x: &[f64],
    y: &[f64],
    x_lo: f64,
    x_hi: f64,
    columns: usize,
    keep: impl Fn(f64, f64) -> bool,
) -> Vec<Vec<(f64, f64)>> {
    struct Run {
        col: i64,
        first: usize,
        min: usize,
        max: usize,
        last: usize,
    }
    fn flush(run: Option<Run>, x: &[f64], y: &[f64], piece: &mut Vec<(f64, f64)>) {
        if let Some(r) = run {
            let mut idx = [r.first, r.min, r.max, r.last];
            idx.sort_unstable();
            let mut prev = usize::MAX;
            for i in idx {
                if i != prev {
                    piece.push((x[i], y[i]));
                    prev = i;
                }
            }
        }
    }

    let columns = columns.max(1);
    let span = x_hi - x_lo;
    let per_unit = if span > 0.0 { columns as f64 / span } else { 0.0 };
    let max_col = columns as i64 - 1;
    let mut pieces = Vec::new();
    let mut piece = Vec::new();
    let mut run: Option<Run> = None;

    for (i, (&xi, &yi)) in x.iter().zip(y).enumerate() {
        if !xi.is_finite() || !yi.is_finite() || !keep(xi, yi) {
            flush(run.take(), x, y, &mut piece);
            if !piece.is_empty() {
                pieces.push(std::mem::take(&mut piece));
            }
            continue;
        }
        let col = (((xi - x_lo) * per_unit).floor() as i64).clamp(0, max_col);
        match &mut run {
            Some(r) if r.col == col => {
                if yi < y[r.min] {
                    r.min = i;
                }
                if yi > y[r.max] {
                    r.max = i;
                }
                r.last = i;
            }
            _ => {
                flush(run.take(), x, y, &mut piece);
                run = Some(Run { col, first: i, min: i, max: i, last: i });
            }
        }
    }
    flush(run, x, y, &mut piece);
    if !piece.is_empty() {
        pieces.push(piece);
    }
    pieces
}

/// Every `stride`-th index of `0..n` plus the last one, with the stride
/// chosen so that at most about `max_points` indices remain.
fn stride_indices(n: usize, max_points: usize) -> impl Iterator<Item = usize> {
    let stride = if n > max_points { n.div_ceil(max_points.max(1)) } else { 1 };
    let last_extra = n.checked_sub(1).filter(|last| last % stride != 0);
    (0..n).step_by(stride).chain(last_extra)
}

/// Splits an x-y trace, scaled by `scale`, into pieces of finite points
/// (within ±[`AXIS_LIMIT`]), at the given indices.
fn finite_pieces(x: &[f64], y: &[f64], indices: impl Iterator<Item = usize>, scale: f64) -> Vec<Vec<(f64, f64)>> {
    let mut pieces = Vec::new();
    let mut piece = Vec::new();
    for i in indices {
        let (xi, yi) = (x[i] * scale, y[i] * scale);
        if xi.abs() <= AXIS_LIMIT && yi.abs() <= AXIS_LIMIT {
            piece.push((xi, yi));
        } else if !piece.is_empty() {
            pieces.push(std::mem::take(&mut piece));
        }
    }
    if !piece.is_empty() {
        pieces.push(piece);
    }
    pieces
}

// ---------------------------------------------------------------------------
// Legends

/// The corner whose legend box would cover the fewest points.
///
/// `points` are axis fractions in `[0, 1]` (y up); `box_frac` is the legend
/// size as fractions of the plotting area.
fn quiet_corner<'p>(
    points: impl Iterator<Item = (f64, f64)> + Clone + 'p,
    box_frac: (f64, f64),
) -> SeriesLabelPosition {
    let (bw, bh) = (box_frac.0 + 0.02, box_frac.1 + 0.02);
    let corners = [
        (SeriesLabelPosition::UpperRight, 1.0 - bw, 1.0, 1.0 - bh, 1.0),
        (SeriesLabelPosition::UpperLeft, 0.0, bw, 1.0 - bh, 1.0),
        (SeriesLabelPosition::LowerRight, 1.0 - bw, 1.0, 0.0, bh),
        (SeriesLabelPosition::LowerLeft, 0.0, bw, 0.0, bh),
    ];
    let mut best = (usize::MAX, SeriesLabelPosition::UpperRight);
    for (pos, x0, x1, y0, y1) in corners {
        let n = points.clone().filter(|&(fx, fy)| fx >= x0 && fx <= x1 && fy >= y0 && fy <= y1).count();
        if n < best.0 {
            best = (n, pos);
        }
    }
    best.1
}

/// Estimated legend box size in pixels for the given entries.
fn legend_size(area: &Area<'_>, labels: &[String]) -> (f64, f64) {
    let style = font(LEGEND_PX);
    let w = labels.iter().filter_map(|l| area.estimate_text_size(l, &style).ok()).map(|(w, _)| w).max().unwrap_or(0);
    // Text plus plotters' legend area (30 px) and margins (2 × 10 px);
    // lines are about 1.2 font heights apart.
    (f64::from(w) + 50.0, labels.len() as f64 * f64::from(LEGEND_PX) * 1.25 + 20.0)
}

fn draw_legend<'a, CT>(
    chart: &mut ChartContext<'a, BitMapBackend<'a>, CT>,
    pos: SeriesLabelPosition,
    path: &Path,
) -> Result<(), PlotError>
where
    CT: plotters::coord::CoordTranslate,
{
    chart
        .configure_series_labels()
        .position(pos)
        .margin(10)
        .legend_area_size(30)
        .label_font(font(LEGEND_PX))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.5))
        .draw()
        .map_err(draw_err(path))
}

fn draw_mesh<'a, X, Y>(
    chart: &mut ChartContext<'a, BitMapBackend<'a>, Cartesian2d<X, Y>>,
    x_label: &str,
    y_label: &str,
    x_fmt: &dyn Fn(&f64) -> String,
    y_fmt: &dyn Fn(&f64) -> String,
    path: &Path,
) -> Result<(), PlotError>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_labels(MAX_TICKS)
        .y_labels(MAX_TICKS)
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(x_fmt)
        .y_label_formatter(y_fmt)
        .label_style(font(TICK_PX))
        .axis_desc_style(font(LABEL_PX))
        .bold_line_style(GRID_BOLD)
        .light_line_style(GRID_LIGHT)
        .axis_style(BLACK)
        .set_all_tick_mark_size(6)
        .draw()
        .map_err(draw_err(path))
}

/// Writes the finished bitmap to its file.
fn finish(root: &Area<'_>, path: &Path) -> Result<(), PlotError> {
    root.present().map_err(draw_err(path))
}

// ---------------------------------------------------------------------------
// lines

/// Draws lines against a shared x axis (radius vs time, race speed vs time,
/// coil currents, …) into a 1200×800 PNG at `path`.
///
/// Each series is reduced to at most four points per pixel column (first,
/// min, max, last), so peaks survive on traces of millions of samples.
/// Non-finite samples, and on a [`Scale::Log10`] y axis samples `<= 0`,
/// are skipped and leave a gap. A legend is drawn when there is more than
/// one series, in the corner that hides the fewest points.
///
/// # Errors
/// [`PlotError::NoData`] if no series has a drawable point,
/// [`PlotError::BadInput`] if a series' x and y differ in length,
/// [`PlotError::Draw`] if plotters cannot draw or write the file.
///
/// ```no_run
/// use plant::plot::{lines, Scale, Series};
/// let t: Vec<f64> = (0..1000).map(|i| i as f64 * 1e-3).collect();
/// let r: Vec<f64> = t.iter().map(|t| 50.0 * (1.0 - (-t / 0.2).exp())).collect();
/// let s = [Series { label: "radius", x: &t, y: &r }];
/// lines("radius.png".as_ref(), "Rotor radius", "time (s)", "radius (µm)", &s, Scale::Linear)?;
/// # Ok::<(), plant::plot::PlotError>(())
/// ```
pub fn lines(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    y_scale: Scale,
) -> Result<(), PlotError> {
    for s in series {
        check_lengths(path, s.label, s.x, s.y)?;
    }
    let log = y_scale == Scale::Log10;
    let keep_y = move |v: f64| !log || v > 0.0;

    // Bounds over points that are drawable in both coordinates.
    let mut xb: Option<(f64, f64)> = None;
    let mut yb: Option<(f64, f64)> = None;
    for s in series {
        for (&x, &y) in s.x.iter().zip(s.y) {
            if x.is_finite() && y.is_finite() && keep_y(y) {
                xb = Some(xb.map_or((x, x), |(lo, hi)| (lo.min(x), hi.max(x))));
                yb = Some(yb.map_or((y, y), |(lo, hi)| (lo.min(y), hi.max(y))));
            }
        }
    }
    let (Some((x0, x1)), Some((y0, y1))) = (xb, yb) else {
        let what = if log { "no finite positive sample in any series" } else { "no finite sample in any series" };
        return Err(no_data(path, what));
    };
    let x_range = padded(x0, x1);
    let y_range = if log { log_padded(y0, y1) } else { padded(y0, y1) };

    ensure_font(path)?;
    let root = BitMapBackend::new(path, WIDE_SIZE).into_drawing_area();
    let area = titled_root(&root, path, title)?;
    let (pw, ph) = plot_pixels(&area, path)?;

    // Only points inside the axes are drawn (plotters does not clip to the
    // plotting area); this matters only for values beyond ±AXIS_LIMIT or
    // more than MAX_DECADES below the top of a log axis.
    let inside =
        |x: f64, y: f64| (x_range.0..=x_range.1).contains(&x) && (y_range.0..=y_range.1).contains(&y) && keep_y(y);
    let pieces: Vec<Vec<Vec<(f64, f64)>>> =
        series.iter().map(|s| decimate_min_max(s.x, s.y, x_range.0, x_range.1, pw, inside)).collect();

    let labels: Vec<String> = series.iter().map(|s| s.label.to_string()).collect();
    let legend_pos = if series.len() > 1 {
        let (lw, lh) = legend_size(&area, &labels);
        let xm = AxisMap { lo: x_range.0, hi: x_range.1, log: false };
        let ym = AxisMap { lo: y_range.0, hi: y_range.1, log };
        let pts = pieces.iter().flatten().flatten().map(move |&(x, y)| (xm.frac(x), ym.frac(y)));
        Some(quiet_corner(pts, (lw / pw as f64, lh / ph as f64)))
    } else {
        None
    };

    let x_fmt = linear_ticks(x_range.0, x_range.1);
    if log {
        let y_coord: LogCoord<f64> = (y_range.0..y_range.1).log_scale().into();
        let mut chart = builder(&area).build_cartesian_2d(x_range.0..x_range.1, y_coord).map_err(draw_err(path))?;
        draw_mesh(&mut chart, x_label, y_label, &x_fmt, &log_ticks, path)?;
        draw_pieces(&mut chart, &pieces, &labels, legend_pos, path)?;
    } else {
        let y_fmt = linear_ticks(y_range.0, y_range.1);
        let mut chart =
            builder(&area).build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1).map_err(draw_err(path))?;
        draw_mesh(&mut chart, x_label, y_label, &x_fmt, &y_fmt, path)?;
        draw_pieces(&mut chart, &pieces, &labels, legend_pos, path)?;
    }
    finish(&root, path)
}

fn draw_pieces<'a, Y>(
    chart: &mut ChartContext<'a, BitMapBackend<'a>, Cartesian2d<RangedCoordf64, Y>>,
    pieces: &[Vec<Vec<(f64, f64)>>],
    labels: &[String],
    legend_pos: Option<SeriesLabelPosition>,
    path: &Path,
) -> Result<(), PlotError>
where
    Y: Ranged<ValueType = f64>,
{
    for (i, (series_pieces, label)) in pieces.iter().zip(labels).enumerate() {
        let c = colour(i);
        let style = c.stroke_width(2);
        // An isolated sample between gaps is shown as a dot.
        chart
            .draw_series(series_pieces.iter().filter(|p| p.len() == 1).map(|p| Circle::new(p[0], 2, c.filled())))
            .map_err(draw_err(path))?;
        // Drawn segment by segment: plotters joins the segments of a wide
        // path with unlimited mitres, which throws long spikes off the
        // sharp turns of a dense, decimated trace.
        let anno = chart
            .draw_series(
                series_pieces.iter().flat_map(|p| p.windows(2)).map(|w| PathElement::new(vec![w[0], w[1]], style)),
            )
            .map_err(draw_err(path))?;
        anno.label(label.as_str()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(3)));
    }
    if let Some(pos) = legend_pos {
        draw_legend(chart, pos, path)?;
    }
    Ok(())
}

// ---------------------------------------------------------------------------
// orbit

/// Draws a rotor orbit relative to the housing, in µm, with the clearance
/// circle of radius `clearance_m`, into a 900×900 PNG at `path`.
///
/// Inputs are in metres. The axes are centred on the housing and scaled
/// equally, so a circle looks round. The start and end points are marked.
/// Orbits of more than [`ORBIT_MAX_POINTS`] samples are stride-decimated
/// (first and last sample kept). See [`orbit_with_circles`] for more than
/// one reference circle.
///
/// # Errors
/// As [`orbit_with_circles`].
pub fn orbit(path: &Path, title: &str, x_m: &[f64], y_m: &[f64], clearance_m: f64) -> Result<(), PlotError> {
    orbit_with_circles(path, title, x_m, y_m, &[RefCircle { label: "clearance", radius_m: clearance_m }])
}

/// Draws a rotor orbit like [`orbit`], with any number of dashed reference
/// circles about the housing centre (the first dark grey, the next in
/// other colours), each labelled with its radius in µm.
///
/// # Errors
/// [`PlotError::NoData`] if no sample is finite, [`PlotError::BadInput`]
/// if `x_m` and `y_m` differ in length, [`PlotError::Draw`] if plotters
/// cannot draw or write the file.
pub fn orbit_with_circles(
    path: &Path,
    title: &str,
    x_m: &[f64],
    y_m: &[f64],
    circles: &[RefCircle],
) -> Result<(), PlotError> {
    const UM: f64 = 1e6;
    check_lengths(path, "orbit", x_m, y_m)?;
    let pieces = finite_pieces(x_m, y_m, stride_indices(x_m.len(), ORBIT_MAX_POINTS), UM);
    // First and last finite samples, searched on the full data so that
    // decimation cannot move them.
    let finite = |i: &usize| x_m[*i].is_finite() && y_m[*i].is_finite();
    let (Some(first), Some(last)) = ((0..x_m.len()).find(finite), (0..x_m.len()).rev().find(finite)) else {
        return Err(no_data(path, "no finite orbit sample"));
    };
    let start = (x_m[first] * UM, y_m[first] * UM);
    let end = (x_m[last] * UM, y_m[last] * UM);

    let circles: Vec<(String, f64)> = circles
        .iter()
        .filter(|c| c.radius_m > 0.0 && c.radius_m * UM <= AXIS_LIMIT)
        .map(|c| {
            let r = c.radius_m * UM;
            (format!("{} ({} µm)", c.label, short_number(r)), r)
        })
        .collect();

    let mut reach = circles.iter().map(|c| c.1).fold(0.0, f64::max);
    for p in pieces.iter().flatten() {
        reach = reach.max(p.0.abs()).max(p.1.abs());
    }
    if !(reach.is_finite() && reach > 0.0) {
        reach = 1.0;
    }
    let half = 1.05 * reach;

    let line = colour(0);
    let (green, red) = (colour(2), colour(3));
    let mut entries: Vec<(String, Mark)> =
        circles.iter().enumerate().map(|(i, c)| (c.0.clone(), Mark::Dashed(circle_colour(i)))).collect();
    entries.push(("orbit".into(), Mark::Line(line)));
    entries.push(("start".into(), Mark::Dot(green)));
    entries.push(("end".into(), Mark::Square(red)));

    ensure_font(path)?;
    let root = BitMapBackend::new(path, SQUARE_SIZE).into_drawing_area();
    let area = titled_root(&root, path, title)?;
    // The legend goes in a strip above the chart: inside, it would hide
    // part of a circle in any corner.
    let area = legend_strip(&area, &entries, path)?;
    let (pw, ph) = plot_pixels(&area, path)?;
    let (xr, yr) = equalise((-half, half), (-half, half), pw, ph);
    let um_per_px = (xr.1 - xr.0) / pw as f64;

    let mut chart = builder(&area).build_cartesian_2d(xr.0..xr.1, yr.0..yr.1).map_err(draw_err(path))?;
    let (x_fmt, y_fmt) = (linear_ticks(xr.0, xr.1), linear_ticks(yr.0, yr.1));
    draw_mesh(&mut chart, "x (µm)", "y (µm)", &x_fmt, &y_fmt, path)?;

    chart
        .draw_series(pieces.iter().filter(|p| p.len() > 1).map(|p| PathElement::new(p.clone(), line.stroke_width(1))))
        .map_err(draw_err(path))?;
    // Reference circles on top of the orbit, so that they stay visible
    // where the rotor runs along them.
    for (i, (_, r)) in circles.iter().enumerate() {
        let style = circle_colour(i).stroke_width(2);
        chart
            .draw_series(dashed_circle(*r, um_per_px).into_iter().map(|d| PathElement::new(d, style)))
            .map_err(draw_err(path))?;
    }
    let on_chart = |p: &(f64, f64)| (xr.0..=xr.1).contains(&p.0) && (yr.0..=yr.1).contains(&p.1);
    chart
        .draw_series(std::iter::once(start).filter(on_chart).map(|p| Circle::new(p, 7, green.filled())))
        .map_err(draw_err(path))?;
    chart
        .draw_series(
            std::iter::once(end)
                .filter(on_chart)
                .map(|p| EmptyElement::at(p) + Rectangle::new([(-6, -6), (6, 6)], red.filled())),
        )
        .map_err(draw_err(path))?;
    finish(&root, path)
}

fn circle_colour(i: usize) -> RGBColor {
    CIRCLE_COLOURS[i % CIRCLE_COLOURS.len()]
}

/// Arcs of a dashed circle of radius `r` about the origin: dashes of
/// about 12 px with 6 px gaps at `per_px` data units per pixel.
fn dashed_circle(r: f64, per_px: f64) -> Vec<Vec<(f64, f64)>> {
    let circumference_px = std::f64::consts::TAU * r / per_px;
    let dashes = ((circumference_px / 18.0).round() as usize).clamp(8, 2000);
    let period = std::f64::consts::TAU / dashes as f64;
    (0..dashes)
        .map(|k| {
            let a0 = k as f64 * period;
            (0..=6)
                .map(|j| {
                    let a = a0 + period * (12.0 / 18.0) * f64::from(j) / 6.0;
                    (r * a.cos(), r * a.sin())
                })
                .collect()
        })
        .collect()
}

/// A legend symbol.
#[derive(Clone, Copy)]
enum Mark {
    Line(RGBColor),
    Dashed(RGBColor),
    Dot(RGBColor),
    Square(RGBColor),
}

/// Draws a legend in centred rows (wrapped to the width) at the top of
/// `area`, and
/// returns the area below it.
fn legend_strip<'a>(area: &Area<'a>, entries: &[(String, Mark)], path: &Path) -> Result<Area<'a>, PlotError> {
    const MARK_W: i32 = 28;
    const GAP: i32 = 28;
    const ROW_H: i32 = 28;
    let style = font(LEGEND_PX);
    let (w, _) = area.dim_in_pixel();
    let max_w = w as i32 - 40;
    // Lay the entries out in rows.
    let mut rows: Vec<Vec<(usize, i32)>> = vec![Vec::new()];
    let mut row_w = 0;
    for (i, (label, _)) in entries.iter().enumerate() {
        let text_w = area.estimate_text_size(label, &style).map_err(draw_err(path))?.0 as i32;
        let entry_w = MARK_W + 8 + text_w;
        let row = rows.last_mut().expect("rows is never empty");
        if !row.is_empty() && row_w + GAP + entry_w > max_w {
            rows.push(vec![(i, entry_w)]);
            row_w = entry_w;
        } else {
            row_w += if row.is_empty() { 0 } else { GAP } + entry_w;
            row.push((i, entry_w));
        }
    }
    let height = rows.len() as i32 * ROW_H + 8;
    let (strip, rest) = area.split_vertically(height);
    for (r, row) in rows.iter().enumerate() {
        let total: i32 = row.iter().map(|e| e.1).sum::<i32>() + GAP * (row.len() as i32 - 1);
        let mut x = (w as i32 - total) / 2;
        let y = r as i32 * ROW_H + ROW_H / 2 + 2;
        for &(i, entry_w) in row {
            let (label, mark) = &entries[i];
            draw_mark(&strip, *mark, (x, y), MARK_W).map_err(draw_err(path))?;
            strip
                .draw(&Text::new(label.as_str(), (x + MARK_W + 8, y), style.pos(Pos::new(HPos::Left, VPos::Center))))
                .map_err(draw_err(path))?;
            x += entry_w + GAP;
        }
    }
    Ok(rest)
}

fn draw_mark(
    area: &Area<'_>,
    mark: Mark,
    (x, y): (i32, i32),
    w: i32,
) -> Result<(), DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>> {
    let mid = x + w / 2;
    match mark {
        Mark::Line(c) => area.draw(&PathElement::new(vec![(x, y), (x + w, y)], c.stroke_width(3))),
        Mark::Dashed(c) => {
            area.draw(&PathElement::new(vec![(x, y), (x + 10, y)], c.stroke_width(2)))?;
            area.draw(&PathElement::new(vec![(x + 16, y), (x + w, y)], c.stroke_width(2)))
        }
        Mark::Dot(c) => area.draw(&Circle::new((mid, y), 7, c.filled())),
        Mark::Square(c) => area.draw(&Rectangle::new([(mid - 6, y - 6), (mid + 6, y + 6)], c.filled())),
    }
}

/// A number with at most four significant digits and no trailing zeros.
fn short_number(v: f64) -> String {
    let s = format!("{:.4}", v);
    let digits = if v.abs() >= 1.0 { (3 - v.abs().log10().floor() as i32).max(0) as usize } else { 4 };
    let s = if digits < 4 { format!("{:.*}", digits, v) } else { s };
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

// ---------------------------------------------------------------------------
// scatter

/// Draws groups of markers (Poincaré maps, bifurcation diagrams) in
/// distinct colours into a PNG at `path`: 900×900 with equally scaled axes
/// when `equal_axes`, else 1200×800.
///
/// Each group draws at most one marker per pixel, so maps of millions of
/// points stay fast. Non-finite points are skipped. A legend is drawn when
/// there is more than one group.
///
/// # Errors
/// [`PlotError::NoData`] if no point is finite, [`PlotError::BadInput`] if
/// a group's x and y differ in length, [`PlotError::Draw`] if plotters
/// cannot draw or write the file.
pub fn scatter(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    groups: &[PointGroup],
    equal_axes: bool,
) -> Result<(), PlotError> {
    for g in groups {
        check_lengths(path, g.label, g.x, g.y)?;
    }
    let finite_points =
        || groups.iter().flat_map(|g| g.x.iter().zip(g.y).filter(|(x, y)| x.is_finite() && y.is_finite()));
    let (Some(xb), Some(yb)) =
        (finite_bounds(finite_points().map(|p| *p.0)), finite_bounds(finite_points().map(|p| *p.1)))
    else {
        return Err(no_data(path, "no finite point in any group"));
    };

    ensure_font(path)?;
    let size = if equal_axes { SQUARE_SIZE } else { WIDE_SIZE };
    let root = BitMapBackend::new(path, size).into_drawing_area();
    let area = titled_root(&root, path, title)?;
    let (pw, ph) = plot_pixels(&area, path)?;
    let (mut xr, mut yr) = (padded(xb.0, xb.1), padded(yb.0, yb.1));
    if equal_axes {
        // Both axes get the larger padded span, then the plotting area's
        // aspect ratio, so that one unit is as long on both.
        let s = (xr.1 - xr.0).max(yr.1 - yr.0);
        (xr, yr) = equalise(centred(xr.0, xr.1, s), centred(yr.0, yr.1, s), pw, ph);
    }

    let mut chart = builder(&area).build_cartesian_2d(xr.0..xr.1, yr.0..yr.1).map_err(draw_err(path))?;
    let (x_fmt, y_fmt) = (linear_ticks(xr.0, xr.1), linear_ticks(yr.0, yr.1));
    draw_mesh(&mut chart, x_label, y_label, &x_fmt, &y_fmt, path)?;

    let xm = AxisMap { lo: xr.0, hi: xr.1, log: false };
    let ym = AxisMap { lo: yr.0, hi: yr.1, log: false };
    let mut occupied = vec![false; pw * ph];
    let mut kept_all: Vec<(f64, f64)> = Vec::new();
    // Marker size: smaller as the map gets denser.
    let radius = match groups.iter().map(|g| g.x.len()).sum::<usize>() {
        0..=2_000 => 3,
        2_001..=20_000 => 2,
        _ => 1,
    };
    for (i, g) in groups.iter().enumerate() {
        occupied.iter_mut().for_each(|o| *o = false);
        let mut kept = Vec::new();
        for (&x, &y) in g.x.iter().zip(g.y) {
            let (fx, fy) = (xm.frac(x), ym.frac(y));
            // Also skips the non-finite, and anything beyond ±AXIS_LIMIT.
            if !((0.0..=1.0).contains(&fx) && (0.0..=1.0).contains(&fy)) {
                continue;
            }
            let px = ((fx * pw as f64) as usize).min(pw - 1);
            let py = ((fy * ph as f64) as usize).min(ph - 1);
            let cell = &mut occupied[py * pw + px];
            if !*cell {
                *cell = true;
                kept.push((x, y));
            }
        }
        let c = colour(i);
        chart
            .draw_series(kept.iter().map(|&p| Circle::new(p, radius, c.filled())))
            .map_err(draw_err(path))?
            .label(g.label)
            .legend(move |(x, y)| Circle::new((x + 12, y), 5, c.filled()));
        kept_all.extend(kept.iter().map(|&(x, y)| (xm.frac(x), ym.frac(y))));
    }
    if groups.len() > 1 {
        let labels: Vec<String> = groups.iter().map(|g| g.label.to_string()).collect();
        let (lw, lh) = legend_size(&area, &labels);
        let pos = quiet_corner(kept_all.iter().copied(), (lw / pw as f64, lh / ph as f64));
        draw_legend(&mut chart, pos, path)?;
    }
    finish(&root, path)
}

// ---------------------------------------------------------------------------
// heatmap

/// Viridis colour for `t` in `[0, 1]` (clamped).
fn viridis(t: f64) -> RGBColor {
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let s = t * (VIRIDIS.len() - 1) as f64;
    let i = (s.floor() as usize).min(VIRIDIS.len() - 2);
    let f = s - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |p: u8, q: u8| (f64::from(p) + f * (f64::from(q) - f64::from(p))).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Cell edges for grid centres `c`: midpoints between neighbours, with
/// the outer cells as wide as their neighbour. A single centre gets a unit
/// wide cell.
fn cell_edges(c: &[f64]) -> Vec<f64> {
    match c.len() {
        0 => Vec::new(),
        1 => vec![c[0] - 0.5, c[0] + 0.5],
        n => {
            let mut e = Vec::with_capacity(n + 1);
            e.push(c[0] - 0.5 * (c[1] - c[0]));
            e.extend(c.windows(2).map(|w| 0.5 * (w[0] + w[1])));
            e.push(c[n - 1] + 0.5 * (c[n - 1] - c[n - 2]));
            e
        }
    }
}

/// Draws a heat map of `z[row][col]` on the grid `x` (columns) × `y`
/// (rows), with a viridis colour bar labelled `z_label`, into a 1200×800
/// PNG at `path`.
///
/// Values are coloured as given: for a spectrogram in dB, convert before
/// calling (e.g. with [`to_db`]) and say so in `z_label`. The colour range
/// is the finite range of `z`; non-finite cells are left white. `x` and
/// `y` are cell centres, monotonic (regular grids expected); cells smaller
/// than a pixel are max-pooled so that narrow peaks stay visible.
///
/// # Errors
/// [`PlotError::NoData`] if the grid is empty or no value is finite,
/// [`PlotError::BadInput`] if `z` does not have `y.len()` rows of
/// `x.len()` values or a grid axis is not finite, [`PlotError::Draw`] if
/// plotters cannot draw or write the file.
#[allow(clippy::too_many_arguments)] // the agreed API: one call per chart
pub fn heatmap(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    x: &[f64],
    y: &[f64],
    z: &[Vec<f64>],
    z_label: &str,
) -> Result<(), PlotError> {
    let bad = |reason: String| PlotError::BadInput { path: path.to_path_buf(), reason };
    if x.is_empty() || y.is_empty() || z.is_empty() {
        return Err(no_data(path, "empty grid"));
    }
    if z.len() != y.len() {
        return Err(bad(format!("z has {} rows but y has {} values", z.len(), y.len())));
    }
    if let Some((r, row)) = z.iter().enumerate().find(|(_, row)| row.len() != x.len()) {
        return Err(bad(format!("z row {r} has {} values but x has {}", row.len(), x.len())));
    }
    if !x.iter().chain(y).all(|v| v.is_finite()) {
        return Err(bad("x and y must be finite".to_string()));
    }
    let Some((z0, z1)) = finite_bounds(z.iter().flatten().copied()) else {
        return Err(no_data(path, "no finite z value"));
    };
    let (z0, z1) = unpadded(z0, z1);

    let (xe, ye) = (cell_edges(x), cell_edges(y));
    let xb = finite_bounds(xe.iter().copied()).unwrap_or((0.0, 1.0));
    let yb = finite_bounds(ye.iter().copied()).unwrap_or((0.0, 1.0));
    let (xr, yr) = (unpadded(xb.0, xb.1), unpadded(yb.0, yb.1));

    ensure_font(path)?;
    let root = BitMapBackend::new(path, WIDE_SIZE).into_drawing_area();
    let area = titled_root(&root, path, title)?;
    let (main, bar) = area.split_horizontally(WIDE_SIZE.0 - 170);
    let (pw, ph) = plot_pixels(&main, path)?;

    let mut chart = builder(&main).build_cartesian_2d(xr.0..xr.1, yr.0..yr.1).map_err(draw_err(path))?;

    // Rasterise: each pixel shows the largest value of the cells it touches.
    let mut pixels = vec![f64::NAN; pw * ph];
    let to_px = |v: f64, lo: f64, hi: f64, n: usize| (v - lo) / (hi - lo) * n as f64;
    let px_span = |a: f64, b: f64, lo: f64, hi: f64, n: usize| {
        let (p, q) = (to_px(a.min(b), lo, hi, n), to_px(a.max(b), lo, hi, n));
        let p0 = (p.floor().max(0.0) as usize).min(n - 1);
        let p1 = (q.ceil() as usize).clamp(p0 + 1, n);
        p0..p1
    };
    let cols: Vec<Range<usize>> = (0..x.len()).map(|c| px_span(xe[c], xe[c + 1], xr.0, xr.1, pw)).collect();
    for (r, row) in z.iter().enumerate() {
        let rows = px_span(ye[r], ye[r + 1], yr.0, yr.1, ph);
        for (c, &v) in row.iter().enumerate() {
            if !v.is_finite() {
                continue;
            }
            for py in rows.clone() {
                let line = &mut pixels[py * pw..(py + 1) * pw];
                for p in &mut line[cols[c].clone()] {
                    if p.is_nan() || *p < v {
                        *p = v;
                    }
                }
            }
        }
    }
    {
        let plot = chart.plotting_area().strip_coord_spec();
        for py in 0..ph {
            for px in 0..pw {
                let v = pixels[py * pw + px];
                if v.is_finite() {
                    let screen = (px as i32, (ph - 1 - py) as i32);
                    plot.draw_pixel(screen, &viridis((v - z0) / (z1 - z0))).map_err(draw_err(path))?;
                }
            }
        }
    }
    let (x_fmt, y_fmt) = (linear_ticks(xr.0, xr.1), linear_ticks(yr.0, yr.1));
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(MAX_TICKS)
        .y_labels(MAX_TICKS)
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style(font(TICK_PX))
        .axis_desc_style(font(LABEL_PX))
        .axis_style(BLACK)
        .set_all_tick_mark_size(6)
        .draw()
        .map_err(draw_err(path))?;

    // Colour bar, with the same top and bottom as the plotting area.
    let mut bar_chart = ChartBuilder::on(&bar)
        .margin_top(10)
        .margin_bottom(10)
        .margin_left(10)
        .margin_right(10)
        .x_label_area_size(70)
        .right_y_label_area_size(100)
        .build_cartesian_2d(0f64..1f64, z0..z1)
        .map_err(draw_err(path))?;
    let steps = 256;
    bar_chart
        .draw_series((0..steps).map(|k| {
            let a = z0 + (z1 - z0) * k as f64 / steps as f64;
            let b = z0 + (z1 - z0) * (k + 1) as f64 / steps as f64;
            Rectangle::new([(0.0, a), (1.0, b)], viridis((k as f64 + 0.5) / steps as f64).filled())
        }))
        .map_err(draw_err(path))?;
    let z_fmt = linear_ticks(z0, z1);
    bar_chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(MAX_TICKS)
        .y_desc(z_label)
        .y_label_formatter(&z_fmt)
        .label_style(font(TICK_PX))
        .axis_desc_style(font(LABEL_PX))
        .axis_style(BLACK)
        .set_all_tick_mark_size(6)
        .draw()
        .map_err(draw_err(path))?;
    finish(&root, path)
}

/// Converts a grid of magnitudes to decibels, `20·log10(|v| / reference)`
/// (amplitudes; halve the result for powers). Zeros become `-inf` and are
/// left white by [`heatmap`]; values below `floor_db` are raised to it.
pub fn to_db(z: &[Vec<f64>], reference: f64, floor_db: f64) -> Vec<Vec<f64>> {
    z.iter()
        .map(|row| {
            row.iter()
                .map(|&v| {
                    let db = 20.0 * (v.abs() / reference).log10();
                    if db.is_nan() {
                        db
                    } else {
                        db.max(floor_db)
                    }
                })
                .collect()
        })
        .collect()
}

// ---------------------------------------------------------------------------
// log-log

/// Draws series on log-log axes, each point marked and joined in order (work-precision
/// charts), plus optional groups of crosses (e.g. diverged runs), into a 1200×800 PNG.
/// Non-finite and non-positive points are skipped.
///
/// # Errors
/// [`PlotError::NoData`] if nothing is drawable, [`PlotError::BadInput`] for mismatched
/// lengths, [`PlotError::Draw`] if plotters fails.
pub fn loglog(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    crosses: &[PointGroup],
) -> Result<(), PlotError> {
    for s in series {
        check_lengths(path, s.label, s.x, s.y)?;
    }
    for g in crosses {
        check_lengths(path, g.label, g.x, g.y)?;
    }
    let ok = |x: f64, y: f64| x.is_finite() && y.is_finite() && x > 0.0 && y > 0.0;
    let all = series.iter().map(|s| (s.x, s.y)).chain(crosses.iter().map(|g| (g.x, g.y)));
    let pts: Vec<(f64, f64)> =
        all.flat_map(|(x, y)| x.iter().zip(y).map(|(a, b)| (*a, *b))).filter(|p| ok(p.0, p.1)).collect();
    let (Some(xb), Some(yb)) = (finite_bounds(pts.iter().map(|p| p.0)), finite_bounds(pts.iter().map(|p| p.1))) else {
        return Err(no_data(path, "no finite positive point"));
    };
    let (xr, yr) = (log_padded(xb.0, xb.1), log_padded(yb.0, yb.1));
    ensure_font(path)?;
    let root = BitMapBackend::new(path, WIDE_SIZE).into_drawing_area();
    let area = titled_root(&root, path, title)?;
    let x_coord: LogCoord<f64> = (xr.0..xr.1).log_scale().into();
    let y_coord: LogCoord<f64> = (yr.0..yr.1).log_scale().into();
    let mut chart = builder(&area).build_cartesian_2d(x_coord, y_coord).map_err(draw_err(path))?;
    draw_mesh(&mut chart, x_label, y_label, &log_ticks, &log_ticks, path)?;
    for (i, s) in series.iter().enumerate() {
        let c = colour(i);
        let p: Vec<(f64, f64)> = s.x.iter().zip(s.y).map(|(a, b)| (*a, *b)).filter(|p| ok(p.0, p.1)).collect();
        chart
            .draw_series(p.windows(2).map(|w| PathElement::new(vec![w[0], w[1]], c.stroke_width(2))))
            .map_err(draw_err(path))?;
        chart
            .draw_series(p.iter().map(|q| Circle::new(*q, 4, c.filled())))
            .map_err(draw_err(path))?
            .label(s.label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(3)));
    }
    for (j, g) in crosses.iter().enumerate() {
        let c = colour(series.len() + j);
        let p: Vec<(f64, f64)> = g.x.iter().zip(g.y).map(|(a, b)| (*a, *b)).filter(|p| ok(p.0, p.1)).collect();
        chart
            .draw_series(p.iter().map(|q| Cross::new(*q, 6, c.stroke_width(2))))
            .map_err(draw_err(path))?
            .label(g.label)
            .legend(move |(x, y)| Cross::new((x + 12, y), 6, c.stroke_width(2)));
    }
    draw_legend(&mut chart, SeriesLabelPosition::UpperRight, path)?;
    finish(&root, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh directory under the system temp dir, unique per test,
    /// removed when dropped.
    struct Scratch(PathBuf);

    impl Scratch {
        fn join(&self, name: &str) -> PathBuf {
            self.0.join(name)
        }
    }

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    fn temp_dir(name: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!(
            "plant-plot-{}-{}-{}",
            name,
            std::process::id(),
            std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_nanos()).unwrap_or(0)
        ));
        std::fs::create_dir_all(&dir).expect("create temp dir");
        Scratch(dir)
    }

    fn assert_png(path: &Path) {
        let bytes = std::fs::read(path).expect("read png");
        assert!(bytes.len() > 1000, "{} is too small", path.display());
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{} is not a PNG", path.display());
    }

    #[test]
    fn lines_writes_png_linear_and_log() {
        let dir = temp_dir("lines");
        let t: Vec<f64> = (0..5000).map(|i| i as f64 * 1e-4).collect();
        let a: Vec<f64> = t.iter().map(|t| (80.0 * t).sin()).collect();
        let b: Vec<f64> = t.iter().map(|t| 1.0 + t * 10.0).collect();
        let s = [Series { label: "a", x: &t, y: &a }, Series { label: "b", x: &t, y: &b }];
        let p = dir.join("lin.png");
        lines(&p, "two", "t (s)", "v", &s, Scale::Linear).unwrap();
        assert_png(&p);
        let p = dir.join("log.png");
        lines(&p, "log", "t (s)", "v", &s, Scale::Log10).unwrap();
        assert_png(&p);
    }

    #[test]
    fn orbit_scatter_heatmap_write_png() {
        let dir = temp_dir("others");
        let n = 2000;
        let x: Vec<f64> = (0..n).map(|i| 1e-4 * (i as f64 * 0.05).cos()).collect();
        let y: Vec<f64> = (0..n).map(|i| 1e-4 * (i as f64 * 0.05).sin()).collect();
        let p = dir.join("orbit.png");
        orbit(&p, "orbit", &x, &y, 2e-4).unwrap();
        assert_png(&p);

        let g = [PointGroup { label: "g", x: &x, y: &y }];
        for eq in [true, false] {
            let p = dir.join(&format!("scatter-{eq}.png"));
            scatter(&p, "scatter", "x", "y", &g, eq).unwrap();
            assert_png(&p);
        }

        let gx: Vec<f64> = (0..50).map(f64::from).collect();
        let gy: Vec<f64> = (0..30).map(|i| f64::from(i) * 10.0).collect();
        let z: Vec<Vec<f64>> = gy.iter().map(|yy| gx.iter().map(|xx| xx * yy).collect()).collect();
        let p = dir.join("heat.png");
        heatmap(&p, "heat", "x", "y", &gx, &gy, &z, "z").unwrap();
        assert_png(&p);
    }

    #[test]
    fn decimation_keeps_single_spike_min_and_max() {
        let n = 1_000_000;
        let x: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let mut y: Vec<f64> = (0..n).map(|i| (i as f64 * 0.01).sin() * 0.1).collect();
        y[123_457] = 50.0;
        y[876_543] = -30.0;
        let pieces = decimate_min_max(&x, &y, 0.0, n as f64, 1000, |_, _| true);
        assert_eq!(pieces.len(), 1);
        let kept = &pieces[0];
        assert!(kept.len() <= 4 * 1000, "kept {} points", kept.len());
        assert!(kept.contains(&(123_457.0, 50.0)));
        assert!(kept.contains(&(876_543.0, -30.0)));
        assert_eq!(kept.first(), Some(&(0.0, y[0])));
        assert_eq!(kept.last(), Some(&((n - 1) as f64, y[n - 1])));
        // Order of samples is preserved.
        assert!(kept.windows(2).all(|w| w[0].0 < w[1].0));
    }

    #[test]
    fn decimation_splits_at_non_finite_and_rejected_values() {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let y = [1.0, f64::NAN, 2.0, 3.0, -1.0, 4.0];
        let pieces = decimate_min_max(&x, &y, 0.0, 5.0, 100, |_, v| v > 0.0);
        assert_eq!(pieces, vec![vec![(0.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)], vec![(5.0, 4.0)]]);
    }

    #[test]
    fn stride_keeps_first_and_last() {
        let idx: Vec<usize> = stride_indices(1_000_001, 200_000).collect();
        assert_eq!(idx.first(), Some(&0));
        assert_eq!(idx.last(), Some(&1_000_000));
        assert!(idx.len() <= 200_002);
        let idx: Vec<usize> = stride_indices(10, 200_000).collect();
        assert_eq!(idx, (0..10).collect::<Vec<_>>());
    }

    #[test]
    fn nan_input_does_not_panic() {
        let dir = temp_dir("nan");
        let x = [0.0, 1.0, f64::NAN, 3.0, 4.0, f64::INFINITY];
        let y = [1.0, f64::NAN, 2.0, 3.0, f64::NEG_INFINITY, 5.0];
        let s = [Series { label: "s", x: &x, y: &y }];
        let p = dir.join("nan-lines.png");
        lines(&p, "nan", "x", "y", &s, Scale::Linear).unwrap();
        assert_png(&p);
        assert!(lines(&dir.join("nan-log.png"), "nan", "x", "y", &s, Scale::Log10).is_ok());
        let o = [1e-5, f64::NAN, 2e-5, 3e-5];
        assert!(orbit(&dir.join("nan-orbit.png"), "o", &o, &o, f64::NAN).is_ok());
        let g = [PointGroup { label: "g", x: &x, y: &y }];
        assert!(scatter(&dir.join("nan-scatter.png"), "s", "x", "y", &g, true).is_ok());
        let z = vec![vec![f64::NAN, 1.0], vec![2.0, f64::INFINITY]];
        assert!(heatmap(&dir.join("nan-heat.png"), "h", "x", "y", &[0.0, 1.0], &[0.0, 1.0], &z, "z").is_ok());
        // All non-finite is no data, not a panic.
        let all_nan = [f64::NAN; 4];
        let s = [Series { label: "s", x: &all_nan, y: &all_nan }];
        assert!(matches!(lines(&dir.join("x.png"), "t", "x", "y", &s, Scale::Linear), Err(PlotError::NoData { .. })));
    }

    #[test]
    fn empty_input_is_an_error() {
        let dir = temp_dir("empty");
        let p = dir.join("e.png");
        assert!(matches!(lines(&p, "t", "x", "y", &[], Scale::Linear), Err(PlotError::NoData { .. })));
        let s = [Series { label: "s", x: &[], y: &[] }];
        assert!(matches!(lines(&p, "t", "x", "y", &s, Scale::Log10), Err(PlotError::NoData { .. })));
        assert!(matches!(orbit(&p, "t", &[], &[], 1e-4), Err(PlotError::NoData { .. })));
        assert!(matches!(scatter(&p, "t", "x", "y", &[], false), Err(PlotError::NoData { .. })));
        assert!(matches!(heatmap(&p, "t", "x", "y", &[], &[], &[], "z"), Err(PlotError::NoData { .. })));
        // Non-positive only, on a log axis.
        let v = [0.0, -1.0];
        let s = [Series { label: "s", x: &v, y: &v }];
        assert!(matches!(lines(&p, "t", "x", "y", &s, Scale::Log10), Err(PlotError::NoData { .. })));
        assert!(!p.exists());
    }

    /// Pins two plotters traps: an axis span that overflows to infinity
    /// makes its tick search loop forever, and an overflowing midpoint
    /// gives NaN bounds, which it asserts against.
    #[test]
    fn extreme_values_neither_panic_nor_hang() {
        let dir = temp_dir("extreme");
        let x = [0.0, 1.0, 2.0];
        for y in [[-1e308, 1e308, 0.0], [1e308; 3], [1e-300, 2e-300, 1e300]] {
            let s = [Series { label: "s", x: &x, y: &y }];
            let _ = lines(&dir.join("e.png"), "t", "x", "y", &s, Scale::Linear);
            let _ = lines(&dir.join("l.png"), "t", "x", "y", &s, Scale::Log10);
            let g = [PointGroup { label: "g", x: &y, y: &y }];
            let _ = scatter(&dir.join("s.png"), "t", "x", "y", &g, true);
            let _ = orbit(&dir.join("o.png"), "t", &y, &y, 1e-4);
            let _ = heatmap(&dir.join("h.png"), "t", "x", "y", &x, &x[..1], &[y.to_vec()], "z");
        }
    }

    #[test]
    fn unwritable_path_is_a_draw_error() {
        let dir = temp_dir("nodir");
        let p = dir.join("missing-subdir").join("x.png");
        let x = [0.0, 1.0];
        let s = [Series { label: "s", x: &x, y: &x }];
        let err = lines(&p, "t", "x", "y", &s, Scale::Linear).unwrap_err();
        assert!(matches!(err, PlotError::Draw { .. }), "{err}");
        assert!(err.to_string().contains("missing-subdir"), "{err}");
    }

    #[test]
    fn mismatched_lengths_are_bad_input() {
        let dir = temp_dir("bad");
        let p = dir.join("b.png");
        let s = [Series { label: "s", x: &[1.0, 2.0], y: &[1.0] }];
        assert!(matches!(lines(&p, "t", "x", "y", &s, Scale::Linear), Err(PlotError::BadInput { .. })));
        let z = vec![vec![1.0, 2.0]];
        assert!(matches!(
            heatmap(&p, "t", "x", "y", &[0.0, 1.0, 2.0], &[0.0], &z, "z"),
            Err(PlotError::BadInput { .. })
        ));
    }

    #[test]
    fn constant_series_gets_a_nonzero_range() {
        assert_eq!(padded(0.0, 0.0), (-1.0, 1.0));
        let (lo, hi) = padded(5.0, 5.0);
        assert!(lo < 5.0 && hi > 5.0);
        let (lo, hi) = log_padded(3.0, 3.0);
        assert!(lo < 3.0 && hi > 3.0);
        let dir = temp_dir("const");
        let x = [0.0, 1.0, 2.0];
        let y = [2.5; 3];
        let s = [Series { label: "c", x: &x, y: &y }];
        lines(&dir.join("c.png"), "c", "x", "y", &s, Scale::Linear).unwrap();
        lines(&dir.join("cl.png"), "c", "x", "y", &s, Scale::Log10).unwrap();
    }

    #[test]
    fn tick_labels_are_short() {
        let f = linear_ticks(0.0, 1.5);
        assert_eq!(f(&0.2), "0.2");
        assert_eq!(f(&1.0), "1.0");
        let f = linear_ticks(-2e-6, 2e-6);
        assert_eq!(f(&5e-7), "5e-7");
        assert_eq!(f(&1e-22), "0");
        let f = linear_ticks(0.0, 1000.0);
        assert_eq!(f(&200.0), "200");
        assert_eq!(short_number(250.0), "250");
        assert_eq!(short_number(12.5), "12.5");
    }

    #[test]
    fn equal_axes_have_equal_scale() {
        let ((x0, x1), (y0, y1)) = equalise((0.0, 2.0), (0.0, 1.0), 400, 300);
        assert!(((x1 - x0) / 400.0 - (y1 - y0) / 300.0).abs() < 1e-12);
        assert!(x1 - x0 >= 2.0 && y1 - y0 >= 1.0);
    }
}
