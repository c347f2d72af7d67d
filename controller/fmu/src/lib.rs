//! A controller FMU as the testbed's controller (issue 29 item 1; docs/guide/fmu-controller.md).
//!
//! A Functional Mock-up Unit exported from Simulink, OpenModelica, pythonfmu or written in C
//! runs as a [`controller::RotorLaw`]: FMI 2.0 and FMI 3.0 co-simulation FMUs step once per
//! controller tick (`doStep` over the controller period); an FMI 2.0 model-exchange FMU is
//! integrated over each period with a fixed-step method ([`Solver`]). Its variables meet the
//! wire's signals by a naming convention ([`signal_names`]) or the scene's mapping table.
//!
//! * [`inspect`] checks an `.fmu` without loading it (the plant does, when a scene loads): a
//!   zip, FMI 2.0 or 3.0, an interface the host runs, a binary for Linux x86-64, every signal's
//!   variable.
//! * [`Fmu::open`] unpacks it into a temporary folder and loads its library; [`Fmu::law`]
//!   instantiates it, sets `[controller.params]` by name, initialises it and returns the law.
//! * The binary `controller-fmu` serves it over the wire (`controller::serve`); the plant starts
//!   it for a scene with `controller.fmu` in lockstep and realtime modes, and runs the law in its
//!   own process in sampled mode.

pub mod binding;
pub mod description;
pub mod spec;

use binding::{status_name, Fmi2, Fmi3, Status, FMI2_CALLBACKS};
use controller::{LawError, Params, RotorDesign, RotorLaw, RotorSample, ROTOR_AXES};
pub use description::{Causality, Description, FmiVersion, VarType, Variable};
pub use spec::{Solver, Spec};
use std::ffi::{c_void, CString};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// The law's name (`controller.law` of a scene with `controller.fmu`).
pub const LAW_NAME: &str = "fmu";

/// Why an FMU cannot be opened or run; the message names the file, the variable or the call.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("controller.fmu = \"{path}\": {why}", path = path.display())]
pub struct FmuError {
    /// The `.fmu` file.
    pub path: PathBuf,
    /// What is wrong.
    pub why: String,
}

/// Which FMI interface the host runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interface {
    /// Co-simulation (FMI 2.0 or 3.0): `doStep` per tick.
    CoSimulation,
    /// Model exchange (FMI 2.0): integrated by the host.
    ModelExchange,
}

/// The axes' names of a rotor of `axes` axes, in axis order: `x`, `y` (planar); `x_a`, `y_a`,
/// `x_b`, `y_b` (two-plane).
pub fn axis_names(axes: usize) -> &'static [&'static str] {
    if axes == 4 {
        &["x_a", "y_a", "x_b", "y_b"]
    } else {
        &["x", "y"]
    }
}

/// The wire's signals of a rotor of `axes` axes: inputs (`sensor_<axis>` (V), `speed`
/// (rad/s), `angle` (rad), `time` (s)) and outputs (`current_<axis>` (A)). By the naming
/// convention each is the FMU variable of the same name; the scene's `controller.fmu.map`
/// names another.
pub fn signal_names(axes: usize) -> (Vec<String>, Vec<String>) {
    let names = axis_names(axes);
    let mut inputs: Vec<String> = names.iter().map(|a| format!("sensor_{a}")).collect();
    inputs.extend(["speed", "angle", "time"].map(String::from));
    (inputs, names.iter().map(|a| format!("current_{a}")).collect())
}

/// What each signal is bound to: value references of the FMU's Float64 variables.
#[derive(Clone, Debug, PartialEq)]
pub struct Binding {
    /// Per axis: the sensor input.
    pub sensors: Vec<u32>,
    /// The keyphasor's speed, angle and the time, when the FMU has them.
    pub speed: Option<u32>,
    /// The keyphasor's angle.
    pub angle: Option<u32>,
    /// The plant's time.
    pub time: Option<u32>,
    /// Per axis: the current output.
    pub currents: Vec<u32>,
}

/// Binds the signals of a rotor of `axes` axes to `md`'s variables: the map's name or the
/// convention's; sensors and currents required, `speed`, `angle`, `time` optional (a mapped
/// one required). A signal the rotor has not, or a variable of the wrong causality or type, is
/// refused with the FMU's inputs or outputs listed.
pub fn bind(md: &Description, spec: &Spec, axes: usize) -> Result<Binding, String> {
    let (inputs, outputs) = signal_names(axes);
    for key in spec.map.keys() {
        if !inputs.contains(key) && !outputs.contains(key) {
            return Err(format!(
                "controller.fmu.map.{key}: not a signal of this rotor ({axes} axes): its signals are {}, {}",
                inputs.join(", "),
                outputs.join(", ")
            ));
        }
    }
    let find = |signal: &str, causality: Causality, required: bool| -> Result<Option<u32>, String> {
        let mapped = spec.map.get(signal);
        let name = mapped.map(String::as_str).unwrap_or(signal);
        let what = if causality == Causality::Input { "inputs" } else { "outputs" };
        let source = match mapped {
            Some(_) => format!("controller.fmu.map.{signal} = \"{name}\""),
            None => format!("signal {signal} (the naming convention; controller.fmu.map names another variable)"),
        };
        let Some(v) = md.variable(name) else {
            if mapped.is_none() && !required {
                return Ok(None);
            }
            return Err(format!(
                "{source}: the FMU has no variable `{name}` (its {what}: {})",
                md.names_of(&causality)
            ));
        };
        if v.causality != causality {
            return Err(format!(
                "{source}: the FMU's variable `{name}` is not an {} (its {what}: {})",
                if causality == Causality::Input { "input" } else { "output" },
                md.names_of(&causality)
            ));
        }
        if v.ty != VarType::Float64 || v.array {
            let label = v.ty.label(md.version);
            return Err(format!(
                "{source}: the FMU's variable `{name}` is {} {label}{}, not a scalar {}",
                if label.starts_with(['A', 'E', 'I', 'O', 'U']) { "an" } else { "a" },
                if v.array { " array" } else { "" },
                VarType::Float64.label(md.version)
            ));
        }
        Ok(Some(v.vr))
    };
    let names = axis_names(axes);
    let mut b = Binding { sensors: Vec::new(), speed: None, angle: None, time: None, currents: Vec::new() };
    for a in names {
        b.sensors.push(find(&format!("sensor_{a}"), Causality::Input, true)?.unwrap_or_default());
        b.currents.push(find(&format!("current_{a}"), Causality::Output, true)?.unwrap_or_default());
    }
    b.speed = find("speed", Causality::Input, false)?;
    b.angle = find("angle", Causality::Input, false)?;
    b.time = find("time", Causality::Input, false)?;
    Ok(b)
}

