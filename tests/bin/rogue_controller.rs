//! A controller that misbehaves on purpose, for the end-to-end tests of the
//! plant's defences (not shipped, not documented for users). The plant starts
//! it through `controller.command = [this, "--mode", MODE]` and appends
//! `--run-id ID`; or a test starts it with both.
//!
//! Modes:
//! - `types`: opens the run's `ack` service with other message types, as a
//!   controller of another protocol version would, and exits 2;
//! - `version`: answers the hello with an ack of the next protocol version (5);
//! - `two-axes`: a controller that can run two axes only (a planar one written against the
//!   wire): refuses a four-axis hello with status 3 (`Refusal::Axes`), as the protocol says;
//! - `other-session`: accepts the hello, then answers every sensor frame
//!   with the run's token but another session;
//! - `every-other`: answers only the sensor frames with an even `seq`;
//! - `nan`: answers with the law's currents, but NaN on x from sample 100 on (`--value V`: V
//!   instead of NaN, e.g. `inf` or `-inf`, on x, and its negative on y);
//! - `overrides`: acks with the overrides document `--overrides TEXT` (TOML), then answers
//!   with the law's currents;
//! - `late`: answers every frame `--late-us` µs (default 1000) after it came, too late for a
//!   realtime tick: a collapsed schedule, whatever the machine;
//! - `hang`: answers until sample `--die-at`, then sends nothing more while staying alive (a
//!   hung controller), until the plant is gone or 60 s passed;
//! - `die`: answers with the law's currents until sample `--die-at` (default 4000), then
//!   kills itself with SIGKILL, as a controller killed in the middle of a run;
//! - `no-wake`: answers every frame with the law's currents but never wakes
//!   the plant: it polls every millisecond, asks for no wake-up and does not
//!   serve `command/wake`.
//!
//! Every mode but `types` runs the registry's law the hello names, and ends
//! on the plant's STOP frame or when the plant's node is gone.

use controller::link::{self, Endpoint, Mailbox, Peer};
use controller::wire::{self, Ack, CommandFrame, Hello, SensorFrame};
use std::process::ExitCode;
use std::time::{Duration, Instant};

