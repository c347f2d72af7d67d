//! The plant as a value: a [`Plant`] that anything can step, one controller tick at a time.
//!
//! A `Plant` holds everything a run evolves: the rotor model with its state (the hardware's
//! states appended when the scene has amplifiers or a sensor front end), the integrator and its
//! step-size memory, where the run is among the base motion's breakpoints, each race's parking,
//! the sensor's noise generator, the output rows' clock and the execution-time histograms.
//! Given the command of one tick (each axis's coil current, as the wire carries them; or the
//! continuous PD inside the derivative) it integrates the tick, hands the output rows of the
//! tick to a [`Sink`], and returns what the controller reads next: every axis's sensor sample
//! with the keyphasor.
//!
//! The CLI's run loop ([`crate::run`]) is one driver of it: the digital loop
//! ([`crate::digital`]: the law or the controller session, saturation, the invalid-command
//! budget, the delay line) makes the command from the sample, the plant steps. Another driver
//! (an FMU, a test, a user's program) does the same:
//!
//! ```
//! use plant_sim::stepper::{Command, Plant};
//! let scene = plant_sim::config::load_scene("../../config/cosim-10g.toml".as_ref(), &["scene.duration_s=0.002".into()])?;
//! let bias = plant_sim::run::bias_of(&scene, &plant_sim::run::plane_gains(&scene)?);
//! let mut plant = Plant::new(&scene, &Command::Held(bias))?;
//! let mut trace: Vec<plant_sim::rows::Record> = Vec::with_capacity(64); // a Sink that keeps every row
//! plant.record(&mut trace); // the row at t = 0
//! while !plant.finished() {
//!     let sample = *plant.sample();
//!     // A proportional law of our own on the sensor signal (V → A), bias added.
//!     let mut command = bias;
//!     command[0] -= 0.05 * sample.sensor_v[0];
//!     command[1] -= 0.05 * sample.sensor_v[1];
//!     plant.step(&Command::Held(command), &mut trace)?;
//! }
//! assert_eq!(plant.tick(), 40);
//! assert_eq!(trace.len(), 41);
//! // Its whole state as a value: a copy steps on exactly as the original.
//! let saved = plant.snapshot();
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! [`Plant::snapshot`] and [`Plant::restore`] give that state as a value
//! ([`crate::snapshot::Snapshot`]); a plant restored at any tick writes the same rows as the
//! one that never stopped.

use crate::config::{Rotor, Scene};
use crate::hardware::{Wired, EXTRA, EXTRA_UNIPOLAR};
pub use crate::hooks::Excitation;
use crate::integrate::{IntegrationError, Integrator, Settings, Stats, System};
use crate::machine::{Builds, Machine};
use crate::model::{Control, RaceWhenClear};
use crate::run::{plane_gains, settings_with, PlantError, RunError, Sink, TickCost};
use crate::sensor::Sensor;
use crate::snapshot::{Fingerprint, Snapshot, SnapshotError};
use crate::tick_time::{Tet, TickTime};
use controller::{wrap_angle, PdGains, RotorSample, ROTOR_AXES};
use plant_physics::integrate::AdaptiveState;
use std::time::{Duration, Instant};

/// What the plant applies over one tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Command {
    /// Each axis's coil current reference (A), as the wire carries them: x_A, y_A, x_B, y_B
    /// (a planar rotor reads the first two), held over the tick (zero-order hold).
    Held([f64; ROTOR_AXES]),
    /// The continuous PD inside the derivative (`controller.mode = "continuous"`), with a sine
    /// on one plane's sensor signal, which the PD then reads (a sensitivity measurement).
    Continuous(Option<Excitation>),
}

/// The plant of one scene, stepped one controller tick at a time (module doc).
pub struct Plant {
    core: Box<dyn Core>,
    sample: RotorSample,
    fingerprint: Fingerprint,
}

impl std::fmt::Debug for Plant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Plant").field("tick", &self.tick()).field("t", &self.time()).finish_non_exhaustive()
    }
}

/// What is done with the scene's rotor model and its initial state, whichever the model
/// ([`with_machine`]): [`Plant::new`] wraps it in the scene's hardware and steps it, `plant bench
/// tick` repeats its tick in contact ([`Machine::contact_state`]).
pub trait WithMachine {
    /// What it gives.
    type Output;

    /// Does it with `model` (a [`Machine`] on `N` states) at state `y`. `NE` and `NU` are the
    /// model's state lengths with the hardware's states appended, `N + EXTRA` and `N +
    /// EXTRA_UNIPOLAR` ([`Wired`]): a sum of a generic constant is not a type's parameter in
    /// stable Rust, so the caller, who knows `N`, adds them up.
    fn with<M, const N: usize, const NE: usize, const NU: usize>(self, model: M, y: [f64; N]) -> Self::Output
    where
        M: Machine<N> + Clone + 'static;
}

