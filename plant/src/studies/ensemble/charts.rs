//! Charts of ensembles: the probability of recovery with its 95 % band against the swept value
//! (`recovery_probability.png`), bifurcation diagrams with the band under them
//! (`bifurcation_x.png`, `bifurcation_y.png`: Poincaré points of the first members coloured by
//! their mode, the band in a lower panel), the probability-coloured map of a 2-D sweep
//! (`map.png`), and a single scene's members (`members.png`). Points (cells) with numerically
//! sensitive members are ringed (crossed) in red.
//!
//! Drawn with plotters directly (the band, the two panels and the fixed 0 … 1 colour scale are
//! not among [`crate::plot`]'s kinds), in the same style: DejaVu Sans, white background,
//! tab10 colours, viridis (plotters' colour map, through `plot::viridis`).

use crate::ensemble::member::MemberResult;
use crate::ensemble::point::{PointStats, StoppedBy};
use crate::ensemble::stats::Threshold;
use crate::grid::{Grid, Mode, Spacing};
use crate::plot::{self, PointGroup};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

const FONT: &str = plot::FONT_FAMILY;
const BLUE: RGBColor = RGBColor(0x1f, 0x77, 0xb4);
const MODE_COLOURS: [(Mode, RGBColor); 4] = [
    (Mode::Recovered, RGBColor(0x1f, 0x77, 0xb4)),
    (Mode::DryWhirl, RGBColor(0xff, 0x7f, 0x0e)),
    (Mode::Rebound, RGBColor(0x2c, 0xa0, 0x2c)),
    (Mode::Diverged, RGBColor(0x7f, 0x7f, 0x7f)),
];
const SENSITIVE: RGBColor = RGBColor(0xd6, 0x27, 0x28);

/// Poincaré points of one mode: (mode, colour, points).
type ModeGroup = (Mode, RGBColor, Vec<(f64, f64)>);

fn draw_err<E: std::fmt::Debug>(path: &Path) -> impl Fn(E) -> anyhow::Error + '_ {
    move |e| anyhow::anyhow!("drawing {} failed: {e:?}", path.display())
}

/// The swept axis as drawn: values (log10 for a log axis) and label.
fn axis(grid: &Grid, k: usize) -> Option<(Vec<f64>, String)> {
    let a = grid.axes.get(k)?;
    let log = a.spacing == Spacing::Log;
    let values = a.values().into_iter().map(|v| if log { v.log10() } else { v }).collect();
    Some((values, if log { format!("log10({})", a.key) } else { a.key.clone() }))
}

fn range(v: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) =
        v.filter(|x| x.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = if hi > lo { 0.04 * (hi - lo) } else { 0.5 * lo.abs().max(1.0) };
    (lo - pad, hi + pad)
}

