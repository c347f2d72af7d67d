//! The C API of the controller process: `libamb_testbed_controller.so` and
//! `.a`, declared by `controller/include/amb_testbed_controller.h`.
//!
//! A law written in C (or C++, Fortran, Zig, Julia, Go, … anything that
//! calls C) is a struct of function pointers, [`Law`]: `build` it from the
//! plant's design ([`Design`]) and its parameters ([`Params`], the scene's
//! `[controller.params]` read key by key with [`amb_params_number`] and
//! [`amb_params_flag`], or whole as TOML text with [`amb_params_text`]),
//! `update` it on a sample ([`Sample`]) into the coil currents, `reset` it,
//! `drop` it. One call, [`amb_serve`], is the whole controller process,
//! exactly as `controller::serve` is for a Rust law (it *is* that call): the
//! command line, the run-id lock, the handshake with the plant, the wake
//! protocol, liveness, SIGINT/SIGTERM and the exit codes. The user needs no
//! iceoryx2 of their own: the library holds it.
//!
//! A C law is a law of the whole rotor (`controller::RotorLaw`): it gets every
//! axis at once, so it drives the planar model (2 axes, one plane) and the
//! two-plane rotor (4 axes: x, y at bearing A, then at B) alike, or refuses
//! the one it cannot. A sample holds `axes` entries (room for [`MAX_AXES`])
//! and the keyphasor (the rotor's speed and angle); a design `planes`
//! per-plane designs (room for [`MAX_PLANES`]) and, on the two-plane rotor,
//! its geometry. [`ABI_VERSION`] says which layout a law was built against and
//! [`amb_serve`] refuses another.
//!
//! **Bad input and faults.** A law's table with a NULL function, a NULL or
//! over-long name, another ABI version, or more than [`MAX_LAWS`] laws: a
//! message naming the law and the field, exit 2 (the plant: `refused`, exit
//! 2, with this message quoted). Parameters the law refuses (a getter's
//! error, or `build` returning NULL with a message): the hello is refused
//! with the message (code 7 for a parameter, 5 for the design), exit 2 on
//! both sides. A non-finite current: sent as it is (NaN), said once here;
//! the plant holds the last valid current and ends the run past its budget
//! (`invalid_commands`, exit 8). A law that aborts (or a C++ exception that
//! escapes it: the functions are `C-unwind`, and Rust cannot catch a foreign
//! exception, so the process aborts with a message) ends the process: the
//! plant reports a lost controller (exit 4), quoting its last output from
//! `controller.log`, and writes its outputs. A law that closes the library's
//! file descriptors: exit 1 at once with a line naming the law and the call
//! (a descriptor of its own, checked after each call). Nothing unwinds across the
//! boundary out of this library: [`amb_serve`] catches a panic of its own and
//! returns an exit code.

use controller::{Check, LawError, ParamReader, RotorLaw, RotorLawEntry, ROTOR_AXES};
use std::collections::HashSet;
use std::ffi::{c_char, c_int, c_void, CStr, OsString};
use std::sync::{Mutex, OnceLock};

/// The layout version of the structs below; a law states the one it was built against.
pub const ABI_VERSION: u32 = 1;
/// Room for axes in a sample and in the currents (`controller::wire::MAX_AXES`).
pub const MAX_AXES: usize = controller::wire::MAX_AXES;
/// Room for bearing planes in a design (two axes each).
pub const MAX_PLANES: usize = MAX_AXES / 2;
/// Most laws one process serves.
pub const MAX_LAWS: usize = 16;
/// Longest law name (bytes): the wire's law field less its NUL.
pub const MAX_NAME_LEN: usize = controller::wire::LAW_NAME_LEN - 1;

/// `amb_params_number`'s range checks (`AMB_CHECK_*`).
pub mod check {
    /// Finite.
    pub const FINITE: u32 = 0;
    /// Finite and > 0.
    pub const POSITIVE: u32 = 1;
    /// Finite and >= 0.
    pub const NON_NEGATIVE: u32 = 2;
    /// Finite and strictly between `lo` and `hi`.
    pub const BETWEEN: u32 = 3;
}

/// The plant's constants of one bearing plane (SI), `controller::LoopConstants`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LoopConstants {
    /// k_i (N/A).
    pub ki_n_per_a: f64,
    /// k_s (N/m).
    pub ks_n_per_m: f64,
    /// A_a (A/V).
    pub amp_gain_a_per_v: f64,
    /// A_s (V/m).
    pub sensor_gain_v_per_m: f64,
    /// m_r (kg).
    pub rotor_mass_kg: f64,
    /// g (m/s²).
    pub gravity_m_s2: f64,
    /// Touchdown air gap r_0 (m).
    pub air_gap_m: f64,
}

