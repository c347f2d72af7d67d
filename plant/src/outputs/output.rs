//! Writing a run's results to its folder: `scene.toml` (the scene as
//! resolved, overrides included), `trace.csv` (streamed as the rows are
//! made), `summary.json` (written whole, at the end) and PNG charts.
//!
//! **The output promise.** Whatever way a run ends after its scene loaded,
//! its folder holds `scene.toml`, `trace.csv` up to the stop, `summary.json`
//! with `status` and `error`, and the charts that have something to draw. A
//! reused folder first loses the files of an earlier run that this run
//! writes ([`RUN_FILES`]), and only those, so that no chart of another run
//! survives next to this one's results.

use crate::analysis::Analysis;
use crate::bounded::MinMaxBins;
use crate::config::{ConfigError, Scene};
use crate::cosim::Launch;
use crate::hooks::Hooks;
use crate::offload::{run_into_offloaded, When};
use crate::plot::{self, Scale, Series};
use crate::record::{ChartData, PlaneRecorded, Recorder};
use crate::recording::mcap_file::McapSink;
use crate::run::{Outcome, RunResult, SetupError, Sink, SinkRun};
use crate::summary::Summary;
use crate::trace::{Record, TraceError, TraceWriter};
use anyhow::Context;
use std::path::{Path, PathBuf};

/// The files a run writes into its folder (and removes first when the folder is reused).
pub const RUN_FILES: &[&str] = &[
    "scene.toml",
    "trace.csv",
    "summary.json",
    "orbit.png",
    "radius.png",
    "race_speed.png",
    "currents.png",
    "contact_force.png",
    "spectrum.png",
    "whirl_spectrum.png",
    "spectrogram.png",
    "poincare.png",
    // A two-plane run's: an orbit and the analysis charts per plane, and the tilt.
    "orbit_a.png",
    "orbit_b.png",
    "tilt.png",
    // A flexible run's: the orbit at mid-span.
    "orbit_mid.png",
    "spectrum_a.png",
    "whirl_spectrum_a.png",
    "spectrogram_a.png",
    "poincare_a.png",
    "spectrum_b.png",
    "whirl_spectrum_b.png",
    "spectrogram_b.png",
    "poincare_b.png",
    "controller.log",
    "tet.png",
    crate::recording::mcap_file::FILE,
];

/// Why `plant run` stopped before it wrote its results.
#[derive(Debug, thiserror::Error)]
pub enum RunDirError {
    /// The run could not start (bad controller design, no controller).
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// An output could not be written.
    #[error("{0:#}")]
    Output(anyhow::Error),
}

/// What `plant run` wrote.
#[derive(Debug)]
pub struct Written {
    /// `summary.json`.
    pub summary: Summary,
    /// How the run went.
    pub run: SinkRun,
    /// Charts not drawn because they had nothing to draw (a run stopped at its start).
    pub skipped_charts: Vec<&'static str>,
    /// What the live view served (`plant run --live`).
    pub live: Option<crate::live::Served>,
}

/// Creates `dir`, removes the files an earlier run left there that this run
/// writes ([`RUN_FILES`]), and writes `scene.toml`.
pub fn prepare(dir: &Path, scene: &Scene) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating output folder {}", dir.display()))?;
    remove_stale(dir)?;
    prepare_scene_toml(dir, scene)
}

/// Writes `scene.toml`: the scene as resolved.
fn prepare_scene_toml(dir: &Path, scene: &Scene) -> anyhow::Result<()> {
    let resolved = scene.to_toml().context("serialising the resolved scene")?;
    crate::outfile::write(&dir.join("scene.toml"), resolved.as_bytes())
}

