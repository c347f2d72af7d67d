//! `run.mcap`: a run's rows as messages on the topics of [`super::topics`] (CDR, with ROS 2
//! message definitions as schemas), its events as `foxglove.Log` on `/events`
//! ([`super::events`]) and the scene as metadata, in chunks (uncompressed, or lz4 with `[output]
//! mcap_compression = "lz4"`), for Foxglove, Lichtblick, PlotJuggler and the `mcap`
//! readers. A [`crate::run::Sink`], fed the same rows as `trace.csv`.
//!
//! The file is created new in the run's folder ([`crate::outfile::create`]: an entry at the
//! name, a link included, is unlinked, never followed) and streamed as the rows come; the
//! writer's summary and footer go at the end. A write that fails (a full disk) stops the
//! recording, not the run: the error is kept and reported when the run's own outputs are
//! written.

use super::events::{Event, Events, LOG_SCHEMA};
use super::extra::{extras, ros2_name};
use super::orbit::{self, Orbits};
use super::topics::{topics, Columns, Topic};
use crate::config::Scene;
use crate::summary::Summary;
use crate::trace::Record;
use anyhow::Context;
use controller::{RotorSample, ROTOR_AXES};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// The recording's file name in a run's folder.
pub const FILE: &str = "run.mcap";

/// The topic of the run's events.
pub const EVENTS_TOPIC: &str = "/events";

type Writer = mcap::Writer<BufWriter<File>>;

/// The recording of one run, as its rows come.
pub struct McapSink {
    path: PathBuf,
    writer: Option<Writer>,
    columns: Columns,
    topics: Vec<(Topic, u16)>,
    events_channel: u16,
    events: Events,
    pending: Vec<Event>,
    values: Vec<f64>,
    bytes: Vec<u8>,
    sequence: u32,
    error: Option<anyhow::Error>,
    orbits: Orbits,
    /// Each plane's orbit channel, then the loop's sample and command channels (if sampled).
    extra_channels: Vec<u16>,
    axes: usize,
    tick_bytes: Vec<u8>,
}

/// A simulated time (s) as an MCAP time (ns); a time before 0 (none is) or not finite is 0.
fn nanoseconds(t_s: f64) -> u64 {
    // `as` saturates: NaN and negative times give 0.
    (t_s * 1e9).round() as u64
}

impl McapSink {
    /// Creates `dir/run.mcap` for a run of `scene`: the topics' schemas and channels and the
    /// scene's metadata (`scene`: its name and the resolved scene file).
    pub fn create(dir: &Path, scene: &Scene) -> anyhow::Result<Self> {
        Self::create_at(&dir.join(FILE), scene)
    }

    /// [`McapSink::create`] at `path` (`soak.mcap` of a soak).
    pub fn create_at(path: &Path, scene: &Scene) -> anyhow::Result<Self> {
        let made = Self::open(path, scene);
        made.with_context(|| format!("creating {}", path.display()))
    }

    fn open(path: &Path, scene: &Scene) -> anyhow::Result<Self> {
        let file = crate::outfile::create(path)?;
        // Not compressed by default: lz4 through the `mcap` writer (many small writes per
        // message, each with the lz4 frame's checksum) was about half the recording's CPU time.
        let compression = match scene.mcap_compression {
            crate::config::McapCompression::None => None,
            crate::config::McapCompression::Lz4 => Some(mcap::Compression::Lz4),
        };
        let options = mcap::WriteOptions::new()
            .compression(compression)
            .profile("")
            .library(concat!("plant ", env!("CARGO_PKG_VERSION")));
        let mut writer = options.create(BufWriter::with_capacity(1 << 20, file))?;
        // The metadata first: writing it ends the open chunk, and a chunk of schemas and
        // channels alone has no message index, which Lichtblick's and Foxglove's reader
        // (`@mcap/core`) refuses ("Chunks without message indexes are not currently supported").
        let toml = scene.to_toml()?;
        let metadata = BTreeMap::from([("name".to_string(), scene.name.clone()), ("scene.toml".to_string(), toml)]);
        writer.write_metadata(&mcap::records::Metadata { name: "scene".into(), metadata })?;
        let columns = Columns::of(scene);
        let none = BTreeMap::new();
        let mut channels = Vec::new();
        for topic in topics(&columns) {
            let schema = writer.add_schema(&ros2_name(topic.schema), "ros2msg", topic.schema_text().as_bytes())?;
            let channel = writer.add_channel(schema, &topic.name, "cdr", &none)?;
            channels.push((topic, channel));
        }
        let log = writer.add_schema("foxglove.Log", "jsonschema", LOG_SCHEMA.as_bytes())?;
        let events_channel = writer.add_channel(log, EVENTS_TOPIC, "json", &none)?;
        let mut extra_channels = Vec::new();
        for extra in extras(scene) {
            let schema = writer.add_schema(&extra.schema_name, "ros2msg", extra.schema.as_bytes())?;
            extra_channels.push(writer.add_channel(schema, &extra.topic, "cdr", &none)?);
        }
        Ok(Self {
            path: path.to_path_buf(),
            writer: Some(writer),
            columns,
            topics: channels,
            events_channel,
            events: Events::new(scene),
            pending: Vec::new(),
            values: Vec::new(),
            bytes: Vec::with_capacity(512),
            sequence: 0,
            error: None,
            orbits: Orbits::new(scene, orbit::RATE_HZ),
            extra_channels,
            axes: 2 * scene.planes(),
            tick_bytes: Vec::with_capacity(128),
        })
    }

