//! The run's side of the live view: each row's events, and at the live rate the row's
//! messages on the recording's topics ([`crate::recording::topics`], the same schemas and
//! bytes as `run.mcap`), as frames handed to the [`Server`] without waiting. A
//! [`crate::run::Sink`], fed the same rows as `trace.csv`.

use super::protocol::Channel;
use super::server::{Frame, Served, Server};
use crate::config::Scene;
use crate::recording::events::{Event, Events, LOG_SCHEMA};
use crate::recording::extra::extras;
use crate::recording::extra::ros2_name;
use crate::recording::mcap_file::EVENTS_TOPIC;
pub use crate::recording::orbit::period;
use crate::recording::orbit::{self, Orbits};
use crate::recording::topics::{topics, Columns, Topic};
use crate::summary::Summary;
use crate::trace::Record;
use controller::{RotorSample, ROTOR_AXES};

/// The live view of one run.
pub struct LiveSink {
    server: Server,
    columns: Columns,
    topics: Vec<Topic>,
    events: Events,
    pending: Vec<Event>,
    values: Vec<f64>,
    rate_hz: f64,
    /// The live period of the last row sent (see [`period`]).
    last: Option<f64>,
    /// Each plane's orbit window, sent at [`orbit::RATE_HZ`] (or the live rate if lower).
    orbits: Orbits,
    /// The loop's last tick, sent with the next row that opens a live period (sampled and
    /// co-simulated runs).
    tick: Option<(RotorSample, [f64; ROTOR_AXES])>,
    ticks: bool,
    axes: usize,
}

/// The channels a run of `scene` advertises: each topic of the recording (CDR, its ROS 2
/// message definition), then `/events` (`foxglove.Log`, JSON), then the topics besides the
/// rows' ([`crate::recording::extra`]: each plane's orbit, the loop's sample and command). Ids
/// from 1, in this order.
pub fn channels(scene: &Scene) -> Vec<Channel> {
    let mut out: Vec<Channel> = topics(&Columns::of(scene))
        .into_iter()
        .map(|t| Channel {
            id: 0,
            schema_name: ros2_name(t.schema),
            schema: t.schema_text(),
            topic: t.name,
            encoding: "cdr",
            schema_encoding: "ros2msg",
        })
        .collect();
    out.push(Channel {
        id: 0,
        topic: EVENTS_TOPIC.into(),
        encoding: "json",
        schema_name: "foxglove.Log".into(),
        schema: LOG_SCHEMA.into(),
        schema_encoding: "jsonschema",
    });
    out.extend(extras(scene).into_iter().map(|e| Channel {
        id: 0,
        topic: e.topic,
        encoding: "cdr",
        schema_name: e.schema_name,
        schema: e.schema,
        schema_encoding: "ros2msg",
    }));
    for (i, c) in out.iter_mut().enumerate() {
        c.id = u32::try_from(i + 1).unwrap_or(u32::MAX);
    }
    out
}

/// A simulated time (s) as nanoseconds (0 for a negative or non-finite time).
fn nanoseconds(t_s: f64) -> u64 {
    // `as` saturates: NaN and negative times give 0.
    (t_s * 1e9).round() as u64
}

impl LiveSink {
    /// The live view of a run of `scene` through `server` (started with [`channels`]).
    pub fn new(server: Server, scene: &Scene) -> Self {
        let columns = Columns::of(scene);
        Self {
            server,
            columns,
            topics: topics(&columns),
            events: Events::new(scene),
            pending: Vec::new(),
            values: Vec::new(),
            rate_hz: scene.live_rate_hz,
            last: None,
            orbits: Orbits::new(scene, orbit::RATE_HZ.min(scene.live_rate_hz)),
            tick: None,
            ticks: extras(scene).len() > scene.planes(),
            axes: 2 * scene.planes(),
        }
    }