/// Writes [`with_machine`] from the list of models (`config::models::rotor_models!`): an arm per
/// model, each with the model's state length, which the hardware's lengths are added to here
/// (a sum of a generic constant is not a type's parameter in stable Rust).
macro_rules! with_machine {
    ($(
        $(#[$doc:meta])*
        $variant:ident = $name:literal, $what:literal, $is:literal: $keys:ident => $params:ty, [f64; $n:path];
    )+) => {
        /// The scene's rotor model built from its parameters with `controls` (one per plane; a
        /// planar model takes the first), at its initial state (levitated on the unbalance orbit,
        /// each race at rest), handed to `what`. The one place the plant tells the rotor models
        /// apart, an arm per model of the list ([`Builds`], in each model's file of `machine/`).
        pub fn with_machine<W: WithMachine>(scene: &Scene, controls: [Control; 2], what: W) -> W::Output {
            match &scene.rotor {
                $(Rotor::$variant(params) => {
                    const N: usize = $n;
                    let model = Builds::<N>::machine(params, &scene.base, controls);
                    let y = crate::initial::start(scene, |start| Builds::<N>::initial_state(params, start));
                    what.with::<_, N, { N + EXTRA }, { N + EXTRA_UNIPOLAR }>(model, y)
                })+
            }
        }
    };
}

crate::config::models::rotor_models!(with_machine);

/// [`Plant::new`]'s [`WithMachine`]: the stepper of the model, wrapped in the scene's hardware
/// ([`Wired`]) when it has amplifiers or a sensor front end.
struct BuildCore<'a> {
    scene: &'a Scene,
    controls: [Control; 2],
    gains: Vec<PdGains>,
    timed: bool,
}

impl WithMachine for BuildCore<'_> {
    type Output = Box<dyn Core>;

    fn with<M, const N: usize, const NE: usize, const NU: usize>(self, model: M, y: [f64; N]) -> Box<dyn Core>
    where
        M: Machine<N> + Clone + 'static,
    {
        let Self { scene, controls, gains, timed } = self;
        let hw = &scene.hardware;
        if hw.is_unipolar() {
            let wired = Wired::<_, N, NU>::new(model, controls, hw.clone());
            let y = wired.initial(&y);
            let settings = settings_of(scene, &wired);
            Box::new(Stepper::new(scene, wired, y, settings, gains, timed))
        } else if hw.is_on() {
            let wired = Wired::<_, N, NE>::new(model, controls, hw.clone());
            let y = wired.initial(&y);
            let settings = settings_of(scene, &wired);
            Box::new(Stepper::new(scene, wired, y, settings, gains, timed))
        } else {
            let settings = settings_of(scene, &model);
            Box::new(Stepper::new(scene, model, y, settings, gains, timed))
        }
    }
}

impl Plant {
    /// The plant of `scene` at its initial state (levitated on the unbalance orbit, each race at
    /// rest), with `initial` applied: the command the row at t = 0 shows (the bias currents of a
    /// sampled or co-simulated loop, [`crate::run::bias_of`], or the continuous PD).
    ///
    /// The execution time of each tick is measured when `scene`'s controller runs in another
    /// process, or after [`Plant::time_ticks`].
    pub fn new(scene: &Scene, initial: &Command) -> Result<Self, PlantError> {
        let gains = plane_gains(scene)?;
        let timed = matches!(
            scene.controller.mode,
            crate::config::ControlMode::Lockstep | crate::config::ControlMode::Realtime
        );
        let control = |i: usize| match initial {
            Command::Continuous(_) => Control::Continuous(gains[i]),
            Command::Held(c) => Control::Held([c[2 * i], c[2 * i + 1]]),
        };
        let last = scene.planes() - 1;
        let controls: [Control; 2] = std::array::from_fn(|i| control(i.min(last)));
        // The model of the scene's rotor (the one place the plant tells them apart,
        // `with_machine`), wrapped in the hardware the scene has.
        let core = with_machine(scene, controls, BuildCore { scene, controls, gains, timed });
        let fingerprint = Fingerprint::of(scene, core.state().len());
        let mut plant = Self { core, sample: RotorSample::default(), fingerprint };
        plant.sample = plant.core.read_sample();
        Ok(plant)
    }

    /// Measures the execution time of every tick from now on (as co-simulated runs always do):
    /// `plant bench tick`.
    pub fn time_ticks(&mut self) {
        self.core.time_ticks();
    }

    /// What the controller reads at the current tick: every axis's sensor signal (V; gain,
    /// noise and ADC applied; through the front end if the scene has one) and the keyphasor.
    pub fn sample(&self) -> &RotorSample {
        &self.sample
    }

