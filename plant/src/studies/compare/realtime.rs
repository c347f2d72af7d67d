//! Realtime against lockstep (`plant compare --realtime`): `realtime.csv` ([`RealtimeRow`]),
//! and whether the runs' traces are the same to the bit.

use super::*;

crate::table::table_row! {
/// One run of a realtime comparison (`plant compare --realtime`): a row of `realtime.csv`.
#[derive(Clone, Debug, Serialize)]
pub struct RealtimeRow {
    /// 0 for the lockstep run, 1… for the realtime runs.
    pub run: usize,
    /// `lockstep` or `realtime`.
    pub mode: ControlMode,
    /// How the run ended.
    pub status: Status,
    /// Ticks whose reply was missing (realtime).
    pub deadline_misses: u64,
    /// Their share of the ticks with a reply due.
    #[serde(with = "sci")]
    pub deadline_miss_fraction: f64,
    /// Longest run of consecutive misses.
    pub longest_miss_burst: u64,
    /// Ticks started more than a period late (realtime).
    pub plant_overruns: u64,
    /// The plant's whole tick, 99.9th percentile (µs).
    #[serde(with = "sci")]
    pub tick_p999_us: f64,
    /// … largest (µs).
    #[serde(with = "sci")]
    pub tick_max_us: f64,
    /// The integration alone, 99.9th percentile (µs).
    #[serde(with = "sci")]
    pub integration_p999_us: f64,
    /// … largest (µs).
    #[serde(with = "sci")]
    pub integration_max_us: f64,
    /// Sensor frame published → reply published, 99.9th percentile (µs).
    #[serde(with = "sci")]
    pub latency_p999_us: f64,
    /// Post-shock mode.
    pub post_shock_mode: MotionMode,
    /// Time from the shock start to the last contact (s); NaN if still in contact at the end.
    #[serde(with = "sci")]
    pub recovery_s: f64,
    /// Peak rotor – race force (N).
    #[serde(with = "sci")]
    pub max_contact_force_n: f64,
    /// Largest rotor radius (m).
    #[serde(with = "sci")]
    pub max_radius_m: f64,
    /// Contact fraction over the last 200 revolutions.
    #[serde(with = "sci")]
    pub steady_contact_fraction: f64,
    /// RMS distance of the rotor displacement from the lockstep run's over the whole run (m).
    #[serde(with = "sci")]
    pub rms_dev_m: f64,
    /// Largest distance (m).
    #[serde(with = "sci")]
    pub max_dev_m: f64,
    /// The trace is the lockstep run's, bit for bit (every run without a deadline miss is).
    pub same_as_lockstep: bool,
    /// The machine's load average over the last minute when the run ended.
    #[serde(with = "sci")]
    pub load_1min: f64,
}
}

/// Header of `realtime.csv`.
pub const REALTIME_HEADER: &str = RealtimeRow::HEADER;