/// The interface the host runs of `md`: co-simulation when offered, else FMI 2.0 model exchange.
fn interface_of(md: &Description) -> Result<(Interface, String), String> {
    if let Some(id) = &md.co_simulation {
        return Ok((Interface::CoSimulation, id.clone()));
    }
    match (&md.model_exchange, md.version) {
        (Some(id), FmiVersion::Two) => Ok((Interface::ModelExchange, id.clone())),
        (Some(_), FmiVersion::Three) => {
            Err("an FMI 3.0 model-exchange FMU: this host runs FMI 3.0 co-simulation (and FMI 2.0 model exchange); export it as co-simulation".into())
        }
        (None, _) => Err("modelDescription.xml declares neither <CoSimulation> nor <ModelExchange>".into()),
    }
}

/// What [`inspect`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct Inspected {
    /// The model description.
    pub description: Description,
    /// The interface the host will run.
    pub interface: Interface,
    /// The signals' variables.
    pub binding: Binding,
}

/// Checks the `.fmu` of `spec` for a rotor of `axes` axes without loading its code: a zip
/// with a modelDescription.xml of FMI 2.0 or 3.0, an interface the host runs, the shared
/// library for Linux x86-64, every signal's variable.
pub fn inspect(spec: &Spec, axes: usize) -> Result<Inspected, FmuError> {
    let (description, interface) = inspect_archive(spec)?;
    let binding = bind(&description, spec, axes).map_err(|why| FmuError { path: spec.path.clone(), why })?;
    Ok(Inspected { description, interface, binding })
}

/// The most an FMU may hold unpacked (bytes): every file of it together. A Simulink or
/// pythonfmu controller is a few MB; a zip bomb (2 MB that unpack to 2 GiB) is refused.
pub const MAX_UNPACKED_BYTES: u64 = 512 << 20;

/// The most entries (files and folders) an FMU may hold.
pub const MAX_ENTRIES: usize = 10_000;

/// The largest `modelDescription.xml` read (bytes).
const MAX_DESCRIPTION_BYTES: u64 = 64 << 20;

/// Opens `path` for reading if it is a regular file, without blocking: opened with
/// `O_NONBLOCK` (a FIFO or a device opens at once instead of waiting for a writer) and
/// refused unless the opened file is a regular one (`fstat` of what was opened, not of the
/// name).
pub fn open_regular(path: &Path) -> Result<std::fs::File, String> {
    use std::os::unix::fs::OpenOptionsExt;
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
        .map_err(|e| format!("cannot open it: {e}"))?;
    let meta = file.metadata().map_err(|e| format!("cannot read its metadata: {e}"))?;
    if !meta.is_file() {
        let kind = {
            use std::os::unix::fs::FileTypeExt;
            let t = meta.file_type();
            if t.is_dir() {
                "a folder"
            } else if t.is_fifo() {
                "a FIFO"
            } else if t.is_char_device() || t.is_block_device() {
                "a device"
            } else if t.is_socket() {
                "a socket"
            } else {
                "not a regular file"
            }
        };
        return Err(format!("{kind}, not a regular file: an FMU is a file (a zip archive)"));
    }
    Ok(file)
}

/// [`inspect`] without the signals (the rotor's axes not known yet).
pub fn inspect_archive(spec: &Spec) -> Result<(Description, Interface), FmuError> {
    let fail = |why: String| FmuError { path: spec.path.clone(), why };
    let file = open_regular(&spec.path).map_err(fail)?;
    let mut zip = zip::ZipArchive::new(file)
        .map_err(|e| fail(format!("not an FMU: an FMU is a zip archive, and this file is not one ({e})")))?;
    let mut xml = String::new();
    zip.by_name("modelDescription.xml")
        .map_err(|_| fail("not an FMU: the archive has no modelDescription.xml".into()))?
        .take(MAX_DESCRIPTION_BYTES + 1)
        .read_to_string(&mut xml)
        .map_err(|e| fail(format!("modelDescription.xml cannot be read: {e}")))?;
    if xml.len() as u64 > MAX_DESCRIPTION_BYTES {
        return Err(fail(format!(
            "modelDescription.xml is larger than {} MiB unpacked (the limit of a model description)",
            MAX_DESCRIPTION_BYTES >> 20
        )));
    }
    let description = Description::parse(&xml).map_err(fail)?;
    let (interface, id) = interface_of(&description).map_err(fail)?;
    let binary = format!("binaries/{}/{id}.so", description.version.platform());
    if zip.by_name(&binary).is_err() {
        let mut platforms: Vec<String> = zip
            .file_names()
            .filter_map(|n| n.strip_prefix("binaries/"))
            .filter_map(|n| n.split('/').next())
            .filter(|p| !p.is_empty())
            .map(String::from)
            .collect();
        platforms.sort();
        platforms.dedup();
        let has = if platforms.is_empty() {
            "no binaries at all".to_string()
        } else {
            format!("binaries for {}", platforms.join(", "))
        };
        let sources = if zip.file_names().any(|n| n.starts_with("sources/")) {
            " (it ships sources/: compile them for Linux x86-64 and re-export)"
        } else {
            ""
        };
        return Err(fail(format!("no binary for this platform (Linux x86-64: {binary}); the FMU has {has}{sources}")));
    }
    Ok((description, interface))
}

