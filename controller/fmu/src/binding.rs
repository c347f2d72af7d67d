//! The FMI C functions the host calls, loaded from the FMU's shared library (FMI 2.0: the
//! common, co-simulation and model-exchange functions; FMI 3.0: the common and co-simulation
//! functions), and the callbacks it gives the FMU (its log goes to stderr: in a controller
//! process started by the plant, `controller.log`).
//!
//! The typedefs are written here from the standard (FMI 2.0.4 `fmi2FunctionTypes.h`, FMI
//! 3.0 `fmi3FunctionTypes.h`): only the functions the host calls.

use std::ffi::{c_char, c_double, c_int, c_void, CStr};

/// FMI 2.0 `fmi2Status` / FMI 3.0 `fmi3Status` (the same numbers): OK, Warning, Discard,
/// Error, Fatal (FMI 2.0 also Pending).
pub type Status = c_int;

/// Status code 2: Discard.
pub const DISCARD: Status = 2;

/// A status as text.
pub fn status_name(s: Status) -> &'static str {
    match s {
        0 => "OK",
        1 => "Warning",
        2 => "Discard",
        3 => "Error",
        4 => "Fatal",
        5 => "Pending",
        _ => "an unknown status",
    }
}

/// FMI 2.0 `fmi2CallbackFunctions`.
#[repr(C)]
pub struct Fmi2Callbacks {
    /// `fmi2CallbackLogger`: variadic in the standard; the host reads the fixed arguments
    /// only (the message is written as the FMU passed it, unformatted when it holds
    /// `printf` directives).
    pub logger: Fmi2Logger,
    /// `calloc`.
    pub allocate_memory: unsafe extern "C" fn(usize, usize) -> *mut c_void,
    /// `free`.
    pub free_memory: unsafe extern "C" fn(*mut c_void),
    /// Asynchronous steps are not used.
    pub step_finished: *const c_void,
    /// The host's environment pointer (unused).
    pub component_environment: *mut c_void,
}

/// The logger as the host defines it (the fixed arguments of `fmi2CallbackLogger`).
pub type Fmi2Logger = unsafe extern "C" fn(*mut c_void, *const c_char, Status, *const c_char, *const c_char);

/// FMI 2.0 `fmi2EventInfo`.
#[repr(C)]
#[derive(Default, Debug, Clone, Copy)]
pub struct Fmi2EventInfo {
    /// `newDiscreteStatesNeeded`.
    pub new_discrete_states_needed: c_int,
    /// `terminateSimulation`.
    pub terminate_simulation: c_int,
    /// `nominalsOfContinuousStatesChanged`.
    pub nominals_changed: c_int,
    /// `valuesOfContinuousStatesChanged`.
    pub values_changed: c_int,
    /// `nextEventTimeDefined`.
    pub next_event_time_defined: c_int,
    /// `nextEventTime`.
    pub next_event_time: c_double,
}

fn text(p: *const c_char) -> String {
    if p.is_null() {
        String::new()
    } else {
        // SAFETY: the FMU passes NUL-terminated strings (the standard's contract).
        unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
    }
}

/// The FMI 2.0 logger: one line on stderr per message.
///
/// # Safety
/// Called by the FMU with NUL-terminated strings or NULL.
pub unsafe extern "C" fn log2(
    _env: *mut c_void,
    instance: *const c_char,
    status: Status,
    category: *const c_char,
    message: *const c_char,
) {
    eprintln!("fmu {} [{}] {}: {}", text(instance), text(category), status_name(status), text(message));
}

/// The FMI 3.0 log callback (`fmi3LogMessageCallback`): one line on stderr per message.
///
/// # Safety
/// Called by the FMU with NUL-terminated strings or NULL.
pub unsafe extern "C" fn log3(_env: *mut c_void, status: Status, category: *const c_char, message: *const c_char) {
    eprintln!("fmu [{}] {}: {}", text(category), status_name(status), text(message));
}

/// `calloc` for the FMU.
///
/// # Safety
/// The C allocator's contract.
pub unsafe extern "C" fn allocate(n: usize, size: usize) -> *mut c_void {
    libc::calloc(n, size)
}

/// `free` for the FMU.
///
/// # Safety
/// The C allocator's contract.
pub unsafe extern "C" fn release(p: *mut c_void) {
    libc::free(p)
}

/// The callbacks of every FMI 2.0 instance (static: they outlive any instance).
pub static FMI2_CALLBACKS: Fmi2CallbacksCell = Fmi2CallbacksCell(Fmi2Callbacks {
    logger: log2,
    allocate_memory: allocate,
    free_memory: release,
    step_finished: std::ptr::null(),
    component_environment: std::ptr::null_mut(),
});

/// [`Fmi2Callbacks`] in a static (its pointers are never written).
pub struct Fmi2CallbacksCell(pub Fmi2Callbacks);
// SAFETY: read-only function pointers and null pointers.
unsafe impl Sync for Fmi2CallbacksCell {}

type Component = *mut c_void;
type Vr = u32;

