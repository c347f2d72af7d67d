//! End-to-end tests of the Python controller kit (`python/`, issue 10 item 5).
//!
//! What is pinned: the kit's structures and constants are the Rust ones
//! (`controller::wire::layouts()` and `constants()`: every size, offset, type
//! name and constant); `pd` in Python, served by the kit in lockstep, writes
//! the Rust `pd`'s trace byte for byte, and answers a four-axis run as the
//! Rust `pd` does, plane by plane, bit for bit; the kit answers the handshake as the Rust
//! controller does (token echo, no overrides, each refusal with its code and a
//! message naming law, key, value and unit) and exits with its codes (0, 2, 4,
//! 130); a law's parameters are checked with the Rust laws' messages; the
//! re-levitation example recovers the rotor; the kit's own pytest suite
//! (`python/tests`, with its `mypy --strict` check) passes.
//!
//! The kit runs in a virtual environment the tests make once, under the target
//! folder (`target/python-venv`: `python3 -m venv`, then `pip install -e
//! 'python/[test]'`, which brings the pinned `iceoryx2`, `pytest` and `mypy`
//! from PyPI); it is reused while
//! its stamp (the kit's `pyproject.toml`) matches. `python3` ≥ 3.11 must be on
//! `PATH`. Every process is bounded in time.

mod common;
#[path = "common/v3.rs"]
mod v3;

use common::{assert_exit, num, output_within, plant_run, read_json, scene, stderr, workspace_root, Proc, TempDir};
use controller::link::{self, Endpoint, Mailbox};
use controller::wire::{self, Ack, CommandFrame, Hello, SensorFrame};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// The limit of one short run in a debug build on a loaded machine.
const LIMIT: Duration = Duration::from_secs(120);

/// The release of iceoryx2 the kit pins (the Rust crate's, `Cargo.lock`).
const ICEORYX2: &str = "0.10.0";

/// A unique run id per test and process.
fn run_id(name: &str) -> String {
    format!("py{}-{name}", std::process::id())
}

/// The kit's virtual environment, made (or checked) once per test binary.
fn venv() -> &'static Path {
    static VENV: OnceLock<PathBuf> = OnceLock::new();
    VENV.get_or_init(prepare_venv)
}

/// The venv's interpreter.
fn python() -> PathBuf {
    venv().join("bin").join("python")
}

/// `target/python-venv` with the kit installed in editable mode: made if absent or stale,
/// under a file lock (two test runs at once share it).
fn prepare_venv() -> PathBuf {
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).parent().expect("CARGO_TARGET_TMPDIR is target/tmp");
    let dir = target.join("python-venv");
    let kit = workspace_root().join("python");
    let pyproject = std::fs::read_to_string(kit.join("pyproject.toml")).expect("python/pyproject.toml");
    let stamp = format!("kit: {}\n{pyproject}", kit.display());
    let lock = std::fs::File::create(target.join("python-venv.lock")).expect("venv lock file");
    lock.lock().expect("locking the venv");
    let stamp_file = dir.join("amb-testbed.stamp");
    if dir.join("bin/python").exists() && std::fs::read_to_string(&stamp_file).ok().as_deref() == Some(&stamp) {
        return dir;
    }
    let version = output_within(
        Command::new("python3").args(["-c", "import sys; print(sys.version_info >= (3, 11))"]),
        Duration::from_secs(30),
    );
    assert!(
        String::from_utf8_lossy(&version.stdout).trim() == "True",
        "the Python kit needs python3 >= 3.11 on PATH (tomllib): {version:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
    let venv = output_within(Command::new("python3").arg("-m").arg("venv").arg(&dir), Duration::from_secs(120));
    assert_exit(&venv, 0);
    let install = output_within(
        Command::new(dir.join("bin/python"))
            .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check", "--editable"])
            .arg(format!("{}[test]", kit.display())),
        Duration::from_secs(600),
    );
    assert_exit(&install, 0);
    std::fs::write(&stamp_file, stamp).expect("venv stamp");
    dir
}

/// `python examples/python/<script> ARGS` in the kit's venv (not started).
fn python_controller(script: &str, args: &[&str]) -> Command {
    let mut cmd = Command::new(python());
    cmd.arg(workspace_root().join("examples/python").join(script)).args(args);
    cmd
}

/// The plant's side of a run, played by the test: its node and the handshake and frame ports.
struct TestPlant {
    frames: Endpoint<SensorFrame, CommandFrame>,
    handshake: Mailbox<Hello, Ack>,
    _node: iceoryx2::node::Node<link::Ipc>,
}

impl TestPlant {
    fn open(id: &str) -> Self {
        iceoryx2::prelude::set_log_level(iceoryx2::prelude::LogLevel::Fatal);
        let node = link::node(id, "plant").expect("node");
        let handshake = Mailbox::open(&node, id, "hello", "ack").expect("handshake");
        let frames = Endpoint::open(&node, id, "sensor", "command", Duration::from_micros(200)).expect("frames");
        Self { frames, handshake, _node: node }
    }

    /// Publishes `hello` every 5 ms until an ack of its session comes (within 60 s).
    fn handshake(&self, hello: Hello) -> Ack {
        let deadline = Instant::now() + Duration::from_secs(60);
        loop {
            self.handshake.send(hello).expect("hello");
            std::thread::sleep(Duration::from_millis(5));
            while let Some(ack) = self.handshake.try_receive().expect("ack") {
                if ack.session == hello.session {
                    return ack;
                }
            }
            assert!(Instant::now() < deadline, "no ack within 60 s");
        }
    }

