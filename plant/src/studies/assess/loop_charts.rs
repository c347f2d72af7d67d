//! The open loop's Bode and Nyquist charts on the report card (issue 39 item 3): for each
//! controller, `open_loop_N.png`, each measured axis' open loop `G_o` (the margins' loop, every
//! other axis closed, in the negative-feedback form: `S = 1/(1 + G_o)`), the closed form (the
//! law's linear form on the linear plant, [`super::margins::AxisMargins::open_loop`]) as a line
//! and the measured points (`G_o = 1/S − 1` at each measured frequency) as dots on it:
//! magnitude (dB) and phase (degrees, in `(−360°, 0°]` as the phase margin reads it) against
//! frequency, and the Nyquist plot around the critical point −1 with the unit circle.
//! A law without a linear form has its measured points only.

use super::margins::AxisMargins;
use super::sensitivity::AxisResult;
use super::{ControllerReport, Report};
use crate::plot::{
    builder, colour, draw_err, draw_mesh, ensure_font, legend_strip, log_axis, log_ticks, titled_root, Mark, PlotError,
    SeriesStyle, Shape, DASH, WIDE_SIZE,
};
use nalgebra::Complex;
use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::Path;

type C64 = Complex<f64>;

/// The Nyquist plot's window: real part (and the imaginary part, ± its half-span) around −1.
const NYQUIST_RE: (f64, f64) = (-4.0, 2.0);

/// A line's points `(x, y)`.
type Points = Vec<(f64, f64)>;

/// One curve on a panel: the closed form's points and the measured ones.
type Drawn = (Points, Points);

/// What a panel draws beneath the curves (reference lines, the critical point).
type Extras<'e, X, Y> =
    dyn Fn(&mut ChartContext<'_, BitMapBackend<'_>, Cartesian2d<X, Y>>) -> Result<(), PlotError> + 'e;

/// One panel's curves and how to draw them.
struct Panel<'a> {
    /// The axes' labels, x then y.
    labels: (&'a str, &'a str),
    /// Each curve's points.
    data: &'a [Drawn],
    /// A jump in y that breaks a line (a phase wrap); infinite: none.
    jump: f64,
    /// The x axis's tick labels.
    x_ticks: &'a dyn Fn(&f64) -> String,
}

/// One axis at one speed: its label, its closed form `(f, G_o)` and its measured points.
struct Curve {
    label: String,
    closed: Vec<(f64, C64)>,
    measured: Vec<(f64, C64)>,
}

/// `arg` in degrees in `(−360°, 0°]`.
fn phase_deg(g: C64) -> f64 {
    let a = g.im.atan2(g.re).to_degrees();
    if a > 0.0 {
        a - 360.0
    } else {
        a
    }
}

fn db(g: C64) -> f64 {
    20.0 * g.norm().log10()
}

fn curves(c: &ControllerReport) -> Vec<Curve> {
    let Some(s) = &c.sensitivity.result else { return Vec::new() };
    s.axes
        .iter()
        .filter(|a| a.stable && !a.points.is_empty())
        .map(|a: &AxisResult| {
            let m: Option<&AxisMargins> = s.margins.iter().find(|m| m.axis == a.axis && m.speed_hz == a.speed_hz);
            let measured = a
                .points
                .iter()
                .map(|p| (p.f_hz, C64::new(p.s[0], p.s[1])))
                .filter(|(_, s)| s.norm() > 0.0)
                .map(|(f, s)| (f, C64::new(1.0, 0.0) / s - 1.0))
                .collect();
            Curve {
                label: format!("{} at {:.0} Hz", a.axis, a.speed_hz),
                closed: m.map(|m| m.open_loop.clone()).unwrap_or_default(),
                measured,
            }
        })
        .collect()
}

