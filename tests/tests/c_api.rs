//! The C API of the controller process (issue 21 item 1): `controller/c` builds
//! `libamb_testbed_controller.a` and `.so`; `controller/include/amb_testbed_controller.h`
//! declares it. Here: the header's layout and constants against the Rust definitions
//! (compiled as C11 and C++11 with the system compiler), the C and C++ `pd` examples built
//! against the static and the shared library and run by the plant in lockstep (their traces
//! byte-identical to the Rust `pd`'s), and the faults: a non-finite answer, an abort, a C++
//! exception, a NULL function, another ABI version, a refused design, refused parameters;
//! each with its message, its exit code and the plant's outputs. Every process is bounded.

mod common;

use common::{
    assert_exit, controller_bin, output_within, plant_run, read_json, scene, stderr, workspace_root, TempDir, SHORT,
};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::Duration;

/// The most any one command of this file may take (debug build, a loaded 2-core machine).
const LIMIT: Duration = Duration::from_secs(300);

fn output(cmd: &mut Command) -> std::process::Output {
    output_within(cmd, LIMIT)
}

/// The system libraries a Rust static library needs on Linux (`--print native-static-libs`).
const NATIVE_LIBS: &[&str] = &["-lgcc_s", "-lutil", "-lrt", "-lpthread", "-lm", "-ldl", "-lc"];

/// `libamb_testbed_controller.a` and `.so`, built once per test binary in this profile.
fn libraries() -> &'static (PathBuf, PathBuf) {
    static LIBS: OnceLock<(PathBuf, PathBuf)> = OnceLock::new();
    LIBS.get_or_init(|| {
        (common::workspace_lib("amb_testbed_controller", "a"), common::workspace_lib("amb_testbed_controller", "so"))
    })
}

fn include() -> PathBuf {
    workspace_root().join("controller").join("include")
}

/// Compiles `source` (C or C++ by its extension) against the static library (or the shared
/// one) into `exe`; the compiler's warnings are errors.
fn compile(source: &Path, exe: &Path, shared: bool) {
    let (a, so) = libraries();
    let cpp = source.extension().is_some_and(|e| e == "cpp");
    let mut cmd = Command::new(if cpp { "c++" } else { "cc" });
    cmd.args(if cpp { ["-std=c++17"] } else { ["-std=c11"] })
        .args(["-O2", "-ffp-contract=off", "-Wall", "-Wextra", "-Werror", "-pedantic", "-I"])
        .arg(include())
        .arg(source);
    if shared {
        let dir = so.parent().expect("the library's folder");
        cmd.arg("-L").arg(dir).arg("-lamb_testbed_controller").arg(format!("-Wl,-rpath,{}", dir.display()));
    } else {
        cmd.arg(a).args(NATIVE_LIBS);
    }
    let out = output(cmd.arg("-o").arg(exe));
    assert!(out.status.success(), "compiling {}:\n{}", source.display(), stderr(&out));
}

/// `SHORT` (50 ms of the 10 G scene, 1000 ticks) in lockstep, with `command` as the
/// controller, and extra overrides.
fn lockstep(command: Option<&Path>, extra: &[&str]) -> Vec<String> {
    let mut sets: Vec<String> = SHORT.iter().map(|s| s.to_string()).collect();
    sets.push("controller.mode=lockstep".into());
    if let Some(c) = command {
        sets.push(format!("controller.command=[{:?}]", c.display().to_string()));
    }
    sets.extend(extra.iter().map(|s| s.to_string()));
    sets
}

fn run(out: &Path, sets: &[String], env: &[(&str, &str)]) -> std::process::Output {
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    let mut cmd = plant_run(&scene("paper-10g.toml"), out, &sets);
    for (k, v) in env {
        cmd.env(k, v);
    }
    output(&mut cmd)
}

