//! The FMI 3.0 functions, exported unmangled with the C ABI: the common functions, the
//! co-simulation functions, and those of model exchange, scheduled execution, clocks and the
//! types this FMU has no variables of, which answer with an error message (FMI 3.0 section 2.3:
//! an FMU exports every function of the interface types it supports; the rest are exported too,
//! so that an importer that looks them all up finds them).
//!
//! Each function checks its pointers (a NULL instance gives `fmi3Error` without a message, as
//! there is no logger), converts C arrays to slices and calls [`Fmi3Instance`] inside
//! `catch_unwind`, as the FMI 2.0 exports do ([`crate::fmi2::exports`]); no panic unwinds into the
//! importer.
//!
//! Safety contract of every function: the caller follows FMI 3.0 — `instance` is NULL or a live
//! pointer returned by [`fmi3InstantiateCoSimulation`] and not freed, used by one thread at a
//! time; arrays hold at least the stated number of elements; strings are NUL-terminated; FMU
//! states come from [`fmi3GetFMUState`] of an instance of this FMU.

#![allow(non_snake_case, clippy::missing_safety_doc, clippy::too_many_arguments)]

use super::instance::Fmi3Instance;
use super::types::*;
use crate::fmi2::exports::{
    copy_string, load_slave, panic_text, resource_directory, slice_in, slice_out,
};
use crate::fmi2::logger::{Logger, Sink};
use crate::fmi2::{fmi2Status, Instance};
use std::ffi::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::ptr::null_mut;

mod cosimulation;
mod state;
mod unsupported;
mod values;
pub use cosimulation::*;
pub use state::*;
pub use unsupported::*;
pub use values::*;

/// Runs `f` on the instance behind `instance`, catching panics.
unsafe fn call(
    instance: fmi3Instance,
    function: &str,
    f: impl FnOnce(&mut Fmi3Instance) -> fmi2Status,
) -> fmi3Status {
    let ptr = instance as *mut Fmi3Instance;
    if ptr.is_null() {
        return fmi3Status::fmi3Error;
    }
    match catch_unwind(AssertUnwindSafe(|| f(&mut *ptr))) {
        Ok(status) => status.into(),
        Err(payload) => {
            let text = panic_text(payload.as_ref());
            let _ = catch_unwind(AssertUnwindSafe(|| (*ptr).inner.panicked(function, &text)));
            fmi3Status::fmi3Error
        }
    }
}

fn null_arrays(n_value_references: usize, n_values: usize) -> String {
    format!("valueReferences or values is NULL with nValueReferences = {n_value_references}, nValues = {n_values}")
}

// ---------------------------------------------------------------------------------------------
// Inquire version

/// `fmi3GetVersion` → `"3.0"` (a static string).
#[no_mangle]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

/// `fmi3SetDebugLogging`: `nCategories = 0` applies `loggingOn` to every category.
#[no_mangle]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    instance: fmi3Instance,
    loggingOn: fmi3Boolean,
    nCategories: usize,
    categories: *const fmi3String,
) -> fmi3Status {
    const F: &str = "fmi3SetDebugLogging";
    call(instance, F, |inst| {
        let on = loggingOn != fmi3False;
        if nCategories == 0 {
            return inst.inner.set_debug_logging(on, None);
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
        inst.inner.set_debug_logging(on, Some(&names))
    })
}

// ---------------------------------------------------------------------------------------------
// Creation and destruction

/// The importer's log callback as a logger sink: FMI 3.0's callback has no instance name and
/// takes the message as it is (no format string).
fn sink(callback: fmi3LogMessageCallback, environment: fmi3InstanceEnvironment) -> Sink {
    let Some(callback) = callback else {
        return Sink::None;
    };
    Sink::Rust(Box::new(move |status, category, message| {
        let category = crate::fmi2::logger::to_c_string(category);
        let message = crate::fmi2::logger::to_c_string(message);
        // SAFETY: the importer gave us this callback and environment in
        // fmi3InstantiateCoSimulation; both strings are NUL-terminated and outlive the call.
        unsafe {
            callback(
                environment,
                status.into(),
                category.as_ptr(),
                message.as_ptr(),
            )
        }
    }))
}

/// `fmi3InstantiateCoSimulation`: copies every string, checks the instantiation token, reads the
/// body from `resourcePath` (a directory path; the embedded default body when NULL or absent)
/// and returns a new instance, or NULL after a logged message. Event mode and early return are
/// not offered (`hasEventMode="false"`): asking for them is an error; intermediate variables
/// are not offered either (`providesIntermediateUpdate="false"`), so the callback is never
/// called.
#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    resourcePath: fmi3String,
    visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    eventModeUsed: fmi3Boolean,
    earlyReturnAllowed: fmi3Boolean,
    requiredIntermediateVariables: *const fmi3ValueReference,
    nRequiredIntermediateVariables: usize,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
    intermediateUpdate: fmi3IntermediateUpdateCallback,
) -> fmi3Instance {
    let _ = (
        visible,
        earlyReturnAllowed,
        requiredIntermediateVariables,
        intermediateUpdate,
    );
    catch_unwind(AssertUnwindSafe(|| {
        let name = copy_string(instanceName);
        let token = copy_string(instantiationToken);
        let resources = copy_string(resourcePath);
        let logger = Logger::new(
            sink(logMessage, instanceEnvironment),
            name.as_deref().unwrap_or(""),
            loggingOn != fmi3False,
        )
        .for_fmi3();
        instantiate(
            name,
            token,
            resources,
            eventModeUsed != fmi3False,
            nRequiredIntermediateVariables,
            logger,
        )
    }))
    .unwrap_or(null_mut())
}

