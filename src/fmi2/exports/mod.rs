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
pub(crate) fn panic_text(payload: &(dyn Any + Send)) -> String {
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
pub(crate) unsafe fn slice_in<'a, T>(p: *const T, n: usize) -> Option<&'a [T]> {
    if n == 0 {
        Some(&[])
    } else if p.is_null() {
        None
    } else {
        Some(std::slice::from_raw_parts(p, n))
    }
}

/// Mutable counterpart of [`slice_in`].
pub(crate) unsafe fn slice_out<'a, T>(p: *mut T, n: usize) -> Option<&'a mut [T]> {
    if n == 0 {
        Some(&mut [])
    } else if p.is_null() {
        None
    } else {
        Some(std::slice::from_raw_parts_mut(p, n))
    }
}

/// A copy of a C string (lossy UTF-8); None for NULL.
pub(crate) unsafe fn copy_string(p: fmi2String) -> Option<String> {
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
    let resources = resource_location.as_deref().map(resource_path);
    let resource_dir = resource_directory(F, "fmuResourceLocation", resources, &mut logger);
    let Some(slave) = load_slave(F, &name, &guid, resource_dir.as_deref(), &mut logger) else {
        return null_mut();
    };
    logger.event(&format!("{F}: instance {name} created"));
    Box::into_raw(Box::new(Instance::new(slave, logger))) as fmi2Component
}

/// The resource directory of a new instance (FMI 2.0 and 3.0) from the importer's argument
/// `argument` (None: not given; `Err`: not a usable location), or None, logged, for the
/// embedded default body.
pub(crate) fn resource_directory(
    function: &str,
    argument: &str,
    location: Option<Result<PathBuf, String>>,
    logger: &mut Logger,
) -> Option<PathBuf> {
    let default = "using the embedded default body";
    match location {
        None => {
            logger.event(&format!("{function}: no {argument}; {default}"));
            None
        }
        Some(Ok(p)) if p.is_dir() => {
            logger.event(&format!("{function}: resources in {}", p.display()));
            Some(p)
        }
        Some(Ok(p)) => {
            logger.event(&format!(
                "{function}: resource directory {} does not exist; {default}",
                p.display()
            ));
            None
        }
        Some(Err(e)) => {
            logger.event(&format!("{function}: {e}; {default}"));
            None
        }
    }
}

/// The slave of a new instance (FMI 2.0 and 3.0): the body from `resource_dir` (the embedded
/// default body when None), checked against the importer's GUID (`instantiationToken`); None
/// after a logged message.
pub(crate) fn load_slave(
    function: &str,
    name: &str,
    guid: &str,
    resource_dir: Option<&std::path::Path>,
    logger: &mut Logger,
) -> Option<Slave> {
    let slave = match catch_unwind(|| Slave::from_resources(resource_dir)) {
        Ok(Ok(slave)) => slave,
        Ok(Err(e)) => {
            logger.error(&format!("{function}: {name}: {}", e.message));
            return None;
        }
        Err(payload) => {
            logger.error(&format!(
                "{function}: {name}: internal error (panic) while loading the body: {}",
                panic_text(payload.as_ref())
            ));
            return None;
        }
    };
    if slave.guid() != guid {
        logger.error(&format!(
            "{function}: {name}: fmuGUID {guid} does not match this FMU's GUID {} (modelDescription.xml and binary or body.json are from different builds)",
            slave.guid()
        ));
        return None;
    }
    Some(slave)
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

mod cosimulation;
mod state;
mod values;
pub use cosimulation::*;
pub use state::*;
pub use values::*;
