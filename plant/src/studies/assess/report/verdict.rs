//! The report's verdict table: one column per controller, one row per figure, each cell
//! written by a function of its own.

use super::super::{ControllerReport, Report};
use super::{esc, num, safe_class};
use std::fmt::Write as _;

/// The verdict table (`<h2>` to `</table>`).
pub(super) fn table(r: &Report) -> String {
    let mut h = String::new();
    let _ = writeln!(h, "<h2>Verdict</h2>\n<table><tr><th></th>");
    for c in &r.controllers {
        let _ = write!(h, "<th>{}</th>", esc(&c.label));
    }
    let row = |h: &mut String, name: &str, f: &dyn Fn(&ControllerReport) -> String| {
        let _ = write!(h, "<tr><th>{name}</th>");
        for c in &r.controllers {
            let _ = write!(h, "<td>{}</td>", f(c));
        }
        let _ = writeln!(h, "</tr>");
    };
    row(&mut h, "verdict", &|c| format!("<b>{}</b>", esc(&c.verdict)));
    row(&mut h, "law, mode, rate", &|c| format!("{} · {} · {:.0} Hz", esc(&c.law), esc(&c.mode), c.rate_hz));
    row(&mut h, "overrides", &overrides);
    row(&mut h, "stability margin (ISO 14839-3)", &stability);
    row(
        &mut h,
        "gain and phase margins (computed: the law's linear form on the linear plant; measured: L = 1/S − 1)",
        &margins,
    );
    row(&mut h, "closed form (where the law has one; two-plane: plane A's load share alone)", &closed_form);
    row(&mut h, "closed form of the coupled loop (flexible rotor), per axis", &coupled);
    row(&mut h, "vibration (ISO 14839-2)", &vibration);
    row(&mut h, "highest safe shock", &|c| highest_safe(c, r));
    row(&mut h, "wall time", &wall_time);
    let _ = writeln!(h, "</table>");
    h
}

fn overrides(c: &ControllerReport) -> String {
    c.set.iter().map(|s| format!("<code>{}</code>", esc(s))).collect::<Vec<_>>().join("<br>")
}

fn stability(c: &ControllerReport) -> String {
    match &c.sensitivity.result {
        Some(s) => {
            let not_all = match c.sensitivity.status {
                "measured" => String::new(),
                status => format!(
                    "<span class=\"bad\">{status}</span>: {}<br>",
                    esc(c.sensitivity.why.as_deref().unwrap_or(""))
                ),
            };
            not_all
                + &s.axes
                    .iter()
                    .map(|a| match &a.peak {
                        Some(p) if a.stable => format!(
                            "{} at {:.0} Hz: zone <b>{}</b>, |S| {:.2} ({:.2} dB) at {:.2} Hz",
                            a.axis, a.speed_hz, a.zone, p.s_abs, p.s_db, p.f_hz
                        ),
                        _ => format!(
                            "{} at {:.0} Hz: <b class=\"bad\">unstable</b> ({})",
                            a.axis,
                            a.speed_hz,
                            esc(a.note.as_deref().unwrap_or(""))
                        ),
                    })
                    .collect::<Vec<_>>()
                    .join("<br>")
        }
        None => format!(
            "<span class=\"bad\">{}</span>: {}",
            c.sensitivity.status,
            esc(c.sensitivity.why.as_deref().unwrap_or(""))
        ),
    }
}

fn margins(c: &ControllerReport) -> String {
    let all = c.sensitivity.result.as_ref().map(|s| s.margins.as_slice()).unwrap_or_default();
    if all.is_empty() {
        return "–".into();
    }
    let basis = if all.iter().all(|m| m.computed.is_none()) {
        "<span class=\"note\">measured only: the law has no linear form here (a controller process, an FMU, \
             or a law without one)</span><br>"
    } else {
        ""
    };
    basis.to_string()
        + &all
            .iter()
            .map(|m| {
                let computed = m.computed.as_ref().map_or("no linear form".into(), crate::assess::margins::words);
                let measured =
                    m.measured.as_ref().map_or("not measured (unstable)".into(), crate::assess::margins::words);
                format!("{} at {:.0} Hz: computed {computed}; measured {measured}", m.axis, m.speed_hz)
            })
            .collect::<Vec<_>>()
            .join("<br>")
}

fn closed_form(c: &ControllerReport) -> String {
    match c.sensitivity.result.as_ref().and_then(|s| s.closed_form.as_ref()) {
        Some(cf) if cf.stable => {
            format!("zone {}, |S| {} ({} dB) at {} Hz", cf.zone, num(cf.s_abs, 2), num(cf.s_db, 2), num(cf.f_hz, 2))
        }
        Some(_) => "unstable".into(),
        None => "–".into(),
    }
}

