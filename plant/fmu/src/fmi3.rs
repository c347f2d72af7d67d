//! The FMI 3.0 co-simulation C API (`fmi3Functions.h`) over the same instance as FMI 2.0's:
//! `plant fmu SCENE --fmi 3` writes the FMU that loads it (`binaries/x86_64-linux/`, with
//! `fixedInternalStepSize` the plant's tick). The variables are FMI 2.0's, as `Float64`, and
//! `time` (the independent variable) after them; every other type has no variable.

use super::*;

/// `fmi3LogMessageCallback`.
pub(crate) type LogMessage = unsafe extern "C" fn(*mut c_void, Status, *const c_char, *const c_char);

/// A log line of the shared instance in FMI 3.0's names (the calls, the GUID).
pub(crate) fn names(message: &str) -> String {
    const NAMES: [(&str, &str); 16] = [
        ("fmi2DoStep", "fmi3DoStep"),
        ("fmi2SetReal", "fmi3SetFloat64"),
        ("fmi2GetReal", "fmi3GetFloat64"),
        ("fmi2Reset", "fmi3Reset"),
        ("fmi2SetupExperiment", "fmi3EnterInitializationMode"),
        ("fmi2EnterInitializationMode", "fmi3EnterInitializationMode"),
        ("fmi2ExitInitializationMode", "fmi3ExitInitializationMode"),
        ("fmi2Terminate", "fmi3Terminate"),
        ("fmi2SetDebugLogging", "fmi3SetDebugLogging"),
        ("fmi2GetFMUstate", "fmi3GetFMUState"),
        ("fmi2SetFMUstate", "fmi3SetFMUState"),
        ("fmi2FreeFMUstate", "fmi3FreeFMUState"),
        ("fmi2SerializedFMUstateSize", "fmi3SerializedFMUStateSize"),
        ("fmi2SerializeFMUstate", "fmi3SerializeFMUState"),
        ("fmi2DeSerializeFMUstate", "fmi3DeserializeFMUState"),
        ("fmuGUID", "instantiationToken"),
    ];
    let mut m = message.to_string();
    for (two, three) in NAMES {
        m = m.replace(two, three);
    }
    m
}

/// The value reference of `time`: after the model's variables.
fn time_vr(inst: &Instance) -> u32 {
    inst.model.variables.len() as u32
}

#[no_mangle]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    c: *mut c_void,
    logging_on: bool,
    n: usize,
    categories: *const *const c_char,
) -> Status {
    super::fmi2SetDebugLogging(c, c_int::from(logging_on), n, categories)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instance_name: *const c_char,
    token: *const c_char,
    resource_path: *const c_char,
    _visible: bool,
    logging_on: bool,
    _event_mode_used: bool,
    _early_return_allowed: bool,
    _required_intermediate: *const u32,
    _n_required_intermediate: usize,
    environment: *mut c_void,
    log: Option<LogMessage>,
    _intermediate_update: *const c_void,
) -> *mut c_void {
    let made = catch_unwind(AssertUnwindSafe(|| {
        let callbacks = Callbacks::Fmi3 { environment, log };
        let name = CString::new(text(instance_name).unwrap_or_default()).unwrap_or_default();
        match new_instance(callbacks, name, text(resource_path), text(token), logging_on, "fmi3InstantiateCoSimulation")
        {
            Some(inst) => Box::into_raw(inst) as *mut c_void,
            None => std::ptr::null_mut(),
        }
    }));
    made.unwrap_or(std::ptr::null_mut())
}

