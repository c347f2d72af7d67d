//! A controller FMU is a controller (issue 29 item 1; docs/guide/fmu-controller.md): the `pd`
//! of `tests/fmu/pd.c`, compiled here with the system C compiler as an FMI 2.0 co-simulation,
//! an FMI 3.0 co-simulation and an FMI 2.0 model-exchange FMU (planar and four-axis), zipped
//! into `.fmu` files with the modelDescription.xml this file writes, runs as the scene's
//! controller (`controller.fmu`) in sampled, lockstep and realtime modes; its traces against the
//! Rust `pd`'s. Then the bad input of the issue: not a zip, no binary for this platform, FMI
//! 1.0, a missing variable, an unknown parameter, a step's Discard/Error/Fatal, NaN, a SIGSEGV
//! and a hang inside the step, each with its message, exit code and what was written.
//!
//! Issue 29 item 3, against tools nobody here wrote: the same `pd.c` compiled against the FMI
//! headers FMPy ships (`fmpy/c-code/`, from the FMPy of `target/fmpy-venv`, `common::fmpy_venv`)
//! and a `pd` built with `pythonfmu` (PyPI) from `tests/fmu/pythonfmu_pd.py` write the Rust
//! `pd`'s trace of `config/cosim-10g.toml` byte for byte; the four-axis FMU of the two-plane
//! scene is compiled against FMPy's headers too.

mod common;

use common::{
    assert_exit, fmpy_venv, output_within, plant_bin, read_json, scene, stderr, workspace_root, TempDir, SHORT,
};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::Duration;

/// The most any one command of this file may take (debug build, a loaded 2-core machine).
const LIMIT: Duration = Duration::from_secs(300);

fn output(cmd: &mut Command) -> std::process::Output {
    output_within(cmd, LIMIT)
}

/// `controller-fmu`, built next to `plant` (where the plant looks for it).
fn host_built() {
    static BUILT: OnceLock<()> = OnceLock::new();
    BUILT.get_or_init(|| {
        plant_bin();
        common::workspace_bin("controller-fmu");
        assert!(plant_bin().with_file_name("controller-fmu").is_file(), "controller-fmu is not next to plant");
    });
}

/// How an FMU of `tests/fmu/pd.c` is built.
#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Cs2,
    Cs3,
    Me2,
}

/// Which FMI declarations `pd.c` is compiled against.
#[derive(Clone, Copy, PartialEq)]
enum Headers {
    /// Its own few declarations of the FMI types.
    Own,
    /// The headers FMPy ships (`fmpy/c-code/fmi2Functions.h`, `fmi3Functions.h`): the compiler
    /// checks each function of `pd.c` against the standard's declaration.
    Fmpy,
}

/// The folder of the FMI headers FMPy ships, in the FMPy of `target/fmpy-venv`.
fn fmpy_headers() -> PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let python = fmpy_venv().join("bin/python");
        let code = "import os, fmpy; print(os.path.join(os.path.dirname(fmpy.__file__), 'c-code'))";
        let out = output(Command::new(python).arg("-c").arg(code));
        assert_exit(&out, 0);
        let dir = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
        for h in ["fmi2Functions.h", "fmi3Functions.h"] {
            assert!(dir.join(h).is_file(), "FMPy ships no {h} in {}", dir.display());
        }
        dir
    })
    .clone()
}

/// Compiles `tests/fmu/pd.c` as `kind` for `axes` axes into `dir/pd.so` (warnings are errors).
fn compile(dir: &Path, kind: Kind, axes: usize) -> Vec<u8> {
    compile_with(dir, kind, axes, Headers::Own)
}

/// [`compile`] against `headers`.
fn compile_with(dir: &Path, kind: Kind, axes: usize, headers: Headers) -> Vec<u8> {
    let so = dir.join(format!("pd-{}-{axes}-{}.so", kind as u8, headers as u8));
    let mut cmd = Command::new("cc");
    cmd.args(["-std=c11", "-O2", "-ffp-contract=off", "-Wall", "-Wextra", "-Werror", "-shared", "-fPIC"])
        .arg(format!("-DAXES={axes}"))
        .arg(if kind == Kind::Cs3 { "-DFMI=3" } else { "-DFMI=2" });
    if headers == Headers::Fmpy {
        cmd.arg("-DFMI_HEADERS").arg(format!("-I{}", fmpy_headers().display()));
    }
    if kind == Kind::Me2 {
        cmd.arg("-DME");
    }
    let out = output(cmd.arg(workspace_root().join("tests/fmu/pd.c")).arg("-o").arg(&so).arg("-lm"));
    assert!(out.status.success(), "compiling pd.c: {}", stderr(&out));
    std::fs::read(&so).unwrap()
}

