//! Checking a law against a run: any law (a registry's, or a crate's own
//! [`LawEntry`]) run in this process on a scene, and a recorded `trace.csv`
//! replayed through it.
//!
//! * [`run_law`] runs a scene with the law in the plant's process, as
//!   `controller.mode = "sampled"` runs a law of the registry: a law served by
//!   its own controller process in `lockstep` must give the same trace, bit
//!   for bit.
//! * [`replay`] reads a run folder (`scene.toml`, `trace.csv`), builds the
//!   law from the folder's design and `[controller.params]`, feeds it the
//!   sensor samples the run's controller read (rebuilt from the trace's `dx_m`,
//!   `dy_m` at each tick through the scene's sensor: gain, seeded noise, ADC;
//!   the keyphasor from `rotor_speed_rad_s` and `rotor_angle_rad`),
//!   and compares what it answers, saturated, held over non-finite answers and
//!   delayed `delay_samples` ticks, with the currents the trace applied
//!   (`ix_a`, `iy_a`), bit for bit. The alignment: the current of row `r` at
//!   time `t_r` is the one held over the tick ending at `t_r`, computed from
//!   the sample `ceil(t_r / T) − 1 − d` (row 0 holds the bias). With
//!   `output.rate_hz = controller.rate_hz` (the default), row k is tick k and
//!   its current comes from sample `k − 1 − d` (`k − 2` with one sample of
//!   delay).
//!
//! Sampled and lockstep runs replay exactly; a realtime run (one-sample-old
//! replies, deadline misses) or a run whose controller was lost or replaced
//! (fallback, reconnection) shows differences, which the report names.
//!
//! ```no_run
//! # fn main() -> anyhow::Result<()> {
//! use plant::check::{replay, run_law};
//! let scene = plant::config::load_scene("config/cosim-10g.toml".as_ref(), &["scene.duration_s=0.05".into()])?;
//! let run = run_law(&scene, &controller::pd::LAW, &mut plant::run::Quiet)?;
//! plant::output::write_run("runs/pd-in-process".as_ref(), &scene, &run)?;
//! let report = replay("runs/pd-in-process".as_ref(), &controller::pd::LAW)?;
//! assert!(report.identical(), "{report}");
//! # Ok(()) }
//! ```

use crate::config::{ConfigError, ControlMode, Scene};
use crate::digital::CommandPath;
use crate::hooks::Hooks;
use crate::run::{RunResult, SetupError};
use crate::sensor::Sensor;
use crate::trace::{Trace, TraceError};
use controller::{ControlLaw, LawEntry, LawError, RotorLaw, RotorSample, ROTOR_AXES};
use std::path::Path;

/// Runs `scene` with `law` (built from the scene's design and `[controller.params]`) in this
/// process, as sampled mode does, whatever the scene's `controller.mode`.
pub fn run_law(scene: &Scene, law: &LawEntry, hooks: &mut dyn Hooks) -> Result<RunResult, SetupError> {
    // One per bearing plane, side by side (the planar model's one plane: the law's own arithmetic).
    let built = controller::AnyLaw::from(*law).build(&scene.rotor_design(), &scene.controller.params)?;
    let mut trace = Trace::with_capacity((scene.duration / scene.output_interval).ceil() as usize + 2);
    let run = crate::run::run_law_into(scene, built, hooks, &mut trace)?;
    Ok(RunResult { trace, run })
}

/// Why a run folder could not be replayed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// `scene.toml` could not be loaded.
    #[error(transparent)]
    Scene(#[from] ConfigError),
    /// The law refuses the folder's design or parameters.
    #[error(transparent)]
    Law(#[from] LawError),
    /// `trace.csv` could not be read.
    #[error(transparent)]
    Trace(#[from] TraceError),
    /// The run cannot be replayed (a continuous run; trace rows that are not at the ticks).
    #[error("{0}")]
    Layout(String),
}

/// A tick whose applied current is not the law's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Difference {
    /// The sample the command was computed from.
    pub seq: u64,
    /// Its time (s).
    pub t_s: f64,
    /// The trace row that holds it (from 0, the header not counted).
    pub row: usize,
    /// The bearing plane whose currents differ (0: A, the planar model's; 1: B).
    pub plane: usize,
    /// The currents the trace applied (A).
    pub trace_a: [f64; 2],
    /// The law's (A).
    pub law_a: [f64; 2],
}

/// What a replay found.
#[derive(Clone, Debug, PartialEq)]
pub struct Replay {
    /// Rows compared (every row after the first tick's command is due).
    pub compared: u64,
    /// Rows whose currents differ from the law's in any bit.
    pub differing: u64,
    /// The first of them.
    pub first: Option<Difference>,
    /// The largest difference (A).
    pub largest_a: f64,
}

impl Replay {
    /// Every compared current is the law's, bit for bit (and at least one was compared).
    pub fn identical(&self) -> bool {
        self.compared > 0 && self.differing == 0
    }
}

impl std::fmt::Display for Replay {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.first {
            None => write!(f, "{} rows compared: every applied current is the law's, bit for bit", self.compared),
            Some(d) => write!(
                f,
                "{} of {} rows differ (largest {:e} A); the first: row {} (sample {}, t = {} s) applied {:?} A, the law gives {:?} A",
                self.differing, self.compared, self.largest_a, d.row, d.seq, d.t_s, d.trace_a, d.law_a
            ),
        }
    }
}

