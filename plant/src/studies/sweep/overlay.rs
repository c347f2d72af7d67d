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
//!
//! `--redraw CSV` draws the chart again from an earlier `overlay.csv` alone (the committed
//! tables of `docs/charts/`, whose sweeps take hours): its curves in their order, their 0.5
//! crossings found again from the points' probabilities and intervals, as `plant sweep` finds
//! them; only `overlay.png` is written.

use crate::ensemble::stats::thresholds_along;
use crate::exit::Ending;
use crate::plot::{self, ProbabilityCurve};
use crate::table::sci;
use anyhow::Context;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// `plant overlay` arguments.
#[derive(clap::Args, Debug, Clone)]
pub struct OverlayArgs {
    /// Folders of finished ensemble sweeps (`plant sweep` of a file with an `[ensemble]` table)
    /// of the same key, one curve each, in the legend's order.
    #[arg(required_unless_present = "redraw", value_name = "SWEEP_DIR")]
    pub sweeps: Vec<PathBuf>,
    /// A curve's legend text, one per folder in their order (repeatable; default: the folder's
    /// name).
    #[arg(long = "label", value_name = "TEXT")]
    pub labels: Vec<String>,
    /// Draw the chart again from an earlier `overlay.csv` (its labels, points and spacing),
    /// reading no sweep folder; writes `overlay.png` only.
    #[arg(long, value_name = "CSV", conflicts_with_all = ["sweeps", "labels"])]
    pub redraw: Option<PathBuf>,
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

/// A row of `overlay.csv`: one point of one curve (its header: the fields' names, in order).
#[derive(Serialize, Deserialize)]
struct OverlayRow {
    label: String,
    folder: String,
    key: String,
    #[serde(with = "sci")]
    value: f64,
    members: usize,
    recovered: usize,
    #[serde(with = "sci")]
    p_recovered: f64,
    #[serde(with = "sci")]
    p_lo: f64,
    #[serde(with = "sci")]
    p_hi: f64,
    numerically_sensitive: usize,
    /// The axis's spacing, `linear` or `log` (a table written before this column read as
    /// linear: every shipped overlay was).
    #[serde(default = "linear")]
    spacing: String,
}

fn linear() -> String {
    "linear".to_string()
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
    let curves = match &args.redraw {
        Some(csv) => curves_of_table(csv)?,
        None => read_curves(args)?,
    };
    same_axis(&curves)?;
    let (key, log) = (curves[0].key.clone(), curves[0].log);
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from("runs").join("overlay"));
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    match &args.redraw {
        None => write_table(&curves, &key, &out)?,
        // An earlier overlay's table would sit beside a chart drawn from another one; the
        // table this chart is drawn from (redrawn in its own folder) stays.
        Some(csv) => {
            let table = out.join("overlay.csv");
            let canonical = |p: &Path| std::fs::canonicalize(p).ok();
            if canonical(&table).is_none_or(|t| Some(t) != canonical(csv)) {
                crate::outfile::remove(&table)?;
            }
        }
    }
    write_chart(args, &curves, &key, log, &out)?;
    let written = if args.redraw.is_some() { "overlay.png" } else { "overlay.png, overlay.csv" };
    eprintln!("plant overlay: {} curves of {key} → {}/{written}", curves.len(), out.display());
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
    Ok(curves)
}

/// The curves of an earlier `overlay.csv`: consecutive rows of one label and folder make a
/// curve; each curve's crossings are found again from its points.
fn curves_of_table(csv: &Path) -> anyhow::Result<Vec<Curve>> {
    let shown = csv.display();
    let rows: Vec<OverlayRow> = crate::table::read(csv).map_err(|e| bad(format!("--redraw: {e:#}")))?;
    let mut curves: Vec<Curve> = Vec::new();
    for (i, r) in rows.into_iter().enumerate() {
        let line = i + 2;
        let log = match r.spacing.as_str() {
            "linear" => false,
            "log" => true,
            other => return Err(bad(format!("--redraw {shown}: line {line}: spacing \"{other}\": linear or log"))),
        };
        if !r.value.is_finite() {
            return Err(bad(format!("--redraw {shown}: line {line}: value {} of {} is not finite", r.value, r.key)));
        }
        let point = JsonPoint {
            value: Some(r.value),
            members: r.members,
            recovered: r.recovered,
            p_recovered: r.p_recovered,
            p_lo: r.p_lo,
            p_hi: r.p_hi,
            numerically_sensitive: r.numerically_sensitive,
        };
        match curves.last_mut() {
            Some(c) if c.label == r.label && c.dir.as_os_str() == r.folder.as_str() => {
                if c.log != log {
                    return Err(bad(format!(
                        "--redraw {shown}: line {line}: curve \"{}\" changes its spacing",
                        r.label
                    )));
                }
                c.points.push(point);
            }
            _ => curves.push(Curve {
                label: r.label,
                dir: PathBuf::from(r.folder),
                key: r.key,
                log,
                points: vec![point],
                thresholds: Vec::new(),
            }),
        }
    }
    if curves.is_empty() {
        return Err(bad(format!("--redraw {shown}: no rows")));
    }
    for c in &mut curves {
        let column = |f: fn(&JsonPoint) -> f64| -> Vec<f64> { c.points.iter().map(f).collect() };
        let values = column(|p| p.value.unwrap_or(f64::NAN));
        let found =
            thresholds_along(&values, c.log, &column(|p| p.p_recovered), &column(|p| p.p_lo), &column(|p| p.p_hi));
        c.thresholds =
            found.into_iter().map(|t| JsonThreshold { value: t.value, interval: t.interval, open: t.open }).collect();
    }
    Ok(curves)
}

