//! `plant`: runs scenes of the AMB/touchdown-bearing testbed.
//!
//! `main` → [`run`] → [`exit_code::code`], on ripgrep's model: every command
//! returns its errors to `main`, which prints them once ([`report`]) and maps
//! them to the exit code by their type, never by their text ([`exit_code`]
//! holds the codes and the one map; `docs/guide/running.md` the table).

mod cli;
mod exit_code;
mod fmu_exit;

use anyhow::Context;
use clap::{CommandFactory, FromArgMatches};
use cli::{BenchCommand, Cli, Command, ControllerArg};
use exit_code::Code;
use plant::config::{load_scene, Scene};
use plant::cosim::Launch;
use plant::exit::{Ending, StopKind};
use plant::run::{Hooks, Outcome};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Most round trips `plant bench ipc` records or warms up with (each recorded one keeps 8
/// bytes of figures).
const MAX_BENCH_SAMPLES: u64 = 10_000_000;

/// The command line, with negative numbers taken as values on every verb (`--max-speed-hz -1`
/// reaches the range check that names the flag and its bounds, rather than clap's
/// "unexpected argument '-1'").
fn parse_cli() -> Cli {
    fn negative_numbers(cmd: clap::Command) -> clap::Command {
        cmd.allow_negative_numbers(true).mut_subcommands(negative_numbers)
    }
    let matches = negative_numbers(Cli::command()).get_matches();
    Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit())
}

fn main() -> ExitCode {
    fmu_exit::keep();
    let cli = parse_cli();
    iceoryx2::prelude::set_log_level_from_env_or(iceoryx2::prelude::LogLevel::Fatal);
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            report(&err);
            ExitCode::from(u8::from(exit_code::code(&err)))
        }
    }
}

/// Prints an error once: `plant: error: …` (an interruption is not an error: `plant: …`).
fn report(err: &anyhow::Error) {
    let text = chain_text(err);
    if exit_code::code(err) == Code::Interrupted {
        eprintln!("plant: {text}");
    } else {
        eprintln!("plant: error: {text}");
    }
}

/// The error and its causes, `outer: inner: …`, each said once: a wrapper that displays its
/// cause (`#[error("{0}")]` with `#[from]`) would otherwise repeat it.
fn chain_text(err: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in err.chain() {
        let part = cause.to_string();
        if !text.ends_with(&part) {
            if !text.is_empty() {
                text.push_str(": ");
            }
            text.push_str(&part);
        }
    }
    text
}

/// A warning for the user.
fn warn(message: &str) {
    eprintln!("plant: warning: {message}");
}

/// Runs one command.
fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Run {
            scene,
            out,
            mut set,
            quiet,
            controller,
            run_id,
            save_state_at,
            from_state,
            robustness,
            mcap,
            live,
        } => {
            if mcap {
                set.push("output.mcap=true".into());
            }
            let states = States { save_at: save_state_at, from: from_state };
            if let Some(n) = robustness {
                set.push(format!("robustness.members={n}"));
            }
            run_scene(&scene, out, &set, quiet, controller.launch(run_id), states, live.as_deref())
        }
        Command::Soak { programme, out, mut set, quiet, resume, mcap, live } => {
            if mcap {
                set.push("output.mcap=true".into());
            }
            soak_cmd(&programme, out, &set, quiet, resume, live.as_deref())
        }
        Command::Compare { scene, rates, out, set, no_cosim, maps, laws, realtime, runs, robustness, live } => {
            let req = plant::compare::Request {
                scene: &scene,
                set: &set,
                rates: &rates,
                out: out.as_deref(),
                cosim: !no_cosim,
                maps,
                laws: &laws,
                realtime: realtime.then_some(runs),
                robustness,
                live: live.as_deref(),
            };
            let written = plant::compare::command(&req, &mut |l| eprintln!("plant compare: {l}"), &mut |w| warn(w))?;
            eprintln!("plant compare: wrote {}", written.display());
            Ok(())
        }
        Command::Analyze { dir } => analyze_cmd(&dir),
        Command::Fmu { scene, out, set, fmi, library } => fmu_cmd(&scene, &out, &set, fmi, library.as_deref()),
        Command::Campbell { scene, out, set, max_speed_hz, points, decay_speeds_hz } => {
            let req = plant::campbell::Request {
                scene: &scene,
                set: &set,
                out: out.as_deref(),
                max_speed_hz,
                points,
                decay_speeds_hz: &decay_speeds_hz,
            };
            let written = plant::campbell::command(&req, &mut |l| eprintln!("plant campbell: {l}"))?;
            for f in written {
                eprintln!("plant campbell: wrote {}", f.display());
            }
            Ok(())
        }
        Command::Linear { scene, speed_hz, out, set } => {
            let req = plant::linear::Request { scene: &scene, set: &set, speed_hz, out: out.as_deref() };
            for f in plant::linear::command(&req)? {
                eprintln!("plant linear: wrote {}", f.display());
            }
            Ok(())
        }
        Command::Sweep(args) => plant::sweep::command(&args),
        Command::Overlay(args) => plant::sweep::overlay::command(&args),
        Command::Ensemble(args) => plant::ensemble::command(&args),
        Command::Assess(args) => {
            let dir = plant::assess::command(&args, &plant::interrupt::stop_flag())?;
            eprintln!("plant assess: report in {}", dir.join("report.html").display());
            Ok(())
        }
        Command::Bench { what } => bench_cmd(what),
    }
}

