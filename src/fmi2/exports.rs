//! The 25 common and 9 co-simulation functions of FMI 2.0, exported unmangled with the C ABI.
//!
//! Each function: checks its pointers (a NULL instance gives `fmi2Error` without a message, since
//! there is no logger to send it to; NULL arrays with a non-zero length give `fmi2Error` and a
//! message), converts C arrays to slices, and calls [`Instance`] inside `catch_unwind`: a panic
//! becomes `fmi2Error`, is logged, and puts the instance in the Error state. No panic unwinds
//! into the importer.
//!
//! Safety contract of every function (hence no per-function `# Safety` sections): the caller
//! follows FMI 2.0 — `c` is NULL or a live pointer returned by [`fmi2Instantiate`] and not freed,
//! used by one thread at a time; arrays hold at least the stated number of elements; strings are
//! NUL-terminated; FMU states come from [`fmi2GetFMUstate`] of an instance of this FMU.

#![allow(non_snake_case, clippy::missing_safety_doc)]

use super::instance::{Instance, Snapshot};
use super::logger::{Logger, Sink};
use super::types::*;
use super::uri::resource_path;
use crate::slave::{Slave, SlaveState};
use std::any::Any;
use std::ffi::{c_char, c_int, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::ptr::null_mut;

/// The instance behind an `fmi2Component`.
pub type Component = Instance<Slave>;
/// The object behind an `fmi2FMUstate`.
pub type FmuState = Snapshot<SlaveState>;

/// The text of a panic payload.
fn panic_text(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "a panic without a message".to_string()
    }
}

/// Runs `f` on the instance behind `c`, catching panics.
unsafe fn call(
    c: fmi2Component,
    function: &str,
    f: impl FnOnce(&mut Component) -> fmi2Status,
) -> fmi2Status {
    let ptr = c as *mut Component;
    if ptr.is_null() {
        return fmi2Status::fmi2Error;
    }
    match catch_unwind(AssertUnwindSafe(|| f(&mut *ptr))) {
        Ok(status) => status,
        Err(payload) => {
            let text = panic_text(payload.as_ref());
            // Logging goes through the importer's callback; guard it as well.
            let _ = catch_unwind(AssertUnwindSafe(|| (*ptr).panicked(function, &text)));
            fmi2Status::fmi2Error
        }
    }
}

/// `n` elements at `p`; an empty slice for `n == 0` (whatever `p`), None for NULL with `n > 0`.
unsafe fn slice_in<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        Some(&[])
    } else if p.is_null() {
        None
    } else {
        Some(std::slice::from_raw_parts(p, n))
    }
}

/// Mutable counterpart of [`slice_in`].
unsafe fn slice_out<'a, T>(p: *mut T, n: usize) -> Option<&'a mut [T]> {
    if n == 0 {
        Some(&mut [])
    } else if p.is_null() {
        None
    } else {
        Some(std::slice::from_raw_parts_mut(p, n))
    }
}

/// A copy of a C string (lossy UTF-8); None for NULL.
unsafe fn copy_string(p: fmi2String) -> Option<String> {
    if p.is_null() {
        None
    } else {
        Some(CStr::from_ptr(p).to_string_lossy().into_owned())
    }
}

fn null_arrays(nvr: usize) -> String {
    format!("vr or value is NULL with nvr = {nvr}")
}

// ---------------------------------------------------------------------------------------------
// Inquire version and platform

/// `fmi2GetTypesPlatform` → `"default"` (a static string).
#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

/// `fmi2GetVersion` → `"2.0"` (a static string).
#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

// ---------------------------------------------------------------------------------------------
// Creation and destruction

