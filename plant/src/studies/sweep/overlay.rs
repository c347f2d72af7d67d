//! `plant overlay`: the recovery probability of several finished ensemble sweeps of one key on
//! one chart, each sweep a curve with its Wilson 95 % intervals as error bars
//! ([`crate::plot::probability`]), and their points in one table.
//!
//! Reads each folder's `sweep.json` (its key, its points' probabilities and intervals, its
//! 0.5 crossings) and `manifest.json` (the axis's spacing); writes `overlay.png` and
//! `overlay.csv` (`label, folder, key, value, members, recovered, p_recovered, p_lo, p_hi,
//! numerically_sensitive`) into `--out`. Bad input, each exit 2 naming the folder: a folder
//! that does not exist, one that is not a finished ensemble sweep (a sweep of single runs has
//! no probabilities; an unmerged one no `sweep.json`), a 2-D map, sweeps of different keys or
//! spacings, a `--label` count that is not the folders'.

use crate::exit::Ending;
use crate::grid::outputs::{csv_writer, e, finish};
use crate::plot::{self, ProbabilityCurve};
use anyhow::Context;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// `plant overlay` arguments.
#[derive(clap::Args, Debug, Clone)]
pub struct OverlayArgs {
    /// Folders of finished ensemble sweeps (`plant sweep` of a file with an `[ensemble]` table)
    /// of the same key, one curve each, in the legend's order.
    #[arg(required = true, value_name = "SWEEP_DIR")]
    pub sweeps: Vec<PathBuf>,
    /// A curve's legend text, one per folder in their order (repeatable; default: the folder's
    /// name).
    #[arg(long = "label", value_name = "TEXT")]
    pub labels: Vec<String>,
    /// The chart's title (default: "probability of recovery against KEY").
    #[arg(long)]
    pub title: Option<String>,
    /// The x axis's label (default: the swept key and its unit).
    #[arg(long)]
    pub x_label: Option<String>,
    /// Draw every curve at its own x values (by default curves are set apart sideways, together
    /// by half the smallest step, so that their error bars do not hide each other; the x label
    /// says by how much).
    #[arg(long)]
    pub no_offset: bool,
    /// Output folder (default: runs/overlay).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// What `plant overlay` reads of a `sweep.json`.
#[derive(Deserialize)]
struct SweepJson {
    kind: String,
    keys: Vec<String>,
    points: Vec<JsonPoint>,
    #[serde(default)]
    thresholds: Vec<JsonThreshold>,
}

/// A point of a `sweep.json`.
#[derive(Deserialize)]
struct JsonPoint {
    value: Option<f64>,
    members: usize,
    recovered: usize,
    p_recovered: f64,
    p_lo: f64,
    p_hi: f64,
    #[serde(default)]
    numerically_sensitive: usize,
}

/// A 0.5 crossing of a `sweep.json`.
#[derive(Deserialize)]
struct JsonThreshold {
    value: f64,
    interval: [f64; 2],
    #[serde(default)]
    open: bool,
}

/// One sweep as read.
struct Curve {
    label: String,
    dir: PathBuf,
    key: String,
    log: bool,
    points: Vec<JsonPoint>,
    thresholds: Vec<JsonThreshold>,
}

fn bad(message: String) -> anyhow::Error {
    Ending::BadArgument(format!("plant overlay: {message}")).into()
}

/// Reads the sweep in `dir`.
fn read_sweep(dir: &Path, label: String) -> anyhow::Result<Curve> {
    let shown = dir.display();
    if !dir.is_dir() {
        return Err(bad(format!("{shown}: no such sweep folder")));
    }
    let json = dir.join("sweep.json");
    if !json.is_file() {
        let why = if dir.join("ensemble.json").is_file() {
            "a single scene's ensemble (ensemble.json), not a sweep: it has one point, no curve"
        } else if dir.join("points.csv").is_file() {
            "a sweep of single runs (points.csv without sweep.json): it has no probability of recovery; give the sweep file an [ensemble] table"
        } else {
            "no sweep.json: not a finished ensemble sweep (plant sweep writes it when every point is decided; --merge)"
        };
        return Err(bad(format!("{shown}: {why}")));
    }
    let text = crate::input::read_text(&json, crate::input::MAX_JSON_BYTES)
        .map_err(|e| bad(format!("{}: {e}", json.display())))?;
    let s: SweepJson = serde_json::from_str(&text)
        .map_err(|e| bad(format!("{}: not the summary of an ensemble sweep: {e}", json.display())))?;
    if s.kind != "sweep" {
        return Err(bad(format!("{}: kind \"{}\", not a sweep", json.display(), s.kind)));
    }
    let key = match s.keys.as_slice() {
        [key] => key.clone(),
        keys => {
            return Err(bad(format!(
                "{shown}: a sweep of {} keys ({}): only the sweeps of one key are curves",
                keys.len(),
                keys.join(" × ")
            )))
        }
    };
    if s.points.is_empty() {
        return Err(bad(format!("{shown}: a sweep without points")));
    }
    if let Some(p) = s.points.iter().find(|p| !p.value.is_some_and(f64::is_finite)) {
        return Err(bad(format!("{shown}: a point without a finite value of {key} ({:?})", p.value)));
    }
    // The axis's spacing, from the sweep's definition (linear when the manifest does not say).
    let log = crate::input::read_text(&dir.join("manifest.json"), crate::input::MAX_JSON_BYTES)
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .is_some_and(|m| m["definition"]["spacing"] == "log");
    Ok(Curve { label, dir: dir.to_path_buf(), key, log, points: s.points, thresholds: s.thresholds })
}

/// The unit of a scene key, from its suffix (`peak_g`: G); `None` when the suffix names none.
pub fn unit_of(key: &str) -> Option<&'static str> {
    const UNITS: [(&str, &str); 13] = [
        ("_n_s_per_m", "N·s/m"),
        ("_n_per_m", "N/m"),
        ("_g", "G"),
        ("_hz", "Hz"),
        ("_um", "µm"),
        ("_mm", "mm"),
        ("_mh", "mH"),
        ("_ohm", "Ω"),
        ("_deg", "°"),
        ("_s", "s"),
        ("_v", "V"),
        ("_a", "A"),
        ("_kg", "kg"),
    ];
    UNITS.iter().find(|(suffix, _)| key.ends_with(suffix)).map(|(_, unit)| *unit)
}

