//! End-to-end tests of controllers from anywhere (issue 10, items 3, 4 and 6):
//! a controller crate outside the workspace, built and run in lockstep; any
//! executable as `controller.command`, with the contract it gets (argument,
//! environment, paths, respawn) and the bad ones refused with a message, an
//! exit code and `summary.json`; the C header checked against `controller/src/wire/`.
//! Every process is bounded in time.

mod common;

use common::{
    assert_exit, controller_bin, num, output_within, plant_run, read_json, rogue_bin, scene, stderr, workspace_root,
    write_script, Csv, TempDir, SHORT,
};
use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};

/// The example crate's law, compiled here from its own source: the trace of the out-of-tree
/// controller process is checked against this code run in this process.
#[allow(dead_code)]
#[path = "../../examples/rust-controller/src/lib.rs"]
mod pd_notch;

/// The most any one command of this file may take (debug build, a loaded 2-core machine).
const LIMIT: Duration = Duration::from_secs(300);

fn output(cmd: &mut Command) -> std::process::Output {
    output_within(cmd, LIMIT)
}

/// `SHORT` plus extra overrides.
fn sets(extra: &[String]) -> Vec<String> {
    SHORT.iter().map(|s| s.to_string()).chain(extra.iter().cloned()).collect()
}

fn as_strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

/// `controller.command=[…]` as a `--set` override.
fn command_set(argv: &[&str]) -> String {
    let items: Vec<String> = argv.iter().map(|a| format!("{a:?}")).collect();
    format!("controller.command=[{}]", items.join(", "))
}

/// The target folder this test binary was built in (`<target>/<profile>/deps/<test>`).
fn target_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("the test's own path");
    exe.ancestors().nth(3).expect("<target>/<profile>/deps/<test>").to_path_buf()
}

/// Issue 10 item 3: a controller crate outside the workspace, depending on `controller` by
/// path, is built (offline, locked, into the workspace's target folder so the shared
/// dependencies are reused) and run by the plant through `controller.command` in lockstep.
/// Its trace is what its law gives: the run folder replayed through the example's own code
/// (`plant::check::replay`) reproduces every applied current bit for bit, differs from the
/// plain PD's, and the law run in the plant's process (`plant::check::run_law`) gives the
/// same trace.
#[test]
fn an_out_of_tree_rust_controller_runs_in_lockstep_and_its_law_gives_the_trace() {
    let crate_dir = workspace_root().join("examples").join("rust-controller");
    let started = Instant::now();
    let mut build = Command::new(env!("CARGO"));
    build.current_dir(&crate_dir).env("CARGO_TARGET_DIR", target_dir()).args([
        "build",
        "--offline",
        "--locked",
        "-q",
        "--message-format=json",
        "--bin",
        "pd-notch-controller",
    ]);
    if !cfg!(debug_assertions) {
        build.arg("--release");
    }
    let built = output(&mut build);
    assert!(built.status.success(), "building the example crate: {}", stderr(&built));
    let exe = String::from_utf8_lossy(&built.stdout)
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter(|m| m["reason"] == "compiler-artifact" && m["target"]["name"] == "pd-notch-controller")
        .find_map(|m| m["executable"].as_str().map(PathBuf::from))
        .expect("the example's executable");
    eprintln!("example crate built in {:.1} s", started.elapsed().as_secs_f64());

    let dir = TempDir::new("out-of-tree");
    let out = dir.join("run");
    let scene_file = crate_dir.join("pd-notch-10g.toml");
    let extra = sets(&[command_set(&[&exe.display().to_string()])]);
    let run = output(&mut plant_run(&scene_file, &out, &as_strs(&extra)));
    assert_exit(&run, 0);
    let s = read_json(&out.join("summary.json"));
    assert!(s["cosim"]["controller"].as_str().unwrap().starts_with("pd_notch:"), "{s:#}");
    assert_eq!(s["cosim"]["controller_command"][0].as_str(), Some(exe.display().to_string().as_str()));

    // The run folder replayed through the crate's law (plant::check, issue 21 item 3): every
    // applied current is the law's, bit for bit; through the plain PD it is not.
    let replayed = plant::check::replay(&out, &pd_notch::LAW).expect("the replay");
    eprintln!("replay of the out-of-tree crate's lockstep run through its law: {replayed}");
    assert!(replayed.identical(), "{replayed}");
    assert_eq!(replayed.compared, 1000);
    let scene = plant::config::load_scene(&out.join("scene.toml"), &[]).expect("the run's scene");
    let mut pd = controller::build_law("pd", &scene.plane_design(0), &controller::Params::default()).unwrap();
    let pd = plant::check::replay_trace(&scene, &out.join("trace.csv"), pd.as_mut()).expect("the replay");
    assert!(!pd.identical() && pd.largest_a > 1e-3, "the notch changed nothing: {pd}");
    // And the same law run in the plant's process gives the same trace.
    let in_process = plant::check::run_law(&scene, &pd_notch::LAW, &mut plant::run::Quiet).expect("the run");
    let trace = Csv::read(&out.join("trace.csv"));
    assert_eq!(in_process.trace.loads.ix_a, trace.column("ix_a"));
    assert_eq!(in_process.trace.motion.dy_m, trace.column("dy_m"));
}

