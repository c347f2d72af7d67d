//! A tick's command: in lockstep the sensor frame out and the reply to it waited for
//! (spinning, then blocking in slices that watch the controller); in realtime
//! [`super::realtime`]'s.

use super::*;

impl Session {
    /// The command for sample `k` to push into the delay line: the reply to
    /// `k` (lockstep) or to `k − 1` (realtime), or a fallback.
    pub fn command(&mut self, sample: &RotorSample, hooks: &mut dyn Hooks) -> Result<[f64; ROTOR_AXES], Halt> {
        if let Some(w) = &self.watchdog {
            w.tick();
            if let Some(pid) = w.take_demoted() {
                let why = format!(
                    "the controller (pid {pid}) held the shared core for {} s without letting the plant tick: put \
                     under the normal scheduler; a controller on the plant's core must block between frames",
                    crate::cosim::watchdog::STALL.as_secs_f64()
                );
                self.event("controller_demoted", sample.t_s, sample.seq, why.clone());
                hooks.note(&format!("warning: {why}"));
                self.scheduling.controller = controller::link::policy(pid).to_string();
                self.scheduling.controller_priority = None;
            }
        }
        match self.mode {
            ControlMode::Realtime => self.realtime(sample, hooks),
            _ => self.lockstep(sample, hooks),
        }
    }

    pub(in crate::run::cosim) fn lockstep(
        &mut self,
        sample: &RotorSample,
        hooks: &mut dyn Hooks,
    ) -> Result<[f64; ROTOR_AXES], Halt> {
        let k = sample.seq;
        let frame = self.frame(sample);
        let t0 = Instant::now();
        if let Err(e) = self.frames.send(frame) {
            return self.on_lost(sample, format!("IPC failure: {e}"), hooks);
        }
        self.figures.sent += 1;
        let session = self.hello.session;
        let timeout = Duration::from_secs_f64(self.settings.reply_timeout);
        let deadline = Duration::from_secs_f64(self.settings.lockstep_timeout);
        let mut next_check = timeout;
        let mut verdict = Verdict::Wait;
        let mut seen = Seen::default();
        loop {
            let (child, log, watch) = (&mut self.child, &mut self.log, &mut self.watch);
            let waited = self.frames.wait(SLICE, || {
                if hooks.cancelled() {
                    return false;
                }
                verdict = check_silence(t0, &mut next_check, timeout, deadline, child, log, watch);
                matches!(verdict, Verdict::Wait)
            });
            let reply = match waited {
                Ok(Some(r)) => r,
                Ok(None) => match std::mem::replace(&mut verdict, Verdict::Wait) {
                    Verdict::Gone(why) => return self.on_lost(sample, why, hooks),
                    Verdict::Silent => return self.on_silent(sample, &seen, hooks),
                    Verdict::Wait => return Err(Halt::Interrupted("interrupted by a signal".into())),
                },
                Err(e) => return self.on_lost(sample, format!("IPC failure: {e}"), hooks),
            };
            // Token first: another run's frame (same run id), a stale or a foreign process's.
            let applied = if reply.token != self.hello.token {
                self.figures.foreign += 1;
                seen.foreign += 1;
                false
            } else if reply.session != session {
                seen.note_session(reply.session);
                false
            } else if reply.status & CommandFrame::STOPPING != 0 {
                return self.on_lost(sample, STOPPED_BY_SIGNAL.into(), hooks);
            } else {
                self.figures.received += 1;
                self.figures.note_reply_seq(reply.seq);
                if reply.seq != k {
                    self.figures.stale += 1;
                    seen.other_seq += 1;
                }
                reply.seq == k
            };
            if !applied {
                // A stream of frames that are not the reply keeps the wait from blocking, so
                // the deadline is checked here too. Only the deadline: the node lookup costs
                // milliseconds, and a plant that reads slower than another publisher sends
                // would never reach the controller's reply (a subscriber takes from its first
                // publisher with data first).
                if t0.elapsed() < deadline {
                    continue;
                }
                return match controller_gone(&mut self.child, &mut self.log, &mut self.watch, None) {
                    Some(why) => self.on_lost(sample, why, hooks),
                    None => self.on_silent(sample, &seen, hooks),
                };
            }
            self.figures.round_trip.record(t0.elapsed().as_nanos() as u64);
            self.figures.latency.record(reply.sent_ns.saturating_sub(frame.sent_ns));
            self.warn_if_never_woken(hooks);
            return Ok(self.accept(&reply));
        }
    }

    /// Warns once when the controller never serves the plant's wake requests: every reply
    /// then waits for a timed wake-up of the plant (see docs/wire-protocol.md).
    pub(super) fn warn_if_never_woken(&mut self, hooks: &mut dyn Hooks) {
        if !self.wake_warned && self.frames.woken() == 0 && self.frames.unwoken() >= UNWOKEN_WARNING {
            self.wake_warned = true;
            hooks.note(&format!(
                "warning: the controller never wakes the plant: {} replies were found only after a timed wait ran out. \
                 A controller must serve the plant's wake requests (`command/wake`: notify the `command` event \
                 service after publishing a reply when a wake request is pending, docs/wire-protocol.md); \
                 the run goes on, much slower",
                self.frames.unwoken()
            ));
        }
    }
}
