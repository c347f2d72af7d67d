//! Rotor orbits relative to the housing, with reference circles.

use std::path::Path;

use plotters::prelude::*;

use super::axes::{equalise, linear_ticks, short_number, AXIS_LIMIT};
use super::decimate::{finite_pieces, stride_indices};
use super::legend::{legend_strip, Mark};
use super::*;

/// Draws a rotor orbit relative to the housing, in µm, with the touchdown
/// clearance circle of radius `clearance_m` (the bearing's at the orbit's plane), into a 900×900 PNG at `path`.
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
    orbit_with_circles(path, title, x_m, y_m, &[RefCircle { label: "touchdown clearance", radius_m: clearance_m }])
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
    crate::plot::draw_png(path, SQUARE_SIZE, |root| {
        let area = titled_root(root, path, title)?;
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
            .draw_series(
                pieces.iter().filter(|p| p.len() > 1).map(|p| PathElement::new(p.clone(), line.stroke_width(1))),
            )
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
        Ok(())
    })
}

pub(crate) fn circle_colour(i: usize) -> RGBColor {
    CIRCLE_COLOURS[i % CIRCLE_COLOURS.len()]
}

/// Arcs of a dashed circle of radius `r` about the origin: dashes of
/// about 12 px with 6 px gaps at `per_px` data units per pixel.
pub(crate) fn dashed_circle(r: f64, per_px: f64) -> Vec<Vec<(f64, f64)>> {
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