/// A number in three significant figures, without trailing zeros.
fn short(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// `plant overlay`: checks every folder (exit 2 on bad input), then writes the chart and the
/// table into `--out`.
pub fn command(args: &OverlayArgs) -> anyhow::Result<()> {
    let curves = read_curves(args)?;
    let (key, log) = (curves[0].key.clone(), curves[0].log);
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from("runs").join("overlay"));
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    write_table(&curves, &key, &out)?;
    write_chart(args, &curves, &key, log, &out)?;
    eprintln!("plant overlay: {} sweeps of {key} → {}/overlay.png, overlay.csv", curves.len(), out.display());
    Ok(())
}

/// Every folder's sweep, labelled; refused unless all share one x axis (key and spacing).
fn read_curves(args: &OverlayArgs) -> anyhow::Result<Vec<Curve>> {
    if !args.labels.is_empty() && args.labels.len() != args.sweeps.len() {
        return Err(bad(format!(
            "--label given {} times for {} sweep folders: give one per folder, or none",
            args.labels.len(),
            args.sweeps.len()
        )));
    }
    let mut curves = Vec::with_capacity(args.sweeps.len());
    for (i, dir) in args.sweeps.iter().enumerate() {
        let label = args.labels.get(i).cloned().unwrap_or_else(|| {
            dir.file_name().map_or_else(|| dir.display().to_string(), |n| n.to_string_lossy().into_owned())
        });
        curves.push(read_sweep(dir, label)?);
    }
    let first = &curves[0];
    for c in &curves[1..] {
        if c.key != first.key {
            return Err(bad(format!(
                "mismatched axes: {} sweeps {}, {} sweeps {}: curves share one x axis",
                c.dir.display(),
                c.key,
                first.dir.display(),
                first.key
            )));
        }
        if c.log != first.log {
            let spacing = |log: bool| if log { "log" } else { "linear" };
            return Err(bad(format!(
                "mismatched axes: {} is spaced {}, {} {}: curves share one x axis",
                c.dir.display(),
                spacing(c.log),
                first.dir.display(),
                spacing(first.log)
            )));
        }
    }
    Ok(curves)
}