fn main() -> ExitCode {
    iceoryx2::prelude::set_log_level(iceoryx2::prelude::LogLevel::Fatal);
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| args.iter().position(|a| a == flag).and_then(|i| args.get(i + 1)).cloned();
    let mode = value("--mode").unwrap_or_default();
    let die_at: u64 = value("--die-at").and_then(|v| v.parse().ok()).unwrap_or(4000);
    let bad: f64 = value("--value").and_then(|v| v.parse().ok()).unwrap_or(f64::NAN);
    let late = Duration::from_micros(value("--late-us").and_then(|v| v.parse().ok()).unwrap_or(1000));
    let Some(id) = value("--run-id").or_else(|| std::env::var("AMB_TESTBED_RUN_ID").ok()) else {
        eprintln!("rogue-controller: no run id");
        return ExitCode::from(2);
    };
    let node = link::node(&id, "controller").expect("node");
    if mode == "types" {
        return match Mailbox::<SensorFrame, SensorFrame>::open(&node, &id, "ack", "hello") {
            Ok(_) => {
                eprintln!("rogue-controller: opened the plant's services with other types?");
                ExitCode::from(1)
            }
            Err(e) => {
                eprintln!("rogue-controller: {e}");
                ExitCode::from(2)
            }
        };
    }
    let handshake: Mailbox<Ack, Hello> = Mailbox::open(&node, &id, "ack", "hello").expect("handshake");
    let deadline = Instant::now() + Duration::from_secs(30);
    let hello = loop {
        if let Some(h) = handshake.try_receive().expect("hello") {
            break h;
        }
        if Instant::now() > deadline {
            eprintln!("rogue-controller: no hello");
            return ExitCode::from(4);
        }
        std::thread::sleep(Duration::from_millis(1));
    };
    let mut ack = Ack::new(hello.session, hello.token, 0, "pd", &format!("rogue controller, mode {mode}"));
    if mode == "overrides" {
        let text = value("--overrides").unwrap_or_default();
        ack = ack.with_overrides(&text).expect("overrides within 4096 bytes");
    }
    if mode == "two-axes" && hello.axes != wire::AXES {
        let why = format!("this controller runs {} axes, the plant asks for {}", wire::AXES, hello.axes);
        let refusal = Ack::new(hello.session, hello.token, wire::Refusal::Axes.code(), "pd", &why);
        handshake.send(refusal).expect("ack");
        std::thread::sleep(Duration::from_secs(1));
        return ExitCode::from(2);
    }
    if mode == "version" {
        ack.protocol_version = wire::PROTOCOL_VERSION + 1;
        handshake.send(ack).expect("ack");
        std::thread::sleep(Duration::from_secs(1));
        return ExitCode::SUCCESS;
    }
    let params = controller::Params::parse(hello.params_text().expect("params")).expect("params");
    let name = wire::str_of(&hello.law).into_owned();
    let mut law = controller::build_law(&name, &hello.design(), &params).expect("law");
    // The frame subscribers exist before the ack: the plant sends frame 0 right after it,
    // and a subscriber gets no history.
    let frames_polled: Option<Mailbox<CommandFrame, SensorFrame>> =
        (mode == "no-wake").then(|| Mailbox::open(&node, &id, "command", "sensor").expect("frames"));
    let mut frames: Option<Endpoint<CommandFrame, SensorFrame>> = (mode != "no-wake")
        .then(|| Endpoint::open(&node, &id, "command", "sensor", Duration::from_micros(200)).expect("frames"));
    handshake.send(ack).expect("ack");
    let session = if mode == "other-session" { hello.session + 1 } else { hello.session };
    let reply = |law: &mut Box<dyn controller::ControlLaw>, f: &SensorFrame| CommandFrame {
        seq: f.seq,
        token: hello.token,
        session,
        axes: wire::AXES,
        current_a: wire::axes_of(controller::saturate(
            law.update(&controller::Sample { seq: f.seq, t_s: f.t_s, sensor_v: f.sensor_xy(), ..Default::default() }),
            hello.current_limit_a,
        )),
        ..Default::default()
    };
    let plant_gone = || matches!(link::peer(&id, "plant"), Peer::Dead | Peer::Absent);
    if let Some(frames) = frames_polled {
        let mut last_check = Instant::now();
        loop {
            match frames.try_receive().expect("receive") {
                Some(f) if f.token == hello.token && f.status & SensorFrame::STOP != 0 => return ExitCode::SUCCESS,
                Some(f) if f.token == hello.token => frames.send(reply(&mut law, &f)).expect("reply"),
                _ => {
                    if last_check.elapsed() > Duration::from_millis(50) {
                        if plant_gone() {
                            return ExitCode::from(4);
                        }
                        last_check = Instant::now();
                    }
                    // Sleeps between polls (as a controller blocking on a timed wait without
                    // asking to be woken), and never notifies the plant.
                    std::thread::sleep(Duration::from_millis(1));
                }
            }
        }
    }
    let Some(mut frames) = frames.take() else { return ExitCode::from(1) };
    frames.set_spin(Duration::from_nanos(hello.spin_ns));
    let mut last_check = Instant::now();
    loop {
        let got = frames
            .wait(Duration::from_millis(1), || {
                if last_check.elapsed() < Duration::from_millis(50) {
                    return true;
                }
                last_check = Instant::now();
                !plant_gone()
            })
            .expect("wait");
        let Some(f) = got else { return ExitCode::from(4) };
        if f.token != hello.token {
            continue;
        }
        if f.status & SensorFrame::STOP != 0 {
            return ExitCode::SUCCESS;
        }
        if mode == "every-other" && f.seq % 2 == 1 {
            continue;
        }
        if mode == "die" && f.seq >= die_at {
            die();
        }
        if mode == "hang" && f.seq >= die_at {
            let until = Instant::now() + Duration::from_secs(60);
            while Instant::now() < until && !plant_gone() {
                std::thread::sleep(Duration::from_millis(20));
            }
            return ExitCode::from(4);
        }
        if mode == "late" {
            std::thread::sleep(late);
        }
        let mut r = reply(&mut law, &f);
        if mode == "nan" && f.seq >= 100 {
            r.current_a[0] = bad;
            r.current_a[1] = -bad;
        }
        frames.send(r).expect("reply");
    }
}

/// Ends the process by SIGKILL (no destructor, no STOPPING frame), as `kill -9` would.
fn die() -> ! {
    #[cfg(unix)]
    // SAFETY: raise(2) has no memory-safety preconditions.
    unsafe {
        libc::raise(libc::SIGKILL);
    }
    std::process::abort()
}