    /// The next command frame within `limit`, polled without ever asking to be woken.
    fn poll_reply_within(&self, limit: Duration) -> Option<CommandFrame> {
        let until = Instant::now() + limit;
        while Instant::now() < until {
            if let Some(reply) = self.frames.try_receive().expect("receive") {
                return Some(reply);
            }
            std::thread::sleep(Duration::from_micros(100));
        }
        None
    }

    /// The next command frame within `limit`, if any.
    fn reply_within(&mut self, limit: Duration) -> Option<CommandFrame> {
        let until = Instant::now() + limit;
        self.frames.wait(Duration::from_millis(1), || Instant::now() < until).expect("wait")
    }
}

/// The example hello of run `id`: `pd` at the study's design, with a token.
fn hello(id: &str) -> Hello {
    let mut h = Hello::example(id);
    h.token = 0x0123_4567_89ab_cdef;
    h
}

fn sensor_frame(h: &Hello, seq: u64, token: u64, sensor_v: [f64; 2]) -> SensorFrame {
    SensorFrame {
        seq,
        t_s: seq as f64 * h.period_s,
        token,
        session: h.session,
        axes: wire::AXES,
        sensor_v: wire::axes_of(sensor_v),
        ..Default::default()
    }
}

#[test]
fn the_kit_pins_the_iceoryx2_release_of_cargo_lock() {
    let lock = std::fs::read_to_string(workspace_root().join("Cargo.lock")).unwrap();
    let rust = lock
        .split("[[package]]")
        .find(|p| p.contains("\nname = \"iceoryx2\"\n"))
        .and_then(|p| p.lines().find_map(|l| l.strip_prefix("version = \"")))
        .map(|v| v.trim_end_matches('"'))
        .expect("iceoryx2 in Cargo.lock");
    assert_eq!(rust, ICEORYX2, "Cargo.lock moved to iceoryx2 {rust}: pin the same release in python/pyproject.toml");
    let pyproject = std::fs::read_to_string(workspace_root().join("python/pyproject.toml")).unwrap();
    assert!(
        pyproject.contains(&format!("\"iceoryx2=={rust}\"")),
        "python/pyproject.toml does not pin iceoryx2=={rust}"
    );
}

/// Issue 31: `pip install ./python` writes nothing into the checkout (setuptools left `build/`
/// and `*.egg-info` there): a copy of the kit, installed by the venv's pip into a folder of its
/// own, holds exactly the files it held before, and the installed package has its `py.typed`.
#[test]
fn installing_the_kit_writes_nothing_into_its_folder() {
    fn files(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()) {
            if e.file_name().is_some_and(|n| n == "__pycache__") {
                continue;
            }
            out.push(e.clone());
            if e.is_dir() {
                files(&e, out);
            }
        }
    }
    let tmp = TempDir::new("py-install");
    let kit = tmp.join("kit");
    let copy = output_within(
        Command::new("cp").arg("-r").arg(workspace_root().join("python")).arg(&kit),
        Duration::from_secs(30),
    );
    assert_exit(&copy, 0);
    let mut before = Vec::new();
    files(&kit, &mut before);
    let install = output_within(
        Command::new(python())
            .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check", "--no-deps", "--target"])
            .arg(tmp.join("site"))
            .arg(&kit),
        Duration::from_secs(300),
    );
    assert_exit(&install, 0);
    let mut after = Vec::new();
    files(&kit, &mut after);
    before.sort();
    after.sort();
    let new: Vec<_> = after.iter().filter(|p| !before.contains(p)).collect();
    assert!(new.is_empty(), "pip install wrote into the kit's folder: {new:?}");
    assert!(tmp.join("site").join("amb_testbed_controller").join("py.typed").is_file(), "py.typed not installed");
}

/// Issue 20: the kit's wire constants and ctypes layouts come from the Rust definitions or
/// this test fails naming the difference: `wire.describe()` (every constant of `wire.CONSTANTS`,
/// every structure's type name, size, alignment and each field's offset and size as ctypes lays
/// them out) against `controller::wire::constants()` and `layouts()`, both ways.
#[test]
fn python_constants_and_structs_are_the_rust_ones() {
    use controller::wire::{constants, layouts, Constant};
    let script = "import json\nfrom amb_testbed_controller import wire\nprint(json.dumps(wire.describe()))";
    let out = output_within(Command::new(python()).args(["-c", script]), LIMIT);
    assert_exit(&out, 0);
    let py: serde_json::Value = serde_json::from_slice(&out.stdout).expect("describe() as JSON");
    let mut differences = Vec::new();
    let py_constants = py["constants"].as_object().expect("constants");
    let rust_constants = constants();
    for (name, value) in &rust_constants {
        let want = match value {
            Constant::Number(n) => serde_json::json!(n),
            Constant::Text(t) => serde_json::json!(t),
        };
        match py_constants.get(name) {
            None => differences.push(format!("wire.CONSTANTS lacks {name} (Rust: {want})")),
            Some(v) if *v != want => differences.push(format!("wire.CONSTANTS[{name:?}] = {v}, Rust {want}")),
            Some(_) => {}
        }
    }
    for name in py_constants.keys() {
        if !rust_constants.iter().any(|(n, _)| n == name) {
            differences.push(format!("wire.CONSTANTS[{name:?}]: not in controller::wire::constants()"));
        }
    }
    let messages = py["messages"].as_array().expect("messages");
    let rust_layouts = layouts();
    for m in &rust_layouts {
        let Some(p) = messages.iter().find(|p| p["name"] == m.name) else {
            differences.push(format!("the kit has no structure {}", m.name));
            continue;
        };
        for (key, want) in
            [("type_name", serde_json::json!(m.type_name)), ("size", m.size.into()), ("align", m.align.into())]
        {
            if p[key] != want {
                differences.push(format!("{}.{key}: Python {}, Rust {want}", m.name, p[key]));
            }
        }
        let fields: Vec<(String, u64, u64)> = p["fields"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| (f[0].as_str().unwrap().to_string(), f[1].as_u64().unwrap(), f[2].as_u64().unwrap()))
            .collect();
        let rust: Vec<(String, u64, u64)> =
            m.fields.iter().map(|f| (f.name.to_string(), f.offset as u64, f.size as u64)).collect();
        if fields != rust {
            differences.push(format!("{}: Python's (field, offset, size) {fields:?}\n  Rust's {rust:?}", m.name));
        }
    }
    if messages.len() != rust_layouts.len() {
        differences.push(format!("the kit has {} structures, Rust {}", messages.len(), rust_layouts.len()));
    }
    assert!(differences.is_empty(), "the Python kit differs from controller::wire:\n{}", differences.join("\n"));
}