/// `overlay.csv`: a row per point of every curve.
fn write_table(curves: &[Curve], key: &str, out: &Path) -> anyhow::Result<()> {
    let mut w = csv_writer();
    w.write_record([
        "label",
        "folder",
        "key",
        "value",
        "members",
        "recovered",
        "p_recovered",
        "p_lo",
        "p_hi",
        "numerically_sensitive",
    ])?;
    for c in curves {
        for p in &c.points {
            w.write_record([
                c.label.clone(),
                c.dir.display().to_string(),
                key.to_string(),
                e(p.value.unwrap_or(f64::NAN)),
                p.members.to_string(),
                p.recovered.to_string(),
                e(p.p_recovered),
                e(p.p_lo),
                e(p.p_hi),
                p.numerically_sensitive.to_string(),
            ])?;
        }
    }
    finish(w, &out.join("overlay.csv"))?;

    Ok(())
}

/// `overlay.png`: x in the axis's own scale (log10 for a log axis), the 0.5 crossings in the
/// legend.
fn write_chart(args: &OverlayArgs, curves: &[Curve], key: &str, log: bool, out: &Path) -> anyhow::Result<()> {
    let unit = unit_of(key);
    let x_of = |v: f64| if log { v.log10() } else { v };
    let xs: Vec<Vec<f64>> =
        curves.iter().map(|c| c.points.iter().map(|p| x_of(p.value.unwrap_or(f64::NAN))).collect()).collect();
    let mut all: Vec<f64> = xs.iter().flatten().copied().collect();
    all.sort_by(f64::total_cmp);
    all.dedup();
    let step = all.windows(2).map(|w| w[1] - w[0]).filter(|d| *d > 0.0).fold(f64::INFINITY, f64::min);
    let n = curves.len();
    let offset = if args.no_offset || n < 2 || !step.is_finite() { 0.0 } else { 0.5 * step / (n - 1) as f64 };
    let axis = if log { format!("log10({key})") } else { key.to_string() };
    let mut x_label = args.x_label.clone().unwrap_or_else(|| match unit {
        Some(u) if !log => format!("{axis} ({u})"),
        _ => axis.clone(),
    });
    if offset > 0.0 {
        let unit = if log { String::new() } else { unit.map(|u| format!(" {u}")).unwrap_or_default() };
        x_label.push_str(&format!(
            "; curves set apart by up to ±{}{unit} for legibility",
            short(offset * (n - 1) as f64 / 2.0)
        ));
    }
    let labels: Vec<String> = curves
        .iter()
        .map(|c| {
            let unit = unit.map(|u| format!(" {u}")).unwrap_or_default();
            let crossings: Vec<String> = c
                .thresholds
                .iter()
                .map(|t| {
                    let open = if t.open { ", open" } else { "" };
                    format!("{}{unit} [{}, {}{open}]", short(t.value), short(t.interval[0]), short(t.interval[1]))
                })
                .collect();
            if crossings.is_empty() {
                c.label.clone()
            } else {
                format!("{}: P = 0.5 at {}", c.label, crossings.join(", "))
            }
        })
        .collect();
    let columns: Vec<[Vec<f64>; 3]> = curves
        .iter()
        .map(|c| {
            [
                c.points.iter().map(|p| p.p_recovered).collect(),
                c.points.iter().map(|p| p.p_lo).collect(),
                c.points.iter().map(|p| p.p_hi).collect(),
            ]
        })
        .collect();
    let drawn: Vec<ProbabilityCurve> = (0..n)
        .map(|k| ProbabilityCurve {
            label: &labels[k],
            x: &xs[k],
            p: &columns[k][0],
            lo: &columns[k][1],
            hi: &columns[k][2],
        })
        .collect();
    let title = args.title.clone().unwrap_or_else(|| format!("probability of recovery against {key}"));
    plot::probability(&out.join("overlay.png"), &title, &x_label, &drawn, offset).context("writing overlay.png")?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_come_from_the_keys_suffix() {
        assert_eq!(unit_of("shock[0].peak_g"), Some("G"));
        assert_eq!(unit_of("controller.stiffness_n_per_m"), Some("N/m"));
        assert_eq!(unit_of("contact.rotor_race_damping_n_s_per_m"), Some("N·s/m"));
        assert_eq!(unit_of("sensor.range_um"), Some("µm"));
        assert_eq!(unit_of("controller.damping_ratio"), None);
    }

    #[test]
    fn short_numbers_keep_three_figures() {
        assert_eq!(short(3.3846), "3.38");
        assert_eq!(short(0.0125), "0.0125");
        assert_eq!(short(20.0), "20");
        assert_eq!(short(0.25), "0.25");
        assert_eq!(short(150.4), "150");
    }
}
