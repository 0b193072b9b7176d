//! The exported FMI 2.0 functions called in-process, as an importer would, on the paths that do
//! not reach the physics (`src/slave/`): strings, signatures, rejected instantiations, NULL
//! arguments. Tests with a working slave are in `tests/fmi2_slave.rs`.

#![cfg(any(
    all(
        target_os = "linux",
        any(target_arch = "x86_64", target_arch = "aarch64")
    ),
    all(target_os = "windows", target_arch = "x86_64")
))]

mod fmi2_support;

use flexbody::fmi2::exports::*;
use flexbody::fmi2::types::*;
use fmi2_support::*;
use std::ffi::{c_char, c_int, CStr};
use std::ptr::{null, null_mut};

const OK: fmi2Status = fmi2Status::fmi2OK;
const ERR: fmi2Status = fmi2Status::fmi2Error;

#[test]
fn version_and_platform_are_static_strings() {
    let v = fmi2GetVersion();
    let p = fmi2GetTypesPlatform();
    assert_eq!(unsafe { CStr::from_ptr(v) }.to_str().unwrap(), "2.0");
    assert_eq!(unsafe { CStr::from_ptr(p) }.to_str().unwrap(), "default");
    // Static: the same pointer every time.
    assert_eq!(v, fmi2GetVersion());
    assert_eq!(p, fmi2GetTypesPlatform());
}

/// Every export has the type of the FMI 2.0 header (`fmi2FunctionTypes.h`); a drift does not
/// compile. The count is the standard's: 25 common + 9 co-simulation functions.
#[test]
fn exports_have_the_standard_signatures() {
    type C = fmi2Component;
    type S = fmi2Status;
    type Vr = *const fmi2ValueReference;
    let common: [usize; 25] = [
        fmi2GetTypesPlatform as extern "C" fn() -> *const c_char as usize,
        fmi2GetVersion as extern "C" fn() -> *const c_char as usize,
        fmi2SetDebugLogging as unsafe extern "C" fn(C, fmi2Boolean, usize, *const fmi2String) -> S
            as usize,
        fmi2Instantiate
            as unsafe extern "C" fn(
                fmi2String,
                c_int,
                fmi2String,
                fmi2String,
                *const fmi2CallbackFunctions,
                fmi2Boolean,
                fmi2Boolean,
            ) -> C as usize,
        fmi2FreeInstance as unsafe extern "C" fn(C) as usize,
        fmi2SetupExperiment as unsafe extern "C" fn(C, fmi2Boolean, f64, f64, fmi2Boolean, f64) -> S
            as usize,
        fmi2EnterInitializationMode as unsafe extern "C" fn(C) -> S as usize,
        fmi2ExitInitializationMode as unsafe extern "C" fn(C) -> S as usize,
        fmi2Terminate as unsafe extern "C" fn(C) -> S as usize,
        fmi2Reset as unsafe extern "C" fn(C) -> S as usize,
        fmi2GetReal as unsafe extern "C" fn(C, Vr, usize, *mut f64) -> S as usize,
        fmi2GetInteger as unsafe extern "C" fn(C, Vr, usize, *mut fmi2Integer) -> S as usize,
        fmi2GetBoolean as unsafe extern "C" fn(C, Vr, usize, *mut fmi2Boolean) -> S as usize,
        fmi2GetString as unsafe extern "C" fn(C, Vr, usize, *mut fmi2String) -> S as usize,
        fmi2SetReal as unsafe extern "C" fn(C, Vr, usize, *const f64) -> S as usize,
        fmi2SetInteger as unsafe extern "C" fn(C, Vr, usize, *const fmi2Integer) -> S as usize,
        fmi2SetBoolean as unsafe extern "C" fn(C, Vr, usize, *const fmi2Boolean) -> S as usize,
        fmi2SetString as unsafe extern "C" fn(C, Vr, usize, *const fmi2String) -> S as usize,
        fmi2GetFMUstate as unsafe extern "C" fn(C, *mut fmi2FMUstate) -> S as usize,
        fmi2SetFMUstate as unsafe extern "C" fn(C, fmi2FMUstate) -> S as usize,
        fmi2FreeFMUstate as unsafe extern "C" fn(C, *mut fmi2FMUstate) -> S as usize,
        fmi2SerializedFMUstateSize as unsafe extern "C" fn(C, fmi2FMUstate, *mut usize) -> S
            as usize,
        fmi2SerializeFMUstate as unsafe extern "C" fn(C, fmi2FMUstate, *mut fmi2Byte, usize) -> S
            as usize,
        fmi2DeSerializeFMUstate
            as unsafe extern "C" fn(C, *const fmi2Byte, usize, *mut fmi2FMUstate) -> S
            as usize,
        fmi2GetDirectionalDerivative
            as unsafe extern "C" fn(C, Vr, usize, Vr, usize, *const f64, *mut f64) -> S
            as usize,
    ];
    let cs: [usize; 9] = [
        fmi2SetRealInputDerivatives
            as unsafe extern "C" fn(C, Vr, usize, *const fmi2Integer, *const f64) -> S
            as usize,
        fmi2GetRealOutputDerivatives
            as unsafe extern "C" fn(C, Vr, usize, *const fmi2Integer, *mut f64) -> S
            as usize,
        fmi2DoStep as unsafe extern "C" fn(C, f64, f64, fmi2Boolean) -> S as usize,
        fmi2CancelStep as unsafe extern "C" fn(C) -> S as usize,
        fmi2GetStatus as unsafe extern "C" fn(C, c_int, *mut fmi2Status) -> S as usize,
        fmi2GetRealStatus as unsafe extern "C" fn(C, c_int, *mut f64) -> S as usize,
        fmi2GetIntegerStatus as unsafe extern "C" fn(C, c_int, *mut fmi2Integer) -> S as usize,
        fmi2GetBooleanStatus as unsafe extern "C" fn(C, c_int, *mut fmi2Boolean) -> S as usize,
        fmi2GetStringStatus as unsafe extern "C" fn(C, c_int, *mut fmi2String) -> S as usize,
    ];
    let mut all: Vec<usize> = common.iter().chain(cs.iter()).copied().collect();
    all.sort();
    all.dedup();
    assert_eq!(all.len(), 34, "two exports share one function");
}