/// The band panel: p̂ with its Wilson band, the 0.5 line, thresholds, sensitive points.
fn band_panel(
    area: &DrawingArea<BitMapBackend, Shift>,
    path: &Path,
    caption: Option<&str>,
    x_label: &str,
    (x, xr): (&[f64], (f64, f64)),
    stats: &[PointStats],
    thresholds: &[(f64, [f64; 2])],
) -> anyhow::Result<()> {
    // The title, then the legend in a strip above the plot, never over the band or the curve.
    let area = match caption {
        Some(c) => &plot::titled_root(area, path, c)?,
        None => area,
    };
    let grey = RGBColor(0x60, 0x60, 0x60);
    let mut entries = vec![
        ("95 % interval (Wilson)".to_string(), plot::Mark::Band(BLUE)),
        ("P(recovered), members counted per point".to_string(), plot::Mark::LineMarker(BLUE, plot::Shape::Circle)),
        ("P = 0.5".to_string(), plot::Mark::Line(grey)),
    ];
    if stats.iter().any(|s| s.verification.numerically_sensitive > 0) {
        entries.push(("numerically sensitive members".into(), plot::Mark::Open(SENSITIVE, plot::Shape::Circle)));
    }
    if !thresholds.is_empty() {
        entries.push(("P = 0.5 crossing and its interval".into(), plot::Mark::Line(BLACK)));
    }
    let area = &plot::legend_strip(area, &entries, path)?;
    let mut b = ChartBuilder::on(area);
    b.margin(12).x_label_area_size(55).y_label_area_size(80);
    let mut chart = b.build_cartesian_2d(xr.0..xr.1, -0.03f64..1.03f64).map_err(draw_err(path))?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc("P(recovered)")
        .label_style((FONT, 18))
        .axis_desc_style((FONT, 20))
        .light_line_style(RGBColor(0xee, 0xee, 0xee))
        .bold_line_style(RGBColor(0xc8, 0xc8, 0xc8))
        .draw()
        .map_err(draw_err(path))?;
    let band: Vec<(f64, f64)> = x
        .iter()
        .zip(stats)
        .map(|(x, s)| (*x, s.tally.share.hi))
        .chain(x.iter().zip(stats).rev().map(|(x, s)| (*x, s.tally.share.lo)))
        .collect();
    chart.draw_series(std::iter::once(Polygon::new(band, BLUE.mix(0.22).filled()))).map_err(draw_err(path))?;
    chart.draw_series(LineSeries::new([(xr.0, 0.5), (xr.1, 0.5)], grey.stroke_width(1))).map_err(draw_err(path))?;
    chart
        .draw_series(LineSeries::new(x.iter().zip(stats).map(|(x, s)| (*x, s.tally.share.value)), BLUE.stroke_width(2)))
        .map_err(draw_err(path))?;
    chart
        .draw_series(x.iter().zip(stats).map(|(x, s)| Circle::new((*x, s.tally.share.value), 4, BLUE.filled())))
        .map_err(draw_err(path))?;
    let sensitive: Vec<(f64, f64)> = x
        .iter()
        .zip(stats)
        .filter(|(_, s)| s.verification.numerically_sensitive > 0)
        .map(|(x, s)| (*x, s.tally.share.value))
        .collect();
    if !sensitive.is_empty() {
        chart
            .draw_series(sensitive.iter().map(|p| Circle::new(*p, 9, SENSITIVE.stroke_width(2))))
            .map_err(draw_err(path))?;
    }
    for (v, [lo, hi]) in thresholds {
        chart
            .draw_series([
                PathElement::new([(*lo, 0.5), (*hi, 0.5)], BLACK.stroke_width(3)),
                PathElement::new([(*v, 0.38), (*v, 0.62)], BLACK.stroke_width(2)),
            ])
            .map_err(draw_err(path))?;
    }
    Ok(())
}

