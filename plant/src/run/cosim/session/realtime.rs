//! A realtime tick: paced by the wall clock, it sends its frame and applies the reply to the
//! tick before; a reply that did not come is a deadline miss.

use super::*;

impl Session {
    pub(super) fn realtime(&mut self, sample: &RotorSample, hooks: &mut dyn Hooks) -> Result<[f64; ROTOR_AXES], Halt> {
        let k = sample.seq;
        let start = *self.start.get_or_insert_with(Instant::now);
        let deadline = start + Duration::from_secs_f64(k as f64 * self.period);
        pace_until(deadline, self.settings.pacing);
        let woke = Instant::now();
        self.woke = Some(woke);
        self.figures.ticks += 1;
        if woke > deadline + Duration::from_secs_f64(self.period) {
            self.figures.overruns += 1;
            if let Some(why) = self.overrun_budget_exceeded(MISS_BUDGET_MIN_DUE) {
                return Err(Halt::OverrunBudget(why));
            }
        }
        if hooks.cancelled() {
            return Err(Halt::Interrupted("interrupted by a signal".into()));
        }

        // Replies that came in since the last tick.
        let session = self.hello.session;
        let mut fresh: Option<CommandFrame> = None;
        loop {
            let reply = match self.frames.try_receive() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => return self.on_lost(sample, format!("IPC failure: {e}"), hooks),
            };
            if reply.token != self.hello.token {
                self.figures.foreign += 1;
                self.silent.foreign += 1;
                continue;
            }
            if reply.session != session || !self.connected {
                if self.connected {
                    self.silent.note_session(reply.session);
                }
                continue;
            }
            if reply.status & CommandFrame::STOPPING != 0 {
                return self.on_lost(sample, STOPPED_BY_SIGNAL.into(), hooks);
            }
            self.figures.received += 1;
            self.last_heard = Instant::now();
            self.silent = Seen::default();
            self.next_check = Duration::from_secs_f64(self.settings.reply_timeout);
            self.figures.note_reply_seq(reply.seq);
            if reply.seq + (RING as u64) > k && reply.seq < k {
                self.figures.latency.record(reply.sent_ns.saturating_sub(self.sent_ns[reply.seq as usize % RING]));
            }
            if reply.seq + 1 == k {
                fresh = Some(reply);
            } else {
                self.figures.stale += 1;
            }
        }

        let cmd = if !self.connected {
            self.fallback_tick(sample, hooks)?
        } else if k == 0 || k <= self.first_seq {
            self.last_cmd // nothing due yet: the bias (or the fallback after a reconnection)
        } else {
            self.figures.due += 1;
            match fresh {
                Some(reply) => {
                    self.figures.misses.record(false);
                    self.accept(&reply)
                }
                None => match self.missed(sample, hooks) {
                    Some(ended) => return ended,
                    None => self.last_cmd,
                },
            }
        };

        if self.connected {
            let frame = self.frame(sample);
            self.sent_ns[k as usize % RING] = frame.sent_ns;
            if let Err(e) = self.frames.send(frame) {
                return self.on_lost(sample, format!("IPC failure: {e}"), hooks);
            }
            self.figures.sent += 1;
        }
        Ok(cmd)
    }

    /// A tick while the controller is lost: the fallback command, and a reconnection if one
    /// has come (or the run ends when none came in time, or the miss budget is spent).
    fn fallback_tick(&mut self, sample: &RotorSample, hooks: &mut dyn Hooks) -> Result<[f64; ROTOR_AXES], Halt> {
        let k = sample.seq;
        self.figures.fallback_ticks += 1;
        if let Some(why) = self.miss_budget_exceeded(MISS_BUDGET_MIN_DUE) {
            return Err(Halt::MissBudget(why));
        }
        match self.poll_handshake(hooks) {
            Some(Ok(())) => {
                self.first_seq = k;
                self.figures.last_reply_seq = None;
                let detail = self.controller.clone();
                self.event("reconnected", sample.t_s, k, detail);
                hooks.note(&format!("controller reconnected: {}", self.controller));
            }
            Some(Err(e)) => return Err(Halt::Lost(format!("no reconnection: {e}"))),
            None => {
                let waited = self.lost_since.map_or(0.0, |t| t.elapsed().as_secs_f64());
                if waited > self.settings.reconnect_timeout {
                    return Err(Halt::Lost(format!(
                        "controller lost; none reconnected within {} s",
                        self.settings.reconnect_timeout
                    )));
                }
            }
        }
        Ok(self.last_cmd)
    }

    /// A tick whose reply did not come: a deadline miss, the last command held (`None`: the
    /// tick goes on), or the tick's end (a controller that exited or has been silent too long
    /// is lost; the miss budget spent).
    fn missed(&mut self, sample: &RotorSample, hooks: &mut dyn Hooks) -> Option<Result<[f64; ROTOR_AXES], Halt>> {
        self.figures.misses.record(true);
        if let Some(why) = self.miss_budget_exceeded(MISS_BUDGET_MIN_DUE) {
            return Some(Err(Halt::MissBudget(why)));
        }
        if self.last_heard.elapsed() >= self.next_check {
            self.next_check += Duration::from_secs_f64(self.settings.reply_timeout);
            // A child of ours still running is alive: its exit is all there is to
            // watch, and a `waitpid` tells it. Listing the run's nodes reads the
            // file system (/tmp/iceoryx2) inside the tick, where a slow disk turns
            // a burst of misses into a longer one; an external controller has no
            // other sign of life.
            let running = self.child.as_mut().is_some_and(|c| c.exited().is_none());
            if !running {
                let every = Some(Duration::from_secs_f64(self.settings.reply_timeout));
                if let Some(why) = controller_gone(&mut self.child, &mut self.log, &mut self.watch, every) {
                    return Some(self.on_lost(sample, why, hooks));
                }
            }
            // Alive but silent (stopped, hung, answering another session) for
            // controller.lockstep_timeout_ms: lost, as in lockstep.
            if self.last_heard.elapsed().as_secs_f64() >= self.settings.lockstep_timeout {
                let seen = std::mem::take(&mut self.silent);
                return Some(self.on_silent(sample, &seen, hooks));
            }
        }
        None
    }
}

/// Waits for a wall-clock instant. `spin`: sleeps while it is far, then spins.
/// `sleep`: sleeps to it (an absolute `CLOCK_MONOTONIC` sleep, which a timer
/// ends; under `SCHED_FIFO` without timer slack), leaving the core to others.
pub(super) fn pace_until(deadline: Instant, pacing: Pacing) {
    if pacing == Pacing::Sleep {
        let now = Instant::now();
        if now < deadline {
            link::sleep_until_ns(wire::monotonic_ns() + (deadline - now).as_nanos() as u64);
        }
        return;
    }
    const SPIN: Duration = Duration::from_micros(200);
    loop {
        let now = Instant::now();
        if now >= deadline {
            return;
        }
        let left = deadline - now;
        if left > SPIN {
            std::thread::sleep(left - SPIN);
        } else {
            std::hint::spin_loop();
        }
    }
}
