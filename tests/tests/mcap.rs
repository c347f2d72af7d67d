//! End-to-end tests of `run.mcap` (issue 42 item 1): `plant run --mcap` records the run's rows
//! as CDR messages per topic (ROS 2 message definitions as schemas), its events as `foxglove.Log` and the scene as metadata.
//!
//! What is pinned: the file, read back by the `mcap` Python reader (an outside implementation
//! of the format, in a venv under `target/`, `mcap_venv`), holds one message per row on each
//! topic, every field bit for bit the `trace.csv` column it names (planar, two-plane and
//! flexible scenes; the radius as the hypot of the row's x and y, within 1 ulp, computed here),
//! the schemas give each field's unit and column, the scene's metadata is `scene.toml`,
//! and the events hold the shock's start and the run's status; a run without the flag writes
//! no recording and the same `scene.toml` as before; a link at `run.mcap` is replaced, not
//! followed; a bad value of the key exits 2 naming it.

mod common;

use common::{assert_exit, output_within, read_text, scene, stderr, Csv, TempDir, SHORT};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::Duration;

/// One short run in a debug build on a loaded machine: a hang fails.
const LIMIT: Duration = Duration::from_secs(300);

/// The `mcap` Python reader's release the test installs (and the lz4 it reads chunks with).
const MCAP_PY: &str = "1.6.0";
const LZ4_PY: &str = "4.4.5";

/// `target/mcap-venv` with the `mcap` reader: made if absent or stale, under a file lock.
fn mcap_venv() -> &'static Path {
    static VENV: OnceLock<PathBuf> = OnceLock::new();
    VENV.get_or_init(|| {
        let target = Path::new(env!("CARGO_TARGET_TMPDIR")).parent().expect("CARGO_TARGET_TMPDIR is target/tmp");
        let dir = target.join("mcap-venv");
        let stamp = format!("mcap {MCAP_PY}\nlz4 {LZ4_PY}\n");
        let lock = std::fs::File::create(target.join("mcap-venv.lock")).expect("venv lock file");
        lock.lock().expect("locking the venv");
        let stamp_file = dir.join("mcap.stamp");
        if dir.join("bin/python").exists() && std::fs::read_to_string(&stamp_file).ok().as_deref() == Some(&stamp) {
            return dir;
        }
        let _ = std::fs::remove_dir_all(&dir);
        let venv = output_within(Command::new("python3").arg("-m").arg("venv").arg(&dir), Duration::from_secs(120));
        assert_exit(&venv, 0);
        let install = output_within(
            Command::new(dir.join("bin/python"))
                .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"])
                .arg(format!("mcap=={MCAP_PY}"))
                .arg(format!("lz4=={LZ4_PY}")),
            Duration::from_secs(600),
        );
        assert_exit(&install, 0);
        std::fs::write(&stamp_file, stamp).expect("venv stamp");
        dir
    })
}

/// Reads a recording with the `mcap` Python package and prints it as JSON: per topic its
/// schema (name, encoding, text) and its messages' fields as the doubles' bit patterns (signed
/// 64-bit integers), decoded here from the schema's `float64` lines and CDR's layout (a 4-byte
/// little-endian header, then the 8-byte doubles); the metadata; the events' messages.
const READER: &str = r#"
import json, struct, sys
from mcap.reader import make_reader
out = {"topics": {}, "metadata": {}, "events": [], "log_times_ok": True, "headers_ok": True}
def cdr(text, data):
    # CDR, little-endian, by its rules: each primitive aligned to its size counted from the end
    # of the 4-byte encapsulation header; a sequence is a uint32 count, then its items. Doubles
    # are kept as their bits (signed 64-bit integers).
    assert data[:4] == b"\x00\x01\x00\x00", data[:4]
    body, at, fields = data[4:], 0, {}
    def take(fmt, size):
        nonlocal at
        at += (-at) % size
        (v,) = struct.unpack_from(fmt, body, at)
        at += size
        return v
    for line in text.splitlines():
        if not line or line.startswith('#'):
            continue
        kind, name = line.split()[:2]
        if kind == "float64":
            fields[name] = take("<q", 8)
        elif kind == "uint64":
            fields[name] = take("<Q", 8)
        elif kind == "float64[]":
            fields[name] = [take("<q", 8) for _ in range(take("<I", 4))]
        else:
            raise ValueError(line)
    assert at == len(body), (at, len(body))
    return fields