/// The charts of an ensemble grid.
pub fn sweep_charts(
    grid: &Grid,
    dir: &Path,
    stats: &[PointStats],
    counted: &[(Vec<&MemberResult>, StoppedBy)],
    thresholds: &[Threshold],
) -> anyhow::Result<()> {
    plot::ensure_font(dir)?;
    let scene = grid.scene_name();
    let Some((x, x_label)) = axis(grid, 0) else { return Ok(()) };
    if let Some((y, y_label)) = axis(grid, 1) {
        return probability_map(&dir.join("map.png"), grid, (&x, &x_label), (&y, &y_label), stats, &scene);
    }
    let log = grid.axes[0].spacing == Spacing::Log;
    let t: Vec<(f64, [f64; 2])> = thresholds
        .iter()
        .map(|t| {
            let f = |v: f64| if log { v.log10() } else { v };
            (f(t.value), [f(t.interval[0]), f(t.interval[1])])
        })
        .collect();
    let xr = range(x.iter().copied());
    let key = &grid.axes[0].key;
    let path = dir.join("recovery_probability.png");
    {
        plot::draw_png(&path, (1200, 800), |root| {
            root.fill(&WHITE).map_err(draw_err(&path))?;
            let title = format!("{scene}: probability of recovery against {key}");
            band_panel(root, &path, Some(&title), &x_label, (&x, xr), stats, &t)
        })?;
    }
    for (coord, file) in [(0usize, "bifurcation_x.png"), (1, "bifurcation_y.png")] {
        let path = dir.join(file);
        let c = if coord == 0 { "x" } else { "y" };
        let mut groups: Vec<ModeGroup> = MODE_COLOURS.iter().map(|(n, c)| (*n, *c, Vec::new())).collect();
        for (i, (members, _)) in counted.iter().enumerate() {
            for m in members {
                if let Some(g) = groups.iter_mut().find(|g| g.0 == m.counted().mode) {
                    g.2.extend(m.poincare.iter().map(|(_, px, py)| (x[i], if coord == 0 { *px } else { *py } * 1e6)));
                }
            }
        }
        let yr = range(groups.iter().flat_map(|g| g.2.iter().map(|p| p.1)));
        plot::draw_png(&path, (1200, 1000), |root| -> anyhow::Result<()> {
            root.fill(&WHITE).map_err(draw_err(&path))?;
            let root = plot::titled_root(root, &path, &format!("{scene}: bifurcation diagram, {c}(nT) against {key}"))?;
            let (upper, lower) = root.split_vertically(560);
            // The modes' legend in a strip above the upper panel, never over the points.
            let entries: Vec<(String, plot::Mark)> = groups
                .iter()
                .filter(|g| !g.2.is_empty())
                .map(|(name, colour, _)| (name.name().to_string(), plot::Mark::Dot(*colour)))
                .collect();
            let upper = plot::legend_strip(&upper, &entries, &path)?;
            let mut chart = ChartBuilder::on(&upper)
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(80)
                .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
                .map_err(draw_err(&path))?;
            chart
                .configure_mesh()
                .y_desc(format!("{c}(nT) (µm), first {} members", crate::ensemble::member::POINCARE_MEMBERS))
                .label_style((FONT, 18))
                .axis_desc_style((FONT, 20))
                .light_line_style(RGBColor(0xee, 0xee, 0xee))
                .bold_line_style(RGBColor(0xc8, 0xc8, 0xc8))
                .draw()
                .map_err(draw_err(&path))?;
            for (_, colour, pts) in groups.iter().filter(|g| !g.2.is_empty()) {
                let colour = *colour;
                chart.draw_series(pts.iter().map(|p| Circle::new(*p, 2, colour.filled()))).map_err(draw_err(&path))?;
            }
            band_panel(&lower, &path, None, &x_label, (&x, xr), stats, &t)
        })?;
    }
    Ok(())
}

