//! A controller that went silent or was lost: the fallback command, and in lockstep the
//! reconnection (a controller started or waited for anew), bounded by
//! [`super::MAX_RECONNECTIONS`]; whether a silent controller is still there.

use super::*;

impl Session {
    /// A live controller that did not answer within `controller.lockstep_timeout_ms`.
    pub(super) fn on_silent(
        &mut self,
        sample: &RotorSample,
        seen: &Seen,
        hooks: &mut dyn Hooks,
    ) -> Result<[f64; ROTOR_AXES], Halt> {
        let pid = self.controller_pid.map(|p| format!(" (pid {p})")).unwrap_or_default();
        let why = match self.mode {
            ControlMode::Realtime => format!(
                "no reply for controller.lockstep_timeout_ms = {} ms (up to sample {}) although the controller{pid} is \
                 alive: {}",
                self.settings.lockstep_timeout * 1e3,
                sample.seq,
                seen.describe()
            ),
            _ => format!(
                "no reply to sample {} within controller.lockstep_timeout_ms = {} ms although the controller{pid} is alive: {}",
                sample.seq,
                self.settings.lockstep_timeout * 1e3,
                seen.describe()
            ),
        };
        self.on_lost(sample, why, hooks)
    }

    /// A lost controller at sample `k`: record it, then the fallback, then
    /// (lockstep) a blocking reconnection or the end of the run.
    pub(super) fn on_lost(
        &mut self,
        sample: &RotorSample,
        why: String,
        hooks: &mut dyn Hooks,
    ) -> Result<[f64; ROTOR_AXES], Halt> {
        self.connected = false;
        self.lost_since = Some(Instant::now());
        let (cmd, applied) = match self.settings.fallback {
            Fallback::Hold => (self.last_cmd, "holding the last current"),
            Fallback::Bias => (self.bias, "bias current only"),
            Fallback::Stop => (self.last_cmd, "stopping (controller.fallback = \"stop\")"),
        };
        hooks.note(&format!("controller lost at t = {} s (sample {}): {why}; {applied}", sample.t_s, sample.seq));
        self.event("lost", sample.t_s, sample.seq, format!("{why}; {applied}"));
        if let Some(mut child) = self.child.take() {
            child.reap(Duration::ZERO);
        }
        if self.settings.fallback == Fallback::Stop || self.settings.reconnect_timeout <= 0.0 {
            return Err(Halt::Lost(format!("controller lost at t = {} s (sample {}): {why}", sample.t_s, sample.seq)));
        }
        self.losses += 1;
        if self.losses > MAX_RECONNECTIONS {
            return Err(Halt::Lost(format!(
                "controller lost at t = {} s (sample {}): {why}; lost {} times in this run: no further reconnection \
                 (at most {MAX_RECONNECTIONS} per run)",
                sample.t_s, sample.seq, self.losses
            )));
        }
        self.last_cmd = cmd;
        if let Err(e) = self.spawn() {
            return Err(Halt::Lost(format!("{why}; cannot start a new controller: {e}")));
        }
        hooks.note(&format!(
            "waiting up to {} s for a controller to reconnect (run id {})",
            self.settings.reconnect_timeout, self.run_id
        ));
        if self.mode == ControlMode::Realtime {
            self.begin_handshake();
            self.figures.fallback_ticks += 1;
            return Ok(cmd);
        }
        match self.handshake_blocking(self.settings.reconnect_timeout, hooks) {
            Ok(()) => {
                self.first_seq = sample.seq + 1;
                self.figures.last_reply_seq = None;
                self.figures.fallback_ticks += 1;
                let detail = self.controller.clone();
                self.event("reconnected", sample.t_s, sample.seq, detail);
                hooks.note(&format!("controller reconnected: {}", self.controller));
                Ok(cmd)
            }
            Err(CosimError::Interrupted) => Err(Halt::Interrupted("interrupted by a signal".into())),
            Err(e) => Err(Halt::Lost(format!(
                "controller lost at t = {} s (sample {}): {why}; no reconnection: {e}",
                sample.t_s, sample.seq
            ))),
        }
    }
}

/// A lockstep reply is missing since `t0`: every `timeout` the controller is checked (gone: a
/// lost peer); past `deadline` a live one is silent.
///
/// A child of ours that is still running is alive: its exit is all there is to watch, and a
/// `waitpid` tells it. Only an external controller (or a child that exited) is looked up by
/// its node, paced ([`link::PeerWatch`]): a lookup lists every iceoryx2 node of the machine,
/// and unpaced, one at every slice of every wait that outlasted `timeout` (1 ms by default),
/// the lookups took most of a loaded machine's time (292 s of a 370 s debug run of 2 000
/// ticks at a load of 23), which made the replies later still. At the deadline the node is
/// looked up whatever the pacing, to say which it is.
pub(super) fn check_silence(
    t0: Instant,
    next_check: &mut Duration,
    timeout: Duration,
    deadline: Duration,
    child: &mut Option<Child>,
    log: &mut OutputLog,
    watch: &mut link::PeerWatch,
) -> Verdict {
    let waited = t0.elapsed();
    if waited < *next_check {
        return Verdict::Wait;
    }
    *next_check = waited + timeout;
    if waited >= deadline {
        return match controller_gone(child, log, watch, None) {
            Some(why) => Verdict::Gone(why),
            None => Verdict::Silent,
        };
    }
    if child.as_mut().is_some_and(|c| c.exited().is_none()) {
        return Verdict::Wait;
    }
    match controller_gone(child, log, watch, Some(timeout)) {
        Some(why) => Verdict::Gone(why),
        None => Verdict::Wait,
    }
}

/// `Some(why)` if the controller's process is gone: our child exited (with its last output),
/// or its node is dead or absent. `paced`: the node is looked up only if the pacing allows
/// ([`link::PeerWatch::paced`] with this interval; not looked up: presumed alive); `None`:
/// looked up now.
pub(super) fn controller_gone(
    child: &mut Option<Child>,
    log: &mut OutputLog,
    watch: &mut link::PeerWatch,
    paced: Option<Duration>,
) -> Option<String> {
    if let Some(c) = child.as_mut() {
        if let Some(status) = c.exited() {
            log.settle();
            return Some(format!("the controller process exited ({status}){}", log.quote(3)));
        }
    }
    let peer = match paced {
        Some(every) => watch.paced(every)?,
        None => watch.lookup(),
    };
    let why = match peer {
        Peer::Alive => return None,
        Peer::Dead => "the controller's node is dead (its process died)",
        Peer::Absent => "the controller's node is gone",
    };
    // A child of ours whose node went is on its way out: its exit status and last words say why.
    if let Some(c) = child.as_mut() {
        let until = Instant::now() + Duration::from_millis(500);
        while Instant::now() < until {
            if let Some(status) = c.exited() {
                log.settle();
                return Some(format!("{why}: the controller process exited ({status}){}", log.quote(3)));
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        return Some(format!("{why}{}", log.quote(3)));
    }
    Some(why.into())
}
