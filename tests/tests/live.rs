//! End-to-end tests of the live view (issue 42 items 2 and 4): `plant run SCENE --live ADDR`
//! serves the run's rows over the Foxglove WebSocket protocol (`foxglove.websocket.v1`).
//!
//! The client here is written from the protocol's document, not from the server's code: a
//! WebSocket (`tungstenite`) asking for the subprotocol, reading the server info and the
//! advertisement (JSON), subscribing, and decoding the binary message-data frames (opcode 1,
//! u32 subscription, u64 time, the message) and the CDR messages (a 4-byte header, then
//! little-endian doubles named by the schema's `float64` lines).
//!
//! What is pinned: the advertised topics and schemas of a planar run; every message a client
//! gets is the `trace.csv` row at its time, field by field, bit for bit, and those rows are
//! the live rate's (200 Hz of the 20 kHz rows: every 100th row), with none missing when the
//! server dropped nothing; clients that connect late, leave, never read, send garbage or a
//! flood of subscriptions leave `trace.csv` and `scene.toml` byte-identical to a run without
//! `--live`, and a garbage sender is told why and closed; a client that never reads keeps the
//! plant's memory bounded (frames dropped, not queued); an address in use or not an address,
//! and a bad `output.live_rate_hz`, are bad input (exit 2) naming it, before the run writes
//! a trace. All ports are the system's choice.

mod common;

use common::{assert_exit, output_within, read_text, scene, stderr, Csv, Proc, TempDir};
use serde_json::Value;
use std::collections::BTreeMap;
use std::io::Write as _;
use std::net::{TcpListener, TcpStream};
use std::path::Path;
use std::time::{Duration, Instant};
use tungstenite::client::IntoClientRequest;
use tungstenite::{Message, WebSocket};

/// A short run in a debug build on a loaded machine: a hang fails.
const LIMIT: Duration = Duration::from_secs(300);

/// `plant run config/paper-10g.toml --out OUT --set … --live ADDR` (not started).
fn live_run(out: &Path, sets: &[&str], addr: &str) -> std::process::Command {
    let mut cmd = common::plant_run(&scene("paper-10g.toml"), out, sets);
    cmd.args(["--quiet", "--live", addr]);
    cmd
}

/// The address in the run's line `plant: live view at ws://ADDR …`.
fn address(p: &mut Proc) -> String {
    let line = p.wait_line("live view at ws://");
    let rest = line.split("ws://").nth(1).expect("ws:// address");
    rest.split_whitespace().next().expect("address").to_string()
}

/// One advertised channel.
#[derive(Debug, Clone)]
struct Channel {
    topic: String,
    encoding: String,
    schema_name: String,
    schema: String,
    schema_encoding: String,
}

/// Per topic, each message's log time (ns) and bytes.
type Received = BTreeMap<String, Vec<(u64, Vec<u8>)>>;

/// A Foxglove-protocol client.
struct Viewer {
    ws: WebSocket<TcpStream>,
    info: Value,
    channels: BTreeMap<u64, Channel>,
    /// Subscription id → channel id.
    subs: BTreeMap<u32, u64>,
}

impl Viewer {
    /// Connects, asking for the subprotocol, and reads the server info and advertisement.
    fn connect(addr: &str) -> Self {
        let stream = TcpStream::connect(addr).unwrap_or_else(|e| panic!("connecting to {addr}: {e}"));
        stream.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
        let mut request = format!("ws://{addr}").into_client_request().unwrap();
        request.headers_mut().insert("Sec-WebSocket-Protocol", "foxglove.websocket.v1".parse().unwrap());
        let (mut ws, response) = tungstenite::client(request, stream).unwrap_or_else(|e| panic!("handshake: {e:?}"));
        assert_eq!(
            response.headers().get("Sec-WebSocket-Protocol").and_then(|v| v.to_str().ok()),
            Some("foxglove.websocket.v1")
        );
        let mut json = || match ws.read().expect("a message from the server") {
            Message::Text(t) => serde_json::from_str::<Value>(&t).expect("JSON"),
            other => panic!("expected a JSON message, got {other:?}"),
        };
        let info = json();
        let advertise = json();
        assert_eq!(info["op"], "serverInfo", "{info}");
        assert_eq!(advertise["op"], "advertise", "{advertise}");
        let text = |c: &Value, k: &str| c[k].as_str().unwrap_or_else(|| panic!("{k} in {c}")).to_string();
        let channels = advertise["channels"]
            .as_array()
            .expect("channels")
            .iter()
            .map(|c| {
                let ch = Channel {
                    topic: text(c, "topic"),
                    encoding: text(c, "encoding"),
                    schema_name: text(c, "schemaName"),
                    schema: text(c, "schema"),
                    schema_encoding: text(c, "schemaEncoding"),
                };
                (c["id"].as_u64().expect("id"), ch)
            })
            .collect();
        Self { ws, info, channels, subs: BTreeMap::new() }
    }