/// The modelDescription.xml of `pd.c` built as `kind` (the value references of pd.c), FMI
/// version `version` written as given (the FMI 1.0 case), `drop` a variable left out.
fn model_description(kind: Kind, axes: usize, version: &str, drop: &str) -> String {
    let names: &[&str] = if axes == 4 { &["x_a", "y_a", "x_b", "y_b"] } else { &["x", "y"] };
    let three = kind == Kind::Cs3;
    let var = |name: &str, vr: u32, causality: &str, ty: &str, extra: &str| -> String {
        if name == drop {
            return String::new();
        }
        if three {
            let ty = if ty == "Real" { "Float64" } else { "Int32" };
            format!("    <{ty} name=\"{name}\" valueReference=\"{vr}\" causality=\"{causality}\"{extra}/>\n")
        } else {
            format!(
                "    <ScalarVariable name=\"{name}\" valueReference=\"{vr}\" causality=\"{causality}\"{}><{ty}{extra}/></ScalarVariable>\n",
                if causality == "parameter" { " variability=\"fixed\"" } else { "" }
            )
        }
    };
    let mut vars = String::new();
    for (k, a) in names.iter().enumerate() {
        vars += &var(&format!("sensor_{a}"), 1 + k as u32, "input", "Real", " start=\"0\"");
    }
    vars += &var("speed", 10, "input", "Real", " start=\"0\"");
    vars += &var("angle", 11, "input", "Real", " start=\"0\"");
    vars += &var("time", 12, "input", "Real", " start=\"0\"");
    for (k, a) in names.iter().enumerate() {
        vars += &var(&format!("current_{a}"), 20 + k as u32, "output", "Real", "");
    }
    for (name, vr) in
        [("kp", 30), ("kd", 31), ("amp_gain", 32), ("bias_y", 33), ("kp_b", 34), ("kd_b", 35), ("amp_gain_b", 36)]
            .into_iter()
            .chain([("bias_y_b", 37), ("tau", 38)])
    {
        vars += &var(name, vr, "parameter", "Real", " start=\"1\"");
    }
    vars += &var("fault", 40, "parameter", "Integer", " start=\"0\"");
    vars += &var("fault_tick", 41, "parameter", "Integer", " start=\"0\"");
    let (interface, token) = match kind {
        Kind::Me2 => ("<ModelExchange modelIdentifier=\"pd\"/>", "guid=\"{pd-me}\""),
        Kind::Cs2 => ("<CoSimulation modelIdentifier=\"pd\"/>", "guid=\"{pd-cs}\""),
        Kind::Cs3 => ("<CoSimulation modelIdentifier=\"pd\"/>", "instantiationToken=\"{pd-cs3}\""),
    };
    let structure = if kind == Kind::Me2 {
        // The states x (vr 50…) and their derivatives (vr 60…), indexed from 1 in document order.
        let base = vars.matches("<ScalarVariable").count();
        for k in 0..axes {
            vars +=
                &format!("    <ScalarVariable name=\"x{k}\" valueReference=\"{}\"><Real/></ScalarVariable>\n", 50 + k);
        }
        for k in 0..axes {
            vars += &format!(
                "    <ScalarVariable name=\"der(x{k})\" valueReference=\"{}\"><Real derivative=\"{}\"/></ScalarVariable>\n",
                60 + k,
                base + k + 1
            );
        }
        let unknowns: String = (0..axes).map(|k| format!("<Unknown index=\"{}\"/>", base + axes + k + 1)).collect();
        format!("<ModelStructure><Derivatives>{unknowns}</Derivatives></ModelStructure>")
    } else {
        String::new()
    };
    format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<fmiModelDescription fmiVersion=\"{version}\" modelName=\"pd\" {token}>\n  {interface}\n  <ModelVariables>\n{vars}  </ModelVariables>\n  {structure}\n</fmiModelDescription>\n"
    )
}

/// A zip of `files` (path in the archive, bytes) at `path`.
fn zip(path: &Path, files: &[(&str, &[u8])]) -> PathBuf {
    let mut z = zip::ZipWriter::new(std::fs::File::create(path).unwrap());
    let options = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    for (name, bytes) in files {
        z.start_file(*name, options).unwrap();
        z.write_all(bytes).unwrap();
    }
    z.finish().unwrap();
    path.to_path_buf()
}

/// The `.fmu` of `pd.c` built as `kind` for `axes` axes.
fn pd_fmu(dir: &TempDir, kind: Kind, axes: usize) -> PathBuf {
    pd_fmu_with(dir, kind, axes, Headers::Own)
}

/// [`pd_fmu`] compiled against `headers`.
fn pd_fmu_with(dir: &TempDir, kind: Kind, axes: usize, headers: Headers) -> PathBuf {
    let so = compile_with(&dir.join(""), kind, axes, headers);
    let platform = if kind == Kind::Cs3 { "x86_64-linux" } else { "linux64" };
    let md = model_description(kind, axes, if kind == Kind::Cs3 { "3.0" } else { "2.0" }, "");
    let binary = format!("binaries/{platform}/pd.so");
    zip(
        &dir.join(&format!("pd-{}-{axes}-{}.fmu", kind as u8, headers as u8)),
        &[("modelDescription.xml", md.as_bytes()), (&binary, &so)],
    )
}

/// `[controller.params]` that make pd.c the Rust `pd` of `scene` with `sets`: each plane's
/// k_p, k_d, A_a and gravity bias from its design, written exactly (`{:?}` round-trips).
fn pd_params(scene_file: &Path, sets: &[String]) -> String {
    let scene = plant::config::load_scene(scene_file, sets).expect("the scene loads");
    let design = scene.rotor_design();
    let mut params = Vec::new();
    for (p, d) in design.planes().iter().enumerate() {
        let g = controller::PdGains::from_design(&d.pd(), &d.constants).unwrap();
        let s = if p == 0 { "" } else { "_b" };
        params.push(format!(
            "kp{s} = {:?}, kd{s} = {:?}, amp_gain{s} = {:?}, bias_y{s} = {:?}",
            g.kp, g.kd, g.amp_gain_a_per_v, g.bias_a[1]
        ));
        if p == 0 {
            params.push(format!("tau = {:?}", d.period_s));
        }
    }
    format!("controller.params={{{}}}", params.join(", "))
}