    /// Integrates one tick with `command` applied, hands its output rows to `sink`, and returns
    /// what the controller reads at the next tick. A numerical failure (the integrator's, or a
    /// radius past its guard) is returned with its time and state; the plant then stays where
    /// the failure left it.
    ///
    /// Steps past the scene's duration go on, a whole period each.
    pub fn step(&mut self, command: &Command, sink: &mut dyn Sink) -> Result<&RotorSample, RunError> {
        self.step_from(command, sink, Instant::now())
    }

    /// [`Plant::step`] for a tick that started at `tick_start` (a realtime tick starts when the
    /// plant wakes at its wall-clock time): the execution time counts from there.
    pub fn step_from(
        &mut self,
        command: &Command,
        sink: &mut dyn Sink,
        tick_start: Instant,
    ) -> Result<&RotorSample, RunError> {
        self.core.step(command, sink, tick_start)?;
        self.sample = self.core.read_sample();
        Ok(&self.sample)
    }

    /// Hands the current state's output row to `sink` (a run's row at t = 0).
    pub fn record(&self, sink: &mut dyn Sink) {
        self.core.record(sink);
    }

    /// Ticks done.
    pub fn tick(&self) -> u64 {
        self.core.position().tick
    }

    /// Simulated time reached (s): the end of the last tick, or where a failure stopped it.
    pub fn time(&self) -> f64 {
        self.core.position().t
    }

    /// Ticks of the scene's duration.
    pub fn ticks(&self) -> u64 {
        self.core.position().ticks
    }

    /// The scene's duration is reached.
    pub fn finished(&self) -> bool {
        self.tick() >= self.ticks()
    }

    /// Bearing planes of the rotor (1 or 2).
    pub fn planes(&self) -> usize {
        self.core.planes()
    }

    /// The state (SI, ordered as the model's: [`crate::model::ix`] or
    /// [`plant_physics::two_plane::ix`], the hardware's states after it, [`crate::hardware`]).
    pub fn state(&self) -> &[f64] {
        self.core.state()
    }

    /// Integrator statistics since the start of the run.
    pub fn stats(&self) -> Stats {
        self.core.stats()
    }

    /// Macro steps run with a race parked, summed over the planes.
    pub fn parked_steps(&self) -> u64 {
        self.core.parked_steps()
    }

    /// Time with an amplifier at its voltage limit (s); `None` without amplifiers.
    pub fn voltage_saturation(&self) -> Option<f64> {
        self.core.voltage_saturation()
    }

    /// The cost of the ticks so far (the most evaluations in one, the execution times), taken
    /// out of the plant.
    pub fn take_cost(&mut self) -> TickCost {
        self.core.take_cost()
    }

    /// What the state of this plant must match to be restored into it.
    pub fn fingerprint(&self) -> &Fingerprint {
        &self.fingerprint
    }

    /// The whole evolving state, as a value ([`Snapshot`]). It allocates: take it between ticks,
    /// not inside a realtime loop's deadline.
    pub fn snapshot(&self) -> Snapshot {
        self.core.snapshot(self.fingerprint.clone())
    }

    /// Continues from `snapshot`: the next steps write the rows the plant that took it would
    /// have written. Refused, with the first difference named, when the snapshot is of another
    /// rotor, state layout, integrator or rate ([`Fingerprint`]); the plant is then unchanged.
    pub fn restore(&mut self, snapshot: &Snapshot) -> Result<(), SnapshotError> {
        snapshot.check_against(&self.fingerprint)?;
        self.core.restore(snapshot)?;
        self.sample = self.core.read_sample();
        Ok(())
    }
}

/// Where a plant is in its run.
#[derive(Clone, Copy, Debug)]
struct Position {
    tick: u64,
    t: f64,
    ticks: u64,
}

/// A [`Stepper`] of any state size, behind one object-safe interface: a call per tick, the
/// integration itself monomorphic inside.
trait Core {
    fn read_sample(&mut self) -> RotorSample;
    fn step(&mut self, command: &Command, sink: &mut dyn Sink, tick_start: Instant) -> Result<(), RunError>;
    fn record(&self, sink: &mut dyn Sink);
    fn position(&self) -> Position;
    fn planes(&self) -> usize;
    fn state(&self) -> &[f64];
    fn stats(&self) -> Stats;
    fn parked_steps(&self) -> u64;
    fn voltage_saturation(&self) -> Option<f64>;
    fn take_cost(&mut self) -> TickCost;
    fn time_ticks(&mut self);
    fn snapshot(&self, fingerprint: Fingerprint) -> Snapshot;
    fn restore(&mut self, snapshot: &Snapshot) -> Result<(), SnapshotError>;
}

