//! The handshake of a session: the hello a scene sends, opening the run's services, starting
//! (or waiting for) the controller process, and its answer (token, session, protocol version,
//! refusal, overrides, scheduling). A child of [`super`] so that it works on the session's
//! own fields.

use super::{Session, RING};
use crate::config::{ControlMode, CosimSettings, Pacing, Scene};
use crate::cosim::log::OutputLog;
use crate::cosim::process::{self, Child, Program};
use crate::cosim::stats::{Figures, Scheduling};
use crate::cosim::{ControllerProcess, CosimError, Launch};
use crate::hooks::Hooks;
use controller::link::{self, Endpoint, Mailbox};
use controller::wire::{self, mode, Ack, Hello, Refusal};
use controller::ROTOR_AXES;
use std::time::{Duration, Instant};

/// The hello is published again this often until it is answered.
const HELLO_EVERY: Duration = Duration::from_millis(5);

/// A handshake in progress.
pub(super) struct Pending {
    since: Instant,
    last_hello: Option<Instant>,
}

/// The hello a scene sends: the scene's [`controller::RotorDesign`] (2 axes for the planar
/// model, 4 with plane B's design and the geometry for a two-plane rotor), law and parameter
/// document, with the run's token.
pub fn hello_for(scene: &Scene, run_id: &str, token: u64) -> Result<Hello, CosimError> {
    let c = &scene.controller;
    let params = c.params.to_document()?;
    let mut hello = Hello::for_rotor(run_id, &c.law, &scene.rotor_design(), c.rate_hz, &params)?;
    hello.token = token;
    hello.spin_ns = (controller_spin(c.mode, &c.cosim, c.period) * 1e9) as u64;
    hello.mode = if c.mode == ControlMode::Realtime { mode::REALTIME } else { mode::LOCKSTEP };
    Ok(hello)
}

/// Minimum busy-poll budget of a realtime controller, in periods.
const REALTIME_SPIN_PERIODS: f64 = 100.0;

/// The controller's busy-poll budget (s): `controller.spin_us`, but at least
/// [`REALTIME_SPIN_PERIODS`] periods in realtime. A realtime controller owns
/// a core; one that blocks between frames is woken on the plant's core by
/// the scheduler (wake-affine), the two then share one core and most
/// deadlines are missed (measured: 84 % misses at 20 kHz, against < 2 %
/// spinning).
///
/// A controller that shares the plant's core (`pin_cores = [c, c]`) never spins, in any
/// mode: it runs above the plant ([`controller_priority`]) and would keep it from its tick.
/// Nor does a realtime controller whose plant sleeps between ticks (`pacing = "sleep"`).
fn controller_spin(mode: ControlMode, settings: &CosimSettings, period: f64) -> f64 {
    match (mode, settings.pacing) {
        _ if shares_core(settings) => 0.0,
        (ControlMode::Realtime, Pacing::Spin) => settings.spin.max(REALTIME_SPIN_PERIODS * period),
        (ControlMode::Realtime, Pacing::Sleep) => 0.0,
        _ => settings.spin,
    }
}

/// Plant and controller pinned to one core (`pin_cores = [c, c]`).
fn shares_core(settings: &CosimSettings) -> bool {
    settings.pin_cores.is_some_and(|[p, c]| p == c)
}

/// The warning for a realtime plant that spins under `SCHED_FIFO` while RT throttling is on:
/// Linux stops `SCHED_FIFO` threads for the rest of each second once they have run
/// `sched_rt_runtime_us` of it, and a spinning plant wants all of it (measured: stalls of
/// 44–50 ms, 1,400–2,400 plant overruns in the 1.5 s scene).
fn rt_throttling_warning(settings: &CosimSettings, rt_runtime_us: Option<i64>) -> Option<String> {
    let runtime = rt_runtime_us?;
    let stall = link::rt_throttle_ms(runtime)?;
    (settings.realtime_priority > 0 && settings.pacing == Pacing::Spin).then(|| {
        format!(
            "warning: controller.pacing = \"spin\" under SCHED_FIFO with kernel.sched_rt_runtime_us = {runtime}: \
             Linux stops the spinning plant for {stall} ms of every second (RT throttling); turn it off \
             (`sysctl kernel.sched_rt_runtime_us=-1`, or scripts/shield-core.sh on) or use pacing = \"sleep\""
        )
    })
}

