//! Legends: a strip of centred rows above the chart, never over the data.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{draw_err, font, Area, PlotError, LEGEND_PX};

/// A legend symbol.
#[derive(Clone, Copy)]
pub(crate) enum Mark {
    /// A solid line.
    Line(RGBColor),
    /// A dashed line.
    Dashed(RGBColor),
    /// A dotted line.
    Dotted(RGBColor),
    /// A light filled band (an interval).
    Band(RGBColor),
    /// A filled circle.
    Dot(RGBColor),
    /// A filled square.
    Square(RGBColor),
    /// A cross (×).
    Cross(RGBColor),
    /// A marker alone (a series drawn as points).
    Marker(RGBColor, Shape),
    /// A hollow marker alone: its outline, so that a filled one at the same point stays visible.
    Open(RGBColor, Shape),
    /// A solid line with a filled marker on it.
    LineMarker(RGBColor, Shape),
    /// A dashed line with a filled marker on it (a curve of the second round of shapes).
    DashedMarker(RGBColor, Shape),
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
            let (on, off) = super::DASH;
            area.draw(&PathElement::new(vec![(x, y), (x + on, y)], c.stroke_width(2)))?;
            area.draw(&PathElement::new(vec![(x + on + off, y), (x + w, y)], c.stroke_width(2)))
        }
        Mark::Dotted(c) => {
            for k in (0..w).step_by(6) {
                area.draw(&PathElement::new(vec![(x + k, y), (x + k + 2, y)], c.stroke_width(2)))?;
            }
            Ok(())
        }
        Mark::Band(c) => area.draw(&Rectangle::new([(x, y - 6), (x + w, y + 6)], c.mix(0.22).filled())),
        Mark::Dot(c) => area.draw(&Circle::new((mid, y), 7, c.filled())),
        Mark::Square(c) => area.draw(&Rectangle::new([(mid - 6, y - 6), (mid + 6, y + 6)], c.filled())),
        Mark::Cross(c) => area.draw(&Cross::new((mid, y), 6, c.stroke_width(2))),
        Mark::Marker(c, shape) => draw_shape(area, shape, (mid, y), c.filled()),
        Mark::Open(c, shape) => draw_shape(area, shape, (mid, y), c.stroke_width(2)),
        Mark::LineMarker(c, shape) => {
            area.draw(&PathElement::new(vec![(x, y), (x + w, y)], c.stroke_width(2)))?;
            draw_shape(area, shape, (mid, y), c.filled())
        }
        Mark::DashedMarker(c, shape) => {
            for k in (0..w).step_by(10) {
                area.draw(&PathElement::new(vec![(x + k, y), (x + (k + 6).min(w), y)], c.stroke_width(2)))?;
            }
            draw_shape(area, shape, (mid, y), c.filled())
        }
    }
}

/// A marker of `shape` in `style` (filled or an outline) centred on `(x, y)` (pixels).
fn draw_shape(
    area: &Area<'_>,
    shape: Shape,
    (mid, y): (i32, i32),
    style: ShapeStyle,
) -> Result<(), DrawingAreaErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>> {
    let outline = |pts: Vec<(i32, i32)>| {
        if style.filled {
            area.draw(&Polygon::new(pts, style))
        } else {
            let mut closed = pts.clone();
            closed.push(pts[0]);
            area.draw(&PathElement::new(closed, style))
        }
    };
    match shape {
        Shape::Circle => area.draw(&Circle::new((mid, y), 6, style)),
        Shape::Square => area.draw(&Rectangle::new([(mid - 5, y - 5), (mid + 5, y + 5)], style)),
        Shape::Triangle => outline(vec![(mid, y - 6), (mid + 6, y + 5), (mid - 6, y + 5)]),
        Shape::Diamond => outline(vec![(mid, y - 7), (mid + 7, y), (mid, y + 7), (mid - 7, y)]),
    }
}