/// Refuses curves that do not share one x axis (key and spacing).
fn same_axis(curves: &[Curve]) -> anyhow::Result<()> {
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
    Ok(())
}

/// `overlay.csv`: a row per point of every curve.
fn write_table(curves: &[Curve], key: &str, out: &Path) -> anyhow::Result<()> {
    let rows: Vec<OverlayRow> = curves
        .iter()
        .flat_map(|c| {
            c.points.iter().map(|p| OverlayRow {
                label: c.label.clone(),
                folder: c.dir.display().to_string(),
                key: key.to_string(),
                value: p.value.unwrap_or(f64::NAN),
                members: p.members,
                recovered: p.recovered,
                p_recovered: p.p_recovered,
                p_lo: p.p_lo,
                p_hi: p.p_hi,
                numerically_sensitive: p.numerically_sensitive,
                spacing: if c.log { "log" } else { "linear" }.to_string(),
            })
        })
        .collect();
    crate::table::write(&out.join("overlay.csv"), &rows)
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

    fn table_file(name: &str, text: &str) -> PathBuf {
        let path = crate::util::scratch(&format!("overlay-{name}")).join("overlay.csv");
        std::fs::write(&path, text).unwrap();
        path
    }

    const HEADER: &str = "label,folder,key,value,members,recovered,p_recovered,p_lo,p_hi,numerically_sensitive";

    #[test]
    fn a_redrawn_table_finds_its_crossings_again() {
        // Linear: p̂ 1, 1, 0 at 1, 2, 3 G crosses 0.5 half-way from 2 to 3 G, between the points
        // whose bands exclude 0.5 (2 and 3). Log: p̂ 1, 0 at 10 and 100 crosses at 10^1.5.
        let text = format!(
            "{HEADER},spacing\n\
             a,runs/a,shock[0].peak_g,1e0,16,16,1e0,8e-1,1e0,0,linear\n\
             a,runs/a,shock[0].peak_g,2e0,16,16,1e0,8e-1,1e0,0,linear\n\
             a,runs/a,shock[0].peak_g,3e0,16,0,0e0,0e0,2e-1,0,linear\n\
             b,runs/b,shock[0].peak_g,1e0,16,16,1e0,8e-1,1e0,0,linear\n"
        );
        let curves = curves_of_table(&table_file("linear", &text)).unwrap();
        assert_eq!(curves.iter().map(|c| (c.label.as_str(), c.points.len())).collect::<Vec<_>>(), [("a", 3), ("b", 1)]);
        let t = &curves[0].thresholds;
        assert_eq!(t.len(), 1);
        assert_eq!((t[0].value, t[0].interval, t[0].open), (2.5, [2.0, 3.0], false));
        assert!(curves[1].thresholds.is_empty());

        let text = format!(
            "{HEADER},spacing\n\
             l,runs/l,controller.stiffness_n_per_m,1e1,16,16,1e0,8e-1,1e0,0,log\n\
             l,runs/l,controller.stiffness_n_per_m,1e2,16,0,0e0,0e0,2e-1,0,log\n"
        );
        let curves = curves_of_table(&table_file("log", &text)).unwrap();
        assert!(curves[0].log);
        let t = &curves[0].thresholds[0];
        assert!((t.value - 10f64.powf(1.5)).abs() < 1e-9, "{}", t.value);
        assert!((t.interval[0] - 10.0).abs() < 1e-12 && (t.interval[1] - 100.0).abs() < 1e-9, "{:?}", t.interval);
    }

    #[test]
    fn a_table_without_its_spacing_reads_as_linear_and_a_bad_one_is_refused() {
        let old = format!("{HEADER}\nx,runs/x,shock[0].peak_g,1e0,16,16,1e0,8e-1,1e0,0\n");
        assert!(!curves_of_table(&table_file("old", &old)).unwrap()[0].log);
        let bad_spacing = format!("{HEADER},spacing\nx,runs/x,shock[0].peak_g,1e0,16,16,1e0,8e-1,1e0,0,cubic\n");
        let e = format!("{:#}", curves_of_table(&table_file("cubic", &bad_spacing)).err().unwrap());
        assert!(e.contains("line 2: spacing \"cubic\": linear or log"), "{e}");
        let infinite = format!("{HEADER}\nx,runs/x,shock[0].peak_g,inf,16,16,1e0,8e-1,1e0,0\n");
        let e = format!("{:#}", curves_of_table(&table_file("inf", &infinite)).err().unwrap());
        assert!(e.contains("line 2: value inf of shock[0].peak_g is not finite"), "{e}");
        let e = format!("{:#}", curves_of_table(&table_file("empty", &format!("{HEADER}\n"))).err().unwrap());
        assert!(e.contains("no rows"), "{e}");
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