with open(sys.argv[1], "rb") as f:
    reader = make_reader(f)
    for m in reader.iter_metadata():
        out["metadata"][m.name] = dict(m.metadata)
    out["compressions"] = sorted({c.compression for c in reader.get_summary().chunk_indexes})
    out["chunks_without_message_index"] = sum(1 for c in reader.get_summary().chunk_indexes if c.message_index_length == 0)
    for schema, channel, message in reader.iter_messages(log_time_order=False):
        if channel.topic == "/events":
            data = json.loads(message.data)
            out["events"].append([message.log_time, data["level"], data["message"]])
            continue
        if channel.topic.endswith("/orbit") or channel.topic.startswith("/loop/"):
            text = schema.data.decode()
            t = out.setdefault("extra", {}).setdefault(channel.topic, {
                "schema": schema.name, "encoding": schema.encoding, "message_encoding": channel.message_encoding,
                "schema_text": text, "log_times": [], "fields": {}})
            t["log_times"].append(message.log_time)
            for name, value in cdr(text, bytes(message.data)).items():
                t["fields"].setdefault(name, []).append(value)
            continue
        text = schema.data.decode()
        names = [l.split()[1] for l in text.splitlines() if l.startswith("float64 ")]
        t = out["topics"].setdefault(channel.topic, {
            "schema": schema.name, "encoding": schema.encoding, "message_encoding": channel.message_encoding,
            "schema_text": text, "fields": {n: [] for n in names}})
        data = bytes(message.data)
        if data[:4] != b"\x00\x01\x00\x00" or len(data) != 4 + 8 * len(names):
            out["headers_ok"] = False
            continue
        values = struct.unpack("<%dq" % len(names), data[4:])
        if message.log_time != round(struct.unpack("<d", data[4:12])[0] * 1e9):
            out["log_times_ok"] = False
        for n, v in zip(names, values):
            t["fields"][n].append(v)
print(json.dumps(out))
"#;

/// The recording of `dir/run.mcap` as the Python reader sees it.
fn read_back(dir: &Path) -> serde_json::Value {
    read_file(&dir.join("run.mcap"))
}

/// The recording of `file` as the Python reader sees it.
fn read_file(file: &Path) -> serde_json::Value {
    let python = mcap_venv().join("bin/python");
    let out = output_within(Command::new(python).arg("-c").arg(READER).arg(file), Duration::from_secs(300));
    assert_exit(&out, 0);
    serde_json::from_slice(&out.stdout).expect("the reader's JSON")
}

/// Runs `scene_file` with `sets` and `--mcap` into `dir/run`; returns the folder.
fn record(dir: &TempDir, scene_file: &Path, sets: &[&str]) -> PathBuf {
    let out = dir.join("run");
    let mut cmd = common::plant_run(scene_file, &out, sets);
    let done = output_within(cmd.arg("--mcap").arg("--quiet"), LIMIT);
    assert_exit(&done, 0);
    out
}

