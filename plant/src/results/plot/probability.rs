//! Probabilities with their intervals, several curves against one x axis: the recovery
//! probability of ensemble sweeps overlaid (`plant overlay`).

use std::path::Path;

use plotters::prelude::*;

use super::axes::{finite_bounds, linear_ticks, padded};
use super::legend::{legend_strip, Mark, Shape};
use super::*;

/// One curve of a [`probability`] chart: a probability per x with its interval.
#[derive(Debug, Clone, Copy)]
pub struct ProbabilityCurve<'a> {
    /// Legend text.
    pub label: &'a str,
    /// Abscissae.
    pub x: &'a [f64],
    /// The estimate at each x (0 … 1).
    pub p: &'a [f64],
    /// The interval's lower end at each x.
    pub lo: &'a [f64],
    /// The interval's upper end at each x.
    pub hi: &'a [f64],
}

/// Draws probability curves against a shared x axis into a 1200×900 PNG at `path`: each a line
/// through its estimates with a marker per point (colour and marker shape per curve; the
/// lines of curves 5 to 8 dashed), its
/// intervals as error bars with caps, and a dashed line at P = 0.5. Curve `k` of `n` is drawn
/// `(k − (n − 1)/2) · offset` to the side of its x values, so that the error bars of curves
/// at the same x stay apart (0: none; say so in `x_label`). The legend is a strip of rows above
/// the chart; the y axis is 0 … 1.
///
/// # Errors
/// [`PlotError::NoData`] without a finite point, [`PlotError::BadInput`] if a curve's slices
/// differ in length, [`PlotError::Draw`] if plotters cannot draw or write the file.
pub fn probability(
    path: &Path,
    title: &str,
    x_label: &str,
    curves: &[ProbabilityCurve],
    offset: f64,
) -> Result<(), PlotError> {
    for c in curves {
        for (what, v) in [("estimates", c.p), ("lower ends", c.lo), ("upper ends", c.hi)] {
            if v.len() != c.x.len() {
                return Err(PlotError::BadInput {
                    path: path.to_path_buf(),
                    reason: format!("\"{}\" has {} x values but {} {what}", c.label, c.x.len(), v.len()),
                });
            }
        }
    }
    let n = curves.len();
    // The second round of marker shapes draws its lines dashed: colour, shape and line together
    // tell eight curves apart.
    let dashed = |k: usize| (k / Shape::ALL.len()) % 2 == 1;
    let shift = |k: usize| if offset.is_finite() { (k as f64 - (n as f64 - 1.0) / 2.0) * offset } else { 0.0 };
    let xs = || curves.iter().enumerate().flat_map(move |(k, c)| c.x.iter().map(move |x| x + shift(k)));
    let Some((x0, x1)) = finite_bounds(xs()) else {
        return Err(no_data(path, "no finite x value in any curve"));
    };
    let xr = padded(x0, x1);
    let yr = (-0.04, 1.04);

    ensure_font(path)?;
    crate::plot::draw_png(path, (1200, 900), |root| {
        let area = titled_root(root, path, title)?;
        let entries: Vec<(String, Mark)> = curves
            .iter()
            .enumerate()
            .map(|(k, c)| {
                let style = SeriesStyle { colour: colour(k), dashed: dashed(k) };
                (c.label.to_string(), style.mark_with(Shape::ALL[k % Shape::ALL.len()]))
            })
            // The reference line named for what it is.
            .chain(std::iter::once(("P = 0.5".to_string(), Mark::Dashed(RGBColor(0x70, 0x70, 0x70)))))
            .collect();
        let area = legend_strip(&area, &entries, path)?;
        let mut chart = builder(&area).build_cartesian_2d(xr.0..xr.1, yr.0..yr.1).map_err(draw_err(path))?;
        draw_mesh(
            &mut chart,
            x_label,
            "P(recovered), 95 % interval (Wilson)",
            &linear_ticks(xr.0, xr.1),
            &|v: &f64| format!("{v:.1}"),
            path,
        )?;
        chart
            .draw_series(DashedLineSeries::new(
                [(xr.0, 0.5), (xr.1, 0.5)],
                8,
                6,
                RGBColor(0x70, 0x70, 0x70).stroke_width(1),
            ))
            .map_err(draw_err(path))?;
        for (k, c) in curves.iter().enumerate() {
            let tint = colour(k);
            let shape = Shape::ALL[k % Shape::ALL.len()];
            let dx = shift(k);
            let finite = |i: usize| c.x[i].is_finite() && c.p[i].is_finite();
            let points: Vec<(f64, f64)> =
                (0..c.x.len()).filter(|&i| finite(i)).map(|i| (c.x[i] + dx, c.p[i])).collect();
            if dashed(k) {
                chart
                    .draw_series(DashedLineSeries::new(points.iter().copied(), DASH.0, DASH.1, tint.stroke_width(2)))
                    .map_err(draw_err(path))?;
            } else {
                chart
                    .draw_series(LineSeries::new(points.iter().copied(), tint.stroke_width(2)))
                    .map_err(draw_err(path))?;
            }
            let style = tint.mix(0.8).stroke_width(1);
            let bars: Vec<(f64, f64, f64)> = (0..c.x.len())
                .filter(|&i| c.x[i].is_finite() && c.lo[i].is_finite() && c.hi[i].is_finite())
                .map(|i| (c.x[i] + dx, c.lo[i].clamp(0.0, 1.0), c.hi[i].clamp(0.0, 1.0)))
                .collect();
            chart
                .draw_series(bars.iter().map(|&(x, lo, hi)| PathElement::new(vec![(x, lo), (x, hi)], style)))
                .map_err(draw_err(path))?;
            chart
                .draw_series(bars.iter().flat_map(|&(x, lo, hi)| {
                    [lo, hi].map(|y| EmptyElement::at((x, y)) + PathElement::new(vec![(-5, 0), (5, 0)], style))
                }))
                .map_err(draw_err(path))?;
            // The markers over the bars, one shape per curve.
            let fill = tint.filled();
            let at = |p: (f64, f64)| EmptyElement::at(p);
            match shape {
                Shape::Circle => {
                    chart.draw_series(points.iter().map(|&p| at(p) + Circle::new((0, 0), 5, fill))).map(|_| ())
                }
                Shape::Square => chart
                    .draw_series(points.iter().map(|&p| at(p) + Rectangle::new([(-5, -5), (5, 5)], fill)))
                    .map(|_| ()),
                Shape::Triangle => chart
                    .draw_series(points.iter().map(|&p| at(p) + Polygon::new(vec![(0, -7), (6, 5), (-6, 5)], fill)))
                    .map(|_| ()),
                Shape::Diamond => chart
                    .draw_series(
                        points.iter().map(|&p| at(p) + Polygon::new(vec![(0, -7), (7, 0), (0, 7), (-7, 0)], fill)),
                    )
                    .map(|_| ()),
            }
            .map_err(draw_err(path))?;
        }
        Ok(())
    })
}