/// Model exchange and scheduled execution: refused with a log line naming the call.
unsafe fn refuse_instantiation(
    call: &str,
    instance_name: *const c_char,
    environment: *mut c_void,
    log: Option<LogMessage>,
) -> *mut c_void {
    let name = CString::new(text(instance_name).unwrap_or_default()).unwrap_or_default();
    log_with(
        &Callbacks::Fmi3 { environment, log },
        &name,
        ERROR,
        &format!("{call}: this FMU is for co-simulation only"),
    );
    std::ptr::null_mut()
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    instance_name: *const c_char,
    _token: *const c_char,
    _resource_path: *const c_char,
    _visible: bool,
    _logging_on: bool,
    environment: *mut c_void,
    log: Option<LogMessage>,
) -> *mut c_void {
    refuse_instantiation("fmi3InstantiateModelExchange", instance_name, environment, log)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    instance_name: *const c_char,
    _token: *const c_char,
    _resource_path: *const c_char,
    _visible: bool,
    _logging_on: bool,
    environment: *mut c_void,
    log: Option<LogMessage>,
) -> *mut c_void {
    refuse_instantiation("fmi3InstantiateScheduledExecution", instance_name, environment, log)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeInstance(c: *mut c_void) {
    super::fmi2FreeInstance(c)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    c: *mut c_void,
    tolerance_defined: bool,
    tolerance: f64,
    start_time: f64,
    stop_time_defined: bool,
    stop_time: f64,
) -> Status {
    let s = super::fmi2SetupExperiment(
        c,
        c_int::from(tolerance_defined),
        tolerance,
        start_time,
        c_int::from(stop_time_defined),
        stop_time,
    );
    if s != OK {
        return s;
    }
    super::fmi2EnterInitializationMode(c)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3ExitInitializationMode(c: *mut c_void) -> Status {
    super::fmi2ExitInitializationMode(c)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterStepMode(c: *mut c_void) -> Status {
    with(c, "fmi3EnterStepMode", |inst| match inst.expect("fmi3EnterStepMode", &[Phase::Stepping]) {
        Ok(()) => OK,
        Err(s) => s,
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3Terminate(c: *mut c_void) -> Status {
    super::fmi2Terminate(c)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3Reset(c: *mut c_void) -> Status {
    super::fmi2Reset(c)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat64(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    values: *mut f64,
    n_values: usize,
) -> Status {
    with(c, "fmi3GetFloat64", |inst| {
        let (Some(vr), Some(out)) = (slice(vr, n), slice_mut(values, n_values)) else {
            return inst.error("fmi3GetFloat64: a NULL array");
        };
        if n != n_values {
            return inst
                .error(&format!("fmi3GetFloat64: {n} value references but {n_values} values (all are scalars)"));
        }
        let time = time_vr(inst);
        let model: Vec<u32> = vr.iter().copied().filter(|&v| v != time).collect();
        let mut got = vec![0.0; model.len()];
        let s = inst.get_real(&model, &mut got);
        if s != OK {
            return s;
        }
        let mut it = got.into_iter();
        for (o, &v) in out.iter_mut().zip(vr) {
            *o = if v == time { inst.time() } else { it.next().unwrap_or(f64::NAN) };
        }
        OK
    })
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat64(
    c: *mut c_void,
    vr: *const u32,
    n: usize,
    values: *const f64,
    n_values: usize,
) -> Status {
    with(c, "fmi3SetFloat64", |inst| {
        let (Some(vr), Some(v)) = (slice(vr, n), slice(values, n_values)) else {
            return inst.error("fmi3SetFloat64: a NULL array");
        };
        if n != n_values {
            return inst
                .error(&format!("fmi3SetFloat64: {n} value references but {n_values} values (all are scalars)"));
        }
        if vr.contains(&time_vr(inst)) {
            return inst.error("fmi3SetFloat64: time is the independent variable; it cannot be set");
        }
        inst.set_real(vr, v)
    })
}

/// The getters and setters of the types this FMU has no variable of.
macro_rules! no_variables_of {
    ($($name:ident),* $(,)?) => {$(
        #[no_mangle]
        pub extern "C" fn $name(c: *mut c_void, _vr: *const u32, n: usize) -> Status {
            with(c, stringify!($name), |inst| {
                if n == 0 {
                    OK
                } else {
                    inst.error(concat!(stringify!($name), ": this FMU has no variable of this type (all are Float64)"))
                }
            })
        }
    )*};
}

no_variables_of!(
    fmi3GetFloat32,
    fmi3GetInt8,
    fmi3GetUInt8,
    fmi3GetInt16,
    fmi3GetUInt16,
    fmi3GetInt32,
    fmi3GetUInt32,
    fmi3GetInt64,
    fmi3GetUInt64,
    fmi3GetBoolean,
    fmi3GetString,
    fmi3GetBinary,
    fmi3GetClock,
    fmi3SetFloat32,
    fmi3SetInt8,
    fmi3SetUInt8,
    fmi3SetInt16,
    fmi3SetUInt16,
    fmi3SetInt32,
    fmi3SetUInt32,
    fmi3SetInt64,
    fmi3SetUInt64,
    fmi3SetBoolean,
    fmi3SetString,
    fmi3SetBinary,
    fmi3SetClock,
);

/// The functions of features this FMU does not have (event mode, model exchange, clocks,
/// configuration mode, derivatives, dependencies): `fmi3Error` and a log line.
macro_rules! not_provided {
    ($($name:ident: $why:literal),* $(,)?) => {$(
        #[no_mangle]
        pub extern "C" fn $name(c: *mut c_void) -> Status {
            with(c, stringify!($name), |inst| inst.error(concat!(stringify!($name), ": not provided (", $why, ")")))
        }
    )*};
}

not_provided!(
    fmi3EnterEventMode: "no event mode: hasEventMode = false",
    fmi3UpdateDiscreteStates: "no event mode",
    fmi3EvaluateDiscreteStates: "no event mode",
    fmi3EnterConfigurationMode: "no structural parameters",
    fmi3ExitConfigurationMode: "no structural parameters",
    fmi3GetNumberOfVariableDependencies: "the model structure lists the dependencies",
    fmi3GetVariableDependencies: "the model structure lists the dependencies",
    fmi3GetDirectionalDerivative: "providesDirectionalDerivatives = false: the contact is not smooth",
    fmi3GetAdjointDerivative: "providesAdjointDerivatives = false: the contact is not smooth",
    fmi3GetOutputDerivatives: "maxOutputDerivativeOrder = 0",
    fmi3GetIntervalDecimal: "no clocks",
    fmi3GetIntervalFraction: "no clocks",
    fmi3GetShiftDecimal: "no clocks",
    fmi3GetShiftFraction: "no clocks",
    fmi3SetIntervalDecimal: "no clocks",
    fmi3SetIntervalFraction: "no clocks",
    fmi3SetShiftDecimal: "no clocks",
    fmi3SetShiftFraction: "no clocks",
    fmi3ActivateModelPartition: "no scheduled execution",
    fmi3EnterContinuousTimeMode: "co-simulation only",
    fmi3CompletedIntegratorStep: "co-simulation only",
    fmi3SetTime: "co-simulation only",
    fmi3SetContinuousStates: "co-simulation only",
    fmi3GetContinuousStateDerivatives: "co-simulation only",
    fmi3GetEventIndicators: "co-simulation only",
    fmi3GetContinuousStates: "co-simulation only",
    fmi3GetNominalsOfContinuousStates: "co-simulation only",
    fmi3GetNumberOfEventIndicators: "co-simulation only",
    fmi3GetNumberOfContinuousStates: "co-simulation only",
);

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFMUState(c: *mut c_void, state: *mut *mut c_void) -> Status {
    super::fmi2GetFMUstate(c, state)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFMUState(c: *mut c_void, state: *mut c_void) -> Status {
    super::fmi2SetFMUstate(c, state)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeFMUState(c: *mut c_void, state: *mut *mut c_void) -> Status {
    super::fmi2FreeFMUstate(c, state)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(c: *mut c_void, state: *mut c_void, size: *mut usize) -> Status {
    super::fmi2SerializedFMUstateSize(c, state, size)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SerializeFMUState(
    c: *mut c_void,
    state: *mut c_void,
    bytes: *mut u8,
    size: usize,
) -> Status {
    super::fmi2SerializeFMUstate(c, state, bytes as *mut c_char, size)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    c: *mut c_void,
    bytes: *const u8,
    size: usize,
    state: *mut *mut c_void,
) -> Status {
    super::fmi2DeSerializeFMUstate(c, bytes as *const c_char, size, state)
}

#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn fmi3DoStep(
    c: *mut c_void,
    point: f64,
    step: f64,
    _no_set_prior: bool,
    event_handling_needed: *mut bool,
    terminate_simulation: *mut bool,
    early_return: *mut bool,
    last_successful_time: *mut f64,
) -> Status {
    with(c, "fmi3DoStep", |inst| {
        let s = inst.do_step(point, step);
        for flag in [event_handling_needed, terminate_simulation, early_return] {
            if !flag.is_null() {
                *flag = false;
            }
        }
        if !last_successful_time.is_null() {
            *last_successful_time = inst.time();
        }
        s
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn log_lines_name_the_fmi3_calls() {
        assert_eq!(
            super::names("fmi2DoStep: not allowed; fmi2Reset first; fmi2SerializedFMUstateSize"),
            "fmi3DoStep: not allowed; fmi3Reset first; fmi3SerializedFMUStateSize"
        );
    }
}