/// Issue 20: the kit's own tests (pytest, `python/tests`: its structures, each plane's design
/// from a hello, the handshake's refusals, the per-plane lifting, `pd` against its documented
/// form, and `mypy --strict` on the kit and on a law written against its `Law` protocol).
#[test]
fn the_kits_pytest_suite_passes() {
    let target = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let out = output_within(
        Command::new(python())
            .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
            .current_dir(workspace_root().join("python"))
            .env("MYPY_CACHE_DIR", target.join("python-kit-mypy-cache"))
            .env("PYTHONDONTWRITEBYTECODE", "1"),
        LIMIT,
    );
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), stderr(&out));
    assert_exit(&out, 0);
    let passed: usize = text
        .split_whitespace()
        .collect::<Vec<_>>()
        .windows(2)
        .find(|w| w[1].starts_with("passed"))
        .and_then(|w| w[0].parse().ok())
        .unwrap_or(0);
    assert!(passed >= 15, "pytest ran {passed} tests:\n{text}");
}

/// The bit-identity promise: the Python `pd` in lockstep writes the trace of the Rust `pd`
/// (the in-process `sampled` run of the same scene), byte for byte.
#[test]
fn python_pd_in_lockstep_writes_the_rust_pd_trace_byte_for_byte() {
    python_pd_writes_the_rust_pd_trace("cosim-10g.toml", "pd");
}

/// Issue 17: the same on the two-plane rotor (four axes, `pd` once per bearing plane), on the
/// asymmetric 10 G scene through its first impacts at both planes.
#[test]
fn python_pd_on_the_two_plane_scene_writes_the_rust_pd_trace_byte_for_byte() {
    python_pd_writes_the_rust_pd_trace("two-plane-asymmetric-10g.toml", "pd-2p");
}

fn python_pd_writes_the_rust_pd_trace(scene_file: &str, name: &str) {
    let dir = TempDir::new(&format!("py-{name}-identical"));
    let sets = ["scene.duration_s=0.05", "output.plots=false", "controller.law=pd"];
    let sampled = dir.join("sampled");
    let sampled_sets: Vec<&str> = sets.iter().copied().chain(["controller.mode=sampled"]).collect();
    assert_exit(&output_within(&mut plant_run(&scene(scene_file), &sampled, &sampled_sets), LIMIT), 0);

    let id = run_id(name);
    let out = dir.join("python");
    let lockstep_sets: Vec<&str> = sets.iter().copied().chain(["controller.mode=lockstep"]).collect();
    let mut plant_cmd = plant_run(&scene(scene_file), &out, &lockstep_sets);
    plant_cmd.args(["--controller", "external", "--run-id", &id]);
    let plant = Proc::spawn(&mut plant_cmd);
    let ctl = Proc::spawn(&mut python_controller("pd.py", &["--run-id", &id]));
    let (code, log) = plant.finish_within(LIMIT);
    assert_eq!(code, Some(0), "{log}");
    let (code, log) = ctl.finish_within(Duration::from_secs(30));
    assert_eq!(code, Some(0), "{log}");
    assert!(log.contains("answered 1000 frames"), "{log}");

    assert!(
        std::fs::read(out.join("trace.csv")).unwrap() == std::fs::read(sampled.join("trace.csv")).unwrap(),
        "the Python pd in lockstep and the Rust pd wrote different traces"
    );
    let s = read_json(&out.join("summary.json"));
    let c = &s["cosim"];
    assert_eq!(s["status"], "completed");
    assert!(c["controller"].as_str().unwrap().starts_with("pd (Python)"), "{c:#}");
    for key in ["messages_sent", "messages_received"] {
        assert_eq!(num(c, key), 1000.0, "{key} in {c:#}");
    }
    for key in ["sequence_gaps", "stale_replies", "invalid_replies", "foreign_frames", "fallback_ticks"] {
        assert_eq!(num(c, key), 0.0, "{key} in {c:#}");
    }
    assert!(c.get("controller_overrides").is_none_or(|o| o.is_null()), "{c:#}");
}

