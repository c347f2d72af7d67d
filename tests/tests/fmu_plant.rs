//! The plant as an FMU (issue 29 item 2; docs/guide/fmu-plant.md).
//!
//! What is pinned: `plant fmu` writes an FMU that FMPy's validation finds no problem in and
//! FMPy simulates; FMPy closing the loop around it with the Python kit's `pd` at the scene's
//! controller rate reads, tick by tick, the samples `plant run` writes in `sampled` mode, bit
//! for bit (time, rotor position, contact force, race and rotor speed, housing displacement,
//! and the command applied over each tick), and a serialised state continues in another
//! process bit for bit; driven through the C API (the library loaded with `libloading`), an
//! FMU state taken, restored and serialised into a fresh instance continues bit for bit, two
//! instances in one process step independently, importers' rounding of the communication
//! point is taken, and every bad call (a step before initialisation, a step that is not a
//! whole number of ticks, a NaN input, a parameter out of bounds, setting an output, a corrupt
//! state, a diverging plant) returns `fmi2Error` with a log line, never a crash.
//!
//! The FMPy test runs in its own virtual environment under the target folder
//! (`target/fmpy-venv`: FMPy and pythonfmu from PyPI and the Python kit, made once and reused
//! while its stamp matches, `common::fmpy_venv`), as `tests/tests/python.rs` makes the kit's.

mod common;

use common::{
    assert_exit, fmpy_venv, install_executable, output_within, plant_bin, scene, stderr, workspace_root, Csv, TempDir,
};
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Mutex, OnceLock};
use std::time::Duration;

/// The limit of one command.
const LIMIT: Duration = Duration::from_secs(120);

/// The scene of these tests: the study's 10 G scene, 30 ms with the shock at 5 ms (the rotor
/// touches its race from 7.5 ms on, tick 151).
const SHORT: &[&str] = &["scene.duration_s=0.03", "shock[0].start_s=0.005"];

/// `libplant_fmu.so`, built once per test binary in this profile, next to `plant`.
fn library() -> &'static Path {
    static LIB: OnceLock<PathBuf> = OnceLock::new();
    LIB.get_or_init(|| common::workspace_lib("plant_fmu", "so"))
}

/// `plant fmu cosim-10g.toml --set SHORT… --out DIR/NAME`, the binary found next to `plant`.
fn write_fmu(dir: &TempDir, name: &str, sets: &[&str]) -> PathBuf {
    write_fmu_of(dir, name, sets, "2")
}

/// [`write_fmu`] of FMI version `fmi` (`--fmi`).
fn write_fmu_of(dir: &TempDir, name: &str, sets: &[&str], fmi: &str) -> PathBuf {
    library();
    let out = dir.join(name);
    let mut cmd = Command::new(plant_bin());
    cmd.arg("fmu").arg(scene("cosim-10g.toml")).arg("--out").arg(&out).args(["--fmi", fmi]);
    for s in SHORT.iter().chain(sets) {
        cmd.args(["--set", s]);
    }
    let run = output_within(&mut cmd, LIMIT);
    assert_exit(&run, 0);
    assert!(stderr(&run).contains("communication step 0.00005 s"), "{}", stderr(&run));
    out
}

/// The FMU unpacked into `dir/NAME/`: its model description and the resources' URI.
fn unpack(fmu: &Path, dir: &TempDir, name: &str) -> (String, PathBuf) {
    let to = dir.join(name);
    let file = std::fs::File::open(fmu).expect("the FMU");
    zip::ZipArchive::new(file).expect("an FMU is a zip").extract(&to).expect("unpacking the FMU");
    let xml = std::fs::read_to_string(to.join("modelDescription.xml")).expect("modelDescription.xml");
    (xml, to)
}

/// An attribute of the first element that has it, in a model description.
fn attribute(xml: &str, name: &str) -> String {
    let at = xml.find(&format!(" {name}=\"")).unwrap_or_else(|| panic!("no {name} in the description"));
    let rest = &xml[at + name.len() + 3..];
    rest[..rest.find('"').expect("a closed attribute")].to_string()
}

/// Each variable's value reference by name.
fn value_references(xml: &str) -> std::collections::HashMap<String, u32> {
    xml.split("<ScalarVariable ")
        .skip(1)
        .map(|v| {
            let v = format!(" {v}");
            (attribute(&v, "name"), attribute(&v, "valueReference").parse().expect("a value reference"))
        })
        .collect()
}

// ----- The FMU through its C API -----

type Logger = unsafe extern "C" fn(*mut c_void, *const c_char, c_int, *const c_char, *const c_char, *const c_char);

#[repr(C)]
struct Callbacks {
    logger: Logger,
    allocate: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    free: Option<unsafe extern "C" fn(*mut c_void)>,
    step_finished: Option<unsafe extern "C" fn(*mut c_void, c_int)>,
    env: *mut c_void,
}

/// The FMU's log lines (status, message), per instance (the component environment).
type Log = Mutex<Vec<(c_int, String)>>;

/// The logger: the FMU always logs its message as `"%s"` and one string argument, which on
/// x86-64 Linux arrives as this sixth argument.
unsafe extern "C" fn logger(
    env: *mut c_void,
    _name: *const c_char,
    status: c_int,
    _category: *const c_char,
    format: *const c_char,
    arg: *const c_char,
) {
    let log = &*(env as *const Log);
    assert_eq!(CStr::from_ptr(format).to_str(), Ok("%s"));
    log.lock().unwrap().push((status, CStr::from_ptr(arg).to_string_lossy().into_owned()));
}

