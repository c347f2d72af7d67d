//! Running a soak: the loop's hooks (progress, Ctrl-C, RSS samples) and the
//! whole soak from `scene.toml` to `soak.json` and the charts.

use super::checkpoint::{self, Checkpoint, ResumeError};
use super::programme::Programme;
use super::report::{report, Finished};
use super::sink::{Checkpoints, RssSample, SoakSink};
use super::{monitor, rss, ENVELOPE_BIN_S, ENVELOPE_CSV_HEADER, RSS_CSV_HEADER, SOAK_CSV_HEADER};
use crate::cosim::Launch;
use crate::hooks::Hooks;
use crate::offload::{run_into_offloaded, When};
use crate::recording::mcap_file::McapSink;
use crate::row_file::RowFile;
use crate::run::SetupError;
use crate::snapshot::Snapshot;
use anyhow::Context;
use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
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
    /// Continue the soak in `dir` from its checkpoint (`plant soak --resume`).
    pub resume: bool,
    /// Serve the soak live (`plant soak --live`).
    pub live: Option<crate::live::Server>,
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
    /// `--resume`: the folder holds no checkpoint of this programme, or its files do not
    /// match it.
    #[error(transparent)]
    Resume(#[from] super::checkpoint::ResumeError),
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
    /// The plant's snapshots at the shocks' starts, for the sink's checkpoints.
    snapshots: Arc<Mutex<VecDeque<Snapshot>>>,
    /// When to take them: the shocks' starts in lockstep; none in realtime, where a snapshot
    /// (it allocates) would fall inside a tick's deadline.
    checkpoint_at: Vec<f64>,
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

    fn save_state_at(&self) -> &[f64] {
        &self.checkpoint_at
    }

    fn state_saved(&mut self, _at: f64, snapshot: Snapshot) {
        self.snapshots.lock().unwrap_or_else(std::sync::PoisonError::into_inner).push_back(snapshot);
    }
}

/// Runs a programme: writes `scene.toml` first, `soak.csv`, `rss.csv` and
/// `envelope.csv` as it goes, then `soak.json` and the plots.
pub fn run(prog: &Programme, programme_file: &Path, mut opts: Options) -> Result<Finished, SoakError> {
    let started = Instant::now();
    let dir = opts.dir;
    std::fs::create_dir_all(dir)
        .with_context(|| format!("creating output folder {}", dir.display()))
        .map_err(SoakError::Io)?;
    let programme = checkpoint::fingerprint(prog).context("the programme as a value").map_err(SoakError::Io)?;
    // A resumed soak: everything checked before a file is touched.
    let saved = if opts.resume { Some(resumable(dir, prog)?) } else { None };
    let files = open_files(dir, prog, saved.as_ref())?;
    let checkpoints =
        Checkpoints { dir: dir.to_path_buf(), programme, queue: Arc::new(Mutex::new(VecDeque::new())), error: None };
    let snapshots = checkpoints.queue.clone();
    let mut sink = new_sink(prog, saved.as_ref(), files.soak_csv, files.envelope_csv, checkpoints);
    sink.live = opts.live.take().map(|s| crate::live::LiveSink::new(s, &prog.scene));
    sink.mcap = recording(dir, prog, opts.resume)?;
    let mut hooks = new_hooks(prog, &opts, started, files.rss_csv, files.rss, snapshots);
    let launch = Launch { log: Some(dir.join("controller.log")), ..opts.launch.clone() };
    // Offloaded in realtime only, as before `plant run` offloaded on a spare core: the soak's
    // checkpoints pass from the loop's hooks to its sink, an order not examined with the sink on
    // a thread of its own outside realtime (where no checkpoint is taken).
    let result = match run_into_offloaded(
        &prog.scene,
        &launch,
        &mut hooks,
        &mut sink,
        saved.as_ref().map(|c| &c.plant),
        When::Realtime,
    ) {
        Ok(r) => r,
        Err(e) => {
            write_not_started(dir, prog, programme_file, &e)?;
            return Err(e.into());
        }
    };
    if let Some(bar) = &hooks.bar {
        bar.finish_and_clear();
    }
    sink.finish();
    let live = sink.live.take().map(|l| l.finish(None));
    let recorded = sink.mcap.take().map(|m| m.finish(None)).transpose();
    if let Some(e) = sink.checkpoints.error.take() {
        hooks.note(&format!(
            "warning: a checkpoint could not be written ({e:#}): --resume continues from the last one written"
        ));
    }
    if let Some(e) = sink.error.take().or(hooks.error.take()) {
        return Err(SoakError::Io(anyhow::Error::new(e).context("writing soak.csv, envelope.csv or rss.csv")));
    }
    let mut finished = write_results(prog, programme_file, &opts, result, &sink, &mut hooks)?;
    finished.live = live;
    // The recording's failure (a full disk) is said after every other output was written.
    recorded.map_err(SoakError::Io)?;
    Ok(finished)
}

