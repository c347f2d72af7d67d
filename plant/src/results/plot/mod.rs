//! PNG charts of runs and analyses: time traces, orbits, scatter maps and
//! heat maps.
//!
//! One room per job: [`axes`] (ranges and tick labels), [`decimate`]
//! (what of a long trace is drawn), [`legend`] (where legends go), and one
//! file per chart kind ([`lines()`], [`orbit()`], [`scatter()`],
//! [`heatmap()`], [`loglog()`], [`probability()`], [`campbell()`]); this file holds the
//! shared style.
//!
//! # What every chart holds
//!
//! Tick labels on every axis (a log axis always spans at least two labelled powers of ten),
//! the legend outside the data (a strip above the plot), a colour and line style of its own
//! for each series (the palette's ten colours solid, then dashed), and reference lines and
//! circles labelled for what they are.
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
//! Every chart kind puts its legend in centred rows above the plot
//! (`legend::legend_strip`): inside, a legend hides data or a reference line,
//! whichever corner it takes.
//!
//! # Axis ranges
//!
//! Ranges come from the finite data with a 5 % margin on each side; a
//! constant series gets ±10 % of its value (±1 about zero). A log axis
//! that would hold fewer than two powers of ten is widened outwards to
//! whole decades, so that it always has labelled ticks. Orbits are centred
//! on the housing and reach 5 % beyond the largest of the orbit and the
//! circles.

mod axes;
pub(crate) use axes::{linear_ticks, log_axis, log_padded, log_ticks};
mod campbell;
pub(crate) use campbell::{campbell, ModePoints};
mod decimate;
mod heatmap;
pub(crate) use heatmap::viridis;
mod legend;
pub(crate) use legend::{legend_strip, Mark, Shape};
mod lines;
pub(crate) use lines::SeriesStyle;
mod loglog;
mod orbit;
mod probability;
mod scatter;
#[cfg(test)]
mod tests;

pub use heatmap::{heatmap, to_db};
pub use lines::lines;
pub use loglog::loglog;
pub use orbit::{orbit, orbit_with_circles};
pub use probability::{probability, ProbabilityCurve};
pub use scatter::scatter;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::coord::ranged1d::ValueFormatter;
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
/// The dash of a dashed curve, in pixels: `DASH.0` drawn, then `DASH.1` left out (the legend's
/// dashed mark, `Mark::Dashed`, draws the same).
pub const DASH: (i32, i32) = (10, 6);
/// Orbits with more samples than this are stride-decimated for drawing.
pub const ORBIT_MAX_POINTS: usize = 200_000;

pub(crate) const FONT_FAMILY: &str = "sans-serif";
pub(crate) const TITLE_PX: u32 = 28;
pub(crate) const LABEL_PX: u32 = 20;
pub(crate) const TICK_PX: u32 = 18;
pub(crate) const LEGEND_PX: u32 = 18;
pub(crate) const MAX_TICKS: usize = 10;

/// Fixed line and marker palette (matplotlib's "tab10"), used in order.
pub(crate) const PALETTE: [RGBColor; 10] = [
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
pub(crate) const GRID_BOLD: RGBColor = RGBColor(0xc8, 0xc8, 0xc8);
pub(crate) const GRID_LIGHT: RGBColor = RGBColor(0xee, 0xee, 0xee);
pub(crate) const CIRCLE_COLOURS: [RGBColor; 3] =
    [RGBColor(0x40, 0x40, 0x40), RGBColor(0x94, 0x67, 0xbd), RGBColor(0x8c, 0x56, 0x4b)];
/// Viridis sampled at nine evenly spaced points, interpolated linearly.
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

pub(crate) type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// Registers DejaVu Sans as `"sans-serif"` with plotters, once per process.
pub(crate) fn ensure_font(path: &Path) -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| register_font(FONT_FAMILY, FontStyle::Normal, dejavu::sans::regular()).is_ok());
    if ok {
        Ok(())
    } else {
        Err(PlotError::Font { path: path.to_path_buf() })
    }
}