const OK: c_int = 0;
const ERROR: c_int = 3;

/// One loaded binary of an unpacked FMU.
struct Binary {
    lib: libloading::Library,
    guid: CString,
    resources: CString,
}

/// One instance, with its log.
struct Instance<'a> {
    bin: &'a Binary,
    c: *mut c_void,
    log: Box<Log>,
    _callbacks: Box<Callbacks>,
}

impl Binary {
    fn load(xml: &str, dir: &Path) -> Self {
        let id = attribute(xml, "modelIdentifier");
        let so = dir.join("binaries/linux64").join(format!("{id}.so"));
        let lib = unsafe { libloading::Library::new(&so) }.unwrap_or_else(|e| panic!("{}: {e}", so.display()));
        let guid = CString::new(attribute(xml, "guid")).unwrap();
        let resources = CString::new(format!("file://{}", dir.join("resources").display())).unwrap();
        Self { lib, guid, resources }
    }

    fn sym<T: Copy>(&self, name: &str) -> T {
        unsafe { *self.lib.get::<T>(name.as_bytes()).unwrap_or_else(|e| panic!("{name}: {e}")) }
    }

    /// `fmi2Instantiate` as co-simulation (`fmu_type` 1) with `guid`; `None` when refused.
    fn instantiate_as(&self, fmu_type: c_int, guid: &CStr) -> Result<Instance<'_>, Vec<(c_int, String)>> {
        let log: Box<Log> = Box::new(Mutex::new(Vec::new()));
        let callbacks = Box::new(Callbacks {
            logger,
            allocate: None,
            free: None,
            step_finished: None,
            env: &*log as *const Log as *mut c_void,
        });
        type F = unsafe extern "C" fn(
            *const c_char,
            c_int,
            *const c_char,
            *const c_char,
            *const Callbacks,
            c_int,
            c_int,
        ) -> *mut c_void;
        let f: F = self.sym("fmi2Instantiate");
        let c = unsafe { f(c"plant".as_ptr(), fmu_type, guid.as_ptr(), self.resources.as_ptr(), &*callbacks, 0, 0) };
        if c.is_null() {
            return Err(log.lock().unwrap().clone());
        }
        Ok(Instance { bin: self, c, log, _callbacks: callbacks })
    }

    fn instantiate(&self) -> Instance<'_> {
        self.instantiate_as(1, &self.guid).expect("instantiated")
    }
}

impl Instance<'_> {
    fn call0(&self, name: &str) -> c_int {
        let f: unsafe extern "C" fn(*mut c_void) -> c_int = self.bin.sym(name);
        unsafe { f(self.c) }
    }

    /// Set up, enter and exit initialisation.
    fn initialise(&self) {
        let setup: unsafe extern "C" fn(*mut c_void, c_int, f64, f64, c_int, f64) -> c_int =
            self.bin.sym("fmi2SetupExperiment");
        assert_eq!(unsafe { setup(self.c, 0, 0.0, 0.0, 0, 0.0) }, OK);
        assert_eq!(self.call0("fmi2EnterInitializationMode"), OK);
        assert_eq!(self.call0("fmi2ExitInitializationMode"), OK, "{:?}", self.log());
    }

    fn set(&self, vr: &[u32], v: &[f64]) -> c_int {
        let f: unsafe extern "C" fn(*mut c_void, *const u32, usize, *const f64) -> c_int = self.bin.sym("fmi2SetReal");
        unsafe { f(self.c, vr.as_ptr(), vr.len(), v.as_ptr()) }
    }

    fn get(&self, vr: &[u32]) -> Vec<f64> {
        let f: unsafe extern "C" fn(*mut c_void, *const u32, usize, *mut f64) -> c_int = self.bin.sym("fmi2GetReal");
        let mut v = vec![f64::NAN; vr.len()];
        assert_eq!(unsafe { f(self.c, vr.as_ptr(), vr.len(), v.as_mut_ptr()) }, OK, "{:?}", self.log());
        v
    }

    fn step(&self, t: f64, h: f64) -> c_int {
        let f: unsafe extern "C" fn(*mut c_void, f64, f64, c_int) -> c_int = self.bin.sym("fmi2DoStep");
        unsafe { f(self.c, t, h, 0) }
    }

    fn get_state(&self) -> *mut c_void {
        let f: unsafe extern "C" fn(*mut c_void, *mut *mut c_void) -> c_int = self.bin.sym("fmi2GetFMUstate");
        let mut s = std::ptr::null_mut();
        assert_eq!(unsafe { f(self.c, &mut s) }, OK);
        s
    }

    fn set_state(&self, s: *mut c_void) -> c_int {
        let f: unsafe extern "C" fn(*mut c_void, *mut c_void) -> c_int = self.bin.sym("fmi2SetFMUstate");
        unsafe { f(self.c, s) }
    }

    fn free_state(&self, mut s: *mut c_void) {
        let f: unsafe extern "C" fn(*mut c_void, *mut *mut c_void) -> c_int = self.bin.sym("fmi2FreeFMUstate");
        assert_eq!(unsafe { f(self.c, &mut s) }, OK);
        assert!(s.is_null());
    }

    fn serialize(&self, s: *mut c_void) -> Vec<u8> {
        let size: unsafe extern "C" fn(*mut c_void, *mut c_void, *mut usize) -> c_int =
            self.bin.sym("fmi2SerializedFMUstateSize");
        let ser: unsafe extern "C" fn(*mut c_void, *mut c_void, *mut c_char, usize) -> c_int =
            self.bin.sym("fmi2SerializeFMUstate");
        let mut n = 0;
        assert_eq!(unsafe { size(self.c, s, &mut n) }, OK);
        let mut bytes = vec![0u8; n];
        assert_eq!(unsafe { ser(self.c, s, bytes.as_mut_ptr() as *mut c_char, n) }, OK);
        bytes
    }

    /// `fmi2DeSerializeFMUstate`: the state, or the status.
    fn deserialize(&self, bytes: &[u8]) -> Result<*mut c_void, c_int> {
        let f: unsafe extern "C" fn(*mut c_void, *const c_char, usize, *mut *mut c_void) -> c_int =
            self.bin.sym("fmi2DeSerializeFMUstate");
        let mut s = std::ptr::null_mut();
        match unsafe { f(self.c, bytes.as_ptr() as *const c_char, bytes.len(), &mut s) } {
            OK => Ok(s),
            e => Err(e),
        }
    }

    fn log(&self) -> Vec<(c_int, String)> {
        self.log.lock().unwrap().clone()
    }

    /// The last log line, which must be an error's.
    fn last_error(&self) -> String {
        let log = self.log();
        let (status, line) = log.last().cloned().unwrap_or_else(|| panic!("no log line"));
        assert_eq!(status, ERROR, "{line}");
        line
    }
}