/// The record of a run that did not start (the controller refused it or could not be
/// reached, or it was interrupted while waiting): `scene.toml` and a `summary.json` with the
/// scene's name, `status` (`refused`, `not_started`, `interrupted`), `error` and the model
/// choices, so that every exit after the scene loaded leaves both files. An earlier run's
/// files are removed ([`prepare`]).
pub fn write_not_started(dir: &Path, scene: &Scene, status: &str, error: &str) -> anyhow::Result<()> {
    // The controller's output of this attempt stays: the error quotes it.
    std::fs::create_dir_all(dir).with_context(|| format!("creating output folder {}", dir.display()))?;
    remove_stale_except(dir, &["controller.log"])?;
    prepare_scene_toml(dir, scene)?;
    let summary = serde_json::json!({
        "scene": scene.name,
        "status": status,
        "error": error,
        "simulated_s": 0.0,
        "model": crate::summary::ModelInfo::new(scene),
    });
    write_json(&dir.join("summary.json"), &summary)
}

/// Removes the files of [`RUN_FILES`] from `dir` (those that are there).
pub fn remove_stale(dir: &Path) -> anyhow::Result<()> {
    remove_stale_except(dir, &[])
}

/// [`remove_stale`], keeping the files named in `keep`.
fn remove_stale_except(dir: &Path, keep: &[&str]) -> anyhow::Result<()> {
    // An earlier run's state snapshots (`state-T.json`, `--save-state-at`) go too: a folder's
    // snapshots are its own run's.
    let snapshots: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("listing {}", dir.display()))?
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.file_name().and_then(|n| n.to_str()).is_some_and(crate::snapshot::is_file_name))
        .collect();
    for path in RUN_FILES.iter().filter(|n| !keep.contains(n)).map(|name| dir.join(name)).chain(snapshots) {
        crate::outfile::remove(&path).context("an earlier run's file")?;
    }
    Ok(())
}

/// The sink of `plant run`: each row goes to `trace.csv` as it is made and
/// to the [`Recorder`]; nothing is kept per row.
pub struct RunFolder {
    trace: TraceWriter,
    recorder: Recorder,
    error: Option<std::io::Error>,
    mcap: Option<McapSink>,
    live: Option<crate::live::LiveSink>,
}

impl RunFolder {
    /// Creates `dir/trace.csv` (header) for a run of `scene`.
    pub fn create(dir: &Path, scene: &Scene) -> anyhow::Result<Self> {
        let path = dir.join("trace.csv");
        let trace = TraceWriter::create_with_columns(
            &path,
            scene.planes(),
            scene.hardware.amplified(),
            scene.hardware.is_unipolar(),
            scene.rotor.bends(),
        )
        .with_context(|| format!("creating {}", path.display()))?;
        let mcap = scene.mcap.then(|| McapSink::create(dir, scene)).transpose()?;
        Ok(Self { trace, recorder: Recorder::new(scene, scene.plots), error: None, mcap, live: None })
    }

    /// Also serves the rows live through `server` (`plant run --live`).
    pub fn with_live(mut self, server: Option<crate::live::Server>, scene: &Scene) -> Self {
        self.live = server.map(|s| crate::live::LiveSink::new(s, scene));
        self
    }

    /// One sample (also for a trace already in memory).
    pub fn push(&mut self, r: &Record) {
        if self.error.is_none() {
            if let Err(e) = self.trace.write(r) {
                self.error = Some(e);
            }
        }
        self.recorder.push(r);
        if let Some(m) = &mut self.mcap {
            m.push(r);
        }
        if let Some(l) = &mut self.live {
            l.push(r);
        }
    }

