//! The plant as an FMI 2.0 co-simulation FMU: the C API an importer (Simulink's FMU block,
//! OMSimulator, FMPy) calls, around [`plant_sim::Plant`], the value `plant run` steps.
//!
//! `plant fmu SCENE --out plant.fmu` packs this library as `binaries/linux64/<id>.so` with
//! the scene in `resources/scene.toml` and the `modelDescription.xml` that
//! [`plant_sim::fmi::Model`] makes from it. At `fmi2Instantiate` the library loads that
//! scene and makes the same model, so a value reference means here what it means in the file.
//!
//! What the library promises (docs/guide/fmu-plant.md):
//!
//! - A communication step is a whole number of the plant's controller ticks; the importer's
//!   rounding of the time and of the step (`2.9500000000030000` for `2.95`) is taken, since
//!   the FMU counts ticks as integers and compares times with a tolerance; any other step is
//!   refused with `fmi2Error` and a log line naming the step it needs.
//! - The inputs (each axis's coil current command) are held over the step, saturated at the
//!   scene's `controller.current_limit_a` (the amplifier's limit) as `plant run` saturates a
//!   law's answer; the scene's `controller.delay_samples` is the importer's to model.
//! - Every call is guarded: an out-of-order call, a non-finite input, a parameter out of its
//!   bounds, a corrupt serialised state, a diverging plant (with its time and state in the
//!   log) each return `fmi2Error` with a log line; a panic never crosses the C boundary.
//! - The FMU state (`fmi2GetFMUstate`, `fmi2SerializeFMUstate`) is the whole instance: the
//!   parameters, inputs, the plant's [`plant_sim::snapshot::Snapshot`] and the outputs; a state
//!   restored, in this instance or in a fresh one in another process, continues bit for bit.
//!
//! Instances are independent (no global state): several may live in one process.

#![allow(non_snake_case, clippy::missing_safety_doc)]

mod fmi3;

use plant_sim::fmi::{Model, Output, Role, Variable};
use plant_sim::rows::{Columns as _, Record, Row};
use plant_sim::run::Sink;
use plant_sim::snapshot::Snapshot;
use plant_sim::stepper::{Command, Plant};
use serde::{Deserialize, Serialize};
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

/// `fmi2Status`.
type Status = c_int;
const OK: Status = 0;
const WARNING: Status = 1;
const ERROR: Status = 3;

/// `fmi2CoSimulation` of `fmi2Type`.
const CO_SIMULATION: c_int = 1;

/// `fmi2CallbackLogger`.
type Logger = unsafe extern "C" fn(*mut c_void, *const c_char, Status, *const c_char, *const c_char, ...);

/// `fmi2CallbackFunctions`.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct CallbackFunctions {
    logger: Option<Logger>,
    allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    step_finished: Option<unsafe extern "C" fn(*mut c_void, Status)>,
    component_environment: *mut c_void,
}

/// Where an instance is in the FMI 2.0 co-simulation state machine.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
enum Phase {
    /// After `fmi2Instantiate` (or `fmi2Reset`): parameters and inputs may be set.
    Instantiated,
    /// Between `fmi2EnterInitializationMode` and `fmi2ExitInitializationMode`.
    Initialization,
    /// Initialised: `fmi2DoStep` steps.
    Stepping,
    /// After `fmi2Terminate`.
    Terminated,
    /// After a failure (a diverged plant): only reading, `fmi2Reset`, restoring a state and
    /// freeing are left.
    Failed,
}

impl Phase {
    fn words(self) -> &'static str {
        match self {
            Phase::Instantiated => "instantiated (before fmi2EnterInitializationMode)",
            Phase::Initialization => "in initialization mode",
            Phase::Stepping => "initialized (stepping)",
            Phase::Terminated => "terminated",
            Phase::Failed => "failed (after an error: fmi2Reset, fmi2SetFMUstate or fmi2FreeInstance)",
        }
    }
}

/// The plant of an initialised instance.
struct Sim {
    plant: Plant,
    /// The parameter values it was built with (by value reference; inputs and outputs NaN).
    built_with: Vec<f64>,
    /// The amplifier's limit per axis (A).
    limits: [f64; 4],
    /// Each output's value at the current time (by value reference; others NaN).
    outputs: Vec<f64>,
    /// The scene's `scene.duration_s` override that puts its end on the tick grid, if any.
    period: f64,
    /// Where the plant starts, in words (docs/guide/fmu-plant.md, "Where the plant starts").
    start: String,
}

/// One FMU instance.
struct Instance {
    name: CString,
    callbacks: Callbacks,
    logging: bool,
    resources: PathBuf,
    model: Model,
    phase: Phase,
    /// Inputs' and parameters' values (by value reference; outputs NaN).
    values: Vec<f64>,
    start_time: f64,
    sim: Option<Sim>,
}

/// The last output row a step handed over.
struct LastRow(Option<Record>);

impl Sink for LastRow {
    fn sample(&mut self, record: &Record) {
        self.0 = Some(*record);
    }
}

/// Whether parameter `v` takes the value `x` (finite, within its bounds); else why not.
fn in_bounds(v: &Variable, x: f64) -> Result<(), String> {
    let unit = v.unit.map(|u| format!(" {u}")).unwrap_or_default();
    let (lo, hi) = (v.min.unwrap_or(f64::NEG_INFINITY), v.max.unwrap_or(f64::INFINITY));
    if x.is_finite() && x >= lo && x <= hi {
        Ok(())
    } else {
        Err(format!("parameter {} = {x}{unit} is outside its bounds [{lo}, {hi}]{unit}", v.name))
    }
}