impl Drop for Instance<'_> {
    fn drop(&mut self) {
        let f: unsafe extern "C" fn(*mut c_void) = self.bin.sym("fmi2FreeInstance");
        unsafe { f(self.c) };
    }
}

/// A proportional-derivative law of the test's own on the sensor outputs, bias added: what the
/// steps below apply (its state is the previous sample, kept by the test).
fn law(bias: [f64; 2], s: [f64; 2], prev: [f64; 2]) -> [f64; 2] {
    [bias[0] - 0.05 * s[0] - 2e-6 * (s[0] - prev[0]) / 5e-5, bias[1] - 0.05 * s[1] - 2e-6 * (s[1] - prev[1]) / 5e-5]
}

/// Steps `inst` from tick `from` to `to`, one tick at a time, under [`law`], the time given as
/// an importer that adds the step to it would (rounding included); returns every output after
/// each step, as bits, and the last sample.
fn drive(inst: &Instance, vr: &Vrs, from: u64, to: u64, mut prev: [f64; 2]) -> (Vec<Vec<u64>>, [f64; 2]) {
    let mut out = Vec::new();
    let h = 5e-5;
    // An importer's clock: the sum of the steps, not tick × h.
    let mut t = 0.0;
    for _ in 0..from {
        t += h;
    }
    for _ in from..to {
        let s = inst.get(&vr.sensors);
        let c = law(vr.bias, [s[0], s[1]], prev);
        prev = [s[0], s[1]];
        assert_eq!(inst.set(&vr.inputs, &c), OK);
        assert_eq!(inst.step(t, h), OK, "at t = {t}: {:?}", inst.log());
        t += h;
        out.push(inst.get(&vr.outputs).iter().map(|v| v.to_bits()).collect());
    }
    (out, prev)
}

/// The value references the tests use.
struct Vrs {
    inputs: Vec<u32>,
    sensors: Vec<u32>,
    outputs: Vec<u32>,
    bias: [f64; 2],
    peak: u32,
    contact: u32,
}

fn vrs(xml: &str, inst: &Instance) -> Vrs {
    let m = value_references(xml);
    let inputs = vec![m["current_x_A"], m["current_y_A"]];
    let b = inst.get(&inputs);
    let mut outputs: Vec<u32> = xml
        .split("<ScalarVariable ")
        .skip(1)
        .filter(|v| v.contains("causality=\"output\""))
        .map(|v| attribute(&format!(" {v}"), "valueReference").parse().unwrap())
        .collect();
    outputs.sort();
    Vrs {
        inputs,
        sensors: vec![m["sensor_x_A"], m["sensor_y_A"]],
        outputs,
        bias: [b[0], b[1]],
        peak: m["shock[0].peak_g"],
        contact: m["contact_force_A"],
    }
}