/// One bearing plane's design: the closed loop asked for and the plant's constants.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlaneDesign {
    /// Closed-loop stiffness k_e (N/m).
    pub stiffness_n_per_m: f64,
    /// Closed-loop damping ratio ξ_e.
    pub damping_ratio: f64,
    /// Amplifier current limit i_max (A); `amb_serve` saturates the currents at it.
    pub current_limit_a: f64,
    /// 1: the gravity bias `m_r g / k_i` on y.
    pub gravity_bias: u32,
    /// 0.
    pub reserved: u32,
    /// The plant's constants.
    pub constants: LoopConstants,
}

/// The rigid rotor of the two-plane model (`controller::Geometry`); 0 on the planar model.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Geometry {
    /// Rotor mass M (kg).
    pub mass_kg: f64,
    /// Transverse moment of inertia about the centre of mass I_t (kg m²).
    pub transverse_inertia_kg_m2: f64,
    /// Polar moment of inertia I_p (kg m²).
    pub polar_inertia_kg_m2: f64,
    /// Rated spin speed (rad/s).
    pub rated_speed_rad_s: f64,
    /// Axial stations of bearings A and B from the centre of mass (m).
    pub bearing_z_m: [f64; 2],
    /// Axial stations of sensors A and B (m).
    pub sensor_z_m: [f64; 2],
}

/// The design a law is built from.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Design {
    /// Axes the law drives: 2 (x, y of one plane) or 4 (x_A, y_A, x_B, y_B).
    pub axes: u32,
    /// Bearing planes in `plane`: 1 or 2.
    pub planes: u32,
    /// The command computed from sample k is applied from tick k + `delay_samples` (the plant
    /// applies it; for a law that compensates).
    pub delay_samples: u32,
    /// 0.
    pub reserved: u32,
    /// Sampling period T (s), as the plant computed it.
    pub period_s: f64,
    /// Per-plane designs; entries past `planes` are 0.
    pub plane: [PlaneDesign; MAX_PLANES],
    /// The rotor's geometry (two planes); 0 on the planar model.
    pub geometry: Geometry,
}

/// One controller input.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    /// Sample index k.
    pub seq: u64,
    /// Simulated time of the sample (s).
    pub t_s: f64,
    /// Entries of `sensor_v` in use (2: x, y).
    pub axes: u32,
    /// 0.
    pub reserved: u32,
    /// Sensor voltages A_s·Δ (V) per axis; entries past `axes` are 0.
    pub sensor_v: [f64; MAX_AXES],
    /// The rotor's spin speed Ω (rad/s): the keyphasor.
    pub speed_rad_s: f64,
    /// The rotor's angle (rad) in [0, 2π): the keyphasor (at 0 the unbalance points along +x).
    pub angle_rad: f64,
}

/// The parameter reader handed to `build` (opaque to C).
#[repr(C)]
pub struct Params {
    _opaque: [u8; 0],
}

/// `build`: the law's state from the design and its parameters, or NULL (with a message in
/// `error`, `error_len` bytes with its NUL, or after a parameter getter failed).
pub type BuildFn =
    unsafe extern "C-unwind" fn(*mut c_void, *const Design, *mut Params, *mut c_char, usize) -> *mut c_void;
/// `update`: the currents (A) for a sample, `axes` entries into `current_a` (room for
/// [`MAX_AXES`], zeroed), before the amplifier limits.
pub type UpdateFn = unsafe extern "C-unwind" fn(*mut c_void, *const Sample, *mut f64);
/// `reset` and `drop`: the law's state.
pub type StateFn = unsafe extern "C-unwind" fn(*mut c_void);

/// A law: what a C program hands to [`amb_serve`].
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct Law {
    /// [`ABI_VERSION`] (`AMB_CONTROLLER_ABI_VERSION`) as the program was built.
    pub abi_version: u32,
    /// 0.
    pub reserved: u32,
    /// The name the scene's `controller.law` selects (NUL-terminated UTF-8, at most 31 bytes).
    pub name: *const c_char,
    /// One line for help texts (may be NULL).
    pub summary: *const c_char,
    /// Handed to `build` as its first argument (may be NULL).
    pub context: *mut c_void,
    /// Required.
    pub build: Option<BuildFn>,
    /// Required.
    pub update: Option<UpdateFn>,
    /// Required: forget all memory (back to the state before the first sample).
    pub reset: Option<StateFn>,
    /// Required: free the state `build` returned.
    pub drop: Option<StateFn>,
}

/// A law of the table, checked.
struct Registered {
    name: &'static str,
    context: usize,
    build: BuildFn,
    update: UpdateFn,
    reset: StateFn,
    drop: StateFn,
}

/// The laws of the one [`amb_serve`] call of this process.
static LAWS: OnceLock<Vec<Registered>> = OnceLock::new();

