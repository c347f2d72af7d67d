//! Lines against a shared x axis (time traces, spectra).

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::axes::{linear_ticks, log_padded, log_ticks, padded};
use super::decimate::decimate_min_max;
use super::legend::{legend_strip, Mark};
use super::*;

/// Draws lines against a shared x axis (radius vs time, race speed vs time,
/// coil currents, …) into a 1200×800 PNG at `path`.
///
/// Each series is reduced to at most four points per pixel column (first,
/// min, max, last), so peaks survive on traces of millions of samples.
/// Non-finite samples, and on a [`Scale::Log10`] y axis samples `<= 0`,
/// are skipped and leave a gap. A legend is drawn when there is more than
/// one series, in a strip above the plot (never over the data). Each series
/// has its own colour and line style: the palette's ten colours solid, then
/// the same ten dashed ([`series_style`]).
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
    crate::plot::draw_png(path, WIDE_SIZE, |root| {
        let area = titled_root(root, path, title)?;
        let area = if series.len() > 1 {
            let entries: Vec<(String, Mark)> =
                series.iter().enumerate().map(|(i, s)| (s.label.to_string(), series_style(i).mark())).collect();
            legend_strip(&area, &entries, path)?
        } else {
            area
        };
        let (pw, _) = plot_pixels(&area, path)?;

        // Only points inside the axes are drawn (plotters does not clip to the
        // plotting area); this matters only for values beyond ±AXIS_LIMIT or
        // more than MAX_DECADES below the top of a log axis.
        let inside =
            |x: f64, y: f64| (x_range.0..=x_range.1).contains(&x) && (y_range.0..=y_range.1).contains(&y) && keep_y(y);
        let pieces: Vec<Vec<Vec<(f64, f64)>>> =
            series.iter().map(|s| decimate_min_max(s.x, s.y, x_range.0, x_range.1, pw, inside)).collect();

        let x_fmt = linear_ticks(x_range.0, x_range.1);
        if log {
            let y_coord = super::axes::log_axis(y_range.0, y_range.1);
            let mut chart = builder(&area).build_cartesian_2d(x_range.0..x_range.1, y_coord).map_err(draw_err(path))?;
            draw_mesh(&mut chart, x_label, y_label, &x_fmt, &log_ticks, path)?;
            draw_pieces(&mut chart, &pieces, path)?;
        } else {
            let y_fmt = linear_ticks(y_range.0, y_range.1);
            let mut chart = builder(&area)
                .build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1)
                .map_err(draw_err(path))?;
            draw_mesh(&mut chart, x_label, y_label, &x_fmt, &y_fmt, path)?;
            draw_pieces(&mut chart, &pieces, path)?;
        }
        Ok(())
    })
}

/// The colour and line style of series `i`: the palette's ten colours solid, the next ten
/// dashed, so that no two of twenty series look alike (a Campbell diagram of a flexible rotor
/// has more than ten).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct SeriesStyle {
    pub(crate) colour: RGBColor,
    pub(crate) dashed: bool,
}

pub(crate) fn series_style(i: usize) -> SeriesStyle {
    SeriesStyle { colour: colour(i), dashed: (i / PALETTE.len()) % 2 == 1 }
}

impl SeriesStyle {
    /// Its legend symbol.
    pub(crate) fn mark(&self) -> Mark {
        if self.dashed {
            Mark::Dashed(self.colour)
        } else {
            Mark::Line(self.colour)
        }
    }

    /// Its legend symbol with a filled marker of `shape` on the line (a series drawn with a
    /// marker at each point).
    pub(crate) fn mark_with(&self, shape: Shape) -> Mark {
        if self.dashed {
            Mark::DashedMarker(self.colour, shape)
        } else {
            Mark::LineMarker(self.colour, shape)
        }
    }
}

pub(crate) fn draw_pieces<'a, Y>(
    chart: &mut ChartContext<'a, BitMapBackend<'a>, Cartesian2d<RangedCoordf64, Y>>,
    pieces: &[Vec<Vec<(f64, f64)>>],
    path: &Path,
) -> Result<(), PlotError>
where
    Y: Ranged<ValueType = f64>,
{
    for (i, series_pieces) in pieces.iter().enumerate() {
        let SeriesStyle { colour: c, dashed } = series_style(i);
        let style = c.stroke_width(2);
        // An isolated sample between gaps is shown as a dot.
        chart
            .draw_series(series_pieces.iter().filter(|p| p.len() == 1).map(|p| Circle::new(p[0], 2, c.filled())))
            .map_err(draw_err(path))?;
        if dashed {
            // A dashed series is dashed along each piece as a whole (its dashes are short
            // paths, so the mitre spikes below do not arise).
            for p in series_pieces.iter().filter(|p| p.len() > 1) {
                chart
                    .draw_series(DashedLineSeries::new(p.iter().copied(), DASH.0, DASH.1, style))
                    .map_err(draw_err(path))?;
            }
            continue;
        }
        // Drawn segment by segment: plotters joins the segments of a wide
        // path with unlimited mitres, which throws long spikes off the
        // sharp turns of a dense, decimated trace.
        chart
            .draw_series(
                series_pieces.iter().flat_map(|p| p.windows(2)).map(|w| PathElement::new(vec![w[0], w[1]], style)),
            )
            .map_err(draw_err(path))?;
    }
    Ok(())
}
