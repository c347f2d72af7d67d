//! Campbell diagrams: each whirl mode's frequency against the spin speed, drawn as points.
//!
//! Points, not lines: a mode's name at each speed comes from its shape at that speed alone, and
//! a line joining the points of one name would jump between modes where two of them cross.
//! Points show each speed's modes as they were found. A rotor with bending modes gets two
//! panels side by side, the rigid-body modes on a frequency axis of their own (they lie an
//! order of magnitude below the bending modes, and share one flat band on a common axis) and
//! every mode on the whole range; the synchronous line `f = speed` on both.

use std::path::Path;

use plotters::prelude::*;

use super::axes::linear_ticks;
use super::legend::{legend_strip, Mark, Shape};
use super::*;

/// One mode (of one whirl) of a Campbell diagram.
pub(crate) struct ModePoints<'a> {
    /// Legend text.
    pub(crate) label: String,
    /// Its colour.
    pub(crate) colour: RGBColor,
    /// Its marker.
    pub(crate) shape: Shape,
    /// Drawn as an outline (a backward whirl: a forward mode at the same frequency stays visible).
    pub(crate) open: bool,
    /// Spin speeds (Hz), same length as `y`.
    pub(crate) x: &'a [f64],
    /// Whirl frequencies (Hz).
    pub(crate) y: &'a [f64],
    /// A rigid-body mode (drawn on the rigid-body panel too).
    pub(crate) rigid: bool,
}

/// Draws a Campbell diagram of `modes` into a PNG at `path` (module doc): 1200×800 with one
/// panel when every mode is rigid, else 1800×900 with the rigid-body panel on the left. The
/// 1× line runs from 0 to the highest speed, clipped at each panel's top.
///
/// # Errors
/// [`PlotError::NoData`] if no point is finite, [`PlotError::BadInput`] if a mode's x and y
/// differ in length, [`PlotError::Draw`] if plotters cannot draw or write the file.
pub(crate) fn campbell(path: &Path, title: &str, modes: &[ModePoints]) -> Result<(), PlotError> {
    for m in modes {
        check_lengths(path, &m.label, m.x, m.y)?;
    }
    let finite = |m: &ModePoints| -> Vec<(f64, f64)> {
        m.x.iter().zip(m.y).map(|(a, b)| (*a, *b)).filter(|p| p.0.is_finite() && p.1.is_finite()).collect()
    };
    let points: Vec<Vec<(f64, f64)>> = modes.iter().map(finite).collect();
    let top = |rigid_only: bool| {
        modes
            .iter()
            .zip(&points)
            .filter(|(m, _)| m.rigid || !rigid_only)
            .flat_map(|(_, p)| p.iter().map(|q| q.1))
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let max_speed = points.iter().flatten().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
    let (all_top, rigid_top) = (top(false), top(true));
    if !all_top.is_finite() {
        return Err(no_data(path, "no finite mode frequency"));
    }
    let bends = modes.iter().zip(&points).any(|(m, p)| !m.rigid && !p.is_empty());
    // The rigid-body panel reaches 1.5 times its highest mode, so the 1× line's crossings show.
    let mut panels = vec![("every mode", all_top * 1.1)];
    if bends && rigid_top.is_finite() && rigid_top > 0.0 {
        panels.insert(0, ("rigid-body modes", rigid_top * 1.5));
    }
    let size = if panels.len() > 1 { (WIDE_SIZE.0 * 3 / 2, WIDE_SIZE.1 + 100) } else { WIDE_SIZE };
    ensure_font(path)?;
    crate::plot::draw_png(path, size, |root| {
        let area = titled_root(root, path, title)?;
        let sync = "1× spin (unbalance)".to_string();
        let entries: Vec<(String, Mark)> = modes
            .iter()
            .map(|m| {
                (m.label.clone(), if m.open { Mark::Open(m.colour, m.shape) } else { Mark::Marker(m.colour, m.shape) })
            })
            .chain(std::iter::once((sync, Mark::Dashed(BLACK))))
            .collect();
        let area = legend_strip(&area, &entries, path)?;
        let areas = area.split_evenly((1, panels.len()));
        let x1 = if max_speed > 0.0 { max_speed * 1.02 } else { 1.0 };
        for ((name, y1), sub) in panels.iter().zip(&areas) {
            let mut chart = builder(sub).build_cartesian_2d(0.0..x1, 0.0..*y1).map_err(draw_err(path))?;
            let y_label =
                if panels.len() > 1 { format!("whirl frequency (Hz), {name}") } else { "whirl frequency (Hz)".into() };
            let (x_fmt, y_fmt) = (linear_ticks(0.0, x1), linear_ticks(0.0, *y1));
            draw_mesh(&mut chart, "spin speed (Hz)", &y_label, &x_fmt, &y_fmt, path)?;
            let end = max_speed.max(0.0).min(*y1);
            chart
                .draw_series(DashedLineSeries::new([(0.0, 0.0), (end, end)], DASH.0, DASH.1, BLACK.stroke_width(2)))
                .map_err(draw_err(path))?;
            let rigid_panel = panels.len() > 1 && *name == "rigid-body modes";
            for (m, p) in modes.iter().zip(&points) {
                if rigid_panel && !m.rigid {
                    continue;
                }
                let y1 = *y1;
                let style = if m.open { m.colour.stroke_width(2) } else { m.colour.filled() };
                let inside = p.iter().copied().filter(move |q| q.1 >= 0.0 && q.1 <= y1);
                // Outlines a size larger than filled markers, so that both show where they meet.
                let r = if m.open { 4 } else { 3 };
                let vertices = match m.shape {
                    Shape::Triangle => vec![(0, -r - 1), (r + 1, r), (-r - 1, r), (0, -r - 1)],
                    _ => vec![(0, -r - 2), (r + 2, 0), (0, r + 2), (-r - 2, 0), (0, -r - 2)],
                };
                match (m.shape, m.open) {
                    (Shape::Circle, _) => chart.draw_series(inside.map(|q| Circle::new(q, r, style))),
                    (Shape::Square, _) => chart
                        .draw_series(inside.map(|q| EmptyElement::at(q) + Rectangle::new([(-r, -r), (r, r)], style))),
                    (_, true) => chart
                        .draw_series(inside.map(|q| EmptyElement::at(q) + PathElement::new(vertices.clone(), style))),
                    (_, false) => {
                        chart.draw_series(inside.map(|q| EmptyElement::at(q) + Polygon::new(vertices.clone(), style)))
                    }
                }
                .map_err(draw_err(path))?;
            }
        }
        Ok(())
    })
}