/// Category names of the log.
const CAT_ERROR: &CStr = c"logStatusError";
const CAT_WARNING: &CStr = c"logStatusWarning";
const CAT_ALL: &CStr = c"logAll";

/// The importer's logger: FMI 2.0's callbacks or FMI 3.0's log message callback.
#[derive(Clone, Copy)]
enum Callbacks {
    Fmi2(CallbackFunctions),
    Fmi3 { environment: *mut c_void, log: Option<fmi3::LogMessage> },
}

fn log_with(callbacks: &Callbacks, name: &CStr, status: Status, message: &str) {
    let category = match status {
        OK => CAT_ALL,
        WARNING => CAT_WARNING,
        _ => CAT_ERROR,
    };
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    match *callbacks {
        Callbacks::Fmi2(c) => {
            let Some(logger) = c.logger else { return };
            // The message goes as the argument of "%s": a '%' in it is not a format.
            unsafe {
                logger(c.component_environment, name.as_ptr(), status, category.as_ptr(), c"%s".as_ptr(), text.as_ptr())
            };
        }
        Callbacks::Fmi3 { environment, log: Some(log) } => unsafe {
            log(environment, status, category.as_ptr(), text.as_ptr())
        },
        Callbacks::Fmi3 { log: None, .. } => {}
    }
}

impl Instance {
    fn error(&self, message: &str) -> Status {
        let message =
            if matches!(self.callbacks, Callbacks::Fmi3 { .. }) { fmi3::names(message) } else { message.into() };
        log_with(&self.callbacks, &self.name, ERROR, &message);
        ERROR
    }

    fn info(&self, message: &str) {
        if self.logging {
            log_with(&self.callbacks, &self.name, OK, message);
        }
    }

    fn starts(model: &Model) -> Vec<f64> {
        model.variables.iter().map(|v| v.start.unwrap_or(f64::NAN)).collect()
    }

    /// Refuses a call outside `allowed` phases, naming the call and the phase.
    fn expect(&self, call: &str, allowed: &[Phase]) -> Result<(), Status> {
        if allowed.contains(&self.phase) {
            Ok(())
        } else {
            Err(self.error(&format!("{call}: not allowed while the FMU is {}", self.phase.words())))
        }
    }

    /// The `--set` overrides of the parameters that differ from the scene's.
    fn overrides(&self, values: &[f64]) -> Vec<String> {
        self.model
            .variables
            .iter()
            .zip(values)
            .filter_map(|(v, &x)| match &v.role {
                Role::Parameter(key) if Some(x) != v.start => Some(format!("{key}={x:?}")),
                _ => None,
            })
            .collect()
    }

    /// The plant of the current parameters, at t = 0, the inputs as its initial command.
    fn build(&self, values: &[f64]) -> Result<Sim, String> {
        let overrides = self.overrides(values);
        let mut scene = plant_sim::fmi::load_fmu_scene(&self.resources, &overrides)
            .map_err(|e| format!("the scene with the parameters set ({}): {e}", overrides.join(", ")))?;
        // The last tick of a scene whose duration is not on the tick grid would be cut short at
        // the duration: move the duration onto the grid (steps past it go on whole ticks).
        let p = scene.controller.period;
        let n = (scene.duration / p).ceil();
        if n * p > scene.duration {
            let mut fixed = None;
            for extra in 0..4 {
                let d = (n + extra as f64) * p;
                if (d / p).ceil() == n + extra as f64 {
                    fixed = Some(d);
                    break;
                }
            }
            if let Some(d) = fixed {
                let mut with = overrides.clone();
                with.push(format!("scene.duration_s={d:?}"));
                scene = plant_sim::fmi::load_fmu_scene(&self.resources, &with)
                    .map_err(|e| format!("the scene with its duration on the tick grid: {e}"))?;
            }
        }
        let limits = scene.rotor_design().current_limits();
        let command = self.command(values, limits);
        let plant = Plant::new(&scene, &Command::Held(command)).map_err(|e| format!("the plant: {e}"))?;
        let start = start_words(&scene);
        let mut sim = Sim { plant, built_with: values.to_vec(), limits, outputs: Vec::new(), period: p, start };
        let mut row = LastRow(None);
        sim.plant.record(&mut row);
        sim.outputs = self.outputs_of(&sim, row.0.as_ref());
        Ok(sim)
    }

    /// Whether `a` and `b`, two sets of the variables' values, have the same parameters (the
    /// scene keys the plant is built from), to the bit.
    fn same_parameters(&self, a: &[f64], b: &[f64]) -> bool {
        self.model
            .variables
            .iter()
            .zip(a.iter().zip(b))
            .all(|(v, (x, y))| !matches!(v.role, Role::Parameter(_)) || x.to_bits() == y.to_bits())
    }

    /// The inputs, saturated at the amplifier's limit.
    fn command(&self, values: &[f64], limits: [f64; 4]) -> [f64; 4] {
        let mut c = [0.0; 4];
        for (vr, v) in self.model.variables.iter().enumerate() {
            if let Role::Input(axis) = v.role {
                c[axis] = values[vr];
            }
        }
        controller::saturate_axes(c, limits)
    }

