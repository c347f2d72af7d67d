//! The assessment's outputs: `report.json` (every figure), the charts as PNG, and
//! `report.html`, one self-contained page (the charts embedded as data URIs, no script, no
//! network) with the verdict line of each controller at the top, one column each.

mod ladder_table;
mod verdict;

use super::ladder::{LadderResult, Rung};
use super::{ControllerReport, Report};
use crate::plot::{builder, colour, draw_err, draw_mesh, ensure_font, titled_root, PlotError, WIDE_SIZE};
use anyhow::Context;
use base64::Engine;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::Path;

/// The ISO 14839-3 zone boundaries of the peak sensitivity, in dB (3, 4, 5).
const ZONE_DB: [(f64, &str); 3] = [(9.542, "A/B"), (12.041, "B/C"), (13.979, "C/D")];

/// Peaks of `|S|` within this many dB of the worst one are named as its equals.
pub const EQUAL_DB: f64 = 0.05;

/// The worst measured axis (the worst zone, then the highest peak; of equals the first in the
/// order measured: x, y, at standstill then at speed) and the others in its zone whose peak lies
/// within [`EQUAL_DB`] of its own.
pub fn worst_axis(
    axes: &[super::sensitivity::AxisResult],
) -> Option<(&super::sensitivity::AxisResult, Vec<&super::sensitivity::AxisResult>)> {
    let rank = |a: &super::sensitivity::AxisResult| match a.zone.as_str() {
        "A" => 0,
        "B" => 1,
        "C" => 2,
        "D" => 3,
        _ => 4,
    };
    let peak = |a: &super::sensitivity::AxisResult| a.peak.as_ref().map_or(f64::NEG_INFINITY, |p| p.s_db);
    let mut worst: Option<&super::sensitivity::AxisResult> = None;
    for a in axes {
        let beats = worst.is_none_or(|w| rank(a).cmp(&rank(w)).then(peak(a).total_cmp(&peak(w))).is_gt());
        if beats {
            worst = Some(a);
        }
    }
    let w = worst?;
    let equals = axes
        .iter()
        .filter(|a| !std::ptr::eq(*a, w) && rank(a) == rank(w) && (peak(a) - peak(w)).abs() <= EQUAL_DB)
        .collect();
    Some((w, equals))
}

/// The verdict line of a controller: its worst zone, the vibration zone, the highest safe
/// shock and the duty at the duty rung.
pub fn verdict(r: &ControllerReport, duty_g: f64, min_p: f64) -> String {
    let mut parts = Vec::new();
    match (&r.sensitivity.result, r.sensitivity.status) {
        (Some(s), _) => {
            let worst = worst_axis(&s.axes)
                .map(|(a, equals)| {
                    let equal = if equals.is_empty() {
                        String::new()
                    } else {
                        let names: Vec<String> =
                            equals.iter().map(|e| format!("{} at {:.0} Hz", e.axis, e.speed_hz)).collect();
                        format!("; equal within {EQUAL_DB} dB: {}", names.join(", "))
                    };
                    a.peak.as_ref().map_or(format!("{} ({} at {:.0} Hz)", a.zone, a.axis, a.speed_hz), |p| {
                        format!(
                            "zone {} (|S| {:.1} dB at {:.1} Hz, {} at {:.0} Hz{equal})",
                            a.zone, p.s_db, p.f_hz, a.axis, a.speed_hz
                        )
                    })
                })
                .unwrap_or_default();
            // A part that failed or was interrupted: the axes measured before it, said so.
            let so_far = match r.sensitivity.status {
                "measured" => String::new(),
                status => format!("sensitivity {status}, on the {} axes measured: ", s.axes.len()),
            };
            if s.axes.iter().any(|a| !a.stable) {
                parts.push(format!("{so_far}UNSTABLE loop: no stability margin"));
            } else {
                parts.push(format!("{so_far}{worst}"));
            }
        }
        (None, status) => parts.push(format!("sensitivity {status}")),
    }
    if let Some(v) = &r.vibration.result {
        let plane = if v.planes.len() > 1 { format!(" at plane {}", v.plane) } else { String::new() };
        parts.push(format!("vibration zone {} ({:.1} µm, {:.2} C_min{plane})", v.zone, v.peak_um, v.ratio));
    } else if r.vibration.status != "skipped" {
        parts.push(format!("vibration {}", r.vibration.status));
    }
    if let Some(l) = r.ladder.result.as_ref().filter(|l| l.rungs.iter().any(|x| x.tally.members > 0)) {
        // An interrupted or failed ladder: its figures are those of the rungs decided so far.
        let so_far = match r.ladder.status {
            "measured" => String::new(),
            status => format!("ladder {status}, on the members run so far: "),
        };
        parts.push(format!("{so_far}{}", safe_words(l, min_p)));
        parts.extend(l.robustness.as_ref().map(|x| x.words(l.safe_up_to_g)));
        if let Some(rung) = l.rungs.iter().find(|x| (x.peak_g - duty_g).abs() < 1e-9) {
            let d = &rung.duty;
            parts.push(format!(
                "at {duty_g} G{}: P = {:.2} [{:.2}, {:.2}], median {:.3} s in contact, {:.0} J friction, peak ball {:.0} MPa",
                if rung.complete { "" } else { " (incomplete)" },
                rung.tally.p_recovered,
                rung.tally.p_lo,
                rung.tally.p_hi,
                d.contact_time_s.median.unwrap_or(f64::NAN),
                d.friction_energy_j.median.unwrap_or(f64::NAN),
                d.peak_ball_pressure_mpa.median.unwrap_or(f64::NAN)
            ));
        }
    } else if r.ladder.status != "skipped" {
        parts.push(format!("ladder {}", r.ladder.status));
    }
    parts.join("; ")
}