/// The handshake and the frames, with the test as the plant: the ack echoes session and
/// token, names the law, carries no overrides and the controller's pid; each frame is
/// answered with the Rust `pd`'s currents, bit for bit (the first sample's derivative is 0);
/// a frame of another token is never answered; STOP ends the controller with exit 0.
#[test]
fn python_controller_answers_the_handshake_and_frames_as_the_rust_one() {
    let id = run_id("frames");
    let mut plant = TestPlant::open(&id);
    let ctl = Proc::spawn(&mut python_controller("pd.py", &["--run-id", &id, "--connect-timeout-s", "60"]));
    let h = hello(&id);
    let ack = plant.handshake(h);
    assert_eq!(
        (ack.status, ack.session, ack.token, ack.protocol_version),
        (0, h.session, h.token, wire::PROTOCOL_VERSION)
    );
    assert_eq!((wire::str_of(&ack.law).as_ref(), ack.overrides_len, ack.controller_pid), ("pd", 0, ctl.id()));
    assert!(wire::str_of(&ack.message).contains("(Python)"), "{}", wire::str_of(&ack.message));

    let mut law = controller::build_law("pd", &h.design(), &controller::Params::default()).unwrap();
    // Values with many significant bits, and one past the current limit.
    let inputs = [[0.1234567891234, -0.0987654321987], [0.1334567891234, -0.1087654321987], [3.0, -3.0]];
    for (seq, v) in inputs.iter().enumerate() {
        let seq = seq as u64;
        plant.frames.send_and_wake(sensor_frame(&h, seq, h.token ^ 0xff, [9.0, 9.0])).unwrap();
        plant.frames.send_and_wake(sensor_frame(&h, seq, h.token, *v)).unwrap();
        let reply = plant.reply_within(Duration::from_secs(30)).expect("a reply");
        assert_eq!((reply.seq, reply.token, reply.session, reply.axes, reply.status), (seq, h.token, 1, 2, 0));
        let want = controller::saturate(
            law.update(&controller::Sample { seq, t_s: seq as f64 * h.period_s, sensor_v: *v, ..Default::default() }),
            h.current_limit_a,
        );
        let got = reply.current_xy();
        assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "sample {seq}: {got:?} against {want:?}");
        assert!(reply.current_a[2..].iter().all(|&i| i == 0.0));
        assert!(reply.received_ns <= reply.sent_ns && reply.received_ns > 0);
    }
    assert!(plant.reply_within(Duration::from_millis(200)).is_none(), "a frame of another token was answered");
    plant
        .frames
        .send_and_wake(SensorFrame { status: SensorFrame::STOP, ..sensor_frame(&h, 0, h.token, [0.0; 2]) })
        .unwrap();
    let (code, log) = ctl.finish_within(Duration::from_secs(30));
    assert_eq!(code, Some(0), "{log}");
    assert!(log.contains("answered 3 frames"), "{log}");
}

/// Issue 17: on a two-plane rotor (4 axes) the kit runs `pd` once per bearing plane, each
/// from its own plane's design (plane B differs here in k_e, mass share, k_i, sensor gain and
/// current limit), and answers every frame with the Rust controller's decentralised `pd`'s
/// currents, bit for bit, each saturated at its plane's limit; the keyphasor reaches it.
#[test]
fn python_pd_on_four_axes_answers_as_the_rust_pd_bit_for_bit() {
    let id = run_id("four-axes");
    let mut plant = TestPlant::open(&id);
    let ctl = Proc::spawn(&mut python_controller("pd.py", &["--run-id", &id, "--connect-timeout-s", "60"]));
    let mut h = Hello::example_two_plane(&id);
    h.token = 0x0fed_cba9_8765_4321;
    (h.b_stiffness_n_per_m, h.b_rotor_mass_kg, h.b_ki_n_per_a, h.b_sensor_gain_v_per_m) = (1.5e6, 9.0, 190.0, 24_000.0);
    h.b_current_limit_a = 1.0;
    let ack = plant.handshake(h);
    let message = wire::str_of(&ack.message).into_owned();
    assert_eq!(ack.status, 0, "{message}");
    assert!(message.starts_with("pd (Python): 4 axes, k_e = 1000000.0 / 1500000.0 N/m"), "{message}");
    let design = h.rotor_design().expect("a two-plane hello");
    let mut law = controller::build_rotor_law("pd", &design, &controller::Params::default()).unwrap();
    let limits = design.current_limits();
    let inputs = [
        [0.1234567891234, -0.0987654321987, 0.3123456789, 0.0456789123],
        [0.1334567891234, -0.1087654321987, 0.2923456789, 0.0556789123],
        [3.0, -3.0, 0.75, -0.9],
    ];
    for (seq, v) in inputs.iter().enumerate() {
        let seq = seq as u64;
        let frame = SensorFrame {
            axes: wire::TWO_PLANE_AXES,
            sensor_v: wire::rotor_axes_of(*v, 4),
            speed_rad_s: 3141.5,
            angle_rad: 0.25 * seq as f64,
            ..sensor_frame(&h, seq, h.token, [0.0; 2])
        };
        plant.frames.send_and_wake(frame).unwrap();
        let reply = plant.reply_within(Duration::from_secs(30)).expect("a reply");
        assert_eq!((reply.seq, reply.axes, reply.status), (seq, 4, 0));
        let want = controller::saturate_axes(law.update(&frame.rotor_sample()), limits);
        let got = reply.current_axes();
        assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "sample {seq}: {got:?} against {want:?}");
        assert!(reply.current_a[4..].iter().all(|&i| i == 0.0));
    }
    plant
        .frames
        .send_and_wake(SensorFrame { status: SensorFrame::STOP, ..sensor_frame(&h, 0, h.token, [0.0; 2]) })
        .unwrap();
    let (code, log) = ctl.finish_within(Duration::from_secs(30));
    assert_eq!(code, Some(0), "{log}");
}