/// A `RotorLawEntry` needs a plain function per law: one trampoline per table index.
fn build_at<const I: usize>(
    design: &controller::RotorDesign,
    params: &controller::Params,
) -> Result<Box<dyn RotorLaw>, LawError> {
    build(&LAWS.get().expect("amb_serve registered the laws")[I], design, params)
}

const BUILDERS: [controller::BuildRotorLaw; MAX_LAWS] = [
    build_at::<0>,
    build_at::<1>,
    build_at::<2>,
    build_at::<3>,
    build_at::<4>,
    build_at::<5>,
    build_at::<6>,
    build_at::<7>,
    build_at::<8>,
    build_at::<9>,
    build_at::<10>,
    build_at::<11>,
    build_at::<12>,
    build_at::<13>,
    build_at::<14>,
    build_at::<15>,
];

/// The C design of a rotor's design.
pub fn design_of(d: &controller::RotorDesign) -> Design {
    let mut plane = [PlaneDesign::default(); MAX_PLANES];
    for (slot, p) in plane.iter_mut().zip(d.planes()) {
        let c = &p.constants;
        *slot = PlaneDesign {
            stiffness_n_per_m: p.stiffness_n_per_m,
            damping_ratio: p.damping_ratio,
            current_limit_a: p.current_limit_a,
            gravity_bias: u32::from(p.gravity_bias),
            reserved: 0,
            constants: LoopConstants {
                ki_n_per_a: c.ki_n_per_a,
                ks_n_per_m: c.ks_n_per_m,
                amp_gain_a_per_v: c.amp_gain_a_per_v,
                sensor_gain_v_per_m: c.sensor_gain_v_per_m,
                rotor_mass_kg: c.rotor_mass_kg,
                gravity_m_s2: c.gravity_m_s2,
                air_gap_m: c.air_gap_m,
            },
        };
    }
    let geometry = d.geometry().map_or(Geometry::default(), |g| Geometry {
        mass_kg: g.mass_kg,
        transverse_inertia_kg_m2: g.transverse_inertia_kg_m2,
        polar_inertia_kg_m2: g.polar_inertia_kg_m2,
        rated_speed_rad_s: g.rated_speed_rad_s,
        bearing_z_m: g.bearing_z_m,
        sensor_z_m: g.sensor_z_m,
    });
    let a = d.plane_a();
    Design {
        axes: d.axes(),
        planes: d.planes().len() as u32,
        delay_samples: a.delay_samples,
        reserved: 0,
        period_s: a.period_s,
        plane,
        geometry,
    }
}

/// The C sample of a rotor's sample.
pub fn sample_of(s: &controller::RotorSample) -> Sample {
    let mut sensor_v = [0.0; MAX_AXES];
    let n = (s.axes as usize).min(ROTOR_AXES);
    sensor_v[..n].copy_from_slice(&s.sensor_v[..n]);
    Sample {
        seq: s.seq,
        t_s: s.t_s,
        axes: n as u32,
        reserved: 0,
        sensor_v,
        speed_rad_s: s.speed_rad_s,
        angle_rad: s.angle_rad,
    }
}

/// What `build` reads its parameters through.
struct ParamsHandle<'a> {
    reader: ParamReader<'a>,
    /// The first getter's error: the refusal.
    error: Option<LawError>,
    text: std::ffi::CString,
}

/// Builds law `law` through its C `build`.
fn build(
    law: &'static Registered,
    design: &controller::RotorDesign,
    params: &controller::Params,
) -> Result<Box<dyn RotorLaw>, LawError> {
    let cdesign = design_of(design);
    let text = params.to_document().unwrap_or_default();
    let mut handle = ParamsHandle {
        reader: params.reader(law.name),
        error: None,
        text: std::ffi::CString::new(text).unwrap_or_default(),
    };
    let mut error = [0 as c_char; 256];
    // SAFETY: the function comes from the law's table (checked non-NULL); every pointer is
    // valid for the call, `error` holds `error.len()` bytes, the handle outlives the call.
    let state = unsafe {
        (law.build)(
            law.context as *mut c_void,
            &cdesign,
            (&mut handle as *mut ParamsHandle).cast::<Params>(),
            error.as_mut_ptr(),
            error.len(),
        )
    };
    check_descriptors(law.name, "build");
    if state.is_null() {
        if let Some(e) = handle.error {
            return Err(e);
        }
        error[error.len() - 1] = 0;
        // SAFETY: NUL-terminated within the buffer (its last byte set above).
        let why = unsafe { CStr::from_ptr(error.as_ptr()) }.to_string_lossy().trim().to_string();
        let why = if why.is_empty() { "its build function returned NULL without a message".to_string() } else { why };
        return Err(LawError::Refused { law: law.name, why });
    }
    let adapter = Adapter { law, state, warned: false };
    // A getter that failed while build still returned a law: the refusal stands.
    if let Some(e) = handle.error {
        return Err(e);
    }
    handle.reader.finish()?; // refuses the keys the law did not read (the adapter drops the state)
    Ok(Box::new(adapter))
}