    /// Flushes `trace.csv`, writes `summary.json`, then the charts. A run that completed but
    /// was asked to stop (`stopped`: SIGINT/SIGTERM) while its outputs were being written is
    /// `interrupted` (exit 130): every output is still written, and the summary says so.
    pub fn finish(
        mut self,
        dir: &Path,
        scene: &Scene,
        mut run: SinkRun,
        stopped: &dyn Fn() -> bool,
    ) -> anyhow::Result<Written> {
        let interrupt = |run: &mut SinkRun| {
            let late = stopped() && run.outcome == Outcome::Completed;
            if late {
                run.outcome = Outcome::Interrupted;
            }
            late
        };
        interrupt(&mut run);
        let trace_path = dir.join("trace.csv");
        let flushed = match self.error.take() {
            Some(e) => Err(e),
            None => self.trace.flush(),
        };
        let recorded = self.recorder.finish(run.outcome.failure_time());
        let charts = scene.plots.then(|| (recorded.planes.clone(), recorded.tilt_chart.clone()));
        let mid_chart = recorded.mid_chart.clone();
        interrupt(&mut run);
        let mut summary = Summary::from_parts(scene, &run, recorded);
        write_json(&dir.join("summary.json"), &summary)?;
        flushed.with_context(|| format!("writing {}", trace_path.display()))?;
        let mut skipped = Vec::new();
        if let Some((planes, tilt)) = &charts {
            skipped.extend(write_charts(dir, scene, planes, tilt.as_ref()).context("writing charts")?);
            if let Some(mid) = &mid_chart {
                skipped.extend(write_mid_orbit(dir, scene, mid)?);
            }
            if let Some(tet) = &run.ticks.tet {
                match write_tet_chart(&dir.join("tet.png"), scene, tet) {
                    Err(plot::PlotError::NoData { .. }) => skipped.push("tet.png"),
                    other => other.context("writing tet.png")?,
                }
            }
            skipped.extend(write_analysis_charts(dir, scene, planes).context("writing analysis charts")?);
        }
        if interrupt(&mut run) {
            summary.status = run.outcome.status();
            summary.error = run.outcome.error();
            write_json(&dir.join("summary.json"), &summary)?;
        }
        let live = self.live.take().map(|l| l.finish(Some(&summary)));
        // The recording closes last: its failure (a full disk) loses none of the other outputs.
        self.mcap.take().map(|m| m.finish(Some(&summary))).transpose()?;
        Ok(Written { summary, run, skipped_charts: skipped, live })
    }
}

/// Each plane's analysis charts (`spectrum.png`, `whirl_spectrum.png`, `spectrogram.png`,
/// `poincare.png`; with `_a`, `_b` for a two-plane run); returns those not written.
fn write_analysis_charts(
    dir: &Path,
    scene: &Scene,
    planes: &[PlaneRecorded],
) -> Result<Vec<&'static str>, plot::PlotError> {
    let mut skipped = Vec::new();
    for (i, p) in planes.iter().enumerate() {
        let (tag, name) = plane_tag(scene, i);
        let written =
            crate::analysis::write_plots(dir, &name, tag, &p.analysis, &p.analysis_data, scene.plane(i).contact.gap)?;
        skipped.extend(crate::analysis::PLOT_FILES[tag_index(tag)].iter().filter(|f| !written.contains(*f)));
    }
    Ok(skipped)
}

/// A plane's file tag (`""` planar, `"_a"`, `"_b"`) and the chart title's name.
fn plane_tag(scene: &Scene, i: usize) -> (&'static str, String) {
    match (scene.planes(), i) {
        (1, _) => ("", scene.name.clone()),
        (_, 0) => ("_a", format!("{} — plane A", scene.name)),
        _ => ("_b", format!("{} — plane B", scene.name)),
    }
}

fn tag_index(tag: &str) -> usize {
    match tag {
        "_a" => 1,
        "_b" => 2,
        _ => 0,
    }
}

impl Sink for RunFolder {
    fn sample(&mut self, record: &Record) {
        self.push(record);
    }

    fn tick(&mut self, sample: &controller::RotorSample, command: &[f64; controller::ROTOR_AXES]) {
        crate::live::tick(&mut self.mcap, &mut self.live, sample, command);
    }

    fn wants_ticks(&self) -> bool {
        crate::live::wants_ticks(&self.mcap, &self.live)
    }
}

/// `plant run`: runs `scene`, streaming its rows to `dir` (see the module docs).
pub fn run_to_dir(dir: &Path, scene: &Scene, launch: &Launch, hooks: &mut dyn Hooks) -> Result<Written, RunDirError> {
    run_to_dir_from(dir, scene, launch, hooks, None)
}