/// The controller's `SCHED_FIFO` priority next to the plant's `controller.realtime_priority`
/// (0: off): the plant's, or one above it (at most 99) when the two share a core. There the
/// controller runs only when the plant's frame wakes it, at once, preempting the plant: its
/// reply is ready before the next tick whether the plant sleeps or spins between ticks
/// (measured on the 10 G scene, spinning: 0 deadline misses in 10 of 10 runs, each the
/// lockstep trace bit for bit; at one priority a spinning plant starves the controller, and
/// one below the plant, a sleeping plant's clock preempts a controller still at work).
pub(in crate::run::cosim) fn controller_priority(settings: &CosimSettings) -> u32 {
    match settings.realtime_priority {
        0 => 0,
        p if shares_core(settings) => (p + 1).min(99),
        p => p,
    }
}

impl Session {
    /// Opens the services of a run, starts (or waits for) the controller and
    /// completes the handshake. `bias` is the saturated bias command (A, per axis).
    pub fn connect(
        scene: &Scene,
        launch: &Launch,
        bias: [f64; ROTOR_AXES],
        hooks: &mut dyn Hooks,
    ) -> Result<Session, CosimError> {
        let run_id = match &launch.run_id {
            Some(id) => wire::valid_run_id(id).map_err(CosimError::RunId)?.to_string(),
            None => crate::cosim::new_run_id(),
        };
        let hello = hello_for(scene, &run_id, crate::cosim::new_token())?;
        Self::open(
            scene.controller.mode,
            scene.controller.cosim.clone(),
            hello,
            launch,
            bias,
            scene.controller.period,
            hooks,
        )
    }

    pub(in crate::run::cosim) fn open(
        mode: ControlMode,
        settings: CosimSettings,
        hello: Hello,
        launch: &Launch,
        bias: [f64; ROTOR_AXES],
        period: f64,
        hooks: &mut dyn Hooks,
    ) -> Result<Session, CosimError> {
        let run_id = wire::str_of(&hello.run_id).into_owned();
        let program = program_of(launch, &settings)?;
        // Before any service of the run is opened: a second plant under a live run id never
        // touches the first one's services.
        let lock = controller::lock::acquire(&run_id, "plant")?;
        if let Some([plant_core, _]) = settings.pin_cores {
            link::pin_to_core(plant_core).map_err(CosimError::Pin)?;
        }
        let (scheduling, idle_latency) = scheduling_of(mode, &settings, hooks);
        let log = OutputLog::create(launch.log.as_deref())
            .map_err(|e| CosimError::Spawn {
                path: launch.log.clone().unwrap_or_default(),
                why: format!("cannot create the file for the controller's output: {e}"),
            })?
            .avoiding(settings.pinned_cores());
        let node = link::node(&run_id, "plant")?;
        let handshake = Mailbox::open(&node, &run_id, "hello", "ack")?;
        let frames = Endpoint::open(&node, &run_id, "sensor", "command", Duration::from_secs_f64(settings.spin))?;
        let watch = link::PeerWatch::new(&run_id, "controller");
        let mut s = Session {
            mode,
            run_id,
            frames,
            handshake,
            _node: node,
            _idle_latency: idle_latency,
            child: None,
            program,
            log,
            _lock: lock,
            hello,
            limits: hello.rotor_design().map_or([hello.current_limit_a; ROTOR_AXES], |d| d.current_limits()),
            bias,
            period,
            connected: false,
            lost_since: None,
            losses: 0,
            pending: None,
            first_seq: 0,
            last_cmd: bias,
            controller: String::new(),
            controller_pid: None,
            start: None,
            woke: None,
            sent_ns: [0; RING],
            last_heard: Instant::now(),
            silent: Default::default(),
            next_check: Duration::from_secs_f64(settings.reply_timeout),
            wall_start: Instant::now(),
            overrides: None,
            figures: Figures::default(),
            scheduling,
            wake_warned: false,
            watch,
            watchdog: None,
            settings,
        };
        s.start_watchdog(hooks);
        if s.program.is_none() {
            hooks.note(&format!(
                "waiting up to {} s for a controller: start `controller --run-id {}`",
                s.settings.connect_timeout, s.run_id
            ));
        }
        s.spawn()?;
        s.handshake_blocking(s.settings.connect_timeout, hooks)?;
        s.event("connected", 0.0, 0, s.controller.clone());
        s.wall_start = Instant::now();
        Ok(s)
    }