/// A Python controller that finds a version-3 plant's services names the version it met and
/// exits 2, as the Rust controller does.
#[test]
fn the_python_controller_names_a_plant_of_another_version_and_exits_2() {
    let id = run_id("old-plant");
    let _old = v3::Peer::plant(&id);
    let out = output_within(&mut python_controller("pd.py", &["--run-id", &id, "--connect-timeout-s", "5"]), LIMIT);
    assert_exit(&out, 2);
    let err = stderr(&out);
    for needle in [
        "the peer speaks protocol version 3: its type is amb_testbed.v3.Ack",
        "this side speaks version 4",
        "run a plant and a controller of the same protocol version",
    ] {
        assert!(err.contains(needle), "no {needle:?} in\n{err}");
    }
}

/// Plays the plant for one hello spoiled by `spoil`: the controller `script` must refuse it
/// with `code`, a message holding every needle, and exit 2 saying so.
fn assert_refused(name: &str, script: &str, spoil: impl Fn(&mut Hello), code: u32, needles: &[&str]) {
    let id = run_id(&format!("refuse-{name}"));
    let plant = TestPlant::open(&id);
    let ctl = Proc::spawn(&mut python_controller(script, &["--run-id", &id, "--connect-timeout-s", "60"]));
    let mut h = hello(&id);
    spoil(&mut h);
    let ack = plant.handshake(h);
    let message = wire::str_of(&ack.message).into_owned();
    assert_eq!((ack.status, ack.token, ack.overrides_len), (code, h.token, 0), "{name}: {message}");
    let (exit, log) = ctl.finish_within(Duration::from_secs(30));
    assert_eq!(exit, Some(2), "{name}: {log}");
    assert!(log.contains("refused the plant's hello"), "{name}: {log}");
    for n in needles {
        assert!(message.contains(n), "{name}: no {n:?} in the ack's message {message:?}");
        assert!(log.contains(n), "{name}: no {n:?} in:\n{log}");
    }
}

/// Sets a hello's parameter document.
fn set_params(h: &mut Hello, doc: &str) {
    h.params = [0; controller::PARAMS_LEN];
    h.params[..doc.len()].copy_from_slice(doc.as_bytes());
    h.params_len = doc.len() as u32;
}

/// Each mismatch is refused with the protocol's code and a message, and the controller
/// exits 2 saying why.
#[test]
fn python_controller_refuses_hellos_with_the_codes_of_the_protocol() {
    assert_refused("version", "pd.py", |h| h.protocol_version = 3, 1, &["protocol version 3", "speaks 4"]);
    assert_refused("axes", "pd.py", |h| h.axes = 3, 3, &["3 axes", "drives 2 or 4"]);
    assert_refused("run-id", "pd.py", |h| h.run_id = wire::fixed_str("another-run"), 6, &["'another-run'"]);
    assert_refused(
        "law",
        "pd.py",
        |h| h.law = wire::fixed_str("pd_delay"),
        5,
        &["unknown controller law `pd_delay`", "serves pd"],
    );
    assert_refused(
        "design",
        "pd.py",
        |h| h.stiffness_n_per_m = -1.0,
        5,
        &["law pd: controller.stiffness_n_per_m = -1 N/m: must be > 0"],
    );
    assert_refused(
        "pd-params",
        "pd.py",
        |h| set_params(h, "gain = 2"),
        7,
        &["law pd: unknown parameter controller.params.gain = 2", "no parameters"],
    );
    assert_refused("toml", "pd.py", |h| set_params(h, "gain = "), 7, &["not valid TOML"]);
}

/// The re-levitation example refuses its own parameters, naming law, key, value and unit.
#[test]
fn relev_py_refuses_bad_parameters_naming_law_key_value_and_unit() {
    let relev = |doc: &'static str| {
        move |h: &mut Hello| {
            h.law = wire::fixed_str("relev_py");
            set_params(h, doc);
        }
    };
    assert_refused(
        "touch",
        "relev_py.py",
        relev("touch_um = -3"),
        7,
        &["law relev_py: controller.params.touch_um = -3 µm: must be a finite number > 0"],
    );
    assert_refused(
        "calm",
        "relev_py.py",
        relev("calm_ms = \"long\""),
        7,
        &["law relev_py: controller.params.calm_ms = \"long\" ms: expected a number (ms)"],
    );
    assert_refused(
        "order",
        "relev_py.py",
        relev("touch_um = 100.0\nrelease_um = 120.0"),
        7,
        &["controller.params.release_um = 120.0 µm: must be below controller.params.touch_um = 100.0 µm"],
    );
    assert_refused(
        "unknown",
        "relev_py.py",
        relev("enter_um = 100.0"),
        7,
        &["law relev_py: unknown parameter controller.params.enter_um = 100.0", "touch_um, release_um, calm_ms"],
    );
}