/// [`run_to_dir`] from a saved state (`plant run --from-state`): `trace.csv` holds the rows
/// after the snapshot's time, the rows the run that saved it would have written next.
pub fn run_to_dir_from(
    dir: &Path,
    scene: &Scene,
    launch: &Launch,
    hooks: &mut dyn Hooks,
    from: Option<&crate::snapshot::Snapshot>,
) -> Result<Written, RunDirError> {
    run_to_dir_live(dir, scene, launch, hooks, from, None)
}

/// [`run_to_dir_from`], the rows also served live through `live` (`plant run --live`).
pub fn run_to_dir_live(
    dir: &Path,
    scene: &Scene,
    launch: &Launch,
    hooks: &mut dyn Hooks,
    from: Option<&crate::snapshot::Snapshot>,
    live: Option<crate::live::Server>,
) -> Result<Written, RunDirError> {
    prepare(dir, scene).map_err(RunDirError::Output)?;
    let mut folder = RunFolder::create(dir, scene).map_err(RunDirError::Output)?.with_live(live, scene);
    let launch = Launch { log: Some(dir.join("controller.log")), ..launch.clone() };
    let run = run_into_offloaded(scene, &launch, hooks, &mut folder, from, When::SpareCore)?;
    // What an external controller ran differently from the scene goes into the record, so that
    // the folder reproduces the run.
    let recorded = match run.cosim.as_ref().and_then(|c| c.controller_overrides.as_ref()) {
        Some(o) => {
            let recorded = scene.with_controller_overrides(o).map_err(|e| RunDirError::Output(e.into()))?;
            prepare_scene_toml(dir, &recorded).map_err(RunDirError::Output)?;
            Some(recorded)
        }
        None => None,
    };
    folder.finish(dir, recorded.as_ref().unwrap_or(scene), run, &|| hooks.cancelled()).map_err(RunDirError::Output)
}

/// Writes everything a run whose trace is in memory produced, as [`run_to_dir`] does.
pub fn write_run(dir: &Path, scene: &Scene, result: &RunResult) -> anyhow::Result<Summary> {
    prepare(dir, scene)?;
    let mut folder = RunFolder::create(dir, scene)?;
    result.trace.records().for_each(|r| folder.push(&r));
    Ok(folder.finish(dir, scene, result.run.clone(), &|| false)?.summary)
}

/// Writes a value as pretty JSON, atomically ([`crate::atomic::write`]).
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> anyhow::Result<()> {
    let text = serde_json::to_string_pretty(value).context("serialising JSON")?;
    crate::outfile::write(path, (text + "\n").as_bytes())
}