/// Every topic's every field equals its `trace.csv` column bit for bit, one message per row;
/// returns the topics seen.
fn assert_holds_trace(run: &Path, rec: &serde_json::Value) -> Vec<String> {
    let trace = Csv::read(&run.join("trace.csv"));
    let rows = trace.rows.len();
    assert!(rows > 100, "{rows} rows");
    let topics = rec["topics"].as_object().expect("topics");
    let mut carried = Vec::new();
    for (name, t) in topics {
        assert_eq!(t["encoding"], "ros2msg", "{name}");
        assert_eq!(t["message_encoding"], "cdr", "{name}");
        let schema = t["schema_text"].as_str().unwrap();
        let fields = t["fields"].as_object().unwrap();
        let plane_b = name.starts_with("/plane_b/");
        for (field, values) in fields {
            let values: Vec<i64> = serde_json::from_value(values.clone()).unwrap();
            assert_eq!(values.len(), rows, "{name}.{field}: one message per row");
            // The field's line of the schema, with its unit and column in the comment.
            let description = schema
                .lines()
                .find(|l| l.starts_with(&format!("float64 {field} ")))
                .unwrap_or_else(|| panic!("{name}.{field} in {schema}"));
            if field == "radius_m" {
                assert!(description.contains("(m)"), "{description}");
                assert_radius(name, &trace, &values);
                continue;
            }
            let column = if plane_b && field != "t_s" { format!("b_{field}") } else { field.clone() };
            carried.push(column.clone());
            // The unit is the column name's suffix: `_m` → (m), `_a` → (A), …
            assert!(description.contains(&column), "{name}.{field}: {description}");
            assert!(description.contains(&format!("({})", unit_of(&column))), "{name}.{field}: {description}");
            let expected = trace.column(&column);
            for (i, (got, want)) in values.iter().zip(&expected).enumerate() {
                // trace.csv writes every NaN as `NaN`: a NaN's payload is not in the trace.
                if want.is_nan() {
                    assert!(f64::from_bits(*got as u64).is_nan(), "{name}.{field} row {i}: NaN");
                } else {
                    assert_eq!(*got, want.to_bits() as i64, "{name}.{field} row {i}: {want}");
                }
            }
        }
    }
    assert_eq!(rec["log_times_ok"], true, "each message's log time is its t_s in ns");
    assert_eq!(rec["headers_ok"], true, "each message is the CDR header and one double per schema field");
    // Every column but the time is carried once, and `t_s` by every topic.
    carried.retain(|c| c != "t_s");
    carried.sort();
    let mut columns: Vec<String> = trace.header.iter().filter(|c| *c != "t_s").cloned().collect();
    columns.sort();
    assert_eq!(carried, columns);
    topics.keys().cloned().collect()
}

/// A column's unit, from its name (the trace's naming rule, written out again here).
fn unit_of(column: &str) -> &'static str {
    let ends = |s: &str| column.ends_with(s);
    if ends("_m_s") {
        "m/s"
    } else if ends("_rad_s") {
        "rad/s"
    } else if ends("_rad") {
        "rad"
    } else if ends("_m") {
        "m"
    } else if ends("_n") {
        "N"
    } else if ends("_a") {
        "A"
    } else if ends("_v") {
        "V"
    } else {
        "s"
    }
}

/// The radius field: hypot of the row's x and y (the topic's), within one ulp (Python's hypot
/// and libm's may round differently), computed here from the trace.
fn assert_radius(topic: &str, trace: &Csv, values: &[i64]) {
    let (x, y) = match topic {
        "/plane_a/rotor" => ("dx_m", "dy_m"),
        "/plane_b/rotor" => ("b_dx_m", "b_dy_m"),
        "/mid_span" => ("mid_dx_m", "mid_dy_m"),
        other => panic!("radius on {other}"),
    };
    for (i, ((v, x), y)) in values.iter().zip(trace.column(x)).zip(trace.column(y)).enumerate() {
        let want = (x * x + y * y).sqrt();
        let got = f64::from_bits(*v as u64);
        assert!((got - want).abs() <= 2.0 * f64::EPSILON * want, "{topic} radius row {i}: {got} vs {want}");
    }
}

#[test]
fn a_recording_holds_the_trace_bit_for_bit() {
    let dir = TempDir::new("mcap-planar");
    let run = record(&dir, &scene("paper-10g.toml"), SHORT);
    let rec = read_back(&run);
    let topics = assert_holds_trace(&run, &rec);
    let want = ["/housing", "/plane_a/coils", "/plane_a/contact", "/plane_a/race", "/plane_a/rotor", "/rotor/spin"];
    assert_eq!(topics, want);
    // Chunks, not compressed by default (the MCAP format's empty compression name).
    assert_eq!(rec["compressions"], serde_json::json!([""]));
    // Every chunk has its message index: Lichtblick's and Foxglove's reader (`@mcap/core`)
    // refuses a file with a chunk without one ("Chunks without message indexes are not
    // currently supported"), which a chunk of schemas and channels alone, ended by the metadata
    // record, was.
    assert_eq!(rec["chunks_without_message_index"], 0);
    // The scene as metadata: the run's own scene.toml.
    assert_eq!(rec["metadata"]["scene"]["scene.toml"].as_str().unwrap(), read_text(&run.join("scene.toml")));
    // The events: the shock's start at its row (10 ms), contact onsets, the status at the end.
    let events: Vec<(u64, u64, String)> = serde_json::from_value(rec["events"].clone()).unwrap();
    assert!(
        events.iter().any(|(t, level, m)| *t == 10_000_000 && *level == 2 && m == "shock 1 of 1 starts (t = 0.01 s)"),
        "{events:?}"
    );
    assert!(events.iter().any(|(_, _, m)| m == "contact onset 1"), "{events:?}");
    let last_ns = 50_000_000;
    assert!(events.iter().any(|(t, _, m)| *t == last_ns && m == "run completed"), "{events:?}");
    assert!(events.iter().any(|(_, _, m)| m.starts_with("motion after the shock: ")), "{events:?}");
    assert_orbit(&run, &rec, "/plane_a/orbit", ("dx_m", "dy_m"), 0.15e-3);
    // A continuous run has no loop ticks.
    assert!(rec["extra"].get("/loop/sample").is_none());
}