fn short(mode: &str, extra: &[String]) -> Vec<String> {
    let mut sets: Vec<String> = SHORT.iter().map(|s| s.to_string()).collect();
    sets.push(format!("controller.mode={mode:?}"));
    // Block at once when waiting (the tests share a loaded machine; lockstep is deterministic).
    sets.push("controller.spin_us=0".into());
    sets.extend(extra.iter().cloned());
    sets
}

fn run(scene_file: &Path, out: &Path, sets: &[String]) -> std::process::Output {
    host_built();
    let mut cmd = Command::new(plant_bin());
    cmd.arg("run").arg(scene_file).arg("--out").arg(out);
    for s in sets {
        cmd.args(["--set", s]);
    }
    output(&mut cmd)
}

fn fmu_set(fmu: &Path) -> String {
    format!("controller.fmu={:?}", fmu.display().to_string())
}

fn trace(out: &Path) -> Vec<u8> {
    std::fs::read(out.join("trace.csv")).unwrap_or_else(|e| panic!("{}: {e}", out.display()))
}

/// The FMI 2.0 and 3.0 co-simulation `pd`s write the Rust `pd`'s trace byte for byte: in
/// lockstep (through `controller-fmu`) and in sampled mode (in the plant); the FMU's log is in
/// `controller.log`; a parameter that changes the law changes the trace.
#[test]
fn co_simulation_pd_fmus_write_the_rust_pds_trace_byte_for_byte() {
    let dir = TempDir::new("fmu-cs");
    let paper = scene("paper-10g.toml");
    let params = pd_params(&paper, &short("sampled", &[]));
    let rust = dir.join("rust");
    assert_exit(&run(&paper, &rust, &short("sampled", &[])), 0);
    let reference = trace(&rust);
    assert_eq!(reference.iter().filter(|b| **b == b'\n').count(), 1002, "a header and rows 0 to 1000");
    let (two, three) = (pd_fmu(&dir, Kind::Cs2, 2), pd_fmu(&dir, Kind::Cs3, 2));
    for (name, fmu, mode) in
        [("cs2-lockstep", &two, "lockstep"), ("cs3-lockstep", &three, "lockstep"), ("cs2-sampled", &two, "sampled")]
    {
        let out = dir.join(name);
        let ran = run(&paper, &out, &short(mode, &[fmu_set(fmu), params.clone()]));
        assert_exit(&ran, 0);
        assert!(trace(&out) == reference, "{name}: the trace differs from the Rust pd's");
        let s = read_json(&out.join("summary.json"));
        if mode == "lockstep" {
            assert!(s["cosim"]["controller"].as_str().unwrap_or_default().starts_with("fmu: k_e"), "{s:#}");
            let log = std::fs::read_to_string(out.join("controller.log")).unwrap();
            assert!(log.contains("pd: instantiated"), "{name}: the FMU's log is not in controller.log:\n{log}");
            assert!(log.contains("controller-fmu: FMU pd (pd-"), "{name}: {log}");
        }
        let recorded = std::fs::read_to_string(out.join("scene.toml")).unwrap();
        assert!(recorded.contains(&fmu.display().to_string()) && recorded.contains("law = \"fmu\""), "{recorded}");
    }
    let out = dir.join("other-gain");
    let kp = pd_params(&paper, &short("sampled", &["controller.stiffness_n_per_m=1.1e6".into()]));
    assert_exit(&run(&paper, &out, &short("sampled", &[fmu_set(&two), kp])), 0);
    assert!(trace(&out) != reference, "another k_p must change the trace");
}

/// The `pd` of `tests/fmu/pythonfmu_pd.py` as an FMI 2.0 co-simulation FMU, built by
/// `pythonfmu build` (PyPI) into `dir`.
fn pythonfmu_pd(dir: &TempDir) -> PathBuf {
    let script = workspace_root().join("tests/fmu/pythonfmu_pd.py");
    let out = output(
        Command::new(fmpy_venv().join("bin/pythonfmu")).arg("build").arg("-f").arg(&script).arg("-d").arg(dir.join("")),
    );
    assert_exit(&out, 0);
    let fmu = dir.join("PythonPd.fmu");
    assert!(fmu.is_file(), "pythonfmu build wrote no PythonPd.fmu: {}", stderr(&out));
    fmu
}

/// The shared libpython of the venv's interpreter. pythonfmu's binary calls the Python C API
/// but does not link libpython (it expects to be loaded by a Python process, as FMPy is):
/// another host, here `controller-fmu`, must have it loaded (`LD_PRELOAD`).
fn libpython() -> PathBuf {
    let code =
        "import os, sysconfig as s; print(os.path.join(s.get_config_var('LIBDIR'), s.get_config_var('INSTSONAME')))";
    let out = output(Command::new(fmpy_venv().join("bin/python")).arg("-c").arg(code));
    assert_exit(&out, 0);
    let lib = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    assert!(
        lib.is_file(),
        "the venv's Python has no shared libpython at {} (a pythonfmu FMU needs one)",
        lib.display()
    );
    lib
}