/// The kit's parameter reader gives the Rust reader's messages for the same documents.
#[test]
fn python_law_parameters_are_checked_with_the_rust_messages() {
    use controller::{Check, Params};
    // (document, key, unit, check, its name in the kit)
    let cases: &[(&str, &str, &str, Check, &str)] = &[
        ("hold_ms = -5.0", "hold_ms", "ms", Check::NonNegative, "Check.NON_NEGATIVE"),
        ("enter_um = -3", "enter_um", "µm", Check::Positive, "Check.POSITIVE"),
        ("enter_um = \"far\"", "enter_um", "µm", Check::Positive, "Check.POSITIVE"),
        ("xi = 1.5", "xi", "", Check::Between(0.0, 1.0), "Check.between(0.0, 1.0)"),
        ("xi = true", "xi", "", Check::Finite, "Check.FINITE"),
        ("xi = nan", "xi", "", Check::Finite, "Check.FINITE"),
        ("xi = -inf", "xi", "", Check::Finite, "Check.FINITE"),
        ("xi = 1e-300\nother = [1, 2]", "xi", "", Check::Positive, "Check.POSITIVE"),
        ("other = { a = 1 }", "xi", "", Check::Positive, "Check.POSITIVE"),
    ];
    let mut script = String::from("from amb_testbed_controller import Check, ParamError, Params\n");
    for (doc, key, unit, _, check) in cases {
        script += &format!(
            "p = Params.parse('law1', {doc:?})\ntry:\n    p.number({key:?}, {unit:?}, 1.0, {check})\n    p.finish()\n    print('ok')\nexcept ParamError as e:\n    print(e)\n"
        );
    }
    let out = output_within(Command::new(python()).args(["-c", &script]), LIMIT);
    assert_exit(&out, 0);
    let python: Vec<String> = String::from_utf8(out.stdout).unwrap().lines().map(str::to_string).collect();
    let rust: Vec<String> = cases
        .iter()
        .map(|(doc, key, unit, check, _)| {
            let p = Params::parse(doc).unwrap();
            let mut r = p.reader("law1");
            match r.number(key, unit, 1.0, *check).and_then(|_| r.finish()) {
                Ok(()) => "ok".to_string(),
                Err(e) => e.to_string(),
            }
        })
        .collect();
    assert_eq!(python, rust);
}

/// The kit's own examples (doctests) hold.
#[test]
fn the_kit_doctests_pass() {
    let script = "import doctest, sys, amb_testbed_controller.law as m\nr = doctest.testmod(m)\nprint(r)\nsys.exit(r.failed > 0 or r.attempted == 0)";
    let out = output_within(Command::new(python()).args(["-c", script]), LIMIT);
    assert_exit(&out, 0);
}

/// SIGTERM: the controller tells the plant with a STOPPING frame, then exits 130.
#[test]
fn sigterm_to_the_python_controller_sends_stopping_and_exits_130() {
    let id = run_id("sigterm");
    let mut plant = TestPlant::open(&id);
    let ctl = Proc::spawn(&mut python_controller("pd.py", &["--run-id", &id, "--connect-timeout-s", "60"]));
    let h = hello(&id);
    assert_eq!(plant.handshake(h).status, 0);
    plant.frames.send_and_wake(sensor_frame(&h, 0, h.token, [0.0; 2])).unwrap();
    assert!(plant.reply_within(Duration::from_secs(30)).is_some());
    ctl.signal(libc::SIGTERM);
    let bye = plant.reply_within(Duration::from_secs(30)).expect("a STOPPING frame");
    assert_eq!((bye.status, bye.token, bye.session), (CommandFrame::STOPPING, h.token, h.session));
    let (code, log) = ctl.finish_within(Duration::from_secs(30));
    assert_eq!(code, Some(130), "{log}");
    assert!(log.contains("interrupted"), "{log}");
}

/// The plant's node gone after the handshake, or no plant at all: exit 4; a bad run id: exit 2.
#[test]
fn the_python_controller_exits_4_without_a_plant_and_2_on_bad_arguments() {
    let id = run_id("gone");
    let plant = TestPlant::open(&id);
    let ctl = Proc::spawn(&mut python_controller("pd.py", &["--run-id", &id, "--connect-timeout-s", "60"]));
    assert_eq!(plant.handshake(hello(&id)).status, 0);
    drop(plant);
    let (code, log) = ctl.finish_within(Duration::from_secs(30));
    assert_eq!(code, Some(4), "{log}");
    assert!(log.contains("is gone"), "{log}");

    let lonely = output_within(
        &mut python_controller("pd.py", &["--run-id", &run_id("lonely"), "--connect-timeout-s", "0.3"]),
        LIMIT,
    );
    assert_exit(&lonely, 4);
    assert!(stderr(&lonely).contains("no hello from a plant"), "{}", stderr(&lonely));

    let bad = output_within(&mut python_controller("pd.py", &["--run-id", "a/b"]), LIMIT);
    assert_exit(&bad, 2);
    assert!(stderr(&bad).contains("run id 'a/b'"), "{}", stderr(&bad));
    let rt = output_within(
        python_controller("pd.py", &["--run-id", &run_id("rt")]).env("AMB_TESTBED_REALTIME_PRIORITY", "120"),
        LIMIT,
    );
    assert_exit(&rt, 2);
    assert!(
        stderr(&rt).contains("AMB_TESTBED_REALTIME_PRIORITY=120: must be an integer from 0 (off) to 99"),
        "{}",
        stderr(&rt)
    );
    let env = output_within(
        python_controller("pd.py", &["--connect-timeout-s", "0.3"]).env("AMB_TESTBED_RUN_ID", run_id("env")),
        LIMIT,
    );
    assert_exit(&env, 4);
    assert!(stderr(&env).contains(&run_id("env")), "{}", stderr(&env));
}

