//! The `plant` command line: clap types only (`main.rs` runs them).

use clap::{Parser, Subcommand};
use plant::cosim::{ControllerProcess, Launch};
use std::path::PathBuf;

use plant::argument::{count, number};

/// `--repeats` of the benches: 1 to 1000 (0 used to run once silently).
fn repeats() -> impl Fn(&str) -> Result<usize, String> + Clone + Send + Sync + 'static {
    count("a number of timed runs", 1, 1000)
}

/// `--robustness N` of `run` and `compare`: 0 to the most perturbed members a run may ask for.
fn robustness() -> impl Fn(&str) -> Result<u32, String> + Clone + Send + Sync + 'static {
    count("a number of perturbed runs", 0, plant::robustness::MAX_MEMBERS as u64)
}

/// A time of `--save-state-at` (s): any number, so that the run's own check says where the run
/// is (NaN and times outside it are refused there, naming the run's span).
fn time_in_run(s: &str) -> Result<f64, String> {
    s.trim().parse().map_err(|_| format!("`{s}` is not a time in the run: a number in s (e.g. 0.5 or 0.5,1.0)"))
}

/// A core number of the pinning flags.
fn core() -> impl Fn(&str) -> Result<usize, String> + Clone + Send + Sync + 'static {
    count("a core number", 0, 1023)
}