/// Issue 10 item 4: the contract a command gets. The plant runs it exactly, with `--run-id
/// ID` appended and `AMB_TESTBED_RUN_ID`, `AMB_TESTBED_CONNECT_TIMEOUT_S` set; a relative
/// path that exists in the scene's folder is taken from there (and written absolute in the
/// run folder's `scene.toml`); a command that dies is respawned, as the built-in one.
#[cfg(unix)]
#[test]
fn a_command_gets_the_run_id_and_is_respawned_after_a_crash() {
    let dir = TempDir::new("command-contract");
    let scene_file = dir.join("scene.toml");
    std::fs::copy(scene("paper-10g.toml"), &scene_file).unwrap();
    let wrapper = dir.join("wrap.sh");
    let log = dir.join("calls.txt");
    write_script(
        &wrapper,
        &format!(
            "#!/bin/sh\nprintf 'args %s | env %s %s\\n' \"$*\" \"$AMB_TESTBED_RUN_ID\" \"$AMB_TESTBED_CONNECT_TIMEOUT_S\" >> {log:?}\nexec {:?} \"$@\"\n",
            controller_bin().display().to_string()
        ),
    );
    let out = dir.join("run");
    let id = format!("t{}-contract", std::process::id());
    let extra = sets(&[
        "controller.mode=lockstep".into(),
        "controller.reconnect_timeout_ms=20000".into(),
        command_set(&["wrap.sh", "--quiet"]),
    ]);
    let mut cmd = plant_run(&scene_file, &out, &as_strs(&extra));
    cmd.args(["--run-id", &id]).env("AMB_CONTROLLER_CRASH_AT_SEQ", "300");
    let run = output(&mut cmd);
    assert_exit(&run, 0);
    let calls = std::fs::read_to_string(&log).unwrap();
    let expected = format!("args --quiet --run-id {id} | env {id} 10\n");
    assert_eq!(calls, expected.repeat(2), "one call, then the respawn after the crash");
    let s = read_json(&out.join("summary.json"));
    assert_eq!(num(&s["cosim"], "sessions"), 2.0, "{s:#}");
    let absolute = std::path::absolute(&wrapper).unwrap().display().to_string();
    assert_eq!(s["cosim"]["controller_command"][0].as_str(), Some(absolute.as_str()), "{s:#}");
    let recorded = std::fs::read_to_string(out.join("scene.toml")).unwrap();
    assert!(recorded.contains(&absolute), "{recorded}");
}