/// The soak's recording, `soak.mcap` (`[output] mcap`, `plant soak --mcap`): one file over all
/// its shocks. A resumed soak keeps the killed soak's file aside (`soak.1.mcap`, …) and records
/// from its checkpoint on; a soak without a recording removes an earlier soak's file.
fn recording(dir: &Path, prog: &Programme, resume: bool) -> Result<Option<McapSink>, SoakError> {
    let io = SoakError::Io;
    let path = dir.join(SOAK_MCAP);
    if !prog.scene.mcap {
        if !resume {
            crate::outfile::remove(&path).map_err(io)?;
        }
        return Ok(None);
    }
    if resume {
        crate::outfile::keep_aside(&path).map_err(io)?;
    }
    McapSink::create_at(&path, &prog.scene).map(Some).map_err(io)
}

/// The soak's recording's file name.
pub const SOAK_MCAP: &str = "soak.mcap";

/// The soak's row files and the RSS samples so far.
struct Files {
    soak_csv: RowFile,
    envelope_csv: RowFile,
    rss_csv: RowFile,
    rss: Vec<RssSample>,
}

/// A new soak: `scene.toml` and the row files written afresh (an earlier soak's checkpoint
/// removed); a resumed one (`saved`): the files reopened at the checkpoint's lengths.
fn open_files(dir: &Path, prog: &Programme, saved: Option<&Checkpoint>) -> Result<Files, SoakError> {
    let io = SoakError::Io;
    let soak_header: Vec<&str> = SOAK_CSV_HEADER.split(',').collect();
    let envelope_header: Vec<&str> = ENVELOPE_CSV_HEADER.split(',').collect();
    let rss_header: Vec<&str> = RSS_CSV_HEADER.split(',').collect();
    match saved {
        None => {
            // A checkpoint of an earlier soak in this folder would not describe this one's files,
            // and its charts and controller log would sit beside this one's results as if they
            // were its own: this soak draws its own charts (none with `output.plots = false`),
            // and a co-simulated one writes its own log.
            let earlier = [checkpoint::path(dir), dir.join("controller.log")];
            for path in earlier.into_iter().chain(super::plots::CHARTS.iter().map(|n| dir.join(n))) {
                crate::outfile::remove(&path).context("the earlier soak's file").map_err(io)?;
            }
            let resolved = prog.scene.to_toml().context("serialising the resolved scene").map_err(io)?;
            crate::outfile::write(&dir.join("scene.toml"), resolved.as_bytes()).map_err(io)?;
            let create = |name: &str, header: &[&str]| {
                let path = dir.join(name);
                RowFile::create(&path, header).with_context(|| format!("creating {}", path.display())).map_err(io)
            };
            Ok(Files {
                soak_csv: create("soak.csv", &soak_header)?,
                envelope_csv: create("envelope.csv", &envelope_header)?,
                rss_csv: create("rss.csv", &rss_header)?,
                rss: Vec::new(),
            })
        }
        Some(c) => {
            let reopen = |name: &str, header: &[&str], len: u64| {
                let path = dir.join(name);
                RowFile::reopen(&path, header, len).with_context(|| format!("reopening {}", path.display())).map_err(io)
            };
            let (rss_csv, rss) = rss_until(dir, &rss_header, c.plant.t_s).map_err(io)?;
            // The killed soak's controller log, kept before the resumed one writes its own.
            crate::outfile::keep_aside(&dir.join("controller.log")).map_err(io)?;
            Ok(Files {
                soak_csv: reopen("soak.csv", &soak_header, c.soak_csv_bytes)?,
                envelope_csv: reopen("envelope.csv", &envelope_header, c.envelope_csv_bytes)?,
                rss_csv,
                rss,
            })
        }
    }
}

