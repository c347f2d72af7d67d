//! The verdict line of a controller: its worst axis (and that axis' equals), the vibration
//! zone, the highest safe shock and the duty at the duty rung, in words.

use super::super::ladder::{LadderResult, Rung};
use super::super::sensitivity::AxisResult;
use super::super::ControllerReport;

/// Peaks of `|S|` within this many dB of the worst one are named as its equals.
pub const EQUAL_DB: f64 = 0.05;

/// The worst measured axis (the worst zone, then the highest peak; of equals the first in the
/// order measured: x, y, at standstill then at speed) and the others in its zone whose peak lies
/// within [`EQUAL_DB`] of its own.
pub fn worst_axis(axes: &[AxisResult]) -> Option<(&AxisResult, Vec<&AxisResult>)> {
    let rank = |a: &AxisResult| match a.zone.as_str() {
        "A" => 0,
        "B" => 1,
        "C" => 2,
        "D" => 3,
        _ => 4,
    };
    let peak = |a: &AxisResult| a.peak.as_ref().map_or(f64::NEG_INFINITY, |p| p.s_db);
    let mut worst: Option<&AxisResult> = None;
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
                rung.tally.share.value,
                rung.tally.share.lo,
                rung.tally.share.hi,
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
        format!(
            "{}/{} recovered, [{:.2}, {:.2}]",
            x.tally.recovered, x.tally.members, x.tally.share.lo, x.tally.share.hi
        )
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
