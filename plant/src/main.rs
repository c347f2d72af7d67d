//! `plant`: runs scenes of the AMB/touchdown-bearing testbed.

use anyhow::Context;
use clap::{Parser, Subcommand};
use plant::config::{load_scene, ConfigError};
use plant::run::{run, Hooks, Outcome};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Exit codes, one per kind of failure.
mod exit {
    /// Input or output failed (a file could not be written).
    pub const IO: u8 = 1;
    /// Bad input: a malformed or out-of-range scene, an unknown controller.
    pub const BAD_INPUT: u8 = 2;
    /// The simulation diverged (non-finite state, step-size underflow, radius guard).
    pub const DIVERGED: u8 = 3;
    /// Stopped by SIGINT/SIGTERM; results up to that point were written.
    pub const INTERRUPTED: u8 = 130;
}

#[derive(Parser)]
#[command(name = "plant", version, about = "Rotor on AMBs with touchdown bearings under base shock")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene: writes trace.csv, summary.json, scene.toml and PNG plots to the output folder.
    Run {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output folder (default: runs/<scene name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a scene key, e.g. `--set controller.damping_ratio=0.02` (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// No progress line.
        #[arg(long)]
        quiet: bool,
    },
}

/// Progress on stderr about once a second, and the Ctrl-C flag.
struct CliHooks {
    stop: Arc<AtomicBool>,
    duration: f64,
    started: Instant,
    last: Instant,
    quiet: bool,
    terminal: bool,
}

impl Hooks for CliHooks {
    fn progress(&mut self, t: f64) {
        if self.quiet || self.last.elapsed() < Duration::from_secs(1) {
            return;
        }
        self.last = Instant::now();
        let wall = self.started.elapsed().as_secs_f64();
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
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Run { scene, out, set, quiet } => run_scene(scene, out, set, quiet),
    }
}

fn run_scene(path: PathBuf, out: Option<PathBuf>, set: Vec<String>, quiet: bool) -> ExitCode {
    let scene = match load_scene(&path, &set) {
        Ok(s) => s,
        Err(e) => return bad_input(&e),
    };
    let dir = out.unwrap_or_else(|| PathBuf::from("runs").join(&scene.name));
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    if let Err(e) = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed)) {
        eprintln!("plant: warning: cannot install the Ctrl-C handler: {e}");
    }
    let mut hooks = CliHooks {
        stop,
        duration: scene.duration,
        started: Instant::now(),
        last: Instant::now(),
        quiet,
        terminal: std::io::stderr().is_terminal(),
    };
    let result = match run(&scene, &mut hooks) {
        Ok(r) => r,
        Err(e) => return bad_input(&ConfigError::Law(e)),
    };
    if hooks.terminal && !quiet && result.wall_time >= 1.0 {
        eprintln!();
    }
    let summary = match plant::output::write_run(&dir, &scene, &result).context("writing the results") {
        Ok(s) => s,
        Err(e) => {
            eprintln!("plant: error: {e:#}");
            return ExitCode::from(exit::IO);
        }
    };
    eprintln!(
        "plant: {} {} s simulated in {:.2} s ({:.2}x real time); max radius {:.1} µm, max contact force {:.0} N; results in {}",
        summary.status,
        summary.simulated_s,
        summary.wall_time_s,
        summary.realtime_factor,
        summary.max_radius_m * 1e6,
        summary.max_contact_force_n,
        dir.display()
    );
    match result.outcome {
        Outcome::Completed => ExitCode::SUCCESS,
        Outcome::Diverged(e) => {
            eprintln!("plant: error: {e}");
            ExitCode::from(exit::DIVERGED)
        }
        Outcome::Interrupted => {
            eprintln!("plant: interrupted; results up to t = {} s were written", summary.simulated_s);
            ExitCode::from(exit::INTERRUPTED)
        }
    }
}

fn bad_input(e: &ConfigError) -> ExitCode {
    eprintln!("plant: error: {e}");
    ExitCode::from(exit::BAD_INPUT)
}