/// The plant of a model `M` on `N` states.
struct Stepper<const N: usize, M: Machine<N>> {
    model: M,
    y: [f64; N],
    integrator: Integrator<N>,
    /// Each plane's continuous PD (`Command::Continuous`).
    gains: Vec<PdGains>,
    sensor: Sensor,
    /// The sensor's noise generator before the current sample was read (what a snapshot keeps).
    rng_at_tick: u64,
    guards: Guards,
    breakpoints: Vec<f64>,
    next_breakpoint: usize,
    tick: u64,
    t: f64,
    ticks: u64,
    period: f64,
    duration: f64,
    out_dt: f64,
    /// The next output row's number (row `n` at `n · out_dt`).
    next_out: u64,
    /// The output times of the current tick (allocated once).
    out_times: Vec<f64>,
    parked_steps: u64,
    substeps: u32,
    contact_substeps: u32,
    cost: TickCost,
}

impl<const N: usize, M: Machine<N>> Stepper<N, M> {
    fn new(scene: &Scene, model: M, y: [f64; N], settings: Settings<N>, gains: Vec<PdGains>, timed: bool) -> Self {
        let period = scene.controller.period;
        let ticks = (scene.duration / period).ceil() as u64;
        let out_dt = scene.output_interval;
        let sensor = Sensor::new(scene.sensor);
        Self {
            guards: Guards::new(scene, &model),
            model,
            y,
            integrator: Integrator::new(settings),
            gains,
            rng_at_tick: sensor.rng_state(),
            sensor,
            breakpoints: scene.base.breakpoints(),
            next_breakpoint: 0,
            tick: 0,
            t: 0.0,
            ticks,
            period,
            duration: scene.duration,
            out_dt,
            next_out: 1,
            // Output samples per tick; a period longer than the run holds only the run's samples.
            out_times: Vec::with_capacity((period.min(scene.duration) / out_dt).ceil() as usize + 2),
            parked_steps: 0,
            substeps: scene.integrator.substeps,
            contact_substeps: scene.integrator.contact_substeps,
            cost: TickCost { max_rhs_evals: 0, tet: timed.then(|| Box::new(Tet::new(ticks))) },
        }
    }

    /// The end of the current tick: the scene's duration caps the last one; past it, whole periods.
    fn tick_end(&self) -> f64 {
        let t1 = (self.tick + 1) as f64 * self.period;
        if self.tick < self.ticks {
            t1.min(self.duration)
        } else {
            t1
        }
    }
}

impl<const N: usize, M: Machine<N>> Core for Stepper<N, M> {
    fn read_sample(&mut self) -> RotorSample {
        self.rng_at_tick = self.sensor.rng_state();
        let planes = M::PLANES;
        let (model, y) = (&self.model, &self.y);
        // The rotor's speed and its angle wrapped to [0, 2π), from the state.
        let (angle, speed) = model.spin(y);
        let mut sample = RotorSample {
            seq: self.tick,
            t_s: self.tick as f64 * self.period,
            axes: 2 * planes as u32,
            speed_rad_s: speed,
            angle_rad: wrap_angle(angle),
            ..Default::default()
        };
        // Every axis's sensor, the planes in order, one noise sequence (read in every mode: the
        // continuous PD reads its signal inside the derivative, but an excitation reads it here).
        for i in 0..planes {
            let gain = model.bearing(i).loop_constants.sensor_gain_v_per_m;
            let v = self.sensor.read_with_gain(model.sensed(y, i), gain);
            sample.sensor_v[2 * i..2 * i + 2].copy_from_slice(&v);
        }
        sample
    }