/// Through the C API: a state taken at tick 120 (6 ms, before the touchdown) and restored after running on gives
/// the same continuation bit for bit; the same state serialised, loaded into a fresh instance
/// (another instance of the same binary) and run on, gives it too; two instances step side by
/// side as one alone; the communication point is an importer's sum of steps (rounding of a
/// few ulps taken), and a step of several ticks is their sum.
#[test]
fn states_restored_and_serialised_continue_bit_for_bit() {
    let dir = TempDir::new("fmu-state");
    let fmu = write_fmu(&dir, "plant.fmu", &[]);
    let (xml, unpacked) = unpack(&fmu, &dir, "plant");
    let bin = Binary::load(&xml, &unpacked);
    let a = bin.instantiate();
    a.initialise();
    let vr = vrs(&xml, &a);
    let (_, prev) = drive(&a, &vr, 0, 120, [0.0; 2]);
    let saved = a.get_state();
    let bytes = a.serialize(saved);
    let (first, _) = drive(&a, &vr, 120, 320, prev);
    let contact = first.iter().map(|o| f64::from_bits(o[vr.outputs.iter().position(|&v| v == vr.contact).unwrap()]));
    assert!(contact.fold(0.0, f64::max) > 0.0, "the rotor touches its race after the state was taken");

    assert_eq!(a.set_state(saved), OK, "{:?}", a.log());
    let (again, _) = drive(&a, &vr, 120, 320, prev);
    assert_eq!(again, first, "restored in the same instance");
    a.free_state(saved);

    // A fresh instance, its parameters other than the state's until the state is set.
    let b = bin.instantiate();
    assert_eq!(b.set(&[vr.peak], &[3.0]), OK);
    b.initialise();
    let loaded = b.deserialize(&bytes).expect("the serialised state loads");
    assert_eq!(b.set_state(loaded), OK, "{:?}", b.log());
    b.free_state(loaded);
    assert_eq!(b.get(&[vr.peak]), vec![10.0], "the state carries the parameters");
    let (fresh, _) = drive(&b, &vr, 120, 320, prev);
    assert_eq!(fresh, first, "serialised into a fresh instance");

    // Two instances in one process, stepped in turn, each as if alone.
    let (c, d) = (bin.instantiate(), bin.instantiate());
    c.initialise();
    d.initialise();
    let (mut pc, mut pd) = ([0.0; 2], [0.0; 2]);
    let (mut oc, mut od) = (Vec::new(), Vec::new());
    for k in 0..150 {
        let (o, p) = drive_one(&c, &vr, k, pc);
        oc.push(o);
        pc = p;
        let (o, p) = drive_one(&d, &vr, k, pd);
        od.push(o);
        pd = p;
    }
    let alone = bin.instantiate();
    alone.initialise();
    let (one, _) = drive(&alone, &vr, 0, 150, [0.0; 2]);
    assert_eq!(oc, one);
    assert_eq!(od, one);

    // Five ticks in one step are five steps of one tick (the same command held).
    let (e, f) = (bin.instantiate(), bin.instantiate());
    e.initialise();
    f.initialise();
    assert_eq!(e.step(0.0, 5.0 * 5e-5), OK, "{:?}", e.log());
    let mut t = 0.0;
    for _ in 0..5 {
        assert_eq!(f.step(t, 5e-5), OK);
        t += 5e-5;
    }
    assert_eq!(e.get(&vr.outputs), f.get(&vr.outputs));
}

/// One tick of [`drive`] at tick `k` (time `k × h`).
fn drive_one(inst: &Instance, vr: &Vrs, k: u64, prev: [f64; 2]) -> (Vec<u64>, [f64; 2]) {
    let s = inst.get(&vr.sensors);
    let c = law(vr.bias, [s[0], s[1]], prev);
    assert_eq!(inst.set(&vr.inputs, &c), OK);
    assert_eq!(inst.step(k as f64 * 5e-5, 5e-5), OK);
    (inst.get(&vr.outputs).iter().map(|v| v.to_bits()).collect(), [s[0], s[1]])
}

/// Issue 40 item 5: a refused call changes nothing. An instance given, at tick 120, every kind
/// of state `fmi2SetFMUstate` refuses (a time off its tick, a stepping state without its plant,
/// a parameter out of its bounds, a state of other parameters whose plant refuses the
/// snapshot) and other refused calls (inputs with one NaN among them, a parameter
/// while stepping, a step off the time or off the tick grid) keeps its inputs and steps on
/// writing, bit for bit, the outputs of an instance never given them.
#[test]
fn refused_calls_leave_the_instance_stepping_as_if_never_made() {
    let dir = TempDir::new("fmu-refused");
    let fmu = write_fmu(&dir, "plant.fmu", &[]);
    let (xml, unpacked) = unpack(&fmu, &dir, "plant");
    let bin = Binary::load(&xml, &unpacked);
    let clean = bin.instantiate();
    clean.initialise();
    let vr = vrs(&xml, &clean);
    let (_, prev) = drive(&clean, &vr, 0, 120, [0.0; 2]);
    let (expected, _) = drive(&clean, &vr, 120, 200, prev);

    let a = bin.instantiate();
    a.initialise();
    let (_, prev_a) = drive(&a, &vr, 0, 120, [0.0; 2]);
    assert_eq!(prev_a, prev);
    let s = a.get_state();
    let bytes = a.serialize(s);
    a.free_state(s);
    let magic = &bytes[..bytes.iter().position(|&b| b == b'\n').unwrap() + 1];
    let json: serde_json::Value =
        serde_json::from_slice(&bytes[magic.len()..]).expect("a state is JSON after its magic");
    let edited = |f: &dyn Fn(&mut serde_json::Value)| {
        let mut j = json.clone();
        f(&mut j);
        [magic, serde_json::to_string(&j).unwrap().as_bytes()].concat()
    };
    let peak = vr.peak as usize;
    let states: Vec<(&str, Vec<u8>, &str)> = vec![
        ("a time off its tick", edited(&|j| j["snapshot"]["t_s"] = 0.5.into()), "is not tick 120"),
        (
            "stepping without a plant",
            edited(&|j| {
                j["snapshot"] = serde_json::Value::Null;
                j["outputs"] = serde_json::Value::Null;
            }),
            "without its plant",
        ),
        ("a parameter out of bounds", edited(&|j| j["values"][peak] = 5000.0.into()), "outside its bounds"),
        (
            "other parameters and a time off its tick",
            edited(&|j| {
                j["values"][peak] = 3.0.into();
                j["snapshot"]["t_s"] = 0.5.into();
            }),
            "",
        ),
    ];
    let inputs = a.get(&vr.inputs);
    for (what, bytes, says) in &states {
        let s = a.deserialize(bytes).unwrap_or_else(|e| panic!("{what}: well-formed, yet {e}: {:?}", a.log()));
        assert_eq!(a.set_state(s), ERROR, "{what}");
        let line = a.last_error();
        assert!(line.contains("fmi2SetFMUstate") && line.contains(says), "{what}: {line}");
        a.free_state(s);
    }
    assert_eq!(a.set(&vr.inputs, &[1.0, f64::NAN]), ERROR);
    assert_eq!(a.set(&[vr.peak], &[5.0]), ERROR);
    assert_eq!(a.get(&vr.inputs), inputs, "the refused calls took no input");
    let t = 120.0 * 5e-5;
    assert_eq!(a.step(t + 1e-3, 5e-5), ERROR);
    assert_eq!(a.step(t, 0.5 * 5e-5), ERROR);
    assert!(a.log().iter().all(|(_, line)| !line.contains("internal error")), "{:?}", a.log());
    let (after, _) = drive(&a, &vr, 120, 200, prev);
    assert_eq!(after, expected, "the instance steps on as one never given the refused calls");
}