/// Splits a polyline where it leaves `keep` or jumps by more than `jump` in y (a phase wrap),
/// so no segment is drawn across.
fn segments(points: &[(f64, f64)], keep: &dyn Fn(&(f64, f64)) -> bool, jump: f64) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    for p in points {
        let ok = p.0.is_finite() && p.1.is_finite() && keep(p);
        if !ok || cur.last().is_some_and(|q| (q.1 - p.1).abs() > jump) {
            if cur.len() > 1 {
                out.push(std::mem::take(&mut cur));
            }
            cur.clear();
        }
        if ok {
            cur.push(*p);
        }
    }
    if cur.len() > 1 {
        out.push(cur);
    }
    out
}

/// One panel: each curve's closed form as lines and its measured points as dots.
fn panel<X, Y>(
    area: &crate::plot::Area<'_>,
    path: &Path,
    (x, y): (X, Y),
    p: &Panel<'_>,
    extras: &Extras<'_, X, Y>,
) -> Result<(), PlotError>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let (xr, yr) = (x.range(), y.range());
    let mut c = builder(area).build_cartesian_2d(x, y).map_err(draw_err(path))?;
    let fy = |v: &f64| format!("{v}");
    draw_mesh(&mut c, p.labels.0, p.labels.1, p.x_ticks, &fy, path)?;
    extras(&mut c)?;
    let inside = |p: &(f64, f64)| p.0 >= xr.start && p.0 <= xr.end && p.1 >= yr.start && p.1 <= yr.end;
    for (i, (closed, measured)) in p.data.iter().enumerate() {
        let col = colour(i);
        let style = col.stroke_width(2);
        for seg in segments(closed, &inside, p.jump) {
            if dashed(i) {
                c.draw_series(DashedLineSeries::new(seg, DASH.0, DASH.1, style)).map_err(draw_err(path))?;
            } else {
                c.draw_series(LineSeries::new(seg, style)).map_err(draw_err(path))?;
            }
        }
        c.draw_series(measured.iter().filter(|p| inside(p)).map(|p| Circle::new(*p, dot_radius(i), col.filled())))
            .map_err(draw_err(path))?;
    }
    Ok(())
}

/// Curves of a symmetric rotor lie on each other (x and y, or two speeds): every other one's
/// line is dashed and each one's dots are smaller than the one's before, so that those beneath
/// still show.
fn dashed(i: usize) -> bool {
    i % 2 == 1
}

fn dot_radius(i: usize) -> i32 {
    (7 - i as i32).max(3)
}

/// The legend above the three panels: each curve (its closed form a line, its measured points
/// dots on it), then the reference lines, named for what they are.
fn legend(curves: &[Curve]) -> Vec<(String, Mark)> {
    let grey = RGBColor(150, 150, 150);
    curves
        .iter()
        .enumerate()
        .map(|(i, k)| {
            if k.closed.is_empty() {
                (format!("{}: measured (no closed form)", k.label), Mark::Marker(colour(i), Shape::Circle))
            } else {
                let style = SeriesStyle { colour: colour(i), dashed: dashed(i) };
                (format!("{}: closed form (line), measured (dots)", k.label), style.mark_with(Shape::Circle))
            }
        })
        .chain([
            ("0 dB and −180°: the margins' crossings".to_string(), Mark::Line(BLACK)),
            ("unit circle |G_o| = 1".to_string(), Mark::Line(grey)),
            ("critical point −1".to_string(), Mark::Cross(BLACK)),
        ])
        .collect()
}