    /// Every output's value, from the plant's sample and the output row at its time.
    fn outputs_of(&self, sim: &Sim, row: Option<&Record>) -> Vec<f64> {
        let plant = &sim.plant;
        let t = plant.time();
        let fresh;
        let row = match row {
            Some(r) if (r.a.t_s - t).abs() <= 1e-9 * sim.period => r,
            _ => {
                let mut last = LastRow(None);
                plant.record(&mut last);
                // A plant always hands over its row; without one the outputs are NaN, which
                // fmi2DoStep refuses as a diverged plant rather than a panic.
                fresh = last.0.unwrap_or(Record::planar(Row::NAN));
                &fresh
            }
        };
        let s = plant.sample();
        self.model
            .variables
            .iter()
            .map(|v| match v.role {
                Role::Output(o) => match o {
                    Output::Sensor(axis) => s.sensor_v[axis],
                    Output::Speed => s.speed_rad_s,
                    Output::Angle => s.angle_rad,
                    Output::RotorX(i) => row.plane(i).motion.dx_m,
                    Output::RotorY(i) => row.plane(i).motion.dy_m,
                    Output::Radius(i) => row.plane(i).radius(),
                    Output::ContactForce(i) => row.plane(i).loads.contact_force_n,
                    Output::RaceSpeed(i) => row.plane(i).loads.race_speed_rad_s,
                    Output::HousingX => row.a.housing.housing_x_m,
                    Output::HousingY => row.a.housing.housing_y_m,
                },
                _ => f64::NAN,
            })
            .collect()
    }

    /// The time of the FMU (s): the start time and the plant's ticks.
    fn time(&self) -> f64 {
        match &self.sim {
            Some(sim) => self.start_time + sim.plant.tick() as f64 * sim.period,
            None => self.start_time,
        }
    }

    fn variable(&self, vr: u32, call: &str) -> Result<&Variable, Status> {
        self.model.variable(vr).ok_or_else(|| {
            self.error(&format!(
                "{call}: no variable has value reference {vr} (this FMU's are 0 to {})",
                self.model.variables.len() - 1
            ))
        })
    }

    /// Sets the variables `vrs` to `values`: every value checked first, then all taken, so that
    /// a refused call (one bad value among several) leaves the instance as it was.
    fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> Status {
        let mut parameters = false;
        for (&vr, &x) in vrs.iter().zip(values) {
            let v = match self.variable(vr, "fmi2SetReal") {
                Ok(v) => v.clone(),
                Err(s) => return s,
            };
            let unit = v.unit.map(|u| format!(" {u}")).unwrap_or_default();
            match &v.role {
                Role::Output(_) => {
                    return self.error(&format!("fmi2SetReal: {} is an output of the plant; it cannot be set", v.name))
                }
                Role::Input(_) => {
                    if let Err(s) = self.expect(
                        "fmi2SetReal of an input",
                        &[Phase::Instantiated, Phase::Initialization, Phase::Stepping],
                    ) {
                        return s;
                    }
                    if !x.is_finite() {
                        return self.error(&format!(
                            "fmi2SetReal: {} = {x}{unit}: an input must be finite; the value is not taken (it stays {}{unit})",
                            v.name, self.values[vr as usize]
                        ));
                    }
                }
                Role::Parameter(_) => {
                    if let Err(s) = self.expect(
                        &format!("fmi2SetReal of parameter {} (fixed after initialization; fmi2Reset first)", v.name),
                        &[Phase::Instantiated, Phase::Initialization],
                    ) {
                        return s;
                    }
                    if let Err(why) = in_bounds(&v, x) {
                        return self.error(&format!("fmi2SetReal: {why}; the value is not taken"));
                    }
                    parameters = true;
                }
            }
        }
        for (&vr, &x) in vrs.iter().zip(values) {
            self.values[vr as usize] = x;
        }
        if parameters {
            // Outputs read in initialization mode come from a plant of these parameters.
            self.sim = None;
        }
        OK
    }

    fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> Status {
        let needs_outputs =
            vrs.iter().any(|&vr| matches!(self.model.variable(vr).map(|v| &v.role), Some(Role::Output(_))));
        if needs_outputs && self.sim.is_none() {
            if self.phase != Phase::Initialization {
                return self.error(&format!(
                    "fmi2GetReal of an output: the outputs are computed from fmi2EnterInitializationMode on; the FMU \
                     is {}",
                    self.phase.words()
                ));
            }
            match self.build(&self.values) {
                Ok(sim) => self.sim = Some(sim),
                Err(e) => return self.error(&format!("fmi2GetReal: {e}")),
            }
        }
        for (i, &vr) in vrs.iter().enumerate() {
            let role = match self.variable(vr, "fmi2GetReal") {
                Ok(v) => v.role.clone(),
                Err(s) => return s,
            };
            out[i] = match role {
                Role::Output(_) => self.sim.as_ref().map_or(f64::NAN, |s| s.outputs[vr as usize]),
                _ => self.values[vr as usize],
            };
        }
        OK
    }

    fn exit_initialization(&mut self) -> Status {
        if let Err(s) = self.expect("fmi2ExitInitializationMode", &[Phase::Initialization]) {
            return s;
        }
        let reuse = self.sim.as_ref().is_some_and(|s| s.built_with == self.values && s.plant.tick() == 0);
        if !reuse {
            match self.build(&self.values) {
                Ok(sim) => self.sim = Some(sim),
                Err(e) => return self.error(&format!("fmi2ExitInitializationMode: {e}")),
            }
        }
        let Some((period, start)) = self.sim.as_ref().map(|s| (s.period, s.start.clone())) else {
            return self.error("fmi2ExitInitializationMode: the plant was not built");
        };
        self.phase = Phase::Stepping;
        self.info(&format!(
            "initialized: {} bearing plane(s), tick {period} s; communication steps are whole multiples of it; {start}",
            self.model.planes
        ));
        OK
    }

