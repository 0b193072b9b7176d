//! The FMI 2.0 C types (`fmi2TypesPlatform.h`, `fmi2FunctionTypes.h`), written by hand.
//!
//! Incoming enumerations (`fmi2Type`, `fmi2StatusKind`) are taken as `c_int` and compared with the
//! constants below: an out-of-range value in a Rust `enum` would be undefined behaviour.

#![allow(non_camel_case_types, non_upper_case_globals, non_snake_case)]

use std::ffi::{c_char, c_int, c_uint, c_void};

/// `fmi2Component`: the opaque instance pointer handed to the importer.
pub type fmi2Component = *mut c_void;
/// `fmi2ComponentEnvironment`: the importer's opaque pointer, passed back to its callbacks.
pub type fmi2ComponentEnvironment = *mut c_void;
/// `fmi2FMUstate`: an opaque saved state.
pub type fmi2FMUstate = *mut c_void;
/// `fmi2ValueReference`.
pub type fmi2ValueReference = c_uint;
/// `fmi2Real`.
pub type fmi2Real = f64;
/// `fmi2Integer`.
pub type fmi2Integer = c_int;
/// `fmi2Boolean`: `fmi2False` = 0, anything else is true (`fmi2True` = 1 when written).
pub type fmi2Boolean = c_int;
/// `fmi2Char`.
pub type fmi2Char = c_char;
/// `fmi2String`: a NUL-terminated string.
pub type fmi2String = *const fmi2Char;
/// `fmi2Byte`.
pub type fmi2Byte = c_char;

/// `fmi2True`.
pub const fmi2True: fmi2Boolean = 1;
/// `fmi2False`.
pub const fmi2False: fmi2Boolean = 0;

/// `fmi2Status` (returned, so a Rust enum with the C values is safe).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum fmi2Status {
    fmi2OK = 0,
    fmi2Warning = 1,
    fmi2Discard = 2,
    fmi2Error = 3,
    fmi2Fatal = 4,
    fmi2Pending = 5,
}

/// `fmi2Type` value `fmi2ModelExchange`.
pub const fmi2ModelExchange: c_int = 0;
/// `fmi2Type` value `fmi2CoSimulation`.
pub const fmi2CoSimulation: c_int = 1;

/// `fmi2StatusKind` value `fmi2DoStepStatus`.
pub const fmi2DoStepStatus: c_int = 0;
/// `fmi2StatusKind` value `fmi2PendingStatus`.
pub const fmi2PendingStatus: c_int = 1;
/// `fmi2StatusKind` value `fmi2LastSuccessfulTime`.
pub const fmi2LastSuccessfulTime: c_int = 2;
/// `fmi2StatusKind` value `fmi2Terminated`.
pub const fmi2Terminated: c_int = 3;

/// The name of an `fmi2StatusKind` value, for messages.
pub fn status_kind_name(kind: c_int) -> String {
    match kind {
        fmi2DoStepStatus => "fmi2DoStepStatus".into(),
        fmi2PendingStatus => "fmi2PendingStatus".into(),
        fmi2LastSuccessfulTime => "fmi2LastSuccessfulTime".into(),
        fmi2Terminated => "fmi2Terminated".into(),
        other => format!("fmi2StatusKind({other})"),
    }
}

/// `fmi2CallbackLogger`: `void logger(env, instanceName, status, category, message, ...)`,
/// printf-style. This crate always calls it with the format `"%s"` and the text as the one
/// variadic argument, so `%` in messages is harmless.
pub type fmi2CallbackLogger = Option<
    unsafe extern "C" fn(
        fmi2ComponentEnvironment,
        fmi2String,
        fmi2Status,
        fmi2String,
        fmi2String,
        ...
    ),
>;
/// `fmi2CallbackAllocateMemory` (not used: `canNotUseMemoryManagementFunctions="true"`).
pub type fmi2CallbackAllocateMemory = Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>;
/// `fmi2CallbackFreeMemory` (not used).
pub type fmi2CallbackFreeMemory = Option<unsafe extern "C" fn(*mut c_void)>;
/// `fmi2StepFinished` (only for asynchronous steps; never called).
pub type fmi2StepFinished = Option<unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2Status)>;

/// `fmi2CallbackFunctions`. Every member may be NULL; `fmi2Instantiate` copies the struct.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct fmi2CallbackFunctions {
    pub logger: fmi2CallbackLogger,
    pub allocateMemory: fmi2CallbackAllocateMemory,
    pub freeMemory: fmi2CallbackFreeMemory,
    pub stepFinished: fmi2StepFinished,
    pub componentEnvironment: fmi2ComponentEnvironment,
}