/// Issue 29 item 3: a `pd` built with pythonfmu (PyPI) and `pd.c` compiled against the FMI
/// headers FMPy ships (FMI 2.0 and 3.0 co-simulation), each doing the Rust `pd`'s arithmetic,
/// write the Rust `pd`'s trace of `config/cosim-10g.toml` (50 ms, the shock from 10 ms: through
/// the touchdown) byte for byte, in lockstep through `controller-fmu`; the pythonfmu FMU also
/// in sampled mode (hosted in the plant's process).
#[test]
fn pythonfmu_and_fmpy_header_pds_write_the_rust_pds_cosim_trace_byte_for_byte() {
    let dir = TempDir::new("fmu-outside-tools");
    let cosim = scene("cosim-10g.toml");
    let params = pd_params(&cosim, &short("sampled", &[]));
    let rust = dir.join("rust");
    assert_exit(&run(&cosim, &rust, &short("sampled", &["controller.law=\"pd\"".into()])), 0);
    let reference = trace(&rust);
    assert_eq!(reference.iter().filter(|b| **b == b'\n').count(), 1002, "a header and rows 0 to 1000");
    let s = read_json(&rust.join("summary.json"));
    assert!(s["max_contact_force_n"].as_f64().unwrap_or_default() > 0.0, "the window has the touchdown: {s:#}");
    let c2 = pd_fmu_with(&dir, Kind::Cs2, 2, Headers::Fmpy);
    let c3 = pd_fmu_with(&dir, Kind::Cs3, 2, Headers::Fmpy);
    let py = pythonfmu_pd(&dir);
    let preload = libpython();
    for (name, fmu, mode) in [
        ("c-fmi2-fmpy-headers", &c2, "lockstep"),
        ("c-fmi3-fmpy-headers", &c3, "lockstep"),
        ("pythonfmu", &py, "lockstep"),
        ("pythonfmu-sampled", &py, "sampled"),
    ] {
        let out = dir.join(name);
        host_built();
        let mut cmd = Command::new(plant_bin());
        cmd.arg("run").arg(&cosim).arg("--out").arg(&out);
        for s in short(mode, &[fmu_set(fmu), params.clone()]) {
            cmd.args(["--set", &s]);
        }
        if fmu == &py {
            cmd.env("LD_PRELOAD", &preload);
        }
        let ran = output(&mut cmd);
        assert_exit(&ran, 0);
        let log = std::fs::read_to_string(out.join("controller.log")).unwrap_or_default();
        assert!(trace(&out) == reference, "{name}: the trace differs from the Rust pd's\n{log}");
        if mode == "lockstep" {
            let s = read_json(&out.join("summary.json"));
            assert!(s["cosim"]["controller"].as_str().unwrap_or_default().starts_with("fmu: k_e"), "{name}: {s:#}");
        }
    }
    // The pythonfmu FMU computes: another gain, another trace.
    let out = dir.join("pythonfmu-other-gain");
    let kp = pd_params(&cosim, &short("sampled", &["controller.stiffness_n_per_m=1.1e6".into()]));
    let mut cmd = Command::new(plant_bin());
    cmd.arg("run").arg(&cosim).arg("--out").arg(&out).env("LD_PRELOAD", &preload);
    for s in short("lockstep", &[fmu_set(&py), kp]) {
        cmd.args(["--set", &s]);
    }
    assert_exit(&output(&mut cmd), 0);
    assert!(trace(&out) != reference, "another k_p must change the pythonfmu FMU's trace");
}

/// A four-axis FMU (FMI 2.0 co-simulation, compiled against FMPy's headers) drives the two-plane rotor in lockstep: the Rust
/// `pd`'s trace (one law per plane, each with its plane's design) byte for byte; and realtime
/// runs it to the end.
#[test]
fn a_four_axis_fmu_drives_the_two_plane_rotor() {
    let dir = TempDir::new("fmu-two-plane");
    let two_plane = scene("two-plane-asymmetric-10g.toml");
    let brief = |mode: &str, extra: &[String]| {
        let mut sets = short(mode, extra);
        sets.push("scene.duration_s=0.02".into()); // 400 ticks, the shock from 10 ms
        sets
    };
    let params = pd_params(&two_plane, &brief("sampled", &[]));
    let rust = dir.join("rust");
    assert_exit(&run(&two_plane, &rust, &brief("sampled", &[])), 0);
    let fmu = pd_fmu_with(&dir, Kind::Cs2, 4, Headers::Fmpy);
    let out = dir.join("fmu");
    assert_exit(&run(&two_plane, &out, &brief("lockstep", &[fmu_set(&fmu), params.clone()])), 0);
    assert!(trace(&out) == trace(&rust), "the four-axis FMU's trace differs from the Rust pd's");
    // Realtime: paced by the wall clock; whatever it misses on a loaded machine, it runs to the end.
    let out = dir.join("realtime");
    let sets = brief(
        "realtime",
        &[
            fmu_set(&fmu),
            params,
            "controller.max_miss_fraction=1.0".into(),
            "controller.max_overrun_fraction=1.0".into(),
            "controller.pacing=\"sleep\"".into(),
        ],
    );
    let ran = run(&two_plane, &out, &sets);
    assert_exit(&ran, 0);
    assert_eq!(read_json(&out.join("summary.json"))["status"], "completed");
    // A planar FMU lacks the two-plane rotor's signals: refused when the scene loads.
    let planar = pd_fmu(&dir, Kind::Cs2, 2);
    let ran = run(&two_plane, &dir.join("planar"), &brief("lockstep", &[fmu_set(&planar)]));
    assert_exit(&ran, 2);
    let err = stderr(&ran);
    assert!(err.contains("signal sensor_x_a") && err.contains("the FMU has no variable `sensor_x_a`"), "{err}");
    assert!(err.contains("its inputs: sensor_x, sensor_y, speed, angle, time"), "{err}");
}