/// The run's own charts; a chart with nothing to draw is not written. Returns those not written.
/// A two-plane run draws each plane's orbit (`orbit_a.png`, `orbit_b.png`), both planes in each
/// time chart, and the tilt (`tilt.png`).
pub fn write_charts(
    dir: &Path,
    scene: &Scene,
    planes: &[PlaneRecorded],
    tilt: Option<&MinMaxBins>,
) -> Result<Vec<&'static str>, plot::PlotError> {
    let title = |what: &str| format!("{} — {what}", scene.name);
    let mut skipped = Vec::new();
    let mut draw = |file: &'static str, r: Result<(), plot::PlotError>| match r {
        Ok(()) => Ok(()),
        Err(plot::PlotError::NoData { .. }) => {
            skipped.push(file);
            Ok(())
        }
        Err(e) => Err(e),
    };
    let charts: Vec<&ChartData> = planes.iter().filter_map(|p| p.charts.as_ref()).collect();
    let two = charts.len() == 2;
    let gap = |i: usize| scene.plane(i).contact.gap;
    // Series labels: the planar chart's, or with the plane's letter.
    let label = |what: &str, i: usize| if two { format!("{what} {}", ["A", "B"][i]) } else { what.to_string() };

    const ORBITS: [&str; 3] = ["orbit.png", "orbit_a.png", "orbit_b.png"];
    for (i, c) in charts.iter().enumerate() {
        let (ox, oy) = c.orbit();
        let (file, what) = if two {
            (ORBITS[1 + i], format!("rotor orbit at bearing {} relative to housing", ["A", "B"][i]))
        } else {
            (ORBITS[0], "rotor orbit relative to housing".to_string())
        };
        draw(file, plot::orbit(&dir.join(file), &title(&what), &ox, &oy, gap(i)))?;
    }

    // A chart against time (ms), its y axis `y_label`.
    let mut time_chart = |file: &'static str, what: &str, y_label: &str, series: &[Series]| {
        draw(file, plot::lines(&dir.join(file), &title(what), "time (ms)", y_label, series, Scale::Linear))
    };

    let radius: Vec<(Vec<f64>, Vec<f64>)> = charts.iter().map(|c| c.radius_um.points()).collect();
    let gap_lines: Vec<Vec<f64>> = radius.iter().enumerate().map(|(i, (ms, _))| vec![gap(i) * 1e6; ms.len()]).collect();
    let labels: Vec<(String, String)> =
        (0..charts.len()).map(|i| (label("rotor radius", i), label("air gap r0", i))).collect();
    let mut series = Vec::new();
    for (i, (ms, r)) in radius.iter().enumerate() {
        series.push(Series { label: &labels[i].0, x: ms, y: r });
    }
    for (i, (ms, _)) in radius.iter().enumerate() {
        // One gap line when both planes have the same gap.
        if i == 0 || gap(i) != gap(0) {
            series.push(Series {
                label: if two && gap(1) == gap(0) { "air gap r0" } else { &labels[i].1 },
                x: ms,
                y: &gap_lines[i],
            });
        }
    }
    time_chart("radius.png", "rotor radius", "radius (µm)", &series)?;

    let rpm: Vec<(Vec<f64>, Vec<f64>)> = charts.iter().map(|c| c.race_rpm.points()).collect();
    let labels: Vec<String> = (0..charts.len()).map(|i| label("race speed", i)).collect();
    let series: Vec<Series> = rpm.iter().zip(&labels).map(|((x, y), l)| Series { label: l, x, y }).collect();
    time_chart("race_speed.png", "inner race speed", "speed (rpm)", &series)?;

    let currents: Vec<[(Vec<f64>, Vec<f64>); 2]> =
        charts.iter().map(|c| [c.current_a[0].points(), c.current_a[1].points()]).collect();
    let labels: Vec<[String; 2]> = (0..charts.len()).map(|i| [label("i_x", i), label("i_y", i)]).collect();
    let series: Vec<Series> = currents
        .iter()
        .zip(&labels)
        .flat_map(|(c, l)| {
            [Series { label: &l[0], x: &c[0].0, y: &c[0].1 }, Series { label: &l[1], x: &c[1].0, y: &c[1].1 }]
        })
        .collect();
    time_chart("currents.png", "coil currents", "current (A)", &series)?;

    let forces: Vec<[(Vec<f64>, Vec<f64>); 2]> =
        charts.iter().map(|c| [c.force_n[0].points(), c.force_n[1].points()]).collect();
    let labels: Vec<[String; 2]> = (0..charts.len()).map(|i| [label("normal", i), label("friction", i)]).collect();
    // The normal forces first, then the frictions.
    let mut series: Vec<Series> = Vec::new();
    for k in 0..2 {
        for (f, l) in forces.iter().zip(&labels) {
            series.push(Series { label: &l[k], x: &f[k].0, y: &f[k].1 });
        }
    }
    time_chart("contact_force.png", "rotor – race contact force", "force (N)", &series)?;

    if let Some(tilt) = tilt {
        let (ms, urad) = tilt.points();
        time_chart(
            "tilt.png",
            "tilt of the rotor axis |(a, b)|",
            "tilt (µrad)",
            &[Series { label: "tilt angle", x: &ms, y: &urad }],
        )?;
    }
    Ok(skipped)
}

