//! Shared by `tests/fmi2_abi.rs` and `tests/fmi2_slave.rs`: a logger callback that records every
//! message, and small wrappers around the exported functions.
//!
//! The FMI logger is a C variadic function, which stable Rust cannot define. The recorder is a
//! plain `extern "C"` function with the one variadic argument this crate passes (the `"%s"`
//! text) as a sixth parameter, cast to the variadic type. On the System V x86-64 and AArch64
//! Linux ABIs a variadic call passes its first integer/pointer arguments in the same registers
//! as a non-variadic one, and on Windows x64 in the same registers and stack slots, so the
//! callee reads them correctly; the tests are compiled for those targets only (Windows: cross-built
//! and run under wine by `cargo xtask test`).

#![allow(dead_code, non_snake_case)]

use flexbody::fmi2::exports::*;
use flexbody::fmi2::types::*;
use std::ffi::{c_char, c_void, CStr, CString};
use std::sync::Mutex;

/// The `file:` URI of a local directory as importers pass it: `file:///tmp/x` on Linux,
/// `file:///C:/Users/x` on Windows (forward slashes), spaces percent-encoded.
pub fn file_uri(dir: &std::path::Path) -> String {
    let path = dir
        .to_str()
        .expect("a UTF-8 path")
        .replace('\\', "/")
        .replace(' ', "%20");
    if path.starts_with('/') {
        format!("file://{path}")
    } else {
        format!("file:///{path}")
    }
}

/// One recorded logger call.
#[derive(Debug, Clone)]
pub struct Message {
    pub environment: usize,
    pub instance_name: String,
    pub instance_name_ptr: usize,
    pub status: fmi2Status,
    pub category: String,
    pub format: String,
    pub text: String,
}

/// The importer side: its environment is a pointer to this recorder.
#[derive(Default)]
pub struct Recorder {
    pub messages: Mutex<Vec<Message>>,
}

impl Recorder {
    pub fn take(&self) -> Vec<Message> {
        std::mem::take(&mut *self.messages.lock().unwrap())
    }

    pub fn texts(&self) -> Vec<String> {
        self.messages
            .lock()
            .unwrap()
            .iter()
            .map(|m| m.text.clone())
            .collect()
    }

    pub fn last_text(&self) -> String {
        self.messages
            .lock()
            .unwrap()
            .last()
            .map(|m| m.text.clone())
            .unwrap_or_default()
    }
}

unsafe fn text(p: *const c_char) -> String {
    if p.is_null() {
        "<NULL>".into()
    } else {
        CStr::from_ptr(p).to_string_lossy().into_owned()
    }
}

unsafe extern "C" fn record(
    environment: fmi2ComponentEnvironment,
    instance_name: fmi2String,
    status: fmi2Status,
    category: fmi2String,
    format: fmi2String,
    argument: *const c_char,
) {
    let recorder = &*(environment as *const Recorder);
    recorder.messages.lock().unwrap().push(Message {
        environment: environment as usize,
        instance_name: text(instance_name),
        instance_name_ptr: instance_name as usize,
        status,
        category: text(category),
        format: text(format),
        text: text(argument),
    });
}

type Fixed = unsafe extern "C" fn(
    fmi2ComponentEnvironment,
    fmi2String,
    fmi2Status,
    fmi2String,
    fmi2String,
    *const c_char,
);

/// Callbacks whose logger records into `recorder` (which must outlive the instance).
pub fn callbacks(recorder: &Recorder) -> fmi2CallbackFunctions {
    // SAFETY: see the module documentation (register-compatible on the supported targets).
    let logger = unsafe {
        std::mem::transmute::<
            Fixed,
            unsafe extern "C" fn(
                fmi2ComponentEnvironment,
                fmi2String,
                fmi2Status,
                fmi2String,
                fmi2String,
                ...
            ),
        >(record)
    };
    fmi2CallbackFunctions {
        logger: Some(logger),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: recorder as *const Recorder as *mut c_void,
    }
}

/// `fmi2Instantiate` with owned strings (dropped right after the call, as an importer may do).
pub fn instantiate(
    name: Option<&str>,
    fmu_type: i32,
    guid: Option<&str>,
    resource_location: Option<&str>,
    functions: Option<&fmi2CallbackFunctions>,
    logging_on: bool,
) -> fmi2Component {
    let name = name.map(|s| CString::new(s).unwrap());
    let guid = guid.map(|s| CString::new(s).unwrap());
    let location = resource_location.map(|s| CString::new(s).unwrap());
    let ptr = |s: &Option<CString>| s.as_ref().map_or(std::ptr::null(), |s| s.as_ptr());
    let c = unsafe {
        fmi2Instantiate(
            ptr(&name),
            fmu_type,
            ptr(&guid),
            ptr(&location),
            functions.map_or(std::ptr::null(), |f| f as *const _),
            fmi2False,
            if logging_on { fmi2True } else { fmi2False },
        )
    };
    // Overwrite the strings before freeing them: the instance must have copied them.
    for s in [name, guid, location].into_iter().flatten() {
        let mut bytes = s.into_bytes_with_nul();
        bytes.iter_mut().for_each(|b| *b = b'#');
        drop(bytes);
    }
    c
}

pub fn get_real(c: fmi2Component, vrs: &[u32]) -> (fmi2Status, Vec<f64>) {
    let mut values = vec![f64::NAN; vrs.len()];
    let s = unsafe { fmi2GetReal(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr()) };
    (s, values)
}

pub fn set_real(c: fmi2Component, vrs: &[u32], values: &[f64]) -> fmi2Status {
    assert_eq!(vrs.len(), values.len());
    unsafe { fmi2SetReal(c, vrs.as_ptr(), vrs.len(), values.as_ptr()) }
}