/// A 2-D sweep's map, each cell coloured by its probability of recovery (viridis, 0 … 1),
/// cells with numerically sensitive members crossed in red.
fn probability_map(
    path: &Path,
    grid: &Grid,
    (x, x_label): (&[f64], &str),
    (y, y_label): (&[f64], &str),
    stats: &[PointStats],
    scene: &str,
) -> anyhow::Result<()> {
    let edges = |c: &[f64]| -> Vec<f64> {
        match c.len() {
            0 => Vec::new(),
            1 => vec![c[0] - 0.5, c[0] + 0.5],
            n => {
                let mut e = vec![c[0] - 0.5 * (c[1] - c[0])];
                e.extend(c.windows(2).map(|w| 0.5 * (w[0] + w[1])));
                e.push(c[n - 1] + 0.5 * (c[n - 1] - c[n - 2]));
                e
            }
        }
    };
    let (xe, ye) = (edges(x), edges(y));
    let n1 = x.len();
    plot::draw_png(path, (1200, 800), |root| -> anyhow::Result<()> {
        root.fill(&WHITE).map_err(draw_err(path))?;
        let title = format!("{scene}: probability of recovery over {} × {}", grid.axes[0].key, grid.axes[1].key);
        let root = plot::titled_root(root, path, &title)?;
        let crossed: Vec<(f64, f64)> = stats
            .iter()
            .filter(|s| s.verification.numerically_sensitive > 0)
            .map(|s| (x[s.index % n1], y[s.index / n1]))
            .collect();
        // The crosses' legend in a strip above the map, never over its cells.
        let root = if crossed.is_empty() {
            root
        } else {
            plot::legend_strip(&root, &[("numerically sensitive members".into(), plot::Mark::Cross(SENSITIVE))], path)?
        };
        let (main, bar) = root.split_horizontally(1030);
        let mut chart = ChartBuilder::on(&main)
            .margin(12)
            .x_label_area_size(55)
            .y_label_area_size(90)
            .build_cartesian_2d(xe[0]..xe[xe.len() - 1], ye[0]..ye[ye.len() - 1])
            .map_err(draw_err(path))?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(x_label)
            .y_desc(y_label)
            .label_style((FONT, 18))
            .axis_desc_style((FONT, 20))
            .draw()
            .map_err(draw_err(path))?;
        chart
            .draw_series(stats.iter().map(|s| {
                let (c, r) = (s.index % n1, s.index / n1);
                Rectangle::new([(xe[c], ye[r]), (xe[c + 1], ye[r + 1])], plot::viridis(s.tally.share.value).filled())
            }))
            .map_err(draw_err(path))?;
        chart
            .draw_series(crossed.iter().map(|p| Cross::new(*p, 6, SENSITIVE.stroke_width(2))))
            .map_err(draw_err(path))?;
        let mut bc = ChartBuilder::on(&bar)
            .margin_top(12)
            .margin_bottom(67)
            .margin_left(10)
            .margin_right(10)
            .right_y_label_area_size(100)
            .build_cartesian_2d(0f64..1f64, 0f64..1f64)
            .map_err(draw_err(path))?;
        bc.draw_series((0..200).map(|k| {
            let (a, b) = (k as f64 / 200.0, (k + 1) as f64 / 200.0);
            Rectangle::new([(0.0, a), (1.0, b)], plot::viridis(0.5 * (a + b)).filled())
        }))
        .map_err(draw_err(path))?;
        bc.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_desc("P(recovered)")
            .label_style((FONT, 18))
            .axis_desc_style((FONT, 20))
            .draw()
            .map_err(draw_err(path))?;
        Ok(())
    })
}

/// A single scene's members: recovery time against the rotor's angle at the shock's arrival
/// (or the member index without an angle draw), coloured by mode; members that never
/// recovered sit at the end of the run; numerically sensitive members form their own group.
pub fn members_chart(grid: &Grid, dir: &Path, members: &[&MemberResult]) -> Result<(), plot::PlotError> {
    let mut groups: Vec<(String, Vec<f64>, Vec<f64>)> = Vec::new();
    let angle = members.iter().all(|m| m.angle_deg.is_some());
    let x_of = |m: &MemberResult| m.angle_deg.unwrap_or(m.member as f64);
    let end = members.iter().map(|m| m.counted().steady_window_start_s).fold(0.0, f64::max);
    for (name, _) in MODE_COLOURS {
        let sel: Vec<&&MemberResult> = members.iter().filter(|m| m.counted().mode == name && !m.sensitive()).collect();
        groups.push((
            name.name().to_string(),
            sel.iter().map(|m| x_of(m)).collect(),
            sel.iter().map(|m| m.counted().recovery_s.unwrap_or(end)).collect(),
        ));
    }
    let sel: Vec<&&MemberResult> = members.iter().filter(|m| m.sensitive()).collect();
    groups.push((
        "numerically sensitive".into(),
        sel.iter().map(|m| x_of(m)).collect(),
        sel.iter().map(|m| m.counted().recovery_s.unwrap_or(end)).collect(),
    ));
    let pg: Vec<PointGroup> =
        groups.iter().filter(|g| !g.1.is_empty()).map(|g| PointGroup { label: &g.0, x: &g.1, y: &g.2 }).collect();
    plot::scatter(
        &dir.join("members.png"),
        &format!("{}: members' recovery time", grid.scene_name()),
        if angle { "rotor angle at the shock's arrival (deg)" } else { "member" },
        "time from the shock to the last contact (s)",
        &pg,
        false,
    )
}