/// The highest safe shock in words, with the interval that decides it: the safe rung's
/// [lower, upper], or where none is safe the first rung's (the one that failed), and the counts.
fn safe_words(l: &LadderResult, min_p: f64) -> String {
    let interval = |x: &Rung| {
        format!("{}/{} recovered, [{:.2}, {:.2}]", x.tally.recovered, x.tally.members, x.tally.p_lo, x.tally.p_hi)
    };
    match l.safe_up_to_g {
        Some(g) => {
            let at = l.rungs.iter().find(|x| x.peak_g == g).map(|x| format!(" ({} at {g} G)", interval(x)));
            format!("P(recovered) ≥ {min_p} up to {g} G{}", at.unwrap_or_default())
        }
        None => {
            let first =
                l.rungs.iter().find(|x| x.tally.members > 0).map(|x| format!(" (at {} G: {})", x.peak_g, interval(x)));
            format!("P(recovered) ≥ {min_p} at no rung{}", first.unwrap_or_default())
        }
    }
}

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
        let x_coord: plotters::coord::combinators::LogCoord<f64> = (x0..x1).log_scale().into();
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
fn sensitivity_chart(path: &Path, c: &ControllerReport) -> Result<bool, PlotError> {
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
        ZONE_DB.iter().map(|(db, l)| (*db, format!("ISO 14839-3 zone {l} ({db:.1} dB)"))).collect();
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
fn sensitivity_lines(s: &super::SensitivityPart, speed: Option<f64>) -> Vec<Line> {
    let mut lines = Vec::new();
    let at = |a: &&super::sensitivity::AxisResult| speed.is_none_or(|sp| a.speed_hz == sp);
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
fn ladder_charts(dir: &Path, r: &Report) -> Result<Vec<(String, String)>, PlotError> {
    let with: Vec<(usize, &ControllerReport, &super::ladder::LadderResult)> =
        r.controllers.iter().enumerate().filter_map(|(i, c)| c.ladder.result.as_ref().map(|l| (i, c, l))).collect();
    if with.is_empty() {
        return Ok(Vec::new());
    }
    let mut out = Vec::new();
    let series = |f: &dyn Fn(&super::ladder::Rung) -> Option<f64>, dashed: bool, suffix: &str| -> Vec<Line> {
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
                    .map(|x| (x.peak_g, x.tally.p_lo, x.tally.p_hi))
                    .collect(),
            )
        })
        .collect();
    // A ladder interrupted or stopped before any member was counted has nothing to draw.
    let lines = series(&|x| Some(x.tally.p_recovered), false, "");
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
    let mut lines = series(&|x| x.tally.recovery_median_s.map(|v| v * 1e3), false, " median");
    lines.extend(series(&|x| x.tally.recovery_p90_s.map(|v| v * 1e3), true, " p90"));
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

/// The class (colour) of a highest safe shock of `g` (G): `ok` (green) from the duty rung
/// `duty_g` up, `low` (amber) below it; none at all is `bad` (red).
pub fn safe_class(g: f64, duty_g: f64) -> &'static str {
    if g + 1e-9 >= duty_g {
        "ok"
    } else {
        "low"
    }
}