/// Bits of a JSON list of doubles' bit patterns.
fn doubles(v: &serde_json::Value) -> Vec<f64> {
    let bits: Vec<i64> = serde_json::from_value(v.clone()).expect("a list of bit patterns");
    bits.into_iter().map(|b| f64::from_bits(b as u64)).collect()
}

/// The orbit topic: a message every 20 ms of simulated time (rows 0, 400, 800 of a 20 kHz
/// trace), each the window's rows 400 back, every 2nd ending at its own row, equal to the
/// trace's `x`, `y` columns bit for bit, then a 73-point circle of radius `clearance_m` (the
/// scene's `touchdown.air_gap_mm`), the two polylines separated by NaN in each y array.
fn assert_orbit(run: &Path, rec: &serde_json::Value, topic: &str, (x, y): (&str, &str), clearance_m: f64) {
    let trace = Csv::read(&run.join("trace.csv"));
    let (xs, ys) = (trace.column(x), trace.column(y));
    let orbit = &rec["extra"][topic];
    assert_eq!(orbit["schema"], "plant_msgs/msg/Orbit");
    assert_eq!(orbit["message_encoding"], "cdr");
    let schema = orbit["schema_text"].as_str().unwrap();
    for line in ["float64[] x_m  # x_m (m)", "float64 clearance_m  # clearance_m (m)"] {
        assert!(schema.contains(line), "{schema}");
    }
    let log_times: Vec<u64> = serde_json::from_value(orbit["log_times"].clone()).unwrap();
    let rows_per_message = 400;
    let want: Vec<u64> = (0..xs.len()).step_by(rows_per_message).map(|j| j as u64 * 50_000).collect();
    assert_eq!(log_times, want);
    let fields = &orbit["fields"];
    let (t, clearance) = (doubles(&fields["t_s"]), doubles(&fields["clearance_m"]));
    for (m, &ns) in log_times.iter().enumerate() {
        let j = (ns / 50_000) as usize;
        assert_eq!(t[m], trace.column("t_s")[j]);
        assert_eq!(clearance[m], clearance_m);
        let (ox, oy, cy) =
            (doubles(&fields["x_m"][m]), doubles(&fields["orbit_y_m"][m]), doubles(&fields["clearance_y_m"][m]));
        let rows: Vec<usize> = (0..=j).rev().step_by(2).take_while(|&i| i + rows_per_message > j).collect();
        let n = rows.len();
        assert_eq!(ox.len(), n + 73, "message {m}");
        assert!(oy.len() == ox.len() && cy.len() == ox.len());
        for (k, &i) in rows.iter().rev().enumerate() {
            assert_eq!((ox[k].to_bits(), oy[k].to_bits()), (xs[i].to_bits(), ys[i].to_bits()), "message {m} row {i}");
            assert!(cy[k].is_nan());
        }
        for k in n..n + 73 {
            assert!(oy[k].is_nan());
            let r = ox[k].hypot(cy[k]);
            assert!((r - clearance_m).abs() <= 1e-15, "message {m} circle point {k}: radius {r}");
        }
        assert_eq!((ox[n], cy[n]), (ox[n + 72], cy[n + 72]), "the circle is closed");
    }
}