    fn step(&mut self, command: &Command, sink: &mut dyn Sink, tick_start: Instant) -> Result<(), RunError> {
        let planes = M::PLANES;
        let k = self.tick;
        let t0 = k as f64 * self.period;
        let t1 = self.tick_end();
        match command {
            Command::Held(c) => {
                for i in 0..planes {
                    self.model.set_control(i, Control::Held([c[2 * i], c[2 * i + 1]]));
                }
            }
            Command::Continuous(excitation) => {
                for i in 0..planes {
                    let control = match excitation {
                        Some(e) if e.plane == i => Control::ContinuousExcited(self.gains[i], e.sine),
                        _ => Control::Continuous(self.gains[i]),
                    };
                    self.model.set_control(i, control);
                }
            }
        }
        let commanded = Instant::now();
        // Park or release each race; the fixed step is the contact one while any race is free.
        let mut changed = false;
        for i in 0..planes {
            if let RaceWhenClear::Parked(release) = self.model.bearing(i).race_when_clear {
                let clear = self.model.race_clear(t0, t1 - t0, &self.y, i);
                if clear && !self.model.parked(i) {
                    self.model.park_race(&mut self.y, i);
                    self.model.set_parked(i, true);
                    changed = true;
                } else if !clear && (self.model.parked(i) || k == 0) {
                    if self.model.parked(i) {
                        self.model.release_race(t0, &mut self.y, i, release);
                    }
                    self.model.set_parked(i, false);
                    changed = true;
                }
                self.parked_steps += u64::from(self.model.parked(i));
            }
        }
        if changed {
            let all_parked = (0..planes).all(|i| self.model.parked(i));
            self.integrator.set_substeps(if all_parked { self.substeps } else { self.contact_substeps });
        }
        self.out_times.clear();
        let out_dt = self.out_dt;
        while (self.next_out as f64) * out_dt <= t1 + 1e-9 * out_dt {
            self.out_times.push(((self.next_out as f64) * out_dt).min(t1));
            self.next_out += 1;
        }
        let timed = self.cost.tet.is_some();
        let (evals, touching) = (self.integrator.stats().rhs_evals, timed && touching(&self.model, &self.y));
        let mut rows = Duration::ZERO;
        let integrating = Instant::now();
        let model = &self.model;
        let step = advance_across_breakpoints(
            &mut self.integrator,
            model,
            (t0, t1),
            &mut self.y,
            &self.out_times,
            (&self.breakpoints, &mut self.next_breakpoint),
            |ts, ys| {
                if timed {
                    // The output rows' time is the sink's, not the integration's.
                    let row = Instant::now();
                    feed(model, sink, ts, ys);
                    rows += row.elapsed();
                } else {
                    feed(model, sink, ts, ys);
                }
            },
        );
        self.cost.max_rhs_evals = self.cost.max_rhs_evals.max(self.integrator.stats().rhs_evals - evals);
        if let Some(tet) = self.cost.tet.as_mut() {
            let end = Instant::now();
            let ns = |d: Duration| d.as_nanos() as u64;
            tet.record(
                k,
                TickTime {
                    command_ns: ns(commanded - tick_start),
                    integration_ns: ns((end - integrating).saturating_sub(rows)),
                    tick_ns: ns(end - tick_start),
                    contact: touching || self::touching(&self.model, &self.y),
                },
            );
        }
        self.t = t1;
        self.tick += 1;
        if let Err(e) = step.map_err(RunError::from).and_then(|()| self.guards.check(&self.model, t1, &self.y)) {
            // The run reached the failure, not the end of its macro step (an integration error
            // stops inside it).
            self.t = e.time();
            return Err(e);
        }
        Ok(())
    }

    fn record(&self, sink: &mut dyn Sink) {
        feed(&self.model, sink, self.t, &self.y);
    }

    fn position(&self) -> Position {
        Position { tick: self.tick, t: self.t, ticks: self.ticks }
    }

    fn planes(&self) -> usize {
        M::PLANES
    }

    fn state(&self) -> &[f64] {
        &self.y
    }

    fn stats(&self) -> Stats {
        self.integrator.stats()
    }

    fn parked_steps(&self) -> u64 {
        self.parked_steps
    }

    fn voltage_saturation(&self) -> Option<f64> {
        self.model.voltage_saturation(&self.y)
    }

    fn take_cost(&mut self) -> TickCost {
        std::mem::take(&mut self.cost)
    }

    fn time_ticks(&mut self) {
        if self.cost.tet.is_none() {
            self.cost.tet = Some(Box::new(Tet::new(self.ticks)));
        }
    }

    fn snapshot(&self, fingerprint: Fingerprint) -> Snapshot {
        let stats = self.integrator.stats();
        Snapshot {
            format: crate::snapshot::FORMAT,
            fingerprint,
            tick: self.tick,
            t_s: self.t,
            state: self.y.to_vec(),
            adaptive: self.integrator.adaptive_state(),
            substeps: self.integrator.settings().substeps,
            steps: stats.steps,
            rejected: stats.rejected,
            rhs_evals: stats.rhs_evals,
            max_rhs_evals: self.cost.max_rhs_evals,
            next_output: self.next_out,
            parked: (0..M::PLANES).map(|i| self.model.parked(i)).collect(),
            parked_steps: self.parked_steps,
            sensor_rng: self.rng_at_tick,
            digital: None,
            seal: String::new(),
        }
    }