    /// One row: its events, and its messages if it opens a live period. Nothing is made while
    /// no client is connected.
    pub fn push(&mut self, r: &Record) {
        self.events.row(r, &mut self.pending);
        let orbit_due = self.orbits.row(r);
        let t = r.t_s();
        let k = period(t, self.rate_hz);
        let due = self.last.is_none_or(|last| k > last);
        if due {
            self.last = Some(k);
        }
        if !self.server.hub().has_clients() {
            self.pending.clear();
            return;
        }
        if !due && !orbit_due && self.pending.is_empty() {
            return;
        }
        let ns = nanoseconds(t);
        let mut frame = Frame { ns, messages: Vec::new() };
        if due {
            self.columns.values(r, &mut self.values);
            for (i, topic) in self.topics.iter().enumerate() {
                let mut bytes = Vec::with_capacity(8 * (topic.fields.len() + 2) + 4);
                topic.message(&self.values, &mut bytes);
                frame.messages.push((i, ns, bytes));
            }
        }
        let events = self.topics.len();
        let planes = self.orbits.topics().count();
        if orbit_due {
            for i in 0..planes {
                let mut bytes = Vec::new();
                self.orbits.message(i, &mut bytes);
                frame.messages.push((events + 1 + i, ns, bytes));
            }
        }
        if let Some((sample, command)) = if due { self.tick.take() } else { None } {
            let (mut a, mut b) = (Vec::new(), Vec::new());
            crate::recording::ticks::messages(&sample, &command, self.axes, &mut a, &mut b);
            let at = nanoseconds(sample.t_s);
            frame.messages.push((events + 1 + planes, at, a));
            frame.messages.push((events + 2 + planes, at, b));
        }
        self.push_events(&mut frame, events);
        self.server.hub().offer(frame);
    }

    /// One tick of the loop: kept, and sent with the next row that opens a live period.
    pub fn tick(&mut self, sample: &RotorSample, command: &[f64; ROTOR_AXES]) {
        if self.ticks {
            self.tick = Some((*sample, *command));
        }
    }

    /// Whether the live view has the loop's topics (a sampled or co-simulated run).
    pub fn wants_ticks(&self) -> bool {
        self.ticks
    }

    fn push_events(&mut self, frame: &mut Frame, channel: usize) {
        for e in self.pending.drain(..) {
            let ns = nanoseconds(e.t_s);
            frame.messages.push((channel, ns, e.to_log_json(ns).into_bytes()));
        }
    }

    /// Sends the run's end (with a `plant run`'s summary: its status, motion mode, a
    /// co-simulation's figures) and stops the server: the clients get what was queued for
    /// them, then are closed.
    pub fn finish(self, summary: Option<&Summary>) -> Served {
        self.end_run(summary).stop()
    }

    /// Sends the run's end, as [`LiveSink::finish`] does, and hands the server back still
    /// serving, for the next of several runs served in turn (`plant compare --realtime
    /// --live`): a new [`LiveSink::new`] of it starts the next run's rows, whose times start again.
    pub fn end_run(mut self, summary: Option<&Summary>) -> Server {
        if let Some(summary) = summary {
            self.pending.extend(self.events.end(summary));
        }
        let mut frame = Frame { ns: nanoseconds(self.pending.first().map_or(0.0, |e| e.t_s)), messages: Vec::new() };
        let events = self.topics.len();
        self.push_events(&mut frame, events);
        if self.server.hub().has_clients() {
            self.server.hub().offer(frame);
        }
        self.server
    }

    /// Logs a line on `/events` at simulated time `t_s` (`realtime run 2 of 3 starts`), sent
    /// with the next frame.
    pub fn note(&mut self, t_s: f64, message: String) {
        self.pending.push(Event { t_s, level: crate::recording::events::Level::Info, message });
    }
}

impl crate::run::Sink for LiveSink {
    fn sample(&mut self, record: &Record) {
        self.push(record);
    }

    fn tick(&mut self, sample: &RotorSample, command: &[f64; ROTOR_AXES]) {
        LiveSink::tick(self, sample, command);
    }

    fn wants_ticks(&self) -> bool {
        self.ticks
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_row_opens_a_period_at_each_multiple_of_the_live_interval() {
        // Rows at 20 kHz, 200 Hz live: rows 0, 100, 200, … open a period (t = i / 20000 s,
        // i.e. t·200 = i/100, whose floor steps at each multiple of 100).
        let opened: Vec<usize> = (0..=1000)
            .filter(|&i| i == 0 || period(i as f64 / 20000.0, 200.0) > period((i - 1) as f64 / 20000.0, 200.0))
            .collect();
        assert_eq!(opened, (0..=10).map(|k| 100 * k).collect::<Vec<_>>());
        // 0.3 · 10 = 2.9999999999999996 in doubles: still the period of 3.
        assert_eq!(period(0.3, 10.0), 3.0);
    }
}