/// Unpacks `zip` into the new folder `dir`, within [`MAX_ENTRIES`] entries and
/// [`MAX_UNPACKED_BYTES`] bytes counted as they are written (an entry's declared size may lie);
/// refused past either, naming the limit, and for an entry that points outside `dir` or is a
/// symbolic link. Written by hand: the zip crate's `extract` has no limit.
fn unpack(zip: &mut zip::ZipArchive<std::fs::File>, dir: &Path) -> Result<(), String> {
    if zip.len() > MAX_ENTRIES {
        return Err(format!(
            "{} entries in the archive; an FMU may hold at most {MAX_ENTRIES} (a zip bomb?)",
            zip.len()
        ));
    }
    let limit = || {
        format!(
            "unpacked, it holds more than {} MiB (the limit of an FMU's unpacked size, {MAX_UNPACKED_BYTES} bytes):              a zip bomb, or an FMU far larger than a controller's",
            MAX_UNPACKED_BYTES >> 20
        )
    };
    let mut left = MAX_UNPACKED_BYTES;
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    for i in 0..zip.len() {
        let mut entry = zip.by_index(i).map_err(|e| format!("entry {i} of the archive cannot be read: {e}"))?;
        let name = entry.name().to_string();
        let Some(relative) = entry.enclosed_name() else {
            return Err(format!("the archive's entry {name:?} points outside the FMU's folder"));
        };
        let out = dir.join(relative);
        if entry.is_dir() {
            std::fs::create_dir_all(&out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
            continue;
        }
        if entry.is_symlink() {
            return Err(format!("the archive's entry {name:?} is a symbolic link; an FMU's files are regular files"));
        }
        if entry.size() > left {
            return Err(limit());
        }
        if let Some(parent) = out.parent() {
            std::fs::create_dir_all(parent).map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
        }
        let mut file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&out)
            .map_err(|e| format!("cannot unpack {name:?} into {}: {e}", out.display()))?;
        let written = std::io::copy(&mut (&mut entry).take(left + 1), &mut file)
            .map_err(|e| format!("cannot unpack {name:?}: {e}"))?;
        if written > left {
            return Err(limit());
        }
        left -= written;
        if let Some(mode) = entry.unix_mode() {
            use std::os::unix::fs::PermissionsExt;
            // The archive's permission bits (an executable among the resources), no others.
            let _ = file.set_permissions(std::fs::Permissions::from_mode(mode & 0o777));
        }
    }
    Ok(())
}

/// The prefix of the folders FMUs are unpacked into, in the temporary folder.
const COPY_PREFIX: &str = "amb-testbed-fmu-";