/// A descriptor of the library's own, `/dev/null` opened when [`amb_serve`] starts, with its
/// device and inode: a law that closes the library's descriptors (a daemon's
/// `for (fd = 3; fd < 1024; fd++) close(fd);`) closes it too. The library looks after each of
/// the law's calls, before its IPC uses descriptors that are gone: iceoryx2 then panicked and a
/// destructor panicked again while unwinding, which aborts the process (issue 40 item 7).
static SENTINEL: OnceLock<(c_int, u64, u64)> = OnceLock::new();

/// Opens [`SENTINEL`] (once per process; without it nothing is checked).
fn open_sentinel() {
    SENTINEL.get_or_init(|| {
        // SAFETY: a NUL-terminated path; the descriptor is kept for the process's life.
        let fd = unsafe { libc::open(c"/dev/null".as_ptr(), libc::O_RDONLY | libc::O_CLOEXEC) };
        identity(fd).map_or((-1, 0, 0), |(dev, ino)| (fd, dev, ino))
    });
}

/// The device and inode of the open descriptor `fd`, or `None` if it is not open.
fn identity(fd: c_int) -> Option<(u64, u64)> {
    if fd < 0 {
        return None;
    }
    // SAFETY: fstat into a zeroed struct of the right type.
    let mut st: libc::stat = unsafe { std::mem::zeroed() };
    (unsafe { libc::fstat(fd, &mut st) } == 0).then_some((st.st_dev, st.st_ino))
}

/// After the law's `call`: if the library's descriptors were closed, one line and the process
/// ends at once with exit 1 (an IPC failure), without running the destructors of its IPC
/// (they would abort on the closed descriptors). The plant's lost-controller handling takes over.
fn check_descriptors(law: &str, call: &str) {
    let Some(&(fd, dev, ino)) = SENTINEL.get() else { return };
    if fd < 0 || identity(fd) == Some((dev, ino)) {
        return;
    }
    let code = controller::serve::exit::IO;
    let line = format!(
        "amb_serve: error: law `{law}` closed the library's file descriptors in its `{call}` (the library's \
         descriptor {fd} is closed or another file): its IPC with the plant is gone; exiting {code} at once\n"
    );
    // SAFETY: a write of our buffer to stderr, then the process ends without unwinding.
    unsafe {
        libc::write(2, line.as_ptr().cast(), line.len());
        libc::_exit(c_int::from(code))
    }
}

/// A C law as a `RotorLaw`.
struct Adapter {
    law: &'static Registered,
    state: *mut c_void,
    warned: bool,
}

// SAFETY: the state is used by one thread at a time (the controller process's loop); the C
// law promises no more than that.
unsafe impl Send for Adapter {}

impl RotorLaw for Adapter {
    fn name(&self) -> &'static str {
        self.law.name
    }

    fn update(&mut self, s: &controller::RotorSample) -> [f64; ROTOR_AXES] {
        let sample = sample_of(s);
        let mut current = [0.0; MAX_AXES];
        // SAFETY: the state is the one `build` returned; `current` has room for MAX_AXES.
        unsafe { (self.law.update)(self.state, &sample, current.as_mut_ptr()) };
        check_descriptors(self.law.name, "update");
        let mut i = [0.0; ROTOR_AXES];
        i.copy_from_slice(&current[..ROTOR_AXES]);
        let used = &i[..sample.axes as usize];
        if !self.warned && !used.iter().all(|v| v.is_finite()) {
            self.warned = true;
            eprintln!(
                "amb_serve: warning: law `{}` returned a non-finite current {:?} A for sample {} (t = {} s); \
                 it is sent as it is (a NaN after the limit): the plant holds the last valid current and ends the run \
                 past controller.max_invalid_burst or controller.max_invalid_fraction (said once)",
                self.law.name, used, s.seq, s.t_s
            );
        }
        i
    }

    fn reset(&mut self) {
        // SAFETY: the state `build` returned.
        unsafe { (self.law.reset)(self.state) };
        check_descriptors(self.law.name, "reset");
    }
}

impl Drop for Adapter {
    fn drop(&mut self) {
        // SAFETY: the state `build` returned, dropped once.
        unsafe { (self.law.drop)(self.state) };
        check_descriptors(self.law.name, "drop");
    }
}

/// A C string as UTF-8, or why not.
///
/// # Safety
/// `p` is NULL or a NUL-terminated string.
unsafe fn text<'a>(p: *const c_char) -> Result<Option<&'a str>, String> {
    if p.is_null() {
        return Ok(None);
    }
    // SAFETY: the caller's promise.
    unsafe { CStr::from_ptr(p) }.to_str().map(Some).map_err(|_| "is not UTF-8".to_string())
}