macro_rules! api {
    ($(#[$meta:meta])* $name:ident { $( $field:ident : $sym:literal => fn($($arg:ty),*) $(-> $ret:ty)? ; )* }
     optional { $( $ofield:ident : $osym:literal => fn($($oarg:ty),*) $(-> $oret:ty)? ; )* }) => {
        $(#[$meta])*
        pub struct $name {
            $( #[doc = $sym] pub $field: unsafe extern "C" fn($($arg),*) $(-> $ret)?, )*
            $( #[doc = $osym] pub $ofield: Option<unsafe extern "C" fn($($oarg),*) $(-> $oret)?>, )*
            _lib: libloading::Library,
        }

        impl $name {
            /// Loads the functions from the library (a required one missing is an error naming it).
            pub fn load(lib: libloading::Library) -> Result<Self, String> {
                // SAFETY: the symbols are typed after the standard's headers; the library stays
                // loaded as long as the table (it is moved into it).
                unsafe {
                    $( let $field = *lib
                        .get::<unsafe extern "C" fn($($arg),*) $(-> $ret)?>(concat!($sym, "\0").as_bytes())
                        .map_err(|e| format!("the FMU's library has no function {}: {e}", $sym))?; )*
                    $( let $ofield = lib
                        .get::<unsafe extern "C" fn($($oarg),*) $(-> $oret)?>(concat!($osym, "\0").as_bytes())
                        .ok()
                        .map(|s| *s); )*
                    Ok(Self { $($field,)* $($ofield,)* _lib: lib })
                }
            }
        }
    };
}

api! {
    /// The FMI 2.0 functions.
    Fmi2 {
        instantiate: "fmi2Instantiate" =>
            fn(*const c_char, c_int, *const c_char, *const c_char, *const Fmi2Callbacks, c_int, c_int) -> Component;
        free_instance: "fmi2FreeInstance" => fn(Component);
        setup_experiment: "fmi2SetupExperiment" => fn(Component, c_int, c_double, c_double, c_int, c_double) -> Status;
        enter_initialization_mode: "fmi2EnterInitializationMode" => fn(Component) -> Status;
        exit_initialization_mode: "fmi2ExitInitializationMode" => fn(Component) -> Status;
        terminate: "fmi2Terminate" => fn(Component) -> Status;
        set_real: "fmi2SetReal" => fn(Component, *const Vr, usize, *const c_double) -> Status;
        get_real: "fmi2GetReal" => fn(Component, *const Vr, usize, *mut c_double) -> Status;
        set_integer: "fmi2SetInteger" => fn(Component, *const Vr, usize, *const c_int) -> Status;
        set_boolean: "fmi2SetBoolean" => fn(Component, *const Vr, usize, *const c_int) -> Status;
        set_string: "fmi2SetString" => fn(Component, *const Vr, usize, *const *const c_char) -> Status;
    }
    optional {
        do_step: "fmi2DoStep" => fn(Component, c_double, c_double, c_int) -> Status;
        set_time: "fmi2SetTime" => fn(Component, c_double) -> Status;
        set_continuous_states: "fmi2SetContinuousStates" => fn(Component, *const c_double, usize) -> Status;
        get_continuous_states: "fmi2GetContinuousStates" => fn(Component, *mut c_double, usize) -> Status;
        get_derivatives: "fmi2GetDerivatives" => fn(Component, *mut c_double, usize) -> Status;
        completed_integrator_step: "fmi2CompletedIntegratorStep" => fn(Component, c_int, *mut c_int, *mut c_int) -> Status;
        enter_event_mode: "fmi2EnterEventMode" => fn(Component) -> Status;
        new_discrete_states: "fmi2NewDiscreteStates" => fn(Component, *mut Fmi2EventInfo) -> Status;
        enter_continuous_time_mode: "fmi2EnterContinuousTimeMode" => fn(Component) -> Status;
    }
}

api! {
    /// The FMI 3.0 functions (co-simulation).
    Fmi3 {
        instantiate_co_simulation: "fmi3InstantiateCoSimulation" =>
            fn(*const c_char, *const c_char, *const c_char, bool, bool, bool, bool, *const Vr, usize, *mut c_void,
               unsafe extern "C" fn(*mut c_void, Status, *const c_char, *const c_char), *const c_void) -> Component;
        free_instance: "fmi3FreeInstance" => fn(Component);
        enter_initialization_mode: "fmi3EnterInitializationMode" => fn(Component, bool, c_double, c_double, bool, c_double) -> Status;
        exit_initialization_mode: "fmi3ExitInitializationMode" => fn(Component) -> Status;
        terminate: "fmi3Terminate" => fn(Component) -> Status;
        set_float64: "fmi3SetFloat64" => fn(Component, *const Vr, usize, *const c_double, usize) -> Status;
        get_float64: "fmi3GetFloat64" => fn(Component, *const Vr, usize, *mut c_double, usize) -> Status;
        set_int32: "fmi3SetInt32" => fn(Component, *const Vr, usize, *const i32, usize) -> Status;
        set_boolean: "fmi3SetBoolean" => fn(Component, *const Vr, usize, *const bool, usize) -> Status;
        set_string: "fmi3SetString" => fn(Component, *const Vr, usize, *const *const c_char, usize) -> Status;
        do_step: "fmi3DoStep" =>
            fn(Component, c_double, c_double, bool, *mut bool, *mut bool, *mut bool, *mut c_double) -> Status;
    }
    optional {}
}