/// Runs one `plant bench` command.
fn bench_cmd(what: BenchCommand) -> anyhow::Result<()> {
    match what {
        BenchCommand::Ensemble(args) => {
            plant::ensemble::bench::bench(&args, &mut |l| eprintln!("plant bench: {l}")).map(|_| ())
        }
        BenchCommand::Ipc { samples, warmup, pin_cores, spin_us, controller, run_id } => {
            bench_ipc(samples, warmup, pin_cores, spin_us, controller, run_id)
        }
        BenchCommand::Accuracy { out, config, repeats, quick, peer, peer_python, peer_rows, redraw } => {
            let req = plant::bench::accuracy::Request {
                out: out.as_deref(),
                config: &config,
                repeats,
                quick,
                peer_python: peer.then_some(peer_python.as_path()),
                peer_rows: peer_rows.as_deref(),
                redraw: redraw.as_deref(),
            };
            bench_wrote(plant::bench::accuracy::command(&req, &mut bench_log)?)
        }
        BenchCommand::Models { out, redraw: Some(csv), .. } => {
            bench_wrote([plant::bench::models::redraw(out.as_deref(), &csv)?])
        }
        BenchCommand::Models { out, config, repeats, redraw: None } => {
            bench_wrote([plant::bench::models::command(out.as_deref(), &config, repeats, &mut bench_log)?])
        }
        BenchCommand::Tick { scene, set, repeats, out, sched } => {
            let req = plant::bench::tick::Request {
                scene: &scene,
                set: &set,
                repeats,
                out: out.as_deref(),
                pin_core: sched.pin_core,
                realtime_priority: sched.realtime_priority,
            };
            bench_wrote([plant::bench::tick::command(&req, &mut bench_log)?])
        }
        BenchCommand::Host { rate_hz, seconds, out, sched } => {
            let (pin_core, realtime_priority) = (sched.pin_core, sched.realtime_priority);
            let req =
                plant::bench::host::Request { rate_hz, seconds, out: out.as_deref(), pin_core, realtime_priority };
            bench_wrote([plant::bench::host::command(&req, &mut bench_log)?])
        }
        BenchCommand::Engineering { out, config, repeats } => {
            bench_wrote([plant::bench::engineering::command(out.as_deref(), &config, repeats, &mut bench_log)?])
        }
    }
}

/// A progress line of `plant bench`.
fn bench_log(line: &str) {
    eprintln!("plant bench: {line}");
}

/// Names the files a bench wrote.
fn bench_wrote(files: impl IntoIterator<Item = PathBuf>) -> anyhow::Result<()> {
    for f in files {
        eprintln!("plant bench: wrote {}", f.display());
    }
    Ok(())
}