/// Removes the unpacked copies left by processes that are gone (killed before they could
/// remove theirs: SIGKILL, a crash inside the FMU): each copy's name holds its process's id,
/// and a copy is removed when that process no longer exists and the copy is the user's.
/// Run each time an FMU is opened, so a leaked copy lives until the next run that opens one.
fn remove_stale_copies() {
    let Ok(entries) = std::fs::read_dir(std::env::temp_dir()) else { return };
    // SAFETY: getuid cannot fail.
    let uid = unsafe { libc::getuid() };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name
            .to_str()
            .and_then(|n| n.strip_prefix(COPY_PREFIX))
            .and_then(|rest| rest.split('-').next())
            .and_then(|p| p.parse::<libc::pid_t>().ok())
        else {
            continue;
        };
        use std::os::unix::fs::MetadataExt;
        let ours = entry.metadata().is_ok_and(|m| m.is_dir() && m.uid() == uid);
        // SAFETY: signal 0 only checks whether the process exists.
        let gone = pid > 0
            && unsafe { libc::kill(pid, 0) } != 0
            && std::io::Error::last_os_error().raw_os_error() == Some(libc::ESRCH);
        if ours && gone {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

/// A folder removed with everything in it when dropped.
struct TempDir(PathBuf);

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The library of an opened FMU.
enum Api {
    Two(Fmi2),
    Three(Fmi3),
}

/// An opened FMU: unpacked into a temporary folder (removed when the last user drops it) and
/// its library loaded.
pub struct Fmu {
    spec: Spec,
    description: Description,
    interface: Interface,
    api: Api,
    resources: PathBuf,
    // Last: the folder outlives the library loaded from it.
    _dir: TempDir,
}

/// Set while one tick's FMI calls run (monotonic ns at their start), else 0: what the host's
/// watchdog reads ([`inside_since_ns`]).
static INSIDE_SINCE_NS: AtomicU64 = AtomicU64::new(0);
/// The tick the FMI calls in progress belong to.
static INSIDE_TICK: AtomicU64 = AtomicU64::new(0);

/// When the FMI calls in progress started (monotonic ns; `None`: not inside the FMU) and
/// their tick.
pub fn inside_since_ns() -> Option<(u64, u64)> {
    match INSIDE_SINCE_NS.load(Ordering::Relaxed) {
        0 => None,
        ns => Some((ns, INSIDE_TICK.load(Ordering::Relaxed))),
    }
}

/// Monotonic clock (ns).
pub fn monotonic_ns() -> u64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: a valid timespec pointer.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    (ts.tv_sec as u64) * 1_000_000_000 + ts.tv_nsec as u64
}

impl Fmu {
    /// Unpacks and loads the FMU of `spec`, checked by [`inspect_archive`] (the signals are
    /// bound by [`Fmu::law`], for the rotor it drives).
    pub fn open(spec: &Spec) -> Result<Arc<Self>, FmuError> {
        let (description, interface) = inspect_archive(spec)?;
        let fail = |why: String| FmuError { path: spec.path.clone(), why };
        static COUNT: AtomicU64 = AtomicU64::new(0);
        let dir = std::env::temp_dir().join(format!(
            "{COPY_PREFIX}{}-{}-{}",
            std::process::id(),
            COUNT.fetch_add(1, Ordering::Relaxed),
            monotonic_ns()
        ));
        remove_stale_copies();
        let dir = TempDir(dir);
        let file = open_regular(&spec.path).map_err(fail)?;
        let mut zip = zip::ZipArchive::new(file).map_err(|e| fail(format!("not a zip archive: {e}")))?;
        unpack(&mut zip, &dir.0).map_err(fail)?;
        let id = match interface {
            Interface::CoSimulation => description.co_simulation.clone(),
            Interface::ModelExchange => description.model_exchange.clone(),
        }
        .unwrap_or_default();
        let lib_path = dir.0.join("binaries").join(description.version.platform()).join(format!("{id}.so"));
        // SAFETY: loading a library runs its initialisers: the FMU's code, trusted as a
        // controller is.
        let lib = unsafe { libloading::Library::new(&lib_path) }
            .map_err(|e| fail(format!("cannot load its library {}: {e}", lib_path.display())))?;
        let api = match description.version {
            FmiVersion::Two => Api::Two(Fmi2::load(lib).map_err(fail)?),
            FmiVersion::Three => Api::Three(Fmi3::load(lib).map_err(fail)?),
        };
        if let (Api::Two(f), Interface::CoSimulation) = (&api, interface) {
            if f.do_step.is_none() {
                return Err(fail("the FMU's library has no function fmi2DoStep".into()));
            }
        }
        if let (Api::Two(f), Interface::ModelExchange) = (&api, interface) {
            let missing = [
                ("fmi2SetTime", f.set_time.is_none()),
                ("fmi2SetContinuousStates", f.set_continuous_states.is_none()),
                ("fmi2GetContinuousStates", f.get_continuous_states.is_none()),
                ("fmi2GetDerivatives", f.get_derivatives.is_none()),
                ("fmi2CompletedIntegratorStep", f.completed_integrator_step.is_none()),
                ("fmi2EnterEventMode", f.enter_event_mode.is_none()),
                ("fmi2NewDiscreteStates", f.new_discrete_states.is_none()),
                ("fmi2EnterContinuousTimeMode", f.enter_continuous_time_mode.is_none()),
            ];
            if let Some((name, _)) = missing.iter().find(|(_, m)| *m) {
                return Err(fail(format!("the FMU's library has no function {name} (model exchange)")));
            }
        }
        let resources = dir.0.join("resources");
        Ok(Arc::new(Self { spec: spec.clone(), description, interface, api, resources, _dir: dir }))
    }

    /// The temporary folder the FMU is unpacked into (removed when the last user drops it; a
    /// process that ends at once removes it first).
    pub fn folder(&self) -> &Path {
        &self._dir.0
    }

    /// The model description.
    pub fn description(&self) -> &Description {
        &self.description
    }

    /// The interface the host runs.
    pub fn interface(&self) -> Interface {
        self.interface
    }

    /// One line for the ack and the log: the model, FMI version and interface.
    pub fn describe(&self) -> String {
        let interface = match self.interface {
            Interface::CoSimulation => "co-simulation".to_string(),
            Interface::ModelExchange => {
                format!("model exchange, {} x {} per period", self.spec.solver.name(), self.spec.substeps)
            }
        };
        format!(
            "FMU {} ({}, FMI {} {interface})",
            self.description.model_name,
            self.spec.path.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default(),
            self.description.version.label()
        )
    }

    /// Instantiates the FMU for `design`'s rotor, sets `params` by name, initialises it, and
    /// returns it as a law. An unknown parameter is refused with the FMU's parameters listed.
    pub fn law(self: &Arc<Self>, design: &RotorDesign, params: &Params) -> Result<FmuLaw, LawError> {
        let refused = |why: String| LawError::Refused { law: LAW_NAME, why };
        let axes = design.axes() as usize;
        let binding = bind(&self.description, &self.spec, axes).map_err(refused)?;
        let period = design.plane_a().period_s;
        let name = CString::new("controller").expect("no NUL");
        let token =
            CString::new(self.description.token.clone()).map_err(|_| refused("the token holds a NUL".into()))?;
        let comp = match &self.api {
            Api::Two(f) => {
                let uri = CString::new(format!("file://{}", self.resources.display()))
                    .map_err(|_| refused("the resource path holds a NUL".into()))?;
                let kind = if self.interface == Interface::CoSimulation { 1 } else { 0 };
                // SAFETY: valid strings and a static callback table.
                unsafe { (f.instantiate)(name.as_ptr(), kind, token.as_ptr(), uri.as_ptr(), &FMI2_CALLBACKS.0, 0, 1) }
            }
            Api::Three(f) => {
                let path = CString::new(format!("{}/", self.resources.display()))
                    .map_err(|_| refused("the resource path holds a NUL".into()))?;
                // SAFETY: valid strings, no intermediate variables, a static log callback.
                unsafe {
                    (f.instantiate_co_simulation)(
                        name.as_ptr(),
                        token.as_ptr(),
                        path.as_ptr(),
                        false,
                        true,
                        false,
                        false,
                        std::ptr::null(),
                        0,
                        std::ptr::null_mut(),
                        binding::log3,
                        std::ptr::null(),
                    )
                }
            }
        };
        if comp.is_null() {
            return Err(refused(format!(
                "{}: instantiation failed (the FMU returned NULL; its log says why)",
                self.describe()
            )));
        }
        let mut law = FmuLaw {
            fmu: Arc::clone(self),
            comp,
            binding,
            axes,
            period,
            ticks: 0,
            failed: None,
            on_failure: OnFailure::Nan,
            me: None,
            inputs: Vec::new(),
            input_values: Vec::new(),
            outputs: [0.0; ROTOR_AXES],
        };
        law.set_params(params)?;
        law.initialise().map_err(refused)?;
        Ok(law)
    }
}

/// What a law does when the FMU fails during the run (a step's Discard, Error or Fatal).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OnFailure {
    /// Says it once on stderr and answers NaN from then on (the plant holds the last current
    /// and ends the run as `invalid_commands`): the law inside the plant (sampled mode).
    Nan,
    /// Says it on stderr and ends the process with this exit code (the plant's lost-controller
    /// handling takes over): the controller process.
    Exit(i32),
}

/// Model exchange: the states and the integrator's scratch.
struct MeState {
    x: Vec<f64>,
    k: [Vec<f64>; 4],
    tmp: Vec<f64>,
    next_event: Option<f64>,
}

/// An FMU instance as a law of the whole rotor.
pub struct FmuLaw {
    fmu: Arc<Fmu>,
    comp: *mut c_void,
    binding: Binding,
    axes: usize,
    period: f64,
    ticks: u64,
    failed: Option<String>,
    on_failure: OnFailure,
    me: Option<MeState>,
    inputs: Vec<u32>,
    input_values: Vec<f64>,
    outputs: [f64; ROTOR_AXES],
}