/// The soak's sink, its monitor from the checkpoint (`saved`) or new.
fn new_sink<'a>(
    prog: &'a Programme,
    saved: Option<&Checkpoint>,
    soak_csv: RowFile,
    envelope_csv: RowFile,
    checkpoints: Checkpoints,
) -> SoakSink<'a> {
    let scene = &prog.scene;
    let (tracker, envelope, figures, rows) = match saved {
        Some(c) => (c.tracker.clone(), c.envelope.clone(), c.figures.clone(), c.rows),
        None => (
            monitor::ShockTracker::new(
                prog.shocks.iter().map(|s| s.start_s).collect(),
                scene.duration,
                scene.output_interval,
                prog.clear_radius[0],
                prog.hold,
            ),
            monitor::Envelope::new(ENVELOPE_BIN_S),
            Vec::with_capacity(prog.shocks.len()),
            0,
        ),
    };
    SoakSink {
        tracker,
        envelope,
        planned: &prog.shocks,
        clear_radius: prog.clear_radius.clone(),
        figures,
        soak_csv,
        envelope_csv,
        error: None,
        rows,
        checkpoints,
        live: None,
        mcap: None,
    }
}

/// The loop's hooks: the progress display, and the RSS samples going on from `rss` (those of
/// the soak resumed, whose wall clock goes on from its last sample's).
fn new_hooks<'a>(
    prog: &Programme,
    opts: &Options<'a>,
    started: Instant,
    rss_csv: RowFile,
    rss: Vec<RssSample>,
    snapshots: Arc<Mutex<VecDeque<Snapshot>>>,
) -> SoakHooks<'a> {
    let scene = &prog.scene;
    let starts: Vec<f64> = prog.shocks.iter().map(|s| s.start_s).collect();
    let wall_before = Duration::from_secs_f64(rss.last().map_or(0.0, |s| s.wall_s));
    let started = started.checked_sub(wall_before).unwrap_or(started);
    let half = 0.5 * scene.controller.period;
    let next_rss = rss.last().map_or(0, |s| ((s.t_s + half) / prog.rss_every).floor() as u64 + 1);
    let bar = (opts.progress == Progress::Bar).then(|| {
        let bar = indicatif::ProgressBar::new((scene.duration * 1e3) as u64);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {msg}, {elapsed} elapsed, ETA {eta}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar
    });
    SoakHooks {
        stop: opts.stop,
        progress: opts.progress,
        bar,
        started,
        last_line: Instant::now(),
        duration: scene.duration,
        period: scene.controller.period,
        checkpoint_at: if scene.controller.mode == crate::config::ControlMode::Realtime {
            Vec::new()
        } else {
            starts.clone()
        },
        starts,
        rss_every: prog.rss_every,
        next_rss,
        controller_pid: None,
        rss: {
            let mut all = Vec::with_capacity((scene.duration / prog.rss_every).ceil() as usize + 4);
            all.extend(rss);
            all
        },
        rss_csv,
        error: None,
        snapshots,
    }
}

