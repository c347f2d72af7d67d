//! Lines against a shared x axis (time traces, spectra).

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::axes::{linear_ticks, log_padded, log_ticks, padded, AxisMap};
use super::decimate::decimate_min_max;
use super::legend::{draw_legend, legend_size, quiet_corner};
use super::*;

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
    crate::plot::draw_png(path, WIDE_SIZE, |root| {
        let area = titled_root(root, path, title)?;
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
            let mut chart = builder(&area)
                .build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1)
                .map_err(draw_err(path))?;
            draw_mesh(&mut chart, x_label, y_label, &x_fmt, &y_fmt, path)?;
            draw_pieces(&mut chart, &pieces, &labels, legend_pos, path)?;
        }
        Ok(())
    })
}

pub(crate) fn draw_pieces<'a, Y>(
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