    /// One row: its message on each topic, and the events it passes.
    pub fn push(&mut self, r: &Record) {
        if self.error.is_some() {
            return;
        }
        self.columns.values(r, &mut self.values);
        let ns = nanoseconds(r.a.t_s);
        self.events.row(r, &mut self.pending);
        let Some(writer) = self.writer.as_mut() else { return };
        let mut written = Ok(());
        for (topic, channel) in &self.topics {
            topic.message(&self.values, &mut self.bytes);
            written = write(writer, *channel, &mut self.sequence, ns, &self.bytes);
            if written.is_err() {
                break;
            }
        }
        if self.orbits.row(r) {
            let planes = self.orbits.topics().count();
            for (i, channel) in self.extra_channels.iter().take(planes).enumerate() {
                if written.is_ok() {
                    self.orbits.message(i, &mut self.bytes);
                    written = write(writer, *channel, &mut self.sequence, ns, &self.bytes);
                }
            }
        }
        for event in self.pending.drain(..) {
            if written.is_ok() {
                let ns = nanoseconds(event.t_s);
                written = write(writer, self.events_channel, &mut self.sequence, ns, event.to_log_json(ns).as_bytes());
            }
        }
        if let Err(e) = written {
            self.error = Some(e.into());
        }
    }

    /// Logs the run's end (with a `plant run`'s summary: its status, motion mode, a
    /// co-simulation's figures) and writes the file's summary and footer. The first error of
    /// the recording, if any, naming the file.
    pub fn finish(mut self, summary: Option<&Summary>) -> anyhow::Result<()> {
        let path = self.path.clone();
        self.close(summary).with_context(|| format!("writing {}", path.display()))
    }

    fn close(&mut self, summary: Option<&Summary>) -> anyhow::Result<()> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        let Some(mut writer) = self.writer.take() else { return Ok(()) };
        for event in summary.map(|s| self.events.end(s)).unwrap_or_default() {
            let ns = nanoseconds(event.t_s);
            write(&mut writer, self.events_channel, &mut self.sequence, ns, event.to_log_json(ns).as_bytes())?;
        }
        writer.finish()?;
        let mut file = writer.into_inner();
        std::io::Write::flush(&mut file)?;
        // Not synced to disk: a streamed output, as `trace.csv` is.
        file.into_inner().map_err(|e| e.into_error())?;
        Ok(())
    }
}

fn write(writer: &mut Writer, channel: u16, sequence: &mut u32, ns: u64, data: &[u8]) -> mcap::McapResult<()> {
    *sequence = sequence.wrapping_add(1);
    let header =
        mcap::records::MessageHeader { channel_id: channel, sequence: *sequence, log_time: ns, publish_time: ns };
    writer.write_to_known_channel(&header, data)
}

impl McapSink {
    /// One tick of the loop: its messages on `/loop/sample` and `/loop/command`.
    pub fn tick(&mut self, sample: &RotorSample, command: &[f64; ROTOR_AXES]) {
        let planes = self.orbits.topics().count();
        let (Some(&sample_channel), Some(&command_channel)) =
            (self.extra_channels.get(planes), self.extra_channels.get(planes + 1))
        else {
            return;
        };
        let Some(writer) = self.writer.as_mut().filter(|_| self.error.is_none()) else { return };
        super::ticks::messages(sample, command, self.axes, &mut self.bytes, &mut self.tick_bytes);
        let ns = nanoseconds(sample.t_s);
        let mut written = write(writer, sample_channel, &mut self.sequence, ns, &self.bytes);
        if written.is_ok() {
            written = write(writer, command_channel, &mut self.sequence, ns, &self.tick_bytes);
        }
        if let Err(e) = written {
            self.error = Some(e.into());
        }
    }

    /// Whether the recording has the loop's topics (a sampled or co-simulated run).
    pub fn wants_ticks(&self) -> bool {
        self.extra_channels.len() > self.orbits.topics().count()
    }
}

impl crate::run::Sink for McapSink {
    fn sample(&mut self, record: &Record) {
        self.push(record);
    }

    fn tick(&mut self, sample: &RotorSample, command: &[f64; ROTOR_AXES]) {
        McapSink::tick(self, sample, command);
    }

    fn wants_ticks(&self) -> bool {
        McapSink::wants_ticks(self)
    }
}