/// `open_loop_N.png` of one controller: Bode magnitude and phase on the left, Nyquist on the
/// right. `false` (nothing written) where no axis was measured stable.
fn chart(path: &Path, c: &ControllerReport) -> Result<bool, PlotError> {
    let curves = curves(c);
    if curves.is_empty() {
        return Ok(false);
    }
    let map = |f: &dyn Fn(f64, C64) -> (f64, f64)| -> Vec<Drawn> {
        curves
            .iter()
            .map(|k| {
                (k.closed.iter().map(|(x, g)| f(*x, *g)).collect(), k.measured.iter().map(|(x, g)| f(*x, *g)).collect())
            })
            .collect()
    };
    let mag = map(&|f, g| (f, db(g)));
    let phase = map(&|f, g| (f, phase_deg(g)));
    let nyq = map(&|_, g| (g.re, g.im));
    let all = |d: &[Drawn]| -> Points {
        d.iter().flat_map(|(a, b)| a.iter().chain(b).copied()).filter(|p| p.0.is_finite() && p.1.is_finite()).collect()
    };
    let (f0, f1) = all(&mag).iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.0), b.max(p.0)));
    if !(f0.is_finite() && f0 > 0.0 && f1 > f0) {
        return Ok(false);
    }
    let (m0, m1) = all(&mag).iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.1), b.max(p.1)));
    // Magnitude: at most 60 dB below 0 dB shown (a roll-off far down says nothing of margins).
    let (m0, m1) = ((m0.max(-60.0) - 3.0).min(-6.0), (m1 + 3.0).max(6.0));
    let half = (NYQUIST_RE.1 - NYQUIST_RE.0) / 2.0;
    ensure_font(path)?;
    crate::plot::draw_png(path, (WIDE_SIZE.0 * 3 / 2, WIDE_SIZE.1), |root| {
        let area = titled_root(root, path, &format!("{}: open loop G_o per axis (S = 1/(1 + G_o))", c.label))?;
        let area = legend_strip(&area, &legend(&curves), path)?;
        let (left, right) = area.split_horizontally(WIDE_SIZE.0 * 3 / 4 + 60);
        let (top, bottom) = left.split_vertically(left.dim_in_pixel().1 / 2);
        let log = || log_axis(f0, f1);
        let lin = |a: f64, b: f64| -> plotters::coord::types::RangedCoordf64 { (a..b).into() };
        panel(
            &top,
            path,
            (log(), lin(m0, m1)),
            &Panel { labels: ("frequency (Hz)", "|G_o| (dB)"), data: &mag, jump: f64::INFINITY, x_ticks: &log_ticks },
            &|c| {
                c.draw_series(std::iter::once(PathElement::new(vec![(f0, 0.0), (f1, 0.0)], BLACK.stroke_width(1))))
                    .map_err(draw_err(path))?;
                Ok(())
            },
        )?;
        panel(
            &bottom,
            path,
            (log(), lin(-360.0, 0.0)),
            &Panel { labels: ("frequency (Hz)", "arg G_o (°)"), data: &phase, jump: 180.0, x_ticks: &log_ticks },
            &|c| {
                c.draw_series(std::iter::once(PathElement::new(
                    vec![(f0, -180.0), (f1, -180.0)],
                    BLACK.stroke_width(1),
                )))
                .map_err(draw_err(path))?;
                Ok(())
            },
        )?;
        panel(
            &right,
            path,
            (lin(NYQUIST_RE.0, NYQUIST_RE.1), lin(-half, half)),
            &Panel {
                labels: ("Re G_o", "Im G_o"),
                data: &nyq,
                jump: f64::INFINITY,
                x_ticks: &|v: &f64| format!("{v}"),
            },
            &|c| {
                let circle: Vec<(f64, f64)> =
                    (0..=180).map(|i| i as f64 * std::f64::consts::TAU / 180.0).map(|t| (t.cos(), t.sin())).collect();
                c.draw_series(std::iter::once(PathElement::new(circle, RGBColor(150, 150, 150).stroke_width(1))))
                    .map_err(draw_err(path))?;
                c.draw_series(std::iter::once(Cross::new((-1.0, 0.0), 8, BLACK.stroke_width(2))))
                    .map_err(draw_err(path))?;
                Ok(())
            },
        )?;
        Ok::<(), PlotError>(())
    })?;
    Ok(true)
}

