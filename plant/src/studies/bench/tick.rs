//! The plant's execution time per tick (`plant bench tick`): what one tick of the plant
//! costs, alone, on the realtime setting and on the scene's own integrator.
//!
//! A realtime run must finish each tick inside its period. This bench runs a scene with its
//! law in the plant's process (`sampled` mode: the arithmetic of a lockstep run, and of a
//! realtime run without a deadline miss, with no controller process and no IPC), once per
//! setting and repeat, timing every tick as a co-simulation run does
//! ([`crate::cosim::stats::Tet`]): the integration alone, over all ticks and over those in
//! contact, the whole tick, and the most model evaluations in one tick. The settings are the
//! fixed-step setting of realtime runs ([`crate::config::Scene::fixed_step_overrides`]) and
//! the scene's own integrator. With `--pin-core` and `--realtime-priority` the bench's thread
//! runs pinned and under `SCHED_FIFO`, as a realtime run's plant does; the figures of a
//! realtime run against these say what the controller and the host add. Also the run's
//! figures (post-shock mode, peak contact force, largest radius, contact fraction), so that
//! the two settings' answers sit beside their costs. Writes `tick.csv` ([`TickRow`]).
//!
//! What the host adds shows in one more measurement, `repeat.csv` ([`RepeatRow`]): the same
//! tick in contact (the rotor 2 µm into its race, the race free, the realtime setting's
//! substeps) integrated from the same state as many times as the run has ticks. The work is
//! identical every time, so its spread is the machine's: interrupts, the hypervisor, caches,
//! other processes. On a two-plane rotor both bearing planes are 2 µm into their races.

use crate::analysis::classify::MotionMode;
use crate::config::{load_scene, Scene};
use crate::cosim::Launch;
use crate::hooks::Hooks;
use crate::machine::Machine;
use crate::status::Status;
use crate::summary::Summary;
use crate::table::sci;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Header of `tick.csv`.
pub const TICK_HEADER: &str = TickRow::HEADER;

crate::table::table_row! {
/// One run of one setting: a row of `tick.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct TickRow {
    /// `realtime fixed: …` or `scene: …` (the integrator in words).
    pub setting: String,
    /// Repeat number, from 1.
    pub run: usize,
    /// How the run ended.
    pub status: Status,
    /// Ticks timed.
    pub ticks: u64,
    /// Ticks that started or ended with the rotor touching its race.
    pub contact_ticks: u64,
    /// Integration alone, median (µs).
    #[serde(with = "sci")]
    pub integration_p50_us: f64,
    /// Integration alone, 99th percentile (µs).
    #[serde(with = "sci")]
    pub integration_p99_us: f64,
    /// Integration alone, 99.9th percentile (µs).
    #[serde(with = "sci")]
    pub integration_p999_us: f64,
    /// Integration alone, largest (µs).
    #[serde(with = "sci")]
    pub integration_max_us: f64,
    /// Integration alone over the ticks in contact, median (µs).
    #[serde(with = "sci")]
    pub contact_p50_us: f64,
    /// … 99th percentile (µs).
    #[serde(with = "sci")]
    pub contact_p99_us: f64,
    /// … 99.9th percentile (µs).
    #[serde(with = "sci")]
    pub contact_p999_us: f64,
    /// … largest (µs).
    #[serde(with = "sci")]
    pub contact_max_us: f64,
    /// The whole tick (sensor, law, park decision, integration, the trace row in memory), median (µs).
    #[serde(with = "sci")]
    pub tick_p50_us: f64,
    /// … 99.9th percentile (µs).
    #[serde(with = "sci")]
    pub tick_p999_us: f64,
    /// … largest (µs).
    #[serde(with = "sci")]
    pub tick_max_us: f64,
    /// The most model evaluations in one tick.
    pub max_rhs_evals_per_tick: u64,
    /// Wall time of the loop (s).
    #[serde(with = "sci")]
    pub wall_time_s: f64,
    /// Post-shock mode.
    pub post_shock_mode: MotionMode,
    /// Peak rotor – race force (N).
    #[serde(with = "sci")]
    pub max_contact_force_n: f64,
    /// Largest rotor radius (m).
    #[serde(with = "sci")]
    pub max_radius_m: f64,
    /// Contact fraction over the last 200 revolutions.
    #[serde(with = "sci")]
    pub contact_fraction: f64,
    /// The bench thread's scheduling: `other`, or `fifo 50`, and its core if pinned.
    pub scheduling: String,
    /// The machine's load average over the last minute when the run ended (`/proc/loadavg`).
    #[serde(with = "sci")]
    pub load_1min: f64,
}
}