/// `key`/`unit` strings live as long as the process (ParamReader keeps `&'static str`):
/// interned, so a law rebuilt on each reconnection does not leak them again.
fn intern(s: &str) -> &'static str {
    static SEEN: Mutex<Option<HashSet<&'static str>>> = Mutex::new(None);
    let mut seen = SEEN.lock().unwrap_or_else(|p| p.into_inner());
    let set = seen.get_or_insert_with(HashSet::new);
    match set.get(s) {
        Some(k) => k,
        None => {
            let k: &'static str = Box::leak(s.to_owned().into_boxed_str());
            set.insert(k);
            k
        }
    }
}

/// Checks the law table: every law's version, name and functions.
///
/// # Safety
/// `laws` is NULL or points to `count` laws whose strings are NUL-terminated.
unsafe fn register(laws: *const Law, count: usize) -> Result<Vec<Registered>, String> {
    if laws.is_null() || count == 0 {
        return Err("no law to serve (the table is NULL or empty)".into());
    }
    if count > MAX_LAWS {
        return Err(format!("{count} laws: a process serves at most {MAX_LAWS}"));
    }
    // SAFETY: the caller's promise.
    let table = unsafe { std::slice::from_raw_parts(laws, count) };
    let mut out = Vec::with_capacity(count);
    for (i, law) in table.iter().enumerate() {
        // SAFETY: the caller's promise.
        let name = unsafe { text(law.name) }.map_err(|e| format!("law {i}: its name {e}"))?;
        let Some(name) = name.filter(|n| !n.is_empty()) else {
            return Err(format!("law {i}: its name is NULL or empty"));
        };
        let who = format!("law {i} (`{name}`)");
        if name.len() > MAX_NAME_LEN {
            return Err(format!("{who}: its name is {} bytes, at most {MAX_NAME_LEN}", name.len()));
        }
        if law.abi_version != ABI_VERSION {
            return Err(format!(
                "{who}: built against ABI version {} of amb_testbed_controller.h, this library is version {ABI_VERSION}: rebuild it with this library's header",
                law.abi_version
            ));
        }
        if out.iter().any(|r: &Registered| r.name == name) {
            return Err(format!("{who}: a second law of that name"));
        }
        let missing = |f: &str| format!("{who}: `{f}` is NULL; every function of an amb_law must be set");
        out.push(Registered {
            name: intern(name),
            context: law.context as usize,
            build: law.build.ok_or_else(|| missing("build"))?,
            update: law.update.ok_or_else(|| missing("update"))?,
            reset: law.reset.ok_or_else(|| missing("reset"))?,
            drop: law.drop.ok_or_else(|| missing("drop"))?,
        });
    }
    Ok(out)
}

/// The whole controller process for the `count` laws of `laws`: the command line `argv`
/// (`argc` entries, the program first; NULL: the process's own), the run-id lock, the
/// handshake, one reply per sensor frame, liveness, signals. Returns the exit code (0 the
/// plant ended the run, 1 IPC failure, 2 bad input or a refused hello, 4 the plant is gone,
/// 130 SIGINT/SIGTERM) for `main` to return. Once per process. `--help` and `--version`
/// print and exit the process.
///
/// # Safety
/// `laws` points to `count` laws (or is NULL); their strings are NUL-terminated and live as
/// long as the process; their functions are sound for the pointers documented in the header;
/// `argv` is NULL or holds `argc` NUL-terminated strings.
#[no_mangle]
pub unsafe extern "C" fn amb_serve(laws: *const Law, count: usize, argc: c_int, argv: *const *const c_char) -> c_int {
    let run = std::panic::AssertUnwindSafe(|| {
        open_sentinel();
        // SAFETY: the caller's promise.
        let args: Vec<OsString> = if argv.is_null() {
            std::env::args_os().collect()
        } else {
            use std::os::unix::ffi::OsStrExt;
            (0..usize::try_from(argc).unwrap_or(0))
                // SAFETY: the caller's promise: argc entries.
                .map(|i| unsafe { *argv.add(i) })
                .filter(|p| !p.is_null())
                // SAFETY: NUL-terminated (the caller's promise).
                .map(|p| std::ffi::OsStr::from_bytes(unsafe { CStr::from_ptr(p) }.to_bytes()).to_os_string())
                .collect()
        };
        let program = args
            .first()
            .and_then(|p| std::path::Path::new(p).file_name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_else(|| "controller".into());
        // SAFETY: the caller's promise.
        let registered = match unsafe { register(laws, count) } {
            Ok(r) => r,
            Err(why) => {
                eprintln!("{program}: error: amb_serve: {why}");
                return i32::from(controller::serve::exit::BAD_INPUT);
            }
        };
        if LAWS.set(registered).is_err() {
            eprintln!("{program}: error: amb_serve: called a second time in this process (once per process)");
            return i32::from(controller::serve::exit::BAD_INPUT);
        }
        let entries: Vec<RotorLawEntry> = LAWS
            .get()
            .expect("set above")
            .iter()
            .zip(BUILDERS)
            .map(|(law, build)| RotorLawEntry { name: law.name, summary: "a law of the C API", build })
            .collect();
        i32::from(controller::serve::serve_code(args, &entries))
    });
    match std::panic::catch_unwind(run) {
        Ok(code) => code,
        Err(_) => {
            eprintln!("amb_serve: error: an internal error (a panic, said above); exiting");
            i32::from(controller::serve::exit::IO)
        }
    }
}

/// The library's [`ABI_VERSION`].
#[no_mangle]
pub extern "C" fn amb_abi_version() -> u32 {
    ABI_VERSION
}

/// # Safety
/// `params` is the handle `build` received, during that call.
unsafe fn handle<'a>(params: *mut Params) -> Option<&'a mut ParamsHandle<'a>> {
    // SAFETY: the caller's promise.
    unsafe { params.cast::<ParamsHandle>().as_mut() }
}