    /// Subscribes to every channel (subscription ids 100, 101, …).
    fn subscribe_all(&mut self) {
        let pairs: Vec<Value> = self
            .channels
            .keys()
            .enumerate()
            .map(|(i, id)| {
                let sub = 100 + u32::try_from(i).unwrap();
                self.subs.insert(sub, *id);
                serde_json::json!({"id": sub, "channelId": id})
            })
            .collect();
        let text = serde_json::json!({"op": "subscribe", "subscriptions": pairs}).to_string();
        self.ws.send(Message::Text(text.into())).expect("subscribing");
    }

    fn send_text(&mut self, text: &str) -> Result<(), tungstenite::Error> {
        self.ws.send(Message::Text(text.to_string().into()))
    }

    /// Reads until the server closes (or `limit` passes): per topic, each message's log time
    /// and bytes; the status messages.
    fn read_all(&mut self, limit: Duration) -> (Received, Vec<Value>) {
        let end = Instant::now() + limit;
        let mut topics = Received::new();
        let mut statuses = Vec::new();
        while Instant::now() < end {
            match self.ws.read() {
                Ok(Message::Binary(b)) => match b[0] {
                    1 => {
                        let sub = u32::from_le_bytes(b[1..5].try_into().unwrap());
                        let ns = u64::from_le_bytes(b[5..13].try_into().unwrap());
                        let channel = self
                            .subs
                            .get(&sub)
                            .unwrap_or_else(|| panic!("a message on subscription {sub}, never made"));
                        let topic = self.channels[channel].topic.clone();
                        topics.entry(topic).or_default().push((ns, b[13..].to_vec()));
                    }
                    2 => assert_eq!(b.len(), 9, "a time frame is 9 bytes"),
                    op => panic!("unknown binary opcode {op}"),
                },
                Ok(Message::Text(t)) => statuses.push(serde_json::from_str(&t).expect("JSON")),
                Ok(Message::Close(_)) => {}
                Ok(_) => {}
                Err(tungstenite::Error::ConnectionClosed | tungstenite::Error::AlreadyClosed) => break,
                Err(e) => panic!("reading from the server: {e}"),
            }
        }
        (topics, statuses)
    }
}

/// The `float64` fields of a schema, in order, with the trace column each names (`None` for the
/// radius, which no column holds).
fn fields(schema: &str) -> Vec<(String, Option<String>)> {
    schema
        .lines()
        .filter_map(|l| l.strip_prefix("float64 "))
        .map(|l| {
            let name = l.split_whitespace().next().unwrap().to_string();
            let column = l.split("trace.csv column ").nth(1).map(|c| c.trim().to_string());
            (name, column)
        })
        .collect()
}