/// Each bearing plane's control for a contact tick: its bias current, held (a planar model reads
/// the first).
fn held_bias(scene: &Scene) -> anyhow::Result<[crate::model::Control; 2]> {
    let bias = crate::run::bias_of(scene, &crate::run::plane_gains(scene)?);
    Ok([crate::model::Control::Held([bias[0], bias[1]]), crate::model::Control::Held([bias[2], bias[3]])])
}

/// Header of `repeat.csv`.
pub const REPEAT_HEADER: &str = RepeatRow::HEADER;

crate::table::table_row! {
/// The same tick integrated again and again: a row of `repeat.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct RepeatRow {
    /// What was repeated.
    pub setting: String,
    /// Repeats timed.
    pub repeats: u64,
    /// Model evaluations per repeat.
    pub rhs_evals: u64,
    /// Median (µs).
    #[serde(with = "sci")]
    pub p50_us: f64,
    /// 99th percentile (µs).
    #[serde(with = "sci")]
    pub p99_us: f64,
    /// 99.9th percentile (µs).
    #[serde(with = "sci")]
    pub p999_us: f64,
    /// Largest (µs).
    #[serde(with = "sci")]
    pub max_us: f64,
    /// The bench thread's scheduling.
    pub scheduling: String,
    /// The machine's load average over the last minute when it ended.
    #[serde(with = "sci")]
    pub load_1min: f64,
}
}

/// Integrates one contact tick of `scene` (the realtime setting) `repeats` times from the same
/// state, timing each: identical work, so the spread is the host's. The scene's rotor model with
/// each plane's bias current held, the races free, in its contact state
/// ([`crate::machine::Machine::contact_state`]); the bare model, without the scene's hardware.
fn repeat_contact_tick(scene: &Scene, repeats: u64) -> anyhow::Result<(crate::cosim::Percentiles, u64)> {
    crate::stepper::with_machine(scene, held_bias(scene)?, RepeatContactTick { scene, repeats })
}

/// [`repeat_contact_tick`] on the scene's model, whichever it is.
struct RepeatContactTick<'a> {
    scene: &'a Scene,
    repeats: u64,
}

impl crate::stepper::WithMachine for RepeatContactTick<'_> {
    type Output = anyhow::Result<(crate::cosim::Percentiles, u64)>;

    fn with<M, const N: usize, const NE: usize, const NU: usize>(self, model: M, y: [f64; N]) -> Self::Output
    where
        M: Machine<N> + Clone + 'static,
    {
        let y0 = model.contact_state(&y);
        let settings = crate::stepper::settings_of(self.scene, &model);
        time_repeated_tick(self.scene, &model, settings, y0, self.repeats)
    }
}

/// Integrates one tick of `model` (the scene's period, its contact substeps) from `y0`
/// `repeats` times, timing each; the percentiles (µs) and the evaluations per repeat.
fn time_repeated_tick<S: crate::integrate::System<N>, const N: usize>(
    scene: &Scene,
    model: &S,
    settings: crate::integrate::Settings<N>,
    y0: [f64; N],
    repeats: u64,
) -> anyhow::Result<(crate::cosim::Percentiles, u64)> {
    let mut integrator = crate::integrate::Integrator::new(settings);
    integrator.set_substeps(scene.integrator.contact_substeps);
    let (t0, t1) = (0.0, scene.controller.period);
    let mut times = crate::cosim::Latencies::new();
    for _ in 0..repeats {
        let mut y = y0;
        let start = std::time::Instant::now();
        integrator.advance(model, t0, t1, &mut y)?;
        times.record(start.elapsed().as_nanos() as u64);
        std::hint::black_box(&y);
    }
    Ok((times.percentiles(), integrator.stats().rhs_evals / repeats.max(1)))
}

/// The machine's load average over the last minute (`/proc/loadavg`), NaN where there is none.
pub fn load_average() -> f64 {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|v| v.parse().ok()))
        .unwrap_or(f64::NAN)
}