/// `tet.png`: the plant's execution time per tick over the run (per bin of ticks, the largest
/// of the whole tick, of the command and of the integration, and the mean tick), against the
/// controller period.
pub fn write_tet_chart(path: &Path, scene: &Scene, tet: &crate::cosim::stats::Tet) -> Result<(), plot::PlotError> {
    let period = scene.controller.period;
    let bins = tet.bins();
    let us = |ns: u64| ns as f64 * 1e-3;
    let t: Vec<f64> = bins.iter().map(|b| b.first_tick as f64 * period).collect();
    let tick: Vec<f64> = bins.iter().map(|b| us(b.tick_max_ns)).collect();
    let mean: Vec<f64> = bins.iter().map(|b| us(b.tick_sum_ns) / b.ticks.max(1) as f64).collect();
    let command: Vec<f64> = bins.iter().map(|b| us(b.command_max_ns)).collect();
    let integration: Vec<f64> = bins.iter().map(|b| us(b.integration_max_ns)).collect();
    let line = vec![period * 1e6; t.len()];
    let per_bin = bins.first().map_or(1, |b| b.ticks);
    plot::lines(
        path,
        &format!("{} — plant execution time per tick (per {per_bin} ticks)", scene.name),
        "time (s)",
        "execution time (µs)",
        &[
            Series { label: "tick, largest", x: &t, y: &tick },
            Series { label: "tick, mean", x: &t, y: &mean },
            Series { label: "command, largest", x: &t, y: &command },
            Series { label: "integration, largest", x: &t, y: &integration },
            Series { label: "controller period", x: &t, y: &line },
        ],
        Scale::Log10,
    )
}