/// Replays the run folder `dir` through `law`, built from the folder's design and
/// `[controller.params]` (see the module doc): once per bearing plane, or the whole rotor's.
pub fn replay(dir: &Path, law: &LawEntry) -> Result<Replay, ReplayError> {
    let scene = crate::config::load_scene(&dir.join("scene.toml"), &[])?;
    let mut built = controller::AnyLaw::from(*law).build(&scene.rotor_design(), &scene.controller.params)?;
    replay_rotor_trace(&scene, &dir.join("trace.csv"), built.as_mut())
}

/// Replays `trace` (a `trace.csv` of a run of `scene`, planar) through the per-plane `law`, as
/// it is (not reset). A two-plane run needs a law per plane: [`replay`] or
/// [`replay_rotor_trace`].
pub fn replay_trace(scene: &Scene, trace: &Path, law: &mut dyn ControlLaw) -> Result<Replay, ReplayError> {
    if scene.planes() != 1 {
        return Err(ReplayError::Layout(
            "one per-plane law cannot serve both planes of a two-plane run: replay it with plant::check::replay \
             or replay_rotor_trace (a law per plane)"
                .into(),
        ));
    }
    replay_rotor_trace(scene, trace, &mut OnePlane(law))
}

/// A per-plane law on the planar model's one plane, as a law of the rotor.
struct OnePlane<'a>(&'a mut dyn ControlLaw);

impl RotorLaw for OnePlane<'_> {
    fn name(&self) -> &'static str {
        self.0.name()
    }
    fn update(&mut self, sample: &RotorSample) -> [f64; ROTOR_AXES] {
        let [x, y] = self.0.update(&sample.plane(0));
        let mut out = [0.0; ROTOR_AXES];
        out[..2].copy_from_slice(&[x, y]);
        out
    }
    fn reset(&mut self) {
        self.0.reset();
    }
}

