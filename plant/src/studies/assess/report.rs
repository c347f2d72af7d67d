//! The assessment's outputs: `report.json` (every figure), the charts as PNG, and
//! `report.html`, one self-contained page (the charts embedded as data URIs, no script, no
//! network) with the verdict line of each controller at the top, one column each.
//!
//! By section: `verdict_line` the verdict in words, `verdict` its table, `legend` how to read
//! the page, `ladder_table` the shock ladder, `charts` the PNGs; this file writes them in order.

mod charts;
mod ladder_table;
mod legend;
mod verdict;
mod verdict_line;

use charts::{ladder_charts, sensitivity_chart};
use legend::legend;
pub use verdict_line::{verdict, worst_axis, EQUAL_DB};

use super::Report;
use anyhow::Context;
use base64::Engine;
use std::fmt::Write as _;
use std::path::Path;

/// The ISO 14839-3 zone boundaries of the peak sensitivity in dB, each named, from the grading's
/// own limits ([`super::sensitivity::ZONE_LIMITS`]), so the lines drawn are the ones graded by.
fn zone_db() -> [(f64, &'static str); 3] {
    let [ab, bc, cd] = super::sensitivity::ZONE_LIMITS.map(|s| 20.0 * s.log10());
    [(ab, "A/B"), (bc, "B/C"), (cd, "C/D")]
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
        // The boundaries as the grading has them: |S| = 3, 4, 5 (9.5, 12, 14 dB).
        let short = |v: f64| format!("{v:.1}").trim_end_matches(".0").to_string();
        let limits = super::sensitivity::ZONE_LIMITS.map(short).join(", ");
        let dbs = zone_db().map(|(db, _)| short(db)).join(", ");
        let _ = writeln!(h, "<h2>Sensitivity functions</h2><p class=\"note\">Measured by adding a sine to the sensor signal the controller reads, one axis at a time (stepped sine, settled, fitted by least squares over whole periods; docs/guide/assess.md). Horizontal lines: the zone boundaries at |S| = {limits} ({dbs} dB). Dashed black: the closed form of the law where it has one.</p>");
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
    use super::super::sensitivity::{zone, AxisResult, Peak};
    use super::{safe_class, worst_axis, zone_db};

    /// Each zone line the report draws is where the grading changes zone, and is named for the
    /// pair of zones on its two sides (a peak 0.001 dB below is graded in the first, above in the
    /// second), and they are the standard's 9.5, 12 and 14 dB to the drawn precision.
    #[test]
    fn the_zone_lines_are_the_grading_boundaries() {
        let lines = zone_db();
        for (db, name) in lines {
            let graded = |d: f64| zone(10f64.powf(d / 20.0));
            assert_eq!(format!("{}/{}", graded(db - 1e-3), graded(db + 1e-3)), name, "line at {db} dB");
        }
        let shown: Vec<String> = lines.iter().map(|(db, _)| format!("{db:.1}")).collect();
        assert_eq!(shown, ["9.5", "12.0", "14.0"]);
    }

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
