//! The exported `fmi2*` functions of the FMI 2.0 co-simulation interface, each a thin
//! `extern "C"` shell over the instance's methods in `fmi2.rs`: arguments checked, panics
//! caught, refusals logged. What rodcube does not offer (FMU states, directional and input or
//! output derivatives, asynchronous steps, Integer/Boolean/String inputs) is `fmi2Error`
//! with a message, as the standard allows where the model description's capability flags say
//! so.

use super::{
    CallbackFunctions, DO_STEP_STATUS, FMI2_ERROR, FMI2_OK, Instance, LAST_SUCCESSFUL_TIME, Mode,
    Refusal, TERMINATED, instantiate, log, refuse, slice, slice_mut, text, with,
};
use std::ffi::{c_char, c_int, c_uint, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// `fmi2GetTypesPlatform`.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

/// `fmi2GetVersion`.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// `fmi2Instantiate`: NULL (with a logged message) for a model exchange instance, a GUID or
/// resources not this library's.
///
/// # Safety
/// The strings are NULL or NUL-terminated; `functions` is NULL or points to the callbacks.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: *const c_char,
    fmu_type: c_int,
    fmu_guid: *const c_char,
    resource_location: *const c_char,
    functions: *const CallbackFunctions,
    _visible: c_int,
    _logging_on: c_int,
) -> *mut c_void {
    let made = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: as the caller promises.
        let callbacks = unsafe { functions.as_ref() };
        let logger = callbacks.and_then(|f| f.logger);
        let env = callbacks.map_or(std::ptr::null_mut(), |f| f.component_environment);
        // SAFETY: as the caller promises.
        let name = unsafe { text(instance_name, "the instance name") }.map(str::to_string);
        let made = (|| {
            // SAFETY: as the caller promises.
            let (guid, resources) = unsafe {
                (
                    text(fmu_guid, "the GUID")?,
                    text(resource_location, "the resource location")?,
                )
            };
            instantiate(name.as_deref()?, fmu_type, guid, resources, logger, env)
        })();
        match made {
            Ok(instance) => Box::into_raw(Box::new(instance)).cast::<c_void>(),
            Err(message) => {
                let name = std::ffi::CString::new(name.unwrap_or_default()).unwrap_or_default();
                log(logger, env, &name, FMI2_ERROR, &message);
                std::ptr::null_mut()
            }
        }
    }));
    made.unwrap_or(std::ptr::null_mut())
}

/// `fmi2FreeInstance` (NULL is ignored).
///
/// # Safety
/// `c` is NULL or an instance from `fmi2Instantiate` not yet freed.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: *mut c_void) {
    if !c.is_null() {
        let _ = catch_unwind(AssertUnwindSafe(|| {
            // SAFETY: made by `Box::into_raw` in `fmi2Instantiate`, freed once.
            drop(unsafe { Box::from_raw(c.cast::<Instance>()) })
        }));
    }
}

/// `fmi2SetDebugLogging`: errors are always logged; there are no debug categories.
///
/// # Safety
/// `c` is NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: *mut c_void,
    _logging_on: c_int,
    n_categories: usize,
    _categories: *const *const c_char,
) -> c_int {
    // SAFETY: as the caller promises.
    unsafe {
        with(c, |_| {
            if n_categories > 0 {
                return refuse("this FMU has no log categories");
            }
            Ok(FMI2_OK)
        })
    }
}

/// `fmi2SetupExperiment`: the tolerance (relative, within the planner's range; default 1e-10)
/// and the stop time (the motion goes on through impacts to it; without one it ends at its
/// first landing, as `rodcube run` without `until`).
///
/// # Safety
/// `c` is NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: *mut c_void,
    tolerance_defined: c_int,
    tolerance: f64,
    start_time: f64,
    stop_time_defined: c_int,
    stop_time: f64,
) -> c_int {
    // SAFETY: as the caller promises.
    unsafe {
        with(c, |i| {
            i.expect_mode(&[Mode::Instantiated], "fmi2SetupExperiment")?;
            let (lo, hi) = crate::plan::TOLERANCE_RANGE;
            if tolerance_defined != 0 {
                if !(tolerance >= lo && tolerance <= hi) {
                    return refuse(format!(
                        "tolerance {tolerance:e} is outside [{lo:e}, {hi:e}]"
                    ));
                }
                i.tolerance = tolerance;
            }
            if !start_time.is_finite() || (stop_time_defined != 0 && !stop_time.is_finite()) {
                return refuse("the start and stop times must be finite");
            }
            i.start_time = start_time;
            i.time = start_time;
            i.stop_time = (stop_time_defined != 0).then_some(stop_time);
            Ok(FMI2_OK)
        })
    }
}

/// Moves the instance from mode `from` to `to` (refusing the call `call` in any other mode),
/// after `work` succeeds.
///
/// # Safety
/// `c` is NULL or a live instance.
unsafe fn transition(
    c: *mut c_void,
    call: &str,
    (from, to): (Mode, Mode),
    work: impl FnOnce(&mut Instance) -> Result<(), Refusal>,
) -> c_int {
    // SAFETY: as the caller promises.
    unsafe {
        with(c, |i| {
            i.expect_mode(&[from], call)?;
            work(i)?;
            i.mode = to;
            Ok(FMI2_OK)
        })
    }
}