#[derive(Parser)]
#[command(name = "plant", version, about = "Rotor on AMBs with touchdown bearings under base shock")]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
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
        /// Co-simulation (`lockstep`, `realtime`): `spawn` starts the `controller` next to
        /// this executable; `external` waits for one you start with `controller --run-id ID`.
        #[arg(long, value_enum, default_value_t = ControllerArg::Spawn)]
        controller: ControllerArg,
        /// Co-simulation run id (names the shared-memory services); default: a fresh one.
        #[arg(long)]
        run_id: Option<String>,
        /// Save the plant's whole state at these times (s, ascending, within the run), each at
        /// the end of the first controller tick at or after it, as `state-T.json` in the output
        /// folder: `--from-state` continues from one.
        #[arg(long, value_delimiter = ',', value_name = "T[,T...]",
              value_parser = time_in_run)]
        save_state_at: Vec<f64>,
        /// Start from a state saved with `--save-state-at` (of a scene with the same rotor,
        /// hardware, integrator and rates; the controller, its law and gains, and the shock
        /// programme may differ): `trace.csv` then holds the rows after that state's time.
        #[arg(long, value_name = "FILE")]
        from_state: Option<PathBuf>,
        /// Also run N perturbed copies (the unbalance's angle by ±k·1e-9 rad, the rotor's start by
        /// ±k pm), in parallel, and say how robust the outcome is (summary.json `robustness`; the
        /// same as `--set robustness.members=N`).
        #[arg(long, value_name = "N", value_parser = robustness())]
        robustness: Option<u32>,
        /// Also record the run as run.mcap in the output folder, for Foxglove, Lichtblick and
        /// PlotJuggler (the same as `--set output.mcap=true`).
        #[arg(long)]
        mcap: bool,
        /// Serve the run live over the Foxglove WebSocket protocol on ADDR (default
        /// 127.0.0.1:8765; port 0: the system's choice, printed), at `output.live_rate_hz`
        /// (default 200 Hz of simulated time), for Foxglove or Lichtblick. Put it after the scene.
        #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = plant::live::DEFAULT_ADDR)]
        live: Option<String>,
    },
    /// Soak test: one long co-simulation through a programme of shocks; writes soak.csv (per
    /// shock), soak.json (overall, criteria), rss.csv, envelope.csv and plots.
    Soak {
        /// Programme file (TOML).
        programme: PathBuf,
        /// Output folder (default: runs/soak-<programme file stem>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a key of the programme's scene, after the programme's own `set` (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// No progress display.
        #[arg(long)]
        quiet: bool,
        /// Continue the soak in the output folder from its last checkpoint (taken at each
        /// shock's start), under the same programme and `--set`s: the soak's files come out as
        /// the uninterrupted soak's.
        #[arg(long)]
        resume: bool,
        /// Also record the soak as soak.mcap in the output folder, one file over all its shocks
        /// (the same as `--set output.mcap=true`).
        #[arg(long)]
        mcap: bool,
        /// Serve the soak live over the Foxglove WebSocket protocol on ADDR, as `plant run
        /// --live` does. Put it after the programme.
        #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = plant::live::DEFAULT_ADDR)]
        live: Option<String>,
    },
    /// Measurements of the testbed itself.
    Bench {
        #[command(subcommand)]
        what: BenchCommand,
    },
    /// Sampled against continuous PD: the scene with the continuous law and sampled at each
    /// rate (in-process and over iceoryx2); writes compare.csv and overlaid plots.
    Compare {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Controller rates, e.g. `5k,10k,20k,50k`.
        #[arg(long, default_value = "5k,10k,20k,50k", value_parser = plant::compare::parse_rates)]
        rates: std::vec::Vec<f64>,
        /// Output folder (default: runs/compare-<scene name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a scene key (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Skip the lockstep (controller process) runs.
        #[arg(long)]
        no_cosim: bool,
        /// Also draw the stability maps (rate × damping ratio, rate × delay).
        #[arg(long)]
        maps: bool,
        /// Compare control laws instead of rates: run the scene as it is (its mode and rate)
        /// once per law, e.g. `pd_delay,relev`; writes laws.csv and laws_*.png.
        #[arg(long, value_delimiter = ',', conflicts_with = "maps")]
        laws: Vec<String>,
        /// Realtime against lockstep: run the scene in realtime `--runs` times and once in
        /// lockstep on the same integrator setting (the realtime one); writes realtime.csv.
        #[arg(long, conflicts_with_all = ["maps", "laws", "no_cosim"])]
        realtime: bool,
        /// Realtime runs of `--realtime`.
        #[arg(long, default_value_t = 1, requires = "realtime", value_parser = count::<usize>("a number of realtime runs", 1, 1000))]
        runs: usize,
        /// Serve `--realtime`'s realtime runs live over the Foxglove WebSocket protocol on ADDR,
        /// one after the other, as `plant run --live` does (default 127.0.0.1:8765).
        #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = plant::live::DEFAULT_ADDR, requires = "realtime")]
        live: Option<String>,
        /// Give each compared run (rates or laws) its robustness answer with N perturbed copies,
        /// as `plant run --robustness N`, and say whether each difference from the reference
        /// run lies within the runs' spreads (compare_robustness.csv and .json).
        #[arg(long, value_name = "N", conflicts_with = "realtime", value_parser = robustness())]
        robustness: Option<u32>,
    },
    /// The whirl modes of a two-plane or flexible scene's rotor on its continuous PD against spin
    /// speed (Campbell diagram, linearised; a flexible rotor's bending modes beside its
    /// rigid-body modes) and, for the two-plane rotor, the same frequencies from simulated free
    /// decays; writes campbell.csv, campbell.png and decay.csv.
    Campbell {
        /// A two-plane or flexible scene file (TOML, `rotor.model = "two_plane"` or `"flexible"`).
        scene: PathBuf,
        /// Output folder (default: runs/campbell-<scene name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a scene key (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Highest spin speed of the diagram (Hz).
        #[arg(long, default_value_t = 500.0, value_parser = number("a spin speed", "Hz", 0.0, 1e5))]
        max_speed_hz: f64,
        /// Speeds of the diagram, from 0 to the highest (2 to 10000).
        #[arg(long, default_value_t = 51, value_parser = count::<usize>("a number of speeds", 2, 10_000))]
        points: usize,
        /// Spin speeds of the free decays (Hz), comma-separated; empty (`""`): none.
        #[arg(long, default_value = "0,250,500", value_parser = parse_speeds)]
        decay_speeds_hz: std::vec::Vec<f64>,
    },
    /// The scene's plant linearised about its levitated state at a spin speed, for
    /// python-control, MATLAB or numpy: from each axis' current command (A) to its sensor signal
    /// (V), continuous and as the controller sees it (zero-order hold at its rate, its delay);
    /// writes linear.json and linear.npz (docs/guide/linear.md).
    Linear {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Spin speed to linearise at (Hz); default: the scene's rotor.speed_hz.
        #[arg(long, allow_negative_numbers = true, value_parser = number("a spin speed", "Hz", 0.0, 1e5))]
        speed_hz: Option<f64>,
        /// Output folder (default: runs/linear-<scene name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a scene key (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Write the scene's plant as an FMI 2.0 (or 3.0) co-simulation FMU for Linux x86-64 (Simulink's FMU
    /// block, OpenModelica/OMSimulator, FMPy): modelDescription.xml, the binary, the scene in
    /// resources/ (docs/guide/fmu-plant.md).
    Fmu {
        /// Scene file (TOML).
        scene: PathBuf,
        /// The FMU file to write (e.g. plant.fmu).
        #[arg(long)]
        out: PathBuf,
        /// Override a scene key before it goes into the FMU (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// The FMI version: 2 (FMI 2.0 co-simulation) or 3 (FMI 3.0 co-simulation, with
        /// fixedInternalStepSize the controller tick).
        #[arg(long, default_value_t = 2, value_parser = count::<u8>("an FMI version", 2, 3))]
        fmi: u8,
        /// The FMU's binary (default: libplant_fmu.so next to this executable, which
        /// `cargo build -p plant-fmu` puts there).
        #[arg(long, value_name = "FILE")]
        library: Option<PathBuf>,
    },
    /// Analyse an existing run folder (trace.csv + scene.toml): spectra, spectrogram, Poincaré map,
    /// classification; updates summary.json and writes the analysis plots.
    Analyze {
        /// Run folder written by `plant run`.
        dir: PathBuf,
    },
    /// Sweep one scene key (or two, for a map) over a range, running the points in parallel
    /// (each point an ensemble with an `[ensemble]` table); writes points.csv, poincare.csv and
    /// bifurcation diagrams. Resumes an interrupted sweep.
    Sweep(plant::sweep::SweepArgs),
    /// Overlay the recovery probability of finished ensemble sweeps of one key on one chart,
    /// each sweep a curve with its Wilson 95 % intervals; writes overlay.png and overlay.csv.
    Overlay(plant::sweep::overlay::OverlayArgs),
    /// Judge controllers the way the field does: the stability margin of each axis (ISO 14839-3
    /// sensitivity, measured through the loop), the vibration (ISO 14839-2), the shock ladder
    /// and the touchdown bearing's duty; writes report.html, report.json and PNG charts.
    Assess(plant::assess::AssessArgs),
    /// Run a scene's ensemble (`[ensemble]`): members drawn around the scene; writes
    /// ensemble.csv, members.csv, ensemble.json and members.png.
    Ensemble(plant::ensemble::EnsembleArgs),
}