/// What the report's words, abbreviations and colours mean: the page reads without the guide.
fn legend(r: &Report) -> String {
    let min_p = r.ladder_settings.min_p;
    let duty_g = r.ladder_settings.duty_g;
    let mut h = String::from("<h2>How to read this report</h2>\n<dl class=\"note\">\n");
    let mut item = |term: &str, text: String| {
        let _ = writeln!(h, "<dt>{term}</dt><dd>{text}</dd>");
    };
    item(
        "Stability margin (ISO 14839-3), zones A–D",
        format!(
            "The plant adds a sine E to the sensor signal the controller reads, one axis at a time; \
             S = (what the controller read) / E is the sensitivity function, T = S − 1. The peak of |S| \
             over frequency grades the axis: zone <b>A</b> |S| &lt; 3 ({:.1} dB), <b>B</b> 3 to 4 ({:.1} dB), \
             <b>C</b> 4 to 5 ({:.1} dB), <b>D</b> 5 or more. <b>unstable</b>: the free decay after an offset grows, \
             so there is no margin to grade. Each axis (x, y; on a two-plane rotor x_A, y_A, x_B, y_B) is \
             measured at standstill and at the rotor's speed (“x at 500 Hz”: axis x, rotor at 500 Hz).",
            ZONE_DB[0].0, ZONE_DB[1].0, ZONE_DB[2].0
        ),
    );
    item(
        "The worst axis in the verdict",
        format!(
            "The worst zone over every axis and speed, then within it the highest peak of |S|; of exactly \
             equal peaks the first measured (x before y, standstill before speed). Axes whose peak lies \
             within {EQUAL_DB} dB of it in the same zone are named after it as its equals (a machine that is \
             the same in x and y, or whose margin does not change with speed, has several)."
        ),
    );
    item(
        "Closed form",
        "|S| computed from the law's equations and the linearised bearing, where the law has them \
         (pd, pd_delay, relev's nominal design, the continuous PD); a controller process is a black box \
         and has none. On a two-plane rotor: plane A's load share as a planar rotor, not the coupled loop."
            .into(),
    );
    item(
        "Gain and phase margins",
        "The loop opened at the axis where the sensitivity is measured, every other axis closed: \
         L = 1/S − 1. PM: the smallest phase margin, at a gain crossover (|L| = 1). GM: the gain margin \
         nearest 0 dB, at a phase crossover (L real and negative); an AMB's open loop is unstable, so its \
         first crossover is at DC with a negative margin (the gain may fall by that much before the rotor \
         drops); a sampled loop adds one above the gain crossover where the gain may rise. <b>computed</b>: \
         the law's linear form on the scene's linear model (<code>plant linear</code>); <b>measured</b>: from \
         the measured S, between the measured frequencies only (DC is not measured)."
            .into(),
    );
    item(
        "Vibration (ISO 14839-2), zones A–D",
        "The levitated rotor at its speed, no shock: the peak of the orbit at the sensor against \
         C<sub>min</sub>, the minimum radial clearance (the touchdown bearing's air gap): zone <b>A</b> below \
         0.3 C<sub>min</sub>, <b>B</b> 0.3 to 0.4, <b>C</b> 0.4 to 0.5, <b>D</b> 0.5 or more. The coil current: \
         its largest swing about the mean and the RMS of the swing, per axis, against the amplifier's limit."
            .into(),
    );
    item(
        "Highest safe shock",
        format!(
            "The ladder runs the scene's shock scaled to each rung's peak (G) over many draws of the rotor's \
             angle; P(recovered) is the share of draws that end back on the orbit, with its Wilson 95 % \
             interval [lower, upper]. The highest safe shock is the highest rung up to which every rung's \
             lower bound is at least {min_p}. Colours: <b class=\"ok\">green</b> at or above the {duty_g} G \
             rung whose duty the verdict gives, <b class=\"low\">amber</b> below it, <b class=\"bad\">red</b> \
             none (not even the first rung)."
        ),
    );
    item(
        "Motion modes (the ladder's counts)",
        "How each draw ends, read over the run's last part: <b>recovered</b> back on its small unbalance \
         orbit, no contact; <b>dry whirl</b> continuous contact, whirling around the clearance circle; \
         <b>rebound</b> repeated impacts; <b>diverged</b> the run failed numerically (also at the \
         reference setting)."
            .into(),
    );
    item(
        "Duty",
        "Per shock, median [90th percentile, p90] over the rung's counted draws: time in contact, peak \
         rotor–race force and its Hertz pressure, the most loaded ball's load and pressure, the friction \
         energy, the race's peak speed and acceleration, and the ball-load cycles whose range reaches the \
         given share of Q₀, one ball's static capacity (the basis is at the end of the page)."
            .into(),
    );
    h.push_str("</dl>\n");
    h
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn num(v: Option<f64>, digits: usize) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.digits$}"),
        _ => "–".into(),
    }
}