/// Issue 40 item 5: where the plant starts is the scene's, stated and chosen when the FMU is
/// written. The rotor of `cosim-10g` (m = 11.5 kg, e = 2 µm, 500 Hz, phase 0) starts at t = 0 on
/// the linear unbalance orbit of the scene's controller design, Z = m e ω² / (k_e − m ω² + j c_e ω)
/// with c_e = 2 ξ_e √(k_e m) (x = Re Z, y = Im Z): k_e = 1e6 N/m, ξ_e = 0.026 as written, and
/// another design with `--set`; at rest at the centre with `initial.unbalance_orbit = false`;
/// shifted by `initial.rotor_x_um`. Each against the closed form, computed here.
#[test]
fn the_start_is_the_scenes_controller_designs_orbit_chosen_with_set() {
    let dir = TempDir::new("fmu-start");
    let (m, e, w) = (11.5, 2e-6, std::f64::consts::TAU * 500.0);
    let orbit = |k: f64, xi: f64| {
        let c = 2.0 * xi * (k * m).sqrt();
        // m e ω² / (a + j b), a = k − m ω², b = c ω.
        let (a, b) = (k - m * w * w, c * w);
        let f = m * e * w * w / (a * a + b * b);
        [f * a, -f * b]
    };
    let cases: [(&str, &[&str], [f64; 2]); 4] = [
        ("as-written", &[], orbit(1e6, 0.026)),
        ("other-design", &["controller.stiffness_n_per_m=4e6", "controller.damping_ratio=0.1"], orbit(4e6, 0.1)),
        ("at-rest", &["initial.unbalance_orbit=false"], [0.0, 0.0]),
        ("offset", &["initial.rotor_x_um=5"], {
            let z = orbit(1e6, 0.026);
            [z[0] + 5e-6, z[1]]
        }),
    ];
    for (name, sets, expected) in cases {
        let fmu = write_fmu(&dir, &format!("{name}.fmu"), sets);
        let (xml, unpacked) = unpack(&fmu, &dir, name);
        let bin = Binary::load(&xml, &unpacked);
        let a = bin.instantiate();
        a.initialise();
        let m = value_references(&xml);
        let got = a.get(&[m["rotor_x_A"], m["rotor_y_A"]]);
        for (g, x) in got.iter().zip(expected) {
            assert!((g - x).abs() <= 1e-12 * e, "{name}: the start is {got:?} m, the closed form {expected:?} m");
        }
    }
}

/// Issue 40 item 7: the FMU's `resources/scene.toml` replaced by a FIFO (or a file of `/proc`)
/// is refused at `fmi2Instantiate` at once, with a log line naming it: it blocked the importer.
#[cfg(target_os = "linux")]
#[test]
fn a_fifo_as_the_fmus_scene_is_refused_at_once() {
    let dir = TempDir::new("fmu-scene-fifo");
    let fmu = write_fmu(&dir, "plant.fmu", &[]);
    let (xml, unpacked) = unpack(&fmu, &dir, "plant");
    let scene_file = unpacked.join("resources/scene.toml");
    for (what, make) in [
        ("a FIFO", &(|p: &Path| assert!(Command::new("mkfifo").arg(p).status().unwrap().success())) as &dyn Fn(&Path)),
        ("a file of /proc", &|p: &Path| std::os::unix::fs::symlink("/proc/self/status", p).unwrap()),
    ] {
        std::fs::remove_file(&scene_file).unwrap();
        make(&scene_file);
        let bin = Binary::load(&xml, &unpacked);
        let log = bin.instantiate_as(1, &bin.guid).err().unwrap_or_else(|| panic!("{what}: instantiated"));
        let line = &log.last().expect("a log line").1;
        assert!(line.contains("scene.toml") && line.contains("not a regular file"), "{what}: {line}");
    }
}