#[test]
fn a_sampled_loops_samples_and_commands_are_recorded() {
    // paper-10g's PD sampled at 20 kHz (the period of its output rows): one tick per row.
    let dir = TempDir::new("mcap-loop");
    let sets: Vec<&str> = SHORT.iter().copied().chain(["controller.mode=\"sampled\""]).collect();
    let run = record(&dir, &scene("paper-10g.toml"), &sets);
    let rec = read_back(&run);
    let trace = Csv::read(&run.join("trace.csv"));
    let sample = &rec["extra"]["/loop/sample"];
    let command = &rec["extra"]["/loop/command"];
    assert_eq!(sample["schema"], "plant_msgs/msg/LoopSample");
    assert_eq!(command["schema"], "plant_msgs/msg/LoopCommand");
    for (t, lines) in [
        (
            sample,
            &["uint64 seq", "float64 sensor_xa_v  # sensor_xa_v (V)", "float64 speed_rad_s  # speed_rad_s (rad/s)"][..],
        ),
        (command, &["float64 command_xa_a  # command_xa_a (A)", "float64 command_ya_a  # command_ya_a (A)"][..]),
    ] {
        let text = t["schema_text"].as_str().unwrap();
        for l in lines {
            assert!(text.contains(l), "{text}");
        }
        assert!(!text.contains("_xb_"), "a planar run has two axes: {text}");
    }
    // 0.05 s at 50 µs: ticks 0 … 999, each at k·T.
    let seq: Vec<u64> = serde_json::from_value(sample["fields"]["seq"].clone()).unwrap();
    assert_eq!(seq, (0..1000).collect::<Vec<u64>>());
    let t = doubles(&sample["fields"]["t_s"]);
    let t_trace = trace.column("t_s");
    for k in 0..1000 {
        assert_eq!(t[k], t_trace[k], "tick {k} at row {k}'s time");
    }
    let log_times: Vec<u64> = serde_json::from_value(command["log_times"].clone()).unwrap();
    assert_eq!(log_times, (0..1000).map(|k| k * 50_000).collect::<Vec<u64>>());
    // The command applied over tick k is the current reference of the rows it makes: row k + 1's
    // `ix_a`, `iy_a` (the trace's commanded currents), bit for bit.
    let (ix, iy) = (trace.column("ix_a"), trace.column("iy_a"));
    let (cx, cy) = (doubles(&command["fields"]["command_xa_a"]), doubles(&command["fields"]["command_ya_a"]));
    for k in 0..1000 {
        assert_eq!((cx[k].to_bits(), cy[k].to_bits()), (ix[k + 1].to_bits(), iy[k + 1].to_bits()), "tick {k}");
    }
    // The sensor reads the rotor's position relative to the housing at the tick: 25 000 V/m
    // (paper-10g's `sensor_gain_v_per_m`) times row k's `dx_m`.
    let (dx, v) = (trace.column("dx_m"), doubles(&sample["fields"]["sensor_xa_v"]));
    for k in 0..1000 {
        assert!((v[k] - 25_000.0 * dx[k]).abs() <= 1e-9 * v[k].abs().max(1e-9), "tick {k}: {} V for {} m", v[k], dx[k]);
    }
}

#[test]
fn two_plane_and_flexible_recordings_hold_their_planes_and_mid_span() {
    let dir = TempDir::new("mcap-two-plane");
    let run = record(&dir, &scene("two-plane-asymmetric-10g.toml"), &["scene.duration_s=0.02", "output.plots=false"]);
    let topics = assert_holds_trace(&run, &read_back(&run));
    for t in ["/plane_b/rotor", "/plane_b/race", "/plane_b/contact", "/plane_b/coils", "/tilt"] {
        assert!(topics.iter().any(|x| x == t), "{t} in {topics:?}");
    }
    let dir = TempDir::new("mcap-flexible");
    let run = record(&dir, &scene("flexible-10g.toml"), &["scene.duration_s=0.01", "output.plots=false"]);
    let rec = read_back(&run);
    let topics = assert_holds_trace(&run, &rec);
    assert!(topics.iter().any(|x| x == "/mid_span"), "{topics:?}");
    // Every series of the shipped layout names a topic and field of this recording (the
    // flexible rotor's has both planes and the mid-span).
    let layout: serde_json::Value =
        serde_json::from_str(&read_text(&common::workspace_root().join("docs/layouts/plant-study.json")))
            .expect("the layout's JSON");
    let mut paths = Vec::new();
    for panel in layout["configById"].as_object().unwrap().values() {
        for p in panel["paths"].as_array().into_iter().flatten() {
            paths.push(p["value"].as_str().unwrap().to_string());
        }
        if let Some(x) = panel["xAxisPath"]["value"].as_str() {
            paths.push(x.to_string());
        }
        if let Some(t) = panel["topicToRender"].as_str() {
            assert_eq!(t, "/events");
        }
    }
    assert!(paths.len() >= 10, "{paths:?}");
    for path in paths {
        let (topic, field) = path.split_once('.').unwrap_or_else(|| panic!("{path}"));
        // An array's path (the orbit's `x_m[:]`) names the array.
        let field = field.strip_suffix("[:]").unwrap_or(field);
        let found = rec["topics"][topic]["fields"].get(field).or_else(|| rec["extra"][topic]["fields"].get(field));
        assert!(found.is_some(), "the layout's {path} is not in the recording");
    }
    // Both planes' orbits, each with the clearance circle.
    for topic in ["/plane_a/orbit", "/plane_b/orbit"] {
        assert_eq!(rec["extra"][topic]["schema"], "plant_msgs/msg/Orbit", "{topic}");
    }
}

