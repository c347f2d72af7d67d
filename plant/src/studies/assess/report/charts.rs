//! The report's charts as PNG: each controller's sensitivity functions and the shock ladder's
//! probability and duty against the shock's peak.

use super::super::ladder::LadderResult;
use super::super::{ControllerReport, Report};
use super::zone_db;
use crate::plot::{builder, colour, draw_err, draw_mesh, ensure_font, titled_root, PlotError, WIDE_SIZE};
use plotters::prelude::*;
use std::path::Path;

/// A line of a chart.
#[derive(Clone)]
struct Line {
    label: String,
    points: Vec<(f64, f64)>,
    colour: RGBColor,
    dash: Dash,
    width: u32,
}

/// A line's style: with its colour, what tells two series apart.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Dash {
    Solid,
    Dashed,
    Dotted,
}

/// Error bars of one series: its colour and `(x, low, high)` per bar.
type ErrorBars = (RGBColor, Vec<(f64, f64, f64)>);

/// An x–y chart with a log or linear x axis, horizontal reference lines, optional error bars.
fn chart(
    path: &Path,
    title: &str,
    labels: (&str, &str),
    x_log: bool,
    lines: &[Line],
    hlines: &[(f64, &str)],
    bars: &[ErrorBars],
) -> Result<(), PlotError> {
    ensure_font(path)?;
    crate::plot::draw_png(path, WIDE_SIZE, |root| {
        let area = titled_root(root, path, title)?;
        let area = legend_rows(&area, path, lines)?;
        panel(&area, path, labels, x_log, lines, hlines, bars)
    })
}

/// The legend of `lines` in rows at the top of `area`, never over the curves or the reference
/// lines' labels; returns the area below it.
fn legend_rows<'a>(
    area: &crate::plot::Area<'a>,
    path: &Path,
    lines: &[Line],
) -> Result<crate::plot::Area<'a>, PlotError> {
    let mut entries: Vec<(String, crate::plot::Mark)> = Vec::new();
    for l in lines {
        let mark = match l.dash {
            Dash::Solid => crate::plot::Mark::Line(l.colour),
            Dash::Dashed => crate::plot::Mark::Dashed(l.colour),
            Dash::Dotted => crate::plot::Mark::Dotted(l.colour),
        };
        // Panels share one legend: each series once.
        if !entries.iter().any(|(label, _)| *label == l.label) {
            entries.push((l.label.clone(), mark));
        }
    }
    crate::plot::legend_strip(area, &entries, path)
}