/// `fmi2SetDebugLogging`: `nCategories = 0` applies `loggingOn` to every category.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    loggingOn: fmi2Boolean,
    nCategories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    const F: &str = "fmi2SetDebugLogging";
    call(c, F, |inst| {
        if nCategories == 0 {
            return inst.set_debug_logging(loggingOn != fmi2False, None);
        }
        let Some(pointers) = slice_in(categories, nCategories) else {
            return inst.fail(
                F,
                &format!("categories is NULL with nCategories = {nCategories}"),
            );
        };
        let mut names = Vec::with_capacity(pointers.len());
        for (i, &p) in pointers.iter().enumerate() {
            match copy_string(p) {
                Some(s) => names.push(s),
                None => return inst.fail(F, &format!("categories[{i}] is NULL")),
            }
        }
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        inst.set_debug_logging(loggingOn != fmi2False, Some(&names))
    })
}

/// `fmi2Instantiate`: copies every string, checks the type and the GUID, reads the body from the
/// resource directory (the embedded default body when there is none) and returns a new instance,
/// or NULL after a logged message.
#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instanceName: fmi2String,
    fmuType: c_int,
    fmuGUID: fmi2String,
    fmuResourceLocation: fmi2String,
    functions: *const fmi2CallbackFunctions,
    visible: fmi2Boolean,
    loggingOn: fmi2Boolean,
) -> fmi2Component {
    let _ = visible;
    catch_unwind(AssertUnwindSafe(|| {
        instantiate(
            copy_string(instanceName),
            fmuType,
            copy_string(fmuGUID),
            copy_string(fmuResourceLocation),
            functions.as_ref().copied(),
            loggingOn != fmi2False,
        )
    }))
    .unwrap_or(null_mut())
}

/// The body of [`fmi2Instantiate`] once every argument is copied.
fn instantiate(
    name: Option<String>,
    fmu_type: c_int,
    guid: Option<String>,
    resource_location: Option<String>,
    callbacks: Option<fmi2CallbackFunctions>,
    logging_on: bool,
) -> fmi2Component {
    const F: &str = "fmi2Instantiate";
    let sink = match callbacks {
        Some(cb) if cb.logger.is_some() => Sink::C {
            logger: cb.logger,
            environment: cb.componentEnvironment,
        },
        _ => Sink::None,
    };
    let mut logger = Logger::new(sink, name.as_deref().unwrap_or(""), logging_on);
    let name = match name {
        Some(n) if !n.is_empty() => n,
        _ => {
            logger.error(&format!("{F}: instanceName is NULL or empty"));
            return null_mut();
        }
    };
    if fmu_type != fmi2CoSimulation {
        let what = if fmu_type == fmi2ModelExchange {
            "fmi2ModelExchange".to_string()
        } else {
            format!("fmi2Type({fmu_type})")
        };
        logger.error(&format!(
            "{F}: {name}: fmuType {what} is not supported; this FMU is co-simulation only (fmi2CoSimulation)"
        ));
        return null_mut();
    }
    let guid = match guid {
        Some(g) if !g.is_empty() => g,
        _ => {
            logger.error(&format!("{F}: {name}: fmuGUID is NULL or empty"));
            return null_mut();
        }
    };
    let resource_dir: Option<PathBuf> = match resource_location.as_deref() {
        None => {
            logger.event(&format!(
                "{F}: no fmuResourceLocation; using the embedded default body"
            ));
            None
        }
        Some(uri) => match resource_path(uri) {
            Ok(p) if p.is_dir() => {
                logger.event(&format!("{F}: resources in {}", p.display()));
                Some(p)
            }
            Ok(p) => {
                logger.event(&format!(
                    "{F}: resource directory {} does not exist; using the embedded default body",
                    p.display()
                ));
                None
            }
            Err(e) => {
                logger.event(&format!("{F}: {e}; using the embedded default body"));
                None
            }
        },
    };
    let slave = match catch_unwind(|| Slave::from_resources(resource_dir.as_deref())) {
        Ok(Ok(slave)) => slave,
        Ok(Err(e)) => {
            logger.error(&format!("{F}: {name}: {}", e.message));
            return null_mut();
        }
        Err(payload) => {
            logger.error(&format!(
                "{F}: {name}: internal error (panic) while loading the body: {}",
                panic_text(payload.as_ref())
            ));
            return null_mut();
        }
    };
    if slave.guid() != guid {
        logger.error(&format!(
            "{F}: {name}: fmuGUID {guid} does not match this FMU's GUID {} (modelDescription.xml and binary or body.json are from different builds)",
            slave.guid()
        ));
        return null_mut();
    }
    logger.event(&format!("{F}: instance {name} created"));
    Box::into_raw(Box::new(Instance::new(slave, logger))) as fmi2Component
}