/// Loads a scene, prints its warnings and the stability check's; a scene the check refuses
/// is bad input.
fn load_checked(scene: &Scene) -> anyhow::Result<()> {
    for w in &scene.warnings {
        warn(w);
    }
    match plant::stability::check(scene) {
        plant::stability::StepVerdict::Fine => Ok(()),
        plant::stability::StepVerdict::Warn(w) => {
            warn(&w);
            Ok(())
        }
        plant::stability::StepVerdict::Refuse(why) => Err(Ending::BadArgument(why).into()),
    }
}

/// Wall time (s) after which a run's pace is judged ([`pace_warning`]).
const PACE_AFTER_S: f64 = 10.0;
/// Projected wall time (s) past which a run's pace is said.
const SLOW_RUN_S: f64 = 600.0;

/// A warning when a run, at the pace of its first [`PACE_AFTER_S`] of wall time or more, would
/// take longer than [`SLOW_RUN_S`]: legal values can make a run practically endless (issue 31
/// item 11: `contact.friction_static = 0` about 18 min for 1.5 s), and the user should learn
/// it from the run, not from the clock. `t` simulated of `duration` s in `wall` s.
fn pace_warning(t: f64, duration: f64, wall: f64) -> Option<String> {
    if wall < PACE_AFTER_S || t.is_nan() || t <= 0.0 || duration.is_nan() || duration <= t {
        return None;
    }
    let projected = wall * duration / t;
    (projected > SLOW_RUN_S).then(|| {
        format!(
            "at its pace so far ({t:.4} of {duration} s simulated in {wall:.0} s, {:.2e} of real time) this run \
             takes about {:.0} min; a stiff setting makes a run slow (contact.friction_static = 0, a fast \
             sensor.bandwidth_hz or amb.current_loop_hz under an adaptive integrator, a tight \
             integrator.rtol); Ctrl-C stops it and keeps what was computed",
            t / wall,
            projected / 60.0
        )
    })
}

/// Progress on stderr about once a second, a warning when the run is slow, and the Ctrl-C flag.
struct CliHooks {
    stop: Arc<AtomicBool>,
    duration: f64,
    started: Instant,
    last: Instant,
    quiet: bool,
    terminal: bool,
    /// The pace warning was given.
    pace_said: bool,
    /// `--save-state-at`, and the run folder the snapshots go to.
    save_at: Vec<f64>,
    dir: PathBuf,
    /// The first snapshot that could not be written.
    save_error: Option<plant::snapshot::SnapshotError>,
}

/// `plant run`'s `--save-state-at` and `--from-state`.
struct States {
    save_at: Vec<f64>,
    from: Option<PathBuf>,
}

impl States {
    /// The snapshot to start from, read and checked against `scene`, and the save times checked:
    /// bad input before anything is written.
    fn check(&self, scene: &Scene) -> anyhow::Result<Option<plant::snapshot::Snapshot>> {
        let from = match &self.from {
            None => None,
            Some(path) => {
                let snapshot = plant::snapshot::Snapshot::read(path)?;
                plant::run::check_start(scene, &snapshot)
                    .with_context(|| format!("--from-state {}", path.display()))?;
                if snapshot.t_s >= scene.duration {
                    return Err(Ending::BadArgument(format!(
                        "--from-state {}: the state is at t = {} s, not before the scene's end, \
                         scene.duration_s = {} s: nothing to run",
                        path.display(),
                        snapshot.t_s,
                        scene.duration
                    ))
                    .into());
                }
                Some(snapshot)
            }
        };
        let start = from.as_ref().map_or(0.0, |s| s.t_s);
        for (i, &t) in self.save_at.iter().enumerate() {
            let bad =
                |why: String| Ending::BadArgument(format!("--save-state-at {} s: {why}", plant::argument::shown(t)));
            if !(t.is_finite() && t > start && t <= scene.duration) {
                return Err(bad(format!(
                    "outside the run (after {start} s, up to scene.duration_s = {} s)",
                    scene.duration
                ))
                .into());
            }
            if i > 0 && t <= self.save_at[i - 1] {
                return Err(bad(format!(
                    "not after the time before it, {} s: give the times ascending",
                    self.save_at[i - 1]
                ))
                .into());
            }
        }
        Ok(from)
    }
}