    fn do_step(&mut self, point: f64, step: f64) -> Status {
        if let Err(s) = self.expect("fmi2DoStep", &[Phase::Stepping]) {
            return s;
        }
        let t = self.time();
        // Never the case: every call that leaves the FMU stepping leaves it with its plant
        // (a refused fmi2SetFMUstate leaves the instance as it was). Said, not assumed.
        let Some(sim) = self.sim.as_ref() else {
            return self.error("fmi2DoStep: the FMU has no plant (a bug of the FMU, please report it); fmi2Reset");
        };
        let p = sim.period;
        let rate = 1.0 / p;
        // Importers' rounding: a millionth of a tick, or a billionth of the time, whichever is
        // larger, never a quarter of a tick.
        let tol = |scale: f64| (1e-6 * p).max(1e-9 * scale.abs()).min(0.25 * p);
        if !(point.is_finite() && (point - t).abs() <= tol(t)) {
            return self.error(&format!(
                "fmi2DoStep: currentCommunicationPoint = {point:.17} s, but the FMU is at t = {t:.17} s (tick {} of \
                 {p} s); steps follow each other without gaps",
                sim.plant.tick()
            ));
        }
        let ticks = (step / p).round();
        if !(step.is_finite() && ticks >= 1.0 && (step - ticks * p).abs() <= tol(step) && ticks <= 1e9) {
            let hint = if step.is_finite() && step > p {
                format!(" (or {} s)", (step / p).round().max(1.0) * p)
            } else {
                String::new()
            };
            return self.error(&format!(
                "fmi2DoStep: communicationStepSize = {step:e} s is not a whole number of the plant's tick, {p:e} s \
                 (the scene's controller.rate_hz = {rate} Hz): use a step of {p:e} s{hint} or another whole multiple"
            ));
        }
        let command = self.command(&self.values, sim.limits);
        let mut row = LastRow(None);
        let Some(sim) = self.sim.as_mut() else { return ERROR };
        for _ in 0..ticks as u64 {
            if let Err(e) = sim.plant.step(&Command::Held(command), &mut row) {
                let what = e.to_string();
                // The run's error names the state it failed in; if not, the plant's state.
                let state =
                    if what.contains("state") { String::new() } else { format!("; state = {:?}", sim.plant.state()) };
                self.phase = Phase::Failed;
                return self.error(&format!(
                    "fmi2DoStep: the plant diverged at t = {} s: {what}{state}; the inputs were {command:?} A",
                    self.start_time + e.time()
                ));
            }
        }
        let Some(sim) = self.sim.as_ref() else { return ERROR };
        let outputs = self.outputs_of(sim, row.0.as_ref());
        if let Some(bad) =
            outputs.iter().zip(&self.model.variables).find(|(x, v)| matches!(v.role, Role::Output(_)) && !x.is_finite())
        {
            let (x, v) = bad;
            let state = sim.plant.state().to_vec();
            self.phase = Phase::Failed;
            return self.error(&format!(
                "fmi2DoStep: output {} is {x} at t = {} s: the plant diverged; state = {state:?}",
                v.name,
                self.time()
            ));
        }
        if let Some(sim) = self.sim.as_mut() {
            sim.outputs = outputs;
        }
        OK
    }

    fn state(&self) -> State {
        let outputs = self.sim.as_ref().map(|s| s.outputs.iter().map(|x| x.is_finite().then_some(*x)).collect());
        State {
            format: STATE_FORMAT,
            guid: self.model.guid.clone(),
            phase: self.phase,
            start_time: self.start_time,
            values: self.values.iter().map(|x| x.is_finite().then_some(*x)).collect(),
            snapshot: self.sim.as_ref().map(|s| s.plant.snapshot()),
            outputs,
        }
    }

    /// Restores `state`: everything in it checked first (the GUID, the counts, every value, the
    /// phase against the plant, the plant's snapshot against a plant of its parameters), then
    /// all of it taken; a refused state leaves the instance as it was, stepping on if it was.
    fn set_state(&mut self, state: &State) -> Status {
        if state.guid != self.model.guid {
            return self.error(&format!(
                "fmi2SetFMUstate: a state of another FMU (GUID {}; this FMU's is {})",
                state.guid, self.model.guid
            ));
        }
        let n = self.model.variables.len();
        if state.values.len() != n || state.outputs.as_ref().is_some_and(|o| o.len() != n) {
            return self.error(&format!(
                "fmi2SetFMUstate: the state has {} values; this FMU has {n} variables",
                state.values.len()
            ));
        }
        if !state.start_time.is_finite() {
            return self.error(&format!("fmi2SetFMUstate: the state's start time is {} s", state.start_time));
        }
        let values: Vec<f64> = state.values.iter().map(|x| x.unwrap_or(f64::NAN)).collect();
        for (v, &x) in self.model.variables.iter().zip(&values) {
            match v.role {
                Role::Output(_) => {}
                Role::Input(_) if !x.is_finite() => {
                    return self.error(&format!("fmi2SetFMUstate: the state's {} is not a number", v.name))
                }
                Role::Input(_) => {}
                Role::Parameter(_) => {
                    if let Err(why) = in_bounds(v, x) {
                        return self.error(&format!("fmi2SetFMUstate: the state's {why}"));
                    }
                }
            }
        }
        let outputs = match (&state.snapshot, &state.outputs) {
            (Some(_), Some(outputs)) => Some(outputs.iter().map(|x| x.unwrap_or(f64::NAN)).collect::<Vec<f64>>()),
            (None, None) if state.phase == Phase::Stepping => {
                return self.error("fmi2SetFMUstate: a state of an initialized (stepping) FMU without its plant")
            }
            (None, None) => None,
            _ => return self.error("fmi2SetFMUstate: a state with a plant and no outputs, or outputs and no plant"),
        };
        match (&state.snapshot, outputs) {
            (Some(snapshot), Some(outputs)) => {
                // The plant of the same parameters is kept: the restore replaces everything it
                // evolves, and the inputs are each step's command (rebuilding it cost about
                // 1 ms a call in an FMPy loop: docs/results/speed.md). `Plant::restore`
                // checks the snapshot before it changes anything: refused, the plant is as it was.
                let reuse = self.sim.as_ref().is_some_and(|s| self.same_parameters(&s.built_with, &values));
                match self.sim.as_mut() {
                    Some(sim) if reuse => {
                        if let Err(e) = sim.plant.restore(snapshot) {
                            return self.error(&format!("fmi2SetFMUstate: {e}"));
                        }
                        sim.outputs = outputs;
                    }
                    _ => {
                        let mut sim = match self.build(&values) {
                            Ok(s) => s,
                            Err(e) => return self.error(&format!("fmi2SetFMUstate: {e}")),
                        };
                        if let Err(e) = sim.plant.restore(snapshot) {
                            return self.error(&format!("fmi2SetFMUstate: {e}"));
                        }
                        sim.outputs = outputs;
                        self.sim = Some(sim);
                    }
                }
            }
            _ => self.sim = None,
        }
        self.values = values;
        self.phase = state.phase;
        self.start_time = state.start_time;
        OK
    }
}