    /// On a shared core the controller runs above the plant; the watchdog above both.
    fn start_watchdog(&mut self, hooks: &mut dyn Hooks) {
        let above = controller_priority(&self.settings);
        if let Some([core, _]) = self.settings.pin_cores {
            if shares_core(&self.settings) && above > 0 && self.scheduling.plant == "fifo" {
                self.watchdog = super::super::watchdog::Watchdog::start(core, (above as i32 + 1).min(99));
                if self.watchdog.is_none() {
                    hooks.note(
                        "warning: cannot start the plant's watchdog on the shared core: a controller that stops \
                         blocking between frames would hold the core",
                    );
                }
            }
        }
    }

    pub(super) fn spawn(&mut self) -> Result<(), CosimError> {
        if let Some(program) = &self.program {
            let args = process::Args {
                run_id: &self.run_id,
                pin_core: self.settings.pin_cores.map(|c| c[1]),
                connect_timeout_s: self.settings.connect_timeout.max(1.0),
                realtime_priority: controller_priority(&self.settings),
            };
            self.child = Some(Child::spawn(program, &args, &mut self.log)?);
        }
        Ok(())
    }

    /// Starts a handshake with a new session number.
    pub(super) fn begin_handshake(&mut self) {
        self.hello.session += 1;
        self.pending = Some(Pending { since: Instant::now(), last_hello: None });
    }

    /// Advances the pending handshake: `Some(Ok(()))` when accepted.
    pub(super) fn poll_handshake(&mut self, hooks: &mut dyn Hooks) -> Option<Result<(), CosimError>> {
        let pending = self.pending.as_mut()?;
        if pending.last_hello.is_none_or(|t| t.elapsed() >= HELLO_EVERY) {
            if let Err(e) = self.handshake.send(self.hello) {
                return Some(Err(e.into()));
            }
            pending.last_hello = Some(Instant::now());
        }
        loop {
            match self.handshake.try_receive() {
                Err(e) => return Some(Err(e.into())),
                Ok(None) => return None,
                Ok(Some(ack)) if ack.token != self.hello.token => {
                    // An answer to another run's hello (same run id), or a foreign process's.
                    self.figures.foreign += 1;
                    continue;
                }
                Ok(Some(ack)) if ack.session != self.hello.session => continue, // an earlier session's
                Ok(Some(ack)) => {
                    self.pending = None;
                    if ack.protocol_version != wire::PROTOCOL_VERSION {
                        return Some(Err(CosimError::Protocol(format!(
                            "it says protocol version {} (pid {}); this plant speaks version {}",
                            ack.protocol_version,
                            ack.controller_pid,
                            wire::PROTOCOL_VERSION
                        ))));
                    }
                    let message = wire::str_of(&ack.message).into_owned();
                    if ack.status != 0 {
                        return Some(Err(CosimError::Refused { reason: Refusal::describe(ack.status), message }));
                    }
                    match controller_overrides(&ack) {
                        Ok(o) => {
                            // The controller is untrusted input: it may run its own law and design,
                            // never change the run it serves. Refused whole, nothing applied.
                            let allowed = o.as_ref().map_or(Ok(()), |t| {
                                crate::config::check_controller_overrides(t, self.hello.current_limit_a)
                            });
                            if let Err(why) = allowed {
                                let controller = match &self.program {
                                    Some(p) => format!("{} ({message}, pid {})", p.describe(), ack.controller_pid),
                                    None => format!("the external controller ({message}, pid {})", ack.controller_pid),
                                };
                                return Some(Err(CosimError::Overrides { controller, why }));
                            }
                            self.overrides = o;
                        }
                        Err(why) => return Some(Err(CosimError::Protocol(why))),
                    }
                    self.controller = format!("{message} (pid {})", ack.controller_pid);
                    self.controller_pid = Some(ack.controller_pid);
                    self.connected = true;
                    self.lost_since = None;
                    self.last_heard = Instant::now();
                    self.silent = Default::default();
                    self.next_check = Duration::from_secs_f64(self.settings.reply_timeout);
                    self.schedule_controller(ack.controller_pid, hooks);
                    return Some(Ok(()));
                }
            }
        }
    }