    fn restore(&mut self, s: &Snapshot) -> Result<(), SnapshotError> {
        let y: [f64; N] = s.state.as_slice().try_into().map_err(|_| SnapshotError::Layout {
            what: "state",
            expected: N,
            found: s.state.len(),
        })?;
        if s.parked.len() != M::PLANES {
            return Err(SnapshotError::Layout { what: "parked races", expected: M::PLANES, found: s.parked.len() });
        }
        if let Some(bad) = s.state.iter().position(|v| !v.is_finite()) {
            return Err(SnapshotError::NonFinite { index: bad, value: s.state[bad] });
        }
        if !(s.t_s.is_finite() && (s.t_s - s.tick as f64 * self.period).abs() <= 1e-9 * self.period.max(s.t_s)) {
            return Err(SnapshotError::Time { tick: s.tick, t_s: s.t_s, period_s: self.period });
        }
        if s.substeps == 0 || !(s.adaptive.h.is_finite() && s.adaptive.h >= 0.0 && s.adaptive.err_old.is_finite()) {
            return Err(SnapshotError::Integrator(format!(
                "substeps = {}, step-size memory h = {} s, err_old = {}",
                s.substeps, s.adaptive.h, s.adaptive.err_old
            )));
        }
        self.check_fields(s)?;
        self.y = y;
        self.tick = s.tick;
        self.t = s.t_s;
        self.integrator.set_adaptive_state(AdaptiveState { h: s.adaptive.h, err_old: s.adaptive.err_old });
        self.integrator.set_substeps(s.substeps);
        self.integrator.set_stats(Stats { steps: s.steps, rejected: s.rejected, rhs_evals: s.rhs_evals });
        self.cost.max_rhs_evals = s.max_rhs_evals;
        self.next_out = s.next_output;
        for (i, &parked) in s.parked.iter().enumerate() {
            self.model.set_parked(i, parked);
        }
        self.parked_steps = s.parked_steps;
        self.sensor.set_rng_state(s.sensor_rng);
        // The breakpoints passed are those of this scene's programme before the snapshot's time
        // (the programme may be another than the one that ran up to it).
        let tiny = 1e-9 * self.period;
        self.next_breakpoint = self.breakpoints.partition_point(|b| *b < s.t_s - tiny);
        Ok(())
    }
}

/// The largest counter a snapshot may carry: 2^53, the last integer an `f64` holds exactly
/// (counters are summed and divided as `f64`), far beyond any run's (a year of 10 kHz ticks is
/// 3e11) and far from a `u64`'s wrap (an edited counter at 2^64 − 1 wrapped).
const MAX_COUNT: u64 = 1 << 53;

impl<const N: usize, M: Machine<N>> Stepper<N, M> {
    /// The fields of `s` against this plant's scene and physics, beyond their layout: each
    /// refused naming the field, its value and what it must be (issue 40: an edited state was
    /// believed). A state this plant wrote passes; the seal is checked before
    /// ([`crate::run::check_start`]).
    fn check_fields(&self, s: &Snapshot) -> Result<(), SnapshotError> {
        self.check_counters(s)?;
        self.check_integrator(s)?;
        self.check_positions(s)
    }

    /// The times and the counters of `s` ([`Self::check_fields`]).
    fn check_counters(&self, s: &Snapshot) -> Result<(), SnapshotError> {
        // Times: within the run, on the tick grid (checked above), and the output rows' clock
        // where this plant's would be at that time.
        // (Whether the state is before the scene's end is the caller's question: `plant run`
        // names scene.duration_s.)
        if s.tick > MAX_COUNT {
            return Err(SnapshotError::field("tick", s.tick, format!("at most 2^53 = {MAX_COUNT}")));
        }
        let expected_out = next_output_after(s.t_s, self.out_dt);
        if s.next_output != expected_out {
            return Err(SnapshotError::field(
                "next_output",
                s.next_output,
                format!(
                    "{expected_out}: the first output row after the state's time t_s = {} s on the output grid of {} s",
                    s.t_s, self.out_dt
                ),
            ));
        }
        // Counters: below 2^53, and consistent with each other and with the ticks.
        for (field, value) in [
            ("steps", s.steps),
            ("rejected", s.rejected),
            ("rhs_evals", s.rhs_evals),
            ("max_rhs_evals", s.max_rhs_evals),
            ("parked_steps", s.parked_steps),
        ] {
            if value > MAX_COUNT {
                return Err(SnapshotError::field(field, value, format!("at most 2^53 = {MAX_COUNT}")));
            }
        }
        if s.steps > s.rhs_evals || s.rejected > s.rhs_evals {
            return Err(SnapshotError::field(
                "rhs_evals",
                s.rhs_evals,
                format!(
                    "at least the steps ({}) and the rejected steps ({}): each takes an evaluation",
                    s.steps, s.rejected
                ),
            ));
        }
        if s.max_rhs_evals > s.rhs_evals {
            return Err(SnapshotError::field(
                "max_rhs_evals",
                s.max_rhs_evals,
                format!("at most rhs_evals = {}", s.rhs_evals),
            ));
        }
        if s.tick > 0 && (s.steps == 0 || s.max_rhs_evals == 0) {
            return Err(SnapshotError::field(
                if s.steps == 0 { "steps" } else { "max_rhs_evals" },
                0,
                format!("at least 1 after {} ticks", s.tick),
            ));
        }
        let planes = M::PLANES as u64;
        if s.parked_steps > s.tick.saturating_mul(planes) {
            return Err(SnapshotError::field(
                "parked_steps",
                s.parked_steps,
                format!("at most tick × planes = {} × {planes} (a macro step parks each race once at most)", s.tick),
            ));
        }
        Ok(())
    }