/// `fmi2FreeInstance`: NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    if c.is_null() {
        return;
    }
    let ptr = c as *mut Component;
    // A panic while dropping leaks the rest; it must not unwind into the importer.
    let _ = catch_unwind(AssertUnwindSafe(|| drop(Box::from_raw(ptr))));
}

// ---------------------------------------------------------------------------------------------
// Initialization, termination, reset

/// `fmi2SetupExperiment`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    toleranceDefined: fmi2Boolean,
    tolerance: fmi2Real,
    startTime: fmi2Real,
    stopTimeDefined: fmi2Boolean,
    stopTime: fmi2Real,
) -> fmi2Status {
    call(c, "fmi2SetupExperiment", |inst| {
        inst.setup_experiment(
            (toleranceDefined != fmi2False).then_some(tolerance),
            startTime,
            (stopTimeDefined != fmi2False).then_some(stopTime),
        )
    })
}

/// `fmi2EnterInitializationMode`.
#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    call(c, "fmi2EnterInitializationMode", |inst| {
        inst.enter_initialization_mode()
    })
}

/// `fmi2ExitInitializationMode`.
#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    call(c, "fmi2ExitInitializationMode", |inst| {
        inst.exit_initialization_mode()
    })
}

/// `fmi2Terminate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    call(c, "fmi2Terminate", |inst| inst.terminate())
}

/// `fmi2Reset`.
#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    call(c, "fmi2Reset", |inst| inst.reset())
}

// ---------------------------------------------------------------------------------------------
// Getting and setting variable values

/// `fmi2GetReal`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetReal";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_out(value, nvr)) {
            (Some(vrs), Some(values)) => inst.get_values(F, vrs, values),
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

/// `fmi2GetInteger`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    const F: &str = "fmi2GetInteger";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_out(value, nvr)) {
            (Some(vrs), Some(values)) => inst.get_values::<i32>(F, vrs, values),
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

/// `fmi2GetBoolean`: writes `fmi2True`/`fmi2False`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    const F: &str = "fmi2GetBoolean";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_out(value, nvr)) {
            (Some(vrs), Some(values)) => {
                let mut flags = vec![false; nvr];
                let status = inst.get_values::<bool>(F, vrs, &mut flags);
                if status == fmi2Status::fmi2OK {
                    for (out, flag) in values.iter_mut().zip(flags) {
                        *out = if flag { fmi2True } else { fmi2False };
                    }
                }
                status
            }
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

/// `fmi2GetString`: the strings stay valid until the next `fmi2GetString` on this instance.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    const F: &str = "fmi2GetString";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_out(value, nvr)) {
            (Some(vrs), Some(out)) => {
                let (status, strings) = inst.get_strings(F, vrs);
                for (o, s) in out.iter_mut().zip(strings) {
                    *o = s.as_ptr();
                }
                status
            }
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

/// `fmi2SetReal`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2SetReal";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_in(value, nvr)) {
            (Some(vrs), Some(values)) => inst.set_values(F, vrs, values),
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

/// `fmi2SetInteger`.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    const F: &str = "fmi2SetInteger";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_in(value, nvr)) {
            (Some(vrs), Some(values)) => inst.set_values::<i32>(F, vrs, values),
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

