//! The report's shock-ladder section: one table per controller (a row per rung, and the
//! two-plane rotor's bearings under it), then the ladder's charts.

use super::super::Report;
use super::{esc, image, num};
use std::fmt::Write as _;
use std::path::Path;

/// The ladder section, where any controller has a ladder; `charts` are the (file, caption) pairs
/// already drawn into `dir`.
pub(super) fn section(h: &mut String, dir: &Path, r: &Report, charts: &[(String, String)]) -> anyhow::Result<()> {
    if !r.controllers.iter().any(|c| c.ladder.result.is_some()) {
        return Ok(());
    }
    let _ = writeln!(h, "<h2>Shock ladder and the touchdown bearing's duty</h2>");
    let _ = writeln!(h, "<p class=\"note\">Each rung is an ensemble over the rotor's angle at the shock's arrival; P(recovered) with its Wilson 95 % interval; recovery time from the shock's start to the last contact (median, p90); the duty per shock, median [p90] over the counted members. Members' setting: {}.</p>",
            esc(&r.controllers.iter().find_map(|c| c.ladder.result.as_ref().map(|l| l.member_setting.clone())).unwrap_or_default()));
    for c in r.controllers.iter() {
        let Some(l) = &c.ladder.result else { continue };
        let _ = writeln!(h, "<h3>{}</h3><table><tr><th>peak (G)</th><th>members</th><th>P(recovered) [95 %]</th><th>recovered / dry whirl / rebound / diverged</th><th>recovery median / p90 (ms)</th><th>contact (ms)</th><th>peak force (N)</th><th>rotor–race pressure (MPa)</th><th>most loaded ball (N / MPa)</th><th>friction energy (J)</th><th>race peak speed (rpm)</th><th>race peak accel. (krad/s²)</th><th>ball-load cycles ≥ {:.0} % Q₀</th></tr>",
                esc(&c.label), r.bearing.map_or(50.0, |b| b.capacity_fraction * 100.0));
        let mp = |s: &crate::assess::ladder::Spread, k: f64, dig: usize| {
            format!("{} [{}]", num(s.median.map(|v| v * k), dig), num(s.p90.map(|v| v * k), dig))
        };
        // The duty's cells of one rung (or of one of the two-plane rotor's bearings).
        let duty_cells = |d: &crate::assess::ladder::RungDuty| {
            format!(
                "<td>{}</td><td>{}</td><td>{}</td><td>{} / {}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>",
                mp(&d.contact_time_s, 1e3, 1),
                mp(&d.peak_contact_force_n, 1.0, 0),
                mp(&d.peak_race_pressure_mpa, 1.0, 0),
                num(d.peak_ball_load_n.median, 0),
                num(d.peak_ball_pressure_mpa.median, 0),
                mp(&d.friction_energy_j, 1.0, 2),
                mp(&d.race_peak_speed_rpm, 1.0, 0),
                mp(&d.race_peak_accel_rad_s2, 1e-3, 0),
                mp(&d.ball_cycles, 1.0, 1),
            )
        };
        for x in &l.rungs {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}{}</td><td>{:.2} [{:.2}, {:.2}]</td><td>{}/{}/{}/{}</td><td>{} / {}</td>{}</tr>",
                x.peak_g,
                x.tally.members,
                if x.complete { "" } else { " (incomplete)" },
                x.tally.share.value,
                x.tally.share.lo,
                x.tally.share.hi,
                x.tally.recovered,
                x.tally.dry_whirl,
                x.tally.rebound,
                x.tally.diverged,
                num(x.tally.recovery.median_s.map(|v| v * 1e3), 1),
                num(x.tally.recovery.p90_s.map(|v| v * 1e3), 1),
                duty_cells(&x.duty),
            );
            // The two-plane rotor: each touchdown bearing's own duty under the rung's
            // (which holds, figure by figure, the larger of the two).
            for (k, d) in x.duty_planes.iter().enumerate() {
                let _ = writeln!(
                    h,
                    "<tr class=\"note\"><td></td><td colspan=\"4\">touchdown bearing {}</td>{}</tr>",
                    ["A", "B"][k.min(1)],
                    duty_cells(d)
                );
            }
        }
        let _ = writeln!(h, "</table>");
        h.push_str(
            &l.robustness.as_ref().map_or(String::new(), |x| crate::assess::ladder::robustness_html(x, l.safe_up_to_g)),
        );
    }
    for (name, alt) in charts {
        h.push_str(&image(dir, name, alt)?);
    }
    Ok(())
}