/// Who starts the controller process.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ControllerArg {
    /// The plant starts it and reaps it.
    Spawn,
    /// The user starts it.
    External,
}

impl ControllerArg {
    /// The launch of a co-simulation run.
    pub fn launch(self, run_id: Option<String>) -> Launch {
        let controller = match self {
            ControllerArg::Spawn => ControllerProcess::Spawn(None),
            ControllerArg::External => ControllerProcess::External,
        };
        Launch { controller, run_id, log: None }
    }
}

/// How a timing bench's thread runs, as a realtime run's plant does.
#[derive(clap::Args, Clone, Copy)]
pub struct BenchScheduling {
    /// Pin the bench's thread to this core.
    #[arg(long, value_parser = core())]
    pub pin_core: Option<usize>,
    /// `SCHED_FIFO` at this priority (1 to 99) with memory locked (`bench host`: and every
    /// core's idle latency held at 0); 0: the normal scheduler.
    #[arg(long, default_value_t = 0, value_parser = count::<u32>("a realtime priority (0: off)", 0, 99))]
    pub realtime_priority: u32,
}

#[derive(Subcommand)]
pub enum BenchCommand {
    /// Ensemble throughput (members per core-second, fast setting with and without
    /// verification, the scene's own setting) and how the fast setting's modes compare with
    /// the scene's own; writes bench.csv and bench.json.
    Ensemble(plant::ensemble::bench::BenchArgs),
    /// IPC round trip plant → controller process → plant (lockstep frames, the real
    /// controller binary); prints p50/p99/p99.9/max. Build with `--release` for figures.
    Ipc {
        /// Recorded round trips (1 to 1e7).
        #[arg(long, default_value_t = 200_000, value_parser = count::<u64>("a number of round trips", 1, 10_000_000))]
        samples: u64,
        /// Unrecorded round trips first (0 to 1e7).
        #[arg(long, default_value_t = 20_000, value_parser = count::<u64>("a number of round trips", 0, 10_000_000))]
        warmup: u64,
        /// Pin plant and controller to these cores, e.g. `--pin-cores 0,1`.
        #[arg(long, value_delimiter = ',', value_parser = core())]
        pin_cores: Option<Vec<usize>>,
        /// Busy-poll budget before blocking (µs, 0 to 1e6).
        #[arg(long, default_value_t = 200.0, value_parser = number("a busy-poll budget", "µs", 0.0, 1e6))]
        spin_us: f64,
        /// `spawn` (default) or `external`.
        #[arg(long, value_enum, default_value_t = ControllerArg::Spawn)]
        controller: ControllerArg,
        /// Run id; default: a fresh one.
        #[arg(long)]
        run_id: Option<String>,
    },
    /// Work-precision charts of every integrator on three scenes (levitation, impact, rub),
    /// the reference floor, and the stability limits of the fixed-step methods.
    Accuracy {
        /// Output folder (default: runs/bench-accuracy).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Scene folder holding paper-3g.toml and paper-10g.toml.
        #[arg(long, default_value = "config")]
        config: PathBuf,
        /// Timed runs per setting (1 to 1000); the minimum counts.
        #[arg(long, default_value_t = 5, value_parser = repeats())]
        repeats: usize,
        /// Two settings per method, one timed run: a smoke test of the bench.
        #[arg(long)]
        quick: bool,
        /// Also run the scipy peer (bench/peer, needs its venv: see bench/peer/README.md) on the
        /// same scenes and draw it on the same charts.
        #[arg(long)]
        peer: bool,
        /// Python interpreter for the peer.
        #[arg(long, default_value = "bench/peer/.venv/bin/python")]
        peer_python: PathBuf,
        /// Draw the peer rows of an earlier `accuracy.csv` (e.g. docs/charts/accuracy.csv) on the
        /// charts instead of running the peer; they keep their own timings.
        #[arg(long, conflicts_with = "peer")]
        peer_rows: Option<PathBuf>,
        /// Draw the charts of an earlier `accuracy.csv` (e.g. docs/charts/accuracy.csv, with the
        /// `stability.csv` beside it) again, keeping its timings: only the untimed references and
        /// the failure runs run.
        #[arg(long, conflicts_with_all = ["peer", "peer_rows", "quick"])]
        redraw: Option<PathBuf>,
    },
    /// Error and speed of each model simplification (lumped race support, fixed balls, speed
    /// held, linear bearing) against the most detailed model, on the same three scenes; then the
    /// shipped flexible machine against the rigid two-plane rotor of its rigid body
    /// (models_flexible.csv).
    Models {
        /// Output folder (default: runs/bench-models).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Scene folder holding paper-3g.toml, paper-10g.toml and flexible-10g.toml.
        #[arg(long, default_value = "config")]
        config: PathBuf,
        /// Timed runs per variant (1 to 1000); the minimum counts.
        #[arg(long, default_value_t = 5, value_parser = repeats())]
        repeats: usize,
        /// Draw the charts of an earlier `models.csv` (e.g. docs/charts/models.csv) again; nothing
        /// runs.
        #[arg(long)]
        redraw: Option<PathBuf>,
    },
    /// The plant's execution time per tick, alone (the law in process, no IPC), on the realtime
    /// fixed-step setting and on the scene's own integrator: integration p50/p99/p99.9/max over
    /// all ticks and over those in contact, the most model evaluations in one tick; writes
    /// tick.csv. Build with `--release` for figures.
    Tick {
        /// The scene.
        #[arg(long, default_value = "config/cosim-10g.toml")]
        scene: PathBuf,
        /// Override a scene key, e.g. `--set controller.rate_hz=10000`.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Runs per setting (1 to 1000).
        #[arg(long, default_value_t = 3, value_parser = repeats())]
        repeats: usize,
        /// Output folder (default: runs/bench-tick).
        #[arg(long)]
        out: Option<PathBuf>,
        #[command(flatten)]
        sched: BenchScheduling,
    },
    /// What the host adds: how late this machine starts each tick of a realtime run with
    /// nothing to compute, sleeping to each tick (`pacing = "sleep"`, as cyclictest) and
    /// spinning (`pacing = "spin"`); p50/p99/p99.9/max and the ticks more than a period late
    /// (a floor under a realtime run's plant overruns); writes host.csv. Build with
    /// `--release`, and give the run's `--pin-core` and `--realtime-priority`.
    Host {
        /// Ticks per second (a realtime scene's `controller.rate_hz`), 1 to 1e6.
        #[arg(long, default_value_t = 20_000.0, value_parser = number("a tick rate", "Hz", 1.0, 1e6))]
        rate_hz: f64,
        /// Seconds per loop (0.001 to 3600).
        #[arg(long, default_value_t = 10.0, value_parser = number("a loop's duration", "s", 1e-3, 3600.0))]
        seconds: f64,
        /// Output folder (default: runs/bench-host).
        #[arg(long)]
        out: Option<PathBuf>,
        #[command(flatten)]
        sched: BenchScheduling,
    },
    /// Engineering figures (peak contact force, max radius, contact fraction, post-shock mode)
    /// of full-length impact and rub runs for each method at a representative setting, against a
    /// DOP853 reference.
    Engineering {
        /// Output folder (default: runs/bench-engineering).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Scene folder holding paper-3g.toml and paper-10g.toml.
        #[arg(long, default_value = "config")]
        config: PathBuf,
        /// Timed runs per setting (1 to 1000); the minimum counts.
        #[arg(long, default_value_t = 3, value_parser = repeats())]
        repeats: usize,
    },
}

/// `--decay-speeds-hz`: speeds (Hz) separated by commas; the empty list (`""`) is none.
/// (`std::vec::Vec` in the field: clap then takes the whole list as one value, so that the
/// empty text reaches this parser.)
fn parse_speeds(text: &str) -> Result<Vec<f64>, String> {
    if text.trim().is_empty() {
        return Ok(Vec::new());
    }
    let speed = number("a spin speed", "Hz", 0.0, 1e5);
    text.split(',').map(|v| speed(v).map_err(|e| format!("{e} (e.g. 0,250,500, or \"\" for none)"))).collect()
}