impl Hooks for CliHooks {
    fn progress(&mut self, t: f64) {
        if self.last.elapsed() < Duration::from_secs(1) {
            return;
        }
        self.last = Instant::now();
        let wall = self.started.elapsed().as_secs_f64();
        if !self.pace_said {
            if let Some(w) = pace_warning(t, self.duration, wall) {
                self.pace_said = true;
                if self.terminal && !self.quiet {
                    eprintln!();
                }
                warn(&w);
            }
        }
        if self.quiet {
            return;
        }
        let line = format!(
            "plant: t = {t:.3}/{:.3} s ({:.0} %), {:.2}x real time",
            self.duration,
            100.0 * t / self.duration,
            t / wall
        );
        if self.terminal {
            eprint!("\r{line}   ");
        } else {
            eprintln!("{line}");
        }
    }

    fn cancelled(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    fn note(&mut self, message: &str) {
        if self.terminal && !self.quiet {
            eprint!("\r");
        }
        eprintln!("plant: {message}");
    }

    fn save_state_at(&self) -> &[f64] {
        &self.save_at
    }

    fn state_saved(&mut self, at: f64, snapshot: plant::snapshot::Snapshot) {
        let path = self.dir.join(plant::snapshot::Snapshot::file_name(at));
        match plant::snapshot::write(&snapshot, &path) {
            Ok(()) => self.note(&format!("state at t = {} s saved in {}", snapshot.t_s, path.display())),
            Err(e) => {
                self.note(&format!("warning: {e}"));
                self.save_error.get_or_insert(e);
            }
        }
    }
}

/// `plant run`.
fn run_scene(
    path: &Path,
    out: Option<PathBuf>,
    set: &[String],
    quiet: bool,
    launch: Launch,
    states: States,
    live: Option<&str>,
) -> anyhow::Result<()> {
    let scene = load_scene(path, set)?;
    load_checked(&scene)?;
    let from = states.check(&scene)?;
    let robustness = plant::robustness::members(&scene)?;
    if robustness > 0 && from.is_some() {
        let why = "a run from a saved state starts from that state, which the perturbations (the unbalance's angle \
                   and the rotor's start at t = 0) do not reach: save the state from a run with robustness instead";
        return Err(plant::config::ConfigError::Range {
            key: "robustness.members".into(),
            value: robustness.to_string(),
            unit: String::new(),
            why: why.into(),
        }
        .into());
    }
    let dir = out.unwrap_or_else(|| PathBuf::from("runs").join(&scene.name));
    let _claim = plant::claim::claim(&dir, true)?;
    let live = live.map(|addr| plant::live::start(addr, &scene)).transpose()?;
    if let Some(server) = &live {
        eprintln!("plant: live view at ws://{} (Foxglove WebSocket protocol)", server.addr());
    }
    let mut hooks = CliHooks {
        stop: plant::interrupt::stop_flag(),
        duration: scene.duration,
        started: Instant::now(),
        last: Instant::now(),
        quiet,
        terminal: std::io::stderr().is_terminal(),
        save_at: states.save_at,
        dir: dir.clone(),
        save_error: None,
        pace_said: false,
    };
    let mut written = match plant::output::run_to_dir_live(&dir, &scene, &launch, &mut hooks, from.as_ref(), live) {
        Ok(w) => w,
        Err(plant::output::RunDirError::Setup(e)) => {
            // The scene loaded: the folder records why the run did not start.
            if let Err(w) = plant::output::write_not_started(&dir, &scene, e.status().name(), &e.to_string()) {
                warn(&format!("{w:#}"));
            }
            return Err(e.into());
        }
        Err(plant::output::RunDirError::Output(e)) => return Err(e.context("writing the results")),
    };
    if hooks.terminal && !quiet && written.run.clock.wall_time >= 1.0 {
        eprintln!();
    }
    for chart in &written.skipped_charts {
        eprintln!("plant: {chart} not drawn: nothing to draw");
    }
    if let Some(s) = written.live {
        eprintln!("plant: {}", live_line(&s));
    }
    eprintln!("plant: {}; results in {}", written.summary.headline(), dir.display());
    if robustness > 0 && written.run.outcome != Outcome::Interrupted {
        robustness_of(path, set, &scene, &mut written, robustness, &dir, quiet)?;
    }
    if let Some(c) = written.summary.cosim.as_ref().filter(|c| c.schedule_held == Some(false)) {
        warn(&format!(
            "the realtime schedule did not hold: {} deadline misses ({:.3} % of the ticks with a reply due, \
             controller.max_miss_fraction = {}) and {} plant overruns ({:.3} %, controller.max_overrun_fraction = {}); \
             a late command is another control loop: `plant compare {} --realtime` shows whether it changed the outcome",
            c.deadline_misses,
            100.0 * c.deadline_miss_fraction,
            scene.controller.cosim.max_miss_fraction,
            c.plant_overruns,
            100.0 * c.plant_overrun_fraction,
            scene.controller.cosim.max_overrun_fraction,
            path.display()
        ));
    }
    stopped(&written.run.outcome, written.summary.simulated_s)?;
    match hooks.save_error {
        Some(e) => Err(e.into()),
        None => Ok(()),
    }
}

/// Runs the `n` perturbed members of a written run and adds their verdict to its
/// `summary.json` (written again, whole) and its last line.
fn robustness_of(
    path: &Path,
    set: &[String],
    scene: &Scene,
    written: &mut plant::output::Written,
    n: usize,
    dir: &Path,
    quiet: bool,
) -> anyhow::Result<()> {
    if !quiet {
        eprintln!("plant: robustness: {n} perturbed runs in parallel …");
    }
    let own = plant::ensemble::member::Figures::of_summary(&written.summary);
    let stop = plant::interrupt::stop_flag();
    match plant::robustness::assess(path, set, scene, &own, n, &stop).context("the robustness runs")? {
        Some(r) => {
            eprintln!("plant: {}", r.headline());
            written.summary.robustness = Some(r);
            plant::output::write_json(&dir.join("summary.json"), &written.summary)
        }
        None => {
            warn("robustness: interrupted; summary.json has the run without it");
            let why = "interrupted during the robustness runs".to_string();
            Err(Ending::Stopped { kind: StopKind::Interrupted, why, simulated_s: written.summary.simulated_s }.into())
        }
    }
}

/// `Err` for a run that did not complete (its results were written).
fn stopped(outcome: &Outcome, simulated_s: f64) -> anyhow::Result<()> {
    let (kind, why) = match outcome {
        Outcome::Completed => return Ok(()),
        Outcome::Diverged(e) => (StopKind::Diverged, e.to_string()),
        Outcome::Interrupted => (StopKind::Interrupted, "interrupted".to_string()),
        Outcome::PeerLost(why) => (StopKind::PeerLost, why.clone()),
        Outcome::MissBudget(why) => (StopKind::MissBudget, why.clone()),
        Outcome::InvalidCommands(why) => (StopKind::InvalidCommands, why.clone()),
        Outcome::OverrunBudget(why) => (StopKind::OverrunBudget, why.clone()),
    };
    Err(Ending::Stopped { kind, why, simulated_s }.into())
}

/// `plant soak`.
fn soak_cmd(
    path: &Path,
    out: Option<PathBuf>,
    set: &[String],
    quiet: bool,
    resume: bool,
    live: Option<&str>,
) -> anyhow::Result<()> {
    let prog = plant::soak::programme::load(path, set)?;
    load_checked(&prog.scene)?;
    let dir = out.unwrap_or_else(|| plant::soak::default_dir(path));
    let _claim = plant::claim::claim(&dir, true)?;
    let live = live.map(|addr| plant::live::start(addr, &prog.scene)).transpose()?;
    if let Some(server) = &live {
        eprintln!("plant soak: live view at ws://{} (Foxglove WebSocket protocol)", server.addr());
    }
    let stop = plant::interrupt::stop_flag();
    let progress = match (quiet, std::io::stderr().is_terminal()) {
        (true, _) => plant::soak::Progress::Quiet,
        (false, true) => plant::soak::Progress::Bar,
        (false, false) => plant::soak::Progress::Lines,
    };
    eprintln!(
        "plant soak: {} shocks over {} s simulated ({}), results in {}{}",
        prog.shocks.len(),
        prog.scene.duration,
        plant::summary::snake_name(&prog.scene.controller.mode),
        dir.display(),
        if resume { ", resumed from its checkpoint" } else { "" }
    );
    let opts = plant::soak::Options { dir: &dir, launch: Launch::default(), stop: &stop, progress, resume, live };
    let done = match plant::soak::run(&prog, path, opts) {
        Ok(d) => d,
        Err(plant::soak::SoakError::Setup(e)) => return Err(e.into()),
        Err(plant::soak::SoakError::Io(e)) => return Err(e),
        Err(plant::soak::SoakError::Resume(e)) => return Err(Ending::BadArgument(e.to_string()).into()),
    };
    let r = &done.report;
    if let Some(s) = done.live {
        eprintln!("plant soak: {}", live_line(&s));
    }
    eprintln!("plant soak: {}", r.headline());
    let failed: Vec<_> = r.criteria.iter().filter(|v| !v.passed).collect();
    for v in &failed {
        eprintln!("plant soak: criterion failed: {v}");
    }
    stopped(&done.outcome, r.simulated_s)?;
    if !failed.is_empty() {
        return Err(Ending::CriteriaFailed(failed.len()).into());
    }
    eprintln!("plant soak: all {} criteria met; results in {}", r.criteria.len(), dir.display());
    Ok(())
}

/// What a live view served, for a run's last lines.
fn live_line(s: &plant::live::Served) -> String {
    format!(
        "live view: {} client(s); {} frames made, {} not delivered (a client's queue full)",
        s.clients, s.frames, s.dropped
    )
}

/// `plant analyze`.
/// `plant fmu`: the scene checked as `plant run` checks it, then the FMU file.
fn fmu_cmd(path: &Path, out: &Path, set: &[String], fmi: u8, library: Option<&Path>) -> anyhow::Result<()> {
    let scene = load_scene(path, set)?;
    load_checked(&scene)?;
    let library = plant::fmu_export::find_library(library).map_err(Ending::BadArgument)?;
    let fmi = if fmi == 3 { plant::fmu_export::Fmi::V3 } else { plant::fmu_export::Fmi::V2 };
    let model = plant::fmu_export::package(&scene, &library, out, fmi)?;
    let (inputs, outputs, parameters) = model.variables.iter().fold((0, 0, 0), |(i, o, p), v| match v.role {
        plant::fmu_export::Role::Input(_) => (i + 1, o, p),
        plant::fmu_export::Role::Output(_) => (i, o + 1, p),
        plant::fmu_export::Role::Parameter(_) => (i, o, p + 1),
    });
    eprintln!(
        "plant: wrote {} (FMI {} co-simulation, model {}, {inputs} inputs, {outputs} outputs, {parameters} parameters; \
         communication step {} s or a whole multiple)",
        out.display(),
        fmi.version(),
        model.identifier,
        model.period
    );
    Ok(())
}

fn analyze_cmd(dir: &Path) -> anyhow::Result<()> {
    let _claim = plant::claim::claim(dir, false)?;
    let a = plant::output::analyze_dir(dir, &plant::interrupt::stop_flag())?;
    eprintln!(
        "plant: {}: post-shock mode {:?}, steady class {:?} (k = {:?}), whirl {:.1} Hz; summary.json updated",
        dir.display(),
        a.post_shock_mode,
        a.steady_class,
        a.period_k,
        a.whirl_hz
    );
    Ok(())
}

/// `plant bench ipc`: round trips through a controller process.
fn bench_ipc(
    samples: u64,
    warmup: u64,
    pin_cores: Option<Vec<usize>>,
    spin_us: f64,
    controller: ControllerArg,
    run_id: Option<String>,
) -> anyhow::Result<()> {
    for (flag, n) in [("--samples", samples), ("--warmup", warmup)] {
        if n > MAX_BENCH_SAMPLES {
            return Err(Ending::BadArgument(format!("{flag} {n}: must be at most {MAX_BENCH_SAMPLES}")).into());
        }
    }
    let pins = match pin_cores.as_deref() {
        None => None,
        Some(&[plant_core, controller_core]) => Some([plant_core, controller_core]),
        Some(other) => {
            return Err(Ending::BadArgument(format!(
                "--pin-cores {other:?}: expected two cores, PLANT,CONTROLLER (e.g. 0,1)"
            ))
            .into())
        }
    };
    if !(spin_us.is_finite() && (0.0..=1e6).contains(&spin_us)) {
        return Err(Ending::BadArgument(format!("--spin-us {spin_us} µs: must be between 0 and 1e6")).into());
    }
    let mut hooks = CliHooks {
        stop: plant::interrupt::stop_flag(),
        duration: 0.0,
        started: Instant::now(),
        last: Instant::now(),
        quiet: true,
        terminal: false,
        save_at: Vec::new(),
        dir: PathBuf::new(),
        save_error: None,
        pace_said: true,
    };
    let started = Instant::now();
    let launch = controller.launch(run_id);
    let (rt, latency, blocks) = plant::cosim::bench_round_trips(samples, warmup, &launch, pins, spin_us, &mut hooks)?;
    let wall = started.elapsed().as_secs_f64();
    println!(
        "ipc round trip (plant -> controller -> plant), {} samples: p50 {:.2} us, p99 {:.2} us, p99.9 {:.2} us, max {:.2} us",
        rt.count, rt.p50, rt.p99, rt.p999, rt.max
    );
    println!(
        "frame published -> reply published: p50 {:.2} us, p99 {:.2} us, p99.9 {:.2} us, max {:.2} us",
        latency.p50, latency.p99, latency.p999, latency.max
    );
    println!(
        "blocking waits {blocks}; pinned {}; spin {spin_us} us; {:.0} round trips/s overall",
        pins.map_or("no".to_string(), |p| format!("plant {} controller {}", p[0], p[1])),
        (samples + warmup) as f64 / wall
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 31 item 11: a run slowed to a crawl by legal values said nothing. Past 10 s of
    /// wall time, a projected wall time over 10 min is said with the estimate; a fast run, an
    /// early judgement and a run at its end say nothing.
    #[test]
    fn a_slow_run_is_told_its_projected_cost() {
        let w = pace_warning(0.01, 1.5, 12.0).expect("30 min projected");
        assert!(w.contains("about 30 min") && w.contains("0.0100 of 1.5 s") && w.contains("Ctrl-C"), "{w}");
        assert_eq!(pace_warning(0.5, 1.5, 12.0), None, "36 s projected");
        assert_eq!(pace_warning(0.0001, 1.5, 5.0), None, "judged too early");
        assert_eq!(pace_warning(0.0, 1.5, 60.0), None, "no simulated time yet");
        assert_eq!(pace_warning(1.5, 1.5, 900.0), None, "at its end");
    }

    #[test]
    fn each_cause_is_said_once() {
        let setup = plant::run::SetupError::Cosim(plant::cosim::CosimError::RunId("run id \"a b\": a space".into()));
        let err = anyhow::Error::from(setup).context("starting the run");
        assert_eq!(format!("{err:#}"), "starting the run: run id \"a b\": a space: run id \"a b\": a space");
        assert_eq!(chain_text(&err), "starting the run: run id \"a b\": a space");
        let plain = anyhow::anyhow!("disk full").context("writing trace.csv");
        assert_eq!(chain_text(&plain), "writing trace.csv: disk full");
    }
}