/// One live controller per run id: a second one (Python or Rust) is refused with exit 2,
/// naming the first; the lock goes with the process that held it.
#[test]
fn a_second_python_controller_under_a_live_run_id_is_refused() {
    let dir = TempDir::new("py-lock");
    let id = run_id("lock");
    let first = Proc::spawn(
        python_controller("pd.py", &["--run-id", &id, "--connect-timeout-s", "60"])
            .env("AMB_TESTBED_LOCK_DIR", dir.join("locks")),
    );
    let lock = dir.join("locks").join(format!("{id}.controller.lock"));
    let until = Instant::now() + Duration::from_secs(30);
    while !std::fs::read_to_string(&lock).is_ok_and(|t| t.contains(&format!("pid {}", first.id()))) {
        assert!(Instant::now() < until, "the first controller did not take {}", lock.display());
        std::thread::sleep(Duration::from_millis(20));
    }
    let second = output_within(
        python_controller("pd.py", &["--run-id", &id, "--connect-timeout-s", "0.3"])
            .env("AMB_TESTBED_LOCK_DIR", dir.join("locks")),
        LIMIT,
    );
    assert_exit(&second, 2);
    let err = stderr(&second);
    assert!(err.contains("is in use by a live controller") && err.contains(&format!("pid {}", first.id())), "{err}");
    first.signal(libc::SIGTERM);
    let (code, log) = first.finish_within(Duration::from_secs(30));
    assert_eq!(code, Some(130), "{log}");
    assert!(!lock.exists(), "the released lock's file is left behind (issue 21 item 7)");
    let third = output_within(
        python_controller("pd.py", &["--run-id", &id, "--connect-timeout-s", "0.3"])
            .env("AMB_TESTBED_LOCK_DIR", dir.join("locks")),
        LIMIT,
    );
    assert_exit(&third, 4); // the lock was free again: it waited for a hello
}

/// The wake protocol on the controller's side, watched through extra ports on the run's
/// services: the controller notifies the `command` event service after a reply only when
/// the plant asked (a `WakeRequest` on `command/wake`), and asks to be woken (a
/// `WakeRequest` on `sensor/wake`) before it blocks.
#[test]
fn the_python_controller_serves_and_makes_wake_requests() {
    use iceoryx2::prelude::*;
    let id = run_id("wake");
    let plant = TestPlant::open(&id);
    let ctl = Proc::spawn(&mut python_controller("pd.py", &["--run-id", &id, "--connect-timeout-s", "60"]));
    let h = hello(&id);
    assert_eq!(plant.handshake(h).status, 0);
    let service = |what: &str| ServiceName::new(&wire::name(&id, what)).unwrap();
    let pubsub = |what: &str| {
        plant
            ._node
            .service_builder(&service(what))
            .publish_subscribe::<wire::WakeRequest>()
            .subscriber_max_buffer_size(link::BUFFER)
            .history_size(0)
            .enable_safe_overflow(true)
            .max_publishers(link::MAX_PORTS)
            .max_subscribers(link::MAX_PORTS)
            .max_nodes(link::MAX_NODES)
            .open_or_create()
            .expect("wake service")
    };
    let asks = pubsub("command/wake").publisher_builder().create().unwrap();
    let requests = pubsub("sensor/wake").subscriber_builder().create().unwrap();
    let events = plant
        ._node
        .service_builder(&service("command"))
        .event()
        .max_notifiers(link::MAX_PORTS)
        .max_listeners(link::MAX_PORTS)
        .max_nodes(link::MAX_NODES)
        .open_or_create()
        .expect("event service")
        .listener_builder()
        .create()
        .unwrap();
    let notified = || {
        let mut n = 0;
        events.try_wait(|_| n += 1).unwrap();
        n
    };
    // Idle past its spin budget (0.2 ms), the controller has asked to be woken.
    let until = Instant::now() + Duration::from_secs(30);
    while requests.receive().unwrap().is_none() {
        assert!(Instant::now() < until, "the idle controller published no wake request within 30 s");
        std::thread::sleep(Duration::from_millis(1));
    }
    while requests.receive().unwrap().is_some() {}
    notified();
    // Not asked: no notification. Asked: one.
    for (seq, ask) in [(0, false), (1, true), (2, false), (3, true)] {
        if ask {
            asks.send_copy(wire::WakeRequest { seq }).unwrap();
        }
        plant.frames.send_and_wake(sensor_frame(&h, seq, h.token, [0.01, 0.02])).unwrap();
        let reply = plant.poll_reply_within(Duration::from_secs(30)).expect("a reply");
        assert_eq!(reply.seq, seq);
        // The notification follows the reply: wait for it when asked; else give it time to show.
        let until = Instant::now() + if ask { Duration::from_secs(30) } else { Duration::from_millis(50) };
        let mut n = 0;
        while n == 0 && Instant::now() < until {
            n += notified();
            std::thread::sleep(Duration::from_millis(1));
        }
        assert_eq!(n > 0, ask, "frame {seq}: asked {ask}, notified {n} times");
    }
    plant
        .frames
        .send_and_wake(SensorFrame { status: SensorFrame::STOP, ..sensor_frame(&h, 0, h.token, [0.0; 2]) })
        .unwrap();
    let (code, log) = ctl.finish_within(Duration::from_secs(30));
    assert_eq!(code, Some(0), "{log}");
}