pub(crate) fn draw_err<E: std::fmt::Display>(path: &Path) -> impl Fn(E) -> PlotError + '_ {
    move |e| PlotError::Draw { path: path.to_path_buf(), message: e.to_string() }
}

pub(crate) fn no_data(path: &Path, what: &str) -> PlotError {
    PlotError::NoData { path: path.to_path_buf(), what: what.to_string() }
}

pub(crate) fn check_lengths(path: &Path, label: &str, x: &[f64], y: &[f64]) -> Result<(), PlotError> {
    if x.len() == y.len() {
        Ok(())
    } else {
        Err(PlotError::BadInput {
            path: path.to_path_buf(),
            reason: format!("\"{label}\" has {} x values but {} y values", x.len(), y.len()),
        })
    }
}

pub(crate) fn font(px: u32) -> TextStyle<'static> {
    (FONT_FAMILY, px).into_font().color(&BLACK)
}

pub(crate) fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Paints the bitmap white and draws the title in a strip at the top;
/// returns the area below the strip.
pub(crate) fn titled_root<'a>(root: &Area<'a>, path: &Path, title: &str) -> Result<Area<'a>, PlotError> {
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
pub(crate) fn builder<'a, 'b>(area: &'a Area<'b>) -> ChartBuilder<'a, 'b, BitMapBackend<'b>> {
    let mut b = ChartBuilder::on(area);
    b.margin_top(10).margin_bottom(10).margin_left(15).margin_right(35).x_label_area_size(70).y_label_area_size(115);
    b
}

/// Width and height in pixels of the plotting area `builder` gives on `area`.
pub(crate) fn plot_pixels(area: &Area<'_>, path: &Path) -> Result<(usize, usize), PlotError> {
    let probe = builder(area).build_cartesian_2d(0f64..1f64, 0f64..1f64).map_err(draw_err(path))?;
    let (w, h) = probe.plotting_area().dim_in_pixel();
    Ok((w.max(1) as usize, h.max(1) as usize))
}

pub(crate) fn draw_mesh<'a, X, Y>(
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
    let mut mesh = chart.configure_mesh();
    mesh.x_labels(MAX_TICKS)
        .y_labels(MAX_TICKS)
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(x_fmt)
        .y_label_formatter(y_fmt)
        .bold_line_style(GRID_BOLD)
        .light_line_style(GRID_LIGHT);
    axis_look(&mut mesh).draw().map_err(draw_err(path))
}

/// The look every chart's axes share: the tick and label fonts, black axes, 6-pixel tick marks.
pub(crate) fn axis_look<'m, 'a, 'b, X, Y, DB>(
    mesh: &'m mut plotters::chart::MeshStyle<'a, 'b, X, Y, DB>,
) -> &'m mut plotters::chart::MeshStyle<'a, 'b, X, Y, DB>
where
    X: Ranged,
    Y: Ranged,
    DB: DrawingBackend,
{
    mesh.label_style(font(TICK_PX)).axis_desc_style(font(LABEL_PX)).axis_style(BLACK).set_all_tick_mark_size(6)
}

/// Draws a chart of `size` pixels in memory with `draw`, then writes it to `path` as PNG
/// through [`crate::outfile::png`]: never through a link at `path` (plotters' own
/// `BitMapBackend::new(path)` opens the path and follows one). Nothing is written when
/// `draw` fails.
pub(crate) fn draw_png<E: From<PlotError>>(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&Area<'_>) -> Result<(), E>,
) -> Result<(), E> {
    let mut rgb = vec![0u8; size.0 as usize * size.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        draw(&root)?;
        root.present().map_err(draw_err(path))?;
    }
    crate::outfile::png(path, &rgb, size)
        .map_err(|e| PlotError::Draw { path: path.to_path_buf(), message: format!("{e:#}") })?;
    Ok(())
}