/// Where the plant of `scene` starts, in words: `plant run`'s initial state of the scene, which
/// the scene's controller design sets (docs/guide/fmu-plant.md, "Where the plant starts").
fn start_words(scene: &plant_sim::config::Scene) -> String {
    let c = &scene.controller;
    let i = &scene.initial;
    let orbit = if i.unbalance_orbit {
        format!(
            "on the unbalance orbit of the scene's controller design (controller.stiffness_n_per_m = {} N/m, \
             controller.damping_ratio = {}{})",
            c.stiffness,
            c.damping_ratio,
            if scene.planes() > 1 { ", each plane's on its load share" } else { "" }
        )
    } else {
        "at rest at the centre (initial.unbalance_orbit = false)".to_string()
    };
    let sag = if c.gravity_bias { "" } else { ", sagged by m g / k_e (controller.gravity_bias = false)" };
    format!(
        "the plant starts {orbit}{sag}, offset by initial.rotor_x_um = {}, initial.rotor_y_um = {} um \
         (plant fmu SCENE --set KEY=VALUE chooses another start)",
        i.rotor_offset[0] * 1e6,
        i.rotor_offset[1] * 1e6
    )
}

/// The serialised state's format.
const STATE_FORMAT: u32 = 1;
/// What a serialised state starts with.
const STATE_MAGIC: &[u8] = b"amb-testbed plant FMU state\n";
/// The largest serialised state taken (bytes).
const MAX_STATE_BYTES: usize = 64 << 20;

/// An FMU state: the whole instance.
#[derive(Clone, Serialize, Deserialize)]
struct State {
    format: u32,
    guid: String,
    phase: Phase,
    start_time: f64,
    /// Inputs' and parameters' values (outputs `None`).
    values: Vec<Option<f64>>,
    /// The plant, once built.
    snapshot: Option<Snapshot>,
    /// The outputs at the state's time (with the plant).
    outputs: Option<Vec<Option<f64>>>,
}

/// An `fmi2FMUstate`: the state and its serialised bytes once asked for.
struct StateBox {
    state: State,
    bytes: Option<Vec<u8>>,
}

impl StateBox {
    fn bytes(&mut self) -> Result<&[u8], String> {
        if self.bytes.is_none() {
            let mut b = STATE_MAGIC.to_vec();
            serde_json::to_writer(&mut b, &self.state).map_err(|e| e.to_string())?;
            self.bytes = Some(b);
        }
        Ok(self.bytes.as_deref().unwrap_or_default())
    }

    fn from_bytes(bytes: &[u8]) -> Result<State, String> {
        let body = bytes.strip_prefix(STATE_MAGIC).ok_or("not a state of this FMU (its first bytes differ)")?;
        let state: State = serde_json::from_slice(body).map_err(|e| format!("a corrupt or truncated state: {e}"))?;
        if state.format != STATE_FORMAT {
            return Err(format!("a state of format {}; this FMU reads format {STATE_FORMAT}", state.format));
        }
        Ok(state)
    }
}

fn panic_text(p: &Box<dyn std::any::Any + Send>) -> String {
    p.downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| p.downcast_ref::<String>().cloned()).unwrap_or_default()
}

/// Runs `f` on the instance `c`, a panic turned into `fmi2Error` with a log line.
fn with(c: *mut c_void, call: &str, f: impl FnOnce(&mut Instance) -> Status) -> Status {
    if c.is_null() {
        return ERROR;
    }
    let p = c as *mut Instance;
    match catch_unwind(AssertUnwindSafe(|| f(unsafe { &mut *p }))) {
        Ok(s) => s,
        Err(e) => {
            let text = panic_text(&e);
            let _ = catch_unwind(AssertUnwindSafe(|| {
                let inst = unsafe { &mut *p };
                inst.phase = Phase::Failed;
                inst.error(&format!("{call}: internal error (a bug of the FMU, please report it): {text}"))
            }));
            ERROR
        }
    }
}

/// A slice from a C array (empty for a null pointer or `n = 0`).
unsafe fn slice<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        Some(&[])
    } else if p.is_null() {
        None
    } else {
        Some(std::slice::from_raw_parts(p, n))
    }
}

unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Option<&'a mut [T]> {
    if n == 0 {
        Some(&mut [])
    } else if p.is_null() {
        None
    } else {
        Some(std::slice::from_raw_parts_mut(p, n))
    }
}