/// `fmi2SetBoolean`: any non-zero value is true.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    const F: &str = "fmi2SetBoolean";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_in(value, nvr)) {
            (Some(vrs), Some(values)) => {
                let flags: Vec<bool> = values.iter().map(|&b| b != fmi2False).collect();
                inst.set_values::<bool>(F, vrs, &flags)
            }
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

/// `fmi2SetString`: the strings are copied (lossy UTF-8).
#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    const F: &str = "fmi2SetString";
    call(c, F, |inst| {
        match (slice_in(vr, nvr), slice_in(value, nvr)) {
            (Some(vrs), Some(values)) => {
                let copies: Vec<Option<String>> = values.iter().map(|&p| copy_string(p)).collect();
                inst.set_strings(F, vrs, &copies)
            }
            _ => inst.fail(F, &null_arrays(nvr)),
        }
    })
}

// ---------------------------------------------------------------------------------------------
// FMU state

/// `fmi2GetFMUstate`: a NULL `*FMUstate` receives a new state; a non-NULL one is overwritten.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    const F: &str = "fmi2GetFMUstate";
    call(c, F, |inst| {
        if FMUstate.is_null() {
            return inst.fail(F, "FMUstate is NULL");
        }
        let snapshot = match inst.snapshot(F) {
            Ok(s) => s,
            Err(status) => return status,
        };
        store_state(inst, F, FMUstate, snapshot)
    })
}

/// Stores `snapshot` in `*FMUstate` (fmi2GetFMUstate, fmi2DeSerializeFMUstate): a new state when
/// `*FMUstate` is NULL, else it overwrites the live state `*FMUstate` points to.
unsafe fn store_state(
    inst: &mut Component,
    function: &str,
    FMUstate: *mut fmi2FMUstate,
    snapshot: FmuState,
) -> fmi2Status {
    let existing = *FMUstate as *mut FmuState;
    if existing.is_null() {
        *FMUstate = Box::into_raw(Box::new(snapshot)) as fmi2FMUstate;
    } else {
        if !(*existing).is_valid() {
            return inst.fail(
                function,
                "*FMUstate is not a live state of this FMU (freed, or from another FMU)",
            );
        }
        *existing = snapshot;
    }
    fmi2Status::fmi2OK
}

/// `fmi2SetFMUstate`: the state stays valid and can be used again.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status {
    const F: &str = "fmi2SetFMUstate";
    call(c, F, |inst| match (FMUstate as *const FmuState).as_ref() {
        Some(snapshot) => inst.restore(snapshot),
        None => inst.fail(F, "FMUstate is NULL"),
    })
}

/// `fmi2FreeFMUstate`: frees `*FMUstate` and sets it to NULL; a NULL state is a no-op.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    const F: &str = "fmi2FreeFMUstate";
    call(c, F, |inst| {
        if let Err(status) = inst.may_free_state() {
            return status;
        }
        if FMUstate.is_null() || (*FMUstate).is_null() {
            return fmi2Status::fmi2OK;
        }
        let ptr = *FMUstate as *mut FmuState;
        if !(*ptr).is_valid() {
            return inst.fail(
                F,
                "*FMUstate is not a live state of this FMU (freed, or from another FMU)",
            );
        }
        drop(Box::from_raw(ptr));
        *FMUstate = null_mut();
        fmi2Status::fmi2OK
    })
}

/// The live state behind `FMUstate`, or an error message.
unsafe fn live_state<'a>(
    inst: &mut Component,
    function: &str,
    FMUstate: fmi2FMUstate,
) -> Result<&'a FmuState, fmi2Status> {
    match (FMUstate as *const FmuState).as_ref() {
        None => Err(inst.fail(function, "FMUstate is NULL")),
        Some(s) if !s.is_valid() => Err(inst.fail(
            function,
            "FMUstate is not a live state of this FMU (freed, or from another FMU)",
        )),
        Some(s) => Ok(s),
    }
}

