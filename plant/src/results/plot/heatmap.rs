//! Heat maps (spectrograms, stability maps) with a colour bar.

use std::ops::Range;
use std::path::Path;

use plotters::prelude::*;

use super::axes::{finite_bounds, linear_ticks, unpadded};
use super::*;

/// Viridis colour for `t` in `[0, 1]` (clamped), from plotters' colour map.
/// Non-finite `t` gives the bottom colour: plotters' map would panic on NaN.
pub(crate) fn viridis(t: f64) -> RGBColor {
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    ViridisRGB::get_color(t)
}

/// Cell edges for grid centres `c`: midpoints between neighbours, with
/// the outer cells as wide as their neighbour. A single centre gets a unit
/// wide cell.
pub(crate) fn cell_edges(c: &[f64]) -> Vec<f64> {
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
    crate::plot::draw_png(path, WIDE_SIZE, |root| {
        let area = titled_root(root, path, title)?;
        let (main, bar) = area.split_horizontally(WIDE_SIZE.0 - 170);
        let (pw, ph) = plot_pixels(&main, path)?;

        let mut chart = builder(&main).build_cartesian_2d(xr.0..xr.1, yr.0..yr.1).map_err(draw_err(path))?;

        let pixels = rasterise(z, (&xe, &ye), (xr, yr), (pw, ph));
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
        let mut mesh = chart.configure_mesh();
        mesh.disable_mesh()
            .x_labels(MAX_TICKS)
            .y_labels(MAX_TICKS)
            .x_desc(x_label)
            .y_desc(y_label)
            .x_label_formatter(&x_fmt)
            .y_label_formatter(&y_fmt);
        axis_look(&mut mesh).draw().map_err(draw_err(path))?;

        colour_bar(&bar, path, (z0, z1), z_label)?;
        Ok(())
    })
}

/// Each pixel of a `pw` × `ph` plotting area over `xr` × `yr` holds the largest finite value of
/// the cells (edges `xe`, `ye`) it touches; NaN where none does. Row 0 is the bottom.
fn rasterise(
    z: &[Vec<f64>],
    (xe, ye): (&[f64], &[f64]),
    (xr, yr): ((f64, f64), (f64, f64)),
    (pw, ph): (usize, usize),
) -> Vec<f64> {
    let mut pixels = vec![f64::NAN; pw * ph];
    let to_px = |v: f64, lo: f64, hi: f64, n: usize| (v - lo) / (hi - lo) * n as f64;
    let px_span = |a: f64, b: f64, lo: f64, hi: f64, n: usize| {
        let (p, q) = (to_px(a.min(b), lo, hi, n), to_px(a.max(b), lo, hi, n));
        let p0 = (p.floor().max(0.0) as usize).min(n - 1);
        let p1 = (q.ceil() as usize).clamp(p0 + 1, n);
        p0..p1
    };
    let cols: Vec<Range<usize>> = (0..xe.len() - 1).map(|c| px_span(xe[c], xe[c + 1], xr.0, xr.1, pw)).collect();
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
    pixels
}

/// The colour bar beside a heat map, over `z0..z1`, with the same top and bottom as the
/// plotting area.
fn colour_bar<DB: DrawingBackend>(
    bar: &DrawingArea<DB, Shift>,
    path: &Path,
    (z0, z1): (f64, f64),
    z_label: &str,
) -> Result<(), PlotError> {
    let mut bar_chart = ChartBuilder::on(bar)
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
    let mut mesh = bar_chart.configure_mesh();
    mesh.disable_mesh().disable_x_axis().y_labels(MAX_TICKS).y_desc(z_label).y_label_formatter(&z_fmt);
    axis_look(&mut mesh).draw().map_err(draw_err(path))?;
    Ok(())
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