// SAFETY: the instance is used from one thread at a time (the law is moved, never shared);
// FMI allows an instance to be called from any thread, one call at a time.
unsafe impl Send for FmuLaw {}

fn check(call: &str, s: Status) -> Result<(), String> {
    if s <= 1 {
        Ok(())
    } else {
        Err(format!("{call} returned {}", status_name(s)))
    }
}

impl FmuLaw {
    /// What the law does when the FMU fails during the run.
    pub fn on_failure(mut self, policy: OnFailure) -> Self {
        self.on_failure = policy;
        self
    }

    /// The opened FMU.
    pub fn fmu(&self) -> &Fmu {
        &self.fmu
    }

    fn set_params(&mut self, params: &Params) -> Result<(), LawError> {
        let md = &self.fmu.description;
        for (key, value) in params.table() {
            let var = md.variable(key).filter(|v| v.causality == Causality::Parameter && !v.array);
            let Some(var) = var else {
                // Leaked on this error path only: the error type holds static names.
                let known: Vec<&'static str> = md
                    .variables
                    .iter()
                    .filter(|v| v.causality == Causality::Parameter)
                    .map(|v| &*Box::leak(v.name.clone().into_boxed_str()))
                    .collect();
                return Err(LawError::UnknownParam {
                    law: LAW_NAME,
                    key: key.clone(),
                    value: value.to_string(),
                    known,
                });
            };
            let bad = |why: String| LawError::Param {
                law: LAW_NAME,
                key: key.clone(),
                value: value.to_string(),
                unit: "",
                why,
            };
            let label = var.ty.label(md.version);
            let article = if label.starts_with(['A', 'E', 'I', 'O', 'U']) { "an" } else { "a" };
            let ty = format!("{article} {label}");
            let vr = [var.vr];
            let comp = self.comp;
            // SAFETY (each call): one value for one value reference of that type.
            let status = match (&var.ty, value, &self.fmu.api) {
                (VarType::Float64, toml::Value::Float(_) | toml::Value::Integer(_), api) => {
                    let v = [value.as_float().unwrap_or_else(|| value.as_integer().unwrap_or(0) as f64)];
                    match api {
                        Api::Two(f) => unsafe { (f.set_real)(comp, vr.as_ptr(), 1, v.as_ptr()) },
                        Api::Three(f) => unsafe { (f.set_float64)(comp, vr.as_ptr(), 1, v.as_ptr(), 1) },
                    }
                }
                (VarType::Int32, toml::Value::Integer(i), api) => {
                    let v =
                        [i32::try_from(*i)
                            .map_err(|_| bad(format!("the FMU's parameter is {ty}: out of its range")))?];
                    match api {
                        Api::Two(f) => unsafe { (f.set_integer)(comp, vr.as_ptr(), 1, v.as_ptr()) },
                        Api::Three(f) => unsafe { (f.set_int32)(comp, vr.as_ptr(), 1, v.as_ptr(), 1) },
                    }
                }
                (VarType::Boolean, toml::Value::Boolean(b), api) => match api {
                    Api::Two(f) => unsafe { (f.set_boolean)(comp, vr.as_ptr(), 1, [*b as i32].as_ptr()) },
                    Api::Three(f) => unsafe { (f.set_boolean)(comp, vr.as_ptr(), 1, [*b].as_ptr(), 1) },
                },
                (VarType::String, toml::Value::String(s), api) => {
                    let c = CString::new(s.as_str()).map_err(|_| bad("holds a NUL".into()))?;
                    let p = [c.as_ptr()];
                    match api {
                        Api::Two(f) => unsafe { (f.set_string)(comp, vr.as_ptr(), 1, p.as_ptr()) },
                        Api::Three(f) => unsafe { (f.set_string)(comp, vr.as_ptr(), 1, p.as_ptr(), 1) },
                    }
                }
                (VarType::Other(_), _, _) => {
                    return Err(bad(format!("the FMU's parameter is {ty}: not settable here")))
                }
                _ => {
                    let want = match var.ty {
                        VarType::Float64 => "a number",
                        VarType::Int32 => "an integer",
                        VarType::Boolean => "true or false",
                        _ => "a string",
                    };
                    return Err(bad(format!("the FMU's parameter is {ty}: give {want}")));
                }
            };
            if status > 1 {
                return Err(bad(format!("the FMU refused it (status {})", status_name(status))));
            }
        }
        Ok(())
    }

    fn initialise(&mut self) -> Result<(), String> {
        let comp = self.comp;
        match &self.fmu.api {
            Api::Two(f) => {
                // SAFETY (each call): an instance in the state the call expects.
                check("fmi2SetupExperiment", unsafe { (f.setup_experiment)(comp, 0, 0.0, 0.0, 0, 0.0) })?;
                check("fmi2EnterInitializationMode", unsafe { (f.enter_initialization_mode)(comp) })?;
                check("fmi2ExitInitializationMode", unsafe { (f.exit_initialization_mode)(comp) })?;
                if self.fmu.interface == Interface::ModelExchange {
                    let n = self.fmu.description.states;
                    let mut me = MeState {
                        x: vec![0.0; n],
                        k: std::array::from_fn(|_| vec![0.0; n]),
                        tmp: vec![0.0; n],
                        next_event: None,
                    };
                    me.next_event = self.event_iteration()?;
                    let enter = f.enter_continuous_time_mode.expect("checked at open");
                    check("fmi2EnterContinuousTimeMode", unsafe { enter(comp) })?;
                    let get = f.get_continuous_states.expect("checked at open");
                    check("fmi2GetContinuousStates", unsafe { get(comp, me.x.as_mut_ptr(), n) })?;
                    self.me = Some(me);
                }
            }
            Api::Three(f) => {
                check("fmi3EnterInitializationMode", unsafe {
                    (f.enter_initialization_mode)(comp, false, 0.0, 0.0, false, 0.0)
                })?;
                check("fmi3ExitInitializationMode", unsafe { (f.exit_initialization_mode)(comp) })?;
            }
        }
        let b = &self.binding;
        self.inputs = b.sensors.iter().copied().chain(b.speed).chain(b.angle).chain(b.time).collect();
        self.input_values = vec![0.0; self.inputs.len()];
        Ok(())
    }