/// Reads the number at `key` of the law's parameters (unit `unit`, may be NULL) into
/// `*value`, `default_value` when absent, checked (`AMB_CHECK_*`; `lo`, `hi` for
/// `AMB_CHECK_BETWEEN`; the default too). A NULL `value` is refused. Returns 0, or -1 when
/// refused (the law's `build` should then return
/// NULL: the hello is refused with the message naming the law, the key, the value and the
/// unit). Call it from `build` only.
///
/// # Safety
/// `params` is the handle `build` received; `key` and `unit` NUL-terminated (or `unit`
/// NULL); `value` valid for a write.
#[no_mangle]
pub unsafe extern "C" fn amb_params_number(
    params: *mut Params,
    key: *const c_char,
    unit: *const c_char,
    default_value: f64,
    check: u32,
    lo: f64,
    hi: f64,
    value: *mut f64,
) -> c_int {
    // SAFETY: the caller's promise.
    let Some(h) = (unsafe { handle(params) }) else { return -1 };
    if h.error.is_some() {
        return -1;
    }
    // SAFETY: the caller's promise.
    let (key, unit) = match unsafe { (text(key), text(unit)) } {
        (Ok(Some(k)), Ok(u)) => (intern(k), intern(u.unwrap_or(""))),
        _ => {
            h.error = Some(LawError::Refused {
                law: h.reader.law(),
                why: "amb_params_number: a NULL or non-UTF-8 key".into(),
            });
            return -1;
        }
    };
    let check = match check {
        check::FINITE => Check::Finite,
        check::POSITIVE => Check::Positive,
        check::NON_NEGATIVE => Check::NonNegative,
        check::BETWEEN => Check::Between(lo, hi),
        other => {
            h.error = Some(h.reader.error(key, other, "", "amb_params_number: an unknown check (AMB_CHECK_*)"));
            return -1;
        }
    };
    if value.is_null() {
        // The value would be lost: the law would run on whatever its variable held.
        h.error = Some(h.reader.error(key, "?", unit, "amb_params_number: a NULL value pointer"));
        return -1;
    }
    // The default is checked too (`ParamReader::number`).
    match h.reader.number(key, unit, default_value, check) {
        Ok(v) => {
            // SAFETY: the caller's promise; not NULL (checked above).
            unsafe { *value = v };
            0
        }
        Err(e) => {
            h.error = Some(e);
            -1
        }
    }
}

/// Reads the boolean at `key` into `*value` (1 or 0), `default_value` when absent. Returns 0,
/// or -1 when refused (see [`amb_params_number`]).
///
/// # Safety
/// As [`amb_params_number`].
#[no_mangle]
pub unsafe extern "C" fn amb_params_flag(
    params: *mut Params,
    key: *const c_char,
    default_value: c_int,
    value: *mut c_int,
) -> c_int {
    // SAFETY: the caller's promise.
    let Some(h) = (unsafe { handle(params) }) else { return -1 };
    if h.error.is_some() {
        return -1;
    }
    // SAFETY: the caller's promise.
    let Ok(Some(key)) = (unsafe { text(key) }) else {
        h.error =
            Some(LawError::Refused { law: h.reader.law(), why: "amb_params_flag: a NULL or non-UTF-8 key".into() });
        return -1;
    };
    let key = intern(key);
    if value.is_null() {
        h.error = Some(h.reader.error(key, "?", "", "amb_params_flag: a NULL value pointer"));
        return -1;
    }
    match h.reader.flag(key, default_value != 0) {
        Ok(b) => {
            // SAFETY: the caller's promise; not NULL (checked above).
            unsafe { *value = c_int::from(b) };
            0
        }
        Err(e) => {
            h.error = Some(e);
            -1
        }
    }
}