/// Issue 40 item 4: an FMU whose `resources/scene.toml` was edited in a key that is no FMU
/// variable (the rotor's mass, the integrator) ran another plant under the same GUID; the GUID
/// now covers the whole resolved scene, and `fmi2Instantiate` refuses with a line saying so.
#[test]
fn an_edited_scene_in_the_fmu_is_refused_at_instantiation() {
    let dir = TempDir::new("fmu-scene-edited");
    let fmu = write_fmu(&dir, "plant.fmu", &[]);
    let (xml, unpacked) = unpack(&fmu, &dir, "plant");
    let scene_file = unpacked.join("resources/scene.toml");
    let original = std::fs::read_to_string(&scene_file).unwrap();
    // The untouched FMU instantiates.
    drop(Binary::load(&xml, &unpacked).instantiate());
    for (from, to) in [("mass_kg = 11.5", "mass_kg = 12.0"), ("method = \"dp5\"", "method = \"rk4\"")] {
        assert!(original.contains(from), "{from} not in the FMU's scene:\n{original}");
        std::fs::write(&scene_file, original.replacen(from, to, 1)).unwrap();
        let bin = Binary::load(&xml, &unpacked);
        let log = bin.instantiate_as(1, &bin.guid).err().unwrap_or_else(|| panic!("{to}: instantiated"));
        let line = &log.last().expect("a log line").1;
        assert!(line.contains("fmuGUID = ") && line.contains("resources/scene.toml was edited"), "{to}: {line}");
    }
}

/// Every bad call returns `fmi2Error` with a log line that says what was wrong, and the
/// instance goes on where that is possible; a diverging plant returns `fmi2Error` with its time
/// and state; the instantiation of another FMU's GUID or as model exchange is refused.
#[test]
fn bad_calls_return_an_error_and_a_log_line_never_a_crash() {
    let dir = TempDir::new("fmu-bad");
    let fmu = write_fmu(&dir, "plant.fmu", &["integrator.radius_guard_mm=0.001"]);
    let (xml, unpacked) = unpack(&fmu, &dir, "plant");
    let bin = Binary::load(&xml, &unpacked);

    let refused = bin.instantiate_as(1, c"{00000000-0000-0000-0000-000000000000}").err().expect("refused");
    assert!(refused.last().unwrap().1.contains("fmuGUID = {00000000"), "{refused:?}");
    let refused = bin.instantiate_as(0, &bin.guid).err().expect("refused");
    assert!(refused.last().unwrap().1.contains("co-simulation only"), "{refused:?}");

    let a = bin.instantiate();
    let vr = vrs(&xml, &a);
    let m = value_references(&xml);
    assert_eq!(a.step(0.0, 5e-5), ERROR);
    assert!(a.last_error().contains("fmi2DoStep: not allowed while the FMU is instantiated"), "{:?}", a.log());
    assert_eq!(a.set(&[vr.peak], &[5000.0]), ERROR);
    assert!(a.last_error().contains("shock[0].peak_g = 5000 g_n is outside its bounds"), "{:?}", a.log());
    assert_eq!(a.set(&[m["touchdown.air_gap_mm"]], &[f64::NAN]), ERROR);
    assert_eq!(a.set(&[m["radius_A"]], &[0.0]), ERROR);
    assert!(a.last_error().contains("radius_A is an output"), "{:?}", a.log());
    assert_eq!(a.set(&vr.inputs, &[f64::NAN, 0.0]), ERROR);
    assert!(a.last_error().contains("current_x_A = NaN A: an input must be finite"), "{:?}", a.log());
    a.initialise();
    assert_eq!(a.set(&[vr.peak], &[5.0]), ERROR);
    assert!(a.last_error().contains("fixed after initialization"), "{:?}", a.log());
    assert_eq!(a.set(&vr.inputs, &[f64::INFINITY, 0.0]), ERROR);
    assert_eq!(a.get(&vr.inputs), vr.bias.to_vec(), "a refused input is not taken");

    // Steps: a fraction of a tick, a gap in time, and an importer's rounding (taken).
    assert_eq!(a.step(0.0, 0.7 * 5e-5), ERROR);
    let line = a.last_error();
    assert!(
        line.contains("is not a whole number of the plant's tick, 5e-5 s") && line.contains("use a step of 5e-5 s"),
        "{line}"
    );
    assert_eq!(a.step(0.0, 2.5 * 5e-5), ERROR);
    assert!(a.last_error().contains("(or 0.00015"), "{:?}", a.log());
    assert_eq!(a.step(1e-3, 5e-5), ERROR);
    assert!(a.last_error().contains("currentCommunicationPoint = 0.00100000000000000"), "{:?}", a.log());
    assert_eq!(a.step(3e-18, 5e-5 + 3e-18), OK, "{:?}", a.log());
    assert_eq!(a.step(5e-5 * (1.0 + 1e-12), 5e-5 * (1.0 - 1e-12)), OK, "{:?}", a.log());

    // Corrupt and foreign states.
    let s = a.get_state();
    let bytes = a.serialize(s);
    a.free_state(s);
    for (what, bad) in [
        ("truncated", bytes[..bytes.len() / 2].to_vec()),
        ("not this FMU's", b"{\"format\": 1}".to_vec()),
        (
            "a flipped number",
            String::from_utf8(bytes.clone()).unwrap().replacen("\"tick\":2", "\"tick\":x", 1).into_bytes(),
        ),
    ] {
        assert_eq!(a.deserialize(&bad).err(), Some(ERROR), "{what}");
        assert!(a.last_error().contains("fmi2DeSerializeFMUstate"), "{what}: {:?}", a.log());
    }
    let text = String::from_utf8(bytes).unwrap();
    let wrong_time = text.replacen("\"t_s\":0.0001", "\"t_s\":0.5", 1);
    let s = a.deserialize(wrong_time.as_bytes()).expect("well-formed");
    assert_eq!(a.set_state(s), ERROR);
    assert!(a.last_error().contains("is not tick 2"), "{:?}", a.log());
    a.free_state(s);

    // FMIKit-Simulink#310: at t = 2.95 s (a state moved to tick 59 000) the importer's
    // 2.9500000000030000 is the FMU's tick-grid time, taken.
    let t = 59_000.0 * 5e-5;
    let late = text
        .replacen("\"tick\":2,", "\"tick\":59000,", 1)
        .replacen("\"t_s\":0.0001", &format!("\"t_s\":{t:?}"), 1)
        .replacen("\"next_output\":3", "\"next_output\":59001", 1);
    assert_ne!(late, text);
    let s = a.deserialize(late.as_bytes()).expect("well-formed");
    assert_eq!(a.set_state(s), OK, "{:?}", a.log());
    a.free_state(s);
    assert_eq!(a.step(2.950_000_000_003, 5e-5), OK, "{:?}", a.log());
    assert_eq!(a.step(2.950_000_000_003 + 5e-5, 5e-5), OK, "{:?}", a.log());

    // Divergence: the rotor, left to its bias currents, falls into its race; its radius passes
    // the guard (1 µm past the air gap and the ball clearance) within 60 ms.
    let b = bin.instantiate();
    b.initialise();
    let mut status = OK;
    let mut k = 0;
    while status == OK && k < 1200 {
        status = b.step(k as f64 * 5e-5, 5e-5);
        k += 1;
    }
    assert_eq!(status, ERROR, "the plant diverged within {k} ticks");
    let line = b.last_error();
    assert!(
        line.contains("the plant diverged at t = ") && line.contains("rotor radius") && line.contains("state"),
        "{line}"
    );
    assert_eq!(b.step(k as f64 * 5e-5, 5e-5), ERROR);
    assert!(b.last_error().contains("not allowed while the FMU is failed"), "{:?}", b.log());
    assert_eq!(b.call0("fmi2Reset"), OK);
    b.initialise();
    assert_eq!(b.step(0.0, 5e-5), OK, "after fmi2Reset the FMU steps again");
}