    /// FMI 2.0 model exchange: the event iteration (in event mode); the next time event.
    fn event_iteration(&self) -> Result<Option<f64>, String> {
        let Api::Two(f) = &self.fmu.api else { return Ok(None) };
        let new = f.new_discrete_states.expect("checked at open");
        let mut info = binding::Fmi2EventInfo { new_discrete_states_needed: 1, ..Default::default() };
        let mut rounds = 0;
        while info.new_discrete_states_needed != 0 {
            info.new_discrete_states_needed = 0;
            // SAFETY: an instance in event mode, a valid event-info struct.
            check("fmi2NewDiscreteStates", unsafe { new(self.comp, &mut info) })?;
            if info.terminate_simulation != 0 {
                return Err("the FMU asked to terminate the simulation (fmi2NewDiscreteStates)".into());
            }
            rounds += 1;
            if rounds > 1000 {
                return Err("fmi2NewDiscreteStates asked for new discrete states 1000 times in a row".into());
            }
        }
        Ok((info.next_event_time_defined != 0).then_some(info.next_event_time))
    }

    /// FMI 2.0 model exchange: the derivatives at `(t, x)` into `dx`.
    fn derivatives(f: &Fmi2, comp: *mut c_void, t: f64, x: &[f64], dx: &mut [f64]) -> Result<(), String> {
        // SAFETY (each call): an instance in continuous-time mode, slices of the state count.
        check("fmi2SetTime", unsafe { (f.set_time.expect("checked"))(comp, t) })?;
        check("fmi2SetContinuousStates", unsafe {
            (f.set_continuous_states.expect("checked"))(comp, x.as_ptr(), x.len())
        })?;
        check("fmi2GetDerivatives", unsafe { (f.get_derivatives.expect("checked"))(comp, dx.as_mut_ptr(), dx.len()) })
    }

    /// One controller tick: the inputs set, the FMU stepped (or integrated), the outputs read.
    fn tick(&mut self, sample: &RotorSample) -> Result<(), String> {
        let comp = self.comp;
        let t = self.ticks as f64 * self.period;
        let b = &self.binding;
        let mut k = 0;
        for a in 0..self.axes {
            self.input_values[k] = sample.sensor_v[a];
            k += 1;
        }
        for (present, value) in [(b.speed, sample.speed_rad_s), (b.angle, sample.angle_rad), (b.time, sample.t_s)] {
            if present.is_some() {
                self.input_values[k] = value;
                k += 1;
            }
        }
        let (vin, nin) = (self.inputs.as_ptr(), self.inputs.len());
        let (vout, nout) = (b.currents.as_ptr(), b.currents.len());
        let out = self.outputs.as_mut_ptr();
        // SAFETY (each call below): value references and values of the same lengths, an
        // instance in the state the call expects.
        match &self.fmu.api {
            Api::Three(f) => {
                check("fmi3SetFloat64", unsafe { (f.set_float64)(comp, vin, nin, self.input_values.as_ptr(), nin) })?;
                let (mut event, mut terminate, mut early, mut last) = (false, false, false, 0.0);
                let s = unsafe {
                    (f.do_step)(comp, t, self.period, true, &mut event, &mut terminate, &mut early, &mut last)
                };
                check(&format!("fmi3DoStep(t = {t} s, h = {} s)", self.period), s)?;
                if terminate {
                    return Err(format!("fmi3DoStep(t = {t} s) asked to terminate the simulation"));
                }
                check("fmi3GetFloat64", unsafe { (f.get_float64)(comp, vout, nout, out, nout) })?;
            }
            Api::Two(f) => {
                check("fmi2SetReal", unsafe { (f.set_real)(comp, vin, nin, self.input_values.as_ptr()) })?;
                match self.fmu.interface {
                    Interface::CoSimulation => {
                        let s = unsafe { (f.do_step.expect("checked at open"))(comp, t, self.period, 1) };
                        check(&format!("fmi2DoStep(t = {t} s, h = {} s)", self.period), s)?;
                        check("fmi2GetReal", unsafe { (f.get_real)(comp, vout, nout, out) })?;
                    }
                    Interface::ModelExchange => {
                        // The output at the sample (the states and inputs of t_k), then the
                        // states integrated over the period with the inputs held.
                        check("fmi2SetTime", unsafe { (f.set_time.expect("checked"))(comp, t) })?;
                        check("fmi2GetReal", unsafe { (f.get_real)(comp, vout, nout, out) })?;
                        self.integrate(t)?;
                    }
                }
            }
        }
        Ok(())
    }

