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
//! The shapes extend to the two-plane rotor without a break: a sample holds
//! `axes` entries of room for [`MAX_AXES`] plus the rotor's speed and angle
//! (the keyphasor: 0 until the protocol carries it), a design `planes`
//! per-plane designs of room for [`MAX_PLANES`]; [`ABI_VERSION`] says which
//! layout a law was built against and [`amb_serve`] refuses another.
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
//! `controller.log`, and writes its outputs. Nothing unwinds across the
//! boundary out of this library: [`amb_serve`] catches a panic of its own and
//! returns an exit code.

use controller::{Check, ControlLaw, LawEntry, LawError, ParamReader};
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

/// The design a law is built from.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Design {
    /// Axes the law drives: 2 (x, y of one plane; 4 on the two-plane rotor).
    pub axes: u32,
    /// Bearing planes in `plane`: 1 (2 on the two-plane rotor).
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
    /// The rotor's speed (rad/s): the keyphasor; 0 until the protocol carries it.
    pub speed_rad_s: f64,
    /// The rotor's angle (rad) in [0, 2π): the keyphasor; 0 until the protocol carries it.
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
/// [`MAX_AXES`], zeroed), before the amplifier limit.
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

/// A `LawEntry` needs a plain function per law: one trampoline per table index.
fn build_at<const I: usize>(
    design: &controller::Design,
    params: &controller::Params,
) -> Result<Box<dyn ControlLaw>, LawError> {
    build(&LAWS.get().expect("amb_serve registered the laws")[I], design, params)
}

const BUILDERS: [controller::registry::BuildLaw; MAX_LAWS] = [
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

/// The C design of a (one-plane) Rust design.
pub fn design_of(d: &controller::Design) -> Design {
    let c = &d.constants;
    let mut plane = [PlaneDesign::default(); MAX_PLANES];
    plane[0] = PlaneDesign {
        stiffness_n_per_m: d.stiffness_n_per_m,
        damping_ratio: d.damping_ratio,
        current_limit_a: d.current_limit_a,
        gravity_bias: u32::from(d.gravity_bias),
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
    Design { axes: 2, planes: 1, delay_samples: d.delay_samples, reserved: 0, period_s: d.period_s, plane }
}

/// The C sample of a (one-plane) Rust sample.
pub fn sample_of(s: &controller::Sample) -> Sample {
    Sample {
        seq: s.seq,
        t_s: s.t_s,
        axes: 2,
        reserved: 0,
        sensor_v: controller::wire::axes_of(s.sensor_v),
        speed_rad_s: 0.0,
        angle_rad: 0.0,
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
    design: &controller::Design,
    params: &controller::Params,
) -> Result<Box<dyn ControlLaw>, LawError> {
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

/// A C law as a `ControlLaw`.
struct Adapter {
    law: &'static Registered,
    state: *mut c_void,
    warned: bool,
}

// SAFETY: the state is used by one thread at a time (the controller process's loop); the C
// law promises no more than that.
unsafe impl Send for Adapter {}

impl ControlLaw for Adapter {
    fn name(&self) -> &'static str {
        self.law.name
    }

    fn update(&mut self, s: &controller::Sample) -> [f64; 2] {
        let sample = sample_of(s);
        let mut current = [0.0; MAX_AXES];
        // SAFETY: the state is the one `build` returned; `current` has room for MAX_AXES.
        unsafe { (self.law.update)(self.state, &sample, current.as_mut_ptr()) };
        let i = [current[0], current[1]];
        if !self.warned && !i.iter().all(|v| v.is_finite()) {
            self.warned = true;
            eprintln!(
                "amb_serve: warning: law `{}` returned a non-finite current {i:?} A for sample {} (t = {} s); \
                 it is sent as it is (a NaN after the limit): the plant holds the last valid current and ends the run \
                 past controller.max_invalid_burst or controller.max_invalid_fraction (said once)",
                self.law.name, s.seq, s.t_s
            );
        }
        i
    }

    fn reset(&mut self) {
        // SAFETY: the state `build` returned.
        unsafe { (self.law.reset)(self.state) }
    }
}

impl Drop for Adapter {
    fn drop(&mut self) {
        // SAFETY: the state `build` returned, dropped once.
        unsafe { (self.law.drop)(self.state) }
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
        let entries: Vec<LawEntry> = LAWS
            .get()
            .expect("set above")
            .iter()
            .zip(BUILDERS)
            .map(|(law, build)| LawEntry { name: law.name, summary: "a law of the C API", build })
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
/// `AMB_CHECK_BETWEEN`). Returns 0, or -1 when refused (the law's `build` should then return
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
    match h.reader.number(key, unit, default_value, check) {
        Ok(v) => {
            if !value.is_null() {
                // SAFETY: the caller's promise.
                unsafe { *value = v };
            }
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
    match h.reader.flag(intern(key), default_value != 0) {
        Ok(b) => {
            if !value.is_null() {
                // SAFETY: the caller's promise.
                unsafe { *value = c_int::from(b) };
            }
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