#[test]
fn model_exchange_is_refused_with_a_message_through_the_importers_logger() {
    let recorder = Recorder::default();
    let functions = callbacks(&recorder);
    let c = instantiate(
        Some("inst A"),
        fmi2ModelExchange,
        Some("{guid}"),
        None,
        Some(&functions),
        false,
    );
    assert!(c.is_null());
    let messages = recorder.take();
    assert_eq!(messages.len(), 1, "{messages:?}");
    let m = &messages[0];
    assert_eq!(
        m.environment, &recorder as *const Recorder as usize,
        "componentEnvironment not passed back"
    );
    assert_eq!(
        m.instance_name, "inst A",
        "instance name not copied before the caller overwrote it"
    );
    assert_eq!(m.status, ERR);
    assert_eq!(m.category, "logStatusError");
    assert_eq!(m.format, "%s");
    assert!(
        m.text.contains("fmi2ModelExchange is not supported"),
        "{}",
        m.text
    );
}

#[test]
fn missing_instance_name_or_guid_is_refused_with_a_message() {
    let recorder = Recorder::default();
    let functions = callbacks(&recorder);
    for (name, guid, expected) in [
        (None, Some("{g}"), "instanceName is NULL or empty"),
        (Some(""), Some("{g}"), "instanceName is NULL or empty"),
        (Some("x"), None, "fmuGUID is NULL or empty"),
        (Some("x"), Some(""), "fmuGUID is NULL or empty"),
    ] {
        let c = instantiate(name, fmi2CoSimulation, guid, None, Some(&functions), false);
        assert!(c.is_null(), "{expected}");
        assert!(
            recorder.last_text().contains(expected),
            "{}",
            recorder.last_text()
        );
    }
    assert_eq!(recorder.take().len(), 4);
}