/// One x–y plot on `area` (the body of [`chart`]; a chart of several panels draws one each).
fn panel(
    area: &crate::plot::Area<'_>,
    path: &Path,
    (x_label, y_label): (&str, &str),
    x_log: bool,
    lines: &[Line],
    hlines: &[(f64, &str)],
    bars: &[ErrorBars],
) -> Result<(), PlotError> {
    let pts = lines.iter().flat_map(|l| l.points.iter().copied()).filter(|p| p.0.is_finite() && p.1.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for (x, y) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    for (_, b) in bars {
        for (_, lo, hi) in b {
            y0 = y0.min(*lo);
            y1 = y1.max(*hi);
        }
    }
    for (y, _) in hlines {
        y0 = y0.min(*y);
        y1 = y1.max(*y);
    }
    if !(x0.is_finite() && y0.is_finite()) {
        return Err(PlotError::NoData { path: path.into(), what: "no finite point".into() });
    }
    if x1 <= x0 {
        x1 = x0 * 1.1 + 1.0;
    }
    let pad = ((y1 - y0) * 0.06).max(1e-9);
    let (y0, y1) = (y0 - pad, y1 + pad);
    // A band narrower than a decade is drawn on a linear axis (a log axis gets no tick inside
    // it); a log axis spans at least two labelled powers of ten.
    let x_log = x_log && x0 > 0.0 && x1 / x0 >= 10.0;
    let (x0, x1) = if x_log { crate::plot::log_padded(x0, x1) } else { (x0, x1) };
    let fmt_y = |v: &f64| format!("{v:.3}").trim_end_matches('0').trim_end_matches('.').to_string();
    macro_rules! body {
        ($chart:expr) => {{
            let mut c = $chart;
            for (y, label) in hlines {
                c.draw_series(std::iter::once(PathElement::new(
                    vec![(x0, *y), (x1, *y)],
                    RGBColor(120, 120, 120).stroke_width(1),
                )))
                .map_err(draw_err(path))?;
                // The label sits on its line at the right end, clear of the next one's and of
                // the curves' low-frequency peaks.
                let above = plotters::style::text_anchor::Pos::new(
                    plotters::style::text_anchor::HPos::Right,
                    plotters::style::text_anchor::VPos::Bottom,
                );
                c.draw_series(std::iter::once(Text::new(
                    label.to_string(),
                    (x1, *y),
                    crate::plot::font(16).pos(above),
                )))
                .map_err(draw_err(path))?;
            }
            for (col, b) in bars {
                for (x, lo, hi) in b {
                    c.draw_series(std::iter::once(PathElement::new(vec![(*x, *lo), (*x, *hi)], col.stroke_width(2))))
                        .map_err(draw_err(path))?;
                }
            }
            for l in lines {
                let style = l.colour.stroke_width(l.width);
                let pts: Vec<(f64, f64)> =
                    l.points.iter().copied().filter(|p| p.0.is_finite() && p.1.is_finite()).collect();
                match l.dash {
                    Dash::Solid => c.draw_series(LineSeries::new(pts.clone(), style)).map_err(draw_err(path))?,
                    Dash::Dashed => {
                        c.draw_series(DashedLineSeries::new(pts.clone(), 8, 6, style)).map_err(draw_err(path))?
                    }
                    Dash::Dotted => {
                        c.draw_series(DashedLineSeries::new(pts.clone(), 2, 4, style)).map_err(draw_err(path))?
                    }
                };
                if l.dash == Dash::Solid && pts.len() < 40 {
                    c.draw_series(pts.iter().map(|p| Circle::new(*p, 3, l.colour.filled()))).map_err(draw_err(path))?;
                }
            }
        }};
    }
    if x_log {
        let x_coord = crate::plot::log_axis(x0, x1);
        let mut c = builder(area).build_cartesian_2d(x_coord, y0..y1).map_err(draw_err(path))?;
        draw_mesh(&mut c, x_label, y_label, &crate::plot::log_ticks, &fmt_y, path)?;
        body!(c);
    } else {
        let mut c = builder(area).build_cartesian_2d(x0..x1, y0..y1).map_err(draw_err(path))?;
        draw_mesh(&mut c, x_label, y_label, &crate::plot::linear_ticks(x0, x1), &fmt_y, path)?;
        body!(c);
    }
    Ok(())
}

/// The Bode magnitude chart of one controller: `|S|` and `|T|` of each axis and speed, the
/// closed form where there is one, the zone boundaries.
pub(super) fn sensitivity_chart(path: &Path, c: &ControllerReport) -> Result<bool, PlotError> {
    let Some(s) = &c.sensitivity.result else { return Ok(false) };
    // One panel per rotor speed, side by side (standstill first): the curves at standstill and
    // at speed often lie on one another, and one panel would show only the last drawn.
    let mut speeds: Vec<f64> = s.axes.iter().filter(|a| !a.points.is_empty()).map(|a| a.speed_hz).collect();
    speeds.sort_by(f64::total_cmp);
    speeds.dedup();
    let panels: Vec<(f64, Vec<Line>)> = speeds.iter().map(|sp| (*sp, sensitivity_lines(s, Some(*sp)))).collect();
    if panels.iter().all(|(_, lines)| lines.iter().all(|l| l.points.is_empty())) {
        return Ok(false);
    }
    // Each boundary named for what it is: the ISO 14839-3 zone boundary of the peak |S|.
    let zone_labels: Vec<(f64, String)> =
        zone_db().iter().map(|(db, l)| (*db, format!("ISO 14839-3 zone {l} ({db:.1} dB)"))).collect();
    let zones: Vec<(f64, &str)> = zone_labels.iter().map(|(db, l)| (*db, l.as_str())).collect();
    ensure_font(path)?;
    // Taller than wide charts: the legend takes rows above the panels.
    let size =
        if panels.len() > 1 { (WIDE_SIZE.0 * 3 / 2, WIDE_SIZE.1 + 100) } else { (WIDE_SIZE.0, WIDE_SIZE.1 + 100) };
    crate::plot::draw_png(path, size, |root| {
        let area = titled_root(root, path, &format!("{}: sensitivity S and T per axis (ISO 14839-3)", c.label))?;
        // One legend over the panels (the same series in each; the speed is the panel's), so
        // that the panels' plots line up.
        let all: Vec<Line> = panels.iter().flat_map(|(_, lines)| lines.iter().cloned()).collect();
        let area = legend_rows(&area, path, &all)?;
        let areas = area.split_evenly((1, panels.len().max(1)));
        for ((speed, lines), sub) in panels.iter().zip(&areas) {
            let x = if *speed > 0.0 {
                format!("frequency (Hz); rotor at {speed:.0} Hz")
            } else {
                "frequency (Hz); rotor at standstill".into()
            };
            panel(sub, path, (&x, "magnitude (dB)"), true, lines, &zones, &[])?;
        }
        Ok::<(), PlotError>(())
    })?;
    Ok(true)
}

/// The lines of the sensitivity chart: `|S|` and `|T|` of each axis measured at `speed` (Hz;
/// `None`: every speed), and the closed form where there is one.
fn sensitivity_lines(s: &super::super::SensitivityPart, speed: Option<f64>) -> Vec<Line> {
    let mut lines = Vec::new();
    let at = |a: &&super::super::sensitivity::AxisResult| speed.is_none_or(|sp| a.speed_hz == sp);
    for (i, a) in s.axes.iter().filter(|a| !a.points.is_empty()).filter(at).enumerate() {
        // The speed is the panel's (its x label) when the lines are one speed's.
        let name = if speed.is_some() { a.axis.to_string() } else { format!("{} at {:.0} Hz", a.axis, a.speed_hz) };
        lines.push(Line {
            label: format!("|S| {name}"),
            points: a.points.iter().map(|p| (p.f_hz, p.s_db)).collect(),
            colour: colour(i),
            dash: Dash::Solid,
            // x axes wider than y axes: the two often coincide, and the wider line shows around
            // the narrower one drawn over it.
            width: if a.axis.starts_with('x') { 5 } else { 2 },
        });
        lines.push(Line {
            label: format!("|T| {name}"),
            points: a.points.iter().map(|p| (p.f_hz, p.t_db)).collect(),
            colour: {
                let RGBColor(r, g, b) = colour(i);
                RGBColor(r / 2 + 110, g / 2 + 110, b / 2 + 110)
            },
            dash: Dash::Dotted,
            width: 2,
        });
    }
    if let Some(cf) = &s.closed_form {
        // The two-plane rotor: plane A's load share as a planar rotor, not the coupled loop.
        let label = if s.closed_form_planes.is_empty() { "|S| closed form" } else { "|S| closed form, plane A alone" };
        lines.push(Line { label: label.into(), points: cf.curve.clone(), colour: BLACK, dash: Dash::Dashed, width: 2 });
    }
    // The coupled loop's closed form of each axis (the flexible rotor).
    for (i, f) in s.closed_form_axes.iter().filter(|f| speed.is_none_or(|sp| f.speed_hz == sp) && f.stable).enumerate()
    {
        lines.push(Line {
            label: if speed.is_some() {
                format!("|S| closed form {}, all axes' loops", f.axis)
            } else {
                format!("|S| closed form {} at {:.0} Hz, all axes' loops", f.axis, f.speed_hz)
            },
            points: f.curve.clone(),
            colour: colour(i),
            dash: Dash::Dashed,
            width: 1,
        });
    }
    lines
}

/// The ladder's charts over all controllers: probability with its interval, recovery times,
/// friction energy and the most loaded ball's pressure.
pub(super) fn ladder_charts(dir: &Path, r: &Report) -> Result<Vec<(String, String)>, PlotError> {
    let with: Vec<(usize, &ControllerReport, &LadderResult)> =
        r.controllers.iter().enumerate().filter_map(|(i, c)| c.ladder.result.as_ref().map(|l| (i, c, l))).collect();
    if with.is_empty() {
        return Ok(Vec::new());
    }
    let mut out = Vec::new();
    let series = |f: &dyn Fn(&super::super::ladder::Rung) -> Option<f64>, dashed: bool, suffix: &str| -> Vec<Line> {
        with.iter()
            .map(|(i, c, l)| Line {
                label: format!("{}{suffix}", c.label),
                points: l
                    .rungs
                    .iter()
                    .filter(|x| x.tally.members > 0)
                    .filter_map(|x| f(x).map(|v| (x.peak_g, v)))
                    .collect(),
                colour: colour(*i),
                dash: if dashed { Dash::Dashed } else { Dash::Solid },
                width: 2,
            })
            .collect()
    };
    let bars: Vec<ErrorBars> = with
        .iter()
        .map(|(i, _, l)| {
            (
                colour(*i),
                l.rungs
                    .iter()
                    .filter(|x| x.tally.members > 0)
                    .map(|x| (x.peak_g, x.tally.share.lo, x.tally.share.hi))
                    .collect(),
            )
        })
        .collect();
    // A ladder interrupted or stopped before any member was counted has nothing to draw.
    let lines = series(&|x| Some(x.tally.share.value), false, "");
    if lines.iter().any(|l| !l.points.is_empty()) {
        let p = dir.join("ladder_probability.png");
        let min_p = format!("required probability (min_p = {})", r.ladder_settings.min_p);
        chart(
            &p,
            "Probability of recovery against the shock's peak (Wilson 95 % intervals)",
            ("peak of the shock (G)", "P(recovered)"),
            false,
            &lines,
            &[(r.ladder_settings.min_p, min_p.as_str())],
            &bars,
        )?;
        out.push(("ladder_probability.png".into(), "Probability of recovery per rung".into()));
    }
    let mut lines = series(&|x| x.tally.recovery.median_s.map(|v| v * 1e3), false, " median");
    lines.extend(series(&|x| x.tally.recovery.p90_s.map(|v| v * 1e3), true, " p90"));
    if lines.iter().any(|l| !l.points.is_empty()) {
        let p = dir.join("ladder_recovery.png");
        chart(
            &p,
            "Recovery time of the recovered members",
            ("peak of the shock (G)", "recovery time (ms)"),
            false,
            &lines,
            &[],
            &[],
        )?;
        out.push(("ladder_recovery.png".into(), "Recovery time, median and 90th percentile".into()));
    }
    let mut lines = series(&|x| x.duty.friction_energy_j.median, false, " median");
    lines.extend(series(&|x| x.duty.friction_energy_j.p90, true, " p90"));
    if lines.iter().any(|l| !l.points.is_empty()) {
        let p = dir.join("duty_friction.png");
        chart(
            &p,
            "Friction energy dissipated at the rotor – race contact per shock",
            ("peak of the shock (G)", "energy (J)"),
            false,
            &lines,
            &[],
            &[],
        )?;
        out.push(("duty_friction.png".into(), "Friction energy per shock".into()));
    }
    let lines = series(&|x| x.duty.peak_ball_pressure_mpa.median, false, " median");
    if lines.iter().any(|l| !l.points.is_empty()) {
        let p = dir.join("duty_ball_pressure.png");
        let limit = r.bearing.map(|b| b.materials.static_pressure_pa * 1e-6);
        let hl: Vec<(f64, &str)> = limit.map(|l| vec![(l, "the balls' static pressure limit")]).unwrap_or_default();
        chart(
            &p,
            "Peak Hertz pressure of the most loaded ball (inner raceway)",
            ("peak of the shock (G)", "pressure (MPa)"),
            false,
            &lines,
            &hl,
            &[],
        )?;
        out.push(("duty_ball_pressure.png".into(), "Most loaded ball's peak pressure".into()));
    }
    Ok(out)
}