/// `fmi2EnterInitializationMode`.
///
/// # Safety
/// `c` is NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: *mut c_void) -> c_int {
    let modes = (Mode::Instantiated, Mode::Initialization);
    // SAFETY: as the caller promises.
    unsafe { transition(c, "fmi2EnterInitializationMode", modes, |_| Ok(())) }
}

/// `fmi2ExitInitializationMode`: binds the parameters (the model's requirements between them
/// checked here) and solves the release (unless an output read in initialization mode did,
/// with the same parameters).
///
/// # Safety
/// `c` is NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: *mut c_void) -> c_int {
    let modes = (Mode::Initialization, Mode::Stepping);
    // SAFETY: as the caller promises.
    unsafe {
        transition(
            c,
            "fmi2ExitInitializationMode",
            modes,
            Instance::outputs_ready,
        )
    }
}

/// `fmi2Terminate`.
///
/// # Safety
/// `c` is NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: *mut c_void) -> c_int {
    let modes = (Mode::Stepping, Mode::Terminated);
    // SAFETY: as the caller promises.
    unsafe { transition(c, "fmi2Terminate", modes, |_| Ok(())) }
}

/// `fmi2Reset`: back to the start values and the state after `fmi2Instantiate`.
///
/// # Safety
/// `c` is NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: *mut c_void) -> c_int {
    // SAFETY: as the caller promises.
    unsafe {
        with(c, |i| {
            i.reset();
            Ok(FMI2_OK)
        })
    }
}

/// `fmi2GetReal`: parameters at any time, outputs from `fmi2EnterInitializationMode` on (the
/// release state until the first step).
///
/// # Safety
/// `c` is NULL or a live instance; `vr` and `value` point to `nvr` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(
    c: *mut c_void,
    vr: *const c_uint,
    nvr: usize,
    value: *mut f64,
) -> c_int {
    // SAFETY: as the caller promises.
    unsafe { with(c, |i| i.get_real(slice(vr, nvr)?, slice_mut(value, nvr)?)) }
}

/// `fmi2GetInteger`: the phase index.
///
/// # Safety
/// `c` is NULL or a live instance; `vr` and `value` point to `nvr` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetInteger(
    c: *mut c_void,
    vr: *const c_uint,
    nvr: usize,
    value: *mut c_int,
) -> c_int {
    // SAFETY: as the caller promises.
    unsafe {
        with(c, |i| {
            i.get_integer(slice(vr, nvr)?, slice_mut(value, nvr)?)
        })
    }
}

/// `fmi2SetReal`: parameters, before `fmi2ExitInitializationMode`, and the tunable ones
/// between steps too (the motion taken up at the current communication point with the new
/// values); a value out of the parameter's domain, parameters that break a requirement, or a
/// fixed parameter set between steps is `fmi2Error`, logged, and leaves the parameters (and
/// the motion) as they were.
///
/// # Safety
/// `c` is NULL or a live instance; `vr` and `value` point to `nvr` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetReal(
    c: *mut c_void,
    vr: *const c_uint,
    nvr: usize,
    value: *const f64,
) -> c_int {
    // SAFETY: as the caller promises.
    unsafe { with(c, |i| i.set_real(slice(vr, nvr)?, slice(value, nvr)?)) }
}

/// A call about variables of a type the FMU has none of: `fmi2OK` for none, else
/// `fmi2Error`.
///
/// # Safety
/// `c` is NULL or a live instance.
unsafe fn no_variables(c: *mut c_void, nvr: usize, what: &'static str) -> c_int {
    // SAFETY: as the caller promises.
    unsafe {
        with(c, |_| {
            if nvr == 0 {
                return Ok(FMI2_OK);
            }
            refuse(format!("this FMU has no {what} variables"))
        })
    }
}

macro_rules! no_variables {
    ($($name:ident($value:ty, $what:literal);)*) => {$(
        #[doc = concat!("`", stringify!($name), "`: the FMU has no ", $what, " variables ",
                        "(`fmi2OK` for none, else `fmi2Error`).")]
        ///
        /// # Safety
        /// `c` is NULL or a live instance.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $name(
            c: *mut c_void,
            _vr: *const c_uint,
            nvr: usize,
            _value: $value,
        ) -> c_int {
            // SAFETY: as the caller promises.
            unsafe { no_variables(c, nvr, $what) }
        }
    )*};
}

no_variables! {
    fmi2GetBoolean(*mut c_int, "Boolean");
    fmi2GetString(*mut *const c_char, "String");
    fmi2SetInteger(*const c_int, "settable Integer");
    fmi2SetBoolean(*const c_int, "Boolean");
    fmi2SetString(*const *const c_char, "String");
}

/// A capability the model description says the FMU lacks: `fmi2Error`, logged.
///
/// # Safety
/// `c` is NULL or a live instance.
unsafe fn unsupported(c: *mut c_void, call: &'static str) -> c_int {
    // SAFETY: as the caller promises.
    unsafe {
        with(c, |_| {
            refuse(format!("{call} is not supported by this FMU"))
        })
    }
}

