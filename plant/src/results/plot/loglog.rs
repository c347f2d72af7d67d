//! Log-log charts with marked points (work-precision charts).

use std::path::Path;

use plotters::prelude::*;

use super::axes::{finite_bounds, log_axis, log_padded, log_ticks};
use super::legend::{legend_strip, Mark, Shape};
use super::*;

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
    crate::plot::draw_png(path, WIDE_SIZE, |root| {
        let area = titled_root(root, path, title)?;
        // The legend in a strip above the plot, never over the data.
        let entries: Vec<(String, Mark)> = series
            .iter()
            .enumerate()
            .map(|(i, s)| (s.label.to_string(), Mark::LineMarker(colour(i), Shape::Circle)))
            .chain(
                crosses.iter().enumerate().map(|(j, g)| (g.label.to_string(), Mark::Cross(colour(series.len() + j)))),
            )
            .collect();
        let area = legend_strip(&area, &entries, path)?;
        let (x_coord, y_coord) = (log_axis(xr.0, xr.1), log_axis(yr.0, yr.1));
        let mut chart = builder(&area).build_cartesian_2d(x_coord, y_coord).map_err(draw_err(path))?;
        draw_mesh(&mut chart, x_label, y_label, &log_ticks, &log_ticks, path)?;
        for (i, s) in series.iter().enumerate() {
            let c = colour(i);
            let p: Vec<(f64, f64)> = s.x.iter().zip(s.y).map(|(a, b)| (*a, *b)).filter(|p| ok(p.0, p.1)).collect();
            chart
                .draw_series(p.windows(2).map(|w| PathElement::new(vec![w[0], w[1]], c.stroke_width(2))))
                .map_err(draw_err(path))?;
            chart.draw_series(p.iter().map(|q| Circle::new(*q, 4, c.filled()))).map_err(draw_err(path))?;
        }
        for (j, g) in crosses.iter().enumerate() {
            let c = colour(series.len() + j);
            let p: Vec<(f64, f64)> = g.x.iter().zip(g.y).map(|(a, b)| (*a, *b)).filter(|p| ok(p.0, p.1)).collect();
            chart.draw_series(p.iter().map(|q| Cross::new(*q, 6, c.stroke_width(2)))).map_err(draw_err(path))?;
        }
        Ok(())
    })
}
