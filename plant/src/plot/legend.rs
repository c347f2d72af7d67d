//! Legends: inside the chart in the corner that hides the fewest points,
//! or in a strip of centred rows above it.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{draw_err, font, Area, PlotError, LEGEND_PX};

/// The corner whose legend box would cover the fewest points.
///
/// `points` are axis fractions in `[0, 1]` (y up); `box_frac` is the legend
/// size as fractions of the plotting area.
pub(crate) fn quiet_corner<'p>(
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
pub(crate) fn legend_size(area: &Area<'_>, labels: &[String]) -> (f64, f64) {
    let style = font(LEGEND_PX);
    let w = labels.iter().filter_map(|l| area.estimate_text_size(l, &style).ok()).map(|(w, _)| w).max().unwrap_or(0);
    // Text plus plotters' legend area (30 px) and margins (2 × 10 px);
    // lines are about 1.2 font heights apart.
    (f64::from(w) + 50.0, labels.len() as f64 * f64::from(LEGEND_PX) * 1.25 + 20.0)
}

pub(crate) fn draw_legend<'a, CT>(
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

/// A legend symbol.
#[derive(Clone, Copy)]
pub(crate) enum Mark {
    /// A solid line.
    Line(RGBColor),
    /// A dashed line.
    Dashed(RGBColor),
    /// A filled circle.
    Dot(RGBColor),
    /// A filled square.
    Square(RGBColor),
    /// A solid line with a filled marker on it.
    LineMarker(RGBColor, Shape),
}

/// A marker's shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Shape {
    Circle,
    Square,
    Triangle,
    Diamond,
}

impl Shape {
    /// Every shape, in the order curves take them.
    pub(crate) const ALL: [Shape; 4] = [Shape::Circle, Shape::Square, Shape::Triangle, Shape::Diamond];
}

/// Draws a legend in centred rows (wrapped to the width) at the top of
/// `area`, and
/// returns the area below it.
pub(crate) fn legend_strip<'a>(
    area: &Area<'a>,
    entries: &[(String, Mark)],
    path: &Path,
) -> Result<Area<'a>, PlotError> {
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

pub(crate) fn draw_mark(
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
        Mark::LineMarker(c, shape) => {
            area.draw(&PathElement::new(vec![(x, y), (x + w, y)], c.stroke_width(2)))?;
            match shape {
                Shape::Circle => area.draw(&Circle::new((mid, y), 6, c.filled())),
                Shape::Square => area.draw(&Rectangle::new([(mid - 5, y - 5), (mid + 5, y + 5)], c.filled())),
                Shape::Triangle => {
                    area.draw(&Polygon::new(vec![(mid, y - 6), (mid + 6, y + 5), (mid - 6, y + 5)], c.filled()))
                }
                Shape::Diamond => {
                    area.draw(&Polygon::new(vec![(mid, y - 7), (mid + 7, y), (mid, y + 7), (mid - 7, y)], c.filled()))
                }
            }
        }
    }
}