    /// FMI 2.0 model exchange: the states from `t0` over one period, `substeps` fixed steps.
    // Indexed loops: the Runge–Kutta stages read as the formulas.
    #[allow(clippy::needless_range_loop)]
    fn integrate(&mut self, t0: f64) -> Result<(), String> {
        let Api::Two(f) = &self.fmu.api else { return Ok(()) };
        let comp = self.comp;
        let Some(me) = self.me.as_mut() else { return Ok(()) };
        let m = self.fmu.spec.substeps.max(1);
        let h = self.period / m as f64;
        let n = me.x.len();
        for j in 0..m {
            let t = t0 + j as f64 * h;
            if n > 0 {
                let [k1, k2, k3, k4] = &mut me.k;
                match self.fmu.spec.solver {
                    Solver::Euler => {
                        Self::derivatives(f, comp, t, &me.x, k1)?;
                        for i in 0..n {
                            me.x[i] += h * k1[i];
                        }
                    }
                    Solver::Rk4 => {
                        Self::derivatives(f, comp, t, &me.x, k1)?;
                        for i in 0..n {
                            me.tmp[i] = me.x[i] + 0.5 * h * k1[i];
                        }
                        Self::derivatives(f, comp, t + 0.5 * h, &me.tmp, k2)?;
                        for i in 0..n {
                            me.tmp[i] = me.x[i] + 0.5 * h * k2[i];
                        }
                        Self::derivatives(f, comp, t + 0.5 * h, &me.tmp, k3)?;
                        for i in 0..n {
                            me.tmp[i] = me.x[i] + h * k3[i];
                        }
                        Self::derivatives(f, comp, t + h, &me.tmp, k4)?;
                        for i in 0..n {
                            me.x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
                        }
                    }
                }
                if me.x.iter().any(|v| !v.is_finite()) {
                    return Err(format!("the FMU's states became non-finite at t = {} s (model exchange)", t + h));
                }
            }
            let t1 = t0 + (j + 1) as f64 * h;
            // SAFETY: an instance in continuous-time mode, a slice of the state count.
            check("fmi2SetTime", unsafe { (f.set_time.expect("checked"))(comp, t1) })?;
            check("fmi2SetContinuousStates", unsafe {
                (f.set_continuous_states.expect("checked"))(comp, me.x.as_ptr(), n)
            })?;
            let (mut enter, mut terminate) = (0, 0);
            check("fmi2CompletedIntegratorStep", unsafe {
                (f.completed_integrator_step.expect("checked"))(comp, 1, &mut enter, &mut terminate)
            })?;
            if terminate != 0 {
                return Err(format!("the FMU asked to terminate the simulation at t = {t1} s"));
            }
            let timed = me.next_event.is_some_and(|te| t1 >= te - 1e-9 * h);
            if enter != 0 || timed {
                check("fmi2EnterEventMode", unsafe { (f.enter_event_mode.expect("checked"))(comp) })?;
                let new = f.new_discrete_states.expect("checked at open");
                let mut info = binding::Fmi2EventInfo { new_discrete_states_needed: 1, ..Default::default() };
                while info.new_discrete_states_needed != 0 {
                    info.new_discrete_states_needed = 0;
                    check("fmi2NewDiscreteStates", unsafe { new(comp, &mut info) })?;
                    if info.terminate_simulation != 0 {
                        return Err(format!("the FMU asked to terminate the simulation at t = {t1} s"));
                    }
                }
                me.next_event = (info.next_event_time_defined != 0).then_some(info.next_event_time);
                check("fmi2EnterContinuousTimeMode", unsafe {
                    (f.enter_continuous_time_mode.expect("checked"))(comp)
                })?;
                check("fmi2GetContinuousStates", unsafe {
                    (f.get_continuous_states.expect("checked"))(comp, me.x.as_mut_ptr(), n)
                })?;
            }
        }
        Ok(())
    }
}

impl RotorLaw for FmuLaw {
    fn name(&self) -> &'static str {
        LAW_NAME
    }

    fn update(&mut self, sample: &RotorSample) -> [f64; ROTOR_AXES] {
        if self.failed.is_some() {
            return [f64::NAN; ROTOR_AXES];
        }
        INSIDE_TICK.store(self.ticks, Ordering::Relaxed);
        INSIDE_SINCE_NS.store(monotonic_ns(), Ordering::Relaxed);
        let ended = self.tick(sample);
        INSIDE_SINCE_NS.store(0, Ordering::Relaxed);
        if let Err(why) = ended {
            let message =
                format!("{} failed at tick {} (t = {} s): {why}", self.fmu.describe(), self.ticks, sample.t_s);
            match self.on_failure {
                OnFailure::Exit(code) => {
                    eprintln!(
                        "controller-fmu: error: {message}; exiting (the plant's lost-controller handling takes over)"
                    );
                    let _ = std::fs::remove_dir_all(self.fmu.folder());
                    std::process::exit(code);
                }
                OnFailure::Nan => {
                    eprintln!("plant: error: {message}; the law answers NaN from now on");
                    self.failed = Some(message);
                    return [f64::NAN; ROTOR_AXES];
                }
            }
        }
        self.ticks += 1;
        let mut i = [0.0; ROTOR_AXES];
        i[..self.axes].copy_from_slice(&self.outputs[..self.axes]);
        i
    }

    /// An FMU cannot be reset without its state functions: the law keeps going (the plant
    /// never resets a law during a run).
    fn reset(&mut self) {}
}

impl Drop for FmuLaw {
    fn drop(&mut self) {
        // SAFETY: the instance is freed once; terminate's status does not matter here.
        unsafe {
            match &self.fmu.api {
                Api::Two(f) => {
                    if self.failed.is_none() {
                        (f.terminate)(self.comp);
                    }
                    (f.free_instance)(self.comp)
                }
                Api::Three(f) => {
                    if self.failed.is_none() {
                        (f.terminate)(self.comp);
                    }
                    (f.free_instance)(self.comp)
                }
            }
        }
    }
}

/// The turn of the in-process FMU laws of this process: one at a time (issue 40 item 5).
///
/// An FMU's library is the FMU's code in the plant's process, and an FMU may keep state that is
/// the process's, not its instance's nor even its library copy's: a pythonfmu FMU hosts the
/// Python interpreter, one per process, which it starts on loading and stops on unloading.
/// Two such FMUs alive at once in the threads of one process (`plant assess`, `ensemble` or
/// `sweep` members in `sampled` mode) crashed the plant (SIGSEGV, "double free or
/// corruption"). So a law built by [`build`] waits for its turn and keeps it until it is
/// dropped, its library unloaded with it: the members that run an in-process FMU run one
/// after another, whatever the pool they run on; a member with another law does not wait.
struct Turn;

static TURN: (std::sync::Mutex<bool>, std::sync::Condvar) = (std::sync::Mutex::new(false), std::sync::Condvar::new());

impl Turn {
    /// Waits until no other in-process FMU law is alive, then takes the turn.
    fn take() -> Self {
        let (taken, freed) = &TURN;
        let mut t = taken.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        while *t {
            t = freed.wait(t).unwrap_or_else(std::sync::PoisonError::into_inner);
        }
        *t = true;
        Turn
    }
}

impl Drop for Turn {
    fn drop(&mut self) {
        let (taken, freed) = &TURN;
        *taken.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = false;
        freed.notify_one();
    }
}

