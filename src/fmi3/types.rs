//! The FMI 3.0 C types (`fmi3PlatformTypes.h`, `fmi3FunctionTypes.h`), written by hand.
#![allow(non_camel_case_types, non_upper_case_globals, non_snake_case)]

use crate::fmi2::fmi2Status;
use std::ffi::{c_char, c_void};

/// `fmi3Instance`: the boxed [`super::Fmi3Instance`].
pub type fmi3Instance = *mut c_void;
/// `fmi3InstanceEnvironment`: the importer's pointer, passed back to its callbacks.
pub type fmi3InstanceEnvironment = *mut c_void;
/// `fmi3FMUState`: the boxed [`crate::fmi2::exports::FmuState`] (the same snapshot as FMI 2.0's).
pub type fmi3FMUState = *mut c_void;
/// `fmi3ValueReference`.
pub type fmi3ValueReference = u32;
/// `fmi3Float64`.
pub type fmi3Float64 = f64;
/// `fmi3Int32`.
pub type fmi3Int32 = i32;
/// `fmi3Int64`.
pub type fmi3Int64 = i64;
/// `fmi3Boolean`: C's `bool` (one byte, 0 or 1). Read as a byte, so that any non-zero value an
/// importer writes is true rather than undefined behaviour.
pub type fmi3Boolean = u8;
/// `fmi3String`.
pub type fmi3String = *const c_char;
/// `fmi3Byte`.
pub type fmi3Byte = u8;
/// `fmi3Binary`.
pub type fmi3Binary = *const fmi3Byte;
/// `fmi3Clock` (C's `bool`).
pub type fmi3Clock = u8;

pub const fmi3True: fmi3Boolean = 1;
pub const fmi3False: fmi3Boolean = 0;

/// `fmi3Status`: FMI 2.0's statuses without `fmi2Pending`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum fmi3Status {
    fmi3OK = 0,
    fmi3Warning = 1,
    fmi3Discard = 2,
    fmi3Error = 3,
    fmi3Fatal = 4,
}

impl From<fmi2Status> for fmi3Status {
    /// The same status; `fmi2Pending` (never returned here: steps are synchronous) is an error.
    fn from(status: fmi2Status) -> fmi3Status {
        match status {
            fmi2Status::fmi2OK => fmi3Status::fmi3OK,
            fmi2Status::fmi2Warning => fmi3Status::fmi3Warning,
            fmi2Status::fmi2Discard => fmi3Status::fmi3Discard,
            fmi2Status::fmi2Error | fmi2Status::fmi2Pending => fmi3Status::fmi3Error,
            fmi2Status::fmi2Fatal => fmi3Status::fmi3Fatal,
        }
    }
}

/// `fmi3LogMessageCallback`.
pub type fmi3LogMessageCallback = Option<
    unsafe extern "C" fn(
        instanceEnvironment: fmi3InstanceEnvironment,
        status: fmi3Status,
        category: fmi3String,
        message: fmi3String,
    ),
>;

/// `fmi3IntermediateUpdateCallback` (never called: `providesIntermediateUpdate="false"`).
pub type fmi3IntermediateUpdateCallback = Option<
    unsafe extern "C" fn(
        instanceEnvironment: fmi3InstanceEnvironment,
        intermediateUpdateTime: fmi3Float64,
        intermediateVariableSetRequested: fmi3Boolean,
        intermediateVariableGetAllowed: fmi3Boolean,
        intermediateStepFinished: fmi3Boolean,
        canReturnEarly: fmi3Boolean,
        earlyReturnRequested: *mut fmi3Boolean,
        earlyReturnTime: *mut fmi3Float64,
    ),
>;

/// `fmi3ClockUpdateCallback`, `fmi3LockPreemptionCallback`, `fmi3UnlockPreemptionCallback`
/// (scheduled execution, not supported): only their size matters.
pub type fmi3Callback = Option<unsafe extern "C" fn()>;