/// Writes each controller's `open_loop_N.png` into `dir` and returns the report's section
/// embedding them (empty where nothing was measured).
pub fn section(dir: &Path, r: &Report) -> anyhow::Result<String> {
    let mut h = String::new();
    let head = |h: &mut String| {
        if h.is_empty() {
            let _ = writeln!(
                h,
                "<h2>Open loop: Bode and Nyquist</h2><p class=\"note\">Each measured axis' open loop \
                 G<sub>o</sub>, every other axis closed (S = 1/(1 + G<sub>o</sub>)): lines, the closed \
                 form (the law's linear form on the linear plant; none for a law without one); dots, the \
                 measured points (G<sub>o</sub> = 1/S − 1). The gain margin is read where the phase \
                 crosses −180°, the phase margin where |G<sub>o</sub>| crosses 0 dB; on the Nyquist plot, \
                 the distance to −1 (the cross), with the unit circle. An AMB's open loop is unstable: its \
                 Nyquist plot starts on the negative real axis left of −1.</p>"
            );
        }
    };
    for (i, c) in r.controllers.iter().enumerate() {
        // Said whether or not the loop was measured stable.
        let unstable =
            c.sensitivity.result.as_ref().and_then(|s| s.margins.first()).map_or(0, |m| m.law_unstable_poles);
        if unstable > 0 {
            head(&mut h);
            let _ = writeln!(
                h,
                "<p class=\"note\"><b>{}: an unstable controller</b>: its linear form has {unstable} pole(s) \
                 outside the unit circle (allowed: some designs are; the loop's stability is the sensitivity's \
                 and the Nyquist plot's).</p>",
                c.label.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
            );
        }
        let name = format!("open_loop_{}.png", i + 1);
        if chart(&dir.join(&name), c)? {
            head(&mut h);
            h.push_str(&image(dir, &name, &format!("{}: open loop, Bode and Nyquist", c.label))?);
        }
    }
    Ok(h)
}

/// The chart embedded as a data URI, as the report's other figures are (a copy of
/// `report.rs`'s private `image`: that file is being split, and the report's hook for these
/// charts is kept to one call).
fn image(dir: &Path, name: &str, alt: &str) -> anyhow::Result<String> {
    use anyhow::Context;
    use base64::Engine;
    let bytes = crate::input::read_bytes(&dir.join(name), crate::input::MAX_JSON_BYTES)
        .with_context(|| format!("reading {name}"))?;
    let data = base64::engine::general_purpose::STANDARD.encode(bytes);
    let alt = alt.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;");
    Ok(format!(
        "<figure><img alt=\"{alt}\" src=\"data:image/png;base64,{data}\"><figcaption>{alt} (<code>{name}</code>)</figcaption></figure>\n"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_phase_is_read_in_minus_360_to_0_and_lines_break_at_wraps_and_edges() {
        assert_eq!(phase_deg(C64::new(-1.0, 0.0)), 180.0 - 360.0);
        assert!((phase_deg(C64::new(0.0, 1.0)) + 270.0).abs() < 1e-12);
        assert!((phase_deg(C64::new(0.0, -1.0)) + 90.0).abs() < 1e-12);
        assert!((db(C64::new(0.0, 10.0)) - 20.0).abs() < 1e-12);
        // A wrap from −350° to −10° and a point out of the window each end a segment.
        let pts = [(1.0, -300.0), (2.0, -350.0), (3.0, -10.0), (4.0, -20.0), (5.0, 99.0), (6.0, -30.0), (7.0, -40.0)];
        let segs = segments(&pts, &|p| p.1 <= 0.0, 180.0);
        assert_eq!(
            segs,
            vec![
                vec![(1.0, -300.0), (2.0, -350.0)],
                vec![(3.0, -10.0), (4.0, -20.0)],
                vec![(6.0, -30.0), (7.0, -40.0)]
            ]
        );
    }
}