/// With the wrong GUID the result is NULL with one error message; nothing panics.
#[test]
fn wrong_guid_gives_null_and_a_message_never_a_panic() {
    let recorder = Recorder::default();
    let functions = callbacks(&recorder);
    let c = instantiate(
        Some("x"),
        fmi2CoSimulation,
        Some("{not-this-fmu}"),
        None,
        Some(&functions),
        false,
    );
    assert!(c.is_null());
    let errors: Vec<Message> = recorder
        .take()
        .into_iter()
        .filter(|m| m.status == ERR)
        .collect();
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(
        errors[0].text.starts_with("fmi2Instantiate: x: "),
        "{}",
        errors[0].text
    );
}

#[test]
fn null_callbacks_and_null_logger_are_never_called() {
    // Rejected instantiations log; with no logger that must not crash.
    assert!(instantiate(Some("x"), fmi2ModelExchange, Some("{g}"), None, None, true).is_null());
    let no_logger = fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: null_mut(),
    };
    assert!(instantiate(
        Some("x"),
        fmi2ModelExchange,
        Some("{g}"),
        None,
        Some(&no_logger),
        true
    )
    .is_null());
    assert!(instantiate(
        Some("x"),
        fmi2CoSimulation,
        Some("{g}"),
        Some("file:///nonexistent"),
        None,
        true
    )
    .is_null());
}

#[test]
fn a_null_instance_is_an_error_everywhere_and_free_is_a_no_op() {
    let c = null_mut();
    let vr = [1u32];
    let mut x = [0.0f64];
    let mut n = [0 as fmi2Integer];
    let mut state: fmi2FMUstate = null_mut();
    let mut size = 0usize;
    let mut status = OK;
    let mut s: fmi2String = null();
    unsafe {
        fmi2FreeInstance(c);
        let results = [
            fmi2SetDebugLogging(c, fmi2True, 0, null()),
            fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0),
            fmi2EnterInitializationMode(c),
            fmi2ExitInitializationMode(c),
            fmi2Terminate(c),
            fmi2Reset(c),
            fmi2GetReal(c, vr.as_ptr(), 1, x.as_mut_ptr()),
            fmi2GetInteger(c, vr.as_ptr(), 1, n.as_mut_ptr()),
            fmi2GetBoolean(c, vr.as_ptr(), 1, n.as_mut_ptr()),
            fmi2GetString(c, vr.as_ptr(), 1, &mut s),
            fmi2SetReal(c, vr.as_ptr(), 1, x.as_ptr()),
            fmi2SetInteger(c, vr.as_ptr(), 1, n.as_ptr()),
            fmi2SetBoolean(c, vr.as_ptr(), 1, n.as_ptr()),
            fmi2SetString(c, vr.as_ptr(), 1, &s),
            fmi2GetFMUstate(c, &mut state),
            fmi2SetFMUstate(c, state),
            fmi2FreeFMUstate(c, &mut state),
            fmi2SerializedFMUstateSize(c, state, &mut size),
            fmi2SerializeFMUstate(c, state, null_mut(), 0),
            fmi2DeSerializeFMUstate(c, null(), 0, &mut state),
            fmi2GetDirectionalDerivative(c, null(), 0, null(), 0, null(), null_mut()),
            fmi2SetRealInputDerivatives(c, null(), 0, null(), null()),
            fmi2GetRealOutputDerivatives(c, null(), 0, null(), null_mut()),
            fmi2DoStep(c, 0.0, 1e-3, fmi2True),
            fmi2CancelStep(c),
            fmi2GetStatus(c, fmi2DoStepStatus, &mut status),
            fmi2GetRealStatus(c, fmi2LastSuccessfulTime, x.as_mut_ptr()),
            fmi2GetIntegerStatus(c, fmi2LastSuccessfulTime, n.as_mut_ptr()),
            fmi2GetBooleanStatus(c, fmi2Terminated, n.as_mut_ptr()),
            fmi2GetStringStatus(c, fmi2PendingStatus, &mut s),
        ];
        for (i, r) in results.iter().enumerate() {
            assert_eq!(*r, ERR, "call #{i} with a NULL instance");
        }
    }
    assert!(state.is_null());
}