/// The model-exchange `pd` (a first-order state x' = (u − x)/τ standing in for the previous
/// sample, τ = T, explicit Euler with one step per period: x_{k+1} = x_k + T (u_k − x_k)/T,
/// u_k but for the rounding of that sum) agrees with the Rust `pd`'s trace to 1e-12 of each
/// column's range: the arithmetic differs in the last bits only (x + T (u − x)/T is not u to the
/// bit), over a short, stable window. With RK4 and 4 substeps it is another (smoother) derivative:
/// the trace differs.
#[test]
fn a_model_exchange_pd_agrees_with_the_rust_pd_to_rounding() {
    let dir = TempDir::new("fmu-me");
    let paper = scene("paper-10g.toml");
    let params = pd_params(&paper, &short("sampled", &[]));
    let rust = dir.join("rust");
    assert_exit(&run(&paper, &rust, &short("sampled", &[])), 0);
    let fmu = pd_fmu(&dir, Kind::Me2, 2);
    let table = |solver: &str, substeps: u32| {
        format!("controller.fmu={{path = {:?}, solver = {solver:?}, substeps = {substeps}}}", fmu.display().to_string())
    };
    let out = dir.join("euler");
    assert_exit(&run(&paper, &out, &short("lockstep", &[table("euler", 1), params.clone()])), 0);
    let (a, b) = (common::Csv::read(&rust.join("trace.csv")), common::Csv::read(&out.join("trace.csv")));
    assert_eq!(a.header, b.header);
    assert_eq!(a.rows.len(), b.rows.len());
    let mut worst = (0.0_f64, String::new());
    for (c, name) in a.header.iter().enumerate() {
        let range = a.rows.iter().map(|r| r[c].abs()).fold(0.0_f64, f64::max);
        for (ra, rb) in a.rows.iter().zip(&b.rows) {
            let d = (ra[c] - rb[c]).abs() / range.max(1e-300);
            if d > worst.0 {
                worst = (d, name.clone());
            }
        }
    }
    eprintln!("model exchange against the Rust pd: worst {:e} of {}'s range", worst.0, worst.1);
    assert!(worst.0 <= 1e-12, "the model-exchange pd departs from the Rust pd by {:e} of {}'s range", worst.0, worst.1);
    let out = dir.join("rk4");
    assert_exit(&run(&paper, &out, &short("sampled", &[table("rk4", 4), params])), 0);
    assert!(trace(&out) != trace(&rust));
}

/// Parameters are set by name; an unknown one is refused naming the FMU's parameters (lockstep:
/// by the controller process in the handshake; sampled: by the plant), exit 2.
#[test]
fn an_unknown_parameter_is_refused_with_the_fmus_parameters_listed() {
    let dir = TempDir::new("fmu-params");
    let paper = scene("paper-10g.toml");
    let fmu = pd_fmu(&dir, Kind::Cs2, 2);
    for mode in ["lockstep", "sampled"] {
        let out = dir.join(mode);
        let ran = run(&paper, &out, &short(mode, &[fmu_set(&fmu), "controller.params={kq = 2.0}".into()]));
        assert_exit(&ran, 2);
        let err = stderr(&ran);
        assert!(
            err.contains("law fmu: unknown parameter controller.params.kq = 2.0 (law fmu reads kp, kd, amp_gain, bias_y, kp_b, kd_b, amp_gain_b, bias_y_b, tau, fault, fault_tick)"),
            "{mode}: {err}"
        );
        let ran = run(
            &paper,
            &dir.join(&format!("{mode}-type")),
            &short(mode, &[fmu_set(&fmu), "controller.params={fault = 1.5}".into()]),
        );
        assert_exit(&ran, 2);
        assert!(
            stderr(&ran).contains("controller.params.fault = 1.5: the FMU's parameter is an Integer: give an integer"),
            "{}",
            stderr(&ran)
        );
    }
}