/// The law's parameters as TOML text (NUL-terminated, valid during `build`), for a law that
/// reads them itself. A law that reads them so must still read every key it accepts through
/// the getters, or they are refused as unknown.
///
/// # Safety
/// `params` is the handle `build` received.
#[no_mangle]
pub unsafe extern "C" fn amb_params_text(params: *mut Params) -> *const c_char {
    // SAFETY: the caller's promise.
    match unsafe { handle(params) } {
        Some(h) => h.text.as_ptr(),
        None => c"".as_ptr(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A law of the C API written in Rust: it keeps the design it was built from and answers
    /// each axis with its sensor voltage plus the keyphasor, so the test sees what crossed.
    unsafe extern "C-unwind" fn echo_build(
        _context: *mut c_void,
        design: *const Design,
        params: *mut Params,
        _error: *mut c_char,
        _len: usize,
    ) -> *mut c_void {
        let mut scale = 0.0;
        // SAFETY: the handle build received; a key and unit with their NULs.
        let read = unsafe {
            amb_params_number(params, c"scale".as_ptr(), c"".as_ptr(), 1.0, check::POSITIVE, 0.0, 0.0, &mut scale)
        };
        if read != 0 {
            return std::ptr::null_mut();
        }
        // SAFETY: the design passed in is valid for the call.
        Box::into_raw(Box::new((unsafe { *design }, scale))).cast()
    }

    unsafe extern "C-unwind" fn echo_update(law: *mut c_void, s: *const Sample, current: *mut f64) {
        // SAFETY: the state echo_build made; the sample and MAX_AXES currents valid.
        let ((_, scale), s) = unsafe { (&*law.cast::<(Design, f64)>(), &*s) };
        for j in 0..s.axes as usize {
            // SAFETY: j < axes <= MAX_AXES.
            unsafe { *current.add(j) = scale * s.sensor_v[j] + s.speed_rad_s + s.angle_rad }
        }
    }

    unsafe extern "C-unwind" fn nothing(_law: *mut c_void) {}

    unsafe extern "C-unwind" fn free(law: *mut c_void) {
        // SAFETY: the box echo_build made, freed once.
        drop(unsafe { Box::from_raw(law.cast::<(Design, f64)>()) });
    }

    /// The two-plane rotor crosses the boundary whole: four axes, both planes' designs, the
    /// geometry and the keyphasor in; four currents out; parameters through the reader.
    #[test]
    fn a_two_plane_design_and_sample_cross_the_boundary() {
        let table = [Law {
            abi_version: ABI_VERSION,
            reserved: 0,
            name: c"echo".as_ptr(),
            summary: std::ptr::null(),
            context: std::ptr::null_mut(),
            build: Some(echo_build),
            update: Some(echo_update),
            reset: Some(nothing),
            drop: Some(free),
        }];
        // SAFETY: a table of one law with static strings.
        let registered = unsafe { register(table.as_ptr(), 1) }.unwrap();
        assert!(LAWS.set(registered).is_ok());
        let mut rotor = controller::RotorDesign::symmetric_study();
        if let controller::RotorDesign::TwoPlane { planes, .. } = &mut rotor {
            planes[1].stiffness_n_per_m = 2e6;
        }
        let params = controller::Params::parse("scale = 2.0").unwrap();
        let mut law = BUILDERS[0](&rotor, &params).unwrap();
        assert_eq!(law.name(), "echo");
        let adapter_design = {
            let c = design_of(&rotor);
            assert_eq!((c.axes, c.planes, c.delay_samples), (4, 2, 1));
            assert_eq!((c.plane[0].stiffness_n_per_m, c.plane[1].stiffness_n_per_m), (1e6, 2e6));
            assert_eq!(c.plane[2], PlaneDesign::default());
            assert_eq!((c.geometry.mass_kg, c.geometry.bearing_z_m), (23.0, [-0.18, 0.18]));
            c
        };
        let s = controller::RotorSample {
            seq: 7,
            t_s: 3.5e-4,
            axes: 4,
            sensor_v: [0.1, 0.2, 0.3, 0.4],
            speed_rad_s: 100.0,
            angle_rad: 1.5,
        };
        let i = law.update(&s);
        assert_eq!(i, [0.2 + 101.5, 0.4 + 101.5, 0.6 + 101.5, 0.8 + 101.5]);
        // The design the law kept is the one converted.
        drop(law);
        let planar = controller::RotorDesign::Planar(controller::Design::study());
        let c = design_of(&planar);
        assert_eq!((c.axes, c.planes, c.geometry), (2, 1, Geometry::default()));
        assert_ne!(adapter_design, c);
        // A parameter the law refuses, and one it does not read.
        let e = BUILDERS[0](&rotor, &controller::Params::parse("scale = -1.0").unwrap()).err().unwrap().to_string();
        assert_eq!(e, "law echo: controller.params.scale = -1.0: must be a finite number > 0");
        let e = BUILDERS[0](&rotor, &controller::Params::parse("sclae = 1.0").unwrap()).err().unwrap().to_string();
        assert!(e.contains("unknown parameter controller.params.sclae"), "{e}");
    }

    /// Issue 31 item 11: the getters took a NULL output pointer (the value was dropped and the
    /// law ran on whatever its variable held) and never checked the law's default. Each is
    /// refused now, naming the law and the key, and the refusal sticks (later getters fail).
    #[test]
    fn a_null_output_or_a_default_that_fails_its_check_is_refused() {
        let params = controller::Params::parse("").unwrap();
        let fresh = || ParamsHandle { reader: params.reader("mylaw"), error: None, text: std::ffi::CString::default() };
        let number = |h: &mut ParamsHandle, default: f64, check: u32, out: *mut f64| {
            // SAFETY: a live handle; a key and unit with their NULs; `out` NULL or valid.
            unsafe {
                amb_params_number(
                    (h as *mut ParamsHandle).cast(),
                    c"gain".as_ptr(),
                    c"A".as_ptr(),
                    default,
                    check,
                    0.0,
                    1.0,
                    out,
                )
            }
        };
        let mut h = fresh();
        assert_eq!(number(&mut h, 1.0, check::FINITE, std::ptr::null_mut()), -1);
        let e = h.error.take().unwrap().to_string();
        assert!(
            e.contains("law mylaw") && e.contains("controller.params.gain") && e.contains("NULL value pointer"),
            "{e}"
        );
        let mut h = fresh();
        let mut flag: c_int = 7;
        // SAFETY: as above.
        let f = |h: &mut ParamsHandle, out: *mut c_int| unsafe {
            amb_params_flag((h as *mut ParamsHandle).cast(), c"on".as_ptr(), 1, out)
        };
        assert_eq!(f(&mut h, std::ptr::null_mut()), -1);
        assert!(h.error.take().unwrap().to_string().contains("NULL value pointer"));
        assert_eq!(f(&mut h, &mut flag), 0);
        assert_eq!(flag, 1);
        for (default, c) in
            [(f64::NAN, check::FINITE), (0.0, check::POSITIVE), (-1.0, check::NON_NEGATIVE), (1.0, check::BETWEEN)]
        {
            let mut h = fresh();
            let mut v = 42.0;
            assert_eq!(number(&mut h, default, c, &mut v), -1, "default {default} passed check {c}");
            assert_eq!(v, 42.0, "nothing written on a refusal");
            let e = h.error.as_ref().unwrap().to_string();
            assert!(e.contains("controller.params.gain") && e.contains("the law's own default"), "{e}");
            // The refusal sticks: a later good read fails too.
            assert_eq!(number(&mut h, 0.5, check::FINITE, &mut v), -1);
        }
        let mut h = fresh();
        let mut v = 0.0;
        assert_eq!(number(&mut h, 0.5, check::BETWEEN, &mut v), 0);
        assert_eq!(v, 0.5);
    }

    #[test]
    fn a_bad_table_is_refused_naming_the_law_and_the_field() {
        let good = Law {
            abi_version: ABI_VERSION,
            reserved: 0,
            name: c"ok".as_ptr(),
            summary: std::ptr::null(),
            context: std::ptr::null_mut(),
            build: Some(echo_build),
            update: Some(echo_update),
            reset: Some(nothing),
            drop: Some(free),
        };
        let refused = |table: &[Law]| unsafe { register(table.as_ptr(), table.len()) }.err().unwrap_or_default();
        assert_eq!(
            refused(&[Law { reset: None, ..good }]),
            "law 0 (`ok`): `reset` is NULL; every function of an amb_law must be set"
        );
        assert!(
            refused(&[good, Law { abi_version: 2, ..good }]).starts_with("law 1 (`ok`): built against ABI version 2")
        );
        assert_eq!(refused(&[Law { name: std::ptr::null(), ..good }]), "law 0: its name is NULL or empty");
        assert_eq!(refused(&[good, good]), "law 1 (`ok`): a second law of that name");
        assert_eq!(refused(&[]), "no law to serve (the table is NULL or empty)");
        let long = c"a_name_that_is_longer_than_31_bytes";
        assert!(refused(&[Law { name: long.as_ptr(), ..good }]).contains("at most 31"));
    }
}