/// Issue 10, bad input: a command that does not exist, is not executable, exits at once,
/// answers with another protocol version or other message types, or does not serve the
/// scene's law: each is named, with its exit code and the run folder's `summary.json`.
#[cfg(unix)]
#[test]
fn bad_controller_commands_are_named_with_their_exit_code_and_status() {
    use std::os::unix::fs::PermissionsExt;
    let dir = TempDir::new("bad-commands");
    let plain = dir.join("plain.sh");
    std::fs::write(&plain, "#!/bin/sh\nexit 0\n").unwrap();
    std::fs::set_permissions(&plain, std::fs::Permissions::from_mode(0o644)).unwrap();
    let rogue = rogue_bin().display().to_string();
    let controller = controller_bin().display().to_string();
    let plain = plain.display().to_string();
    // (command, an extra override, exit code, status, what stderr must name)
    type Case<'a> = (Vec<&'a str>, Option<&'a str>, i32, &'a str, Vec<&'a str>);
    let cases: Vec<Case> = vec![
        (vec!["/no/such/controller"], None, 2, "not_started", vec!["controller.command", "/no/such/controller"]),
        (vec![&plain], None, 2, "not_started", vec!["not executable", "plain.sh"]),
        (vec!["false"], None, 4, "not_started", vec!["exited before the handshake", "`false`"]),
        (
            vec![&rogue, "--mode", "types"],
            None,
            2,
            "refused",
            vec!["other message types", "exited before the handshake"],
        ),
        (vec![&rogue, "--mode", "version"], None, 2, "refused", vec!["protocol version 5", "speaks version 4"]),
        (
            vec![&controller],
            Some("controller.law=\"nope\""),
            2,
            "refused",
            vec!["unknown controller law `nope`", "known laws: pd, pid"],
        ),
    ];
    for (i, (argv, law, code, status, needles)) in cases.iter().enumerate() {
        let out = dir.join(&format!("run{i}"));
        let mut extra = vec!["controller.mode=lockstep".to_string(), command_set(argv)];
        extra.extend(law.map(str::to_string));
        let run = output(&mut plant_run(&scene("paper-10g.toml"), &out, &as_strs(&sets(&extra))));
        assert_exit(&run, *code);
        let err = stderr(&run);
        for n in needles {
            assert!(err.contains(n), "{argv:?}: no {n:?} in\n{err}");
        }
        let s = read_json(&out.join("summary.json"));
        assert_eq!(s["status"], *status, "{argv:?}: {s:#}");
        assert!(!s["error"].as_str().unwrap_or_default().is_empty(), "{argv:?}: {s:#}");
        assert!(out.join("scene.toml").is_file());
    }
}

/// The header's `#define AMB_TESTBED_<NAME> value` lines, by name (the include guard and
/// the helper macros left out); a value is a number (a `u` suffix dropped) or a string.
fn header_defines(header: &str) -> Vec<(String, String)> {
    header
        .lines()
        .filter_map(|l| l.trim().strip_prefix("#define AMB_TESTBED_"))
        .filter_map(|rest| {
            let (name, value) = rest.split_once(char::is_whitespace)?;
            let value = value.split("/*").next().unwrap().trim();
            Some((name.to_string(), value.trim_end_matches('u').to_string()))
        })
        .filter(|(name, _)| !matches!(name.as_str(), "STATIC_ASSERT" | "ALIGNOF"))
        .collect()
}

/// The header's structs: `typedef struct amb_testbed_<Name> { … } amb_testbed_<Name>;`, each
/// with its fields' names in order.
fn header_structs(header: &str) -> Vec<(String, Vec<String>)> {
    let mut out = Vec::new();
    let mut current: Option<(String, Vec<String>)> = None;
    for line in header.lines() {
        let line = line.split("/*").next().unwrap().trim();
        if let Some(rest) = line.strip_prefix("typedef struct amb_testbed_") {
            current = Some((rest.trim_end_matches('{').trim().to_string(), Vec::new()));
        } else if line.starts_with('}') {
            out.extend(current.take());
        } else if let Some((_, fields)) = current.as_mut() {
            let decl = line.trim_end_matches(';');
            let name = decl.split('[').next().unwrap().split_whitespace().last();
            fields.extend(name.map(str::to_string));
        }
    }
    out
}