/// Archives that are no FMU this host runs, and a missing variable: refused when the scene
/// loads, exit 2, the file and what is wrong named, nothing run.
#[test]
fn bad_archives_and_missing_variables_are_refused_when_the_scene_loads() {
    let dir = TempDir::new("fmu-bad-archives");
    let paper = scene("paper-10g.toml");
    let so = compile(&dir.join(""), Kind::Cs2, 2);
    let md2 = model_description(Kind::Cs2, 2, "2.0", "");
    let not_zip = dir.join("not-zip.fmu");
    std::fs::write(&not_zip, b"this is not a zip archive").unwrap();
    let windows =
        zip(&dir.join("windows.fmu"), &[("modelDescription.xml", md2.as_bytes()), ("binaries/win64/pd.dll", b"MZ")]);
    let md1 = model_description(Kind::Cs2, 2, "1.0", "");
    let fmi1 = zip(&dir.join("fmi1.fmu"), &[("modelDescription.xml", md1.as_bytes()), ("binaries/linux64/pd.so", &so)]);
    let md_no_current = model_description(Kind::Cs2, 2, "2.0", "current_y");
    let lacks = zip(
        &dir.join("lacks.fmu"),
        &[("modelDescription.xml", md_no_current.as_bytes()), ("binaries/linux64/pd.so", &so)],
    );
    let good = zip(&dir.join("good.fmu"), &[("modelDescription.xml", md2.as_bytes()), ("binaries/linux64/pd.so", &so)]);
    let cases: Vec<(&str, String, Vec<&str>)> = vec![
        ("not-zip", fmu_set(&not_zip), vec!["not-zip.fmu", "not an FMU: an FMU is a zip archive, and this file is not one"]),
        ("windows", fmu_set(&windows), vec!["no binary for this platform (Linux x86-64: binaries/linux64/pd.so); the FMU has binaries for win64"]),
        ("fmi1", fmu_set(&fmi1), vec!["fmiVersion = \"1.0\": FMI 1.0 is not supported"]),
        ("lacks", fmu_set(&lacks), vec!["signal current_y", "the FMU has no variable `current_y` (its outputs: current_x)"]),
        (
            "mapped",
            format!("controller.fmu={{path = {:?}, map = {{current_x = \"u_x\"}}}}", good.display().to_string()),
            vec!["controller.fmu.map.current_x = \"u_x\": the FMU has no variable `u_x` (its outputs: current_x, current_y)"],
        ),
        (
            "not-a-signal",
            format!("controller.fmu={{path = {:?}, map = {{current_z = \"u_x\"}}}}", good.display().to_string()),
            vec!["controller.fmu.map.current_z: not a signal of this rotor (2 axes)"],
        ),
        ("missing-file", fmu_set(&dir.join("nowhere.fmu")), vec!["nowhere.fmu", "cannot open it"]),
        ("with-command", format!("{}\u{0}controller.command=[\"/bin/true\"]", fmu_set(&good)), vec!["either a controller FMU (controller.fmu) or a controller command"]),
        ("with-law", format!("{}\u{0}controller.law=\"relev\"", fmu_set(&good)), vec!["controller.law = \"relev\": with controller.fmu the law is the FMU"]),
    ];
    for (name, set, needles) in cases {
        let out = dir.join(name);
        let mut extra: Vec<String> = set.split('\u{0}').map(String::from).collect();
        extra.push("controller.mode=\"lockstep\"".into());
        let ran = run(&paper, &out, &short("lockstep", &extra));
        assert_exit(&ran, 2);
        let err = stderr(&ran);
        for n in needles {
            assert!(err.contains(n), "{name}: no {n:?} in\n{err}");
        }
        assert!(!out.join("trace.csv").exists(), "{name}: nothing is run");
    }
}

/// An FMU that fails inside a step (Discard, Error, Fatal, SIGSEGV, a hang) is a lost controller
/// (exit 4, `peer_lost`, the trace up to the fault written, the reason in `controller.log`); one
/// that answers NaN is an invalid command (exit 8). Each from step 100 of 200.
#[test]
fn an_fmu_failing_in_its_step_is_a_lost_controller_and_nan_an_invalid_command() {
    let dir = TempDir::new("fmu-faults");
    let paper = scene("paper-10g.toml");
    let fmu = pd_fmu(&dir, Kind::Cs2, 2);
    let three = pd_fmu(&dir, Kind::Cs3, 2);
    // (name, FMU, fault, mode, plant's exit code, status, what the controller's side says)
    type Case<'a> = (&'a str, &'a Path, i64, &'a str, i32, &'a str, &'a str);
    let cases: [Case; 7] = [
        ("discard", &fmu, 1, "lockstep", 4, "peer_lost", "fmi2DoStep(t = 0.005 s, h = 0.00005 s) returned Discard"),
        ("error", &fmu, 2, "lockstep", 4, "peer_lost", "fmi2DoStep(t = 0.005 s, h = 0.00005 s) returned Error"),
        ("fatal", &three, 3, "lockstep", 4, "peer_lost", "fmi3DoStep(t = 0.005 s, h = 0.00005 s) returned Fatal"),
        ("nan", &fmu, 4, "lockstep", 8, "invalid_commands", "non-finite for 11 samples in a row, from sample 100"),
        ("segv", &fmu, 5, "lockstep", 4, "peer_lost", "the FMU crashed (SIGSEGV) inside an FMI call"),
        ("hang", &fmu, 6, "lockstep", 4, "peer_lost", "the FMU's calls of tick 100 have not returned within 200 ms"),
        // In the plant's process: the law answers NaN from the failed step on.
        ("error-sampled", &fmu, 2, "sampled", 8, "invalid_commands", "returned Error; the law answers NaN from now on"),
    ];
    for (name, fmu, fault, mode, code, status, needle) in cases {
        let out = dir.join(name);
        let spec = format!("controller.fmu={{path = {:?}, step_timeout_ms = 200}}", fmu.display().to_string());
        let sets = short(
            mode,
            &[spec, format!("controller.params={{fault = {fault}, fault_tick = 100}}"), "scene.duration_s=0.01".into()],
        );
        let ran = run(&paper, &out, &sets);
        assert_exit(&ran, code);
        let s = read_json(&out.join("summary.json"));
        assert_eq!(s["status"], status, "{name}: {s:#}");
        // The controller process's lines are in controller.log; the plant's on its stderr.
        let said = if code == 4 { std::fs::read_to_string(out.join("controller.log")).unwrap() } else { stderr(&ran) };
        assert!(said.contains(needle), "{name}: no {needle:?} in\n{said}");
        let rows = std::fs::read_to_string(out.join("trace.csv")).unwrap().lines().count();
        assert!(rows > 100, "{name}: the trace up to the fault is written ({rows} lines)");
    }
}