/// The header compiles as C11 and C++11 (its static assertions hold), and every size,
/// offset and constant it declares is the Rust definition's; a program linked with the
/// static library calls it.
#[test]
fn the_header_matches_the_rust_definitions() {
    use amb_testbed_controller as c;
    use std::mem::{offset_of, size_of};
    let mut rust: Vec<String> = Vec::new();
    macro_rules! layout {
        ($c:literal, $t:ty; $($f:ident),*) => {{
            $( rust.push(format!("{} {} {}", $c, stringify!($f), offset_of!($t, $f))); )*
            rust.push(format!("{} - {}", $c, size_of::<$t>()));
        }};
    }
    layout!("amb_loop_constants", c::LoopConstants; ki_n_per_a, ks_n_per_m, amp_gain_a_per_v, sensor_gain_v_per_m,
        rotor_mass_kg, gravity_m_s2, air_gap_m);
    layout!("amb_plane_design", c::PlaneDesign; stiffness_n_per_m, damping_ratio, current_limit_a, gravity_bias,
        reserved, constants);
    layout!("amb_geometry", c::Geometry; mass_kg, transverse_inertia_kg_m2, polar_inertia_kg_m2, rated_speed_rad_s,
        bearing_z_m, sensor_z_m);
    layout!("amb_design", c::Design; axes, planes, delay_samples, reserved, period_s, plane, geometry);
    layout!("amb_sample", c::Sample; seq, t_s, axes, reserved, sensor_v, speed_rad_s, angle_rad);
    layout!("amb_law", c::Law; abi_version, reserved, name, summary, context, build, update, reset, drop);
    let exit = |code: u8| i64::from(code);
    let constants: Vec<(&str, i64)> = vec![
        ("AMB_CONTROLLER_ABI_VERSION", i64::from(c::ABI_VERSION)),
        ("AMB_MAX_AXES", c::MAX_AXES as i64),
        ("AMB_MAX_PLANES", c::MAX_PLANES as i64),
        ("AMB_MAX_LAWS", c::MAX_LAWS as i64),
        ("AMB_MAX_NAME_LEN", c::MAX_NAME_LEN as i64),
        ("AMB_CHECK_FINITE", i64::from(c::check::FINITE)),
        ("AMB_CHECK_POSITIVE", i64::from(c::check::POSITIVE)),
        ("AMB_CHECK_NON_NEGATIVE", i64::from(c::check::NON_NEGATIVE)),
        ("AMB_CHECK_BETWEEN", i64::from(c::check::BETWEEN)),
        ("AMB_EXIT_OK", exit(controller::serve::exit::OK)),
        ("AMB_EXIT_IO", exit(controller::serve::exit::IO)),
        ("AMB_EXIT_BAD_INPUT", exit(controller::serve::exit::BAD_INPUT)),
        ("AMB_EXIT_PLANT_LOST", exit(controller::serve::exit::PLANT_LOST)),
        ("AMB_EXIT_INTERRUPTED", exit(controller::serve::exit::INTERRUPTED)),
    ];
    rust.extend(constants.iter().map(|(name, v)| format!("{name} {v}")));
    rust.push(format!("amb_abi_version() {}", c::ABI_VERSION));
    // Every #define of the header is in that list (a constant added to one side only fails).
    let header = std::fs::read_to_string(include().join("amb_testbed_controller.h")).unwrap();
    let defined: Vec<&str> = header
        .lines()
        .filter_map(|l| l.strip_prefix("#define "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|n| !n.starts_with("AMB_TESTBED_CONTROLLER_H") && !n.contains("STATIC_ASSERT"))
        .collect();
    let listed: Vec<&str> = constants.iter().map(|(n, _)| *n).collect();
    assert_eq!(defined, listed, "the header's constants and the ones checked here differ");

    let mut program = String::from("#include <stdio.h>\n#include \"amb_testbed_controller.h\"\nint main(void) {\n");
    for line in &rust {
        let mut w = line.split(' ');
        let (t, f) = (w.next().unwrap(), w.next().unwrap());
        program += &if f == "-" {
            format!("    printf(\"{t} - %zu\\n\", sizeof({t}));\n")
        } else if t.starts_with("AMB_") {
            format!("    printf(\"{t} %lld\\n\", (long long)({t}));\n")
        } else if t == "amb_abi_version()" {
            "    printf(\"amb_abi_version() %u\\n\", (unsigned)amb_abi_version());\n".to_string()
        } else {
            format!("    printf(\"{t} {f} %zu\\n\", offsetof({t}, {f}));\n")
        };
    }
    program += "    return 0;\n}\n";
    let dir = TempDir::new("c-api-header");
    for (name, compiler, std) in [("layout.c", "cc", "-std=c11"), ("layout.cpp", "c++", "-std=c++11")] {
        let source = dir.join(name);
        std::fs::write(&source, &program).unwrap();
        let exe = dir.join(&format!("{name}.exe"));
        let (a, _) = libraries();
        let out = output(
            Command::new(compiler)
                .args([std, "-Wall", "-Wextra", "-Werror", "-pedantic", "-I"])
                .arg(include())
                .arg(&source)
                .arg(a)
                .args(NATIVE_LIBS)
                .arg("-o")
                .arg(&exe),
        );
        assert!(out.status.success(), "{compiler} failed:\n{}", stderr(&out));
        let ran = output(&mut Command::new(&exe));
        assert!(ran.status.success());
        let c: Vec<String> = String::from_utf8_lossy(&ran.stdout).lines().map(str::to_string).collect();
        assert_eq!(c, rust, "{name}");
    }
}

/// The C `pd` (static library) and the C++ `pd` (shared library) run in lockstep through
/// `controller.command`: their traces are the Rust `pd`'s (the built-in controller), byte
/// for byte; so is the C one with `gain = 1` read through the parameter reader.
#[test]
fn the_c_and_cpp_examples_give_the_rust_pds_trace_byte_for_byte() {
    let dir = TempDir::new("c-api-examples");
    let examples = workspace_root().join("examples");
    let (c, cpp) = (dir.join("pd-c"), dir.join("pd-cpp"));
    compile(&examples.join("c").join("pd.c"), &c, false);
    compile(&examples.join("cpp").join("pd.cpp"), &cpp, true);
    let rust = dir.join("rust");
    assert_exit(&run(&rust, &lockstep(Some(controller_bin()), &[]), &[]), 0);
    let reference = std::fs::read(rust.join("trace.csv")).unwrap();
    assert_eq!(reference.iter().filter(|b| **b == b'\n').count(), 1002, "a header and rows 0 to 1000");
    for (name, exe, extra) in
        [("c", &c, vec![]), ("cpp", &cpp, vec![]), ("c-gain-1", &c, vec!["controller.params={gain = 1.0}"])]
    {
        let out = dir.join(name);
        let ran = run(&out, &lockstep(Some(exe), &extra), &[]);
        assert_exit(&ran, 0);
        let s = read_json(&out.join("summary.json"));
        assert!(s["cosim"]["controller"].as_str().unwrap_or_default().starts_with("pd:"), "{s:#}");
        assert!(
            std::fs::read(out.join("trace.csv")).unwrap() == reference,
            "{name}: the trace differs from the Rust pd's"
        );
    }
    // And a gain that changes the law changes the trace.
    let out = dir.join("c-gain");
    assert_exit(&run(&out, &lockstep(Some(&c), &["controller.params={gain = 1.2}"]), &[]), 0);
    assert!(std::fs::read(out.join("trace.csv")).unwrap() != reference);
}

/// Bad input and faults of a C law: each a clear message, its exit code, and the plant's
/// outputs (`scene.toml`, `summary.json` with its status; a trace for a run that started).
#[test]
fn faults_of_a_c_law_are_named_with_their_exit_codes() {
    let dir = TempDir::new("c-api-faults");
    let (faulty, throwing) = (dir.join("faulty"), dir.join("throwing"));
    compile(&workspace_root().join("tests").join("c").join("faulty.c"), &faulty, false);
    compile(&workspace_root().join("tests").join("c").join("throwing.cpp"), &throwing, true);
    // (name, program, fault, overrides, plant's exit code, status, what stderr names)
    type Case<'a> = (&'a str, &'a Path, &'a str, Vec<&'a str>, i32, &'a str, Vec<&'a str>);
    let cases: Vec<Case> = vec![
        (
            "nan",
            &faulty,
            "nan",
            vec![],
            8,
            "invalid_commands",
            vec!["non-finite for 11 samples in a row, from sample 100"],
        ),
        // Issue 31 item 7: ±∞ were clamped to the limit and counted valid.
        (
            "inf",
            &faulty,
            "inf",
            vec![],
            8,
            "invalid_commands",
            vec!["non-finite for 11 samples in a row, from sample 100"],
        ),
        (
            "abort",
            &faulty,
            "abort",
            vec![],
            4,
            "peer_lost",
            vec!["controller lost", "SIGABRT", "faulty: aborting at sample 100", "controller.log"],
        ),
        // Issue 40 item 7: a law that closes the library's descriptors ends the controller with
        // an exit code of its own, not an abort.
        (
            "closefds",
            &faulty,
            "closefds",
            vec![],
            4,
            "peer_lost",
            vec!["controller lost", "law `faulty` closed the library's file descriptors in its `update`", "exiting 1"],
        ),
        (
            "throw",
            &throwing,
            "",
            vec![],
            4,
            "peer_lost",
            vec!["controller lost", "SIGABRT", "Rust cannot catch foreign exceptions"],
        ),
        ("null", &faulty, "null", vec![], 2, "refused", vec!["law 0 (`faulty`): `update` is NULL"]),
        ("version", &faulty, "version", vec![], 2, "refused", vec!["built against ABI version 99", "version 1"]),
        (
            "refuse",
            &faulty,
            "refuse",
            vec![],
            2,
            "refused",
            vec!["law faulty: cannot drive a plane of k_e = 1e+06 N/m"],
        ),
        (
            "params",
            &faulty,
            "",
            vec!["controller.params={gain = -1.0}"],
            2,
            "refused",
            vec!["law faulty: controller.params.gain = -1.0: must be a finite number > 0"],
        ),
        (
            "unknown-param",
            &faulty,
            "",
            vec!["controller.params={gian = 1.0}"],
            2,
            "refused",
            vec!["law faulty: unknown parameter controller.params.gian = 1.0 (law faulty reads gain)"],
        ),
    ];
    for (name, exe, fault, extra, code, status, needles) in cases {
        let out = dir.join(name);
        let mut sets = extra.clone();
        sets.push("controller.law=\"faulty\"");
        let ran = run(&out, &lockstep(Some(exe), &sets), &[("AMB_FAULT", fault)]);
        assert_exit(&ran, code);
        let err = stderr(&ran);
        for n in &needles {
            assert!(err.contains(n), "{name}: no {n:?} in\n{err}");
        }
        assert!(name != "closefds" || !err.contains("SIGABRT"), "{name}: the controller aborted:\n{err}");
        let s = read_json(&out.join("summary.json"));
        assert_eq!(s["status"], status, "{name}: {s:#}");
        assert!(out.join("scene.toml").is_file(), "{name}");
        if code != 2 {
            let rows = std::fs::read_to_string(out.join("trace.csv")).unwrap().lines().count();
            assert!(rows > 100, "{name}: the trace up to the fault is written ({rows} lines)");
        }
    }
    // The controller side said the NaN itself, in controller.log.
    let log = std::fs::read_to_string(dir.join("nan").join("controller.log")).unwrap();
    assert!(log.contains("law `faulty` returned a non-finite current [NaN, NaN] A for sample 100"), "{log}");
    let log = std::fs::read_to_string(dir.join("inf").join("controller.log")).unwrap();
    assert!(log.contains("law `faulty` returned a non-finite current [inf, -inf] A for sample 100"), "{log}");
}
