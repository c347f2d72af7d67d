//! The soak's charts: radius envelope with the shock starts, recovery time
//! and largest force per shock against the peak, resident memory.

use super::monitor::{EnvelopeRow, ShockFigures};
use super::programme::Programme;
use super::sink::RssSample;
use crate::plot::{self, PointGroup, Scale, Series};
use std::path::Path;

/// The charts a soak draws into its folder: these here and `tet.png` (the plant's execution
/// time per tick, a co-simulated soak's). A new soak removes an earlier soak's first.
pub(crate) const CHARTS: &[&str] = &["radius.png", "recovery.png", "max_force.png", "rss.png", "tet.png"];

/// Reads `envelope.csv` back (written by this module, through the `csv` crate), by column name.
fn read_envelope(path: &Path) -> anyhow::Result<Vec<EnvelopeRow>> {
    crate::table::read(path)
}

pub(crate) fn write_plots(
    dir: &Path,
    prog: &Programme,
    figures: &[ShockFigures],
    rss: &[RssSample],
) -> anyhow::Result<()> {
    let name = &prog.name;
    let scene = &prog.scene;
    // Each plane's gap and clear radius: one line each where the planes' differ.
    let gaps_um: Vec<f64> = (0..scene.planes()).map(|i| scene.plane(i).contact.gap * 1e6).collect();
    let gap_um = gaps_um[0];
    let env = read_envelope(&dir.join("envelope.csv"))?;
    if env.is_empty() {
        return Ok(());
    }
    let t: Vec<f64> = env.iter().map(|r| r.t_s).collect();
    let r_um: Vec<f64> = env.iter().map(|r| r.max_radius_m * 1e6).collect();
    let two = gaps_um.len() == 2 && gaps_um[0] != gaps_um[1];
    let gap_lines: Vec<Vec<f64>> = gaps_um.iter().map(|g| vec![*g; t.len()]).collect();
    let clear_lines: Vec<Vec<f64>> = prog.clear_radius.iter().map(|c| vec![c * 1e6; t.len()]).collect();
    let t_end = t.last().copied().unwrap_or(0.0);
    let (mut mx, mut my) = (Vec::new(), Vec::new());
    for s in prog.shocks.iter().filter(|s| s.start_s <= t_end) {
        mx.extend([s.start_s, s.start_s, f64::NAN]);
        // A short tick below the zero line, drawn first so the radius stays on top.
        my.extend([-0.1 * gap_um, 0.0, f64::NAN]);
    }
    let mut series = Vec::new();
    if !mx.is_empty() {
        series.push(Series { label: "shock start", x: &mx, y: &my });
    }
    series.push(Series { label: "rotor radius (max per 5 ms)", x: &t, y: &r_um });
    if two {
        series.extend([
            Series { label: "air gap r0 at A", x: &t, y: &gap_lines[0] },
            Series { label: "air gap r0 at B", x: &t, y: &gap_lines[1] },
            Series { label: "clear radius at A", x: &t, y: &clear_lines[0] },
            Series { label: "clear radius at B", x: &t, y: &clear_lines[1] },
        ]);
    } else {
        series.extend([
            Series { label: "air gap r0", x: &t, y: &gap_lines[0] },
            Series { label: "clear radius", x: &t, y: &clear_lines[0] },
        ]);
    }
    plot::lines(
        &dir.join("radius.png"),
        &format!("{name} — rotor radius through the soak"),
        "time (s)",
        "radius (µm)",
        &series,
        Scale::Linear,
    )?;

    if !figures.is_empty() {
        let split = |f: &dyn Fn(&ShockFigures) -> f64, recovered: bool| -> (Vec<f64>, Vec<f64>) {
            figures
                .iter()
                .filter(|s| s.recovered == recovered)
                .map(|s| (prog.shocks[s.index].peak_g, f(s)))
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .unzip()
        };
        let (rx, ry) = split(&|s| s.recovery_s, true);
        let (nx, ny) = split(&|s| s.end_s - s.start_s, false);
        let groups = [
            PointGroup { label: "recovered: recovery time", x: &rx, y: &ry },
            PointGroup { label: "not recovered: drawn at its window length", x: &nx, y: &ny },
        ];
        let groups: Vec<PointGroup> = groups.into_iter().filter(|g| !g.x.is_empty()).collect();
        if !groups.is_empty() {
            plot::scatter(
                &dir.join("recovery.png"),
                &format!("{name} — time to recover per shock"),
                "shock peak (G)",
                "time from shock start (s)",
                &groups,
                false,
            )?;
        }
        let (fx, fy) = split(&|s| s.max_contact_force_n, true);
        let (gx, gy) = split(&|s| s.max_contact_force_n, false);
        let groups =
            [PointGroup { label: "recovered", x: &fx, y: &fy }, PointGroup { label: "not recovered", x: &gx, y: &gy }];
        let groups: Vec<PointGroup> = groups.into_iter().filter(|g| !g.x.is_empty()).collect();
        plot::scatter(
            &dir.join("max_force.png"),
            &format!("{name} — largest contact force per shock"),
            "shock peak (G)",
            "max contact force (N)",
            &groups,
            false,
        )?;
    }

    let mib = |v: Option<u64>| v.map_or(f64::NAN, |k| k as f64 / 1024.0);
    let ts: Vec<f64> = rss.iter().map(|s| s.t_s).collect();
    let plant: Vec<f64> = rss.iter().map(|s| mib(s.plant_kib)).collect();
    let ctl: Vec<f64> = rss.iter().map(|s| mib(s.controller_kib)).collect();
    if ts.len() > 1 {
        plot::lines(
            &dir.join("rss.png"),
            &format!("{name} — resident memory"),
            "simulated time (s)",
            "RSS (MiB)",
            &[Series { label: "plant", x: &ts, y: &plant }, Series { label: "controller", x: &ts, y: &ctl }],
            Scale::Linear,
        )?;
    }
    Ok(())
}