/// `fmi2SerializedFMUstateSize`: the number of bytes `fmi2SerializeFMUstate` writes.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    const F: &str = "fmi2SerializedFMUstateSize";
    call(c, F, |inst| {
        if size.is_null() {
            return inst.fail(F, "size is NULL");
        }
        let state = match live_state(inst, F, FMUstate) {
            Ok(s) => s,
            Err(status) => return status,
        };
        match inst.serialize_snapshot(F, state) {
            Ok(bytes) => {
                *size = bytes.len();
                fmi2Status::fmi2OK
            }
            Err(status) => status,
        }
    })
}

/// `fmi2SerializeFMUstate`: writes the state's portable bytes (layout:
/// [`super::instance::SERIALIZED_MAGIC`]) to `serializedState`, which holds `size` bytes, at
/// least `fmi2SerializedFMUstateSize`; bytes beyond the state are set to zero.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    serializedState: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    const F: &str = "fmi2SerializeFMUstate";
    call(c, F, |inst| {
        let state = match live_state(inst, F, FMUstate) {
            Ok(s) => s,
            Err(status) => return status,
        };
        let bytes = match inst.serialize_snapshot(F, state) {
            Ok(b) => b,
            Err(status) => return status,
        };
        if size < bytes.len() {
            return inst.fail(
                F,
                &format!(
                    "size = {size} rejected: the state needs {} bytes (fmi2SerializedFMUstateSize)",
                    bytes.len()
                ),
            );
        }
        let Some(out) = slice_out(serializedState as *mut u8, size) else {
            return inst.fail(F, &format!("serializedState is NULL with size = {size}"));
        };
        out[..bytes.len()].copy_from_slice(&bytes);
        out[bytes.len()..].fill(0);
        fmi2Status::fmi2OK
    })
}

/// `fmi2DeSerializeFMUstate`: a state from bytes of `fmi2SerializeFMUstate` (of an instance of
/// the same FMU, possibly in another process); a NULL `*FMUstate` receives a new state, a
/// non-NULL one is overwritten. Bytes of another body or version are refused with a message.
#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    serializedState: *const fmi2Byte,
    size: usize,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    const F: &str = "fmi2DeSerializeFMUstate";
    call(c, F, |inst| {
        if FMUstate.is_null() {
            return inst.fail(F, "FMUstate is NULL");
        }
        let Some(bytes) = slice_in(serializedState as *const u8, size) else {
            return inst.fail(F, &format!("serializedState is NULL with size = {size}"));
        };
        let snapshot = match inst.deserialize_snapshot(bytes) {
            Ok(s) => s,
            Err(status) => return status,
        };
        store_state(inst, F, FMUstate, snapshot)
    })
}

/// `fmi2GetDirectionalDerivative`: not supported (`providesDirectionalDerivative="false"`).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    vUnknown_ref: *const fmi2ValueReference,
    nUnknown: usize,
    vKnown_ref: *const fmi2ValueReference,
    nKnown: usize,
    dvKnown: *const fmi2Real,
    dvUnknown: *mut fmi2Real,
) -> fmi2Status {
    let _ = (
        vUnknown_ref,
        nUnknown,
        vKnown_ref,
        nKnown,
        dvKnown,
        dvUnknown,
    );
    const F: &str = "fmi2GetDirectionalDerivative";
    call(c, F, |inst| {
        inst.unsupported(
            F,
            "directional derivatives (providesDirectionalDerivative=\"false\")",
        )
    })
}

// ---------------------------------------------------------------------------------------------
// Co-simulation

/// `fmi2SetRealInputDerivatives` (`canInterpolateInputs="true"`): derivatives of force inputs,
/// see [`crate::slave::Slave::set_real_input_derivatives`].
#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *const fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2SetRealInputDerivatives";
    call(c, F, |inst| {
        match (
            slice_in(vr, nvr),
            slice_in(order, nvr),
            slice_in(value, nvr),
        ) {
            (Some(vrs), Some(orders), Some(values)) => {
                inst.set_real_input_derivatives(vrs, orders, values)
            }
            _ => inst.fail(F, &format!("vr, order or value is NULL with nvr = {nvr}")),
        }
    })
}