/// Realtime against lockstep (`plant compare SCENE --realtime --runs N`): the scene in
/// realtime `runs` times, and once in lockstep on the same integrator setting (the realtime
/// one, [`Scene::fixed_step_overrides`] unless `integrator.realtime = "scene"`), so that the
/// only difference is the wall clock: a realtime run without a deadline miss is the lockstep
/// run bit for bit, and a run that differs shows what the host did to the outcome. Writes
/// `realtime.csv` ([`RealtimeRow`]) and `realtime_radius.png`.
///
/// With `live` (`--live ADDR`), the realtime runs' rows are served live as `plant run --live`
/// serves a run's ([`crate::live`]), one run after the other on one server (each run's times
/// start again at 0; `/events` says which run starts); the lockstep run is not served. The
/// address is listened on before any run (one that cannot be is bad input, exit 2).
pub fn compare_realtime(
    scene_path: &Path,
    sets: &[String],
    runs: usize,
    out: &Path,
    log: &mut dyn FnMut(&str),
    stop: &AtomicBool,
    live: Option<&str>,
) -> anyhow::Result<Vec<RealtimeRow>> {
    if !(1..=1000).contains(&runs) {
        return Err(crate::exit::BadArgument(format!("--runs {runs}: must be between 1 and 1000")).into());
    }
    let base: Vec<String> = sets.iter().cloned().chain(["output.plots=false".to_string()]).collect();
    let realtime = with(scene_path, &base, &["controller.mode=\"realtime\"".into()])?;
    let mut server = live.map(|addr| crate::live::start(addr, &realtime)).transpose()?;
    if let Some(s) = &server {
        log(&format!("live view at ws://{} (Foxglove WebSocket protocol), serving the realtime runs", s.addr()));
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    // The realtime scene as resolved holds its integrator setting: the lockstep twin keeps it.
    let lockstep = realtime.reload(&["controller.mode=\"lockstep\"".into()])?;
    let reference = finished(&lockstep, stop)?.ok_or_else(nothing_finished)?;
    let start = lockstep.first_shock_start();
    let row = |n: usize, scene: &Scene, r: &RunResult| {
        let s = Summary::new(scene, r);
        let c = s.cosim.clone();
        let tet = c.as_ref().and_then(|c| c.tet_us).unwrap_or_default();
        let (rms, max) = match r.run.outcome {
            Outcome::Completed => crate::trace::window_error(&r.trace, &reference.trace, 0.0, scene.duration, 1.0),
            _ => (f64::INFINITY, f64::INFINITY),
        };
        RealtimeRow {
            run: n,
            mode: scene.controller.mode,
            status: s.status,
            deadline_misses: c.as_ref().map_or(0, |c| c.deadline_misses),
            deadline_miss_fraction: c.as_ref().map_or(0.0, |c| c.deadline_miss_fraction),
            longest_miss_burst: c.as_ref().map_or(0, |c| c.longest_miss_burst),
            plant_overruns: c.as_ref().map_or(0, |c| c.plant_overruns),
            tick_p999_us: tet.tick.p999,
            tick_max_us: tet.tick.max,
            integration_p999_us: tet.integration.p999,
            integration_max_us: tet.integration.max,
            latency_p999_us: c.as_ref().map_or(f64::NAN, |c| c.latency_us.p999),
            post_shock_mode: s.analysis.post_shock_mode,
            recovery_s: recovery_time(&r.trace, start).unwrap_or(f64::NAN),
            max_contact_force_n: s.max_contact_force_n.unwrap_or(f64::NAN),
            max_radius_m: s.max_radius_m.unwrap_or(f64::NAN),
            steady_contact_fraction: s.analysis.steady_contact_fraction,
            rms_dev_m: rms,
            max_dev_m: max,
            same_as_lockstep: same_bits(&r.trace, &reference.trace),
            load_1min: crate::bench::tick::load_average(),
        }
    };
    let mut rows = vec![row(0, &lockstep, &reference)];
    log(&describe(&rows[0]));
    let mut traces: Vec<(String, RunResult)> = Vec::new();
    for n in 1..=runs {
        let done = match server.take() {
            None => finished(&realtime, stop)?,
            Some(s) => {
                let mut sink = crate::live::LiveSink::new(s, &realtime);
                sink.note(0.0, format!("realtime run {n} of {runs} starts"));
                let r = finished_live(&realtime, stop, &mut sink);
                let summary = r.as_ref().ok().and_then(|r| r.as_ref()).map(|r| Summary::new(&realtime, r));
                server = Some(sink.end_run(summary.as_ref()));
                r?
            }
        };
        let Some(r) = done else { break };
        let rw = row(n, &realtime, &r);
        log(&describe(&rw));
        rows.push(rw);
        if traces.len() < 9 {
            traces.push((format!("realtime {n}"), r));
        }
    }
    if let Some(s) = server {
        let served = s.stop();
        log(&format!(
            "live view: {} client(s); {} frames made, {} not delivered (a client's queue full)",
            served.clients, served.frames, served.dropped
        ));
    }
    crate::table::write_with_header(&out.join("realtime.csv"), REALTIME_HEADER, &rows)?;
    traces.insert(0, ("lockstep".into(), reference));
    let radius: Vec<(String, Vec<f64>, Vec<f64>)> = traces
        .iter()
        .flat_map(|(l, r)| plane_traces(l, &r.trace))
        .map(|(l, t)| (l, t.t_s.clone(), t.radius().iter().map(|v| v * 1e6).collect()))
        .collect();
    let series: Vec<Series> = radius.iter().map(|(l, x, y)| Series { label: l, x, y }).collect();
    plot::lines(
        &out.join("realtime_radius.png"),
        &format!("{}: rotor radius, realtime against lockstep ({})", realtime.name, gap_words(&realtime)),
        "time (s)",
        "radius (µm)",
        &series,
        Scale::Linear,
    )?;
    interrupted(stop, || format!("{} of {} runs finished, written to realtime.csv", rows.len(), runs + 1))?;
    Ok(rows)
}

/// A run's row as its log line.
fn describe(r: &RealtimeRow) -> String {
    format!(
        "{} {}: {}, {} deadline misses ({:.3} %, longest burst {}), {} plant overruns, tick p99.9 {:.1} µs max {:.1} µs; \
         {}, {}, peak force {:.0} N; {}; load {:.2}",
        snake_name(&r.mode),
        r.run,
        r.status,
        r.deadline_misses,
        100.0 * r.deadline_miss_fraction,
        r.longest_miss_burst,
        r.plant_overruns,
        r.tick_p999_us,
        r.tick_max_us,
        r.post_shock_mode,
        recovered(r.recovery_s),
        r.max_contact_force_n,
        if r.same_as_lockstep { "the lockstep trace bit for bit".to_string() } else { format!("max {:.2e} m from lockstep", r.max_dev_m) },
        r.load_1min
    )
}

/// Two traces hold the same numbers, bit for bit.
fn same_bits(a: &crate::trace::Trace, b: &crate::trace::Trace) -> bool {
    a.len() == b.len()
        && a.rows().zip(b.rows()).all(|(x, y)| {
            use crate::trace::Columns as _;
            x.values().iter().zip(&y.values()).all(|(p, q)| p.to_bits() == q.to_bits())
        })
}

/// [`finished`], the run's rows also served live by `live`: the trace kept in memory as
/// [`finished`] keeps it, and both fed from the thread a realtime run hands its rows to
/// ([`crate::offload`]), so that serving them stays out of the ticks.
fn finished_live(
    scene: &Scene,
    stop: &AtomicBool,
    live: &mut crate::live::LiveSink,
) -> anyhow::Result<Option<RunResult>> {
    if stop.load(Ordering::Relaxed) {
        return Ok(None);
    }
    let mut trace = crate::trace::Trace::with_capacity((scene.duration / scene.output_interval).ceil() as usize + 2);
    let mut tee = Tee { trace: &mut trace, live };
    let launch = crate::cosim::Launch::default();
    let when = crate::offload::When::Realtime;
    match crate::offload::run_into_offloaded(scene, &launch, &mut Cancel(stop), &mut tee, None, when) {
        Ok(run) if run.outcome == Outcome::Interrupted => Ok(None),
        Ok(run) => Ok(Some(RunResult { trace, run })),
        Err(_) if stop.load(Ordering::Relaxed) => Ok(None),
        Err(e) => Err(e.into()),
    }
}

/// The rows of a realtime run served live: into its trace and to the live view.
struct Tee<'a> {
    trace: &'a mut crate::trace::Trace,
    live: &'a mut crate::live::LiveSink,
}

impl crate::run::Sink for Tee<'_> {
    fn sample(&mut self, record: &crate::trace::Record) {
        self.trace.push(record);
        self.live.push(record);
    }

    fn tick(&mut self, sample: &controller::RotorSample, command: &[f64; controller::ROTOR_AXES]) {
        self.live.tick(sample, command);
    }

    fn wants_ticks(&self) -> bool {
        self.live.wants_ticks()
    }
}