fn image(dir: &Path, name: &str, alt: &str) -> anyhow::Result<String> {
    let bytes = crate::input::read_bytes(&dir.join(name), crate::input::MAX_JSON_BYTES)
        .with_context(|| format!("reading {name}"))?;
    let data = base64::engine::general_purpose::STANDARD.encode(bytes);
    Ok(format!("<figure><img alt=\"{}\" src=\"data:image/png;base64,{data}\"><figcaption>{} (<code>{name}</code>)</figcaption></figure>\n", esc(alt), esc(alt)))
}

/// Writes `report.json`, the charts and `report.html` into `dir`.
pub fn write(dir: &Path, r: &Report) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    // No folder of this machine in the report: each is shown relative to where the command ran.
    let json = super::relative_text(&serde_json::to_string_pretty(r)?, &r.roots);
    crate::outfile::write(&dir.join("report.json"), json.as_bytes())?;
    let mut charts: Vec<(usize, String)> = Vec::new();
    for (i, c) in r.controllers.iter().enumerate() {
        let name = format!("sensitivity_{}.png", i + 1);
        if sensitivity_chart(&dir.join(&name), c)? {
            charts.push((i, name));
        }
    }
    let ladder = ladder_charts(dir, r)?;
    let mut h = head(r);
    h.push_str(&verdict::table(r));
    h.push_str(&legend(r));
    ladder_table::section(&mut h, dir, r, &ladder)?;
    if !charts.is_empty() {
        let _ = writeln!(h, "<h2>Sensitivity functions</h2><p class=\"note\">Measured by adding a sine to the sensor signal the controller reads, one axis at a time (stepped sine, settled, fitted by least squares over whole periods; docs/guide/assess.md). Horizontal lines: the zone boundaries at |S| = 3, 4, 5 (9.5, 12, 14 dB). Dashed black: the closed form of the law where it has one.</p>");
        for (i, name) in &charts {
            h.push_str(&image(dir, name, &format!("{}: |S| and |T|", r.controllers[*i].label))?);
        }
    }
    h.push_str(&super::loop_charts::section(dir, r)?);
    if let Some(b) = &r.bearing {
        h.push_str(&duty_basis(b));
    }
    let _ = writeln!(h, "<p class=\"note\">Every figure is in <code>report.json</code>.</p></body></html>");
    let h = super::relative_text(&h, &r.roots);
    crate::outfile::write(&dir.join("report.html"), h.as_bytes())?;
    Ok(())
}