/// Issue 20: the wire's constants and layouts reach the C header from one source or this test
/// fails naming the difference. It reads every `#define` and every struct field of
/// `controller/include/amb_testbed_wire.h`, compiles a program with the header (C11 and C++11,
/// warnings as errors: its `_Static_assert`s hold) that prints each field's offset and size,
/// and compares all of it with `controller::wire::constants()` and `layouts()`.
#[test]
fn the_c_header_has_every_constant_and_layout_of_wire_rs() {
    use controller::wire::{constants, layouts, Constant};
    let include = workspace_root().join("controller").join("include");
    let header = std::fs::read_to_string(include.join("amb_testbed_wire.h")).unwrap();
    let mut differences = Vec::new();

    // Constants, both ways.
    let in_header: Vec<(String, String)> = header_defines(&header).into_iter().filter(|(n, _)| n != "WIRE_H").collect();
    let rust: Vec<(String, String)> = constants()
        .into_iter()
        .map(|(n, v)| match v {
            Constant::Number(x) => (n, x.to_string()),
            Constant::Text(t) => (n, format!("{t:?}")),
        })
        .collect();
    for (name, value) in &rust {
        match in_header.iter().find(|(n, _)| n == name) {
            None => differences.push(format!("AMB_TESTBED_{name}: missing from the header (Rust: {value})")),
            Some((_, v)) if v != value => {
                differences.push(format!("AMB_TESTBED_{name}: the header says {v}, Rust {value}"))
            }
            Some(_) => {}
        }
    }
    for (name, value) in &in_header {
        if !rust.iter().any(|(n, _)| n == name) {
            differences.push(format!("AMB_TESTBED_{name} = {value}: in the header, not in wire::constants()"));
        }
    }

    // Structs and fields, by name and order.
    let structs = header_structs(&header);
    let rust_layouts = layouts();
    let names =
        |fields: &[controller::wire::FieldLayout]| fields.iter().map(|f| f.name.to_string()).collect::<Vec<_>>();
    for m in &rust_layouts {
        match structs.iter().find(|(n, _)| n == m.name) {
            None => differences.push(format!("amb_testbed_{}: missing from the header", m.name)),
            Some((_, fields)) if *fields != names(&m.fields) => differences.push(format!(
                "amb_testbed_{}: the header's fields {fields:?}, Rust's {:?}",
                m.name,
                names(&m.fields)
            )),
            Some(_) => {}
        }
    }
    for (name, _) in &structs {
        if !rust_layouts.iter().any(|m| m.name == name) {
            differences.push(format!("amb_testbed_{name}: in the header, not in wire::layouts()"));
        }
    }

    // Sizes, alignments and offsets as the C compiler lays the header's structs out.
    let mut program = String::from("#include <stdio.h>\n#include \"amb_testbed_wire.h\"\nint main(void) {\n");
    for (name, fields) in &structs {
        let ty = format!("amb_testbed_{name}");
        program += &format!("    printf(\"{name} - %zu %zu\\n\", sizeof({ty}), (size_t)AMB_TESTBED_ALIGNOF({ty}));\n");
        for f in fields {
            program +=
                &format!("    printf(\"{name} {f} %zu %zu\\n\", offsetof({ty}, {f}), sizeof((({ty} *)0)->{f}));\n");
        }
    }
    program += "    return 0;\n}\n";
    let dir = TempDir::new("c-header");
    std::fs::write(dir.join("layout.c"), &program).unwrap();
    std::fs::write(dir.join("layout.cpp"), &program).unwrap();
    let exe = dir.join("layout");
    let compiled = output(
        Command::new("cc")
            .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-pedantic", "-I"])
            .arg(&include)
            .arg(dir.join("layout.c"))
            .arg("-o")
            .arg(&exe),
    );
    assert!(compiled.status.success(), "cc failed:\n{}", stderr(&compiled));
    let cpp = output(
        Command::new("c++")
            .args(["-std=c++11", "-Wall", "-Wextra", "-Werror", "-fsyntax-only", "-I"])
            .arg(&include)
            .arg(dir.join("layout.cpp")),
    );
    assert!(cpp.status.success(), "c++ failed:\n{}", stderr(&cpp));
    let ran = output(&mut Command::new(&exe));
    assert!(ran.status.success());
    let c: Vec<String> = String::from_utf8_lossy(&ran.stdout).lines().map(str::to_string).collect();
    for m in &rust_layouts {
        let whole = format!("{} - {} {}", m.name, m.size, m.align);
        if !c.contains(&whole) {
            differences.push(format!(
                "amb_testbed_{}: C gives {:?}, Rust {whole}",
                m.name,
                c.iter().find(|l| l.starts_with(&format!("{} - ", m.name)))
            ));
        }
        for f in &m.fields {
            let line = format!("{} {} {} {}", m.name, f.name, f.offset, f.size);
            if !c.contains(&line) {
                let got = c.iter().find(|l| l.starts_with(&format!("{} {} ", m.name, f.name)));
                differences.push(format!(
                    "amb_testbed_{}.{}: C gives {got:?}, Rust (offset, size) ({}, {})",
                    m.name, f.name, f.offset, f.size
                ));
            }
        }
    }
    assert!(differences.is_empty(), "the C header differs from controller::wire:\n{}", differences.join("\n"));
    let lines: usize = rust_layouts.iter().map(|m| 1 + m.fields.len()).sum();
    assert!(
        rust.len() >= 29 && c.len() == lines,
        "{} constants; {} C lines for {lines} sizes and fields",
        rust.len(),
        c.len()
    );
}

