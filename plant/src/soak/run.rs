//! Running a soak: the loop's hooks (progress, Ctrl-C, RSS samples) and the
//! whole soak from `scene.toml` to `soak.json` and the charts.

use super::programme::Programme;
use super::report::{report, Finished};
use super::sink::{RssSample, SoakSink};
use super::{monitor, rss, ENVELOPE_BIN_S, ENVELOPE_CSV_HEADER, RSS_CSV_HEADER, SOAK_CSV_HEADER};
use crate::cosim::Launch;
use crate::hooks::Hooks;
use crate::offload::run_into_offloaded;
use crate::row_file::RowFile;
use crate::run::SetupError;
use anyhow::Context;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// How progress is shown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Progress {
    /// An indicatif bar (a terminal).
    Bar,
    /// A line about every 10 s (a log).
    Lines,
    /// Nothing.
    Quiet,
}

/// How a soak is run.
pub struct Options<'a> {
    /// Output folder.
    pub dir: &'a Path,
    /// Who starts the controller.
    pub launch: Launch,
    /// Set on Ctrl-C.
    pub stop: &'a AtomicBool,
    /// Progress display.
    pub progress: Progress,
}

/// Why a soak could not run or write its results.
#[derive(Debug, thiserror::Error)]
pub enum SoakError {
    /// The controller design or the co-simulation could not start.
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// A file could not be written.
    #[error("{0:#}")]
    Io(anyhow::Error),
}

/// Progress, Ctrl-C, notes, and the RSS samples.
struct SoakHooks<'a> {
    stop: &'a AtomicBool,
    progress: Progress,
    bar: Option<indicatif::ProgressBar>,
    started: Instant,
    last_line: Instant,
    duration: f64,
    period: f64,
    starts: Vec<f64>,
    rss_every: f64,
    /// Index of the next periodic RSS sample (at `next_rss × rss_every`).
    next_rss: u64,
    controller_pid: Option<u32>,
    rss: Vec<RssSample>,
    rss_csv: RowFile,
    error: Option<std::io::Error>,
}

impl SoakHooks<'_> {
    fn sample_rss(&mut self, t: f64) {
        let s = RssSample {
            t_s: t,
            wall_s: self.started.elapsed().as_secs_f64(),
            plant_kib: rss::rss_kib(None),
            controller_kib: self.controller_pid.and_then(|pid| rss::rss_kib(Some(pid))),
        };
        let written = self.rss_csv.row(s.fields()).and_then(|()| self.rss_csv.flush());
        if let Err(e) = written {
            self.error.get_or_insert(e);
        }
        self.rss.push(s);
    }

    fn shock_at(&self, t: f64) -> usize {
        self.starts.partition_point(|s| *s <= t)
    }
}

impl Hooks for SoakHooks<'_> {
    fn progress(&mut self, t: f64) {
        // RSS every `rss_every` of simulated time, and at the very end while the controller lives.
        let half = 0.5 * self.period;
        if t + half >= self.next_rss as f64 * self.rss_every || t >= self.duration {
            self.sample_rss(t);
            self.next_rss = ((t + half) / self.rss_every).floor() as u64 + 1;
        }
        match self.progress {
            Progress::Bar => {
                if let Some(bar) = &self.bar {
                    let pos = (t * 1e3) as u64;
                    if pos != bar.position() {
                        bar.set_position(pos);
                        if pos.is_multiple_of(100) {
                            bar.set_message(format!("shock {}/{}", self.shock_at(t), self.starts.len()));
                        }
                    }
                }
            }
            Progress::Lines if self.last_line.elapsed() >= Duration::from_secs(10) => {
                self.last_line = Instant::now();
                eprintln!(
                    "plant soak: t = {t:.1}/{:.1} s, shock {}/{}, {:.2}x real time",
                    self.duration,
                    self.shock_at(t),
                    self.starts.len(),
                    t / self.started.elapsed().as_secs_f64()
                );
            }
            _ => {}
        }
    }

    fn cancelled(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    fn note(&mut self, message: &str) {
        match &self.bar {
            Some(bar) => bar.println(format!("plant: {message}")),
            None => eprintln!("plant: {message}"),
        }
    }

    fn controller_connected(&mut self, pid: u32) {
        self.controller_pid = Some(pid);
    }
}