#[test]
fn without_the_flag_nothing_is_recorded_and_scene_toml_is_unchanged() {
    let dir = TempDir::new("mcap-off");
    let out = dir.join("run");
    let done = output_within(common::plant_run(&scene("paper-10g.toml"), &out, SHORT).arg("--quiet"), LIMIT);
    assert_exit(&done, 0);
    assert!(!out.join("run.mcap").exists());
    // The key is written into the resolved scene only when set (earlier runs' scene.toml stay
    // byte-identical).
    assert!(!read_text(&out.join("scene.toml")).contains("mcap"));
    let on = record(&dir, &scene("paper-10g.toml"), SHORT);
    assert!(read_text(&on.join("scene.toml")).contains("mcap = true"));
    // A reused folder loses an earlier recording when the next run does not record.
    let done = output_within(common::plant_run(&scene("paper-10g.toml"), &on, SHORT).arg("--quiet"), LIMIT);
    assert_exit(&done, 0);
    assert!(!on.join("run.mcap").exists(), "a stale run.mcap stayed");
}

#[test]
fn a_link_at_run_mcap_is_replaced_not_followed() {
    let dir = TempDir::new("mcap-link");
    let out = dir.join("run");
    std::fs::create_dir_all(&out).unwrap();
    let victim = dir.join("victim.txt");
    std::fs::write(&victim, "untouched").unwrap();
    std::os::unix::fs::symlink(&victim, out.join("run.mcap")).unwrap();
    record(&dir, &scene("paper-10g.toml"), SHORT);
    assert_eq!(read_text(&victim), "untouched");
    let meta = std::fs::symlink_metadata(out.join("run.mcap")).unwrap();
    assert!(meta.file_type().is_file(), "run.mcap is a regular file");
}

#[test]
fn a_soak_records_one_file_over_its_shocks() {
    common::controller_bin();
    let dir = TempDir::new("mcap-soak");
    let out = dir.join("soak");
    let programme = common::workspace_root().join("config/soak/soak-short.toml");
    let mut cmd = Command::new(common::plant_bin());
    cmd.arg("soak").arg(&programme).arg("--out").arg(&out).args(["--quiet", "--mcap"]);
    assert_exit(&output_within(&mut cmd, LIMIT), 0);
    let rec = read_file(&out.join("soak.mcap"));
    assert_eq!(rec["headers_ok"], true);
    assert_eq!(rec["log_times_ok"], true);
    // soak-short: two shocks in 0.65 s simulated (the second's start, 0.45 s, plus its pulse
    // and settle_s = 0.15 s), rows at 20 kHz from t = 0: one message per row on each topic.
    let json = common::read_json(&out.join("soak.json"));
    let simulated = common::num(&json, "simulated_s");
    let rows = (simulated * 20000.0).round() as usize + 1;
    let t: Vec<i64> = serde_json::from_value(rec["topics"]["/plane_a/rotor"]["fields"]["t_s"].clone()).unwrap();
    assert_eq!(t.len(), rows, "one message per row over {simulated} s");
    let t: Vec<f64> = t.iter().map(|b| f64::from_bits(*b as u64)).collect();
    assert_eq!(t[0], 0.0);
    assert!(t.windows(2).all(|w| w[1] > w[0]), "times increase");
    let events: Vec<(u64, u64, String)> = serde_json::from_value(rec["events"].clone()).unwrap();
    for (n, start_ns) in [(1, 20_000_000), (2, 450_000_000)] {
        assert!(
            events.iter().any(|(ns, _, m)| *ns == start_ns && m.starts_with(&format!("shock {n} of 2 starts"))),
            "{events:?}"
        );
    }
    assert_eq!(rec["metadata"]["scene"]["name"], "soak-short");
}