/// The body of [`fmi3InstantiateCoSimulation`] once every argument is copied.
fn instantiate(
    name: Option<String>,
    token: Option<String>,
    resource_path: Option<String>,
    event_mode_used: bool,
    n_intermediate: usize,
    mut logger: Logger,
) -> fmi3Instance {
    const F: &str = "fmi3InstantiateCoSimulation";
    let name = match name {
        Some(n) if !n.is_empty() => n,
        _ => {
            logger.error(&format!("{F}: instanceName is NULL or empty"));
            return null_mut();
        }
    };
    if event_mode_used {
        logger.error(&format!(
            "{F}: {name}: eventModeUsed = true is not supported: this FMU has no events (hasEventMode=\"false\")"
        ));
        return null_mut();
    }
    if n_intermediate > 0 {
        logger.error(&format!(
            "{F}: {name}: nRequiredIntermediateVariables = {n_intermediate} rejected: this FMU provides no intermediate update (providesIntermediateUpdate=\"false\")"
        ));
        return null_mut();
    }
    let token = match token {
        Some(t) if !t.is_empty() => t,
        _ => {
            logger.error(&format!("{F}: {name}: instantiationToken is NULL or empty"));
            return null_mut();
        }
    };
    let resources = resource_path.map(|p| Ok(PathBuf::from(p)));
    let resource_dir = resource_directory(F, "resourcePath", resources, &mut logger);
    let Some(slave) = load_slave(F, &name, &token, resource_dir.as_deref(), &mut logger) else {
        return null_mut();
    };
    logger.event(&format!("{F}: instance {name} created"));
    let instance = Fmi3Instance::new(Instance::new(slave, logger).reading_start_values());
    Box::into_raw(Box::new(instance)) as fmi3Instance
}

/// `fmi3FreeInstance`: NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn fmi3FreeInstance(instance: fmi3Instance) {
    if instance.is_null() {
        return;
    }
    let ptr = instance as *mut Fmi3Instance;
    let _ = catch_unwind(AssertUnwindSafe(|| drop(Box::from_raw(ptr))));
}

// ---------------------------------------------------------------------------------------------
// Initialization, termination, reset

/// `fmi3EnterInitializationMode`: the experiment (tolerance, start and stop time) and the
/// entry into Initialization Mode.
#[no_mangle]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    instance: fmi3Instance,
    toleranceDefined: fmi3Boolean,
    tolerance: fmi3Float64,
    startTime: fmi3Float64,
    stopTimeDefined: fmi3Boolean,
    stopTime: fmi3Float64,
) -> fmi3Status {
    call(instance, "fmi3EnterInitializationMode", |inst| {
        inst.enter_initialization_mode(
            (toleranceDefined != fmi3False).then_some(tolerance),
            startTime,
            (stopTimeDefined != fmi3False).then_some(stopTime),
        )
    })
}

/// `fmi3ExitInitializationMode`: to Step Mode (there is no event mode).
#[no_mangle]
pub unsafe extern "C" fn fmi3ExitInitializationMode(instance: fmi3Instance) -> fmi3Status {
    call(instance, "fmi3ExitInitializationMode", |inst| {
        inst.inner.exit_initialization_mode()
    })
}

/// `fmi3Terminate`.
#[no_mangle]
pub unsafe extern "C" fn fmi3Terminate(instance: fmi3Instance) -> fmi3Status {
    call(instance, "fmi3Terminate", |inst| inst.inner.terminate())
}

/// `fmi3Reset`.
#[no_mangle]
pub unsafe extern "C" fn fmi3Reset(instance: fmi3Instance) -> fmi3Status {
    call(instance, "fmi3Reset", |inst| inst.inner.reset())
}
