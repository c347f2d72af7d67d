//! Groups of markers: Poincaré maps, bifurcation diagrams.

use std::path::Path;

use plotters::prelude::*;

use super::axes::{centred, equalise, finite_bounds, linear_ticks, padded, AxisMap};
use super::legend::{legend_strip, Mark};
use super::*;

/// Draws groups of markers (Poincaré maps, bifurcation diagrams) in
/// distinct colours into a PNG at `path`: 900×900 with equally scaled axes
/// when `equal_axes`, else 1200×800.
///
/// Each group draws at most one marker per pixel, so maps of millions of
/// points stay fast. Non-finite points are skipped. A legend is drawn when
/// there is more than one group, in a strip above the plot (never over the data).
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
    crate::plot::draw_png(path, size, |root| {
        let area = titled_root(root, path, title)?;
        let area = if groups.len() > 1 {
            let entries: Vec<(String, Mark)> =
                groups.iter().enumerate().map(|(i, g)| (g.label.to_string(), Mark::Dot(colour(i)))).collect();
            legend_strip(&area, &entries, path)?
        } else {
            area
        };
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
            chart.draw_series(kept.iter().map(|&p| Circle::new(p, radius, c.filled()))).map_err(draw_err(path))?;
        }
        Ok(())
    })
}