/// `plant assess` grades an FMU controller like any other: the FMI 2.0 `pd` with the Rust
/// `pd`'s gains gets the Rust `pd`'s vibration figures (ISO 14839-2), to the bit.
#[test]
fn plant_assess_grades_an_fmu_controller_like_the_rust_pd() {
    let dir = TempDir::new("fmu-assess");
    let paper = scene("paper-10g.toml");
    let params = pd_params(&paper, &short("sampled", &[]));
    let fmu = pd_fmu(&dir, Kind::Cs2, 2);
    let file = dir.join("assess.toml");
    let quoted = |s: &str| format!("{s:?}");
    let text = format!(
        "scene = {}\nset = [\"controller.mode=\\\"sampled\\\"\"]\nparts = [\"vibration\"]\n\
         [[controller]]\nlabel = \"rust\"\nset = [\"controller.law=\\\"pd\\\"\"]\n\
         [[controller]]\nlabel = \"fmu\"\nset = [{}, {}]\n",
        quoted(&paper.display().to_string()),
        quoted(&fmu_set(&fmu)),
        quoted(&params),
    );
    std::fs::write(&file, text).unwrap();
    host_built();
    let out = dir.join("report");
    let ran = output(Command::new(plant_bin()).arg("assess").arg(&file).arg("--out").arg(&out));
    assert_exit(&ran, 0);
    let report = read_json(&out.join("report.json"));
    let c = report["controllers"].as_array().unwrap();
    assert_eq!(
        (c[0]["label"].as_str(), c[1]["label"].as_str(), c[1]["law"].as_str()),
        (Some("rust"), Some("fmu"), Some("fmu"))
    );
    let (rust, fmu) = (&c[0]["vibration"], &c[1]["vibration"]);
    assert_eq!(fmu["status"], "measured", "{fmu:#}");
    assert_eq!(rust["result"], fmu["result"], "the FMU's vibration figures differ from the Rust pd's");
}

/// Issue 40 item 5: in-process FMUs of an assessment's members cannot share what is the
/// process's. The `pd` of `pd.c` with fault 7 holds a resource of the process from its first
/// step and aborts when another instance holds it, as two pythonfmu FMUs (two Python hosts in
/// one process) crashed the plant; `plant assess` in `sampled` mode measures both axes' sensitivity
/// (in parallel, two threads at least) with it and finishes, each axis's figures the Rust `pd`'s
/// to the bit.
#[test]
fn an_assessment_of_in_process_fmus_that_hold_the_process_finishes() {
    let dir = TempDir::new("fmu-assess-one-at-a-time");
    let paper = scene("paper-10g.toml");
    let params = pd_params(&paper, &short("sampled", &[]));
    let held = format!("{}, fault = 7, fault_tick = 0}}", params.strip_suffix('}').unwrap());
    let fmu = pd_fmu(&dir, Kind::Cs2, 2);
    let file = dir.join("assess.toml");
    let quoted = |s: &str| format!("{s:?}");
    let text = format!(
        "scene = {}\nset = [\"controller.mode=\\\"sampled\\\"\", \"scene.duration_s=0.3\"]\nparts = [\"sensitivity\"]\n\
         [[controller]]\nlabel = \"rust\"\nset = [\"controller.law=\\\"pd\\\"\"]\n\
         [[controller]]\nlabel = \"fmu\"\nset = [{}, {}]\n\
         [sensitivity]\nf_min_hz = 20.0\nf_max_hz = 200.0\npoints = 4\nprobe_s = 0.3\nresolution = 0.05\nspeeds = [\"standstill\"]\n",
        quoted(&paper.display().to_string()),
        quoted(&fmu_set(&fmu)),
        quoted(&held),
    );
    std::fs::write(&file, text).unwrap();
    host_built();
    let out = dir.join("report");
    let ran =
        output(Command::new(plant_bin()).env("RAYON_NUM_THREADS", "2").arg("assess").arg(&file).arg("--out").arg(&out));
    assert_exit(&ran, 0);
    let report = read_json(&out.join("report.json"));
    let c = report["controllers"].as_array().unwrap();
    let (rust, fmu) = (&c[0]["sensitivity"], &c[1]["sensitivity"]);
    assert_eq!(fmu["status"], "measured", "{fmu:#}");
    let axes = |s: &serde_json::Value| s["result"]["axes"].as_array().cloned().unwrap_or_default();
    assert_eq!(axes(fmu).len(), 2, "{fmu:#}");
    assert_eq!(axes(rust), axes(fmu), "the FMU's sensitivity differs from the Rust pd's");
}

/// Issue 40 item 5: an FMU that ends the process (`_exit(0)` at step 100, `pd.c` fault 8) never
/// leaves the plant ending with exit 0 and no summary. In sampled mode, inside the plant's
/// process, the plant's own `_exit` sees it: one line naming the FMU and the call, exit 4 (a
/// lost controller's); in lockstep `controller-fmu` ends and the plant goes on as for any lost
/// controller: exit 4, `peer_lost`, summary.json and the trace up to the loss.
#[test]
fn an_fmu_that_ends_the_process_never_ends_the_plant_with_exit_0() {
    let dir = TempDir::new("fmu-exit");
    let paper = scene("paper-10g.toml");
    let fmu = pd_fmu(&dir, Kind::Cs2, 2);
    for mode in ["sampled", "lockstep"] {
        let out = dir.join(mode);
        let sets = short(
            mode,
            &[fmu_set(&fmu), "controller.params={fault = 8, fault_tick = 100}".into(), "scene.duration_s=0.01".into()],
        );
        let ran = run(&paper, &out, &sets);
        assert_exit(&ran, 4);
        if mode == "sampled" {
            let err = stderr(&ran);
            assert!(
                err.contains("the controller FMU pd (pd-0-2-0.fmu, FMI 2.0 co-simulation) called _exit(0) inside the plant's process"),
                "{err}"
            );
        } else {
            assert_eq!(read_json(&out.join("summary.json"))["status"], "peer_lost");
        }
    }
}