#[test]
fn lz4_chunks_hold_the_same_trace() {
    let dir = TempDir::new("mcap-lz4");
    let sets: Vec<&str> = SHORT.iter().copied().chain(["output.mcap_compression=\"lz4\""]).collect();
    let run = record(&dir, &scene("paper-10g.toml"), &sets);
    let rec = read_back(&run);
    assert_eq!(rec["compressions"], serde_json::json!(["lz4"]));
    assert_eq!(assert_holds_trace(&run, &rec).len(), 6);
}

#[test]
fn a_bad_compression_exits_2_naming_the_key_and_the_value() {
    let dir = TempDir::new("mcap-bad-compression");
    let out = dir.join("run");
    let mut cmd = common::plant_run(&scene("paper-10g.toml"), &out, &["output.mcap_compression=\"zip\""]);
    let done = output_within(cmd.arg("--mcap"), LIMIT);
    assert_exit(&done, 2);
    let err = stderr(&done);
    assert!(err.contains("mcap_compression") && err.contains("zip"), "{err}");
    assert!(!out.join("run.mcap").exists() && !out.join("trace.csv").exists());
}

#[test]
fn a_bad_value_of_the_key_exits_2_naming_it() {
    let dir = TempDir::new("mcap-bad");
    let out = dir.join("run");
    let mut cmd = common::plant_run(&scene("paper-10g.toml"), &out, &["output.mcap=3"]);
    let done = output_within(&mut cmd, LIMIT);
    assert_exit(&done, 2);
    assert!(stderr(&done).contains("mcap"), "{}", stderr(&done));
    assert!(!out.join("run.mcap").exists() && !out.join("trace.csv").exists());
}

#[test]
fn an_ensembles_member_is_recorded_on_request() {
    let dir = TempDir::new("mcap-member");
    let out = dir.join("ens");
    let mut cmd = Command::new(common::plant_bin());
    cmd.arg("ensemble").arg(scene("paper-10g.toml")).arg("--out").arg(&out).args(["--record-member", "2"]);
    for s in [
        "scene.duration_s=0.06",
        "shock[0].start_s=0.005",
        "ensemble.members=3",
        "ensemble.seed=7",
        "ensemble.verify=false",
    ] {
        cmd.args(["--set", s]);
    }
    let done = output_within(&mut cmd, LIMIT);
    assert_exit(&done, 0);
    let member = out.join("member-2");
    assert!(stderr(&done).contains("member 2 recorded in"), "{}", stderr(&done));
    // The recording holds the member's rows, bit for bit.
    let rec = read_back(&member);
    assert_holds_trace(&member, &rec);
    // It is member 2's run: its figures are members.csv's row of member 2 (parsed from the
    // ensemble's table, the shortest decimal of each double, so equal to the bit).
    let text = read_text(&out.join("members.csv"));
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("{name}"));
    let rows: Vec<Vec<&str>> = text.lines().skip(1).map(|l| l.split(',').collect()).collect();
    let row = rows.iter().find(|r| r[col("member")] == "2").expect("member 2's row");
    let summary = common::read_json(&member.join("summary.json"));
    for key in ["max_radius_m", "max_contact_force_n"] {
        let want: f64 = row[col(key)].parse().unwrap();
        assert_eq!(common::num(&summary, key), want, "{key}");
    }
    // The other members' figures differ (the test tells members apart).
    let other: f64 =
        rows.iter().find(|r| r[col("member")] == "0").unwrap()[col("max_contact_force_n")].parse().unwrap();
    assert_ne!(common::num(&summary, "max_contact_force_n"), other);
    // A member the ensemble does not have is bad input, before anything runs.
    let out = dir.join("bad");
    let mut cmd = Command::new(common::plant_bin());
    cmd.arg("ensemble").arg(scene("paper-10g.toml")).arg("--out").arg(&out).args(["--record-member", "3"]);
    cmd.args(["--set", "ensemble.members=3"]);
    let done = output_within(&mut cmd, LIMIT);
    assert_exit(&done, 2);
    assert!(stderr(&done).contains("--record-member 3: the ensemble has 3 members"), "{}", stderr(&done));
    assert!(!out.join("members.csv").exists());
}