/// The programme loaded but the soak did not start: `soak.json` records why.
fn write_not_started(dir: &Path, prog: &Programme, programme_file: &Path, e: &SetupError) -> Result<(), SoakError> {
    let record = serde_json::json!({
        "programme": prog.name,
        "programme_file": programme_file.display().to_string(),
        "status": e.status(),
        "error": e.to_string(),
        "simulated_s": 0.0,
        "planned_s": prog.scene.duration,
        "shocks": prog.shocks.len(),
        "passed": false,
    });
    crate::output::write_json(&dir.join("soak.json"), &record).context("writing soak.json").map_err(SoakError::Io)
}

/// `soak.json` and the plots of a soak that ran; the checkpoint removed once it completed.
fn write_results(
    prog: &Programme,
    programme_file: &Path,
    opts: &Options,
    mut result: crate::run::SinkRun,
    sink: &SoakSink,
    hooks: &mut SoakHooks,
) -> Result<Finished, SoakError> {
    let io = SoakError::Io;
    let dir = opts.dir;
    let scene = &prog.scene;
    let started = hooks.started;
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
    if result.outcome == crate::run::Outcome::Completed {
        // A completed soak has nothing to resume.
        if let Err(e) = crate::outfile::remove(&checkpoint::path(dir)) {
            hooks.note(&format!("warning: {e:#}"));
        }
    }
    Ok(Finished { outcome: result.outcome, report, live: None })
}

/// Default output folder of a programme file: `runs/soak-<file stem>`.
pub fn default_dir(programme_file: &Path) -> PathBuf {
    let stem = programme_file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    PathBuf::from("runs").join(format!("soak-{stem}"))
}