fn coupled(c: &ControllerReport) -> String {
    let forms = c.sensitivity.result.as_ref().map(|s| s.closed_form_axes.as_slice()).unwrap_or_default();
    if forms.is_empty() {
        return "–".into();
    }
    forms
        .iter()
        .map(|f| match (f.stable, f.s_db) {
            (true, Some(d)) => format!(
                "{} at {:.0} Hz: zone {}, {:.2} dB at {} Hz{}",
                f.axis,
                f.speed_hz,
                f.zone,
                d,
                num(f.f_hz, 2),
                f.measured_difference_db.map_or(String::new(), |m| format!(" (measured within {m:.2} dB)"))
            ),
            _ => format!("{} at {:.0} Hz: unstable", f.axis, f.speed_hz),
        })
        .collect::<Vec<_>>()
        .join("<br>")
}

fn vibration(c: &ControllerReport) -> String {
    match &c.vibration.result {
        Some(v) if v.planes.len() > 1 => format!(
            "zone <b>{}</b> (plane {}): {} at {:.0} Hz; coil current swing {} A (RMS {} A; x_A / y_A / x_B / y_B) of {:.1} A",
            v.zone,
            v.plane,
            v.planes
                .iter()
                .map(|p| format!(
                    "plane {}: {:.2} µm = {:.3} C_min (C_min = {:.0} µm), zone {}",
                    p.plane, p.peak_um, p.ratio, p.clearance_um, p.zone
                ))
                .collect::<Vec<_>>()
                .join("; "),
            v.speed_hz,
            v.coil.current_swing_a.iter().map(|x| format!("{x:.3}")).collect::<Vec<_>>().join(" / "),
            v.coil.current_rms_a.iter().map(|x| format!("{x:.3}")).collect::<Vec<_>>().join(" / "),
            v.coil.current_limit_a
        ),
        Some(v) => format!(
            "zone <b>{}</b>: {:.2} µm = {:.3} C_min (C_min = {:.0} µm) at {:.0} Hz; coil current swing {} A (RMS {} A) of {:.1} A",
            v.zone,
            v.peak_um,
            v.ratio,
            v.clearance_um,
            v.speed_hz,
            v.coil.current_swing_a.iter().map(|x| format!("{x:.3}")).collect::<Vec<_>>().join(" / "),
            v.coil.current_rms_a.iter().map(|x| format!("{x:.3}")).collect::<Vec<_>>().join(" / "),
            v.coil.current_limit_a
        ),
        None => format!("<span class=\"bad\">{}</span>: {}", c.vibration.status, esc(c.vibration.why.as_deref().unwrap_or(""))),
    }
}

fn highest_safe(c: &ControllerReport, r: &Report) -> String {
    match &c.ladder.result {
        Some(l) if c.ladder.status != "measured" => format!(
            "<span class=\"bad\">{}</span>: {}; the complete rungs: {}",
            c.ladder.status,
            esc(c.ladder.why.as_deref().unwrap_or("")),
            l.safe_up_to_g.map_or("none safe".into(), |g| format!("safe up to {g} G"))
        ),
        Some(l) => match l.safe_up_to_g {
            Some(g) => {
                // Coloured by its value: green only from the duty rung (the design shock) up.
                let class = safe_class(g, r.ladder_settings.duty_g);
                let at = l.rungs.iter().find(|x| x.peak_g == g).map_or(String::new(), |x| {
                    format!(
                        "; at {g} G {}/{} recovered, [{:.2}, {:.2}]",
                        x.tally.recovered, x.tally.members, x.tally.share.lo, x.tally.share.hi
                    )
                });
                format!(
                    "<b class=\"{class}\">{g} G</b> (every rung up to it: lower bound ≥ {}{at})",
                    r.ladder_settings.min_p
                )
            }
            None => {
                let first = l.rungs.iter().find(|x| x.tally.members > 0).map_or(String::new(), |x| {
                    format!(
                        ": at {} G {}/{} recovered, [{:.2}, {:.2}]",
                        x.peak_g, x.tally.recovered, x.tally.members, x.tally.share.lo, x.tally.share.hi
                    )
                });
                format!(
                    "<b class=\"bad\">none</b> (the first rung's lower bound is below {}{first})",
                    r.ladder_settings.min_p
                )
            }
        },
        None => {
            format!("<span class=\"bad\">{}</span>: {}", c.ladder.status, esc(c.ladder.why.as_deref().unwrap_or("")))
        }
    }
}

fn wall_time(c: &ControllerReport) -> String {
    format!(
        "{:.1} s (sensitivity {:.1} s, vibration {:.1} s, ladder {:.1} s)",
        c.wall_s, c.sensitivity.wall_s, c.vibration.wall_s, c.ladder.wall_s
    )
}