thread_local! {
    /// How deep this thread is in the code of an in-process FMU ([`InFmu`]).
    static IN_FMU: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
}

/// The in-process FMU whose turn it is, in words (for the plant's last line when it ends the
/// process: [`in_fmu_code`]).
static CURRENT: std::sync::Mutex<String> = std::sync::Mutex::new(String::new());

/// While alive, this thread runs the code of an in-process FMU: loading and instantiating it
/// ([`build`]), a tick, freeing and unloading it.
struct InFmu;

impl InFmu {
    fn enter() -> Self {
        IN_FMU.with(|c| c.set(c.get() + 1));
        InFmu
    }
}

impl Drop for InFmu {
    fn drop(&mut self) {
        IN_FMU.with(|c| c.set(c.get().saturating_sub(1)));
    }
}

/// Whether this thread is inside the code of an in-process FMU (its library loaded, an FMI call
/// under way), and which FMU: the plant's `exit` and `_exit` ask, to tell an FMU that ends the
/// process (which it cannot be stopped from doing) from the plant ending it
/// (docs/guide/fmu-controller.md).
pub fn in_fmu_code() -> Option<String> {
    let inside = IN_FMU.try_with(|c| c.get() > 0).unwrap_or(false);
    inside.then(|| match CURRENT.try_lock() {
        Ok(s) if !s.is_empty() => s.clone(),
        _ => "FMU being loaded".to_string(),
    })
}

/// An in-process FMU law with its [`Turn`], given back once the FMU is freed and unloaded.
struct Turned {
    // Dropped (the instance freed, the library unloaded) before the turn, inside [`InFmu`].
    law: std::mem::ManuallyDrop<FmuLaw>,
    _turn: Turn,
}

impl RotorLaw for Turned {
    fn name(&self) -> &'static str {
        self.law.name()
    }

    fn update(&mut self, sample: &RotorSample) -> [f64; ROTOR_AXES] {
        let _in = InFmu::enter();
        self.law.update(sample)
    }

    fn reset(&mut self) {
        self.law.reset()
    }
}

impl Drop for Turned {
    fn drop(&mut self) {
        let _in = InFmu::enter();
        // SAFETY: dropped once, here; the field is not used after.
        unsafe { std::mem::ManuallyDrop::drop(&mut self.law) };
        if let Ok(mut s) = CURRENT.lock() {
            s.clear();
        }
    }
}

/// Opens the FMU of `spec` and builds its law for `design`'s rotor (the plant's sampled mode),
/// once no other law built here is alive in the process ([`Turn`]).
pub fn build(spec: &Spec, design: &RotorDesign, params: &Params) -> Result<Box<dyn RotorLaw>, LawError> {
    let turn = Turn::take();
    let _in = InFmu::enter();
    if let Ok(mut s) = CURRENT.lock() {
        *s = format!("FMU {}", file_name(&spec.path));
    }
    let fmu = Fmu::open(spec).map_err(|e| LawError::Refused { law: LAW_NAME, why: e.to_string() })?;
    if let Ok(mut s) = CURRENT.lock() {
        *s = fmu.describe();
    }
    let law = fmu.law(design, params)?;
    // The law holds the only other handle on the FMU: dropping it unloads the library.
    drop(fmu);
    Ok(Box::new(Turned { law: std::mem::ManuallyDrop::new(law), _turn: turn }))
}

/// The file name of `path` (for messages).
pub fn file_name(path: &Path) -> String {
    path.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_else(|| path.display().to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn description() -> Description {
        Description::parse(
            r#"<fmiModelDescription fmiVersion="2.0" modelName="c" guid="g"><CoSimulation modelIdentifier="c"/>
<ModelVariables>
  <ScalarVariable name="sensor_x" valueReference="1" causality="input"><Real/></ScalarVariable>
  <ScalarVariable name="y_in" valueReference="2" causality="input"><Real/></ScalarVariable>
  <ScalarVariable name="angle" valueReference="3" causality="input"><Real/></ScalarVariable>
  <ScalarVariable name="current_x" valueReference="4" causality="output"><Real/></ScalarVariable>
  <ScalarVariable name="current_y" valueReference="5" causality="output"><Real/></ScalarVariable>
  <ScalarVariable name="mode" valueReference="6" causality="input"><Integer/></ScalarVariable>
</ModelVariables></fmiModelDescription>"#,
        )
        .unwrap()
    }

    /// The convention's names, the map's, the optional keyphasor and time; each refusal names
    /// the signal, the variable and the FMU's variables of that causality.
    #[test]
    fn signals_bind_by_convention_or_map_and_refusals_name_what_is_missing() {
        let md = description();
        let mut spec = Spec::new("c.fmu");
        let e = bind(&md, &spec, 2).unwrap_err();
        assert!(e.contains("signal sensor_y (the naming convention"), "{e}");
        assert!(e.contains("the FMU has no variable `sensor_y` (its inputs: sensor_x, y_in, angle, mode)"), "{e}");
        spec.map.insert("sensor_y".into(), "y_in".into());
        let b = bind(&md, &spec, 2).unwrap();
        assert_eq!((b.sensors, b.currents), (vec![1, 2], vec![4, 5]));
        assert_eq!((b.speed, b.angle, b.time), (None, Some(3), None));
        spec.map.insert("speed".into(), "current_x".into());
        let e = bind(&md, &spec, 2).unwrap_err();
        assert!(
            e.contains("controller.fmu.map.speed = \"current_x\": the FMU's variable `current_x` is not an input"),
            "{e}"
        );
        spec.map.insert("speed".into(), "mode".into());
        let e = bind(&md, &spec, 2).unwrap_err();
        assert!(e.contains("the FMU's variable `mode` is an Integer, not a scalar Real"), "{e}");
        spec.map.remove("speed");
        spec.map.insert("current_x_b".into(), "current_x".into());
        let e = bind(&md, &spec, 2).unwrap_err();
        assert!(e.contains("controller.fmu.map.current_x_b: not a signal of this rotor (2 axes)"), "{e}");
        assert_eq!(signal_names(4).1, ["current_x_a", "current_y_a", "current_x_b", "current_y_b"]);
    }
}