macro_rules! unsupported {
    ($($name:ident($($arg:ident: $ty:ty),*);)*) => {$(
        #[doc = concat!("`", stringify!($name), "`: not supported (`fmi2Error`).")]
        ///
        /// # Safety
        /// `c` is NULL or a live instance.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $name(c: *mut c_void, $(_: $ty),*) -> c_int {
            // SAFETY: as the caller promises.
            unsafe { unsupported(c, stringify!($name)) }
        }
    )*};
}

unsupported! {
    fmi2GetFMUstate(state: *mut *mut c_void);
    fmi2SetFMUstate(state: *mut c_void);
    fmi2FreeFMUstate(state: *mut *mut c_void);
    fmi2SerializedFMUstateSize(state: *mut c_void, size: *mut usize);
    fmi2SerializeFMUstate(state: *mut c_void, bytes: *mut c_char, size: usize);
    fmi2DeSerializeFMUstate(bytes: *const c_char, size: usize, state: *mut *mut c_void);
    fmi2GetDirectionalDerivative(
        unknown: *const c_uint, n_unknown: usize, known: *const c_uint, n_known: usize,
        dv_known: *const f64, dv_unknown: *mut f64
    );
    fmi2SetRealInputDerivatives(
        vr: *const c_uint, nvr: usize, order: *const c_int, value: *const f64
    );
    fmi2GetRealOutputDerivatives(
        vr: *const c_uint, nvr: usize, order: *const c_int, value: *mut f64
    );
    fmi2CancelStep();
}

/// `fmi2DoStep`: follows the motion from `current` (the instance's time) by `step`, through
/// any events in between. Past the motion's end (its landing, where the run has no stop time
/// or the stop time lies beyond it) it stops there: `fmi2Discard`, with `fmi2Terminated` true
/// and `fmi2LastSuccessfulTime` the end.
///
/// # Safety
/// `c` is NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(
    c: *mut c_void,
    current: f64,
    step: f64,
    _no_set_prior_state: c_int,
) -> c_int {
    // SAFETY: as the caller promises.
    unsafe { with(c, |i| i.step(current, step)) }
}

/// Writes `value` through `out`, or refuses a NULL.
///
/// # Safety
/// `out` is NULL or points to a writable `T`.
unsafe fn put<T>(out: *mut T, value: T) -> Result<c_int, Refusal> {
    // SAFETY: as the caller promises.
    match unsafe { out.as_mut() } {
        Some(slot) => {
            *slot = value;
            Ok(FMI2_OK)
        }
        None => refuse("the status's out pointer is NULL"),
    }
}

/// `fmi2GetStatus`: `fmi2DoStepStatus` only (always `fmi2OK`: steps finish before they
/// return).
///
/// # Safety
/// `c` is NULL or a live instance; `value` points to a writable status.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStatus(c: *mut c_void, kind: c_int, value: *mut c_int) -> c_int {
    // SAFETY: as the caller promises.
    unsafe {
        with(c, |_| match kind {
            DO_STEP_STATUS => put(value, FMI2_OK),
            _ => refuse(format!("fmi2GetStatus of kind {kind} is not supported")),
        })
    }
}

/// `fmi2GetRealStatus`: `fmi2LastSuccessfulTime`, the instance's time.
///
/// # Safety
/// `c` is NULL or a live instance; `value` points to a writable real.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(c: *mut c_void, kind: c_int, value: *mut f64) -> c_int {
    // SAFETY: as the caller promises.
    unsafe {
        with(c, |i| match kind {
            LAST_SUCCESSFUL_TIME => put(value, i.time),
            _ => refuse(format!("fmi2GetRealStatus of kind {kind} is not supported")),
        })
    }
}

/// `fmi2GetIntegerStatus`: none.
///
/// # Safety
/// `c` is NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: *mut c_void,
    kind: c_int,
    _value: *mut c_int,
) -> c_int {
    // SAFETY: as the caller promises.
    unsafe {
        with(c, |_| {
            refuse(format!(
                "fmi2GetIntegerStatus of kind {kind} is not supported"
            ))
        })
    }
}

/// `fmi2GetBooleanStatus`: `fmi2Terminated`, whether the motion has ended.
///
/// # Safety
/// `c` is NULL or a live instance; `value` points to a writable boolean.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: *mut c_void,
    kind: c_int,
    value: *mut c_int,
) -> c_int {
    // SAFETY: as the caller promises.
    unsafe {
        with(c, |i| match kind {
            TERMINATED => put(value, c_int::from(i.terminated)),
            _ => refuse(format!(
                "fmi2GetBooleanStatus of kind {kind} is not supported"
            )),
        })
    }
}

/// `fmi2GetStringStatus`: none.
///
/// # Safety
/// `c` is NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: *mut c_void,
    kind: c_int,
    _value: *mut *const c_char,
) -> c_int {
    // SAFETY: as the caller promises.
    unsafe {
        with(c, |_| {
            refuse(format!(
                "fmi2GetStringStatus of kind {kind} is not supported"
            ))
        })
    }
}