/// Why `plant analyze` failed: bad input (the scene, the trace, an existing
/// `summary.json` that is not JSON: exit 2) or an output that could not be
/// written (exit 1). A failing analysis writes nothing.
#[derive(Debug, thiserror::Error)]
pub enum AnalyzeError {
    /// `scene.toml` could not be loaded.
    #[error(transparent)]
    Scene(#[from] ConfigError),
    /// `trace.csv` could not be read strictly.
    #[error(transparent)]
    Trace(#[from] TraceError),
    /// The folder's `summary.json` is not a JSON object.
    #[error("{path}: {message}")]
    Summary {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// `summary.json` or a chart could not be written.
    #[error("{0:#}")]
    Output(anyhow::Error),
    /// SIGINT/SIGTERM; what was written by then is said.
    #[error("interrupted by a signal; {0}")]
    Interrupted(&'static str),
}

/// The most a `summary.json` that `plant analyze` merges into may hold.
const MAX_SUMMARY_BYTES: u64 = 16 << 20;

/// `plant analyze DIR`: reads `scene.toml` (through the scene loader) and
/// `trace.csv` (strictly, [`crate::trace::read_rows`]), merges the analysis
/// into `summary.json` (created if missing; written atomically, only once the
/// analysis succeeded), then writes the analysis charts. Once `stop` is set
/// (SIGINT/SIGTERM) it stops at the next row or step and says what it wrote.
pub fn analyze_dir(dir: &Path, stop: &std::sync::atomic::AtomicBool) -> Result<Analysis, AnalyzeError> {
    let stopped = || stop.load(std::sync::atomic::Ordering::Relaxed);
    const NOTHING: &str = "nothing was written";
    let scene = crate::config::load_scene(&dir.join("scene.toml"), &[])?;
    let trace_path = dir.join("trace.csv");
    let mut recorder = Recorder::new(&scene, true);
    let mut rows = 0;
    let mut planes = None;
    // A trace past the scene's end is another run's (issue 31 item 11): its rows would be
    // analysed against this scene's shocks and duration. A sample may sit on the end itself,
    // give or take the rounding of the output times.
    let end = scene.duration + 1e-9 * scene.duration.max(scene.output_interval);
    let mut beyond = None;
    let whole = crate::trace::read_rows(&trace_path, |r| {
        let t = r.a.t_s;
        if t > end {
            beyond = Some((rows as u64 + 2, t));
            return false;
        }
        planes.get_or_insert(r.planes());
        recorder.push(r);
        rows += 1;
        !stopped()
    })?;
    if let Some((line, t)) = beyond {
        let what = format!(
            "time {t:e} s is past the end of the scene ({} in {}: scene.duration_s = {} s): the trace is longer \
             than its scene, not this scene's run",
            scene.name,
            dir.join("scene.toml").display(),
            scene.duration
        );
        return Err(TraceError::Malformed { path: trace_path, line, column: Some("t_s".into()), what }.into());
    }
    if !whole {
        return Err(AnalyzeError::Interrupted(NOTHING));
    }
    if rows < 2 {
        return Err(TraceError::TooShort { path: trace_path, rows }.into());
    }
    if planes != Some(scene.planes()) {
        let what = if scene.planes() == 2 {
            "the scene is a two-plane rotor and the trace has no plane B columns (b_dx_m, …, slope_y_rate_rad_s)"
        } else {
            "the scene is planar and the trace has plane B columns"
        };
        return Err(TraceError::Malformed { path: trace_path, line: 1, column: None, what: what.to_string() }.into());
    }
    let recorded = recorder.finish(None);
    if stopped() {
        return Err(AnalyzeError::Interrupted(NOTHING));
    }
    let governing = recorded.governing();
    let analysis = recorded.planes[governing].analysis.clone();

    let summary_path = dir.join("summary.json");
    let bad_summary = |message: String| AnalyzeError::Summary { path: summary_path.display().to_string(), message };
    let mut summary: serde_json::Value = match shock_table::input::read_text(&summary_path, MAX_SUMMARY_BYTES) {
        Ok(text) => serde_json::from_str(&text).map_err(|e| bad_summary(e.to_string()))?,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => serde_json::json!({ "scene": scene.name }),
        // The summary is also this command's output: one that cannot be read cannot be replaced.
        Err(e) => {
            let what = format!("reading {}", summary_path.display());
            return Err(AnalyzeError::Output(anyhow::Error::new(e).context(what)));
        }
    };
    let map = summary.as_object_mut().ok_or_else(|| bad_summary("not a JSON object".to_string()))?;
    if let serde_json::Value::Object(new) = to_json(&analysis)? {
        map.extend(new);
    }
    if let (Some(tilt), [a, b]) = (&recorded.tilt, recorded.planes.as_slice()) {
        // Each plane's analysis and the tilt, into `planes` (its figures kept where the run wrote them).
        let planes = map.entry("planes").or_insert_with(|| serde_json::json!({}));
        if let Some(planes) = planes.as_object_mut() {
            planes.insert("governing".into(), serde_json::Value::from(["a", "b"][governing]));
            for (key, p) in [("a", a), ("b", b)] {
                let plane = planes.entry(key).or_insert_with(|| serde_json::json!({}));
                if let (Some(plane), serde_json::Value::Object(new)) = (plane.as_object_mut(), to_json(&p.analysis)?) {
                    plane.extend(new);
                }
            }
            planes.insert("tilt".into(), to_json(tilt)?);
        }
    }
    if let Some(mid) = &recorded.mid_span {
        // A bending rotor's mid-span (the trace's last two columns). A flexible trace written
        // before those columns existed has none, and gets no entry.
        map.insert("mid_span".into(), to_json(mid)?);
    }
    write_json(&summary_path, &summary).map_err(AnalyzeError::Output)?;
    if stopped() {
        return Err(AnalyzeError::Interrupted("summary.json was updated, the charts were not drawn"));
    }
    write_analysis_charts(dir, &scene, &recorded.planes)
        .context("writing analysis charts")
        .map_err(AnalyzeError::Output)?;
    if let Some(mid) = &recorded.mid_chart {
        write_mid_orbit(dir, &scene, mid).map_err(AnalyzeError::Output)?;
    }
    if stopped() {
        return Err(AnalyzeError::Interrupted("summary.json and the charts were written"));
    }
    Ok(analysis)
}

/// `orbit_mid.png`, the rotor's orbit at mid-span (a bending rotor's run), or the file's name
/// when there was nothing to draw. The bearings' clearance is drawn for scale: there is no
/// touchdown bearing at mid-span.
fn write_mid_orbit(dir: &Path, scene: &Scene, mid: &ChartData) -> anyhow::Result<Option<&'static str>> {
    let (x, y) = mid.orbit();
    let title = format!("{} — rotor orbit at mid-span relative to housing", scene.name);
    // Bearing A's circle named as such: unnamed, it reads as a bearing at mid-span.
    let circle = plot::RefCircle {
        label: "touchdown clearance of bearing A, not at mid-span",
        radius_m: scene.plane(0).contact.gap,
    };
    match plot::orbit_with_circles(&dir.join("orbit_mid.png"), &title, &x, &y, &[circle]) {
        Err(plot::PlotError::NoData { .. }) => Ok(Some("orbit_mid.png")),
        other => other.map(|()| None).context("writing orbit_mid.png"),
    }
}

/// A value as JSON, for `summary.json`.
fn to_json<T: serde::Serialize>(v: &T) -> Result<serde_json::Value, AnalyzeError> {
    serde_json::to_value(v).map_err(|e| AnalyzeError::Output(anyhow::Error::new(e)))
}

/// The output folder of a command: `out`, or `runs/<default>`.
pub fn out_dir(out: Option<&Path>, default: &str) -> std::path::PathBuf {
    out.map_or_else(|| Path::new("runs").join(default), Path::to_path_buf)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{IntegrationError, Stats};
    use crate::run::RunError;

    /// Issue 11 item 6: a run that diverged at t = 0 with a non-finite state has nothing to
    /// draw; its results are still written, the charts skipped (not "nothing to plot", exit 1).
    #[test]
    fn a_divergence_at_t0_writes_its_results_and_skips_the_empty_charts() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let scene = crate::config::load_scene(&root.join("config").join("paper-3g.toml"), &[]).unwrap();
        let dir = std::env::temp_dir().join(format!("plant-output-t0-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        prepare(&dir, &scene).unwrap();
        let mut folder = RunFolder::create(&dir, &scene).unwrap();
        let row = crate::trace::Row { t_s: 0.0, ..<crate::trace::Row as crate::trace::Columns>::NAN };
        folder.push(&Record::planar(row));
        let state = vec![f64::NAN; crate::model::N];
        let run = SinkRun {
            stats: Stats::default(),
            clock: crate::run::RunClock { simulated: scene.controller.period, started: 0.0, wall_time: 0.0 },
            outcome: Outcome::Diverged(RunError::Integration(IntegrationError::NonFinite { t: 0.0, state })),
            final_state: vec![0.0; crate::model::N],
            cosim: None,
            parked_steps: 0,
            voltage_saturation_s: None,
            planes: 1,
            invalid_commands: 0,
            ticks: Default::default(),
        };
        let written =
            folder.finish(&dir, &scene, run, &|| false).expect("a run with nothing to draw is not an output error");
        assert_eq!(written.summary.status, crate::status::Status::Diverged);
        assert!(written.summary.error.as_deref().unwrap_or_default().contains("non-finite state at t = 0 s"));
        assert!(written.skipped_charts.contains(&"orbit.png"), "{:?}", written.skipped_charts);
        assert!(!dir.join("orbit.png").exists());
        let trace = std::fs::read_to_string(dir.join("trace.csv")).unwrap();
        assert_eq!(trace.lines().count(), 2);
        let summary = std::fs::read_to_string(dir.join("summary.json")).unwrap();
        assert!(summary.contains("\"status\": \"diverged\""), "{summary}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