/// The checkpoint of the soak in `dir` and the check that it can go on under `prog`: the same
/// programme, a plant that takes its state, and its files at least as long as when the
/// checkpoint was taken. Nothing is written.
fn resumable(dir: &Path, prog: &Programme) -> Result<Checkpoint, SoakError> {
    let c = Checkpoint::read(dir, prog)?;
    // The monitor's parts against the programme's (an edited checkpoint's shock index out of
    // range made the plots panic, issue 40 item 7): refused here, naming the field.
    let refuse = |message: String| ResumeError::File {
        path: checkpoint::path(dir).display().to_string(),
        message: format!("{message}: an edited or foreign checkpoint; run without --resume to start afresh"),
    };
    let n = prog.shocks.len();
    if let Some((i, f)) = c.figures.iter().enumerate().find(|(i, f)| f.index != *i) {
        return Err(refuse(format!(
            "figures[{i}].index = {}: the closed shocks are the programme's first ones in order (it has {n}, 0 to {})",
            f.index,
            n.saturating_sub(1)
        ))
        .into());
    }
    if c.figures.len() > n {
        return Err(refuse(format!("{} closed shocks, but the programme has {n}", c.figures.len())).into());
    }
    let scene = &prog.scene;
    let starts = prog.shocks.iter().map(|s| s.start_s).collect();
    let fresh =
        monitor::ShockTracker::new(starts, scene.duration, scene.output_interval, prog.clear_radius[0], prog.hold);
    c.tracker.check_resumable(&fresh).map_err(refuse)?;
    c.envelope.check_resumable(&monitor::Envelope::new(ENVELOPE_BIN_S)).map_err(refuse)?;
    crate::run::check_start(&prog.scene, &c.plant)?;
    // The rest against the plant's state and the files (issue 40 item 4: an edited checkpoint
    // wrote a wrong soak.csv with "all criteria met", or cut soak.csv to 0 bytes before it
    // was refused).
    if c.plant.t_s >= scene.duration {
        return Err(refuse(format!(
            "plant.t_s = {} s: before the soak's end, scene.duration_s = {} s",
            c.plant.t_s, scene.duration
        ))
        .into());
    }
    if c.rows != c.plant.next_output {
        return Err(refuse(format!(
            "rows = {}: the rows before the plant's next output row, plant.next_output = {}",
            c.rows, c.plant.next_output
        ))
        .into());
    }
    c.tracker.check_at(c.rows, c.plant.t_s, c.figures.len()).map_err(refuse)?;
    c.envelope.check_at(c.tracker.last_t()).map_err(refuse)?;
    for (name, len) in [("soak.csv", c.soak_csv_bytes), ("envelope.csv", c.envelope_csv_bytes), ("rss.csv", 0)] {
        let path = dir.join(name);
        let fail = |message: String| ResumeError::File { path: path.display().to_string(), message };
        match std::fs::symlink_metadata(&path) {
            Err(e) => return Err(fail(format!("{e}: the soak's files are not all here")).into()),
            Ok(m) if !m.is_file() => return Err(fail("not a regular file".into()).into()),
            Ok(m) if m.len() < len => {
                return Err(fail(format!(
                    "{} bytes, fewer than the {len} written when the checkpoint was taken: cut short or replaced",
                    m.len()
                ))
                .into())
            }
            Ok(_) => {}
        }
    }
    let expected_soak: String = std::iter::once(SOAK_CSV_HEADER.to_owned())
        .chain(c.figures.iter().map(|f| super::sink::shock_row(f, &prog.shocks[f.index]).join(",")))
        .map(|line| line + "\n")
        .collect();
    let bin = c.envelope.bin();
    for (name, len) in [("soak.csv", c.soak_csv_bytes), ("envelope.csv", c.envelope_csv_bytes)] {
        let path = dir.join(name);
        let fail = |message: String| ResumeError::File { path: path.display().to_string(), message };
        let text = crate::input::read_text(&path, 1 << 30).map_err(|e| fail(format!("{e:#}")))?;
        let Some(head) = text.as_bytes().get(..len as usize) else {
            return Err(refuse(format!("{name}_bytes = {len}: more than the {} bytes of {name}", text.len())).into());
        };
        let head = String::from_utf8_lossy(head);
        let expected = if name == "soak.csv" {
            // The header and the closed shocks' rows, as the soak writes them from the figures.
            format!("{} bytes: the header and the {} closed shocks' rows", expected_soak.len(), c.figures.len())
        } else {
            format!("the header and the {} closed envelope bins' rows", c.envelope.index())
        };
        let good = if name == "soak.csv" {
            head == expected_soak
        } else {
            let mut lines = head.split_inclusive('\n');
            lines.next() == Some(&format!("{ENVELOPE_CSV_HEADER}\n"))
                && lines.enumerate().all(|(k, line)| {
                    line.ends_with('\n') && line.split(',').next() == Some(&(k as f64 * bin).to_string())
                })
                && head.lines().count() as u64 == c.envelope.index() + 1
        };
        if !good {
            let field = name.replace('.', "_");
            return Err(refuse(format!("{field}_bytes = {len}: {name}'s first {len} bytes are not {expected}")).into());
        }
    }
    Ok(c)
}

/// `rss.csv` of a soak resumed from `t_s`: its rows up to that time kept (written anew, whole),
/// and reopened to go on.
fn rss_until(dir: &Path, header: &[&str], t_s: f64) -> anyhow::Result<(RowFile, Vec<RssSample>)> {
    let path = dir.join("rss.csv");
    let text = crate::input::read_text(&path, 1 << 30)?;
    let mut kept = format!("{}\n", header.join(","));
    let mut samples = Vec::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let (Some(t), Some(wall)) =
            (f.first().and_then(|v| v.parse::<f64>().ok()), f.get(1).and_then(|v| v.parse().ok()))
        else {
            continue;
        };
        if f.len() != header.len() || t > t_s {
            continue;
        }
        let kib = |i: usize| f.get(i).and_then(|v| v.parse::<u64>().ok());
        samples.push(RssSample { t_s: t, wall_s: wall, plant_kib: kib(2), controller_kib: kib(3) });
        kept.push_str(line);
        kept.push('\n');
    }
    crate::outfile::write(&path, kept.as_bytes())?;
    let file =
        RowFile::reopen(&path, header, kept.len() as u64).with_context(|| format!("reopening {}", path.display()))?;
    Ok((file, samples))
}