    /// With `controller.realtime_priority`, puts the controller under `SCHED_FIFO` too, next to
    /// the plant ([`controller_priority`]; a controller the plant did not start, or one that
    /// did not take it itself).
    fn schedule_controller(&mut self, pid: u32, hooks: &mut dyn Hooks) {
        let priority = self.settings.realtime_priority;
        if priority > 0 {
            if let Err(refused) = link::set_fifo(pid, controller_priority(&self.settings) as i32) {
                hooks.note(&format!(
                    "warning: controller.realtime_priority = {priority}: cannot put the controller under {refused}; running without it"
                ));
                self.scheduling.refused.push(format!("controller: {refused}"));
            }
        }
        if let Some(w) = &self.watchdog {
            w.watch_controller(pid);
        }
        self.scheduling.controller = link::policy(pid).to_string();
        self.scheduling.controller_priority = link::fifo_priority(pid).and_then(|p| u32::try_from(p).ok());
    }

    pub(super) fn handshake_blocking(&mut self, timeout: f64, hooks: &mut dyn Hooks) -> Result<(), CosimError> {
        self.begin_handshake();
        loop {
            if let Some(done) = self.poll_handshake(hooks) {
                return done;
            }
            if hooks.cancelled() {
                return Err(CosimError::Interrupted);
            }
            if let Some(child) = self.child.as_mut() {
                if let Some(status) = child.exited() {
                    self.log.settle();
                    return Err(CosimError::ControllerExited {
                        program: child.program().describe(),
                        status: status.to_string(),
                        code: status.code(),
                        output: self.log.quote(3),
                    });
                }
            }
            let waited = self.pending.as_ref().map_or(0.0, |p| p.since.elapsed().as_secs_f64());
            if waited > timeout {
                self.pending = None;
                let hint = match &self.child {
                    Some(c) => format!(
                        " (the controller {} was started but did not answer{})",
                        c.program().describe(),
                        self.log.quote(3)
                    ),
                    None => format!("; start one with `controller --run-id {}`", self.run_id),
                };
                return Err(CosimError::NoController { waited_s: timeout, run_id: self.run_id.clone(), hint });
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }
}

/// The `[controller]` table of an ack's overrides document (`None` if empty).
fn controller_overrides(ack: &Ack) -> Result<Option<toml::Table>, String> {
    let text = ack.overrides_text()?;
    if text.trim().is_empty() {
        return Ok(None);
    }
    let mut doc: toml::Table = text.parse().map_err(|e| format!("its overrides are not valid TOML: {e}"))?;
    match doc.remove("controller") {
        Some(toml::Value::Table(t)) if doc.is_empty() => Ok(Some(t)),
        _ => Err(format!("its overrides must be one [controller] table, got: {text}")),
    }
}

/// The controller process a run starts: the built-in one beside the plant, `controller.command`,
/// or none (an external controller the user starts).
fn program_of(launch: &Launch, settings: &CosimSettings) -> Result<Option<Program>, CosimError> {
    Ok(match &launch.controller {
        ControllerProcess::Spawn(Some(path)) => Some(Program::Builtin(path.clone())),
        ControllerProcess::Spawn(None) => Some(match &settings.command {
            Some(argv) => process::resolve(argv)?,
            None => Program::Builtin(process::controller_exe_next_to_current()?),
        }),
        ControllerProcess::External => None,
    })
}

/// The plant's scheduling before the controller starts (which inherits it): the realtime
/// policy asked for, what was refused (each a warning), and in realtime mode the pacing and the
/// idle latency held at 0 (the file that holds it, kept open for the run).
fn scheduling_of(
    mode: ControlMode,
    settings: &CosimSettings,
    hooks: &mut dyn Hooks,
) -> (Scheduling, Option<std::fs::File>) {
    let mut scheduling = Scheduling { realtime_priority: settings.realtime_priority, ..Default::default() };
    if settings.realtime_priority > 0 {
        // Before the controller is started: it inherits the policy (and is told to lock its
        // own memory through the environment).
        for refused in link::realtime(settings.realtime_priority as i32) {
            hooks.note(&format!(
                "warning: controller.realtime_priority = {}: the plant could not take {refused}; running without it",
                settings.realtime_priority
            ));
            scheduling.refused.push(format!("plant: {refused}"));
        }
    }
    scheduling.plant = link::policy(0).to_string();
    let mut idle_latency = None;
    if mode == ControlMode::Realtime {
        scheduling.pacing = Some(format!("{:?}", settings.pacing).to_lowercase());
        scheduling.rt_runtime_us = link::rt_runtime_us();
        if let Some(why) = rt_throttling_warning(settings, scheduling.rt_runtime_us) {
            hooks.note(&why);
        }
        if settings.realtime_priority > 0 {
            match link::hold_zero_idle_latency() {
                Ok(f) => {
                    idle_latency = Some(f);
                    scheduling.idle_latency_us = Some(0);
                }
                Err(e) => {
                    hooks.note(&format!(
                        "warning: controller.realtime_priority = {}: cannot hold the idle latency at 0 ({e}); \
                         idle cores may wake slower",
                        settings.realtime_priority
                    ));
                    scheduling.refused.push(format!("plant: {e}"));
                }
            }
        }
    }
    (scheduling, idle_latency)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shipped 10 G scene's co-simulation settings with `pacing`, `pin_cores` and the
    /// priority given.
    fn settings(pacing: Pacing, pin_cores: Option<[usize; 2]>, priority: u32) -> CosimSettings {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/cosim-10g.toml");
        let mut s = crate::config::load_scene(&path, &[]).unwrap().controller.cosim;
        (s.pacing, s.pin_cores, s.realtime_priority) = (pacing, pin_cores, priority);
        s
    }

    /// A spinning realtime controller with a core of its own spins at least 100 periods; one
    /// that sleeps, or shares the plant's core (in any mode), never spins; lockstep keeps
    /// `controller.spin_us`.
    #[test]
    fn the_controller_spins_only_where_it_owns_a_core() {
        let period = 50e-6;
        let at = |pacing, cores, spin| {
            let mut s = settings(pacing, cores, 0);
            s.spin = spin;
            s
        };
        let (rt, ls) = (ControlMode::Realtime, ControlMode::Lockstep);
        assert_eq!(controller_spin(rt, &at(Pacing::Spin, None, 200e-6), period), 100.0 * period);
        assert_eq!(controller_spin(rt, &at(Pacing::Spin, Some([1, 0]), 0.01), period), 0.01);
        assert_eq!(controller_spin(rt, &at(Pacing::Spin, Some([1, 1]), 0.01), period), 0.0);
        assert_eq!(controller_spin(rt, &at(Pacing::Sleep, None, 200e-6), period), 0.0);
        assert_eq!(controller_spin(ls, &at(Pacing::Sleep, None, 200e-6), period), 200e-6);
        assert_eq!(controller_spin(ls, &at(Pacing::Spin, Some([0, 0]), 200e-6), period), 0.0);
    }

    /// A spinning FIFO plant is warned of RT throttling unless it is off; a sleeping one, or one
    /// without a priority, is not.
    #[test]
    fn a_spinning_fifo_plant_is_warned_of_rt_throttling() {
        let spin = settings(Pacing::Spin, Some([1, 1]), 50);
        let why = rt_throttling_warning(&spin, Some(950_000)).unwrap();
        assert!(why.contains("kernel.sched_rt_runtime_us = 950000") && why.contains("for 50 ms"), "{why}");
        assert_eq!(rt_throttling_warning(&spin, Some(-1)), None);
        assert_eq!(rt_throttling_warning(&spin, None), None);
        assert_eq!(rt_throttling_warning(&settings(Pacing::Sleep, Some([1, 1]), 50), Some(950_000)), None);
        assert_eq!(rt_throttling_warning(&settings(Pacing::Spin, Some([1, 1]), 0), Some(950_000)), None);
    }

    /// The controller runs at the plant's priority, one above it on a shared core (at most 99);
    /// 0 stays off.
    #[test]
    fn the_controller_runs_above_the_plant_on_a_shared_core() {
        let p = |cores, priority| controller_priority(&settings(Pacing::Spin, cores, priority));
        assert_eq!(p(Some([1, 1]), 50), 51);
        assert_eq!(p(Some([1, 1]), 99), 99);
        assert_eq!(p(Some([1, 0]), 50), 50);
        assert_eq!(p(None, 50), 50);
        assert_eq!(p(Some([1, 1]), 0), 0);
    }
}