/// The page's head, title and the line saying what was run and where.
fn head(r: &Report) -> String {
    let mut h = String::new();
    let title = format!("Controller assessment: {}", r.scene);
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title>\n<style>\
body{{font-family:sans-serif;max-width:1250px;margin:1.5em auto;padding:0 1em;color:#222;line-height:1.4}}\
table{{border-collapse:collapse;margin:.8em 0;font-size:.92em}}td,th{{border:1px solid #bbb;padding:.3em .55em;text-align:left;vertical-align:top}}\
th{{background:#f1f1f1}}.verdict td{{font-weight:600}}.bad{{color:#b00020}}.ok{{color:#126b12}}\
figure{{margin:1em 0}}img{{max-width:100%;border:1px solid #ddd}}figcaption{{font-size:.9em;color:#555}}code{{font-size:.92em}}\
.note{{font-size:.9em;color:#444}}.low{{color:#a65c00}}dt{{font-weight:600;margin-top:.4em}}dd{{margin-left:1.5em}}</style></head><body>\n<h1>{}</h1>\n",
        esc(&title),
        esc(&title)
    );
    let _ = writeln!(
        h,
        "<p class=\"note\">{} · file <code>{}</code> · scene <code>{}</code> · written to <code>{}</code> (paths relative to where the command ran) · parts: {} · {:.0} s{}</p>",
        esc(&r.program),
        esc(&r.file),
        esc(&r.scene),
        esc(&r.out),
        r.parts.join(", "),
        r.wall_s,
        if r.interrupted {
            " · <span class=\"bad\">INTERRUPTED: the parts marked so were not measured</span>"
        } else {
            ""
        }
    );
    for w in &r.warnings {
        let _ = writeln!(h, "<p class=\"bad\"><b>Warning:</b> {}</p>", esc(w));
    }
    h
}

/// The note under the duty figures: what each one rests on.
fn duty_basis(b: &super::duty::Bearing) -> String {
    let mut h = String::new();
    let _ = writeln!(h, "<h2>Basis of the duty figures</h2><p class=\"note\">Taken at the output samples of each member's run. Rotor–race pressure: Hertz line contact of the shaft in the bore over the race width ({:.1} mm), steel E = {:.0} GPa, ν = {}; with a very conformal contact the half-width is not small against the radius, so it is Hertz's estimate outside its strict validity. Ball pressure: Hertz point contact of the most loaded ball on the inner raceway (ball {:.2} mm, pitch diameter {:.1} mm, groove conformity {}). Static capacity of one ball Q₀ = {:.0} N (the load giving {:.0} MPa, ISO 76's basis; C₀ = Z Q₀/5). Ball-load cycles: rainflow count of each ball's load, cycles with a range ≥ {:.0} % of Q₀, summed over the balls. Friction energy: ∫ |μ N v_slip| dt at the rotor–race contact. None of these figures is a life.</p>",
            b.width_m * 1e3, b.materials.youngs_modulus_pa * 1e-9, b.materials.poisson, b.ball_diameter_m * 1e3, b.pitch_diameter_m * 1e3, b.materials.groove_conformity, b.ball_static_load_n, b.materials.static_pressure_pa * 1e-6, b.capacity_fraction * 100.0);
    h
}

#[cfg(test)]
mod tests {
    use super::super::sensitivity::{AxisResult, Peak};
    use super::{safe_class, worst_axis};

    fn axis(name: &str, speed_hz: f64, zone: &str, s_db: Option<f64>) -> AxisResult {
        AxisResult {
            axis: name.into(),
            speed_hz,
            stable: s_db.is_some(),
            decay_per_s: 1.0,
            probe_hz: 47.0,
            note: None,
            points: Vec::new(),
            peak: s_db.map(|s_db| Peak { f_hz: 47.0, s_abs: 10f64.powf(s_db / 20.0), s_db, spacing: 0.002 }),
            zone: zone.into(),
            simulated_s: 1.0,
        }
    }

    /// The worst axis: the worst zone, then the highest peak, of exact equals the first; the
    /// others of its zone within `EQUAL_DB` are its equals, a lower zone never is.
    #[test]
    fn the_worst_axis_and_its_equals() {
        let axes = [
            axis("x", 0.0, "D", Some(37.10)),
            axis("y", 0.0, "D", Some(37.12)),
            axis("x", 500.0, "D", Some(37.12)),
            axis("y", 500.0, "D", Some(36.0)),
            axis("x_B", 0.0, "C", Some(37.11)),
        ];
        let (w, equals) = worst_axis(&axes).expect("worst");
        assert_eq!((w.axis.as_str(), w.speed_hz), ("y", 0.0));
        let names: Vec<(&str, f64)> = equals.iter().map(|a| (a.axis.as_str(), a.speed_hz)).collect();
        assert_eq!(names, [("x", 0.0), ("x", 500.0)]);
        // A higher zone wins over a higher peak.
        let axes = [axis("x", 0.0, "B", Some(11.0)), axis("y", 0.0, "C", Some(12.5))];
        assert_eq!(worst_axis(&axes).expect("worst").0.axis, "y");
        assert!(worst_axis(&[]).is_none());
    }

    /// Green only from the duty rung up: 1 G against a 10 G duty rung is not green.
    #[test]
    fn the_highest_safe_shock_is_coloured_by_its_value() {
        assert_eq!(safe_class(1.0, 10.0), "low");
        assert_eq!(safe_class(7.0, 10.0), "low");
        assert_eq!(safe_class(10.0, 10.0), "ok");
        assert_eq!(safe_class(20.0, 10.0), "ok");
    }
}