    /// The integrator's fields of `s` ([`Self::check_fields`]).
    fn check_integrator(&self, s: &Snapshot) -> Result<(), SnapshotError> {
        // The integrator: substeps of this scene, a step-size memory within the method's bounds.
        let settings = self.integrator.settings();
        if s.substeps != self.substeps && (self.contact_substeps == 0 || s.substeps != self.contact_substeps) {
            return Err(SnapshotError::field(
                "substeps",
                s.substeps,
                format!(
                    "the scene's integrator.substeps = {} or integrator.contact_substeps = {}",
                    self.substeps, self.contact_substeps
                ),
            ));
        }
        let (h, err_old) = (s.adaptive.h, s.adaptive.err_old);
        let fresh = AdaptiveState::default();
        if !settings.method.is_adaptive() || s.steps == 0 {
            // A fixed-step method never changes the memory; an adaptive one before its first step
            // has none.
            if h != fresh.h || err_old != fresh.err_old {
                return Err(SnapshotError::field(
                    "adaptive",
                    format!("h = {h} s, err_old = {err_old}"),
                    format!(
                        "h = {} s, err_old = {}: no memory {}",
                        fresh.h,
                        fresh.err_old,
                        if s.steps == 0 { "before the first step" } else { "with a fixed-step method" }
                    ),
                ));
            }
        } else {
            // At most the macro step (a tick) and h_max: the integrator caps what it carries so.
            // (Not bounded below by h_min: the step after one shortened to land on a tick's end
            // may carry less.)
            let most = settings.h_max.min(self.period * (1.0 + 1e-9));
            if !(h > 0.0 && h <= most) {
                return Err(SnapshotError::field(
                    "adaptive.h",
                    format!("{h} s"),
                    format!(
                        "a step size the integrator carries: positive, at most the controller period {} s and h_max = {} s",
                        self.period, settings.h_max
                    ),
                ));
            }
            if !(fresh.err_old..=1.0).contains(&err_old) {
                return Err(SnapshotError::field(
                    "adaptive.err_old",
                    err_old,
                    format!("the last accepted step's error norm, {} (its floor) to 1", fresh.err_old),
                ));
            }
        }
        Ok(())
    }

    /// The bodies' positions and the parked races of `s` ([`Self::check_fields`]).
    fn check_positions(&self, s: &Snapshot) -> Result<(), SnapshotError> {
        // Positions: each body within its clearance and the deepest penetration the contact
        // model is meant for (one gap, or the radius guard if smaller; real contacts are microns
        // deep) — a rotor 0.3 mm deep in a 0.15 mm gap was taken.
        let y: &[f64; N] = s.state.as_slice().try_into().map_err(|_| SnapshotError::Layout {
            what: "state",
            expected: N,
            found: s.state.len(),
        })?;
        for (i, &(_, race_guard)) in self.guards.limits.iter().enumerate() {
            let p = self.model.bearing(i);
            let depth = p.contact.gap.min(race_guard - p.balls.clearance);
            let (rotor, race) = self.model.radii(y, i);
            let (rotor_limit, race_limit) = (p.contact.gap + p.balls.clearance + depth, p.balls.clearance + depth);
            let plane = if M::PLANES == 1 { String::new() } else { format!(" at bearing {}", ["A", "B"][i]) };
            if rotor.is_nan() || rotor > rotor_limit {
                return Err(SnapshotError::field(
                    format!("state: the rotor radius{plane}"),
                    format!("{rotor} m"),
                    format!(
                        "at most {rotor_limit} m: the gap {} m, the race's clearance {} m and a contact {depth} m deep",
                        p.contact.gap, p.balls.clearance
                    ),
                ));
            }
            if race.is_nan() || race > race_limit {
                return Err(SnapshotError::field(
                    format!("state: the race radius{plane}"),
                    format!("{race} m"),
                    format!(
                        "at most {race_limit} m: the race's clearance {} m and a contact {depth} m deep",
                        p.balls.clearance
                    ),
                ));
            }
            // A parked race: parking on in this scene, the race held (what parking leaves) and
            // clear of the rotor (a touching race is released).
            if s.parked[i] {
                let mut held = *y;
                self.model.park_race(&mut held, i);
                let why = if !matches!(p.race_when_clear, RaceWhenClear::Parked(_)) {
                    Some("false: the scene's races are never parked (rotor.race_when_clear)")
                } else if held != *y {
                    Some("false: the state's race moves, and a parked race is held")
                } else if self.model.touching(y, i) {
                    Some("false: the rotor touches the race, and a touching race is free")
                } else {
                    None
                };
                if let Some(why) = why {
                    return Err(SnapshotError::field(format!("parked[{i}]"), true, why));
                }
            }
        }
        Ok(())
    }
}