/// `fmi2GetRealOutputDerivatives` (`maxOutputDerivativeOrder="2"`): see
/// [`crate::slave::Slave::get_real_output_derivative`] for which outputs have derivatives.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetRealOutputDerivatives";
    call(c, F, |inst| {
        match (
            slice_in(vr, nvr),
            slice_in(order, nvr),
            slice_out(value, nvr),
        ) {
            (Some(vrs), Some(orders), Some(values)) => {
                inst.get_real_output_derivatives(vrs, orders, values)
            }
            _ => inst.fail(F, &format!("vr, order or value is NULL with nvr = {nvr}")),
        }
    })
}

/// `fmi2DoStep`: `noSetFMUStatePriorToCurrentPoint` is ignored (states are kept by the importer).
#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    let _ = noSetFMUStatePriorToCurrentPoint;
    call(c, "fmi2DoStep", |inst| {
        inst.do_step(currentCommunicationPoint, communicationStepSize)
    })
}

/// `fmi2CancelStep`: FMI 2.0 allows it only in the state StepInProgress, after `fmi2DoStep`
/// returned `fmi2Pending`. Steps here are synchronous (`canRunAsynchronuously="false"`), so that
/// state never occurs and every call is a calling-sequence error (`fmi2Error`, as the Reference
/// FMUs do); the instance is unchanged.
#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    const F: &str = "fmi2CancelStep";
    call(c, F, |inst| inst.cancel_step())
}

/// Writes `result` to `value` (checked for NULL) or returns its error status.
unsafe fn write_status<T>(
    inst: &mut Component,
    function: &str,
    value: *mut T,
    result: impl FnOnce(&mut Component) -> Result<T, fmi2Status>,
) -> fmi2Status {
    if value.is_null() {
        return inst.fail(function, "value is NULL");
    }
    match result(inst) {
        Ok(x) => {
            *value = x;
            fmi2Status::fmi2OK
        }
        Err(status) => status,
    }
}

/// `fmi2GetStatus`: always an error (see [`Instance::get_status`]).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    s: c_int,
    value: *mut fmi2Status,
) -> fmi2Status {
    const F: &str = "fmi2GetStatus";
    call(c, F, |inst| {
        write_status(inst, F, value, |i| i.get_status(s))
    })
}

/// `fmi2GetRealStatus`: `fmi2LastSuccessfulTime`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    s: c_int,
    value: *mut fmi2Real,
) -> fmi2Status {
    const F: &str = "fmi2GetRealStatus";
    call(c, F, |inst| {
        write_status(inst, F, value, |i| i.get_real_status(s))
    })
}

/// `fmi2GetIntegerStatus`: no Integer status exists.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    s: c_int,
    value: *mut fmi2Integer,
) -> fmi2Status {
    const F: &str = "fmi2GetIntegerStatus";
    call(c, F, |inst| {
        write_status(inst, F, value, |i| i.get_integer_status(s))
    })
}

/// `fmi2GetBooleanStatus`: `fmi2Terminated` (true after a discarded step).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    s: c_int,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    const F: &str = "fmi2GetBooleanStatus";
    call(c, F, |inst| {
        write_status(inst, F, value, |i| {
            i.get_boolean_status(s)
                .map(|b| if b { fmi2True } else { fmi2False })
        })
    })
}

/// `fmi2GetStringStatus`: `fmi2PendingStatus` needs a pending step, which never happens.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    s: c_int,
    value: *mut fmi2String,
) -> fmi2Status {
    const F: &str = "fmi2GetStringStatus";
    call(c, F, |inst| {
        if value.is_null() {
            return inst.fail(F, "value is NULL");
        }
        inst.get_string_status(s)
    })
}