/// Pins the calling thread to `pin_core` and puts it under `SCHED_FIFO` at `priority` with
/// memory locked (0: the normal scheduler), as a realtime run's plant; returns what it got
/// (`other` or `fifo N`, and the core). What the system refuses is logged as a warning.
pub fn schedule(pin_core: Option<usize>, priority: u32, log: &mut dyn FnMut(&str)) -> anyhow::Result<String> {
    let mut scheduling = String::from("other");
    if let Some(core) = pin_core {
        controller::link::pin_to_core(core).map_err(|e| crate::exit::BadArgument(format!("--pin-core: {e}")))?;
    }
    if priority > 0 {
        let refused = controller::link::realtime(priority as i32);
        for r in &refused {
            log(&format!("warning: the system refused {r}"));
        }
        scheduling = controller::link::policy(0).to_string();
        if scheduling == "fifo" {
            scheduling = format!("fifo {priority}");
        }
    }
    if let Some(core) = pin_core {
        scheduling = format!("{scheduling}, core {core}");
    }
    Ok(scheduling)
}

/// What `plant bench tick` was asked to do.
pub struct Request<'a> {
    /// The scene file.
    pub scene: &'a Path,
    /// `--set` overrides.
    pub set: &'a [String],
    /// Runs per setting.
    pub repeats: usize,
    /// Output folder (default `runs/bench-tick`).
    pub out: Option<&'a Path>,
    /// Pin the bench's thread to this core.
    pub pin_core: Option<usize>,
    /// `SCHED_FIFO` at this priority (0: the normal scheduler).
    pub realtime_priority: u32,
}

/// Hooks that ask the loop to time every tick, and stop it on SIGINT/SIGTERM.
struct Timed<'a>(&'a std::sync::atomic::AtomicBool);
impl Hooks for Timed<'_> {
    fn time_ticks(&self) -> bool {
        true
    }

    fn cancelled(&self) -> bool {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }
}

/// The settings timed: the realtime one and the scene's own.
fn settings(req: &Request) -> anyhow::Result<Vec<(String, Scene)>> {
    let mut base = req.set.to_vec();
    base.extend(["controller.mode=\"sampled\"".to_string(), "output.plots=false".to_string()]);
    let own = load_scene(req.scene, &base)?;
    let mut fixed_sets = base.clone();
    fixed_sets.extend(own.fixed_step_overrides());
    let fixed = load_scene(req.scene, &fixed_sets)?;
    let describe = |s: &Scene| s.resolved().map(|r| r.integrator_and_race());
    Ok(vec![(format!("realtime fixed: {}", describe(&fixed)?), fixed), (format!("scene: {}", describe(&own)?), own)])
}