/// Replays `trace` (a `trace.csv` of a run of `scene`, planar or two-plane) through `law`, a
/// law of the whole rotor, as it is (not reset): every axis's sensor sample rebuilt from the
/// trace through the scene's sensor (one noise sequence, the planes in order, as the plant
/// reads them), the answer through the digital loop's own command path
/// ([`crate::digital::CommandPath`]: saturation, held non-finite answers, the delay line), and
/// the applied currents compared with every plane's current columns.
pub fn replay_rotor_trace(scene: &Scene, trace: &Path, law: &mut dyn RotorLaw) -> Result<Replay, ReplayError> {
    let c = &scene.controller;
    if c.mode == ControlMode::Continuous {
        return Err(ReplayError::Layout(
            "a continuous run has no controller ticks (its PD acts inside the derivative): nothing to replay".into(),
        ));
    }
    if scene.hardware.front_end.is_on() {
        return Err(ReplayError::Layout(
            "the run's sensor has a front end (sensor.bandwidth_hz, runout or range): what the controller read is not \
             in the trace's displacements"
                .into(),
        ));
    }
    if let Some(p) = scene.rotor.non_collocated_plane() {
        return Err(ReplayError::Layout(format!(
            "plane {}'s sensor is not at its bearing: the trace holds the displacement at the bearing, not what the \
             sensor read",
            ["A", "B"][p]
        )));
    }
    let (period, out_dt) = (c.period, scene.output_interval);
    // Rows per tick; a row at a tick time is the state the controller read there.
    let per_tick = (period / out_dt).round();
    if !(per_tick >= 1.0 && (per_tick * out_dt - period).abs() <= 1e-9 * period) {
        return Err(ReplayError::Layout(format!(
            "output.rate_hz = {} Hz is not a whole multiple of controller.rate_hz = {} Hz: the trace has no row at every tick",
            1.0 / out_dt,
            c.rate_hz
        )));
    }
    let per_tick = per_tick as u64;
    let planes = scene.planes();
    let bias = crate::run::bias_of(scene, &crate::run::plane_gains(scene)?);
    let limits = scene.rotor_design().current_limits();
    let delay = c.delay_samples as usize;
    let mut sensor = Sensor::new(scene.sensor);
    let mut path = CommandPath::new(bias, limits, delay, u64::MAX, 1.0);
    let mut applied = bias;
    let mut report = Replay { compared: 0, differing: 0, first: None, largest_a: 0.0 };
    let mut row: u64 = 0;
    let mut bad_time = None;
    crate::trace::read_rows(trace, |record| {
        let t_row = record.a.t_s;
        // Row `row` closes the step of tick `(row − 1) / per_tick`; the command of that tick was
        // pushed when its sample (the row at its start) was read.
        if row > 0 {
            report.compared += 1;
            let mut differs = false;
            for p in 0..planes {
                let r = record.plane(p);
                let (trace_a, law_a) = ([r.loads.ix_a, r.loads.iy_a], [applied[2 * p], applied[2 * p + 1]]);
                if trace_a.iter().zip(&law_a).all(|(t, l)| t.to_bits() == l.to_bits()) {
                    continue;
                }
                differs = true;
                let gap = (trace_a[0] - law_a[0]).abs().max((trace_a[1] - law_a[1]).abs());
                report.largest_a = report.largest_a.max(if gap.is_nan() { f64::INFINITY } else { gap });
                let tick = (row - 1) / per_tick;
                let from = tick.checked_sub(delay as u64);
                report.first.get_or_insert(Difference {
                    seq: from.unwrap_or(0),
                    t_s: from.map_or(0.0, |k| k as f64 * period),
                    row: row as usize,
                    plane: p,
                    trace_a,
                    law_a,
                });
            }
            report.differing += u64::from(differs);
        }
        if row.is_multiple_of(per_tick) {
            let k = row / per_tick;
            let t_s = k as f64 * period;
            if (t_row - t_s).abs() > 1e-6 * period + 4.0 * f64::EPSILON * t_s.abs() {
                bad_time = Some((row, t_row, t_s));
                return false;
            }
            let a = &record.a;
            let mut sample = RotorSample {
                seq: k,
                t_s,
                axes: 2 * planes as u32,
                speed_rad_s: a.spin.rotor_speed_rad_s,
                angle_rad: controller::wrap_angle(a.spin.rotor_angle_rad),
                ..Default::default()
            };
            for p in 0..planes {
                let r = record.plane(p);
                let gain = scene.plane(p).loop_constants.sensor_gain_v_per_m;
                let v = sensor.read_with_gain([r.motion.dx_m, r.motion.dy_m], gain);
                sample.sensor_v[2 * p..2 * p + 2].copy_from_slice(&v);
            }
            let answer = path.saturate(law.update(&sample));
            // The budget is not judged here (it cannot end a replay): u64::MAX in a row.
            if let Ok(pushed) = path.push(answer, &sample) {
                applied = pushed.applied;
            }
        }
        row += 1;
        true
    })?;
    if let Some((row, t, expected)) = bad_time {
        return Err(ReplayError::Layout(format!(
            "row {row} is at t = {t} s, where tick {} of the scene is at {expected} s: this trace is not of this scene",
            row as f64 / per_tick as f64
        )));
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use controller::Sample;

    fn scene(sets: &[&str]) -> Scene {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut all: Vec<String> =
            ["scene.duration_s=0.01", "shock[0].start_s=0.002", "output.plots=false"].map(String::from).to_vec();
        all.extend(sets.iter().map(|s| s.to_string()));
        crate::config::load_scene(&root.join("config").join("paper-10g.toml"), &all).unwrap()
    }

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("plant-check-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    /// A law run in-process with `run_law` is the sampled run of the registry's law, and its
    /// trace replays through the law bit for bit; through another law it does not.
    #[test]
    fn a_law_run_in_process_replays_bit_for_bit() {
        let s = scene(&["controller.mode=\"sampled\"", "sensor.noise_v_rms=0.01", "sensor.adc_bits=14"]);
        let mine = run_law(&s, &controller::pd::LAW, &mut crate::run::Quiet).unwrap();
        let sampled = crate::run::run(&s, &mut crate::run::Quiet).unwrap();
        assert_eq!(mine.trace.loads.ix_a, sampled.trace.loads.ix_a);
        assert_eq!(mine.trace.motion.dy_m, sampled.trace.motion.dy_m);
        let dir = scratch("replay");
        crate::output::write_run(&dir, &s, &mine).unwrap();
        let same = replay(&dir, &controller::pd::LAW).unwrap();
        assert!(same.identical(), "{same}");
        assert_eq!(same.compared, 200);
        let other = replay(&dir, &controller::pd_delay::LAW).unwrap();
        assert!(!other.identical() && other.first.is_some_and(|d| d.seq == 0 && d.row == 2), "{other}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// The replay covers the two-plane rotor: a sampled two-plane run (a noisy sensor, one
    /// sample of delay) replays bit for bit through the law it ran, once per plane, and another
    /// law differs; a per-plane law handed to `replay_trace` is refused naming the way.
    #[test]
    fn a_two_plane_run_replays_through_the_digital_loops_command_path() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let sets: Vec<String> = [
            "scene.duration_s=0.01",
            "shock[0].start_s=0.002",
            "output.plots=false",
            "controller.mode=\"sampled\"",
            "sensor.noise_v_rms=0.01",
        ]
        .map(String::from)
        .to_vec();
        let s = crate::config::load_scene(&root.join("config").join("two-plane-asymmetric-10g.toml"), &sets).unwrap();
        let run = crate::run::run(&s, &mut crate::run::Quiet).unwrap();
        let dir = scratch("two-plane");
        crate::output::write_run(&dir, &s, &run).unwrap();
        let same = replay(&dir, &controller::pd::LAW).unwrap();
        assert!(same.identical(), "{same}");
        assert_eq!(same.compared, 200);
        let other = replay(&dir, &controller::pd_delay::LAW).unwrap();
        assert!(!other.identical(), "{other}");
        let mut law = (controller::pd::LAW.build)(&s.plane_design(0), &s.controller.params).unwrap();
        let e = replay_trace(&s, &dir.join("trace.csv"), law.as_mut()).unwrap_err().to_string();
        assert!(e.contains("replay_rotor_trace"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Two rows per tick, two samples of delay: the alignment holds.
    #[test]
    fn the_alignment_holds_at_a_multiple_of_the_rate_and_with_more_delay() {
        let s = scene(&["output.rate_hz=40000", "controller.delay_samples=2", "controller.mode=\"sampled\""]);
        let run = run_law(&s, &controller::pid::LAW, &mut crate::run::Quiet).unwrap();
        let dir = scratch("replay-multiple");
        crate::output::write_run(&dir, &s, &run).unwrap();
        let r = replay(&dir, &controller::pid::LAW).unwrap();
        assert_eq!(r.compared, 400);
        // Rows between ticks are interpolated inside the step; the currents are the held ones.
        assert!(r.identical(), "{r}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A law that answers NaN: held and counted in the run, and the replay holds it the same
    /// way; past the budget the run ends as `invalid_commands` (issue 21 item 4, sampled mode).
    #[test]
    fn a_law_that_answers_nan_is_held_then_stops_the_run() {
        struct Nan(u64);
        impl ControlLaw for Nan {
            fn name(&self) -> &'static str {
                "nan_after"
            }
            fn update(&mut self, s: &Sample) -> [f64; 2] {
                if s.seq >= self.0 {
                    [f64::NAN; 2]
                } else {
                    [0.0, 0.5]
                }
            }
            fn reset(&mut self) {}
        }
        fn build(_: &controller::Design, _: &controller::Params) -> Result<Box<dyn ControlLaw>, LawError> {
            Ok(Box::new(Nan(100)))
        }
        const LAW: LawEntry = LawEntry { name: "nan_after", summary: "", build };
        let s = scene(&["controller.mode=\"sampled\""]);
        let run = run_law(&s, &LAW, &mut crate::run::Quiet).unwrap();
        assert!(matches!(&run.run.outcome, crate::run::Outcome::InvalidCommands(w) if w.contains("from sample 100")));
        assert_eq!(run.run.invalid_commands, 11);
        let lenient = scene(&[
            "controller.mode=\"sampled\"",
            "controller.max_invalid_burst=1000",
            "controller.max_invalid_fraction=1",
        ]);
        let run = run_law(&lenient, &LAW, &mut crate::run::Quiet).unwrap();
        assert_eq!((run.run.outcome.clone(), run.run.invalid_commands), (crate::run::Outcome::Completed, 100));
        assert!(run.trace.loads.ix_a.iter().all(|i| i.is_finite()));
        let dir = scratch("replay-nan");
        crate::output::write_run(&dir, &lenient, &run).unwrap();
        let mut law = Nan(100);
        let r = replay_trace(&lenient, &dir.join("trace.csv"), &mut law).unwrap();
        assert!(r.identical(), "{r}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