/// Runs a programme: writes `scene.toml` first, `soak.csv`, `rss.csv` and
/// `envelope.csv` as it goes, then `soak.json` and the plots.
pub fn run(prog: &Programme, programme_file: &Path, opts: Options) -> Result<Finished, SoakError> {
    let started = Instant::now();
    let dir = opts.dir;
    let io = SoakError::Io;
    std::fs::create_dir_all(dir).with_context(|| format!("creating output folder {}", dir.display())).map_err(io)?;
    let scene = &prog.scene;
    let resolved = scene.to_toml().context("serialising the resolved scene").map_err(io)?;
    crate::outfile::write(&dir.join("scene.toml"), resolved.as_bytes()).map_err(io)?;

    let create = |name: &str, header: &[&str]| {
        let path = dir.join(name);
        RowFile::create(&path, header).with_context(|| format!("creating {}", path.display())).map_err(io)
    };
    let soak_header: Vec<&str> = SOAK_CSV_HEADER.split(',').collect();
    let soak_csv = create("soak.csv", &soak_header)?;
    let envelope_csv = create("envelope.csv", &ENVELOPE_CSV_HEADER.split(',').collect::<Vec<_>>())?;
    let rss_csv = create("rss.csv", &RSS_CSV_HEADER.split(',').collect::<Vec<_>>())?;

    let starts: Vec<f64> = prog.shocks.iter().map(|s| s.start_s).collect();
    let mut sink = SoakSink {
        tracker: monitor::ShockTracker::new(
            starts.clone(),
            scene.duration,
            scene.output_interval,
            prog.clear_radius[0],
            prog.hold,
        ),
        envelope: monitor::Envelope::new(ENVELOPE_BIN_S),
        planned: &prog.shocks,
        clear_radius: prog.clear_radius.clone(),
        figures: Vec::with_capacity(prog.shocks.len()),
        soak_csv,
        envelope_csv,
        error: None,
    };
    let bar = (opts.progress == Progress::Bar).then(|| {
        let bar = indicatif::ProgressBar::new((scene.duration * 1e3) as u64);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {msg}, {elapsed} elapsed, ETA {eta}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar
    });
    let mut hooks = SoakHooks {
        stop: opts.stop,
        progress: opts.progress,
        bar,
        started: Instant::now(),
        last_line: Instant::now(),
        duration: scene.duration,
        period: scene.controller.period,
        starts,
        rss_every: prog.rss_every,
        next_rss: 0,
        controller_pid: None,
        rss: Vec::with_capacity((scene.duration / prog.rss_every).ceil() as usize + 4),
        rss_csv,
        error: None,
    };
    let launch = Launch { log: Some(dir.join("controller.log")), ..opts.launch.clone() };
    let mut result = match run_into_offloaded(scene, &launch, &mut hooks, &mut sink, None) {
        Ok(r) => r,
        Err(e) => {
            // The programme loaded: the folder records why the soak did not start.
            let record = serde_json::json!({
                "programme": prog.name,
                "programme_file": programme_file.display().to_string(),
                "status": e.status(),
                "error": e.to_string(),
                "simulated_s": 0.0,
                "planned_s": scene.duration,
                "shocks": prog.shocks.len(),
                "passed": false,
            });
            crate::output::write_json(&dir.join("soak.json"), &record).context("writing soak.json").map_err(io)?;
            return Err(e.into());
        }
    };
    if let Some(bar) = &hooks.bar {
        bar.finish_and_clear();
    }
    sink.finish();
    if let Some(e) = sink.error.take().or(hooks.error.take()) {
        return Err(io(anyhow::Error::new(e).context("writing soak.csv, envelope.csv or rss.csv")));
    }

    // A signal that comes once the loop has completed, while the outputs are written: every
    // output is still written, and the soak is `interrupted` (exit 130).
    let stopped = || opts.stop.load(Ordering::Relaxed);
    let late = |result: &mut crate::run::SinkRun| {
        let late = stopped() && result.outcome == crate::run::Outcome::Completed;
        if late {
            result.outcome = crate::run::Outcome::Interrupted;
        }
        late
    };
    late(&mut result);
    let write = |report: &super::Report| {
        crate::output::write_json(&dir.join("soak.json"), report).context("writing soak.json").map_err(io)
    };
    let mut report = report(prog, programme_file, &result, &sink.figures, &hooks.rss, started);
    write(&report)?;
    if prog.plots {
        super::plots::write_plots(dir, prog, &sink.figures, &hooks.rss).context("writing plots").map_err(io)?;
        if let Some(tet) = &result.ticks.tet {
            match crate::output::write_tet_chart(&dir.join("tet.png"), scene, tet) {
                Ok(()) | Err(crate::plot::PlotError::NoData { .. }) => {}
                Err(e) => return Err(io(anyhow::Error::new(e).context("writing tet.png"))),
            }
        }
    }
    if late(&mut result) {
        report = super::report::report(prog, programme_file, &result, &sink.figures, &hooks.rss, started);
        write(&report)?;
    }
    Ok(Finished { outcome: result.outcome, report })
}

/// Default output folder of a programme file: `runs/soak-<file stem>`.
pub fn default_dir(programme_file: &Path) -> PathBuf {
    let stem = programme_file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    PathBuf::from("runs").join(format!("soak-{stem}"))
}