// ----- FMPy -----

fn fmpy_python() -> PathBuf {
    fmpy_venv().join("bin/python")
}

/// The columns compared, FMU output against `trace.csv`.
const SAME: &[(&str, &str)] = &[
    ("t_s", "t_s"),
    ("rotor_x_A", "dx_m"),
    ("rotor_y_A", "dy_m"),
    ("speed", "rotor_speed_rad_s"),
    ("contact_force_A", "contact_force_n"),
    ("race_speed_A", "race_speed_rad_s"),
    ("housing_x", "housing_x_m"),
    ("housing_y", "housing_y_m"),
];

/// The headline: FMPy closing the loop around the FMU with the kit's `pd` at 20 kHz, one
/// sample of delay, reads at every communication point the row `plant run` writes in `sampled`
/// mode, bit for bit, through the shock and the touchdown (every row but the last: the scene's
/// 30 ms are not a whole number of 50 µs ticks in binary, and `plant run` ends its last tick at
/// 0.03 s, the FMU on the tick grid), and applies over each tick the command `plant run`
/// applies. A state serialised at tick 300 by one Python process, loaded by another, goes on
/// with the same rows. The FMI 3.0 FMU of the scene gives the same rows. FMPy's validation
/// finds no problem in either; `simulate_fmu` runs both.
#[test]
fn fmpy_closes_the_loop_with_the_kits_pd_as_plant_run_does() {
    let dir = TempDir::new("fmu-fmpy");
    let fmu = write_fmu(&dir, "plant.fmu", &[]);
    let script = workspace_root().join("plant/fmu/python/closed_loop.py");
    let looped = dir.join("loop.csv");
    let state = dir.join("state.bin");
    let run = output_within(
        Command::new(fmpy_python()).arg(&script).arg(&fmu).arg(&looped).arg("--save-at").arg("300").arg(&state),
        LIMIT,
    );
    assert_exit(&run, 0);
    let out = dir.join("run");
    let mut cmd = common::plant_run(
        &scene("cosim-10g.toml"),
        &out,
        &[SHORT[0], SHORT[1], "controller.mode=\"sampled\"", "output.plots=false"],
    );
    assert_exit(&output_within(cmd.arg("--quiet"), LIMIT), 0);
    let (fmu_rows, trace) = (Csv::read(&looped), Csv::read(&out.join("trace.csv")));
    assert_eq!(fmu_rows.rows.len(), trace.rows.len(), "one row per tick and the row at t = 0");
    let n = trace.rows.len();
    for (mine, theirs) in SAME {
        let (a, b) = (fmu_rows.column(mine), trace.column(theirs));
        let differ = (0..n - 1).find(|&i| a[i].to_bits() != b[i].to_bits());
        assert_eq!(differ, None, "{mine} against trace.csv's {theirs}: first difference at row {differ:?}");
    }
    for (mine, theirs) in [("current_x_A", "ix_a"), ("current_y_A", "iy_a")] {
        let (a, b) = (fmu_rows.column(mine), trace.column(theirs));
        let differ = (0..n - 1).find(|&i| a[i].to_bits() != b[i + 1].to_bits());
        assert_eq!(differ, None, "the command over tick k against trace.csv's {theirs} at row k + 1");
    }
    let force = fmu_rows.column("contact_force_A");
    assert!(force.iter().cloned().fold(0.0, f64::max) > 1000.0, "the shock drives the rotor into its race");
    let (t_fmu, t_run) = (fmu_rows.column("t_s")[n - 1], trace.column("t_s")[n - 1]);
    assert_eq!(t_run, 0.03);
    assert_eq!(t_fmu, 600.0 * 5e-5, "the FMU ends on the tick grid");

    // Another process from the state saved at tick 300.
    let rest = dir.join("rest.csv");
    let run = output_within(
        Command::new(fmpy_python()).arg(&script).arg(&fmu).arg(&rest).arg("--from-state").arg(&state),
        LIMIT,
    );
    assert_exit(&run, 0);
    let rest = Csv::read(&rest);
    assert_eq!(rest.rows.len(), n - 300);
    let bits =
        |rows: &[Vec<f64>]| rows.iter().map(|r| r.iter().map(|v| v.to_bits()).collect::<Vec<_>>()).collect::<Vec<_>>();
    assert_eq!(bits(&rest.rows), bits(&fmu_rows.rows[300..]), "the run continued in another process");

    // The FMI 3.0 FMU of the same scene in the same loop: the same file, byte for byte.
    let fmu3 = write_fmu_of(&dir, "plant3.fmu", &[], "3");
    let looped3 = dir.join("loop3.csv");
    assert_exit(&output_within(Command::new(fmpy_python()).arg(&script).arg(&fmu3).arg(&looped3), LIMIT), 0);
    assert!(std::fs::read(&looped3).unwrap() == std::fs::read(&looped).unwrap(), "FMI 3.0 against FMI 2.0");

    // FMPy's own checks, of both.
    let check = "import sys, fmpy\nfrom fmpy.validation import validate_fmu\nproblems = validate_fmu(sys.argv[1])\n\
                 print('version:', fmpy.read_model_description(sys.argv[1]).fmiVersion, 'problems:', problems)\n\
                 r = fmpy.simulate_fmu(sys.argv[1], stop_time=0.002)\n\
                 print('rows:', len(r), 'last t:', r['time'][-1], 'names:', ','.join(r.dtype.names))";
    for (f, version) in [(&fmu, "2.0"), (&fmu3, "3.0")] {
        let out = output_within(Command::new(fmpy_python()).arg("-c").arg(check).arg(f), LIMIT);
        assert_exit(&out, 0);
        let said = String::from_utf8_lossy(&out.stdout);
        assert!(said.contains(&format!("version: {version} problems: []")), "{said}");
        assert!(said.contains("rows: 41 last t: 0.002") && said.contains("sensor_y_A"), "{said}");
    }
}