/// Issue 40 item 5: what an FMU file can do to its host before any of its code runs. A zip bomb
/// (an entry that unpacks past the limit) and an archive of too many entries are refused naming
/// the limit, before anything is written; a FIFO given as the FMU is refused at once (it blocked
/// the plant and `controller-fmu`), exit 2; the copy a killed `controller-fmu` leaves behind is
/// removed by the next run that opens an FMU, which removes its own too.
#[cfg(target_os = "linux")]
#[test]
fn bombs_fifos_and_leaked_copies() {
    let dir = TempDir::new("fmu-bombs");
    let paper = scene("paper-10g.toml");
    let so = compile(&dir.join(""), Kind::Cs2, 2);
    let md = model_description(Kind::Cs2, 2, "2.0", "");
    std::fs::write(dir.join("pd.so"), &so).unwrap();
    std::fs::write(dir.join("md.xml"), &md).unwrap();
    // Python's zlib writes 600 MiB of zeros as about 600 kB in a second or two.
    let python = |out: &str, body: &str| {
        let code = format!(
            "import zipfile\nz = zipfile.ZipFile({out:?}, 'w', zipfile.ZIP_DEFLATED)\n\
             z.write({md:?}, 'modelDescription.xml')\nz.write({so:?}, 'binaries/linux64/pd.so')\n{body}\nz.close()\n",
            out = dir.join(out).display().to_string(),
            md = dir.join("md.xml").display().to_string(),
            so = dir.join("pd.so").display().to_string(),
        );
        let ran = output(Command::new("python3").arg("-c").arg(code));
        assert_exit(&ran, 0);
        dir.join(out)
    };
    let bomb = python(
        "bomb.fmu",
        "with z.open('resources/zeros.bin', 'w', force_zip64=True) as f:\n    for _ in range(600):\n        f.write(bytes(1 << 20))",
    );
    assert!(std::fs::metadata(&bomb).unwrap().len() < 8 << 20);
    let many = python("many.fmu", "for i in range(10001):\n    z.writestr('resources/%d' % i, b'')");
    let tmp = dir.join("tmp");
    std::fs::create_dir_all(&tmp).unwrap();
    let run_in = |name: &str, fmu: &Path| {
        host_built();
        let mut cmd = Command::new(plant_bin());
        cmd.env("TMPDIR", &tmp).arg("run").arg(&paper).arg("--out").arg(dir.join(name));
        for s in short(
            "sampled",
            &[fmu_set(fmu), pd_params(&paper, &short("sampled", &[])), "scene.duration_s=0.002".into()],
        ) {
            cmd.args(["--set", &s]);
        }
        output(&mut cmd)
    };
    let copies = || -> Vec<String> {
        std::fs::read_dir(&tmp)
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with("amb-testbed-fmu-"))
            .collect()
    };
    for (name, fmu, needle) in [
        ("bomb", &bomb, "unpacked, it holds more than 512 MiB (the limit of an FMU's unpacked size"),
        ("many", &many, "10003 entries in the archive; an FMU may hold at most 10000"),
    ] {
        let ran = run_in(name, fmu);
        assert_exit(&ran, 2);
        assert!(stderr(&ran).contains(needle), "{name}: no {needle:?} in\n{}", stderr(&ran));
        assert_eq!(copies(), Vec::<String>::new(), "{name}: the refused FMU's copy is removed");
    }

    // A FIFO: refused at once by the plant (the scene's check) and by controller-fmu.
    let fifo = dir.join("fifo.fmu");
    let c = std::ffi::CString::new(fifo.display().to_string()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let ran = run_in("fifo", &fifo);
    assert_exit(&ran, 2);
    assert!(stderr(&ran).contains("a FIFO, not a regular file"), "{}", stderr(&ran));
    let host = plant_bin().with_file_name("controller-fmu");
    let ran = output(Command::new(&host).arg("--fmu").arg(&fifo).args(["--run-id", "fifo"]));
    assert_exit(&ran, 2);
    assert!(stderr(&ran).contains("a FIFO, not a regular file"), "{}", stderr(&ran));

    // A controller-fmu killed while it serves leaves its copy; the next run removes it.
    let good = pd_fmu(&dir, Kind::Cs2, 2);
    let mut child = Command::new(&host)
        .env("TMPDIR", &tmp)
        .arg("--fmu")
        .arg(&good)
        .args(["--run-id", "leaked-copy"])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let deadline = std::time::Instant::now() + LIMIT;
    while copies().is_empty() {
        assert!(child.try_wait().unwrap().is_none(), "controller-fmu ended before it unpacked the FMU");
        assert!(std::time::Instant::now() < deadline, "controller-fmu never unpacked the FMU");
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let leaked = copies();
    assert_eq!(leaked.len(), 1, "the killed controller-fmu's copy is left: {leaked:?}");
    let ran = run_in("after", &good);
    assert_exit(&ran, 0);
    assert_eq!(copies(), Vec::<String>::new(), "the next run removed the leaked copy and its own");
}