/// A path from `fmuResourceLocation`: a `file:` URI (`file:///a/b`, `file:/a/b`,
/// `file://localhost/a/b`, percent-encoded) or a plain path.
fn resource_path(location: &str) -> PathBuf {
    let rest = match location.strip_prefix("file:") {
        None => return PathBuf::from(location),
        Some(r) => r,
    };
    let rest = if let Some(r) = rest.strip_prefix("//") {
        // An authority: empty or localhost.
        match r.find('/') {
            Some(i) => &r[i..],
            None => r,
        }
    } else {
        rest
    };
    let bytes = rest.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            if let Ok(b) = u8::from_str_radix(std::str::from_utf8(&bytes[i + 1..i + 3]).unwrap_or("zz"), 16) {
                out.push(b);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    use std::os::unix::ffi::OsStringExt;
    PathBuf::from(std::ffi::OsString::from_vec(out))
}

unsafe fn text(p: *const c_char) -> Option<String> {
    (!p.is_null()).then(|| CStr::from_ptr(p).to_string_lossy().into_owned())
}

/// A new instance of the FMU whose resources are at `location` (a `file:` URI or a path),
/// checked against the importer's `token` (GUID, instantiation token); `None` after a log line.
fn new_instance(
    callbacks: Callbacks,
    name: CString,
    location: Option<String>,
    token: Option<String>,
    logging: bool,
    call: &str,
) -> Option<Box<Instance>> {
    let fail = |message: String| {
        let line = format!("{call}: {message}");
        let line = if matches!(callbacks, Callbacks::Fmi3 { .. }) { fmi3::names(&line) } else { line };
        log_with(&callbacks, &name, ERROR, &line);
        None
    };
    let Some(location) = location else {
        return fail("no resource location: the FMU's resources/ folder holds its scene".into());
    };
    let resources = resource_path(&location);
    let scene = match plant_sim::fmi::load_fmu_scene(&resources, &[]) {
        Ok(s) => s,
        Err(e) => return fail(format!("the FMU's scene ({}): {e}", resources.join("scene.toml").display())),
    };
    let model = match Model::of(&scene) {
        Ok(m) => m,
        Err(e) => return fail(format!("the FMU's scene: {e}")),
    };
    if let Some(g) = token {
        if g != model.guid {
            return fail(format!(
                "fmuGUID = {g}, but this binary with resources/scene.toml makes {}: the GUID covers the whole \
                 resolved scene, so resources/scene.toml was edited (any key: rotor.mass_kg, integrator.method, ...) \
                 or the binary, the scene and modelDescription.xml are not of one FMU (rewrite it with `plant fmu`)",
                model.guid
            ));
        }
    }
    let values = Instance::starts(&model);
    let inst = Box::new(Instance {
        name,
        callbacks,
        logging,
        resources,
        model,
        phase: Phase::Instantiated,
        values,
        start_time: 0.0,
        sim: None,
    });
    inst.info(&format!("instantiated from {}", inst.resources.display()));
    Some(inst)
}

// ---------------------------------------------------------------------------------------------
// The C API (fmi2Functions.h)

#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: *const c_char,
    fmu_type: c_int,
    guid: *const c_char,
    resource_location: *const c_char,
    functions: *const CallbackFunctions,
    _visible: c_int,
    logging_on: c_int,
) -> *mut c_void {
    let made = catch_unwind(AssertUnwindSafe(|| {
        let callbacks = Callbacks::Fmi2(if functions.is_null() {
            CallbackFunctions {
                logger: None,
                allocate_memory: None,
                free_memory: None,
                step_finished: None,
                component_environment: std::ptr::null_mut(),
            }
        } else {
            *functions
        });
        let name = CString::new(text(instance_name).unwrap_or_default()).unwrap_or_default();
        if fmu_type != CO_SIMULATION {
            log_with(
                &callbacks,
                &name,
                ERROR,
                &format!(
                    "fmi2Instantiate: fmuType = {fmu_type}: this FMU is for co-simulation only (fmi2CoSimulation = 1), \
                     no model exchange"
                ),
            );
            return std::ptr::null_mut();
        }
        match new_instance(callbacks, name, text(resource_location), text(guid), logging_on != 0, "fmi2Instantiate") {
            Some(inst) => Box::into_raw(inst) as *mut c_void,
            None => std::ptr::null_mut(),
        }
    }));
    made.unwrap_or(std::ptr::null_mut())
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: *mut c_void) {
    if !c.is_null() {
        let _ = catch_unwind(AssertUnwindSafe(|| drop(Box::from_raw(c as *mut Instance))));
    }
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: *mut c_void,
    logging_on: c_int,
    n: usize,
    categories: *const *const c_char,
) -> Status {
    with(c, "fmi2SetDebugLogging", |inst| {
        let Some(cats) = slice(categories, n) else { return inst.error("fmi2SetDebugLogging: categories is NULL") };
        for &cat in cats {
            let name = text(cat).unwrap_or_default();
            if !plant_sim::fmi::LOG_CATEGORIES.iter().any(|(c, _)| *c == name) {
                return inst.error(&format!(
                    "fmi2SetDebugLogging: no log category {name:?}; this FMU's are {}",
                    plant_sim::fmi::LOG_CATEGORIES.map(|c| c.0).join(", ")
                ));
            }
        }
        inst.logging = logging_on != 0;
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: *mut c_void,
    _tolerance_defined: c_int,
    _tolerance: f64,
    start_time: f64,
    stop_time_defined: c_int,
    stop_time: f64,
) -> Status {
    with(c, "fmi2SetupExperiment", |inst| {
        if let Err(s) = inst.expect("fmi2SetupExperiment", &[Phase::Instantiated]) {
            return s;
        }
        if !start_time.is_finite() {
            return inst.error(&format!("fmi2SetupExperiment: startTime = {start_time} s"));
        }
        if stop_time_defined != 0 && !(stop_time.is_finite() && stop_time >= start_time) {
            return inst.error(&format!(
                "fmi2SetupExperiment: stopTime = {stop_time} s is not a time after startTime = {start_time} s"
            ));
        }
        inst.start_time = start_time;
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: *mut c_void) -> Status {
    with(c, "fmi2EnterInitializationMode", |inst| {
        if let Err(s) = inst.expect("fmi2EnterInitializationMode", &[Phase::Instantiated]) {
            return s;
        }
        inst.phase = Phase::Initialization;
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: *mut c_void) -> Status {
    with(c, "fmi2ExitInitializationMode", |inst| inst.exit_initialization())
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: *mut c_void) -> Status {
    with(c, "fmi2Terminate", |inst| {
        if let Err(s) = inst.expect("fmi2Terminate", &[Phase::Stepping, Phase::Initialization]) {
            return s;
        }
        inst.phase = Phase::Terminated;
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: *mut c_void) -> Status {
    with(c, "fmi2Reset", |inst| {
        inst.phase = Phase::Instantiated;
        inst.values = Instance::starts(&inst.model);
        inst.sim = None;
        inst.start_time = 0.0;
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(c: *mut c_void, vr: *const u32, n: usize, value: *mut f64) -> Status {
    with(c, "fmi2GetReal", |inst| match (slice(vr, n), slice_mut(value, n)) {
        (Some(vr), Some(value)) => inst.get_real(vr, value),
        _ => inst.error("fmi2GetReal: a NULL array"),
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(c: *mut c_void, vr: *const u32, n: usize, value: *const f64) -> Status {
    with(c, "fmi2SetReal", |inst| match (slice(vr, n), slice(value, n)) {
        (Some(vr), Some(value)) => inst.set_real(vr, value),
        _ => inst.error("fmi2SetReal: a NULL array"),
    })
}

/// The Integer, Boolean and String accessors: this FMU has Real variables only.
fn none_of_type(c: *mut c_void, call: &str, n: usize) -> Status {
    with(c, call, |inst| {
        if n == 0 {
            OK
        } else {
            inst.error(&format!("{call}: this FMU has no variable of this type (all its variables are Real)"))
        }
    })
}

#[no_mangle]
pub extern "C" fn fmi2GetInteger(c: *mut c_void, _vr: *const u32, n: usize, _value: *mut c_int) -> Status {
    none_of_type(c, "fmi2GetInteger", n)
}

#[no_mangle]
pub extern "C" fn fmi2SetInteger(c: *mut c_void, _vr: *const u32, n: usize, _value: *const c_int) -> Status {
    none_of_type(c, "fmi2SetInteger", n)
}

#[no_mangle]
pub extern "C" fn fmi2GetBoolean(c: *mut c_void, _vr: *const u32, n: usize, _value: *mut c_int) -> Status {
    none_of_type(c, "fmi2GetBoolean", n)
}

#[no_mangle]
pub extern "C" fn fmi2SetBoolean(c: *mut c_void, _vr: *const u32, n: usize, _value: *const c_int) -> Status {
    none_of_type(c, "fmi2SetBoolean", n)
}

#[no_mangle]
pub extern "C" fn fmi2GetString(c: *mut c_void, _vr: *const u32, n: usize, _value: *mut *const c_char) -> Status {
    none_of_type(c, "fmi2GetString", n)
}

#[no_mangle]
pub extern "C" fn fmi2SetString(c: *mut c_void, _vr: *const u32, n: usize, _value: *const *const c_char) -> Status {
    none_of_type(c, "fmi2SetString", n)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(c: *mut c_void, state: *mut *mut c_void) -> Status {
    with(c, "fmi2GetFMUstate", |inst| {
        if state.is_null() {
            return inst.error("fmi2GetFMUstate: FMUstate is NULL");
        }
        let s = inst.state();
        if (*state).is_null() {
            *state = Box::into_raw(Box::new(StateBox { state: s, bytes: None })) as *mut c_void;
        } else {
            let b = &mut *(*state as *mut StateBox);
            b.state = s;
            b.bytes = None;
        }
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: *mut c_void, state: *mut c_void) -> Status {
    with(c, "fmi2SetFMUstate", |inst| {
        if state.is_null() {
            return inst.error("fmi2SetFMUstate: FMUstate is NULL");
        }
        let s = (*(state as *mut StateBox)).state.clone();
        inst.set_state(&s)
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(c: *mut c_void, state: *mut *mut c_void) -> Status {
    with(c, "fmi2FreeFMUstate", |_| {
        if !state.is_null() && !(*state).is_null() {
            drop(Box::from_raw(*state as *mut StateBox));
            *state = std::ptr::null_mut();
        }
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(c: *mut c_void, state: *mut c_void, size: *mut usize) -> Status {
    with(c, "fmi2SerializedFMUstateSize", |inst| {
        if state.is_null() || size.is_null() {
            return inst.error("fmi2SerializedFMUstateSize: a NULL argument");
        }
        match (*(state as *mut StateBox)).bytes() {
            Ok(b) => {
                *size = b.len();
                OK
            }
            Err(e) => inst.error(&format!("fmi2SerializedFMUstateSize: {e}")),
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: *mut c_void,
    state: *mut c_void,
    bytes: *mut c_char,
    size: usize,
) -> Status {
    with(c, "fmi2SerializeFMUstate", |inst| {
        if state.is_null() || bytes.is_null() {
            return inst.error("fmi2SerializeFMUstate: a NULL argument");
        }
        match (*(state as *mut StateBox)).bytes() {
            Ok(b) if b.len() <= size => {
                std::ptr::copy_nonoverlapping(b.as_ptr(), bytes as *mut u8, b.len());
                OK
            }
            Ok(b) => inst.error(&format!(
                "fmi2SerializeFMUstate: the state needs {} bytes, the buffer has {size} (fmi2SerializedFMUstateSize)",
                b.len()
            )),
            Err(e) => inst.error(&format!("fmi2SerializeFMUstate: {e}")),
        }
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: *mut c_void,
    bytes: *const c_char,
    size: usize,
    state: *mut *mut c_void,
) -> Status {
    with(c, "fmi2DeSerializeFMUstate", |inst| {
        if state.is_null() {
            return inst.error("fmi2DeSerializeFMUstate: FMUstate is NULL");
        }
        if size > MAX_STATE_BYTES {
            return inst.error(&format!("fmi2DeSerializeFMUstate: {size} bytes; a state of this FMU has far fewer"));
        }
        let Some(b) = slice(bytes as *const u8, size) else {
            return inst.error("fmi2DeSerializeFMUstate: serializedState is NULL");
        };
        match StateBox::from_bytes(b) {
            Ok(s) if s.guid != inst.model.guid => inst.error(&format!(
                "fmi2DeSerializeFMUstate: a state of another FMU (GUID {}; this FMU's is {})",
                s.guid, inst.model.guid
            )),
            Ok(s) => {
                let boxed = Box::new(StateBox { state: s, bytes: None });
                if !(*state).is_null() {
                    drop(Box::from_raw(*state as *mut StateBox));
                }
                *state = Box::into_raw(boxed) as *mut c_void;
                OK
            }
            Err(e) => inst.error(&format!("fmi2DeSerializeFMUstate: {e}")),
        }
    })
}

#[no_mangle]
pub extern "C" fn fmi2GetDirectionalDerivative(
    c: *mut c_void,
    _unknown: *const u32,
    _n_unknown: usize,
    _known: *const u32,
    _n_known: usize,
    _dv_known: *const f64,
    _dv_unknown: *mut f64,
) -> Status {
    with(c, "fmi2GetDirectionalDerivative", |inst| {
        inst.error(
            "fmi2GetDirectionalDerivative: not provided (providesDirectionalDerivative = false: the contact is not smooth)",
        )
    })
}

#[no_mangle]
pub extern "C" fn fmi2SetRealInputDerivatives(
    c: *mut c_void,
    _vr: *const u32,
    _n: usize,
    _order: *const c_int,
    _value: *const f64,
) -> Status {
    with(c, "fmi2SetRealInputDerivatives", |inst| {
        inst.error("fmi2SetRealInputDerivatives: the inputs are held over a step (canInterpolateInputs = false)")
    })
}

#[no_mangle]
pub extern "C" fn fmi2GetRealOutputDerivatives(
    c: *mut c_void,
    _vr: *const u32,
    _n: usize,
    _order: *const c_int,
    _value: *mut f64,
) -> Status {
    with(c, "fmi2GetRealOutputDerivatives", |inst| {
        inst.error("fmi2GetRealOutputDerivatives: not provided (maxOutputDerivativeOrder = 0)")
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(c: *mut c_void, point: f64, step: f64, _no_set_prior: c_int) -> Status {
    with(c, "fmi2DoStep", |inst| inst.do_step(point, step))
}

#[no_mangle]
pub extern "C" fn fmi2CancelStep(c: *mut c_void) -> Status {
    with(c, "fmi2CancelStep", |inst| inst.error("fmi2CancelStep: fmi2DoStep never returns fmi2Pending here"))
}

#[no_mangle]
pub extern "C" fn fmi2GetStatus(c: *mut c_void, _kind: c_int, _value: *mut Status) -> Status {
    with(c, "fmi2GetStatus", |inst| inst.error("fmi2GetStatus: fmi2DoStep never returns fmi2Pending here"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(c: *mut c_void, kind: c_int, value: *mut f64) -> Status {
    with(c, "fmi2GetRealStatus", |inst| {
        // fmi2LastSuccessfulTime = 2.
        if kind == 2 && !value.is_null() {
            *value = inst.time();
            OK
        } else {
            inst.error(&format!("fmi2GetRealStatus: status kind {kind} is not available (only fmi2LastSuccessfulTime)"))
        }
    })
}

#[no_mangle]
pub extern "C" fn fmi2GetIntegerStatus(c: *mut c_void, _kind: c_int, _value: *mut c_int) -> Status {
    with(c, "fmi2GetIntegerStatus", |inst| inst.error("fmi2GetIntegerStatus: no integer status"))
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(c: *mut c_void, kind: c_int, value: *mut c_int) -> Status {
    with(c, "fmi2GetBooleanStatus", |inst| {
        // fmi2Terminated = 3: the slave never asks to end the simulation.
        if kind == 3 && !value.is_null() {
            *value = 0;
            OK
        } else {
            inst.error(&format!("fmi2GetBooleanStatus: status kind {kind} is not available (only fmi2Terminated)"))
        }
    })
}

#[no_mangle]
pub extern "C" fn fmi2GetStringStatus(c: *mut c_void, _kind: c_int, _value: *mut *const c_char) -> Status {
    with(c, "fmi2GetStringStatus", |inst| inst.error("fmi2GetStringStatus: no string status"))
}

#[cfg(test)]
mod tests {
    use super::resource_path;
    use std::path::Path;

    #[test]
    fn resource_locations_become_paths() {
        assert_eq!(resource_path("file:///tmp/a%20b/resources"), Path::new("/tmp/a b/resources"));
        assert_eq!(resource_path("file:/tmp/x/resources/"), Path::new("/tmp/x/resources/"));
        assert_eq!(resource_path("file://localhost/tmp/x"), Path::new("/tmp/x"));
        assert_eq!(resource_path("/plain/path"), Path::new("/plain/path"));
        assert_eq!(resource_path("file:///tmp/100%"), Path::new("/tmp/100%"));
    }
}