/// The doubles of a CDR message of `n` doubles.
fn doubles(bytes: &[u8], n: usize) -> Vec<f64> {
    assert_eq!(&bytes[..4], &[0, 1, 0, 0], "CDR little-endian header");
    assert_eq!(bytes.len(), 4 + 8 * n, "a message of {n} doubles");
    bytes[4..].chunks(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect()
}

/// A topic of the trace's rows (not `/events`, an orbit or the loop's).
fn is_row_topic(topic: &str) -> bool {
    topic != "/events" && !topic.ends_with("/orbit") && !topic.starts_with("/loop/")
}

/// An orbit message decoded by CDR's rules (written here from the layout of `plant.Orbit`: two
/// doubles, then three `float64[]`, each a u32 count 4-aligned and doubles 8-aligned, counted
/// after the 4-byte header): (t_s, clearance_m, [x_m, orbit_y_m, clearance_y_m]).
fn orbit_message(bytes: &[u8]) -> (f64, f64, Vec<Vec<f64>>) {
    assert_eq!(&bytes[..4], &[0, 1, 0, 0], "CDR little-endian header");
    let body = &bytes[4..];
    let f = |at: usize| f64::from_le_bytes(body[at..at + 8].try_into().unwrap());
    let mut at: usize = 16;
    let mut arrays = Vec::new();
    for _ in 0..3 {
        at = at.next_multiple_of(4);
        let n = u32::from_le_bytes(body[at..at + 4].try_into().unwrap()) as usize;
        at = (at + 4).next_multiple_of(8);
        arrays.push((0..n).map(|k| f(at + 8 * k)).collect());
        at += 8 * n;
    }
    assert_eq!(at, body.len(), "the message's length");
    (f(0), f(8), arrays)
}

/// The orbit messages served: at 50 Hz (every 400th row of 20 kHz), each ending with its own
/// row's `dx_m`, `dy_m` before the 73 points of the clearance circle (radius `clearance_m`).
fn assert_orbit(msgs: &[(u64, Vec<u8>)], trace: &Csv, clearance_m: f64) {
    assert!(msgs.len() >= 3, "{} orbit messages", msgs.len());
    let (t, dx, dy) = (trace.column("t_s"), trace.column("dx_m"), trace.column("dy_m"));
    for (ns, bytes) in msgs {
        let (t_s, clearance, a) = orbit_message(bytes);
        assert_eq!(clearance, clearance_m);
        let row = t.iter().position(|&x| x == t_s).unwrap_or_else(|| panic!("orbit t_s = {t_s} is no row's"));
        assert_eq!(row % 400, 0, "orbit at row {row}");
        assert_eq!(*ns, (t_s * 1e9).round() as u64);
        let last = a[0].len() - 73 - 1;
        assert_eq!((a[0][last], a[1][last]), (dx[row], dy[row]), "orbit at row {row}");
        assert!(a[1][last + 1..].iter().all(|v| v.is_nan()) && a[2][..=last].iter().all(|v| v.is_nan()));
        let r = a[0][last + 1].hypot(a[2][last + 1]);
        assert!((r - clearance_m).abs() < 1e-15, "circle radius {r}");
    }
}

#[test]
fn a_sampled_runs_loop_ticks_are_served_at_the_live_rate() {
    let dir = TempDir::new("live-loop");
    let out = dir.join("run");
    let sets = ["scene.duration_s=0.1", "output.plots=false", "controller.mode=\"sampled\""];
    let mut p = Proc::spawn(&mut live_run(&out, &sets, "127.0.0.1:0"));
    let addr = address(&mut p);
    let mut viewer = Viewer::connect(&addr);
    viewer.subscribe_all();
    let (got, _) = viewer.read_all(LIMIT);
    let (code, log) = p.finish_within(LIMIT);
    assert_eq!(code, Some(0), "{log}");
    let schema = |topic: &str| viewer.channels.values().find(|c| c.topic == topic).unwrap().schema.clone();
    assert!(schema("/loop/sample").contains("float64 sensor_xa_v  # sensor_xa_v (V)"));
    assert!(schema("/loop/command").contains("float64 command_ya_a  # command_ya_a (A)"));
    let trace = Csv::read(&out.join("trace.csv"));
    let (t, ix, iy) = (trace.column("t_s"), trace.column("ix_a"), trace.column("iy_a"));
    // Each message: the header, t_s, seq (u64), then the axes' doubles.
    let numbers = |b: &[u8]| -> (f64, u64, Vec<f64>) {
        assert_eq!(&b[..4], &[0, 1, 0, 0]);
        let d = |at: usize| f64::from_le_bytes(b[at..at + 8].try_into().unwrap());
        let rest = (20..b.len()).step_by(8).map(d).collect();
        (d(4), u64::from_le_bytes(b[12..20].try_into().unwrap()), rest)
    };
    let commands = &got["/loop/command"];
    assert!(commands.len() >= 10, "{} commands", commands.len());
    assert_eq!(got["/loop/sample"].len(), commands.len());
    for (ns, bytes) in commands {
        let (t_s, seq, c) = numbers(bytes);
        // Sent with each 200 Hz row (every 100th): the tick that made that row, the one before.
        let k = seq as usize;
        assert_eq!((k + 1) % 100, 0, "tick {k}");
        assert_eq!(t_s, t[k], "tick {k}'s time");
        assert_eq!(*ns, (t_s * 1e9).round() as u64);
        assert_eq!(c.len(), 2, "a planar run's two axes");
        assert_eq!((c[0].to_bits(), c[1].to_bits()), (ix[k + 1].to_bits(), iy[k + 1].to_bits()), "tick {k}");
    }
}

#[test]
fn compare_realtime_serves_its_realtime_runs_one_after_the_other() {
    common::controller_bin();
    let dir = TempDir::new("live-compare");
    let out = dir.join("out");
    let mut cmd = std::process::Command::new(common::plant_bin());
    cmd.arg("compare").arg(scene("cosim-10g.toml")).args(["--realtime", "--runs", "2", "--out"]).arg(&out);
    cmd.args(["--set", "scene.duration_s=0.04", "--set", "shock[0].start_s=0.01"]);
    // Whole runs whatever this machine's load (the budgets' default would end a late one).
    cmd.args(["--set", "controller.max_miss_fraction=1", "--set", "controller.max_overrun_fraction=1"]);
    cmd.args(["--live", "127.0.0.1:0"]);
    let mut p = Proc::spawn(&mut cmd);
    let addr = address(&mut p);
    let mut viewer = Viewer::connect(&addr);
    viewer.subscribe_all();
    let (got, _) = viewer.read_all(LIMIT);
    let (code, log) = p.finish_within(LIMIT);
    assert_eq!(code, Some(0), "{log}");
    let (clients, frames, _) = served(&log);
    assert_eq!(clients, 1, "{log}");
    assert!(frames > 0, "{log}");
    // A realtime run's loop: its ticks' topics too.
    for topic in ["/plane_a/rotor", "/plane_a/orbit", "/loop/sample", "/loop/command"] {
        assert!(viewer.channels.values().any(|c| c.topic == topic), "{topic} advertised");
    }
    let events: Vec<String> = got["/events"]
        .iter()
        .map(|(_, b)| serde_json::from_slice::<Value>(b).unwrap()["message"].as_str().unwrap().to_string())
        .collect();
    for n in [1, 2] {
        assert!(events.iter().any(|m| *m == format!("realtime run {n} of 2 starts")), "{events:?}");
    }
    assert_eq!(events.iter().filter(|m| m.starts_with("realtime co-simulation: ")).count(), 2, "{events:?}");
    // The second run's rows start again at 0: the times go back once.
    let rotor = viewer.channels.values().find(|c| c.topic == "/plane_a/rotor").unwrap();
    let n = fields(&rotor.schema).len();
    let t: Vec<f64> = got["/plane_a/rotor"].iter().map(|(_, b)| doubles(b, n)[0]).collect();
    assert_eq!(t.windows(2).filter(|w| w[1] < w[0]).count(), 1, "{t:?}");
    assert_eq!(t.last().copied(), Some(0.04), "the last run's last row");
    let csv = read_text(&out.join("realtime.csv"));
    assert_eq!(csv.lines().count(), 4, "{csv}");
}

/// The same double, NaN as NaN.
fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

/// The figures of the run's line `plant: live view: C client(s); F frames made, D not delivered`.
fn served(log: &str) -> (u64, u64, u64) {
    let line = log.lines().find(|l| l.contains("live view: ")).unwrap_or_else(|| panic!("no live view line:\n{log}"));
    let numbers: Vec<u64> = line.split(|c: char| !c.is_ascii_digit()).filter_map(|s| s.parse().ok()).collect();
    (numbers[0], numbers[1], numbers[2])
}

#[test]
fn a_client_gets_the_advertised_topics_and_the_trace_rows_at_the_live_rate() {
    let dir = TempDir::new("live-values");
    let out = dir.join("run");
    let mut p = Proc::spawn(&mut live_run(&out, &["scene.duration_s=0.4", "output.plots=false"], "127.0.0.1:0"));
    let addr = address(&mut p);
    let mut viewer = Viewer::connect(&addr);
    viewer.subscribe_all();
    let (got, _) = viewer.read_all(LIMIT);
    let (code, log) = p.finish_within(LIMIT);
    assert_eq!(code, Some(0), "{log}");
    assert_eq!(viewer.info["metadata"]["scene"], "paper-10g");

    // The planar run's topics, as run.mcap's (docs/guide/live-view.md's table), in the order of
    // their first trace column.
    let topics: Vec<(&str, &str)> =
        viewer.channels.values().map(|c| (c.topic.as_str(), c.schema_name.as_str())).collect();
    assert_eq!(
        topics,
        [
            ("/plane_a/rotor", "plant_msgs/msg/Rotor"),
            ("/plane_a/race", "plant_msgs/msg/Race"),
            ("/rotor/spin", "plant_msgs/msg/Spin"),
            ("/plane_a/contact", "plant_msgs/msg/Contact"),
            ("/plane_a/coils", "plant_msgs/msg/Coils"),
            ("/housing", "plant_msgs/msg/Housing"),
            ("/events", "foxglove.Log"),
            ("/plane_a/orbit", "plant_msgs/msg/Orbit"),
        ]
    );
    for c in viewer.channels.values().filter(|c| c.topic != "/events") {
        assert_eq!((c.encoding.as_str(), c.schema_encoding.as_str()), ("cdr", "ros2msg"), "{}", c.topic);
    }
    let rotor = viewer.channels.values().find(|c| c.topic == "/plane_a/rotor").unwrap();
    assert!(rotor.schema.contains("float64 dx_m  # dx_m (m): trace.csv column dx_m\n"), "{}", rotor.schema);
    let events = viewer.channels.values().find(|c| c.topic == "/events").unwrap();
    assert_eq!((events.encoding.as_str(), events.schema_encoding.as_str()), ("json", "jsonschema"));

    let trace = Csv::read(&out.join("trace.csv"));
    let t = trace.column("t_s");
    // Rows at 20 kHz from t = 0 (row i at i / 20000 s): the live rate's rows are every 100th.
    assert_eq!(t[1], 1.0 / 20000.0, "the scene's output rate is 20 kHz");
    let (_, frames, dropped) = served(&log);
    let mut rows_seen = Vec::new();
    assert_orbit(&got["/plane_a/orbit"], &trace, 1.5e-4);
    for c in viewer.channels.values().filter(|c| is_row_topic(&c.topic)) {
        let msgs = got.get(&c.topic).unwrap_or_else(|| panic!("no message on {}", c.topic));
        assert!(msgs.len() >= 10, "{}: {} messages", c.topic, msgs.len());
        let fields = fields(&c.schema);
        let mut rows = Vec::new();
        for (ns, bytes) in msgs {
            let v = doubles(bytes, fields.len());
            let row =
                t.iter().position(|&x| x == v[0]).unwrap_or_else(|| panic!("{}: t_s = {} is no row's", c.topic, v[0]));
            assert_eq!(*ns, (v[0] * 1e9).round() as u64, "the log time is the row's");
            assert_eq!(row % 100, 0, "{}: row {row} (t = {} s) is not a 200 Hz row", c.topic, v[0]);
            for ((name, column), value) in fields.iter().zip(&v) {
                if let Some(column) = column {
                    let want = trace.column(column)[row];
                    assert!(same(*value, want), "{} {name} at row {row}: {value:e}, trace {want:e}", c.topic);
                }
            }
            rows.push(row);
        }
        if dropped == 0 {
            // Nothing dropped: from the first message on, every 200 Hz row.
            let steps: Vec<usize> = rows.windows(2).map(|w| w[1] - w[0]).collect();
            assert!(steps.iter().all(|&s| s == 100), "{}: steps {steps:?}", c.topic);
            assert_eq!(*rows.last().unwrap(), t.len() - 1, "{}: the last row", c.topic);
        }
        rows_seen.push(rows);
    }
    // Each frame holds every topic's message of one row.
    assert!(rows_seen.windows(2).all(|w| w[0] == w[1]) || dropped > 0);
    assert!(frames > 0);
    let log_msgs: Vec<String> = got
        .get("/events")
        .map(|m| {
            m.iter()
                .map(|(_, b)| serde_json::from_slice::<Value>(b).unwrap()["message"].as_str().unwrap().to_string())
                .collect()
        })
        .unwrap_or_default();
    assert!(log_msgs.iter().any(|m| m == "run completed"), "{log_msgs:?}");
}

#[test]
fn a_soak_serves_its_rows_live() {
    common::controller_bin();
    let dir = TempDir::new("live-soak");
    let programme = common::workspace_root().join("config/soak/soak-short.toml");
    let mut cmd = std::process::Command::new(common::plant_bin());
    cmd.arg("soak").arg(&programme).arg("--out").arg(dir.join("soak")).args(["--quiet", "--live", "127.0.0.1:0"]);
    let mut p = Proc::spawn(&mut cmd);
    let addr = address(&mut p);
    let mut viewer = Viewer::connect(&addr);
    assert_eq!(viewer.info["metadata"]["scene"], "soak-short");
    viewer.subscribe_all();
    let (got, _) = viewer.read_all(LIMIT);
    let (code, log) = p.finish_within(LIMIT);
    assert_eq!(code, Some(0), "{log}");
    let (clients, _, _) = served(&log);
    assert_eq!(clients, 1, "{log}");
    let rotor = viewer.channels.values().find(|c| c.topic == "/plane_a/rotor").unwrap();
    let n = fields(&rotor.schema).len();
    let times: Vec<f64> = got["/plane_a/rotor"].iter().map(|(_, b)| doubles(b, n)[0]).collect();
    assert!(times.len() >= 10, "{} messages", times.len());
    // The soak's rows at 20 kHz, served at 200 Hz: every 100th row, in order.
    for w in times.windows(2) {
        assert!(w[1] > w[0], "times not increasing: {w:?}");
    }
    for t in &times {
        let row = (t * 20000.0).round();
        assert!((row / 20000.0 - t).abs() < 1e-12, "t = {t} s is not a 20 kHz row");
        assert_eq!(row % 100.0, 0.0, "t = {t} s is not a 200 Hz row");
    }
    let events: Vec<String> = got["/events"]
        .iter()
        .map(|(_, b)| serde_json::from_slice::<Value>(b).unwrap()["message"].as_str().unwrap().to_string())
        .collect();
    assert!(events.iter().any(|m| m.starts_with("shock 2 of 2 starts")), "{events:?}");
}

/// The memory of a process now (KiB, `VmRSS`).
fn rss_kib(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    status.lines().find_map(|l| l.strip_prefix("VmRSS:")).and_then(|v| v.split_whitespace().next()?.parse().ok())
}

/// Runs `cmd` to its end, sampling its memory; `during` runs once its live address is known.
/// The exit code, stderr and the largest `VmRSS` seen (KiB).
fn sampled(
    cmd: &mut std::process::Command,
    during: impl FnOnce(&str) -> Vec<Viewer>,
) -> (Option<i32>, String, u64, Vec<Viewer>) {
    let mut p = Proc::spawn(cmd);
    let addr = address(&mut p);
    let viewers = during(&addr);
    let mut peak = 0;
    let end = Instant::now() + LIMIT;
    while p.running() && Instant::now() < end {
        peak = peak.max(rss_kib(p.id()).unwrap_or(0));
        std::thread::sleep(Duration::from_millis(10));
    }
    let (code, log) = p.finish_within(LIMIT);
    (code, log, peak, viewers)
}

#[test]
fn a_client_that_never_reads_keeps_the_memory_bounded_and_the_run_unchanged() {
    let dir = TempDir::new("live-never-reads");
    // Every row live (20 kHz): a run of 1.5 s makes 30 001 frames of 7 messages, some 20 MB
    // if they were all kept for a client that never reads.
    let sets = ["scene.duration_s=1.5", "output.plots=false", "output.live_rate_hz=20000"];
    let (code, log, alone, _) = sampled(&mut live_run(&dir.join("alone"), &sets, "127.0.0.1:0"), |_| Vec::new());
    assert_eq!(code, Some(0), "{log}");
    let (code, log, stuck, viewers) = sampled(&mut live_run(&dir.join("stuck"), &sets, "127.0.0.1:0"), |addr| {
        let mut v = Viewer::connect(addr);
        v.subscribe_all();
        vec![v] // never read: the viewer is kept open, unread, until the run ends
    });
    assert_eq!(code, Some(0), "{log}");
    drop(viewers);
    let (clients, frames, dropped) = served(&log);
    assert_eq!(clients, 1, "{log}");
    eprintln!("peak memory {stuck} KiB with a client that never reads, {alone} KiB without one; {frames} frames, {dropped} not delivered");
    assert!(
        stuck < alone + 8 * 1024,
        "peak memory {stuck} KiB with a client that never reads, {alone} KiB without one"
    );
    assert!(dropped > 0 && frames > 20_000, "frames {frames}, dropped {dropped}: {log}");
    assert_eq!(read_text(&dir.join("alone/trace.csv")), read_text(&dir.join("stuck/trace.csv")));
}

#[test]
fn viewers_that_come_late_leave_or_misbehave_change_nothing_in_the_outputs() {
    let dir = TempDir::new("live-identical");
    let sets = ["scene.duration_s=0.5", "output.plots=false"];
    let plain =
        output_within(common::plant_run(&scene("paper-10g.toml"), &dir.join("plain"), &sets).arg("--quiet"), LIMIT);
    assert_exit(&plain, 0);

    let mut p = Proc::spawn(&mut live_run(&dir.join("live"), &sets, "127.0.0.1:0"));
    let addr = address(&mut p);
    // A client that subscribes, reads a little and leaves without closing.
    let mut leaving = Viewer::connect(&addr);
    leaving.subscribe_all();
    let _ = leaving.ws.read();
    drop(leaving);
    // A client that sends garbage: told why (status, level 2), closed after too much of it
    // (the 17th message that is not a request: plant/src/live/server.rs, MAX_BAD = 16). Exactly
    // 17, so that the server reads all it was sent before it closes (more, unread, would make
    // its close a reset that may lose the statuses before this client reads them).
    let mut garbage = Viewer::connect(&addr);
    for i in 0..17 {
        let sent = if i % 2 == 0 {
            garbage.send_text("this is not JSON")
        } else {
            garbage.ws.send(Message::Binary(vec![7u8; 16].into()))
        };
        sent.expect("the server reads 17 bad messages before it closes");
    }
    let (_, statuses) = garbage.read_all(Duration::from_secs(60));
    assert_eq!(statuses.iter().filter(|s| s["op"] == "status" && s["level"] == 2).count(), 17, "{statuses:?}");
    assert!(
        statuses.iter().any(|s| s["op"] == "status"
            && s["level"] == 2
            && s["message"].as_str().unwrap_or("").starts_with("not JSON")),
        "{statuses:?}"
    );
    // A flood of subscriptions: each channel subscribed once, the rest refused.
    let mut flood = Viewer::connect(&addr);
    for i in 0..2000u32 {
        let text =
            serde_json::json!({"op": "subscribe", "subscriptions": [{"id": i, "channelId": 1 + i % 7}]}).to_string();
        if flood.send_text(&text).is_err() {
            break;
        }
    }
    // Not a WebSocket at all.
    if let Ok(mut raw) = TcpStream::connect(&addr) {
        let _ = raw.write_all(b"GET / HTTP/1.1\r\nHost: x\r\n\r\n\x00\x01garbage");
    }
    // A client that comes late and reads to the end.
    let mut late = Viewer::connect(&addr);
    late.subscribe_all();
    let (got, _) = late.read_all(LIMIT);
    let (code, log) = p.finish_within(LIMIT);
    assert_eq!(code, Some(0), "{log}");
    drop(flood);
    let (clients, _, _) = served(&log);
    assert!(clients >= 4, "{log}");
    assert!(got.get("/plane_a/rotor").is_some_and(|m| !m.is_empty()), "the late client got nothing");
    for file in ["trace.csv", "scene.toml"] {
        assert!(
            read_text(&dir.join("plain").join(file)) == read_text(&dir.join("live").join(file)),
            "{file} differs with viewers attached"
        );
    }
}

#[test]
fn an_address_that_cannot_be_served_and_a_bad_live_rate_are_bad_input() {
    let dir = TempDir::new("live-bad");
    let taken = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap().to_string();
    let out = dir.join("in-use");
    let run = output_within(&mut live_run(&out, &["output.plots=false"], &addr), LIMIT);
    assert_exit(&run, 2);
    let err = stderr(&run);
    assert!(err.contains(&format!("--live {addr}: cannot listen there")), "{err}");
    assert!(!out.join("trace.csv").exists(), "a run started");

    let run =
        output_within(&mut live_run(&dir.join("nonsense"), &["output.plots=false"], "no-such-host-or-port"), LIMIT);
    assert_exit(&run, 2);
    assert!(stderr(&run).contains("--live no-such-host-or-port: not an address to listen on"), "{}", stderr(&run));

    for (value, why) in [("0", "must be a finite number > 0"), ("30000", "must be <= output.rate_hz = 20000 Hz")] {
        let set = format!("output.live_rate_hz={value}");
        let run = output_within(&mut live_run(&dir.join("rate"), &[&set], "127.0.0.1:0"), LIMIT);
        assert_exit(&run, 2);
        let err = stderr(&run);
        assert!(
            err.contains("output.live_rate_hz") && err.contains(value) && err.contains("Hz") && err.contains(why),
            "{err}"
        );
    }
    drop(taken);
}