/// `plant fmu` checks the scene as `plant run` does, and names a missing binary with the cargo
/// command that builds it.
#[test]
fn plant_fmu_refuses_a_bad_scene_and_names_a_missing_binary() {
    let dir = TempDir::new("fmu-cli");
    let mut cmd = Command::new(plant_bin());
    cmd.arg("fmu").arg(scene("cosim-10g.toml")).arg("--out").arg(dir.join("x.fmu"));
    let out = output_within(cmd.args(["--set", "touchdown.air_gap_mm=-1"]), LIMIT);
    assert_exit(&out, 2);
    assert!(stderr(&out).contains("touchdown.air_gap_mm"), "{}", stderr(&out));
    let mut cmd = Command::new(plant_bin());
    cmd.arg("fmu").arg(scene("cosim-10g.toml")).arg("--out").arg(dir.join("x.fmu"));
    let out = output_within(cmd.args(["--library", "/nonexistent/libplant_fmu.so"]), LIMIT);
    assert_exit(&out, 2);
    assert!(stderr(&out).contains("--library /nonexistent/libplant_fmu.so: no such file"), "{}", stderr(&out));
    assert!(!dir.join("x.fmu").exists());
    // A `plant` with no binary beside it says how to build one.
    let lonely = dir.join("plant");
    install_executable(plant_bin(), &lonely);
    let out = output_within(
        Command::new(&lonely).arg("fmu").arg(scene("cosim-10g.toml")).arg("--out").arg(dir.join("x.fmu")),
        LIMIT,
    );
    assert_exit(&out, 2);
    assert!(
        stderr(&out).contains("libplant_fmu.so is not next to") && stderr(&out).contains("cargo build"),
        "{}",
        stderr(&out)
    );
    assert!(stderr(&out).contains("-p plant-fmu"), "{}", stderr(&out));
}