/// Issue 21 item 5: the controller inherited the plant's stdout; when that was a pipe nobody
/// drained, a chatty controller blocked before its hello and the plant exited 4 after the
/// connect timeout with no hint why. Its output now goes to `controller.log` in the run
/// folder (bounded), drained as it comes: the run completes with the plant's stdout a pipe
/// nobody reads, and a controller that fails is quoted, naming the file.
#[cfg(unix)]
#[test]
fn the_controllers_output_goes_to_controller_log_and_never_blocks_it() {
    let dir = TempDir::new("controller-log");
    let chatty = dir.join("chatty.sh");
    // 3 MiB on stdout (a pipe holds 64 KiB), a line on stderr, then the real controller.
    write_script(
        &chatty,
        &format!(
            "#!/bin/sh\nhead -c 3145728 /dev/zero | tr '\\0' x\necho 'chatty: starting' >&2\nexec {:?} \"$@\"\n",
            controller_bin().display().to_string()
        ),
    );
    let failing = dir.join("failing.sh");
    write_script(&failing, "#!/bin/sh\necho 'failing: cannot open my gains file' >&2\nexit 3\n");

    let out = dir.join("run");
    let extra = sets(&["controller.mode=lockstep".into(), command_set(&[&chatty.display().to_string()])]);
    let mut cmd = plant_run(&scene("paper-10g.toml"), &out, &as_strs(&extra));
    let stderr_file = dir.join("plant.stderr");
    // The plant's stdout: a pipe that nobody reads (kept open, never drained).
    let mut plant = cmd
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::fs::File::create(&stderr_file).unwrap())
        .spawn()
        .unwrap();
    let started = Instant::now();
    let status = loop {
        if let Some(s) = plant.try_wait().unwrap() {
            break s;
        }
        if started.elapsed() > LIMIT {
            let _ = plant.kill();
            panic!("the run did not end within {LIMIT:?}: {}", std::fs::read_to_string(&stderr_file).unwrap());
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(status.code(), Some(0), "{}", std::fs::read_to_string(&stderr_file).unwrap());
    let log = std::fs::read(out.join("controller.log")).unwrap();
    let text = String::from_utf8_lossy(&log);
    assert!(text.starts_with("--- plant: started `"), "{}", &text[..200]);
    assert!(text.contains("chatty: starting"), "the last output is kept");
    assert!(text.contains("bytes of the controller's output left out here"));
    assert!(log.len() < 2 << 20, "controller.log is bounded: {} bytes", log.len());

    let out = dir.join("failed");
    let extra = sets(&["controller.mode=lockstep".into(), command_set(&[&failing.display().to_string()])]);
    let run = output(&mut plant_run(&scene("paper-10g.toml"), &out, &as_strs(&extra)));
    assert_exit(&run, 4);
    let err = stderr(&run);
    assert!(
        err.contains("controller.log")
            && err.contains("failing: cannot open my gains file")
            && err.contains("exit status: 3"),
        "{err}"
    );
    assert!(read_json(&out.join("summary.json"))["error"]
        .as_str()
        .unwrap_or_default()
        .contains("cannot open my gains file"));
    assert!(std::fs::read_to_string(out.join("controller.log"))
        .unwrap()
        .contains("failing: cannot open my gains file"));
}