/// Runs the bench and writes `tick.csv`; returns its path.
pub fn command(req: &Request, log: &mut dyn FnMut(&str)) -> anyhow::Result<PathBuf> {
    if !(1..=1000).contains(&req.repeats) {
        return Err(crate::exit::BadArgument(format!("--repeats {}: must be between 1 and 1000", req.repeats)).into());
    }
    if req.realtime_priority > 99 {
        let why = format!("--realtime-priority {}: must be 0 (off) to 99", req.realtime_priority);
        return Err(crate::exit::BadArgument(why).into());
    }
    let settings = settings(req)?;
    let dir = crate::output::out_dir(req.out, "bench-tick");
    let _claim = crate::claim::claim(&dir, true)?;
    let scheduling = schedule(req.pin_core, req.realtime_priority, log)?;
    let stop = crate::interrupt::stop_flag();
    let stopped = || stop.load(std::sync::atomic::Ordering::Relaxed);
    let mut rows = Vec::new();
    'settings: for (label, scene) in &settings {
        for run in 1..=req.repeats {
            let result = crate::run::run_with(scene, &Launch::default(), &mut Timed(&stop))?;
            if stopped() && result.run.outcome == crate::run::Outcome::Interrupted {
                // A run stopped part-way is not a measurement of the setting.
                break 'settings;
            }
            let s = Summary::new(scene, &result);
            let report = result.run.ticks.tet.as_ref().map(|t| t.report()).unwrap_or_default();
            let row = TickRow {
                setting: label.clone(),
                run,
                status: s.status,
                ticks: report.tick.count,
                contact_ticks: report.integration_contact.count,
                integration_p50_us: report.integration.p50,
                integration_p99_us: report.integration.p99,
                integration_p999_us: report.integration.p999,
                integration_max_us: report.integration.max,
                contact_p50_us: report.integration_contact.p50,
                contact_p99_us: report.integration_contact.p99,
                contact_p999_us: report.integration_contact.p999,
                contact_max_us: report.integration_contact.max,
                tick_p50_us: report.tick.p50,
                tick_p999_us: report.tick.p999,
                tick_max_us: report.tick.max,
                max_rhs_evals_per_tick: result.run.ticks.max_rhs_evals,
                wall_time_s: result.run.clock.wall_time,
                post_shock_mode: s.analysis.post_shock_mode,
                max_contact_force_n: s.max_contact_force_n.unwrap_or(f64::NAN),
                max_radius_m: s.max_radius_m.unwrap_or(f64::NAN),
                contact_fraction: s.contact_fraction,
                scheduling: scheduling.clone(),
                load_1min: load_average(),
            };
            log(&format!(
                "{label}, run {run}: {}; integration p50 {:.2} / p99.9 {:.2} / max {:.2} µs, in contact ({} ticks) \
                 p99.9 {:.2} / max {:.2} µs; at most {} evaluations in a tick; {}; load {:.2}",
                row.status,
                row.integration_p50_us,
                row.integration_p999_us,
                row.integration_max_us,
                row.contact_ticks,
                row.contact_p999_us,
                row.contact_max_us,
                row.max_rhs_evals_per_tick,
                row.post_shock_mode,
                row.load_1min
            ));
            rows.push(row);
        }
    }
    let path = dir.join("tick.csv");
    crate::table::write_with_header(&path, TICK_HEADER, &rows)?;
    if stopped() {
        let planned = settings.len() * req.repeats;
        let why = format!("{} of {planned} runs finished, written to {}", rows.len(), path.display());
        return Err(crate::exit::Interrupted(why).into());
    }

    let (label, fixed) = &settings[0];
    let repeats = rows.first().map_or(1, |r| r.ticks.max(1));
    let (p, rhs_evals) = repeat_contact_tick(fixed, repeats)?;
    let repeat = RepeatRow {
        setting: format!("one contact tick repeated, {label}"),
        repeats: p.count,
        rhs_evals,
        p50_us: p.p50,
        p99_us: p.p99,
        p999_us: p.p999,
        max_us: p.max,
        scheduling: scheduling.clone(),
        load_1min: load_average(),
    };
    log(&format!(
        "{}: {} times, {} evaluations each: p50 {:.2} / p99 {:.2} / p99.9 {:.2} / max {:.2} µs (the same work: the \
         spread is the host's); load {:.2}",
        repeat.setting,
        repeat.repeats,
        repeat.rhs_evals,
        repeat.p50_us,
        repeat.p99_us,
        repeat.p999_us,
        repeat.max_us,
        repeat.load_1min
    ));
    crate::table::write_with_header(&dir.join("repeat.csv"), REPEAT_HEADER, &[repeat])?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::CONTACT_DEPTH;
    use crate::stepper::{with_machine, WithMachine};

    /// Each plane's contact state: whether the rotor touches the race, how deep it is in (m) and
    /// where the rotor is relative to the race (m).
    struct Depths;

    impl WithMachine for Depths {
        type Output = Vec<(bool, f64, [f64; 2])>;

        fn with<M, const N: usize, const NE: usize, const NU: usize>(self, model: M, y: [f64; N]) -> Self::Output
        where
            M: Machine<N> + Clone + 'static,
        {
            let y = model.contact_state(&y);
            let mut planes = Vec::new();
            model.plane_states(0.0, &y, &mut |i, p| {
                let d = p.rotor.0 - p.race.0;
                planes.push((model.touching(&y, i), d.norm() - p.params.contact.gap, [d.x, d.y]));
            });
            planes
        }
    }

    /// The repeated tick starts with the rotor 2 µm into each plane's race, straight down and
    /// centred in x, on every rotor model: the planar one, the two-plane rotor (the asymmetric
    /// scene: gaps of 150 and 250 µm, so the rotor tilts) and the flexible rotor (the rigid
    /// motion of the shaft, at its touchdown nodes, which are its AMB nodes).
    #[test]
    fn the_contact_tick_starts_with_each_plane_in_its_race() {
        for (file, planes, tolerance) in
            [("cosim-10g.toml", 1, 1e-12), ("two-plane-asymmetric-10g.toml", 2, 1e-12), ("flexible-10g.toml", 2, 1e-9)]
        {
            let scene = crate::shipped(file, &[]);
            let depths = with_machine(&scene, held_bias(&scene).unwrap(), Depths);
            assert_eq!(depths.len(), planes, "{file}");
            for (i, (touching, depth, [dx, dy])) in depths.into_iter().enumerate() {
                assert!(touching, "{file}: plane {i} not in contact");
                assert!(
                    (depth - CONTACT_DEPTH).abs() < tolerance && dx.abs() < tolerance && dy < 0.0,
                    "{file}: plane {i}: {depth} m in, ({dx}, {dy})"
                );
            }
        }
    }
}