/// The number of the first output row after time `t` on a grid of `dt`: where the output
/// clock of a plant that has run to `t` stands (the rule of the tick loop: rows up to
/// `t + 1e-9 dt` are written).
fn next_output_after(t: f64, dt: f64) -> u64 {
    let mut n = ((t / dt).floor() as u64).saturating_sub(1).max(1);
    while (n as f64) * dt <= t + 1e-9 * dt {
        n += 1;
    }
    n
}

/// The integrator's settings for `model` in `scene`: the scene's, with the model's absolute
/// tolerances and the components its error norm counts.
pub fn settings_of<const N: usize, M: Machine<N>>(scene: &Scene, model: &M) -> Settings<N> {
    Settings { rms_count: model.used_components(), ..settings_with(scene, M::atol(scene.integrator.atol_groups)) }
}

/// Hands the output sample of state `y` at time `t` to `sink`, then its bearing planes
/// ([`Sink::planes`]).
#[inline]
fn feed<const N: usize, M: Machine<N>>(model: &M, sink: &mut dyn Sink, t: f64, y: &[f64; N]) {
    sink.sample(&model.record(t, y));
    sink.planes(&At { model, t, y });
}

/// One output sample's bearing planes, computed when a sink asks ([`crate::run::PlaneStates`]).
struct At<'a, M, const N: usize> {
    model: &'a M,
    t: f64,
    y: &'a [f64; N],
}

impl<const N: usize, M: Machine<N>> crate::run::PlaneStates for At<'_, M, N> {
    fn time(&self) -> f64 {
        self.t
    }

    fn visit(&self, visit: &mut dyn FnMut(usize, &crate::machine::PlaneState<'_>)) {
        self.model.plane_states(self.t, self.y, visit);
    }
}

/// The rotor touches one of its races (the rotor – race contact force is not zero).
fn touching<const N: usize, M: Machine<N>>(model: &M, y: &[f64; N]) -> bool {
    (0..M::PLANES).any(|i| model.touching(y, i))
}

/// Advances over `[t0, t1]`, ending a step at every breakpoint of the base motion inside it
/// (where the housing acceleration or its slope jumps): a step across such a kink has an
/// O(h²) local error whatever the method's order. `breakpoints` is sorted; `next` is the index
/// of the first one not yet passed. Samples at `times` go to `sample`.
fn advance_across_breakpoints<const N: usize, S: System<N>, F: FnMut(f64, &[f64; N])>(
    integrator: &mut Integrator<N>,
    model: &S,
    (t0, t1): (f64, f64),
    y: &mut [f64; N],
    times: &[f64],
    (breakpoints, next): (&[f64], &mut usize),
    mut sample: F,
) -> Result<(), IntegrationError> {
    let tiny = 1e-9 * (t1 - t0);
    let mut from = t0;
    let mut done = 0;
    while *next < breakpoints.len() && breakpoints[*next] < t1 - tiny {
        let b = breakpoints[*next];
        *next += 1;
        if b <= from + tiny {
            continue;
        }
        let upto = done + times[done..].partition_point(|t| *t <= b);
        integrator.advance_dense(model, from, b, y, &times[done..upto], &mut sample)?;
        done = upto;
        from = b;
    }
    integrator.advance_dense(model, from, t1, y, &times[done..], sample)
}

/// Radius limits beyond which the contact model has failed, per bearing plane.
struct Guards {
    /// (rotor, race) limits of each plane (m).
    limits: Vec<(f64, f64)>,
}

impl Guards {
    fn new<const N: usize, M: Machine<N>>(scene: &Scene, model: &M) -> Self {
        let g = scene.integrator.radius_guard;
        let limits = (0..M::PLANES)
            .map(|i| {
                let p = model.bearing(i);
                (p.contact.gap + p.balls.clearance + g, p.balls.clearance + g)
            })
            .collect();
        Self { limits }
    }

    fn check<const N: usize, M: Machine<N>>(&self, model: &M, t: f64, y: &[f64; N]) -> Result<(), RunError> {
        const NAMES: [[&str; 2]; 2] =
            [["rotor radius at bearing A", "race A radius"], ["rotor radius at bearing B", "race B radius"]];
        for (i, &(rotor_limit, race_limit)) in self.limits.iter().enumerate() {
            let (rotor, race) = model.radii(y, i);
            let [rotor_name, race_name] = if M::PLANES == 1 { ["rotor radius", "race radius"] } else { NAMES[i] };
            let fail = |what, value_m, limit_m| RunError::RadiusGuard { t, what, value_m, limit_m, state: y.to_vec() };
            if rotor > rotor_limit {
                return Err(fail(rotor_name, rotor, rotor_limit));
            }
            if race > race_limit {
                return Err(fail(race_name, race, race_limit));
            }
        }
        Ok(())
    }
}