/// The shipped Python re-levitation scene, run as a user runs it: the plant starts
/// `python3 relev_py.py` from the scene's `controller.command` (the venv's `python3` first on
/// `PATH`, as after `. .venv/bin/activate`), and the law brings the rotor back after the
/// 10 G shock well before the end of the run. Without the rule (`arm_ms` past the run) the
/// same scene bounces until about 0.37 s, so a law that never switched would fail here.
#[test]
fn the_python_relevitation_scene_runs_through_controller_command_and_recovers() {
    let dir = TempDir::new("py-relev-command");
    let scene = workspace_root().join("examples/python/relev-py.toml");
    let path = format!("{}:{}", venv().join("bin").display(), std::env::var("PATH").unwrap_or_default());
    let mut cmd = plant_run(&scene, &dir.join("run"), &["output.plots=false"]);
    cmd.env("PATH", &path);
    let out = output_within(&mut cmd, LIMIT);
    assert_exit(&out, 0);
    let s = read_json(&dir.join("run").join("summary.json"));
    assert_eq!(s["status"], "completed", "{s:#}");
    assert_eq!(s["post_shock_mode"], "recovered", "{s:#}");
    let recovery = num(&s, "recovery_s");
    assert!(recovery > 0.0 && recovery < 0.1, "recovery_s = {recovery} s in {s:#}");
    let c = &s["cosim"];
    assert!(c["controller"].as_str().unwrap().starts_with("relev_py"), "{c:#}");
    assert_eq!(num(c, "invalid_replies"), 0.0, "{c:#}");
}

/// Laws that answer wrongly on purpose, for [`python_laws_that_answer_wrongly_are_refused`]:
/// each answers correctly (zero currents) before sample 100, then as its name says.
const BAD_LAWS: &str = r#"
import sys
from amb_testbed_controller import serve

class PlaneLaw:
    answer = (0.0, 0.0)
    def __init__(self, design, params):
        pass
    def update(self, sample):
        return self.answer if sample.seq >= 100 else (0.0, 0.0)

class Inf(PlaneLaw):
    name = "inf"
    answer = (float("inf"), float("-inf"))

class Three(PlaneLaw):
    name = "three"
    answer = (0.0, 0.0, 1.0)

class RotorLaw:
    whole_rotor = True
    count = 4
    def __init__(self, design, params):
        self.axes = design.axes
    def update(self, sample):
        return tuple(0.0 for _ in range(self.count if sample.seq >= 100 else self.axes))

class Short(RotorLaw):
    name = "short"
    count = 3

class Long(RotorLaw):
    name = "long"
    count = 5

serve(Inf, Three, Short, Long)
"#;

/// Issue 31 item 7, the Python kit: a law answering ±∞ had them clamped to its limit and
/// counted valid; a law of the whole rotor answering the wrong number of currents had the
/// extras dropped or plane B fed other values (exit 0). ±∞ is an invalid command (exit 8, as
/// NaN); a wrong count is refused at once, naming the law, the sample and the count (the kit
/// exits 2, nothing sent; the plant: the controller lost, its message quoted, exit 4).
#[test]
fn python_laws_that_answer_wrongly_are_refused() {
    let dir = TempDir::new("py-bad-laws");
    let script = dir.join("bad_laws.py");
    std::fs::write(&script, BAD_LAWS).unwrap();
    let command = format!(
        "controller.command={}",
        toml::Value::from(vec![python().display().to_string(), script.display().to_string()])
    );
    // (law, scene, plant's exit code, status, what stderr names)
    let cases: [(&str, &str, i32, &str, &[&str]); 5] = [
        ("inf", "cosim-10g.toml", 8, "invalid_commands", &["non-finite for 11 samples in a row, from sample 100"]),
        (
            "three",
            "cosim-10g.toml",
            4,
            "peer_lost",
            &["law three answered sample 100", "with 3 currents", "it must answer 2"],
        ),
        (
            "three",
            "two-plane-asymmetric-10g.toml",
            4,
            "peer_lost",
            &["law three answered sample 100", "with 3 currents", "i_x, i_y of plane A"],
        ),
        (
            "short",
            "two-plane-asymmetric-10g.toml",
            4,
            "peer_lost",
            &["law short answered sample 100", "with 3 currents", "it must answer 4"],
        ),
        ("long", "two-plane-asymmetric-10g.toml", 4, "peer_lost", &["law long answered sample 100", "with 5 currents"]),
    ];
    for (law, scene_file, code, status, needles) in cases {
        let name = format!("{law}-{}", scene_file.split('-').next().unwrap());
        let out = dir.join(&name);
        let law_set = format!("controller.law=\"{law}\"");
        let sets = [
            "scene.duration_s=0.02",
            "output.plots=false",
            "controller.mode=\"lockstep\"",
            law_set.as_str(),
            command.as_str(),
        ];
        let run = output_within(&mut plant_run(&scene(scene_file), &out, &sets), LIMIT);
        assert_exit(&run, code);
        let err = stderr(&run);
        for n in needles {
            assert!(err.contains(n), "{name}: no {n:?} in\n{err}");
        }
        let s = read_json(&out.join("summary.json"));
        assert_eq!(s["status"], status, "{name}: {s:#}");
    }
}
